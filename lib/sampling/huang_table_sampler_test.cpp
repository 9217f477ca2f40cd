// The Huang table sampler at renderer hits: χ² on θ_o nodes, between them and grazing, at
// φ_o on and between nodes and in every quadrant (through the curve normal), for aspect ratios
// 0.5, 0.85 and 1, roughness 0.05–0.8 and lobe multipliers 0 and 1; and the density it samples
// follows f (in every quadrant) far better than the uniform sphere.
#include "sampling/huang_table_sampler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "chi2.h"
#include "huang_table_breaks.h"
#include "core/frame.h"
#include "fiber/principled_hair.h"
#include "sampler_at.h"
#include "tables/huang_bake.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Sample3;

struct FiberCase {
    float aspect, roughness, reflection, transmission, secondary;
};

// Views in degrees: θ_o (renderer frame) and φ_o, the view's azimuth in Huang's frame (set
// through the curve normal; circular fibers ignore it).
struct ViewCase {
    int fiber;
    double theta_o, phi_o;
};

const FiberCase kFibers[] = {
    {0.85f, 0.3f, 1, 1, 1},  // Blender's default
    {0.5f, 0.05f, 1, 1, 1},
    {1.0f, 0.8f, 1, 1, 1},
    {0.85f, 0.3f, 0, 1, 1},  // no R
    {0.5f, 0.3f, 1, 0, 0},   // R only
    {1.0f, 0.05f, 0, 0, 1},  // TRT and TRRT+ only
};

// θ_o nodes of the test tables (8): ±11.25°, ±33.75°, ±56.25°, ±78.75°; φ_o nodes 0°, 45°, 90°.
const ViewCase kViews[] = {
    {0, 33.75, 45}, {0, -20, 20}, {0, 86, 160}, {0, -89, -110}, {0, 60, -20},
    {1, 11.25, 0},  {1, -45, 70}, {1, 84, -160},
    {2, 0, 0},      {2, 56.25, 0}, {2, -87, 0},
    {3, -20, 20},   {3, 70, 100},
    {4, -20, 20},   {4, 40, -135},
    {5, 25, 0},     {5, -70, 0},
};
constexpr int kFamily = int(std::size(kViews));

std::shared_ptr<const HuangFiber> make_fiber(const FiberCase &c) {
    HuangParams p;
    p.aspect_ratio = c.aspect;
    p.roughness = c.roughness;
    p.reflection = c.reflection;
    p.transmission = c.transmission;
    p.secondary_reflection = c.secondary;
    p.sigma_a = principled_hair::sigma_from_reflectance({0.017513f, 0.005763f, 0.002059f}, c.roughness);
    return std::make_shared<const HuangFiber>(HuangFiber::create(p).value());
}

HuangBakeOptions small_table() {
    HuangBakeOptions o = testing::small_huang_bake();
    o.evaluator = "estimate";
    o.f = false;  // the sampler reads the sampling values alone
    return o;
}

struct Baked {
    std::shared_ptr<const HuangFiber> fiber;
    std::shared_ptr<const HuangTableSampler> sampler;
};

const Baked &baked(int k) {
    static const std::vector<Baked> all = [] {
        std::vector<Baked> out;
        for (const FiberCase &c : kFibers) {
            auto fiber = make_fiber(c);
            const HuangTableSet set = bake_huang_table(*fiber, small_table()).value();
            auto table = std::make_shared<const HuangTable>(
                HuangTable::create(set.theta_o_nodes, set.phi_o_nodes, set.theta_i_count, set.phi_count, set.values)
                    .value());
            out.push_back({fiber, std::make_shared<const HuangTableSampler>(HuangTableSampler::create(fiber, table).value())});
        }
        return out;
    }();
    return all[size_t(k)];
}

// The renderer-frame hit whose view has Huang azimuth φ_o: the major axis a = (0, cos ψ, sin ψ)
// gives φ_o = −π/2 − ψ for ω_o = (sin θ, 0, −cos θ).
FiberHit hit_at(double theta_o_deg, double phi_o_deg) {
    const double theta = radians(theta_o_deg), psi = -kHalfPi - radians(phi_o_deg);
    FiberHit hit;
    hit.wo = {float(std::sin(theta)), 0.0f, float(-std::cos(theta))};
    hit.normal = {0.3f, float(std::cos(psi)), float(std::sin(psi))};
    return hit;
}

TEST(HuangTableSampler, ViewsHaveTheIntendedHuangAzimuth) {
    const HuangPoint point = baked(0).fiber->at(hit_at(30, 160));
    const FiberAngles a = angles_of(point.to_huang(point.hit().wo));
    EXPECT_NEAR(a.theta, radians(30.0), 1e-6);
    EXPECT_NEAR(a.phi, radians(160.0), 1e-5);
}

class HuangTableChi2 : public ::testing::TestWithParam<ViewCase> {};

