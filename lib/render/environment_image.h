// The image of an Environment Texture: equirectangular, scene-linear Rec.709 RGB, read and
// written with OpenImageIO.
//
// Storage is Cycles' and Blender's: row 0 is the BOTTOM row of the picture (texture v = 0, the
// −Z pole of an equirectangular map), column 0 its left edge (u = 0). Files store the top row
// first; the loader and the writer flip, as Cycles' OIIO loader does (negative y stride).
//
// Channels, as Cycles' image manager expands them for its RGBA textures and as the Environment
// Texture's Color output then reads them:
//  - 1 channel: grey, copied to R, G and B;
//  - 2 channels: grey and alpha: grey to R, G, B, alpha ignored;
//  - 3 channels: RGB;
//  - 4 or more: the first three are RGB, the rest (alpha, extra layers) are ignored. Files that
//    store straight alpha (PNG, TGA) come out of OpenImageIO premultiplied, as Cycles
//    premultiplies them for Blender's default alpha mode; EXR and HDR store RGB as is.
//
// Colour: ImageColorSpace::Linear values are scene-linear as stored. Srgb values are stored
// ENCODED and decoded with the sRGB curve (Cycles' color_srgb_to_linear) after interpolation,
// as Cycles does for every image whose colour space is sRGB (ImageMetaData::detect_colorspace
// sets compress_as_srgb; svm_image_texture decodes the interpolated value). Auto (files only)
// chooses Linear for floating-point files (EXR, HDR, float TIFF) and Srgb for integer ones
// (PNG, JPEG), as Blender's default colour spaces for float and byte images. The add-on should
// pass Blender's image.colorspace_settings explicitly ("Linear Rec.709" / "Non-Color" →
// Linear, "sRGB" → Srgb; others are not supported).
//
// Values: every channel must be finite and >= 0 (radiance). Cycles silently zeroes non-finite
// texels and keeps negative ones; hairis refuses both with the pixel named, because a
// negative radiance has no importance-sampling density.
#pragma once

#include <string>
#include <vector>

#include "core/expected.h"
#include "core/math.h"

namespace hairis {

/// Limits checked before anything is allocated: 16384 × 8192 (a "16k" HDRI, 1.5 GB of float
/// RGB) is the largest image accepted.
inline constexpr int kMaxEnvironmentImageAxis = 65536;
inline constexpr long long kMaxEnvironmentImagePixels = 1ll << 27;

/// How stored values map to scene-linear RGB (see the file comment).
enum class ImageColorSpace { Auto = 0, Linear = 1, Srgb = 2 };

/// Where the first row of a pixel array lies in the picture.
enum class RowOrder { BottomFirst = 0, TopFirst = 1 };

/// A validated equirectangular image: width × height texels of RGB, finite and non-negative,
/// row 0 at the bottom, scene-linear or sRGB-encoded (srgb()).
class EnvironmentImage {
  public:
    /// An empty image (width() == 0), to be assigned from a factory.
    EnvironmentImage() = default;

    /// From width·height·3 floats, row-major, bottom row first, in `color_space` (Linear or
    /// Srgb: encoded values, kept as they are). Refuses sizes outside the limits, a vector of
    /// the wrong length, Auto, and non-finite or negative values (naming the pixel).
    static Expected<EnvironmentImage> create(int width, int height, std::vector<float> rgb,
                                             ImageColorSpace color_space = ImageColorSpace::Linear);

    /// From a pixel array of `channels` floats per pixel (Blender's image.pixels: 4 channels,
    /// bottom row first), `count` floats in total, in `color_space` (Linear or Srgb; Auto is
    /// refused: an array does not say what it holds). Sizes are checked before anything is
    /// allocated.
    static Expected<EnvironmentImage> from_pixels(const float *pixels, long long count,
                                                  int width, int height, int channels,
                                                  ImageColorSpace color_space,
                                                  RowOrder order = RowOrder::BottomFirst);

    int width() const { return width_; }
    int height() const { return height_; }
    bool empty() const { return width_ == 0; }
    /// True when the stored values are sRGB-encoded (decode after interpolating).
    bool srgb() const { return srgb_; }
    /// Texel (x, y) as stored, y = 0 the bottom row; x ∈ [0, width), y ∈ [0, height).
    Rgb texel(int x, int y) const {
        const float *p = &rgb_[(size_t(y) * size_t(width_) + size_t(x)) * 3];
        return {p[0], p[1], p[2]};
    }
    /// The 3·width·height stored floats, bottom row first.
    const std::vector<float> &rgb() const { return rgb_; }

  private:
    int width_ = 0, height_ = 0;
    bool srgb_ = false;
    std::vector<float> rgb_;
};

/// Reads an image file with OpenImageIO (any format it reads; EXR and Radiance HDR are what
/// HDRIs come as). Errors name the file and the problem: not found, a directory, unreadable,
/// a size over the limits (refused from the header, before the pixels are read), a volume or
/// a pixel that is not finite or negative.
Expected<EnvironmentImage> load_environment_image(const std::string &path,
                                                  ImageColorSpace color_space =
                                                      ImageColorSpace::Auto);

/// Writes width·height·3 floats (bottom row first) as an RGB image file with OpenImageIO, top
/// row first as files store it; the format follows the extension (".exr": 32-bit float
/// OpenEXR, ".hdr": Radiance RGBE, ".png": 8-bit). The values are written as given, also
/// non-finite or negative ones (EXR keeps them), so that tests can make the files a reader
/// must refuse.
Status write_rgb_image(const std::string &path, int width, int height,
                       const std::vector<float> &rgb);
/// The same for a validated image (its stored values): a small HDRI for tests and tools.
Status write_environment_image(const std::string &path, const EnvironmentImage &image);

/// The sRGB transfer curve's inverse (Cycles' color_srgb_to_linear): c/12.92 below 0.04045,
/// ((c + 0.055)/1.055)^2.4 above, 0 for negative c.
float srgb_to_linear(float c);
inline Rgb srgb_to_linear(Rgb c) { return {srgb_to_linear(c.r), srgb_to_linear(c.g), srgb_to_linear(c.b)}; }

}  // namespace hairis
