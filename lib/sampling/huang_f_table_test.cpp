// The baked f of a Huang table (huang_f_table.h): on its points it returns the expectation the
// bake computed, between them an interpolation whose error against HuangExpectation shrinks
// with the resolution; it respects the fold's mirror symmetries, wraps in φ and closes at the
// poles.
#include "sampling/huang_f_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "core/frame.h"
#include "fiber/principled_hair.h"
#include "tables/huang_bake.h"
#include "sampling/huang_table.h"

namespace hairis {
namespace {

HuangFiber make_fiber(float aspect, float roughness) {
    HuangParams p;
    p.aspect_ratio = aspect;
    p.roughness = roughness;
    p.sigma_a = principled_hair::sigma_from_reflectance({0.017513f, 0.005763f, 0.002059f}, roughness);
    return HuangFiber::create(p).value();
}

HuangBakeOptions options(int theta_o, int phi_o, int theta_i, int phi) {
    HuangBakeOptions o;
    o.theta_o_count = theta_o;
    o.phi_o_count = phi_o;
    o.theta_i_count = theta_i;
    o.phi_count = phi;
    o.first_order = o.f_first_order = 3;
    o.second_order = o.f_second_order = 2;
    return o;
}

struct Baked {
    HuangTableSet set;
    HuangTable table;
    HuangFTable f;
};

Baked bake(const HuangFiber &fiber, const HuangBakeOptions &o) {
    HuangTableSet set = bake_huang_table(fiber, o).value();
    HuangTable table = HuangTable::create(set.theta_o_nodes, set.phi_o_nodes, set.theta_i_count, set.phi_count,
                                          set.values).value();
    HuangFTable f = HuangFTable::create(set).value();
    return {std::move(set), std::move(table), std::move(f)};
}

// The f part's rule as the bake documents it: its orders times the refinement.
HuangQuadrature rule_of(const HuangBakeOptions &o) {
    HuangQuadrature q;
    q.first_order = o.f_first_order * o.f_refinement;
    q.second_order = o.f_second_order * o.f_refinement;
    q.tt_order = o.f_tt_order * o.f_refinement;
    return q;
}

Rgb rest_of(const std::array<Rgb, 4> &lobes) { return lobes[1] + lobes[2] + lobes[3]; }

class HuangFTablePoints : public ::testing::TestWithParam<int> {};

// With f_refinement k, at the rule (3k, 2k) and TT at 8k; the sampling part keeps its rule.
TEST_P(HuangFTablePoints, OnItsPointsItIsTheExpectationOfTtTrtAndTrrt) {
    const HuangFiber fiber = make_fiber(0.85f, 0.3f);
    HuangBakeOptions o = options(6, 3, 12, 16);
    o.f_refinement = GetParam();
    const Baked b = bake(fiber, o);
    EXPECT_EQ(b.set.f_refinement, o.f_refinement);
    const std::vector<double> &points = b.f.sin_theta_points();
    int checked = 0;
    for (int q : {0, 1, 2})
        for (int r : {0, 2, 5}) {
            const Vec3 wo = direction_of(b.set.theta_o_nodes[size_t(r)], b.set.phi_o_nodes[size_t(q)]);
            const HuangTableQuery query = b.table.locate(wo);
            const HuangExpectation e = fiber.expectation({wo, 0.0f, 1.0f}, rule_of(o));
            for (int i : {1, 5, 6, 10})
                for (int j : {0, 3, 8, 15}) {
                    const double phi = -kPi + kTwoPi * (j + 0.5) / o.phi_count;
                    const Vec3 wi = direction_of(float(std::asin(points[size_t(i)])),
                                                 b.set.phi_o_nodes[size_t(q)] + float(phi));
                    const Rgb want = rest_of(e.lobes(wi));
                    const Rgb got = b.f.f_cos(query, wi);
                    const Rgb stored = b.f.value(q, r, i, j);
                    for (int c = 0; c < 3; ++c) {
                        const float scale = std::max(want[c], 1e-6f);
                        EXPECT_NEAR(stored[c], want[c], 1e-4f * scale) << q << " " << r << " " << i << " " << j;
                        EXPECT_NEAR(got[c], want[c], 2e-3f * scale) << q << " " << r << " " << i << " " << j;
                    }
                    ++checked;
                }
        }
    EXPECT_EQ(checked, 3 * 3 * 16);
}

INSTANTIATE_TEST_SUITE_P(Refinements, HuangFTablePoints, ::testing::Values(1, 2));

// A finer f part is closer to the expectation at a much finer rule: the refinement reaches the
// bake (a bake that ignored it would give the same error twice), and it is what it is for.
TEST(HuangFTable, RefinementBringsTheFPartTowardsAFinerRule) {
    const HuangFiber fiber = make_fiber(0.85f, 0.3f);
    HuangBakeOptions o = options(4, 2, 12, 16);
    HuangQuadrature fine;
    fine.first_order = 12;
    fine.second_order = 8;
    fine.tt_order = 32;
    double errors[2] = {0, 0};
    for (int k : {1, 2}) {
        o.f_refinement = k;
        const Baked b = bake(fiber, o);
        double abs_sum = 0, ref_sum = 0;
        for (int q = 0; q < 2; ++q)
            for (int r = 0; r < 4; ++r) {
                const Vec3 wo = direction_of(b.set.theta_o_nodes[size_t(r)], b.set.phi_o_nodes[size_t(q)]);
                const HuangExpectation e = fiber.expectation({wo, 0.0f, 1.0f}, fine);
                const std::vector<double> &points = b.f.sin_theta_points();
                for (int i = 0; i < o.theta_i_count; ++i)
                    for (int j = 0; j < o.phi_count; ++j) {
                        const double phi = -kPi + kTwoPi * (j + 0.5) / o.phi_count;
                        const Vec3 wi = direction_of(float(std::asin(points[size_t(i)])),
                                                     b.set.phi_o_nodes[size_t(q)] + float(phi));
                        const double want = luminance(rest_of(e.lobes(wi)));
                        abs_sum += std::fabs(luminance(b.f.value(q, r, i, j)) - want);
                        ref_sum += want;
                    }
            }
        errors[k - 1] = abs_sum / ref_sum;
    }
    std::printf("L1 error of the f part against the rule (12, 8): %.4f at refinement 1, %.4f at 2\n",
                errors[0], errors[1]);
    EXPECT_LT(errors[1], 0.7 * errors[0]);
}

// Σ |f_table − f| / Σ f over random views and a grid of ω_i (the error that reaches an image
// under light from every direction), and the signed relative error of the integral.
struct Error {
    double l1 = 0, integral = 0;
};

Error error_against_expectation(const HuangFiber &fiber, const Baked &b, const HuangBakeOptions &o, int views) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    double abs_sum = 0, ref_sum = 0, tab_sum = 0;
    for (int v = 0; v < views; ++v) {
        const Vec3 wo = direction_of(float(std::asin(2 * u(rng) - 1)), float(kPi * (2 * u(rng) - 1)));
        const HuangExpectation e = fiber.expectation({wo, 0.0f, 1.0f}, rule_of(o));
        const HuangTableQuery query = b.table.locate(wo);
        constexpr int n = 48;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < 2 * n; ++j) {
                const Vec3 wi = direction_of(float(std::asin(-1 + 2 * (i + u(rng)) / n)), float(-kPi + kPi * (j + u(rng)) / n));
                const double want = luminance(rest_of(e.lobes(wi))), got = luminance(b.f.f_cos(query, wi));
                abs_sum += std::fabs(got - want);
                ref_sum += want;
                tab_sum += got;
            }
    }
    return {abs_sum / ref_sum, tab_sum / ref_sum - 1.0};
}

