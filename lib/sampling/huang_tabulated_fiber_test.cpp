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
#include "fiber/hair_inputs.h"
#include "fiber/huang_strands.h"
#include "sampling/huang_absorption_table.h"
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
    HuangBakeOptions o = testing::small_huang_bake();
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


// Per-strand inputs (HuangStrands): the node is Melanin Concentration at 0.5; strands vary it
// (absorption only: the control variate) or the roughness (the strand's own Cycles eval).
struct StrandFixture {
    PrincipledHairNode node;
    std::shared_ptr<const HuangFiber> fiber;
    std::shared_ptr<const HuangStrands> strands;
    std::shared_ptr<const HuangSamplingTable> table;
    std::shared_ptr<const HuangTabulatedFiber> model;
};

const StrandFixture &strand_fixture() {
    static const StrandFixture f = [] {
        StrandFixture s;
        s.node.parametrization = HairParametrization::Melanin;
        s.node.melanin = 0.5f;
        s.node.roughness = 0.35f;
        s.node.aspect_ratio = 0.7f;
        s.fiber = std::make_shared<const HuangFiber>(HuangFiber::create(to_huang_params(s.node).value()).value());
        s.strands = std::make_shared<const HuangStrands>(HuangStrands::create(s.node, s.fiber).value());
        s.table = bake(*s.fiber);
        s.model = std::make_shared<const HuangTabulatedFiber>(HuangTabulatedFiber::create(s.fiber, s.table, s.strands).value());
        return s;
    }();
    return f;
}

// A strand whose node input `input` is `value`: the inputs that its hits carry, and its own
// fiber, made from the node with the input set directly (not through HairInputValues).
struct Strand {
    Strand(PrincipledHairNode node, HairInput input, float v) : value(v) {
        if (input == HairInput::Melanin) node.melanin = value;
        if (input == HairInput::Roughness) node.roughness = value;
        own = std::make_unique<const HuangFiber>(HuangFiber::create(to_huang_params(node).value()).value());
        inputs.set(input, &value);
    }
    Strand(const Strand &) = delete;
    Strand &operator=(const Strand &) = delete;

    float value;
    HairInputValues inputs;
    std::unique_ptr<const HuangFiber> own;
};

// Running mean and variance of a sequence of draws.
struct Moments {
    double count = 0, sum = 0, sum2 = 0;
    void add(double v) {
        count += 1;
        sum += v;
        sum2 += v * v;
    }
    double mean() const { return sum / count; }
    double variance() const { return std::max(0.0, sum2 / count - mean() * mean()); }
};

// The moments of the green channel of `draws` calls of point.f(wi).
Moments moments(const FiberPoint &point, Vec3 wi, int draws) {
    Moments m;
    for (int n = 0; n < draws; ++n) m.add(point.f(wi).g);
    return m;
}

TEST(HuangTabulatedFiber, AStrandOfOtherMelaninIsTheBakedFCorrectedWithLittleNoise) {
    const StrandFixture &fx = strand_fixture();
    const Strand strand(fx.node, HairInput::Melanin, 0.3f);
    const HuangFiber &own = *strand.own;
    const int draws = 2000;
    const Vec3 directions[] = {safe_normalize(Vec3{-0.3f, 0.6f, 0.7f}), safe_normalize(Vec3{0.4f, -0.2f, 0.9f}),
                               safe_normalize(Vec3{-0.5f, 0.1f, -0.8f})};
    for (const Vec3 wi : directions) {
        FiberHit hit = hit_at(25.0, 0.7);
        hit.seed = 3;
        hit.inputs = &strand.inputs;
        ScratchBuffer scratch;
        const FiberPoint &point = fx.model->prepare(hit, scratch);
        // Draw by draw: the node's table at the hit, plus the strand's Cycles eval minus the
        // node's, both replaying the point's LCG stream (the fibers are made independently of
        // HuangStrands, from the node with the melanin set directly).
        const HuangPoint node_point = fx.fiber->at(hit), own_point = own.at(hit);
        const Vec3 wi_h = node_point.to_huang(wi);
        const Rgb table = fx.model->f_table().f_cos(fx.model->table().locate(node_point.to_huang(hit.wo)), wi_h);
        CyclesLcg lcg = point.huang_point()->lcg();
        Moments cv, plain;
        for (int n = 0; n < draws; ++n) {
            CyclesLcg node_lcg = lcg;
            const Rgb own_eval = own_point.f_estimate(wi, lcg);
            const Rgb expected = table + node_point.f_reflection(wi) + own_eval - node_point.f_estimate(wi, node_lcg);
            const Rgb f = point.f(wi);
            for (int c = 0; c < 3; ++c) ASSERT_NEAR(f[c], expected[c], 1e-6f * (1.0f + std::fabs(expected[c]))) << n;
            cv.add(f.g);
            plain.add(own_eval.g);
        }
        // On the same draws the corrected table is far less noisy than the strand's own eval.
        EXPECT_LT(cv.variance(), 0.5 * plain.variance()) << wi.x << " " << wi.y << " " << wi.z;
    }
}

