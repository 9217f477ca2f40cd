// Test helper: integrals over the upper hemisphere (z > 0) of a unit-direction function, by a
// product Gauss–Legendre rule in (cos θ, φ) with composite panels, and over the sphere about a
// fiber along x. Peaked integrands (a GGX lobe of α ≥ 0.1) converge to 1e-4 relative with the
// default panels.
#pragma once

#include <cmath>

#include "core/math.h"
#include "core/quadrature.h"

namespace hairis::testing {

/// The unit direction at polar angle theta from +Z and azimuth phi from +X.
inline Vec3 polar_direction(double theta, double phi) {
    return {float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)),
            float(std::cos(theta))};
}

/// ∫_{z > 0} g(ω) dω with `cos_panels` × `phi_panels` panels of `points` nodes each.
template <typename G>
double integrate_hemisphere(const G &g, int cos_panels = 96, int phi_panels = 96, int points = 8) {
    const GaussLegendre &rule = GaussLegendre::rule(points);
    double sum = 0.0;
    for (int i = 0; i < cos_panels; ++i) {
        const double c0 = double(i) / cos_panels, c1 = double(i + 1) / cos_panels;
        rule.for_each(c0, c1, [&](double c, double wc) {
            const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
            for (int j = 0; j < phi_panels; ++j) {
                const double p0 = kTwoPi * j / phi_panels, p1 = kTwoPi * (j + 1) / phi_panels;
                rule.for_each(p0, p1, [&](double phi, double wp) {
                    const Vec3 w{float(s * std::cos(phi)), float(s * std::sin(phi)), float(c)};
                    sum += wc * wp * double(g(w));
                });
            }
        });
    }
    return sum;
}

/// ∫ g(ω) dω over the sphere, for a fiber along x: a product Gauss rule in (sin θ, φ) with
/// sin θ = ω.x, which follows a fiber lobe's longitudinal peak.
template <typename G>
double integrate_fiber_sphere(const G &g) {
    const QuadratureRule s = QuadratureRule::composite(-1.0, 1.0, 6, 6);
    const QuadratureRule phi = QuadratureRule::composite(-kPi, kPi, 8, 6);
    double sum = 0.0;
    for (std::size_t i = 0; i < s.x.size(); ++i)
        for (std::size_t j = 0; j < phi.x.size(); ++j) {
            const double c = std::sqrt(1.0 - s.x[i] * s.x[i]);
            const Vec3 wi{float(s.x[i]), float(c * std::cos(phi.x[j])), float(c * std::sin(phi.x[j]))};
            sum += s.w[i] * phi.w[j] * double(g(wi));
        }
    return sum;
}

}  // namespace hairis::testing
