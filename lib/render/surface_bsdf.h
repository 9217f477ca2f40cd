// The BSDF of a mesh surface at one shading point: a weighted sum of reflection lobes
// ("closures", as Cycles builds them from a material's nodes), evaluated and sampled as one.
//
// Frame: lobes live in the local frame (a, b, n) of the shading normal n (orthonormal_basis of
// lights.h), with ω_o (towards the viewer) and ω_i (towards the light) pointing away from the
// surface. ng is the geometric normal on ω_o's side.
//
// Evaluation: f(ω_i)·|cos θ_i| = Σ weight_k · lobe_k(ω_o, ω_i), each lobe by its own rule
// (see SurfaceLobeKind). Like Cycles, every lobe is a reflection: 0 for ω_i below n; the
// microfacet lobes of Cycles 4.x are also 0 for ω_i below ng.
//
// Sampling: one lobe k with probability p_k = select_k / Σ select (u2), then a direction from
// it (u0, u1): the cosine-weighted hemisphere for the diffuse lobes, visible normals for GGX,
// exact normals for GTR1 (or GGX visible normals, below). A direction below n or below ng is no
// sample. The density of what sample() returns is therefore exactly
//   Q(ω_i) = 1(ω_i·ng > 0) Σ_k p_k q_k(ω_i),   q_k = 0 below n,
// the pdf eval() and sample() report (one-sample multiple importance sampling over lobes:
// every lobe's value counts whichever drew the direction).
//
// The sample's weight is f·|cos θ_i| / P with P the same mixture of each lobe's *reported*
// density r_k. For every lobe r_k = q_k, so P = Q and the weight estimates ∫ f cos L without
// bias — except Cycles 3.4's clearcoat (MicrofacetSampling::Cycles34Clearcoat), which Cycles
// draws from GGX visible normals of the clearcoat's α but reports with its GTR1 formula; its
// BSDF-sampled light then converges to ∫ f cos L · Q/P, not to ∫ f cos L, and, Q/P depending on
// the selection probabilities, so does every lobe's share of it. hairis reproduces that on
// purpose, with Cycles' selection weights (defend_selection for the camera hit), because it is
// what Cycles 3.4 renders.
#pragma once

#include <array>
#include <cstdint>

#include "core/math.h"

namespace hairis {

/// How a lobe evaluates, with ω_o, ω_i local and c_i = ω_i.z, c_o = ω_o.z.
enum class SurfaceLobeKind : std::uint8_t {
    /// c_i / π.
    Lambert,
    /// Cycles 3.4's Principled diffuse (Burley 2012 with its retro-reflection, roughness R):
    /// c_i/π · ((1 − F_o/2)(1 − F_i/2) + RR (F_i + F_o + F_i F_o (RR − 1))), F = (1 − c)^5,
    /// RR = R (ω_i·ω_o + 1).
    PrincipledDiffuse,
    /// Cycles 3.4's Oren–Nayar (σ = roughness): c_i (A + B t), A = 1/(π + (3π − 4)σ/6),
    /// B = σA, t = ω_i·ω_o − c_i c_o divided by max(c_i, c_o) where positive.
    OrenNayar34,
    /// Cycles 4.3+'s energy-preserving Oren–Nayar (Fujii's improved model with OpenPBR's
    /// multiple-scattering term): c_i (A + B t + M (1 − E(c_i))), A = 1/(π + σ(π/2 − 2/3)),
    /// B = σA, E(c) = Aπ + B G(c), M = multiscatter (set up from the colour and ω_o).
    OrenNayar,
    /// Cycles 3.4's Principled sheen: (1 − ω_i·h)^5 c_i (no 1/π), h = normalize(ω_i + ω_o).
    Sheen34,
    /// A microfacet reflection: F(ω_i·h) D(h) G / (4 c_o) × energy_scale.
    Microfacet,
};

enum class MicrofacetDistribution : std::uint8_t { Ggx, Gtr1 };

/// Smith's shadowing-masking: G1(c_o) G1(c_i) (Cycles 3.4) or 1/(1 + Λ(c_o) + Λ(c_i)) (4.x).
enum class MicrofacetShadowing : std::uint8_t { Separable, Correlated };

/// The Fresnel factor F(c), c = ω_i·h.
enum class MicrofacetFresnel : std::uint8_t {
    /// 1 (the colour is in the weight).
    One,
    /// Cycles 3.4's interpolate_fresnel_color: f0 (1 − s) + s with
    /// s = (F(c, η) − F(1, η)) / (1 − F(1, η)), times fresnel_scale.
    Interpolated34,
    /// Cycles 4.x's generalized Schlick with the real curve: f0 + (1 − f0) s,
    /// s = clamp((F(c, η) − F0(η)) / (1 − F0(η)), 0, 1), F0(η) = ((η − 1)/(η + 1))².
    SchlickIor,
    /// Cycles 4.x's F82-tint metal: clamp(f0 + (1 − f0) m⁵ − b c m⁶, 0, 1), m = 1 − c.
    F82Tint,
    /// The dielectric F(c, η).
    Dielectric,
};

/// How a microfacet lobe is drawn and which density it reports for the sample weight.
enum class MicrofacetSampling : std::uint8_t {
    /// GGX from its visible normals, GTR1 from its normals; the reported density is the true one.
    Exact,
    /// Cycles 3.4's clearcoat (a GTR1 lobe): drawn from GGX visible normals of the same α
    /// (density G1_GGX(c_o) D_GGX(h) / (4 c_o)), reported as G1(shadowing α², c_o) D_GTR1(h) /
    /// (4 c_o) (bsdf_microfacet_ggx_sample and _eval_reflect of Cycles 3.4).
    Cycles34Clearcoat,
};

/// One lobe: its kind, its closure weight and the parameters its kind reads.
struct SurfaceLobe {
    SurfaceLobeKind kind = SurfaceLobeKind::Lambert;
    Rgb weight{0.0f};
    /// Relative probability of sampling this lobe (>= 0; 0: never drawn from, still evaluated).
    float select = 0.0f;
    /// PrincipledDiffuse's roughness; the Oren–Nayar σ.
    float roughness = 0.0f;
    /// OrenNayar: its multiple-scattering colour M.
    Rgb multiscatter{0.0f};

