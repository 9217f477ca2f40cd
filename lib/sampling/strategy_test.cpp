// Every strategy the policy makes samples the density it reports: χ² at θ_r on table nodes,
// between nodes and near grazing, for the far-field direct table, each n_h of the multiple
// table, their mixture, the near-field mixture, the analytic sampler and the uniform one, and
// for a Huang fiber the table strategy (its table mixed with the uniform sphere); and the
// policy refuses what it cannot build, naming it.
#include "sampling/strategy.h"

#include <gtest/gtest.h>

#include "chi2.h"
#include "huang_table_breaks.h"
#include "core/frame.h"
#include "fiber/fiber_spec.h"
#include "sampler_at.h"
#include "fiber/chiang_strands.h"
#include "fiber/principled_hair.h"
#include "sampling/huang_table_sampler.h"
#include "sampling/mixture_sampler.h"
#include "tables/bake.h"
#include "tables/huang_bake.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Sample3;
using testing::SamplerAt;

constexpr int kNodes = 15;  // nodes every 12° at ±6°, ±18°, ..., ±84°
// θ_r (degrees): on a node, between nodes, and near grazing (on the last node, between the
// last two, and past the last node where the outer slice is used).
const double kThetaR[] = {-36.0, 0.0, 30.0, 84.0, -81.0, 87.5};
// table (direct, 5 n_h, mixture, near-field mixture), analytic, uniform
constexpr int kFamily = 6 * (1 + 5 + 1 + 1) + 6 + 6;

struct Fixture {
    std::shared_ptr<const ChiangFiber> fiber;
    SamplingTables tables;
};

const Fixture &fixture() {
    static const Fixture f = [] {
        const FiberSpec spec = FiberSpec::preset("cycles-default").value();
        auto chiang = ChiangFiber::create(to_chiang_params(spec.node).value()).value();
        BakeOptions options;
        options.theta_r_count = kNodes;
        options.theta_i_count = 32;
        options.phi_count = 32;
        const TableSet set = bake_tables(chiang, spec.parameters().value(), options).value();
        return Fixture{std::make_shared<const ChiangFiber>(chiang), SamplingTables::from(set).value()};
    }();
    return f;
}

StrategyInputs inputs(std::shared_ptr<const ChiangFiber> fiber, const SamplingTables *tables, float w, int n_h) {
    StrategyInputs in;
    in.chiang = std::move(fiber);
    in.tables = tables;
    in.multiple_weight = w;
    in.n_h = n_h;
    return in;
}

Vec3 view_at(double theta_r_deg) { return direction_of(float(radians(theta_r_deg)), -float(kHalfPi)); }

void expect_exact(const Sampler &sampler, double theta_r_deg, float h, const std::string &what,
                  const HairInputValues *strand = nullptr, int family = kFamily) {
    const SamplerAt at(sampler, view_at(theta_r_deg), h, strand);
    Chi2Options options;
    options.test_count = family;
    // The table densities are piecewise constant: split the quadrature at their cell edges.
    for (int k = 0; k <= 32; ++k) {
        options.theta_breaks.push_back(-kHalfPi + kPi * k / 32);
        options.phi_breaks.push_back(-kPi + kTwoPi * k / 32);
    }
    // ... and at the near-field table's (linear inside each cell).
    for (int k = 0; k <= NearFieldTableOptions{}.theta_i_cells; ++k)
        options.theta_breaks.push_back(-kHalfPi + kPi * k / NearFieldTableOptions{}.theta_i_cells);
    const auto r = testing::chi2_sampler_test(at, options);
    EXPECT_TRUE(r.passed) << what << " at theta_r " << theta_r_deg << ": " << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << what << " at theta_r " << theta_r_deg;
    EXPECT_EQ(r.failed_samples, 0) << what;
}

std::shared_ptr<const Sampler> made(StrategyKind kind, const StrategyInputs &in) {
    Expected<std::shared_ptr<const Sampler>> s = make_sampler(kind, in);
    EXPECT_TRUE(s.ok()) << s.error().message;
    return s.value();
}

class TableStrategy : public ::testing::TestWithParam<double> {};

TEST_P(TableStrategy, DirectTableIsExact) {
    expect_exact(*made(StrategyKind::Table, inputs(nullptr, &fixture().tables, 0.0f, 2)), GetParam(), 0.0f, "direct table");
}

TEST_P(TableStrategy, EachMultipleTableIsExact) {
    for (int n_h : {1, 2, 4, 8, 16})
        expect_exact(*made(StrategyKind::Table, inputs(nullptr, &fixture().tables, 1.0f, n_h)), GetParam(), 0.0f,
                     "multiple table n_h " + std::to_string(n_h));
}