// With the absorption part a strand of other melanin is shaded without noise under either
// StrandShading, and as close to its own expectation as the node's baked f is to the node's:
// the part moves the baked f to the strand's absorption. A strand below the part's first node
// keeps Cycles' eval.
TEST(HuangTabulatedFiber, AStrandOfOtherMelaninReadsTheAbsorptionPartWithoutNoise) {
    const StrandFixture &fx = strand_fixture();
    HuangBakeOptions o = testing::small_huang_bake();
    o.first_order = o.f_first_order = 3;
    o.second_order = o.f_second_order = 2;
    o.absorption_nodes = huang_absorption_nodes();
    const auto table =
        std::make_shared<const HuangSamplingTable>(HuangSamplingTable::from(bake_huang_table(*fx.fiber, o).value()).value());
    ASSERT_NE(table->absorption, nullptr);
    HuangQuadrature rule;
    rule.first_order = 3;
    rule.second_order = 2;
    rule.tt_order = o.f_tt_order;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (StrandShading shading : {StrandShading::ControlVariate, StrandShading::OwnEval}) {
        const HuangTabulatedFiber model = HuangTabulatedFiber::create(fx.fiber, table, fx.strands, shading).value();
        for (float melanin : {0.25f, 0.75f}) {
            const Strand strand(fx.node, HairInput::Melanin, melanin);
            double strand_error = 0, strand_sum = 0, node_error = 0, node_sum = 0;
            for (int v = 0; v < 6; ++v) {
                FiberHit hit = hit_at(-60.0 + 24.0 * v, 0.4 * v);
                hit.seed = std::uint32_t(v);
                FiberHit node_hit = hit;
                hit.inputs = &strand.inputs;
                ScratchBuffer scratch;
                const FiberPoint &point = model.prepare(hit, scratch);
                const FiberPoint &node_point = model.prepare(node_hit, scratch);
                const HuangPoint own = strand.own->at(hit), node = fx.fiber->at(node_hit);
                const HuangExpectation own_e = strand.own->expectation(own.huang_hit(), rule);
                const HuangExpectation node_e = fx.fiber->expectation(node.huang_hit(), rule);
                for (int n = 0; n < 200; ++n) {
                    const Vec3 wi = safe_normalize(Vec3{u(rng), u(rng), u(rng)});
                    const Rgb f = point.f(wi);
                    ASSERT_EQ(f.g, point.f(wi).g) << "noise at draw " << n;
                    const Rgb want = own_e.f(own.to_huang(wi)), node_want = node_e.f(node.to_huang(wi));
                    const Rgb node_f = node_point.f(wi);
                    for (int c = 0; c < 3; ++c) {
                        strand_error += std::fabs(f[c] - want[c]);
                        strand_sum += want[c];
                        node_error += std::fabs(node_f[c] - node_want[c]);
                        node_sum += node_want[c];
                    }
                }
            }
            EXPECT_LT(strand_error / strand_sum, 1.5 * node_error / node_sum + 0.003)
                << "melanin " << melanin << ": strand " << strand_error / strand_sum << ", node "
                << node_error / node_sum;
        }
    }
    // Melanin 0 gives no absorption, below the part's first node: Cycles' eval, with its noise.
    const HuangTabulatedFiber model = HuangTabulatedFiber::create(fx.fiber, table, fx.strands).value();
    const Strand clear(fx.node, HairInput::Melanin, 0.0f);
    FiberHit hit = hit_at(25.0, 0.7);
    hit.inputs = &clear.inputs;
    ScratchBuffer scratch;
    const FiberPoint &point = model.prepare(hit, scratch);
    const Vec3 wi = safe_normalize(Vec3{-0.3f, 0.6f, 0.7f});
    const Moments m = moments(point, wi, 200);
    EXPECT_GT(m.variance(), 0.0);
}