TEST(HuangFTable, BetweenItsPointsTheErrorShrinksWithTheResolution) {
    const HuangFiber fiber = make_fiber(0.85f, 0.3f);
    const HuangBakeOptions coarse = options(6, 2, 12, 16), fine = options(16, 4, 32, 48);
    const Error e_coarse = error_against_expectation(fiber, bake(fiber, coarse), coarse, 6);
    const Error e_fine = error_against_expectation(fiber, bake(fiber, fine), fine, 6);
    EXPECT_LT(e_fine.l1, 0.6 * e_coarse.l1) << e_fine.l1 << " vs " << e_coarse.l1;
    // Read with cubic weights, the finer table stays well inside what a multilinear reading of
    // the same points gives (about 2.7% and −0.9% here).
    EXPECT_LT(e_fine.l1, 0.016) << e_fine.l1;
    EXPECT_LT(std::fabs(e_fine.integral), 0.005) << e_fine.integral;
}

// A field that is quadratic in φ and in φ_o is reproduced exactly between the points (a
// cubic reading does; a multilinear one misses by the curvature). The field has the fold's
// mirror symmetry f(−φ_o, φ) = f(φ_o, −φ), which the reading assumes beyond φ_o = 0. θ_o and
// θ_i sit on their nodes and points, so only the φ and φ_o axes are read between points.
TEST(HuangFTable, ReproducesAQuadraticInPhiAndInPhiO) {
    HuangTableSet set;
    set.theta_o_nodes = {-1.0f, -0.3f, 0.4f, 1.1f};
    set.phi_o_nodes = huang_phi_o_nodes(4);
    set.theta_i_count = 8;
    set.phi_count = 16;
    const size_t cells = 4 * 4 * 8 * 16;
    set.values.assign(cells, 1.0f);
    auto phi_of = [&](int j) { return -kPi + kTwoPi * (j + 0.5) / set.phi_count; };
    auto field = [](double phi_o, double phi) { return 5 + phi_o * phi - 0.1 * phi * phi + phi_o * phi_o; };
    for (int q = 0; q < 4; ++q)
        for (int r = 0; r < 4; ++r)
            for (int i = 0; i < 8; ++i)
                for (int j = 0; j < 16; ++j) {
                    const double v = field(set.phi_o_nodes[size_t(q)], phi_of(j)) * (1 + 0.1 * i + r);
                    for (int c = 0; c < 3; ++c) set.f.push_back(float(v * (1 + c)));
                }
    const HuangTable table =
        HuangTable::create(set.theta_o_nodes, set.phi_o_nodes, set.theta_i_count, set.phi_count, set.values).value();
    const HuangFTable f = HuangFTable::create(set).value();
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double h = kTwoPi / set.phi_count;
    for (int n = 0; n < 200; ++n) {
        const int r = int(4 * u(rng)), i = int(8 * u(rng));
        const double phi_o = u(rng) * kPi / 3;                // between the first three φ_o nodes
        const double phi = -kPi + 2 * h + u(rng) * (kTwoPi - 4 * h);  // not across the wrap at ±π
        const HuangTableQuery query = table.locate(direction_of(set.theta_o_nodes[size_t(r)], float(phi_o)));
        const Vec3 wi = direction_of(float(std::asin(f.sin_theta_points()[size_t(i)])), float(phi_o + phi));
        const Rgb got = f.f_cos(query, wi);
        const double want = field(phi_o, phi) * (1 + 0.1 * i + r);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(got[c], want * (1 + c), 2e-4 * want * (1 + c)) << "φ_o " << phi_o << " φ " << phi << " c " << c;
    }
}

