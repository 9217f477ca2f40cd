#include "render/environment_image.h"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>

namespace hairis {

namespace {

const char *channel_name(int c) { return c == 0 ? "R" : (c == 1 ? "G" : "B"); }

std::string describe(float v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", double(v));
    return text;
}

// The size limits, in the words of the parameter that broke them.
Status check_size(long long width, long long height) {
    if (Status s = first_error(
            check::count_in_range("image width", width, 1, kMaxEnvironmentImageAxis),
            check::count_in_range("image height", height, 1, kMaxEnvironmentImageAxis)))
        return s;
    if (width * height > kMaxEnvironmentImagePixels)
        return Error{"image of " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels is larger than the limit of " +
                     std::to_string(kMaxEnvironmentImagePixels) + " pixels (16384 x 8192)"};
    return std::nullopt;
}

// Radiance: every value finite and >= 0. Pixels are named as the picture shows them: x from
// the left, y from the top.
Status check_values(int width, int height, const std::vector<float> &rgb) {
    for (size_t k = 0; k < rgb.size(); ++k) {
        const float v = rgb[k];
        if (std::isfinite(v) && v >= 0.0f) continue;
        const size_t pixel = k / 3;
        const long long x = (long long)(pixel % size_t(width));
        const long long y_from_top = height - 1 - (long long)(pixel / size_t(width));
        return Error{"image pixel (" + std::to_string(x) + ", " + std::to_string(y_from_top) +
                     ") (x from the left, y from the top) has " + channel_name(int(k % 3)) +
                     " = " + describe(v) + "; radiance must be finite and >= 0"};
    }
    return std::nullopt;
}

}  // namespace

float srgb_to_linear(float c) {
    if (!(c > 0.0f)) return 0.0f;
    return c < 0.04045f ? c * (1.0f / 12.92f) : std::pow((c + 0.055f) * (1.0f / 1.055f), 2.4f);
}

Expected<EnvironmentImage> EnvironmentImage::create(int width, int height,
                                                    std::vector<float> rgb,
                                                    ImageColorSpace color_space) {
    if (Status s = check_size(width, height)) return *s;
    if (color_space != ImageColorSpace::Linear && color_space != ImageColorSpace::Srgb)
        return Error{"image colour space must be Linear or Srgb (Auto is only for files)"};
    const size_t expected = size_t(width) * size_t(height) * 3;
    if (rgb.size() != expected)
        return Error{"image of " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels needs " + std::to_string(expected) + " RGB floats (got " +
                     std::to_string(rgb.size()) + ")"};
    if (Status s = check_values(width, height, rgb)) return *s;
    EnvironmentImage image;
    image.width_ = width;
    image.height_ = height;
    image.srgb_ = color_space == ImageColorSpace::Srgb;
    image.rgb_ = std::move(rgb);
    return image;
}

Expected<EnvironmentImage> EnvironmentImage::from_pixels(const float *pixels, long long count,
                                                         int width, int height, int channels,
                                                         ImageColorSpace color_space,
                                                         RowOrder order) {
    if (Status s = first_error(check_size(width, height),
                               check::count_in_range("image channels", channels, 1, 64)))
        return *s;
    if (color_space != ImageColorSpace::Linear && color_space != ImageColorSpace::Srgb)
        return Error{"a pixel array needs its colour space: Linear or Srgb (Auto is only for "
                     "files)"};
    const long long expected = (long long)width * height * channels;
    if (count != expected)
        return Error{"image of " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels with " + std::to_string(channels) + " channels needs " +
                     std::to_string(expected) + " floats (got " + std::to_string(count) + ")"};
    if (pixels == nullptr) return Error{"image pixels are missing (null pointer)"};
    std::vector<float> rgb(size_t(width) * size_t(height) * 3);
    for (int y = 0; y < height; ++y) {
        const int row = order == RowOrder::BottomFirst ? y : height - 1 - y;
        for (int x = 0; x < width; ++x) {
            const float *p = pixels + (size_t(row) * size_t(width) + size_t(x)) * size_t(channels);
            float *q = &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3];
            for (int c = 0; c < 3; ++c) q[c] = p[channels >= 3 ? c : 0];
        }
    }
    return create(width, height, std::move(rgb), color_space);
}

Expected<EnvironmentImage> load_environment_image(const std::string &path,
                                                  ImageColorSpace color_space) {
    auto fail = [&](const std::string &why) {
        return Error{"environment image \"" + path + "\": " + why};
    };
    std::error_code ec;
    if (path.empty()) return Error{"environment image: no file name given"};
    if (!std::filesystem::exists(path, ec)) return fail("file not found");
    if (std::filesystem::is_directory(path, ec)) return fail("is a directory, not an image");

    auto in = OIIO::ImageInput::open(path);
    if (!in) return fail("not a readable image (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec spec = in->spec();
    if (spec.depth > 1) return fail("is a volume (depth " + std::to_string(spec.depth) + ")");
    if (Status s = check_size(spec.width, spec.height)) return fail(s->message);
    if (spec.nchannels < 1) return fail("has no channels");

    const int width = spec.width, height = spec.height;
    const bool srgb = color_space == ImageColorSpace::Srgb ||
                      (color_space == ImageColorSpace::Auto && !spec.format.is_floating_point());
    // RGB straight into place, bottom row first: start at the last row, step back one row per
    // scanline. A grey channel goes to R and is copied to G and B below.
    const int read_channels = spec.nchannels >= 3 ? 3 : 1;
    std::vector<float> rgb(size_t(width) * size_t(height) * 3);
    const OIIO::stride_t pixel_stride = OIIO::stride_t(3 * sizeof(float));
    const OIIO::stride_t row_stride = pixel_stride * OIIO::stride_t(width);
    float *last_row = rgb.data() + size_t(height - 1) * size_t(width) * 3;
    if (!in->read_image(0, 0, 0, read_channels, OIIO::TypeDesc::FLOAT, last_row, pixel_stride,
                        -row_stride)) {
        std::string why = in->geterror();
        if (why.empty()) why = OIIO::geterror();
        return fail("the pixels cannot be read (truncated or corrupt): " + why);
    }
    in->close();
    if (read_channels == 1)
        for (size_t p = 0; p < rgb.size(); p += 3) rgb[p + 1] = rgb[p + 2] = rgb[p];
    Expected<EnvironmentImage> image = EnvironmentImage::create(
        width, height, std::move(rgb), srgb ? ImageColorSpace::Srgb : ImageColorSpace::Linear);
    if (!image) return fail(image.error().message);
    return image;
}

Status write_rgb_image(const std::string &path, int width, int height,
                       const std::vector<float> &rgb) {
    auto fail = [&](const std::string &why) {
        return Error{"writing image \"" + path + "\": " + why};
    };
    if (Status s = check_size(width, height)) return fail(s->message);
    if (rgb.size() != size_t(width) * size_t(height) * 3)
        return fail("needs " + std::to_string(size_t(width) * size_t(height) * 3) +
                    " RGB floats (got " + std::to_string(rgb.size()) + ")");
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return fail("no writer for this file type (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::FLOAT);
    if (!out->open(path, spec)) return fail(out->geterror());
    const OIIO::stride_t row_stride = OIIO::stride_t(3 * sizeof(float)) * OIIO::stride_t(width);
    const float *last_row = rgb.data() + size_t(height - 1) * size_t(width) * 3;
    if (!out->write_image(OIIO::TypeDesc::FLOAT, last_row, OIIO::AutoStride, -row_stride))
        return fail(out->geterror());
    if (!out->close()) return fail(out->geterror());
    return std::nullopt;
}

Status write_environment_image(const std::string &path, const EnvironmentImage &image) {
    return write_rgb_image(path, image.width(), image.height(), image.rgb());
}

}  // namespace hairis
