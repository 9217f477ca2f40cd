// A mesh material as a tree of Blender shader nodes, turned into the lobes of a SurfaceBsdf at
// each shading point the way Cycles' SVM turns the same nodes into closures
// (kernel/svm/closure.h, svm_node_closure_bsdf; Cycles 3.4 and Cycles 4.5, which 5.0 matches
// for everything here). Each node says which Cycles it follows (CyclesVersion).
//
// Nodes and what they become (W = the weight reaching the node through Mix and Add):
//  - Diffuse BSDF: Lambert (roughness 0) or Oren–Nayar (3.4's, or 4.3+'s energy-preserving
//    one with the saturated colour), weight W·Color.
//  - Glossy BSDF: GGX with F = 1, α = roughness², weight W·Color; 3.4 with the separable Smith
//    G, 4.x with the height-correlated one. Multiscatter GGX: 4.x's energy compensation
//    (1/E and the colour's darkening, ggx_albedo.h); Cycles 3.4's random-walk multiscatter GGX
//    is approximated by that compensation.
//  - Emission: radiance Color × Strength × W (constant over the material: emission()).
//  - Mix Shader (factor clamped to [0, 1]) and Add Shader: weights (1 − f, f) and (1, 1).
//  - Principled BSDF, 3.4 (svm_node_closure_bsdf, CLOSURE_BSDF_PRINCIPLED_ID):
//      diffuse  = (1 − metallic) base colour, Burley's diffuse with the roughness
//                 (subsurface: the colour mix(base, Subsurface Color, subsurface) — Cycles'
//                 BSSRDF is approximated by that diffuse lobe);
//      sheen    = sheen × mix(1, tint colour, Sheen Tint) × (1 − metallic);
//      specular = GGX, α = roughness², F interpolated from cspec0 =
//                 mix(0.08 specular mix(1, tint colour, Specular Tint), base, metallic) with
//                 η = 2/(1 − sqrt(0.08 specular)) − 1 (single-scatter "GGX"; Multiscatter GGX
//                 is approximated as for the Glossy BSDF);
//      clearcoat= GTR1 with α = Clearcoat Roughness², G at α = 0.25, F from cspec0 0.04 and
//                 η 1.5, times clearcoat / 4, sampled as Cycles 3.4 samples it (surface_bsdf.h:
//                 MicrofacetSampling::Cycles34Clearcoat), with Cycles' selection weights:
//                 |mean(weight)| × (for its microfacets) the mean Fresnel at ω_o·n, and at the
//                 camera hit at least 1/8 of their sum (its defensive sampling).
//  - Principled BSDF, 4.x (the layered model): coat (GGX dielectric at Coat IOR with energy
//    compensation; the layers below lose its albedo estimate and take Coat Tint along the
//    refracted path), metallic (F82-tint with f0 = base, F82 = Specular Tint), specular
//    (generalized Schlick between f0 = F0(η') × Specular Tint and 1, η' from IOR and IOR
//    Level; the layers below lose its albedo estimate), diffuse (Lambert or Oren–Nayar by
//    Diffuse Roughness) with weight (1 − subsurface) base + subsurface × min(base, 1)
//    (Cycles' BSSRDF approximated by that diffuse), emission not dimmed by the coat.
// Everything else of these nodes is up to the caller to refuse or warn about: transmission,
// anisotropy, normal and tangent inputs, alpha, 4.x sheen and thin film are not modelled.
//
// Normals: Cycles 3.4 lifts every BSDF's normal so that the mirror reflection of ω_o stays
// above the geometric surface (ensure_valid_reflection); 4.x uses the shading normal as is.
// Roughness below √(3.2e-4) (α² ≤ 1e-7, Cycles 3.4's mirror threshold) is raised to it: hairis
// has no singular lobes, so a mirror renders as a very sharp GGX.
#pragma once

#include <memory>
#include <optional>
#include <variant>
#include <vector>

#include "core/expected.h"
#include "core/math.h"
#include "render/lights.h"
#include "render/surface_bsdf.h"
#include "render/texture.h"

