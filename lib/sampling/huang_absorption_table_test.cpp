// The absorption part of a Huang table (huang_absorption_table.h): at its nodes and points it
// is the expectation of a fiber of that absorption; between nodes its error against the
// expectation stays within the budget the renders rely on; a strand of the fiber's absorption
// differs by exactly 0; absorptions below the first node are not read.
#include "sampling/huang_absorption_table.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "core/frame.h"
#include "tables/huang_bake.h"

namespace hairis {
namespace {

HuangFiber fiber_of(const std::array<float, 3> &sigma, float aspect = 0.5f, float roughness = 0.3f) {
    HuangParams p;
    p.aspect_ratio = aspect;
    p.roughness = roughness;
    p.sigma_a = {sigma[0], sigma[1], sigma[2]};
    return HuangFiber::create(p).value();
}

HuangBakeOptions options(std::vector<float> nodes) {
    HuangBakeOptions o;
    o.theta_o_count = 4;
    o.phi_o_count = 2;
    o.theta_i_count = 8;
    o.phi_count = 12;
    o.first_order = o.f_first_order = 3;
    o.second_order = o.f_second_order = 2;
    o.f_tt_order = 4;
    o.absorption_nodes = std::move(nodes);
    return o;
}

HuangQuadrature rule_of(const HuangBakeOptions &o) {
    HuangQuadrature q;
    q.first_order = o.f_first_order;
    q.second_order = o.f_second_order;
    q.tt_order = o.f_tt_order;
    return q;
}

Rgb rest_of(const std::array<Rgb, 4> &lobes) { return lobes[1] + lobes[2] + lobes[3]; }

struct Baked {
    HuangTableSet set;
    HuangTable table;
    HuangAbsorptionTable absorption;
};

Baked bake(const HuangFiber &fiber, const HuangBakeOptions &o) {
    HuangTableSet set = bake_huang_table(fiber, o).value();
    HuangTable table =
        HuangTable::create(set.theta_o_nodes, set.phi_o_nodes, set.theta_i_count, set.phi_count, set.values).value();
    HuangAbsorptionTable absorption = HuangAbsorptionTable::create(set).value();
    return {std::move(set), std::move(table), std::move(absorption)};
}

// ω_i at point (i, j) of φ_o node q.
Vec3 point(const Baked &b, int q, int i, int j) {
    const double phi = -kPi + kTwoPi * (j + 0.5) / b.set.phi_count;
    const std::vector<double> points = huang_sin_theta_points(b.set.theta_i_count);
    return direction_of(float(std::asin(points[size_t(i)])), b.set.phi_o_nodes[size_t(q)] + float(phi));
}

TEST(HuangAbsorptionTable, AtItsNodesAndPointsItIsTheExpectationOfThatAbsorption) {
    const HuangFiber fiber = fiber_of({0.3f, 0.6f, 1.2f});
    const HuangBakeOptions o = options(huang_absorption_nodes(5));
    const Baked b = bake(fiber, o);
    ASSERT_EQ(b.set.absorption_count(), 5);
    int checked = 0;
    for (int k = 0; k < 5; ++k) {
        const float node = b.set.absorption_nodes[size_t(k)];
        const HuangFiber at_node = fiber_of({node, node, node});
        for (int q : {0, 1})
            for (int r : {0, 2}) {
                const Vec3 wo = direction_of(b.set.theta_o_nodes[size_t(r)], b.set.phi_o_nodes[size_t(q)]);
                const HuangTableQuery query = b.table.locate(wo);
                const HuangExpectation e = at_node.expectation({wo, 0.0f, 1.0f}, rule_of(o));
                for (int i : {1, 3, 6})
                    for (int j : {0, 4, 9}) {
                        const Vec3 wi = point(b, q, i, j);
                        const float want = rest_of(e.lobes(wi)).r;
                        const Rgb got = b.absorption.f_cos(query, wi, {node, node, node});
                        for (int c = 0; c < 3; ++c)
                            EXPECT_NEAR(got[c], want, 2e-3f * std::max(want, 1e-6f)) << k << " " << q << " " << r;
                        ++checked;
                    }
            }
    }
    EXPECT_EQ(checked, 5 * 4 * 9);
}

// The part's error at absorption `sigma` against the expectation of a fiber of that absorption,
// at the points of two φ_o (or the one) and two θ_o nodes: Σ|error| and Σ f (R included), and the largest
// error as a share of one direction's f. `check` sees each read and the same direction's read
// at the last node.
struct PartError {
    double abs_sum = 0, ref_sum = 0, worst = 0;
};

template <typename Check>
void add_part_error(const Baked &b, const HuangBakeOptions &o, const HuangFiber &strand,
                    const std::array<float, 3> &sigma, PartError &out, Check check) {
    for (int q = 0; q < std::min(2, b.set.phi_o_count()); ++q)  // a round fiber has one φ_o node
        for (int r : {1, 2}) {
            const Vec3 wo = direction_of(b.set.theta_o_nodes[size_t(r)], b.set.phi_o_nodes[size_t(q)]);
            const HuangTableQuery query = b.table.locate(wo);
            const HuangExpectation e = strand.expectation({wo, 0.0f, 1.0f}, rule_of(o));
            for (int i = 0; i < o.theta_i_count; ++i)
                for (int j = 0; j < o.phi_count; ++j) {
                    const Vec3 wi = point(b, q, i, j);
                    const std::array<Rgb, 4> lobes = e.lobes(wi);
                    const Rgb want = rest_of(lobes), all = lobes[0] + want;
                    const Rgb got = b.absorption.f_cos(query, wi, {sigma[0], sigma[1], sigma[2]});
                    check(got, b.absorption.f_cos(query, wi, {12.0, 12.0, 12.0}));
                    for (int c = 0; c < 3; ++c) {
                        out.abs_sum += std::fabs(got[c] - want[c]);
                        out.ref_sum += all[c];
                        if (all[c] > 1e-3f) out.worst = std::max(out.worst, double(std::fabs(got[c] - want[c]) / all[c]));
                    }
                }
        }
}

// Between nodes, at the points (so that only the absorption axis is interpolated): the bake's
// default nodes against the expectation of fibers of random absorption. The error is measured
// against each direction's whole f (R included), the quantity a render sees. Reading G, or
// log G, linearly between the same nodes fails both bounds.
struct BudgetCase {
    float aspect, roughness;
    double l1, worst;  // the bounds
};

class HuangAbsorptionBudget : public ::testing::TestWithParam<BudgetCase> {};

TEST_P(HuangAbsorptionBudget, BetweenNodesTheErrorStaysWithinItsBudget) {
    const BudgetCase k = GetParam();
    const HuangFiber fiber = fiber_of({0.3f, 0.6f, 1.2f}, k.aspect, k.roughness);
    const HuangBakeOptions o = options(huang_absorption_nodes());
    const Baked b = bake(fiber, o);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    PartError error;
    for (int trial = 0; trial < 6; ++trial) {
        // Absorptions from the first node to 8, even in log(σ + 1/4) as the nodes are.
        std::array<float, 3> sigma;
        for (float &s : sigma)
            s = float(std::exp(std::log(1.0 / 64 + 0.25) + u(rng) * (std::log(8.25) - std::log(1.0 / 64 + 0.25))) - 0.25);
        add_part_error(b, o, fiber_of(sigma, k.aspect, k.roughness), sigma, error, [](Rgb, Rgb) {});
    }
    const double l1 = error.abs_sum / error.ref_sum, worst = error.worst;
    std::printf("absorption part between nodes (aspect %.2f, roughness %.2f): L1 %.5f of f, largest %.4f of a "
                "direction's f\n",
                k.aspect, k.roughness, l1, worst);
    EXPECT_LT(l1, k.l1);
    EXPECT_LT(worst, k.worst);
}

INSTANTIATE_TEST_SUITE_P(Fibers, HuangAbsorptionBudget,
                         ::testing::Values(BudgetCase{0.5f, 0.3f, 1e-3, 0.02}, BudgetCase{1.0f, 0.1f, 1e-3, 0.01},
                                           BudgetCase{0.85f, 0.8f, 1e-3, 0.03}));

// Beyond the last node (black hair, σ up to tens): G never rises, stays finite, and stays
// within a small share of each direction's f; an infinite absorption is not read.
TEST(HuangAbsorptionTable, BeyondTheLastNodeItDecaysAndStaysWithinItsBudget) {
    const HuangFiber fiber = fiber_of({0.3f, 0.6f, 1.2f});
    const HuangBakeOptions o = options(huang_absorption_nodes());
    const Baked b = bake(fiber, o);
    const std::array<float, 3> sigma{14.0f, 22.0f, 40.0f};
    PartError error;
    add_part_error(b, o, fiber_of(sigma), sigma, error, [](Rgb got, Rgb last) {
        for (int c = 0; c < 3; ++c) {
            ASSERT_TRUE(std::isfinite(got[c]) && got[c] >= 0.0f);
            EXPECT_LE(got[c], last[c] * (1.0f + 1e-6f));
        }
    });
    const double worst = error.worst;
    std::printf("absorption part beyond the last node: largest %.4f of a direction's f\n", worst);
    EXPECT_LT(worst, 0.03);
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_FALSE(b.absorption.reads({inf, 0.6, 1.2}, {0.3, 0.6, 1.2}));
}

TEST(HuangAbsorptionTable, AStrandOfTheFibersAbsorptionDiffersByExactlyZero) {
    const HuangFiber fiber = fiber_of({0.3f, 0.6f, 1.2f});
    const Baked b = bake(fiber, options(huang_absorption_nodes(6)));
    const Vec3 wo = direction_of(0.3f, 0.7f), wi = direction_of(-0.2f, 2.5f);
    const HuangTableQuery query = b.table.locate(wo);
    const std::array<double, 3> own{0.3, 0.6, 1.2};
    const Rgb zero = b.absorption.difference(query, wi, own, own);
    EXPECT_EQ(zero.r, 0.0f);
    EXPECT_EQ(zero.g, 0.0f);
    EXPECT_EQ(zero.b, 0.0f);
    // Only the channel that differs moves; more absorption, less light.
    const Rgb darker = b.absorption.difference(query, wi, {0.3, 0.9, 1.2}, own);
    EXPECT_EQ(darker.r, 0.0f);
    EXPECT_LT(darker.g, 0.0f);
    EXPECT_EQ(darker.b, 0.0f);
    // Below the first node a channel is read only where both absorptions are equal.
    const double below = 0.5 * b.set.absorption_nodes[0];
    EXPECT_TRUE(b.absorption.reads({0.3, 0.9, 1.2}, own));
    EXPECT_FALSE(b.absorption.reads({below, 0.6, 1.2}, own));
    EXPECT_FALSE(b.absorption.reads(own, {below, 0.6, 1.2}));
    EXPECT_TRUE(b.absorption.reads({below, 0.9, 1.2}, {below, 0.6, 1.2}));
}

// difference() reads only the nodes its absorptions need; it must give what reading every
// value apart gives, also for absorptions whose nodes lie far apart and one channel alone.
TEST(HuangAbsorptionTable, ItsDifferenceIsTheDifferenceOfItsValues) {
    const HuangFiber fiber = fiber_of({0.3f, 0.6f, 1.2f});
    const Baked b = bake(fiber, options(huang_absorption_nodes()));
    const std::array<std::array<double, 3>, 4> strands = {{{0.3, 0.6, 1.2}, {0.02, 0.6, 1.2},
                                                          {0.3, 9.0, 1.2}, {0.05, 3.0, 20.0}}};
    const std::array<std::array<double, 3>, 2> fibers = {{{0.3, 0.6, 1.2}, {6.0, 0.03, 1.2}}};
    int compared = 0;
    for (int v = 0; v < 5; ++v) {
        const HuangTableQuery query = b.table.locate(direction_of(-0.6f + 0.3f * v, 0.4f + 0.5f * v));
        const Vec3 wi = direction_of(0.5f - 0.25f * v, -2.0f + 0.9f * v);
        for (const auto &fiber_sigma : fibers)
            for (const auto &strand : strands) {
                const Rgb got = b.absorption.difference(query, wi, strand, fiber_sigma);
                const Rgb a = b.absorption.f_cos(query, wi, strand), c = b.absorption.f_cos(query, wi, fiber_sigma);
                for (int k = 0; k < 3; ++k) {
                    const double want = double(a[k]) - double(c[k]);
                    EXPECT_NEAR(got[k], want, 1e-6 * std::max({1.0, double(a[k]), double(c[k])}))
                        << "view " << v << ", channel " << k;
                    if (strand[std::size_t(k)] == fiber_sigma[std::size_t(k)]) {
                        EXPECT_EQ(got[k], 0.0f);
                    }
                    compared += want != 0.0;
                }
            }
    }
    EXPECT_GT(compared, 40);  // the views reach the fiber's scattering, not only zeros
}

TEST(HuangAbsorptionTable, RefusesASetWithoutTheAbsorptionPart) {
    const HuangFiber fiber = fiber_of({0.3f, 0.6f, 1.2f});
    HuangTableSet set = bake_huang_table(fiber, options({})).value();
    const Expected<HuangAbsorptionTable> none = HuangAbsorptionTable::create(set);
    ASSERT_FALSE(none.ok());
    EXPECT_NE(none.error().message.find("no absorption part"), std::string::npos) << none.error().message;
    HuangBakeOptions without_f = options(huang_absorption_nodes(3));
    without_f.f = false;
    const Expected<HuangTableSet> refused = bake_huang_table(fiber, without_f);
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().message.find("needs the f part"), std::string::npos) << refused.error().message;
}

}  // namespace
}  // namespace hairis
