// Huang hair shaded with its baked f: deterministic, R exactly Cycles' R, the rest the table's
// interpolated expectation; near-field hits keep Cycles' eval; the table sampler built on it
// samples the density it reports (χ²); and a table without f or for other parameters is refused.
#include "sampling/huang_tabulated_fiber.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "chi2.h"
#include "huang_table_breaks.h"
#include "core/frame.h"
#include "fiber/principled_hair.h"
#include "sampling/hair_bsdf.h"
#include "sampling/huang_table_sampler.h"
#include "sampling/strategy.h"
#include "tables/huang_bake.h"

namespace hairis {
namespace {

std::shared_ptr<const HuangFiber> make_fiber(float aspect, float roughness) {
    HuangParams p;
    p.aspect_ratio = aspect;
    p.roughness = roughness;
    p.sigma_a = principled_hair::sigma_from_reflectance({0.017513f, 0.005763f, 0.002059f}, roughness);
    return std::make_shared<const HuangFiber>(HuangFiber::create(p).value());
}

std::shared_ptr<const HuangSamplingTable> bake(const HuangFiber &fiber, bool with_f = true) {
    HuangBakeOptions o;
    o.theta_o_count = 8;
    o.phi_o_count = 3;
    o.theta_i_count = 16;
    o.phi_count = 24;
    o.first_order = o.f_first_order = 3;
    o.second_order = o.f_second_order = 2;
    o.f = with_f;
    return std::make_shared<const HuangSamplingTable>(HuangSamplingTable::from(bake_huang_table(fiber, o).value()).value());
}

struct Fixture {
    std::shared_ptr<const HuangFiber> fiber;
    std::shared_ptr<const HuangSamplingTable> table;
    std::shared_ptr<const HuangTabulatedFiber> model;
};

const Fixture &fixture() {
    static const Fixture f = [] {
        auto fiber = make_fiber(0.7f, 0.35f);
        auto table = bake(*fiber);
        auto model = std::make_shared<const HuangTabulatedFiber>(HuangTabulatedFiber::create(fiber, table).value());
        return Fixture{fiber, table, model};
    }();
    return f;
}

// A renderer hit at θ_o (degrees) whose curve normal puts the major axis at ψ from y.
FiberHit hit_at(double theta_o_deg, double psi, float h = 0.0f, float coverage = 1.0f) {
    const double t = radians(theta_o_deg);
    FiberHit hit;
    hit.wo = {float(std::sin(t)), 0.0f, float(-std::cos(t))};
    hit.normal = {0.2f, float(std::cos(psi)), float(std::sin(psi))};
    hit.h = h;
    hit.pixel_coverage = coverage;
    return hit;
}

TEST(HuangTabulatedFiber, FIsRPlusTheBakedRestAndHasNoNoise) {
    const Fixture &fx = fixture();
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    ScratchBuffer scratch;
    for (int n = 0; n < 50; ++n) {
        FiberHit hit = hit_at(80.0 * u(rng), 3.0 * u(rng));
        hit.seed = std::uint32_t(n);
        const Vec3 wi = safe_normalize(Vec3{u(rng), u(rng), u(rng)});
        const auto &point = static_cast<const HuangTabulatedPoint &>(fx.model->prepare(hit, scratch));
        // Another seed at the same hit: the same f (Cycles' eval would draw other chains).
        FiberHit reseeded = hit;
        reseeded.seed = 1000u + std::uint32_t(n);
        const FiberPoint &again = fx.model->prepare(reseeded, scratch);
        EXPECT_EQ(point.f(wi).r, again.f(wi).r);
        // R from the expectation (independent of f_reflection's code path), the rest from the table.
        const HuangPoint cycles = fx.fiber->at(hit);
        const HuangExpectation e = fx.fiber->expectation(cycles.huang_hit());
        const Rgb r = e.lobes(cycles.to_huang(wi))[0];
        const Rgb rest = fx.table->f->f_cos(fx.table->table->locate(cycles.to_huang(hit.wo)), cycles.to_huang(wi));
        const Rgb f = point.f(wi);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], r[c] + rest[c], 1e-5f * (1.0f + f[c])) << n;
    }
}

