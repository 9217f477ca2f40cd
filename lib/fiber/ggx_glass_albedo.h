// The directional albedo E of a rough GGX dielectric interface ("glass": reflection plus
// refraction), tabulated the way Cycles tabulates it for energy compensation
// (cycles_precompute's "ggx_glass_E" and "ggx_glass_inv_E", 16³ floats each).
//
// Definition (Cycles' convention: refraction carries no η² radiance factor): for roughness α,
// incidence cosine μ to the mean normal n and relative index η (far side / incident side),
//   E = ∫ D_w(h) [F(w·h) G2/G1 · 1(o_r·n > 0) + (1 − F(w·h)) G2/G1 · 1(o_t·n < 0)] dω_h,
// D_w the visible-normal density seen from w, o_r / o_t the reflected / refracted direction,
// G2/G1 = ggx::shadowing_ratio(α, w·n, o·n) and F the dielectric Fresnel (1 under total
// internal reflection). As in Cycles, α² ≤ 2e-10 counts as a smooth interface (E = 1) and a
// refraction with |η − 1| < 1e-4 as a specular one (weight 1).
//
// Grid (Cycles' parametrization): node (i, j, k), stored at index i·256 + j·16 + k, holds E at
// roughness coordinate r = clamp(k/15, 1e-4, 1) (α = r²), μ = clamp(j/15, 1e-4, 1) and Fresnel
// coordinate z = clamp(i/15, 1e-4, 0.99), η = (1 + z²)/(1 − z²) (the inverse table: 1/η), so
// that z = sqrt(|η − 1|/(η + 1)) for both tables. Values are clamped to [0, 1].
//
// We compute the tables ourselves by deterministic quadrature, node by node at first use
// (cheap next to a bake, as a fiber touches a few dozen nodes), so the tree holds no generated
// or copied data. Nodes are accurate to about 1e-3 absolute at worst (1e-4 typical), checked by
// the tests against an independent integral over outgoing directions; Cycles' committed
// table, made by Monte Carlo in June 2023, agrees with the exact integral to about 5e-4.
//
// That committed table predates the hemisphere test Cycles' sampler now applies to refracted
// directions: it counts a refraction that leaves on the incident side like any other. Rerun
// today, cycles_precompute would lower ggx_glass_inv_E by up to 0.9 at grazing μ; renders use
// the committed table, so this one follows it.
#pragma once

#include <array>
#include <atomic>

namespace hairis {

class GgxGlassAlbedo {
  public:
    static constexpr int kSize = 16;
    static constexpr int kNodes = kSize * kSize * kSize;
    using Table = std::array<float, kNodes>;

    /// The process-wide tables; each node is computed at its first use (thread-safe).
    static const GgxGlassAlbedo &tables();

    /// Cycles' lookup_table_read_3D at (x, y, z) = (sqrt α, μ, sqrt(|η − 1|/(η + 1))): each
    /// coordinate clamped to [0, 1], trilinear between the nodes at multiples of 1/15; the
    /// inverse table when η < 1.
    float lookup(float sqrt_alpha, float mu, float eta) const;
    /// 1 / lookup(): the energy-compensation factor of one Huang interface.
    float energy_scale(float sqrt_alpha, float mu, float eta) const {
        return 1.0f / lookup(sqrt_alpha, mu, eta);
    }

    /// Node (i, j, k) of the table for η > 1 (`inverse` false) or η < 1.
    float node(bool inverse, int i, int j, int k) const;
    /// The whole table (computes every node not computed yet).
    Table table(bool inverse) const;

    /// The parameters of node (i, j, k): roughness coordinate r, cosine μ, index η.
    static double node_roughness(int k);
    static double node_cosine(int j);
    static double node_ior(int i, bool inverse);

  private:
    GgxGlassAlbedo();
    // NaN until computed; a race computes the same value twice, harmlessly.
    mutable std::array<std::atomic<float>, 2 * kNodes> nodes_;
};

/// E(α, μ, η) by Gauss–Legendre rules over ggx::VisibleParametrization (`order` nodes in β), the
/// reflection and refraction branches weighted by F and 1 − F (no sampling of the branch).
/// The inner (ψ) integral is split where the reflection crosses the horizon and at the critical
/// angle, so the error falls quickly with `order`. Used for the table nodes and by tests.
double ggx_glass_directional_albedo(double alpha, double mu, double eta, int order = 48);

}  // namespace hairis