TEST_P(TableStrategy, MixtureIsExact) {
    expect_exact(*made(StrategyKind::Table, inputs(nullptr, &fixture().tables, 0.3f, 4)), GetParam(), 0.0f, "mixture");
}

TEST_P(TableStrategy, NearFieldMixtureIsExact) {
    // With a Chiang fiber the table strategy follows the near field at h.
    const auto s = made(StrategyKind::Table, inputs(fixture().fiber, &fixture().tables, 0.3f, 4));
    EXPECT_EQ(s->model(), fixture().fiber.get());
    expect_exact(*s, GetParam(), -0.45f, "near-field mixture");
}

TEST_P(TableStrategy, AnalyticIsExact) {
    expect_exact(*made(StrategyKind::Analytic, inputs(fixture().fiber, nullptr, 0.0f, 2)), GetParam(), 0.35f, "analytic");
}

TEST_P(TableStrategy, UniformIsExact) {
    expect_exact(*made(StrategyKind::Uniform, {}), GetParam(), 0.0f, "uniform");
}

INSTANTIATE_TEST_SUITE_P(ThetaR, TableStrategy, ::testing::ValuesIn(kThetaR));

TEST(Strategy, MissingOrMismatchedInputsAreRefusedByName) {
    auto a = make_sampler(StrategyKind::Analytic, {});
    ASSERT_FALSE(a.ok());
    EXPECT_NE(a.error().message.find("Chiang"), std::string::npos);
    auto t = make_sampler(StrategyKind::Table, {});
    ASSERT_FALSE(t.ok());
    EXPECT_NE(t.error().message.find("baked tables"), std::string::npos);
    EXPECT_EQ(t.error().kind, ErrorKind::InvalidTable);
    auto n = make_sampler(StrategyKind::Table, inputs(nullptr, &fixture().tables, 0.5f, 3));
    ASSERT_FALSE(n.ok());
    EXPECT_NE(n.error().message.find("hold n_h 1, 2, 4, 8, 16, not n_h = 3"), std::string::npos) << n.error().message;
    EXPECT_EQ(n.error().kind, ErrorKind::InvalidTable);
    auto w = make_sampler(StrategyKind::Gaussian, inputs(nullptr, nullptr, 2.0f, 2));
    EXPECT_FALSE(w.ok());
    // Tables of another fiber are never used silently.
    ChiangParams other = fixture().fiber->params();
    other.roughness = 0.45f;
    auto stale = make_sampler(StrategyKind::Table,
                              inputs(std::make_shared<const ChiangFiber>(ChiangFiber::create(other).value()),
                                     &fixture().tables, 0.0f, 2));
    ASSERT_FALSE(stale.ok());
    EXPECT_EQ(stale.error().kind, ErrorKind::InvalidTable);
    EXPECT_NE(stale.error().message.find("roughness=0.449999988"), std::string::npos) << stale.error().message;
    EXPECT_STREQ(strategy_name(StrategyKind::Table), "table");
}

TEST(Strategy, AHairShadingRefusesASamplerOfAnotherFiber) {
    const auto s = made(StrategyKind::Analytic, inputs(fixture().fiber, nullptr, 0.0f, 2));
    const auto other = std::make_shared<const ChiangFiber>(ChiangFiber::create({}).value());
    EXPECT_TRUE(HairShading::create(fixture().fiber, s).ok());
    EXPECT_FALSE(HairShading::create(other, s).ok());
    EXPECT_FALSE(HairShading::create(nullptr, s).ok());
    EXPECT_TRUE(HairShading::create(nullptr, made(StrategyKind::Uniform, {})).ok());
}

// Materials whose inputs vary per strand: the tables are baked for the node's own values
// (melanin 0.5, roughness 0.3); strands away from them, in roughness (their M_p is not the
// tables': their own cones), in melanin alone (the tables' rows), or both.
struct StrandCase {
    const char *name;
    float roughness, melanin;  // < 0: the node's own
};
const StrandCase kStrands[] = {{"smoother and darker", 0.15f, 0.9f},
                               {"rougher and lighter", 0.6f, 0.2f},
                               {"darker only", -1.0f, 0.95f}};
const double kStrandThetaR[] = {30.0, -66.0};
// per tilt, strand and θ_r: analytic, table, table mixture
constexpr int kStrandFamily = 2 * 3 * 2 * 3;