TEST(HuangTabulatedFiber, NearFieldHitsKeepCyclesEval) {
    const Fixture &fx = fixture();
    ScratchBuffer scratch;
    // Pixel coverage 0.1: the projected radius exceeds it, Cycles' near field.
    FiberHit hit = hit_at(20.0, 0.4, 0.3f, 0.1f);
    hit.seed = 5;
    const FiberPoint &point = fx.model->prepare(hit, scratch);
    const HuangPoint cycles = fx.fiber->at(hit);
    ASSERT_TRUE(cycles.near_field());
    const Vec3 wi = safe_normalize(Vec3{-0.2f, -0.5f, 0.6f});
    EXPECT_EQ(point.f(wi).g, cycles.f(wi).g);  // the same seed: the same draw
}

TEST(HuangTabulatedFiber, TheTableSamplerOnItSamplesThePdfItReports) {
    const Fixture &fx = fixture();
    const auto sampler = std::make_shared<const HuangTableSampler>(HuangTableSampler::create(fx.model).value());
    ASSERT_EQ(sampler->model(), fx.model.get());
    // On a θ_o node (33.75°), between nodes and grazing.
    const double views[][2] = {{33.75, 0.0}, {-20.0, 1.1}, {87.0, -2.5}};
    for (const auto &v : views) {
        const FiberHit hit = hit_at(v[0], v[1]);
        ScratchBuffer scratch;
        const FiberPoint &point = fx.model->prepare(hit, scratch);
        const SamplerPoint &at = sampler->at(hit, &point, scratch);
        testing::Chi2Options options;
        options.test_count = int(std::size(views));
        // The density is piecewise constant: split the quadrature at the cell edges, mapped into
        // the renderer's frame (θ_i edges through each θ_o node's warp).
        const HuangPoint &cycles = static_cast<const HuangTabulatedPoint &>(point).huang();
        const HuangTableQuery &q = static_cast<const HuangTabulatedPoint &>(point).query();
        const HuangTable &table = fx.model->table();
        testing::add_huang_table_breaks(options, table, q, cycles);
        const testing::Chi2Result r = testing::chi2_direction_test(
            [&](testing::Sample3 s) -> std::optional<Vec3> {
                const auto d = at.sample(s.u0, s.u1, s.u2);
                if (!d) return std::nullopt;
                return d->wi;
            },
            [&](Vec3 wi) { return double(at.pdf(wi)); }, options);
        EXPECT_TRUE(r.passed) << v[0] << " " << v[1] << ": " << r.message;
        EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
        EXPECT_EQ(r.failed_samples, 0);
    }
}

TEST(HuangTabulatedFiber, HairShadingUsesTheBakedFWhereTheTableHasIt) {
    const Fixture &fx = fixture();
    StrategyInputs in;
    in.huang = fx.fiber;
    in.huang_table = fx.table;
    const HairShading with_f = make_hair_shading(StrategyKind::Table, in, fx.fiber).value();
    EXPECT_NE(dynamic_cast<const HuangTabulatedFiber *>(with_f.model()), nullptr);
    in.huang_table = bake(*fx.fiber, false);
    const HairShading without_f = make_hair_shading(StrategyKind::Table, in, fx.fiber).value();
    EXPECT_EQ(without_f.model(), fx.fiber.get());
    const HairShading uniform = make_hair_shading(StrategyKind::Uniform, in, fx.fiber).value();
    EXPECT_EQ(uniform.model(), fx.fiber.get());
    // The baked f makes a BSDF sample's weight a function of the direction alone.
    const FiberHit hit = hit_at(10.0, 0.3);
    ScratchBuffer scratch;
    const HairBsdf bsdf = with_f.at(hit, scratch);
    const auto s = bsdf.sample(0.3f, 0.6f, 0.2f);
    ASSERT_TRUE(s);
    EXPECT_EQ(s->f.r, bsdf.f(s->wi).r);
}

TEST(HuangTabulatedFiber, RefusesMissingPartsAndOtherParameters) {
    const Fixture &fx = fixture();
    EXPECT_FALSE(HuangTabulatedFiber::create(nullptr, fx.table));
    EXPECT_FALSE(HuangTabulatedFiber::create(fx.fiber, nullptr));
    const Expected<HuangTabulatedFiber> no_f = HuangTabulatedFiber::create(fx.fiber, bake(*fx.fiber, false));
    ASSERT_FALSE(no_f);
    EXPECT_NE(no_f.error().message.find("no baked f"), std::string::npos) << no_f.error().message;
    const Expected<HuangTabulatedFiber> other = HuangTabulatedFiber::create(make_fiber(0.7f, 0.5f), fx.table);
    ASSERT_FALSE(other);
    EXPECT_NE(other.error().message.find("baked for"), std::string::npos) << other.error().message;
}

}  // namespace
}  // namespace hairis
