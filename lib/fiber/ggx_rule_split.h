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
        const double sin_beta = std::sin(beta), cos_beta = std::cos(beta);
        const double weight_beta = rule_beta.weights[i] * 0.5 * kPi;
        breaks.assign({lo, hi});
        for (int s = 0; s <= scan; ++s)
            values[std::size_t(s)] = events(p.normal(sin_beta, cos_beta, lo + (hi - lo) * s / scan));
        for (std::size_t e = 0; e < values[0].size(); ++e) {
            for (int s = 0; s < scan; ++s) {
                double fa = values[std::size_t(s)][e], fb = values[std::size_t(s) + 1][e];
                if ((fa < 0.0) == (fb < 0.0)) continue;
                double a = lo + (hi - lo) * s / scan, b = lo + (hi - lo) * (s + 1) / scan;
                const bool negative_at_a = fa < 0.0;
                // Illinois: the secant point of the bracket, with the value kept at an end that
                // stays twice in a row halved so that both ends close in; a secant point
                // outside the open bracket falls back to its midpoint.
                int kept = 0;  // −1: a moved last, +1: b moved last
                for (int it = 0; it < 100 && b - a > 1e-12; ++it) {
                    double c = (fa * b - fb * a) / (fa - fb);
                    if (!(c > a && c < b)) c = 0.5 * (a + b);
                    const double fc = events(p.normal(sin_beta, cos_beta, c))[e];
                    if ((fc < 0.0) == negative_at_a) {
                        a = c;
                        fa = fc;
                        if (kept == -1) fb *= 0.5;
                        kept = -1;
                    } else {
                        b = c;
                        fb = fc;
                        if (kept == 1) fa *= 0.5;
                        kept = 1;
                    }
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
                nodes.push_back({p.normal(sin_beta, cos_beta, psi),
                                 weight_beta * rule_psi.weights[j] * half * p.density(beta, psi)});
            }
        }
    }
    return nodes;
}

}  // namespace hairis::ggx
