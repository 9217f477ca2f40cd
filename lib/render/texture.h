// An Image Texture node on a mesh, looked up at the hit's UV coordinates as Cycles does
// (kernel/svm/image.h, svm_node_tex_image with the Flat projection; kernel/device/cpu/image.h).
//
// Coordinates: the vector is (u, v, 0) from the mesh's UV map, optionally through a Mapping
// node (Point: R·(s∘x) + t, Texture: Rᵀ·(x − t)/s, Vector: R·(s∘x); environment_map.h's
// euler_xyz_rotation), and the texture reads its x and y. Texel (i, j) covers
// [i/w, (i+1)/w] × [j/h, (j+1)/h]; row 0 is the bottom of the picture (v = 0), as the image's
// storage (environment_image.h).
//
// Interpolation: Linear (bilinear between the texel centres: x·w − ½, y·h − ½) or Closest
// (the texel containing the point). Extension of coordinates outside [0, 1]: Repeat (wrap),
// Extend (clamp to the edge texel), Clip (texels outside the image are black: Linear blends
// towards black within half a texel of the edge), Mirror (reflect at every integer, Blender
// 3.5+). sRGB images are decoded after interpolation (environment_image.h).
#pragma once

#include <memory>

#include "core/expected.h"
#include "core/math.h"
#include "render/camera.h"
#include "render/environment_image.h"
#include "render/environment_map.h"

namespace hairis {

enum class TextureInterpolation { Linear = 0, Closest = 1 };
enum class TextureExtension { Repeat = 0, Extend = 1, Clip = 2, Mirror = 3 };

/// What an Image Texture node is made of.
struct ImageTextureDesc {
    std::shared_ptr<const EnvironmentImage> image;
    TextureInterpolation interpolation = TextureInterpolation::Linear;
    TextureExtension extension = TextureExtension::Repeat;
    /// The Mapping node between the UV map and the texture, if any (Point, Texture or Vector).
    bool use_mapping = false;
    MappingNode mapping;
};

/// A validated Image Texture: image, sampling rules and the affine UV map.
class ImageTexture {
  public:
    /// Refuses an empty image, a Normal mapping (it normalizes: no map of the UV plane),
    /// non-finite mapping inputs and a zero Scale component.
    static Expected<ImageTexture> create(ImageTextureDesc desc);

    /// The colour at UV (u, v) (scene-linear RGB).
    Rgb lookup(float u, float v) const;
    /// The colour at texture coordinates (x, y), after the mapping.
    Rgb lookup_mapped(float x, float y) const;

    const EnvironmentImage &image() const { return *desc_.image; }
    const ImageTextureDesc &desc() const { return desc_; }

  private:
    ImageTextureDesc desc_;
    Mat4 uv_to_texture_;  // affine
};

}  // namespace hairis
