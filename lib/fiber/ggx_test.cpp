#include "fiber/ggx.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "core/quadrature.h"

namespace hairis {
namespace {

// The visible-normal rule integrates against the density Cycles' sampler draws from: compare
// moments of h under the rule with the mean over 4·10⁵ of the sampler's normals, for views
// above the mean surface and below it (w·m < 0, where Cycles' TRT still draws).
TEST(Ggx, VisibleRuleMatchesCyclesSamplerDensity) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Vec3d m = safe_normalize(Vec3d{0.2, -0.3, 1.0});
    const double cases[][4] = {{0.3, 0.5, 0.1, 0.8}, {0.8, -0.9, 0.3, 0.2}, {0.3, 0.7, 0.2, -0.3}, {0.6, 0.2, -0.5, -0.6}};
    for (const auto &c : cases) {
        const double alpha = c[0];
        const Vec3d w = safe_normalize(Vec3d{c[1], c[2], c[3]});
        double rule[4] = {0, 0, 0, 0}, weight_sum = 0;
        for (const ggx::VisibleNode &node : ggx::visible_rule(alpha, w, m, 24, 24)) {
            rule[0] += node.weight * node.h.x;
            rule[1] += node.weight * node.h.y;
            rule[2] += node.weight * dot(node.h, m);
            rule[3] += node.weight * dot(node.h, w) * dot(node.h, w);
            weight_sum += node.weight;
        }
        EXPECT_NEAR(weight_sum, 1.0, 1e-12);
        const int n = 400000;
        double mc[4] = {0, 0, 0, 0}, sq[4] = {0, 0, 0, 0};
        for (int i = 0; i < n; ++i) {
            const Vec3d h = ggx::sample_visible(alpha, w, m, u(rng), u(rng));
            const double x[4] = {h.x, h.y, dot(h, m), dot(h, w) * dot(h, w)};
            for (int k = 0; k < 4; ++k) {
                mc[k] += x[k];
                sq[k] += x[k] * x[k];
            }
        }
        for (int k = 0; k < 4; ++k) {
            const double mean = mc[k] / n, se = std::sqrt(std::max(sq[k] / n - mean * mean, 0.0) / n);
            EXPECT_NEAR(rule[k], mean, 5.0 * se + 1e-4) << "alpha " << alpha << " w·m " << dot(w, m) << " moment " << k;
        }
    }
}

// The split rule puts its panel edges on the events' roots along each ψ line: an integrand that
// jumps where either of two planes cuts the normals, g = [h·d₁ > c₁] + 2[h·d₂ > c₂], is then
// constant on every panel of a line, so four nodes integrate each line exactly up to the
// precision of the roots. The reference integrates the same lines (the rule's β nodes and
// weights, VisibleParametrization's density) by a midpoint rule of 2·10⁵ points, no roots
// involved; the rule without the split misses it by far more, so a misplaced root shows.
TEST(Ggx, SplitRuleIntegratesJumpsOnEachLineAtTheEventsRoots) {
    const Vec3d m = safe_normalize(Vec3d{0.1, 0.2, 1.0});
    const Vec3d d1 = safe_normalize(Vec3d{1.0, 0.3, 0.4}), d2 = safe_normalize(Vec3d{-0.4, 1.0, 0.2});
    auto g = [&](Vec3d h) { return (dot(h, d1) > 0.05 ? 1.0 : 0.0) + (dot(h, d2) > -0.1 ? 2.0 : 0.0); };
    auto events = [&](Vec3d h) { return std::array<double, 2>{dot(h, d1) - 0.05, dot(h, d2) + 0.1}; };
    for (const double alpha : {0.3, 0.6})
        for (const Vec3d w : {safe_normalize(Vec3d{0.3, -0.2, 0.9}), safe_normalize(Vec3d{-0.7, 0.4, 0.3})}) {
            double split = 0.0, plain = 0.0;
            for (const ggx::VisibleNode &node : ggx::visible_rule_split(alpha, w, m, 4, 4, 8, events))
                split += node.weight * g(node.h);
            for (const ggx::VisibleNode &node : ggx::visible_rule(alpha, w, m, 4, 4)) plain += node.weight * g(node.h);
            const ggx::VisibleParametrization p(alpha, w, m);
            const GaussLegendre &rule = GaussLegendre::rule(4);
            const double lo = p.psi_min(), hi = 0.5 * kPi;
            const int points = 200000;
            double lines = 0.0;
            for (std::size_t i = 0; i < rule.nodes.size(); ++i) {
                const double beta = 0.5 * kPi * rule.nodes[i];
                double line = 0.0;
                for (int k = 0; k < points; ++k) {
                    const double psi = lo + (hi - lo) * (k + 0.5) / points;
                    line += g(p.normal(beta, psi)) * p.density(beta, psi);
                }
                lines += rule.weights[i] * 0.5 * kPi * line * (hi - lo) / points;
            }
            EXPECT_NEAR(split, lines, 1e-4) << "alpha " << alpha << " w·m " << dot(w, m);
            EXPECT_GT(std::fabs(plain - lines), 1e-2) << "alpha " << alpha << " w·m " << dot(w, m);
        }
}

// D_w is a density over the sphere of normals (for w·m > 0): its integral by an independent
// product rule in (cos θ, φ) about m is 1.
TEST(Ggx, VisibleDensityIntegratesToOne) {
    const Vec3d m{0, 0, 1};
    for (double alpha : {0.1, 0.3, 0.9}) {
        for (double mu : {0.05, 0.5, 1.0}) {
            const Vec3d w{std::sqrt(1.0 - mu * mu), 0.0, mu};
            // GGX is concentrated near cos θ = 1: integrate in t = θ with graded panels.
            const QuadratureRule theta = QuadratureRule::composite(0.0, kHalfPi, 64, 8);
            const QuadratureRule phi = QuadratureRule::composite(-kPi, kPi, 16, 8);
            double sum = 0.0;
            for (std::size_t i = 0; i < theta.x.size(); ++i)
                for (std::size_t j = 0; j < phi.x.size(); ++j) {
                    const double st = std::sin(theta.x[i]), ct = std::cos(theta.x[i]);
                    const Vec3d h{st * std::cos(phi.x[j]), st * std::sin(phi.x[j]), ct};
                    sum += theta.w[i] * phi.w[j] * st * ggx::visible_density(alpha, w, m, h);
                }
            EXPECT_NEAR(sum, 1.0, 2e-3) << "alpha " << alpha << " mu " << mu;
        }
    }
}

TEST(Ggx, RefractionObeysSnell) {
    const Vec3d h = safe_normalize(Vec3d{0.1, 0.2, 1.0});
    const Vec3d w = safe_normalize(Vec3d{0.5, -0.2, 0.7});
    Vec3d t;
    ASSERT_TRUE(ggx::refract(w, h, 1.55, t));
    const double sin_i = length(cross(w, h)), sin_t = length(cross(t, h));
    EXPECT_NEAR(sin_i, 1.55 * sin_t, 1e-12);
    EXPECT_LT(dot(t, h), 0.0);                                  // on the far side
    EXPECT_NEAR(dot(cross(w, h), cross(-t, h)) / (sin_i * sin_t), 1.0, 1e-12);  // same plane
    // Grazing from inside beyond the critical angle: total internal reflection.
    EXPECT_FALSE(ggx::refract(safe_normalize(Vec3d{0.9, 0.0, 0.2}), Vec3d{0, 0, 1}, 1.0 / 1.55, t));
}

}  // namespace
}  // namespace hairis