TEST(HuangTabulatedFiber, OwnEvalShadesAStrandOfOtherMelaninWithItsCyclesEval) {
    // StrandShading::OwnEval: no control variate, the strand's own one-sample Cycles eval,
    // draw by draw (the strand's fiber made from the node with the melanin set directly).
    const StrandFixture &fx = strand_fixture();
    const HuangTabulatedFiber own_eval =
        HuangTabulatedFiber::create(fx.fiber, fx.table, fx.strands, StrandShading::OwnEval).value();
    const Strand strand(fx.node, HairInput::Melanin, 0.3f);
    const HuangFiber &own = *strand.own;
    FiberHit hit = hit_at(25.0, 0.7);
    hit.seed = 3;
    hit.inputs = &strand.inputs;
    ScratchBuffer scratch;
    const FiberPoint &point = own_eval.prepare(hit, scratch);
    const HuangPoint own_point = own.at(hit);
    const Vec3 wi = safe_normalize(Vec3{-0.3f, 0.6f, 0.7f});
    CyclesLcg lcg = point.huang_point()->lcg();
    for (int n = 0; n < 50; ++n) {
        const Rgb expected = own_point.f_estimate(wi, lcg);
        const Rgb f = point.f(wi);
        for (int c = 0; c < 3; ++c) ASSERT_EQ(f[c], expected[c]) << n;
    }
    // A strand without inputs of its own still takes the baked f.
    FiberHit plain = hit;
    plain.inputs = nullptr;
    EXPECT_EQ(own_eval.prepare(plain, scratch).f(wi).g, fx.model->prepare(plain, scratch).f(wi).g);
}

TEST(HuangTabulatedFiber, AStrandOfOtherRoughnessIsShadedWithItsOwnEval) {
    const StrandFixture &fx = strand_fixture();
    const Strand strand(fx.node, HairInput::Roughness, 0.6f);
    const HuangFiber &own = *strand.own;
    FiberHit hit = hit_at(-40.0, 0.2);
    hit.seed = 9;
    hit.inputs = &strand.inputs;
    ScratchBuffer scratch;
    const FiberPoint &point = fx.model->prepare(hit, scratch);
    const HuangPoint own_point = own.at(hit);
    const Vec3 wi = safe_normalize(Vec3{0.2f, 0.5f, 0.8f});
    const Moments m = moments(point, wi, 3000);
    const double exact = own.expectation(own_point.huang_hit()).f(own_point.to_huang(wi)).g;
    EXPECT_NEAR(m.mean(), exact, 5.0 * std::sqrt(m.variance() / 3000) + 1e-4 * exact);
    // Cycles' sampler of the hit is the strand's: its R lobe is the strand's R.
    ASSERT_NE(point.huang_point(), nullptr);
    EXPECT_EQ(point.huang_point()->f_reflection(wi).g, own_point.f_reflection(wi).g);
}

TEST(HuangTabulatedFiber, AStrandWithoutInputsIsTheNodesBakedF) {
    const StrandFixture &fx = strand_fixture();
    const HuangTabulatedFiber without = HuangTabulatedFiber::create(fx.fiber, fx.table).value();
    const HairInputValues none;  // given == 0: the node's own values
    for (const HairInputValues *inputs : {static_cast<const HairInputValues *>(nullptr), &none}) {
        FiberHit hit = hit_at(15.0, 1.2);
        hit.inputs = inputs;
        ScratchBuffer scratch;
        const Vec3 wi = safe_normalize(Vec3{0.1f, -0.7f, 0.4f});
        EXPECT_EQ(fx.model->prepare(hit, scratch).f(wi).b, without.prepare(hit, scratch).f(wi).b);
    }
}

TEST(HuangTabulatedFiber, ReadsTheStrandsInputsAndRefusesStrandsOfAnotherFiber) {
    const StrandFixture &fx = strand_fixture();
    EXPECT_EQ(fx.model->strand_inputs(), fx.strands.get());
    EXPECT_EQ(fixture().model->strand_inputs(), nullptr);
    const Expected<HuangTabulatedFiber> other = HuangTabulatedFiber::create(fixture().fiber, fixture().table, fx.strands);
    ASSERT_FALSE(other);
    EXPECT_NE(other.error().message.find("strands"), std::string::npos) << other.error().message;
}

}  // namespace
}  // namespace hairis