TEST(HuangFTable, MirroredViewsGiveMirroredValues) {
    const HuangFiber fiber = make_fiber(0.6f, 0.4f);
    const HuangBakeOptions o = options(6, 3, 12, 16);
    const Baked b = bake(fiber, o);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int n = 0; n < 200; ++n) {
        const Vec3 wo = safe_normalize(Vec3{u(rng), u(rng), u(rng)});
        const Vec3 wi = safe_normalize(Vec3{u(rng), u(rng), u(rng)});
        const Rgb f = b.f.f_cos(b.table.locate(wo), wi);
        const Rgb fy = b.f.f_cos(b.table.locate({wo.x, -wo.y, wo.z}), {wi.x, -wi.y, wi.z});
        const Rgb fz = b.f.f_cos(b.table.locate({wo.x, wo.y, -wo.z}), {wi.x, wi.y, -wi.z});
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(fy[c], f[c], 1e-5f * (1 + f[c]));
            EXPECT_NEAR(fz[c], f[c], 1e-5f * (1 + f[c]));
        }
    }
}

TEST(HuangFTable, IsContinuousAcrossPhiPiAndVanishesAtThePoles) {
    const HuangFiber fiber = make_fiber(1.0f, 0.3f);
    const Baked b = bake(fiber, options(6, 1, 12, 16));
    const HuangTableQuery q = b.table.locate(direction_of(0.3f, 0.0f));
    for (float theta : {-1.0f, -0.2f, 0.4f, 1.2f}) {
        const Rgb below = b.f.f_cos(q, direction_of(theta, float(kPi) - 1e-4f));
        const Rgb above = b.f.f_cos(q, direction_of(theta, float(-kPi) + 1e-4f));
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(below[c], above[c], 1e-3f * (1 + below[c]));
    }
    for (float x : {-1.0f, 1.0f}) {
        const Rgb pole = b.f.f_cos(q, {x, 0.0f, 0.0f});
        EXPECT_EQ(pole.r, 0.0f);
        EXPECT_EQ(pole.g, 0.0f);
        EXPECT_EQ(pole.b, 0.0f);
    }
}

TEST(HuangFTable, RefusesASetWithoutOrWithABadFPart) {
    const HuangFiber fiber = make_fiber(1.0f, 0.3f);
    HuangBakeOptions o = options(2, 1, 4, 4);
    o.f = false;
    HuangTableSet set = bake_huang_table(fiber, o).value();
    EXPECT_FALSE(set.has_f());
    EXPECT_FALSE(HuangFTable::create(set));
    set.f.assign(3 * set.values.size() - 1, 0.0f);
    const Expected<HuangFTable> short_f = HuangFTable::create(set);
    ASSERT_FALSE(short_f);
    EXPECT_NE(short_f.error().message.find("3 values (RGB) per cell"), std::string::npos) << short_f.error().message;
    set.f.assign(3 * set.values.size(), 0.0f);
    set.f[7] = -1.0f;
    const Expected<HuangFTable> negative = HuangFTable::create(set);
    ASSERT_FALSE(negative);
    EXPECT_NE(negative.error().message.find("entry 7"), std::string::npos) << negative.error().message;
}

}  // namespace
}  // namespace hairis