struct StrandFixture {
    std::shared_ptr<const ChiangStrands> strands;
    SamplingTables tables;
};

const StrandFixture &strand_fixture(ChiangTilt tilt) {
    auto make = [](ChiangTilt t) {
        PrincipledHairNode node;
        node.parametrization = HairParametrization::Melanin;
        node.melanin = 0.5f;
        node.melanin_redness = 0.5f;
        node.tilt = t;
        auto strands = std::make_shared<const ChiangStrands>(ChiangStrands::create(node).value());
        FiberSpec spec;
        spec.node = node;
        BakeOptions options;
        options.theta_r_count = kNodes;
        options.theta_i_count = 32;
        options.phi_count = 32;
        const TableSet set = bake_tables(*strands->fiber(), spec.parameters().value(), options).value();
        return StrandFixture{strands, SamplingTables::from(set).value()};
    };
    static const StrandFixture incident = make(ChiangTilt::Incident), outgoing = make(ChiangTilt::Outgoing);
    return tilt == ChiangTilt::Incident ? incident : outgoing;
}

HairInputValues strand_inputs(const StrandCase &c) {
    HairInputValues v;
    if (c.roughness >= 0.0f) {
        v.set(HairInput::Roughness, &c.roughness);
        v.set(HairInput::RadialRoughness, &c.roughness);
    }
    v.set(HairInput::Melanin, &c.melanin);
    return v;
}

class StrandStrategy : public ::testing::TestWithParam<ChiangTilt> {};

TEST_P(StrandStrategy, EachStrategyIsExactAtAStrandsOwnFiber) {
    const StrandFixture &f = strand_fixture(GetParam());
    StrategyInputs in;
    in.strands = f.strands;
    in.tables = &f.tables;
    const auto analytic = made(StrategyKind::Analytic, in);
    const auto table = made(StrategyKind::Table, in);
    in.multiple_weight = 0.3f;
    const auto mixture = made(StrategyKind::Table, in);
    for (const auto *s : {analytic.get(), table.get(), mixture.get()}) EXPECT_EQ(s->model(), f.strands.get());
    for (const StrandCase &c : kStrands) {
        const HairInputValues strand = strand_inputs(c);
        for (double theta_r : kStrandThetaR) {
            expect_exact(*analytic, theta_r, 0.35f, std::string("analytic, ") + c.name, &strand, kStrandFamily);
            expect_exact(*table, theta_r, 0.35f, std::string("table, ") + c.name, &strand, kStrandFamily);
            expect_exact(*mixture, theta_r, -0.8f, std::string("table mixture, ") + c.name, &strand, kStrandFamily);
        }
    }
}

TEST_P(StrandStrategy, EachStrategyEvaluatesTheStrandsOwnF) {
    const StrandFixture &f = strand_fixture(GetParam());
    StrategyInputs in;
    in.strands = f.strands;
    in.tables = &f.tables;
    const HairInputValues strand = strand_inputs(kStrands[1]);
    PrincipledHairNode node = f.strands->node();
    node.roughness = node.radial_roughness = kStrands[1].roughness;
    node.melanin = kStrands[1].melanin;
    const ChiangFiber expected = ChiangFiber::create(to_chiang_params(node).value()).value();
    const Vec3 wo = view_at(20.0), wi = direction_of(-0.3f, 2.0f);
    for (StrategyKind kind : {StrategyKind::Uniform, StrategyKind::Analytic, StrategyKind::Table}) {
        const HairShading shading = HairShading::create(f.strands, made(kind, in)).value();
        FiberHit hit{wo, 0.2f};
        hit.inputs = &strand;
        ScratchBuffer scratch;
        const HairBsdf bsdf = shading.at(hit, scratch);
        EXPECT_EQ(bsdf.f(wi).g, expected.at({wo, 0.2f}).f(wi).g) << strategy_name(kind);
        float pdf = 0;
        EXPECT_FLOAT_EQ(bsdf.f_and_pdf(wi, pdf).g, expected.at({wo, 0.2f}).f(wi).g) << strategy_name(kind);
        EXPECT_FLOAT_EQ(pdf, bsdf.pdf(wi)) << strategy_name(kind);
    }
}

INSTANTIATE_TEST_SUITE_P(Tilt, StrandStrategy, ::testing::Values(ChiangTilt::Incident, ChiangTilt::Outgoing),
                         [](const ::testing::TestParamInfo<ChiangTilt> &case_info) {
                             return std::string(case_info.param == ChiangTilt::Incident ? "Cycles34" : "Cycles42");
                         });