TEST_P(HuangTableChi2, SamplesThePdfItReports) {
    const ViewCase v = GetParam();
    const Baked &b = baked(v.fiber);
    const FiberHit hit = hit_at(v.theta_o, v.phi_o);
    ScratchBuffer scratch;
    const HuangPoint &point = static_cast<const HuangPoint &>(b.fiber->prepare(hit, scratch));
    const SamplerPoint &at = b.sampler->at(hit, &point, scratch);
    // Split the quadrature at the table's cell edges, mapped into the renderer's frame (θ_i edges
    // through each θ_o node's warp).
    const HuangTable &table = b.sampler->table();
    const HuangTableQuery q = table.locate(point.to_huang(hit.wo));
    Chi2Options options;
    options.test_count = kFamily;
    testing::add_huang_table_breaks(options, table, q, point);
    const std::string what = "fiber " + std::to_string(v.fiber) + " at theta_o " + std::to_string(v.theta_o) +
                             ", phi_o " + std::to_string(v.phi_o);
    const auto r = testing::chi2_sampler_test(at, options);
    std::printf("[chi2] %s: %s\n", what.c_str(), r.message.c_str());
    EXPECT_TRUE(r.passed) << what << ": " << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << what;
    EXPECT_EQ(r.failed_samples, 0) << what;
}

INSTANTIATE_TEST_SUITE_P(Views, HuangTableChi2, ::testing::ValuesIn(kViews));

// The sampled density is close to f (the deterministic expectation, a finer rule than the
// bake's) in every quadrant, for a flat ellipse (aspect 0.5, whose f is far from symmetric in
// φ_i − φ_o): the relative variance of luminance(f)/pdf is small where the uniform sphere's is
// large. A table in the wrong frame, fold or azimuth sign is far off f in some quadrant,
// whatever its χ².
TEST(HuangTableSampler, FollowsFInEveryQuadrant) {
    const auto fiber = make_fiber({0.5f, 0.3f, 1, 1, 1});
    HuangBakeOptions o;
    o.theta_o_count = 12;
    o.phi_o_count = 5;
    o.theta_i_count = 24;
    o.phi_count = 32;
    const HuangTableSet set = bake_huang_table(*fiber, o).value();
    const auto table = std::make_shared<const HuangTable>(
        HuangTable::create(set.theta_o_nodes, set.phi_o_nodes, set.theta_i_count, set.phi_count, set.values).value());
    const auto sampler = std::make_shared<const HuangTableSampler>(HuangTableSampler::create(fiber, table).value());
    HuangQuadrature rule;
    rule.first_order = 4;
    rule.second_order = 3;
    for (double phi_o : {25.0, 155.0, -25.0, -155.0, 65.0, -115.0}) {
        const FiberHit hit = hit_at(-35.0, phi_o);
        ScratchBuffer scratch;
        const HuangPoint &point = static_cast<const HuangPoint &>(fiber->prepare(hit, scratch));
        const SamplerPoint &sp = sampler->at(hit, &point, scratch);
        const HuangExpectation f = fiber->expectation(point.huang_hit(), rule);
        std::mt19937 rng(17);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        auto relative_variance = [&](auto &&draw) {
            const int n = 3000;
            double sum = 0, sum2 = 0;
            for (int k = 0; k < n; ++k) {
                const std::optional<DirectionSample> s = draw();
                const double y = s ? luminance(f.f(point.to_huang(s->wi))) / s->pdf : 0.0;
                sum += y;
                sum2 += y * y;
            }
            const double mean = sum / n;
            return (sum2 / n - mean * mean) / (mean * mean);
        };
        const double table_variance = relative_variance([&] { return sp.sample(u(rng), u(rng), u(rng)); });
        const double uniform_variance = relative_variance([&] {
            const float x = 1.0f - 2.0f * u(rng), r = std::sqrt(std::max(0.0f, 1.0f - x * x)), a = float(kTwoPi) * u(rng);
            return std::optional<DirectionSample>(DirectionSample{{x, r * std::cos(a), r * std::sin(a)}, float(kInvFourPi)});
        });
        EXPECT_LT(table_variance, 0.3) << "phi_o " << phi_o;
        EXPECT_GT(uniform_variance, 2.0) << "phi_o " << phi_o;
        std::printf("[follows f] phi_o %6.1f: relative variance table %.4f, uniform %.3f\n", phi_o, table_variance,
                    uniform_variance);
    }
}

TEST(HuangTableSampler, RefusesMissingPieces) {
    const auto table = std::make_shared<const HuangTable>(
        HuangTable::create({0.0f}, {float(kHalfPi)}, 2, 2, std::vector<float>(4, 1.0f)).value());
    const auto no_fiber = HuangTableSampler::create(nullptr, table);
    ASSERT_FALSE(no_fiber.ok());
    EXPECT_NE(no_fiber.error().message.find("no Huang fiber"), std::string::npos);
    const auto no_table = HuangTableSampler::create(baked(0).fiber, nullptr);
    ASSERT_FALSE(no_table.ok());
    EXPECT_NE(no_table.error().message.find("no Huang table"), std::string::npos);
    EXPECT_EQ(baked(0).sampler->model(), baked(0).fiber.get());
}

}  // namespace
}  // namespace hairis
