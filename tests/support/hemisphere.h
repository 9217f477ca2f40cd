// Test helper: integrals over the upper hemisphere (z > 0) of a unit-direction function, by a
// product Gauss–Legendre rule in (cos θ, φ) with composite panels. Peaked integrands (a GGX
// lobe of α ≥ 0.1) converge to 1e-4 relative with the default panels.
#pragma once

#include <cmath>

#include "core/math.h"
#include "core/quadrature.h"

namespace hairis::testing {

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

}  // namespace hairis::testing