    // Microfacet lobes.
    MicrofacetDistribution distribution = MicrofacetDistribution::Ggx;
    MicrofacetShadowing shadowing = MicrofacetShadowing::Correlated;
    MicrofacetFresnel fresnel = MicrofacetFresnel::One;
    /// The distribution's α (GGX: roughness²; GTR1: its own α).
    float alpha = 0.5f;
    /// α² of the shadowing term (α² except for Cycles 3.4's clearcoat, 0.0625).
    float shadowing_alpha2 = 0.25f;
    /// Reflectance at normal incidence (Interpolated34's cspec0; SchlickIor's and F82Tint's f0).
    Rgb f0{0.0f};
    /// F82Tint's b.
    Rgb f82_b{0.0f};
    float ior = 1.5f;
    float fresnel_scale = 1.0f;
    float energy_scale = 1.0f;
    /// Cycles 4.x: also 0 for ω_i below the geometric normal.
    bool below_ng_is_zero = false;
    MicrofacetSampling sampling = MicrofacetSampling::Exact;
};

/// f·|cos θ_i| of one lobe (without its weight), the density with which it samples ω_i and
/// (when `reported` is not null) the density it reports for the sample weight.
Rgb eval_lobe(const SurfaceLobe &lobe, Vec3 wo, Vec3 wi, float &pdf, float *reported = nullptr);
/// Cycles' bsdf_albedo of one lobe seen from ω_o (local), per unit weight, what its denoising
/// albedo pass sums: 1 for the diffuse lobes, the Fresnel factor at ω_o·n for microfacet lobes
/// (Cycles' smooth-surface estimate, which its tables refine with roughness for 4.x Principled).
Rgb lobe_denoising_albedo(const SurfaceLobe &lobe, Vec3 wo);
/// Cycles' denoising rule for a "specular" closure: a microfacet lobe with α_x α_y <= 0.075²,
/// through which the denoising passes look on to the next hit.
bool lobe_is_specular(const SurfaceLobe &lobe);
/// A direction drawn from one lobe with u0, u1; false when there is none (below n).
bool sample_lobe(const SurfaceLobe &lobe, Vec3 wo, float u0, float u1, Vec3 &wi);

/// The lobes at one point and how they are sampled (see the file comment).
class SurfaceBsdf {
  public:
    static constexpr int kMaxLobes = 16;

    SurfaceBsdf() = default;
    /// The shading frame: unit shading normal n, unit geometric normal ng and ω_o, world space.
    SurfaceBsdf(Vec3 n, Vec3 ng, Vec3 wo);

    /// Adds a lobe with a non-zero weight (ignored otherwise); false when kMaxLobes are taken.
    bool add(const SurfaceLobe &lobe);

    int lobe_count() const { return count_; }
    const SurfaceLobe &lobe(int i) const { return lobes_[std::size_t(i)]; }
    /// True when nothing can be sampled (no lobe with a selection weight).
    bool black() const { return !(select_total_ > 0.0f); }
    /// Cycles 3.4's defensive sampling at the camera hit: every sampled lobe's selection
    /// weight raised to at least `share` of their sum (taken before raising).
    void defend_selection(float share);

    /// The shading normal of the frame (world space).
    Vec3 normal() const { return n_; }
    /// ω_o and directions in the local frame.
    Vec3 local_wo() const { return wo_; }
    Vec3 to_local(Vec3 w) const { return {dot(w, a_), dot(w, b_), dot(w, n_)}; }
    Vec3 to_world(Vec3 l) const { return a_ * l.x + b_ * l.y + n_ * l.z; }

    /// f·|cos θ_i| for world ω_i, and Q(ω_i) (file comment); `reported` (may be null)
    /// receives P(ω_i).
    Rgb eval(Vec3 wi, float &pdf, float *reported = nullptr) const;
    /// Draws ω_i (world) with density pdf = Q(ω_i); weight = f·|cos θ_i| / P(ω_i). False
    /// when there is no sample. `glossy` (may be null) says whether the lobe drawn from is a
    /// microfacet one (Cycles' glossy bounce) or a diffuse one; `reported_pdf` (may be null)
    /// receives P(ω_i), the density Cycles records for the bounce.
    bool sample(float u0, float u1, float u2, Vec3 &wi, Rgb &weight, float &pdf,
                bool *glossy = nullptr, float *reported_pdf = nullptr) const;
    /// Cycles' bsdf_blur of the microfacet closures (Filter Glossy): each lobe's α raised to
    /// `roughness` where below it, with the shadowing's α² where that follows α.
    void blur(float roughness);

  private:
    Rgb eval_local(Vec3 wi, float ng_cos, float &pdf, float *reported) const;

    std::array<SurfaceLobe, kMaxLobes> lobes_{};
    int count_ = 0;
    float select_total_ = 0.0f;
    Vec3 n_{0, 0, 1}, a_{1, 0, 0}, b_{0, 1, 0}, ng_{0, 0, 1};
    Vec3 wo_{0, 0, 1};  // local
};

}  // namespace hairis
