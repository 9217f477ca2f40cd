// A world lit by an equirectangular HDRI, as Cycles evaluates a Background shader fed by an
// Environment Texture, and its importance sampling by luminance with an exact density.
//
// Radiance, as Cycles computes it (cycles@v3.4.0 … v5.0.0, unchanged across them):
//  - Lookup vector: the world direction d (the Texture Coordinate's Generated or Object output,
//    or the Environment Texture's unlinked Vector: all are the ray direction in the world),
//    through the Mapping node, then normalised (svm_node_tex_environment's safe_normalize).
//    hairis takes the Mapping as a linear map A (world_to_texture): lookup ĉ = A·d / |A·d|.
//  - Equirectangular (kernel/camera/projection.h, direction_to_equirectangular):
//    u = (atan2(ĉ.y, ĉ.x) − π) / (−2π), v = (acos(ĉ.z) − π) / (−π). So +X looks at the image
//    centre (u = ½), +Y at u = ¼, −Y at u = ¾, −X at the left/right seam; +Z (v = 1) at the
//    top row, −Z (v = 0) at the bottom row, the horizon at v = ½.
//  - Linear interpolation (the node's default) with Cycles' REPEAT extension in BOTH axes
//    (EnvironmentTextureNode::image_params; kernel/device/cpu/image.h, interp_linear): texel
//    centres at ((i + ½)/w, (j + ½)/h), bilinear weights from u·w − ½ and v·h − ½, indices
//    wrapped modulo w and h — so within half a texel of a pole the top row is blended with
//    the bottom row, exactly as Cycles does.
//  - sRGB images (environment_image.h) are interpolated encoded and decoded afterwards.
//  - Background: L = color × strength × texture RGB.
//
// The Mapping node (kernel/svm/mapping_util.h, svm_mapping; R = euler_to_transform(rotation)
// = Rz·Ry·Rx, the XYZ Euler of Blender; s = scale, t = location):
//    Point: R·(s∘d) + t    Texture: R^T·(d − t) / s    Vector: R·(s∘d)    Normal: R·(d / s)
// A direction is only mapped linearly when t = 0 for Point and Texture (Vector and Normal
// ignore t); mapping_node_transform() refuses a translation there rather than bend the map.
//
// Sampling. The sphere is cut into an importance map of H rows equal in v (latitude) and W
// columns equal in u, in TEXTURE space. Cell (I, J) has the weight
//    ∫∫_cell Y(L(u, v)) du dv / (cell area) × ΔΩ_J,
// the mean luminance of the bilinear radiance over the cell times its solid angle
// ΔΩ_J = Δφ·(z_{J+1} − z_J). The mean is exact: the interpolant is a sum of tent functions,
// whose integrals over a cell are closed-form (for a map at the image's resolution, the 3 × 3
// filter [1 6 1]/8 ⊗ [1 6 1]/8); for sRGB images it is the mean of the interpolated decoded
// texels. A cell gets zero weight only where the radiance is zero almost everywhere in it, so
// every direction with radiance has a positive density, also in a black texel next to a
// bright one. Inside a cell, z = cos θ and φ are drawn uniformly, so the density is constant
// per steradian there: pdf = P(cell) / ΔΩ(cell), P from the stored CDFs (piecewise.h). A world
// direction d is sampled in texture space (ĉ) and mapped back, d = A⁻¹ĉ / |A⁻¹ĉ|, with the
// Jacobian of ĉ(d) = A·d/|A·d|: |det A| / |A·d|³.
//
// sample() returns pdf(wi) for its own direction wi (a direction that float rounding would put
// in a neighbouring cell is moved a few ulps inwards), so the two agree bit for bit.
#pragma once

#include <cstddef>
#include <vector>

#include "render/camera.h"
#include "render/environment_image.h"
#include "core/expected.h"
#include "core/math.h"
#include "sampling/piecewise.h"

