// The isotropic GGX microfacet distribution as Cycles' bsdf_microfacet.h uses it: the normal
// distribution D, Smith's Λ and shadowing-masking G, Heitz 2018's visible-normal sampler
// (with Cycles' frame and disk mapping, so that a given (u1, u2) gives Cycles' microfacet),
// and a deterministic quadrature rule over the same visible-normal density.
//
// α is the GGX roughness (Cycles' alpha, the squared "sqrt roughness" of its tables). Cosines
// are taken to the microfacet's mean normal m (the mesonormal in the hair model); Λ and D
// depend on their square only, as in Cycles.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/math.h"
#include "core/vec3d.h"

namespace hairis::ggx {

/// D(m·h) = α² / (π ((1 − c²) + α² c²)²), c² clamped to 1. Inline: Huang's bake calls it per
/// path and direction.
inline double distribution(double alpha, double cos_mh) {
    const double a2 = alpha * alpha;
    const double c2 = std::min(cos_mh * cos_mh, 1.0);
    const double denominator = (1.0 - c2) + a2 * c2;
    return a2 / (kPi * denominator * denominator);
}
/// Smith's Λ(c) = (sqrt(1 + α² (1/c² − 1)) − 1) / 2 (0 at c² ≥ 1; +inf at c = 0).
inline double smith_lambda(double alpha, double cos_m) {
    const double c2 = cos_m * cos_m;
    if (c2 >= 1.0) return 0.0;
    const double tan2 = std::max(1.0 / c2 - 1.0, 0.0);  // +inf at c = 0
    return 0.5 * (std::sqrt(1.0 + alpha * alpha * tan2) - 1.0);
}
/// G1 = 1 / (1 + Λ(c)).
double shadowing_g1(double alpha, double cos_m);
/// Height-correlated G2 = 1 / (1 + Λ(c1) + Λ(c2)).
double shadowing_g2(double alpha, double cos_m1, double cos_m2);
/// G2 / G1(c1) = (1 + Λ(c1)) / (1 + Λ(c1) + Λ(c2)): the weight of a visible-normal sample
/// seen from direction 1 and leaving in direction 2 (Cycles' bsdf_Go).
double shadowing_ratio(double alpha, double cos_m1, double cos_m2);

/// The visible-normal density of h seen from w about mean normal m, per unit solid angle:
/// G1(w·m) max(0, w·h) D(m·h) / (w·m). Zero when w·m <= 0 or m·h <= 0.
double visible_density(double alpha, Vec3d w, Vec3d m, Vec3d h);

/// Cycles' make_orthonormals: for a unit n, a = normalize((1, 1, 1) × n) (or
/// (n_z − n_y, n_x + n_z, −n_y − n_x) when n's three components are equal) and b = n × a.
void orthonormal_basis(Vec3d n, Vec3d &a, Vec3d &b);

/// One visible normal seen from w (unit, w·m > 0) about m, from u1, u2 in [0, 1]: Cycles'
/// sample_wh/microfacet_ggx_sample_vndf (stretch, Shirley–Chiu concentric disk, warp, lift,
/// unstretch) in the frame orthonormal_basis(m).
Vec3d sample_visible(double alpha, Vec3d w, Vec3d m, double u1, double u2);

/// Heitz's visible normals as a smooth function of two angles. The projected hemisphere of
/// the stretched configuration is the region t = (sin β, cos β sin ψ), β ∈ [−π/2, π/2],
/// ψ ∈ [psi_min, π/2] with psi_min = −asin w'_z (w' the stretched w), on which the visible
/// normals are uniform: D_w(h) dω_h = cos²β cos ψ dβ dψ / area, area = π(1 + w'_z)/2.
/// The same region is what sample_visible draws from when w is below the mean surface
/// (w·m < 0, psi_min > 0): normals with h·m > 0 and w·h > 0, density ∝ (w·h) D(h); so this
/// parametrization is that sampler's density for every w but w = −m.
class VisibleParametrization {
  public:
    VisibleParametrization(double alpha, Vec3d w, Vec3d m);
    /// False only when w = −m (no normal faces w).
    bool valid() const { return valid_; }
    double psi_min() const { return psi_min_; }
    /// The normal h(β, ψ) in world coordinates.
    Vec3d normal(double beta, double psi) const { return normal(std::sin(beta), std::cos(beta), psi); }
    /// h(β, ψ) from sin β and cos β, for many ψ on one line of β.
    Vec3d normal(double sin_beta, double cos_beta, double psi) const;
    /// The density of (β, ψ): cos²β cos ψ / area (integrates to 1 over the region).
    double density(double beta, double psi) const;

  private:
    bool valid_ = false;
    double alpha_ = 0, psi_min_ = 0, area_ = 1;
    Vec3d a_, b_, m_;      // m's frame (orthonormal_basis)
    Vec3d w_, t1_, t2_;    // stretched view and disk basis, in m's frame
};

/// A node of a quadrature rule over the visible normals: ∫ g(h) D_w(h) dh ≈ Σ weight·g(h).
struct VisibleNode {
    Vec3d h;
    double weight = 0;
};

/// The product Gauss–Legendre rule of beta_order × psi_order nodes (each at most
/// GaussLegendre::kMaxPoints) on VisibleParametrization: weights sum to 1; smooth g converge
/// spectrally. No nodes when w = −m.
std::vector<VisibleNode> visible_rule(double alpha, Vec3d w, Vec3d m, int beta_order,
                                      int psi_order);

/// visible_rule with each ψ line split where any of `events(h)` (a std::array of continuous
/// functions of the normal) changes sign, so that jumps and kinks of the integrand at those
/// events (visibility tests, the critical angle) fall between Gauss panels; `scan` points per
/// line bracket the roots, the Illinois variant of regula falsi refines them to 1e-12.
template <typename Events>
std::vector<VisibleNode> visible_rule_split(double alpha, Vec3d w, Vec3d m, int beta_order, int psi_order,
                                            int scan, const Events &events);

/// Mirror reflection of a propagation direction d about unit h: d − 2(d·h)h.
inline Vec3d reflect(Vec3d d, Vec3d h) { return d - 2.0 * dot(d, h) * h; }

/// Refraction of w (pointing away from the surface on h's side, w·h > 0) through a microfacet
/// h into a medium of relative index eta (far side / near side): the propagation direction
/// (c/eta + cos_t) h − w/eta with cos_t = −sqrt(eta² − 1 + c²)/eta, c = w·h.
/// Returns false (and leaves `out` unchanged) under total internal reflection.
bool refract(Vec3d w, Vec3d h, double eta, Vec3d &out);

}  // namespace hairis::ggx

#include "fiber/ggx_rule_split.h"
