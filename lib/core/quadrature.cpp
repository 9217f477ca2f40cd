#include "core/quadrature.h"

#include <boost/math/quadrature/gauss.hpp>

#include <algorithm>
#include <array>
#include <utility>

namespace hairis {

namespace {

// Boost keeps the non-negative half of each rule (zero first for odd n).
template <int N>
GaussLegendre from_boost() {
    using Rule = boost::math::quadrature::gauss<double, N>;
    const auto &x = Rule::abscissa();
    const auto &w = Rule::weights();
    GaussLegendre r;
    for (std::size_t k = x.size(); k-- > 0;) {
        if (x[k] == 0.0) continue;
        r.nodes.push_back(-x[k]);
        r.weights.push_back(w[k]);
    }
    for (std::size_t k = 0; k < x.size(); ++k) {
        r.nodes.push_back(x[k]);
        r.weights.push_back(w[k]);
    }
    return r;
}

template <std::size_t... I>
std::array<GaussLegendre, sizeof...(I)> all_rules(std::index_sequence<I...>) {
    return {from_boost<int(I) + 1>()...};
}

}  // namespace

const GaussLegendre &GaussLegendre::rule(int n) {
    static const std::array<GaussLegendre, kMaxPoints> rules =
        all_rules(std::make_index_sequence<kMaxPoints>{});
    return rules[std::size_t(std::clamp(n, 1, kMaxPoints) - 1)];
}

QuadratureRule QuadratureRule::composite(double a, double b, int panels, int points) {
    const GaussLegendre &gl = GaussLegendre::rule(points);
    panels = std::max(panels, 1);
    QuadratureRule q;
    const double h = (b - a) / panels;
    for (int k = 0; k < panels; ++k)
        gl.for_each(a + k * h, a + (k + 1) * h, [&](double x, double w) {
            q.x.push_back(x);
            q.w.push_back(w);
        });
    return q;
}

}  // namespace hairis