namespace hairis {

/// Blender's Mapping node: its vector_type and its Location, Rotation and Scale inputs.
enum class MappingType { Point = 0, Texture = 1, Vector = 2, Normal = 3 };
struct MappingNode {
    MappingType type = MappingType::Point;
    Vec3 location{0, 0, 0};
    Vec3 rotation{0, 0, 0};  ///< Euler XYZ in radians (Blender's Rotation input)
    Vec3 scale{1, 1, 1};
};

/// Cycles' euler_to_transform: the rotation Rz(r.z)·Ry(r.y)·Rx(r.x) (X applied first).
Mat4 euler_xyz_rotation(Vec3 rotation);

/// The linear map A of a Mapping node applied to a direction (see the file comment). Refuses
/// non-finite inputs, a Location other than 0 for Point and Texture, and a zero Scale
/// component (a singular map).
Expected<Mat4> mapping_node_transform(const MappingNode &node);

/// What the scene passes for a world lit by an Environment Texture.
struct EnvironmentDesc {
    EnvironmentImage image;
    /// World direction → texture lookup vector. Only the 3×3 part is used; the translation
    /// must be 0 and the last row (0, 0, 0, 1). Chain Mapping nodes by multiplying (the node
    /// nearest the texture on the left). A Texture Coordinate's Object output with an object
    /// is that object's inverse matrix (Cycles also applies its translation to the direction,
    /// which only an object at the origin avoids).
    Mat4 world_to_texture;
    /// The Background node's Strength (>= 0) and a constant colour multiplier (>= 0), e.g. a
    /// Multiply node between the texture and the Background's Color.
    float strength = 1.0f;
    Rgb color{1.0f};
    /// Importance-map resolution, like Cycles' World > Settings > Sampling. 0 (Auto): the
    /// image's own but at least kMinAutoMapWidth × kMinAutoMapHeight, as Cycles' Auto for a
    /// world without a single Nishita sun (cycles@v3.4.0…v5.0.0 scene/light.cpp,
    /// device_update_background), and at most kMaxAutoMapWidth × kMaxAutoMapHeight: finer
    /// cells follow the bilinear radiance within a texel, which lowers the variance of a small
    /// HDRI's few-texel sun. Otherwise Manual: width
    /// map_width in [1, kMaxMapWidth] and height map_height in [1, kMaxMapHeight], or
    /// map_width / 2 (at least 1) when map_height is 0, as Cycles' Map Resolution.
    int map_width = 0;
    int map_height = 0;
};

/// A direction drawn from the environment.
struct EnvironmentSample {
    Vec3 wi;       ///< unit world direction towards the environment
    Rgb radiance;  ///< eval(wi)
    float pdf = 0; ///< per steradian; pdf(wi) returns the same value
};

/// An Environment Texture world, sampled by luminance. Immutable and thread-safe after create().
class EnvironmentMap {
  public:
    static constexpr int kMaxMapWidth = 8192;
    static constexpr int kMaxMapHeight = 4096;
    static constexpr int kMinAutoMapWidth = 4096;
    static constexpr int kMinAutoMapHeight = 2048;
    static constexpr int kMaxAutoMapWidth = kMaxMapWidth;
    static constexpr int kMaxAutoMapHeight = kMaxMapHeight;

    /// Validates and builds the importance map. Errors name the field: an empty image, a
    /// non-finite, translated or (nearly) singular world_to_texture, strength or colour
    /// negative or not finite, a radiance that overflows a float, a map resolution out of
    /// range.
    static Expected<EnvironmentMap> create(EnvironmentDesc desc);

    EnvironmentMap() = default;

    /// A direction from (u0, u1) ∈ [0, 1)², with density proportional to the map's cell
    /// weights (mean luminance) in texture space.
    EnvironmentSample sample(float u0, float u1) const;
    /// Density per steradian of sample() at the world direction wi (unit); 0 for NaN.
    float pdf(Vec3 wi) const;
    /// The radiance Cycles' Background returns for a ray leaving in direction wi.
    Rgb eval(Vec3 wi) const;

    /// True when the radiance is zero everywhere: there is nothing to sample (sample() then
    /// draws the uniform sphere, pdf 1/(4π) to float rounding, and eval() is black).
    bool black() const { return black_; }
    /// ∫ Y(L(ω)) dω over the sphere, Y the Rec.709 luminance, from the map's cells: exact for
    /// the bilinear radiance per cell up to the variation of sin θ inside a cell. A uniform
    /// world with the same integral gives the irradiance integral / 4 on any surface. For the
    /// light set's selection weight.
    double luminance_integral() const { return luminance_integral_; }

    int map_width() const { return image_.empty() ? 0 : columns_.count(); }
    int map_height() const { return image_.empty() ? 0 : int(z_edges_.size()) - 1; }
    int image_width() const { return image_.width(); }
    int image_height() const { return image_.height(); }
    /// The bytes this map holds (image and distributions).
    std::size_t memory_bytes() const;

  private:
    Status set_mapping(const Mat4 &world_to_texture);
    Status set_grid(int width, int height);
    Status set_distributions(const std::vector<float> &relative,
                             const std::vector<double> &row_integral, int image_width,
                             int image_height);

    struct Cell {
        int row = 0, column = 0;
    };
    Vec3 to_texture(Vec3 wi, float &length) const;
    Cell cell_of(Vec3 texture_dir) const;
    int row_of(float z) const;
    float cell_pdf(Cell c) const {
        return row_factor_[size_t(c.row)] * conditional_.pmf(c.row, c.column);
    }
    float pdf_with_cell(Vec3 wi, Cell &cell) const;
    Rgb texture_radiance(Vec3 texture_dir) const;

    EnvironmentImage image_;
    Rgb scale_{1.0f};       // color × strength
    float a_[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};      // world → texture
    float a_inv_[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // texture → world
    float abs_det_ = 1.0f;
    bool identity_ = true;  // A = I: no transform, no Jacobian
    UniformCells columns_;            // over u ∈ [0, 1]
    std::vector<float> z_edges_;      // H + 1 row edges in z, −1 … 1, strictly increasing
    std::vector<float> z_last_;       // the largest z of each row a sample may take
    DiscreteCdfs marginal_;           // 1 row over the H map rows
    DiscreteCdfs conditional_;        // H rows over the W map columns
    std::vector<float> row_factor_;   // marginal mass / ΔΩ_J per row
    double luminance_integral_ = 0;
    bool black_ = true;
};

}  // namespace hairis