TEST(Strategy, ASamplerForStrandsPairsOnlyWithThoseStrands) {
    const StrandFixture &f = strand_fixture(ChiangTilt::Incident);
    StrategyInputs in;
    in.strands = f.strands;
    in.tables = &f.tables;
    const auto table = made(StrategyKind::Table, in);
    // The strands, not their own fiber: the fiber's points carry no strand.
    EXPECT_TRUE(HairShading::create(f.strands, table).ok());
    EXPECT_FALSE(HairShading::create(f.strands->fiber(), table).ok());
    StrategyInputs fiber_only;
    fiber_only.chiang = f.strands->fiber();
    fiber_only.tables = &f.tables;
    EXPECT_FALSE(HairShading::create(f.strands, made(StrategyKind::Table, fiber_only)).ok());
    EXPECT_FALSE(HairShading::create(f.strands, made(StrategyKind::Analytic, fiber_only)).ok());
    // Other strands of the same node are another model.
    const auto twin = std::make_shared<const ChiangStrands>(ChiangStrands::create(f.strands->node()).value());
    EXPECT_FALSE(HairShading::create(twin, table).ok());
    // The tables must be the node's own fiber's, and `chiang` nothing else.
    in.chiang = fixture().fiber;
    EXPECT_FALSE(make_sampler(StrategyKind::Table, in).ok());
    StrategyInputs other;
    other.strands = f.strands;
    other.tables = &fixture().tables;
    auto stale = make_sampler(StrategyKind::Table, other);
    ASSERT_FALSE(stale.ok());
    EXPECT_EQ(stale.error().kind, ErrorKind::InvalidTable);
}

// ---------------------------------------------------------------------------------------------
// Huang

constexpr int kHuangFamily = 4;

struct HuangFixture {
    std::shared_ptr<const HuangFiber> fiber;
    HuangSamplingTable table;
};

std::shared_ptr<const HuangFiber> huang_fiber(float roughness = 0.3f) {
    HuangParams p;  // Blender's default node, the default colour mapped with Huang's roughness
    p.roughness = roughness;
    p.sigma_a = principled_hair::sigma_from_reflectance({0.017513f, 0.005763f, 0.002059f}, roughness);
    return std::make_shared<const HuangFiber>(HuangFiber::create(p).value());
}

const HuangFixture &huang_fixture() {
    static const HuangFixture f = [] {
        auto fiber = huang_fiber();
        HuangBakeOptions o = testing::small_huang_bake();
        o.evaluator = "estimate";
        return HuangFixture{fiber, HuangSamplingTable::from(bake_huang_table(*fiber, o).value()).value()};
    }();
    return f;
}

StrategyInputs huang_inputs(const HuangSamplingTable *table, float uniform_weight = kHuangUniformWeight) {
    StrategyInputs in;
    in.huang = huang_fixture().fiber;
    in.huang_table = std::shared_ptr<const HuangSamplingTable>(std::shared_ptr<const HuangSamplingTable>(), table);  // not owned
    in.huang_uniform_weight = uniform_weight;
    return in;
}

using testing::huang_hit;

TEST(HuangStrategy, TableIsExact) {
    const auto s = made(StrategyKind::Table, huang_inputs(&huang_fixture().table));
    EXPECT_EQ(s->model(), huang_fixture().fiber.get());
    const HuangTable &table = *huang_fixture().table.table;
    // θ_o on a node (33.75°), between nodes, grazing; the major axis in several directions.
    const std::pair<double, double> views[] = {{33.75, 0.0}, {-20.0, 0.7}, {86.0, 2.5}, {-60.0, -1.9}};
    for (const auto &[theta_o, psi] : views) {
        const auto r = testing::chi2_huang_table_sampler(*s, table, theta_o, psi, kHuangFamily);
        std::printf("[chi2] Huang table strategy at theta_o %.2f, psi %.1f: %s\n", theta_o, psi, r.message.c_str());
        EXPECT_TRUE(r.passed) << theta_o << ": " << r.message;
        EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << theta_o;
        EXPECT_EQ(r.failed_samples, 0) << theta_o;
    }
}

