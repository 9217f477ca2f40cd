// The Huang bake: the same bytes for any thread count, cancellable, cells holding f at their
// centres in the table's layout and frame (computed here independently of the bake's loops),
// slices on the ellipse's mirror planes symmetric, "estimate" cells means of Cycles evals there,
// the node placement, the recorded parameters and the validation of options.
#include "tables/huang_bake.h"

#include <gtest/gtest.h>

#include "same_bits.h"

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/frame.h"
#include "fiber/principled_hair.h"

namespace hairis {
namespace {

using testing::same_bits;

HuangFiber make_fiber(float aspect, float roughness = 0.3f) {
    HuangParams p;
    p.aspect_ratio = aspect;
    p.roughness = roughness;
    p.sigma_a = principled_hair::sigma_from_reflectance({0.017513f, 0.005763f, 0.002059f}, roughness);
    return HuangFiber::create(p).value();
}

HuangBakeOptions tiny(const std::string &evaluator = "expectation") {
    HuangBakeOptions o;
    o.theta_o_count = 4;
    o.phi_o_count = 3;
    o.theta_i_count = 8;
    o.phi_count = 12;
    o.evaluator = evaluator;
    return o;
}

TEST(HuangBake, SameBytesForOneAndTwoThreads) {
    const HuangFiber fiber = make_fiber(0.85f);
    for (const char *evaluator : {"expectation", "estimate"}) {
        HuangBakeOptions o = tiny(evaluator);
        o.points = 2;
        o.threads = 1;
        const HuangTableSet one = bake_huang_table(fiber, o).value();
        o.threads = 2;
        const HuangTableSet two = bake_huang_table(fiber, o).value();
        ASSERT_EQ(one.values.size(), two.values.size());
        EXPECT_TRUE(same_bits(one.values, two.values)) << evaluator;
        double total = 0.0;
        for (float v : one.values) total += v;
        EXPECT_GT(total, 0.0) << evaluator;
    }
}

TEST(HuangBake, ReportsProgressAndCancels) {
    const HuangFiber fiber = make_fiber(0.85f);
    std::vector<float> seen;
    const Expected<HuangTableSet> done = bake_huang_table(fiber, tiny(), [&](float p) {
        seen.push_back(p);
        return true;
    });
    ASSERT_TRUE(done.ok());
    ASSERT_GE(seen.size(), 2u);
    EXPECT_EQ(seen.front(), 0.0f);
    EXPECT_EQ(seen.back(), 1.0f);
    for (size_t k = 1; k < seen.size(); ++k) EXPECT_GT(seen[k], seen[k - 1]);
    int calls = 0;
    const Expected<HuangTableSet> cancelled = bake_huang_table(fiber, tiny(), [&](float p) { return ++calls < 3 && p < 1.0f; });
    ASSERT_FALSE(cancelled.ok());
    EXPECT_EQ(cancelled.error().kind, ErrorKind::Cancelled);
    EXPECT_EQ(cancelled.error().message, "cancelled");
    EXPECT_EQ(calls, 3);
}

// The cell (q, r, i, j) holds luminance(f·cos θ_i) at its centre in sin θ_i and φ_i − φ_o, for
// the view at θ_o node r and φ_o node q, in Huang's frame.
TEST(HuangBake, CellsHoldFAtTheirCentres) {
    const HuangFiber fiber = make_fiber(0.5f);
    const HuangBakeOptions o = tiny();
    const HuangTableSet set = bake_huang_table(fiber, o).value();
    HuangQuadrature rule;
    rule.first_order = o.first_order;
    rule.second_order = o.second_order;
    rule.tt_order = o.f_tt_order;  // both parts refine TT alike
    int positive = 0;
    for (int q : {0, 1, 2})
        for (int r : {1, 3}) {
            const double theta_o = -kHalfPi + kPi * (r + 0.5) / o.theta_o_count, phi_o = kHalfPi * q / 2;
            const Vec3 wo{float(std::sin(theta_o)), float(std::cos(theta_o) * std::cos(phi_o)),
                          float(std::cos(theta_o) * std::sin(phi_o))};
            const HuangExpectation f = fiber.expectation({wo, 0.0f, 1.0f}, rule);
            for (int i : {2, 4, 6})
                for (int j : {0, 3, 5, 10}) {
                    const double s = 0.5 * (std::sin(-kHalfPi + kPi * i / o.theta_i_count) +
                                            std::sin(-kHalfPi + kPi * (i + 1) / o.theta_i_count));
                    const double phi_i = phi_o - kPi + kTwoPi * (j + 0.5) / o.phi_count, c = std::sqrt(1 - s * s);
                    const Vec3 wi{float(s), float(c * std::cos(phi_i)), float(c * std::sin(phi_i))};
                    const double expected = luminance(f.f(wi));
                    const float baked = set.values[((size_t(q) * o.theta_o_count + r) * o.theta_i_count + i) * o.phi_count + j];
                    EXPECT_NEAR(baked, expected, 1e-4 * expected + 1e-9) << q << " " << r << " " << i << " " << j;
                    positive += expected > 0.0;
                }
        }
    EXPECT_GT(positive, 30);
}

// Views on the ellipse's mirror planes (φ_o = 0 and π/2) see f symmetric in φ_i − φ_o; the
// slices there are, to the rule's accuracy. Views between them are not.
TEST(HuangBake, SlicesOnTheMirrorPlanesAreSymmetric) {
    const HuangFiber fiber = make_fiber(0.5f);
    HuangBakeOptions o = tiny();
    o.phi_count = 24;
    const HuangTableSet set = bake_huang_table(fiber, o).value();
    auto asymmetry = [&](int q, int r) {
        double diff = 0.0, sum = 0.0;
        for (int i = 0; i < o.theta_i_count; ++i)
            for (int j = 0; j < o.phi_count; ++j) {
                const size_t row = ((size_t(q) * o.theta_o_count + r) * o.theta_i_count + i) * o.phi_count;
                diff += std::fabs(set.values[row + j] - set.values[row + o.phi_count - 1 - j]);
                sum += set.values[row + j];
            }
        return diff / sum;
    };
    for (int r = 0; r < o.theta_o_count; ++r) {
        EXPECT_LT(asymmetry(0, r), 0.03) << "phi_o 0, theta_o node " << r;
        EXPECT_LT(asymmetry(2, r), 0.03) << "phi_o pi/2, theta_o node " << r;
        EXPECT_GT(asymmetry(1, r), 0.1) << "phi_o pi/4, theta_o node " << r;
    }
}

// Each "estimate" cell is a mean of Cycles evals at the cell's point: it agrees with the mean
// of fresh evals there (another seed, 16 times as many) within 5 standard errors.
TEST(HuangBake, EstimateCellsAreMeansOfCyclesEvalsAtTheirCentres) {
    const HuangFiber fiber = make_fiber(0.85f);
    HuangBakeOptions o = tiny("estimate");
    o.theta_o_count = 2;
    o.phi_o_count = 2;
    o.estimates = 256;
    const HuangTableSet set = bake_huang_table(fiber, o).value();
    int checked = 0;
    for (int q = 0; q < 2; ++q)
        for (int r = 0; r < 2; ++r) {
            const double theta_o = -kHalfPi + kPi * (r + 0.5) / 2, phi_o = kHalfPi * q;
            FiberHit hit;
            hit.wo = direction_of(float(theta_o), float(phi_o));
            hit.normal = {0.0f, 1.0f, 0.0f};  // Huang's frame is the point's
            const HuangPoint point = fiber.at(hit);
            CyclesLcg lcg{12345};
            for (int i : {3, 4, 5})
                for (int j : {1, 5, 6, 9}) {
                    const double s = 0.5 * (std::sin(-kHalfPi + kPi * i / o.theta_i_count) +
                                            std::sin(-kHalfPi + kPi * (i + 1) / o.theta_i_count));
                    const Vec3 wi = direction_of(float(std::asin(s)), float(phi_o - kPi + kTwoPi * (j + 0.5) / o.phi_count));
                    const int n = 16 * o.estimates;
                    double m = 0, m2 = 0;
                    for (int k = 0; k < n; ++k) {
                        const double y = luminance(point.f_estimate(wi, lcg));
                        m += y / n;
                        m2 += y * y / n;
                    }
                    const double variance = std::max(m2 - m * m, 0.0);
                    const double standard_error = std::sqrt(variance / o.estimates + variance / n);
                    const float baked = set.values[((size_t(q) * 2 + r) * o.theta_i_count + i) * o.phi_count + j];
                    EXPECT_NEAR(baked, m, 5 * standard_error + 1e-9) << q << " " << r << " " << i << " " << j;
                    checked += standard_error > 0.0;
                }
        }
    EXPECT_GT(checked, 20);
}

TEST(HuangBake, NodesAndParameters) {
    HuangBakeOptions o = tiny();
    o.phi_o_count = 4;
    const HuangTableSet ellipse = bake_huang_table(make_fiber(0.85f), o).value();
    ASSERT_EQ(ellipse.phi_o_nodes.size(), 4u);
    EXPECT_EQ(ellipse.phi_o_nodes.front(), 0.0f);
    EXPECT_NEAR(ellipse.phi_o_nodes[1], kPi / 6, 1e-7);
    EXPECT_EQ(ellipse.phi_o_nodes.back(), float(kHalfPi));
    EXPECT_EQ(ellipse.theta_o_nodes, theta_r_nodes(o.theta_o_count));
    EXPECT_EQ(ellipse.values.size(), size_t(4) * o.theta_o_count * o.theta_i_count * o.phi_count);
    EXPECT_EQ(ellipse.model, "huang2022");
    EXPECT_EQ(ellipse.parameters, huang_parameters(make_fiber(0.85f).params()));
    // A circular fiber needs one view azimuth.
    const HuangTableSet circle = bake_huang_table(make_fiber(1.0f), o).value();
    ASSERT_EQ(circle.phi_o_nodes.size(), 1u);
    EXPECT_EQ(circle.values.size(), size_t(o.theta_o_count) * o.theta_i_count * o.phi_count);
    // What the bake makes, the table accepts.
    EXPECT_TRUE(HuangSamplingTable::from(ellipse).ok());
    EXPECT_TRUE(HuangSamplingTable::from(circle).ok());
}

TEST(HuangBake, RefusesOptionsByName) {
    const HuangFiber fiber = make_fiber(0.85f);
    auto message = [&](HuangBakeOptions o) {
        const Expected<HuangTableSet> t = bake_huang_table(fiber, o);
        return t.ok() ? std::string("(accepted)") : t.error().message;
    };
    HuangBakeOptions o;
    o.theta_o_count = 0;
    EXPECT_NE(message(o).find("theta_o_count"), std::string::npos);
    o = {};
    o.phi_o_count = 1000;
    EXPECT_NE(message(o).find("phi_o_count"), std::string::npos);
    o = {};
    o.evaluator = "exact";
    EXPECT_NE(message(o).find("evaluator must be \"expectation\" or \"estimate\" (got \"exact\")"), std::string::npos);
    o = {};
    o.points = 0;
    EXPECT_NE(message(o).find("points"), std::string::npos);
    o = {};
    o.theta_o_count = 1000;
    o.phi_o_count = 200;
    o.theta_i_count = 4000;
    o.phi_count = 4000;
    EXPECT_NE(message(o).find("cells; at most"), std::string::npos);
    // The refinement a table set may record, refused before the bake rather than after it.
    for (int k : {0, kMaxHuangFRefinement + 1}) {
        o = {};
        o.f_tt_order = 0;
        o.f_refinement = k;
        EXPECT_NE(message(o).find("f_refinement"), std::string::npos) << k;
    }
    // The absorption nodes a set may hold, refused before the bake, and only beside the f part.
    o = {};
    o.absorption_nodes = {0.5f};
    EXPECT_NE(message(o).find("absorption_nodes must hold 2 to 32 absorption nodes (got 1)"), std::string::npos)
        << message(o);
    o.absorption_nodes = {0.5f, 0.5f};
    EXPECT_NE(message(o).find("absorption_nodes[1]"), std::string::npos) << message(o);
    o.absorption_nodes = {-1.0f, 0.5f};
    EXPECT_NE(message(o).find("absorption_nodes[0]"), std::string::npos) << message(o);
    o.absorption_nodes = {0.5f, 1.0f};
    o.f = false;
    EXPECT_NE(message(o).find("needs the f part"), std::string::npos) << message(o);
    BakeOptions b;
    b.huang_absorption = true;
    b.huang_f = false;
    const Status status = b.validate();
    ASSERT_TRUE(status.has_value());
    EXPECT_NE(status->message.find("huang_absorption needs huang_f"), std::string::npos) << status->message;
}

// bake_tables on a Huang fiber: its Huang table set at BakeOptions::huang's resolution, the
// same bytes as bake_huang_table with those options, for any thread count, and cancellable.
TEST(HuangBake, BakeTablesOfAHuangFiberIsItsHuangTableSet) {
    const HuangFiber fiber = make_fiber(0.6f);
    BakeOptions o;
    o.huang = {4, 3, 8, 12};
    o.huang_multiple = false;
    o.threads = 1;
    const Expected<TableSet> one = bake_tables(fiber, huang_parameters(fiber.params()), o);
    ASSERT_TRUE(one.ok()) << one.error().message;
    o.threads = 2;
    const TableSet two = bake_tables(fiber, huang_parameters(fiber.params()), o).value();
    const TableSet &t = one.value();
    EXPECT_EQ(t.model, "huang2022");
    EXPECT_FALSE(t.has_far_field());
    EXPECT_FALSE(t.has_multiple());
    EXPECT_FALSE(t.near_field);
    ASSERT_TRUE(t.huang && two.huang);
    EXPECT_EQ(t.huang->theta_o_nodes.size(), 4u);
    EXPECT_EQ(t.huang->phi_o_nodes.size(), 3u);
    EXPECT_EQ(t.huang->theta_i_count, 8);
    EXPECT_EQ(t.huang->phi_count, 12);
    const HuangTableSet direct = bake_huang_table(fiber, tiny()).value();
    ASSERT_EQ(direct.values.size(), t.huang->values.size());
    EXPECT_TRUE(same_bits(direct.values, t.huang->values));
    EXPECT_TRUE(same_bits(two.huang->values, t.huang->values));
    EXPECT_EQ(canonical_parameters(t.parameters), canonical_parameters(huang_parameters(fiber.params())));
    int calls = 0;
    const Expected<TableSet> cancelled =
        bake_tables(fiber, huang_parameters(fiber.params()), o, [&](float) { return ++calls < 2; });
    ASSERT_FALSE(cancelled.ok());
    EXPECT_EQ(cancelled.error().kind, ErrorKind::Cancelled);
}

// The multiple part (huang_multiple): per θ_r node and n_h a density over θ_i (per steradian,
// unnormalised as for Chiang: MultipleTable normalises), of the shape of the Huang fiber's term
// multiple_f_cos(θ_i, θ_r, n_h) (evaluated here at cell centres, not through the bake's grid),
// at the θ_r nodes and n_h values the options give, in their order; the Huang table is the
// same as without it, and the progress ends after the multiple part.
TEST(HuangBake, TheMultiplePartIsTheFibersDualScatteringDensity) {
    const HuangFiber fiber = make_fiber(1.0f);  // circular: one orientation, a quarter of the averages' cost
    BakeOptions o;
    o.huang = {4, 1, 8, 12};
    o.theta_r_count = 5;
    o.theta_i_count = 24;
    o.n_h_values = {1, 4};
    std::vector<float> reported;
    const Expected<TableSet> baked = bake_tables(fiber, huang_parameters(fiber.params()), o, [&](float f) {
        reported.push_back(f);
        return true;
    });
    ASSERT_TRUE(baked.ok()) << baked.error().message;
    const TableSet &t = baked.value();
    ASSERT_TRUE(t.has_multiple());
    EXPECT_FALSE(t.has_far_field());
    EXPECT_EQ(t.theta_r_nodes, theta_r_nodes(5));
    EXPECT_EQ(t.n_h_values, (std::vector<int>{1, 4}));
    ASSERT_EQ(t.multiple.size(), 5u * 2u * 24u);
    ASSERT_FALSE(reported.empty());
    EXPECT_EQ(reported.back(), 1.0f);
    for (size_t n = 1; n < reported.size(); ++n) EXPECT_GE(reported[n], reported[n - 1]);
    BakeOptions alone = o;
    alone.huang_multiple = false;
    const TableSet table_only = bake_tables(fiber, huang_parameters(fiber.params()), alone).value();
    ASSERT_EQ(table_only.huang->values.size(), t.huang->values.size());
    EXPECT_TRUE(same_bits(table_only.huang->values, t.huang->values));

    const DualScattering &dual = *huang_dual_scattering(fiber).value();
    for (int r = 0; r < 5; ++r)
        for (int k = 0; k < 2; ++k) {
            // Marginal mass per cell: the density times the cell's solid angle 2π (sin θ₁ − sin θ₀).
            double total = 0.0, reference_total = 0.0;
            std::vector<double> mass(24), reference(24);
            for (int i = 0; i < 24; ++i) {
                const double th0 = -kHalfPi + kPi * i / 24, th1 = -kHalfPi + kPi * (i + 1) / 24;
                mass[size_t(i)] = t.multiple_at(r, k, i) * kTwoPi * (std::sin(th1) - std::sin(th0));
                const double mid = 0.5 * (th0 + th1);
                reference[size_t(i)] = luminance(dual.multiple_f_cos(mid, t.theta_r_nodes[size_t(r)], t.n_h_values[size_t(k)])) *
                                       kTwoPi * std::cos(mid) * (th1 - th0);
                total += mass[size_t(i)];
                reference_total += reference[size_t(i)];
            }
            ASSERT_GT(total, 0.0);
            ASSERT_GT(reference_total, 0.0);
            // Cell averages against midpoint values: they agree to the curvature inside a cell.
            double l1 = 0.0;
            for (int i = 0; i < 24; ++i) l1 += std::fabs(mass[size_t(i)] / total - reference[size_t(i)] / reference_total);
            EXPECT_LT(l1, 0.03) << "theta_r node " << r << ", n_h " << t.n_h_values[size_t(k)];
        }
}

TEST(HuangBake, BakeTablesRefusesWhatAHuangTableSetCannotHold) {
    const HuangFiber fiber = make_fiber(0.6f);
    auto message = [&](const BakeOptions &o, std::vector<std::pair<std::string, double>> parameters = {}) {
        if (parameters.empty()) parameters = huang_parameters(fiber.params());
        const Expected<TableSet> t = bake_tables(fiber, parameters, o);
        return t.ok() ? std::string("(accepted)") : t.error().message;
    };
    BakeOptions o;
    o.source = "gaussian";
    EXPECT_NE(message(o).find("source must be \"exact\" for a huang2022 fiber"), std::string::npos) << message(o);
    o = {};
    o.huang = {1024, 256, 4096, 4096};
    EXPECT_NE(message(o).find("huang_theta_o, huang_phi_o"), std::string::npos) << message(o);
    o = {};
    o.huang.phi = 5000;
    EXPECT_NE(message(o).find("huang_phi"), std::string::npos) << message(o);
    auto other = huang_parameters(fiber.params());
    other[3].second = 0.9;  // roughness
    EXPECT_NE(message(BakeOptions{}, other).find("are not the huang2022 fiber's"), std::string::npos);
}

}  // namespace
}  // namespace hairis
