// Quadrature rules: the one Gauss–Legendre rule of the core, from Boost Math's tables.
#pragma once

#include <cstddef>
#include <vector>

namespace hairis {

/// Gauss–Legendre nodes (increasing) and weights on [−1, 1]; exact for polynomials of degree
/// 2n − 1.
struct GaussLegendre {
    /// Most nodes a rule can have.
    static constexpr int kMaxPoints = 32;

    std::vector<double> nodes;
    std::vector<double> weights;

    /// The n-point rule, n clamped to [1, kMaxPoints].
    static const GaussLegendre &rule(int n);

    /// Calls visit(x, w) at the rule's nodes mapped to [a, b], w including (b − a)/2.
    template <typename Visit>
    void for_each(double a, double b, Visit &&visit) const {
        const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
        for (std::size_t k = 0; k < nodes.size(); ++k) visit(mid + half * nodes[k], half * weights[k]);
    }
    /// ∫_a^b g(x) dx by the rule.
    template <typename G>
    double integrate(double a, double b, G &&g) const {
        double sum = 0;
        for_each(a, b, [&](double x, double w) { sum += w * g(x); });
        return sum;
    }
};

/// A composite Gauss–Legendre rule on [a, b]: `panels` equal panels of `points` nodes each.
struct QuadratureRule {
    std::vector<double> x;
    std::vector<double> w;
    static QuadratureRule composite(double a, double b, int panels, int points);
};

}  // namespace hairis
