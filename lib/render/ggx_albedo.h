// The GGX reflection tables Cycles 4.0+ looks up for its microfacet closures
// (cycles_precompute's ggx_E, ggx_Eavg, ggx_gen_schlick_ior_s and ggx_gen_schlick_s), computed
// here by our own deterministic quadrature, node by node at first use.
//
// Definitions, for roughness coordinate r (α = r²), view cosine μ to the normal, the visible-
// normal density D_w(h) seen from w, o = 2(w·h)h − w and the height-correlated
// G2/G1 = (1 + Λ(μ)) / (1 + Λ(μ) + Λ(o.z)); a draw whose o falls below the horizon counts 0:
//   E(r, μ)      = ∫ D_w(h) 1(o.z > 0) G2/G1 dh           (the single-scattering albedo)
//   E_avg(r)     = ∫₀¹ 2μ E(r, μ) dμ
//   s_ior(r,μ,η) = ∫ D_w(h) 1(o.z > 0) s(w·h) dh,  s = clamp((F(c, η) − F0)/(1 − F0), 0, 1)
//                  with F the dielectric Fresnel and F0 = F(1, η)
//   s_exp(r,μ,p) = ∫ D_w(h) 1(o.z > 0) (1 − w·h)^p dh
// (the last two are the factors between F0 and F90 of Cycles' generalized Schlick Fresnel,
// averaged the way its precompute averages them: per visible normal, without G).
//
// Grids, as Cycles' (node values clamped to [0, 1]):
//   E      32 × 32: r = clamp(x/31, 1e-4, 1), μ = clamp(y/31, 1e-4, 1), stored y·32 + x;
//   E_avg  32:      r = clamp(x/31, 1e-4, 1);
//   s_ior  16³:     r = clamp(x/15, ...), μ = clamp(y/15, ...), z = clamp(k/15, 1e-4, 0.99),
//                   η = (1 + z²)/(1 − z²), so that z = sqrt(|η − 1|/(η + 1));
//   s_exp  16³:     the same r, μ, and p = 5(1 − z)/z.
// Lookups are Cycles' lookup_table_read_2D/3D: each coordinate clamped to [0, 1], multilinear
// between the nodes.
#pragma once

#include <array>
#include <atomic>

namespace hairis {

/// α² at or below which Cycles treats a microfacet lobe as a mirror (BSDF_ROUGHNESS_SQ_THRESH).
inline constexpr float kMirrorAlphaSquared = 2e-10f;

class GgxAlbedoTables {
  public:
    static constexpr int kSizeE = 32;
    static constexpr int kSizeS = 16;

    /// The process-wide tables (nodes computed at first use, thread-safe).
    static const GgxAlbedoTables &tables();

    /// ggx_E at (r, μ) = (sqrt α, cos θ).
    float e(float rough, float mu) const;
    /// ggx_Eavg at r.
    float e_avg(float rough) const;
    /// ggx_gen_schlick_ior_s at (r, μ, z), z = sqrt(|η − 1|/(η + 1)).
    float s_ior(float rough, float mu, float z) const;
    /// ggx_gen_schlick_s at (r, μ, z), z = 1/(0.2 p + 1) for exponent p.
    float s_exponent(float rough, float mu, float z) const;

    /// Nodes (x along r, y along μ, k along z).
    float e_node(int x, int y) const;
    float e_avg_node(int x) const;
    float s_ior_node(int x, int y, int k) const;
    float s_exponent_node(int x, int y, int k) const;

    /// Parameters of the nodes.
    static double e_roughness(int x);
    static double s_roughness(int x);
    static double e_cosine(int y);
    static double s_cosine(int y);
    static double s_ior_of(int k);
    static double s_exponent_of(int k);

  private:
    GgxAlbedoTables();
    // NaN until computed; a race computes the same value twice, harmlessly.
    mutable std::array<std::atomic<float>, kSizeE * kSizeE> e_;
    mutable std::array<std::atomic<float>, kSizeE> e_avg_;
    mutable std::array<std::atomic<float>, kSizeS * kSizeS * kSizeS> s_ior_, s_exponent_;
};

/// E(α, μ) by Gauss–Legendre rules over the visible normals, split where o crosses the horizon.
double ggx_reflection_albedo(double alpha, double mu);
/// E_avg(α) = ∫₀¹ 2μ E(α, μ) dμ.
double ggx_reflection_albedo_average(double alpha);
/// s_ior(α, μ, η) as defined above.
double ggx_fresnel_factor_ior(double alpha, double mu, double eta);
/// s_exp(α, μ, p) as defined above.
double ggx_fresnel_factor_exponent(double alpha, double mu, double exponent);

}  // namespace hairis
