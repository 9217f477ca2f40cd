// Every strategy's pdf is the density it samples: χ² at θ_r on table nodes, between nodes and
// near grazing, for the direct table, each n_h of the multiple table and their mixture.
#include "hairis/strategies.h"

#include <gtest/gtest.h>

#include <random>

#include "chi2.h"
#include "hairis/bake.h"
#include "hairis/fiber_spec.h"
#include "hairis/frame.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Sample3;

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

Vec3 view_at(double theta_r_deg) { return direction_of(float(radians(theta_r_deg)), -float(kHalfPi)); }

void expect_exact(const DirectionSampler &sampler, double theta_r_deg, float h, const std::string &what) {
    const Vec3 wo = view_at(theta_r_deg);
    Chi2Options options;
    options.test_count = kFamily;
    // The table densities are piecewise constant: split the quadrature at their cell edges.
    for (int k = 0; k <= 32; ++k) {
        options.theta_breaks.push_back(-kHalfPi + kPi * k / 32);
        options.phi_breaks.push_back(-kPi + kTwoPi * k / 32);
    }
    // ... and at the near-field table's (linear inside each cell).
    for (int k = 0; k <= NearFieldTableOptions{}.theta_i_cells; ++k)
        options.theta_breaks.push_back(-kHalfPi + kPi * k / NearFieldTableOptions{}.theta_i_cells);
    const auto r = testing::chi2_direction_test(
        [&](Sample3 u) -> std::optional<Vec3> {
            auto s = sampler.sample(wo, h, u.u0, u.u1, u.u2);
            return s ? std::optional<Vec3>(s->wi) : std::nullopt;
        },
        [&](Vec3 wi) { return double(sampler.pdf(wi, wo, h)); }, options);
    EXPECT_TRUE(r.passed) << what << " at theta_r " << theta_r_deg << ": " << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3)
        << what << " at theta_r " << theta_r_deg;
    // pdf(sample(u)) is the returned pdf.
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int n = 0; n < 20000; ++n) {
        const auto s = sampler.sample(wo, h, u(rng), u(rng), u(rng));
        if (!s) continue;
        ASSERT_NEAR(sampler.pdf(s->wi, wo, h), s->pdf, 1e-5f * s->pdf) << what << " at theta_r " << theta_r_deg;
    }
}

class TableStrategy : public ::testing::TestWithParam<double> {};

TEST_P(TableStrategy, DirectTableIsExact) {
    auto s = make_sampler(StrategyKind::Table, {nullptr, &fixture().tables, {}, 0.0f, 2, nullptr});
    ASSERT_TRUE(s.ok()) << s.error().message;
    expect_exact(*s.value(), GetParam(), 0.0f, "direct table");
}

TEST_P(TableStrategy, EachMultipleTableIsExact) {
    for (int n_h : {1, 2, 4, 8, 16}) {
        auto s = make_sampler(StrategyKind::Table, {nullptr, &fixture().tables, {}, 1.0f, n_h, nullptr});
        ASSERT_TRUE(s.ok()) << s.error().message;
        expect_exact(*s.value(), GetParam(), 0.0f, "multiple table n_h " + std::to_string(n_h));
    }
}

TEST_P(TableStrategy, MixtureIsExact) {
    auto s = make_sampler(StrategyKind::Table, {nullptr, &fixture().tables, {}, 0.3f, 4, nullptr});
    ASSERT_TRUE(s.ok()) << s.error().message;
    expect_exact(*s.value(), GetParam(), 0.0f, "mixture");
}

TEST_P(TableStrategy, NearFieldMixtureIsExact) {
    // With a Chiang fiber the table strategy follows the near field at h.
    auto s = make_sampler(StrategyKind::Table, {fixture().fiber, &fixture().tables, {}, 0.3f, 4, nullptr});
    ASSERT_TRUE(s.ok()) << s.error().message;
    const auto *table = dynamic_cast<const TableSampler *>(s.value().get());
    ASSERT_NE(table, nullptr);
    ASSERT_NE(table->near_field(), nullptr);
    expect_exact(*s.value(), GetParam(), -0.45f, "near-field mixture");
}

TEST_P(TableStrategy, AnalyticIsExact) {
    auto s = make_sampler(StrategyKind::Analytic, {fixture().fiber, nullptr, {}, 0.0f, 2, nullptr});
    ASSERT_TRUE(s.ok()) << s.error().message;
    expect_exact(*s.value(), GetParam(), 0.35f, "analytic");
}

TEST_P(TableStrategy, UniformIsExact) {
    auto s = make_sampler(StrategyKind::Uniform, {});
    ASSERT_TRUE(s.ok());
    expect_exact(*s.value(), GetParam(), 0.0f, "uniform");
}

INSTANTIATE_TEST_SUITE_P(ThetaR, TableStrategy, ::testing::ValuesIn(kThetaR));

TEST(Strategies, MissingInputsAreReported) {
    auto a = make_sampler(StrategyKind::Analytic, {});
    ASSERT_FALSE(a.ok());
    EXPECT_NE(a.error().message.find("Chiang"), std::string::npos);
    auto t = make_sampler(StrategyKind::Table, {});
    ASSERT_FALSE(t.ok());
    EXPECT_NE(t.error().message.find("baked tables"), std::string::npos);
    auto n = make_sampler(StrategyKind::Table, {nullptr, &fixture().tables, {}, 0.5f, 3, nullptr});
    EXPECT_FALSE(n.ok());
    auto w = make_sampler(StrategyKind::Gaussian, {nullptr, nullptr, {}, 2.0f, 2, nullptr});
    EXPECT_FALSE(w.ok());
    EXPECT_STREQ(strategy_name(StrategyKind::Table), "table");
}

}  // namespace
}  // namespace hairis