namespace hairis {

/// A colour input: a constant, or an Image Texture on the UV map.
struct ColorInput {
    Rgb value{0.8f};
    std::shared_ptr<const ImageTexture> texture;  ///< replaces value when set
    Rgb at(float u, float v) const { return texture ? texture->lookup(u, v) : value; }
};

struct PrincipledBsdfNode {
    CyclesVersion cycles = CyclesVersion::V3_4;
    bool multiscatter = false;      ///< Distribution Multiscatter GGX (4.x default)
    ColorInput base_color;
    float metallic = 0.0f;
    float roughness = 0.5f;
    float ior = 1.45f;
    float specular = 0.5f;          ///< 3.4 Specular; 4.x Specular IOR Level
    float specular_tint = 0.0f;     ///< 3.4
    Rgb specular_tint_color{1.0f};  ///< 4.x
    float subsurface = 0.0f;        ///< 3.4 Subsurface; 4.x Subsurface Weight
    Rgb subsurface_color{0.8f};     ///< 3.4
    float sheen = 0.0f;             ///< 3.4
    float sheen_tint = 0.5f;        ///< 3.4
    float coat = 0.0f;              ///< 3.4 Clearcoat; 4.x Coat Weight
    float coat_roughness = 0.03f;
    float coat_ior = 1.5f;          ///< 4.x
    Rgb coat_tint{1.0f};            ///< 4.x
    float diffuse_roughness = 0.0f; ///< 4.x
    Rgb emission{0.0f};             ///< Emission (Color) × Emission Strength
};

struct DiffuseBsdfNode {
    CyclesVersion cycles = CyclesVersion::V3_4;
    ColorInput color;
    float roughness = 0.0f;
};

struct GlossyBsdfNode {
    CyclesVersion cycles = CyclesVersion::V3_4;
    bool multiscatter = false;
    ColorInput color;
    float roughness = 0.5f;
};

struct EmissionNode {
    Rgb color{1.0f};
    float strength = 1.0f;
};

/// Mix Shader: (1 − factor) first + factor second. Children are node indices.
struct MixShaderNode {
    float factor = 0.5f;
    int first = -1, second = -1;
};

struct AddShaderNode {
    int first = -1, second = -1;
};

using SurfaceNode = std::variant<PrincipledBsdfNode, DiffuseBsdfNode, GlossyBsdfNode,
                                 EmissionNode, MixShaderNode, AddShaderNode>;

/// Where a material is shaded: ω_o, the unit shading normal n and geometric normal ng (both on
/// ω_o's side of the surface, as Cycles flips them for back faces) and the UV coordinates.
struct SurfaceShadingPoint {
    Vec3 wo;
    Vec3 n;
    Vec3 ng;
    float u = 0.0f, v = 0.0f;
    /// The camera ray's hit (Cycles 3.4 samples its closures defensively there).
    bool camera_hit = false;
};

/// Cycles 3.4's ensure_valid_reflection: n itself when the mirror reflection of ω_o about it
/// makes at least min(0.9 ω_o·ng, 0.01) with ng, else the normal between n and ng that
/// reaches that angle exactly.
Vec3 valid_reflection_normal(Vec3 ng, Vec3 wo, Vec3 n);

/// A validated tree of nodes; the root is the last node.
class SurfaceMaterial {
  public:
    /// Refuses an empty tree, a child index outside [0, parent) (children precede their
    /// parents; a node may feed several), BSDF nodes of different Cycles versions, non-finite
    /// or negative inputs (each named), and trees whose lobe count could exceed
    /// SurfaceBsdf::kMaxLobes.
    static Expected<SurfaceMaterial> create(std::vector<SurfaceNode> nodes);

    const std::vector<SurfaceNode> &nodes() const { return nodes_; }
    /// The emitted radiance (the same on both sides and in every direction).
    Rgb emission() const { return emission_; }
    /// The Cycles version of its BSDF nodes.
    CyclesVersion cycles() const { return cycles_; }
    /// The most lobes prepare() can produce.
    int max_lobes() const { return max_lobes_; }

    /// The lobes at a shading point.
    SurfaceBsdf prepare(const SurfaceShadingPoint &p) const;

    /// A Mix Shader of two materials ((1 − factor) a + factor b; factor finite), or an Add
    /// Shader when factor is empty: the trees of a and b under a new root.
    static Expected<SurfaceMaterial> combine(const SurfaceMaterial &a, const SurfaceMaterial &b,
                                             std::optional<float> factor);

  private:
    std::vector<SurfaceNode> nodes_;
    Rgb emission_{0.0f};
    CyclesVersion cycles_ = CyclesVersion::V3_4;
    int max_lobes_ = 0;
};

}  // namespace hairis
