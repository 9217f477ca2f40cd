// The template of ggx::visible_rule_split (included by ggx.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/quadrature.h"

namespace hairis::ggx {

template <typename Events>
std::vector<VisibleNode> visible_rule_split(double alpha, Vec3d w, Vec3d m, int beta_order, int psi_order,
                                            int scan, const Events &events) {
    std::vector<VisibleNode> nodes;
    const VisibleParametrization p(alpha, w, m);
    if (!p.valid()) return nodes;
    const GaussLegendre &rule_beta = GaussLegendre::rule(beta_order);
    const GaussLegendre &rule_psi = GaussLegendre::rule(psi_order);
    const double lo = p.psi_min(), hi = 0.5 * kPi;
    std::vector<double> breaks;
    using Values = decltype(events(Vec3d{}));
    std::vector<Values> values(std::size_t(scan) + 1);
    for (std::size_t i = 0; i < rule_beta.nodes.size(); ++i) {
        const double beta = 0.5 * kPi * rule_beta.nodes[i];
        const double weight_beta = rule_beta.weights[i] * 0.5 * kPi;
        breaks.assign({lo, hi});
        for (int s = 0; s <= scan; ++s) values[std::size_t(s)] = events(p.normal(beta, lo + (hi - lo) * s / scan));
        for (std::size_t e = 0; e < values[0].size(); ++e) {
            for (int s = 0; s < scan; ++s) {
                const double e0 = values[std::size_t(s)][e], e1 = values[std::size_t(s) + 1][e];
                if ((e0 < 0.0) == (e1 < 0.0)) continue;
                double a = lo + (hi - lo) * s / scan, b = lo + (hi - lo) * (s + 1) / scan;
                const bool negative_at_a = e0 < 0.0;
                for (int it = 0; it < 40 && b - a > 1e-12; ++it) {
                    const double mid = 0.5 * (a + b);
                    if ((events(p.normal(beta, mid))[e] < 0.0) == negative_at_a) a = mid; else b = mid;
                }
                breaks.push_back(0.5 * (a + b));
            }
        }
        std::sort(breaks.begin(), breaks.end());
        for (std::size_t b = 0; b + 1 < breaks.size(); ++b) {
            const double half = 0.5 * (breaks[b + 1] - breaks[b]), mid = 0.5 * (breaks[b + 1] + breaks[b]);
            if (!(half > 1e-12)) continue;
            for (std::size_t j = 0; j < rule_psi.nodes.size(); ++j) {
                const double psi = mid + half * rule_psi.nodes[j];
                nodes.push_back({p.normal(beta, psi), weight_beta * rule_psi.weights[j] * half * p.density(beta, psi)});
            }
        }
    }
    return nodes;
}

}  // namespace hairis::ggx