// Cells whose baked value is zero while f is not would never be sampled by the table alone;
// the uniform part keeps the density at least u/(4π) everywhere.
TEST(HuangStrategy, TheUniformPartCoversCellsBakedAsZero) {
    const HuangTable &full = *huang_fixture().table.table;
    HuangTableSet set;
    set.parameters = huang_parameters(huang_fixture().fiber->params());
    set.theta_o_nodes = full.theta_o_nodes();
    set.phi_o_nodes = full.phi_o_nodes();
    set.theta_i_count = full.theta_i_count();
    set.phi_count = full.phi_count();
    // The baked values with every other φ cell zeroed.
    for (int q = 0; q < int(set.phi_o_nodes.size()); ++q)
        for (int r = 0; r < int(set.theta_o_nodes.size()); ++r)
            for (int i = 0; i < set.theta_i_count; ++i)
                for (int j = 0; j < set.phi_count; ++j) set.values.push_back(j % 2 ? 0.0f : full.value(q, r, i, j));
    const HuangSamplingTable holes = HuangSamplingTable::from(set).value();
    const auto bare = made(StrategyKind::Table, huang_inputs(&holes, 0.0f));
    const auto guarded = made(StrategyKind::Table, huang_inputs(&holes));
    const FiberHit hit = huang_hit(10.0, 0.4);
    ScratchBuffer scratch;
    const FiberPoint &point = huang_fixture().fiber->prepare(hit, scratch);
    const SamplerPoint &b = bare->at(hit, &point, scratch), &g = guarded->at(hit, &point, scratch);
    int uncovered = 0;
    for (int k = 0; k < 2000; ++k) {
        const Vec3 wi = direction_of(float(-1.5 + 3.0 * ((k * 37) % 2000) / 2000.0), float(-kPi + kTwoPi * k / 2000.0));
        const bool f_positive = luminance(point.f(wi)) > 0.0f;
        if (f_positive && b.pdf(wi) == 0.0f) ++uncovered;
        EXPECT_GE(g.pdf(wi), kHuangUniformWeight * float(kInvFourPi) * (1.0f - 1e-6f));
    }
    EXPECT_GT(uncovered, 100);
}

TEST(HuangStrategy, UniformAndGaussianSampleHuangToo) {
    for (StrategyKind kind : {StrategyKind::Uniform, StrategyKind::Gaussian}) {
        StrategyInputs in = huang_inputs(nullptr);
        const auto s = made(kind, in);
        EXPECT_EQ(s->model(), nullptr);
        EXPECT_TRUE(HairShading::create(huang_fixture().fiber, s).ok()) << strategy_name(kind);
    }
}

TEST(HuangStrategy, RefusesWhatItCannotBuildByName) {
    auto error = [](StrategyKind kind, const StrategyInputs &in) {
        const auto s = make_sampler(kind, in);
        return s.ok() ? Error{"(accepted)"} : s.error();
    };
    const Error analytic = error(StrategyKind::Analytic, huang_inputs(nullptr));
    EXPECT_NE(analytic.message.find("no exact sampler for a Huang fiber"), std::string::npos) << analytic.message;
    EXPECT_NE(analytic.message.find("use table (with a baked Huang table), uniform or gaussian"), std::string::npos);
    const Error none = error(StrategyKind::Table, huang_inputs(nullptr));
    EXPECT_EQ(none.kind, ErrorKind::InvalidTable);
    EXPECT_NE(none.message.find("needs a baked Huang table"), std::string::npos) << none.message;
    // A table baked for another Huang fiber.
    HuangParams other = huang_fixture().fiber->params();
    other.aspect_ratio = 0.6f;
    StrategyInputs stale = huang_inputs(&huang_fixture().table);
    stale.huang = std::make_shared<const HuangFiber>(HuangFiber::create(other).value());
    const Error mismatch = error(StrategyKind::Table, stale);
    EXPECT_EQ(mismatch.kind, ErrorKind::InvalidTable);
    EXPECT_NE(mismatch.message.find("aspect_ratio=0.600000024"), std::string::npos) << mismatch.message;
    StrategyInputs multiple = huang_inputs(&huang_fixture().table);
    multiple.multiple_weight = 0.25f;
    EXPECT_NE(error(StrategyKind::Table, multiple).message.find("multiple_weight must be 0 for a Huang fiber"),
              std::string::npos);
    EXPECT_NE(error(StrategyKind::Table, huang_inputs(&huang_fixture().table, 1.0f)).message.find("huang_uniform_weight"),
              std::string::npos);
    EXPECT_NE(error(StrategyKind::Table, huang_inputs(&huang_fixture().table, -0.1f)).message.find("huang_uniform_weight"),
              std::string::npos);
    StrategyInputs both = huang_inputs(&huang_fixture().table);
    both.chiang = fixture().fiber;
    EXPECT_NE(error(StrategyKind::Uniform, both).message.find("either a Chiang or a Huang fiber"), std::string::npos);
}

}  // namespace
}  // namespace hairis
