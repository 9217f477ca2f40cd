#include "tables/bake.h"

#include <gtest/gtest.h>

#include "same_bits.h"

#include <cstring>

#include "fiber/chiang.h"
#include "fiber/fiber_spec.h"
#include "fiber/marschner.h"
#include "sampling/sampling_table.h"

namespace hairis {
namespace {

using testing::same_bits;

BakeOptions small_options() {
    BakeOptions o;
    o.theta_r_count = 6;
    o.theta_i_count = 24;
    o.phi_count = 24;
    o.n_h_values = {1, 4};
    return o;
}

MarschnerFiber blonde() { return MarschnerFiber::create(MarschnerParams::blonde()).value(); }

TEST(Bake, NodesAreCellCentres) {
    const std::vector<float> n = theta_r_nodes(4);
    ASSERT_EQ(n.size(), 4u);
    EXPECT_NEAR(n[0], -3.0 * kPi / 8.0, 1e-6);
    EXPECT_NEAR(n[3], 3.0 * kPi / 8.0, 1e-6);
}

TEST(Bake, ExactTablesAreValidAndDeterministicAcrossThreadCounts) {
    BakeOptions one = small_options(), two = small_options();
    one.threads = 1;
    two.threads = 2;
    const auto a = bake_tables(blonde(), {{"eta", 1.55}}, one);
    const auto b = bake_tables(blonde(), {{"eta", 1.55}}, two);
    ASSERT_TRUE(a.ok()) << a.error().message;
    ASSERT_TRUE(b.ok()) << b.error().message;
    EXPECT_FALSE(a.value().validate());
    EXPECT_EQ(a.value().model, "marschner2003");
    ASSERT_EQ(a.value().direct.size(), b.value().direct.size());
    EXPECT_TRUE(same_bits(a.value().direct, b.value().direct));
    EXPECT_TRUE(same_bits(a.value().multiple, b.value().multiple));
    // Non-trivial content: every slice has mass; the tables build samplers.
    for (int r = 0; r < 6; ++r) {
        double mass = 0;
        for (int i = 0; i < 24; ++i)
            for (int j = 0; j < 24; ++j) mass += a.value().direct_at(r, i, j);
        EXPECT_GT(mass, 0.0) << "slice " << r;
    }
    const TableSet &t = a.value();
    EXPECT_TRUE(DirectTable::create(t.theta_r_nodes, t.theta_i_count, t.phi_count, t.direct).ok());
    EXPECT_TRUE(MultipleTable::create(t.theta_r_nodes, t.n_h_values, t.theta_i_count, t.multiple).ok());
}

TEST(Bake, ChiangTablesAreDeterministicAcrossThreadCounts) {
    // The bake splits the work across threads; the bytes must not depend on how. Odd θ_i
    // count: the rows do not split evenly.
    BakeOptions one = small_options(), two = small_options();
    one.theta_r_count = two.theta_r_count = 3;
    one.theta_i_count = two.theta_i_count = 15;
    one.threads = 1;
    two.threads = 2;
    const ChiangFiber fiber = ChiangFiber::create(ChiangParams{}).value();
    const auto a = bake_tables(fiber, {}, one);
    const auto b = bake_tables(fiber, {}, two);
    ASSERT_TRUE(a.ok()) << a.error().message;
    ASSERT_TRUE(b.ok()) << b.error().message;
    ASSERT_EQ(a.value().direct.size(), b.value().direct.size());
    EXPECT_TRUE(same_bits(a.value().direct, b.value().direct));
    EXPECT_TRUE(same_bits(a.value().multiple, b.value().multiple));
    for (float v : a.value().direct) ASSERT_GT(v, 0.0f);  // every row was computed
}

TEST(Bake, GaussianSourceFollowsTheSeedPdfs) {
    BakeOptions o = small_options();
    o.source = "gaussian";
    o.quadrature_points = 4;
    const auto t = bake_tables(blonde(), {}, o);
    ASSERT_TRUE(t.ok()) << t.error().message;
    // The direct slice peaks on the TT side (φ near ±π) at θ_i near −θ_r.
    const TableSet &s = t.value();
    const int r = 2;  // θ_r = −15°
    int best_i = 0, best_j = 0;
    for (int i = 0; i < s.theta_i_count; ++i)
        for (int j = 0; j < s.phi_count; ++j)
            if (s.direct_at(r, i, j) > s.direct_at(r, best_i, best_j)) best_i = i, best_j = j;
    const double theta_i = -kHalfPi + kPi * (best_i + 0.5) / s.theta_i_count;
    const double phi = -kPi + kTwoPi * (best_j + 0.5) / s.phi_count;
    EXPECT_NEAR(theta_i, -s.theta_r_nodes[r], 2.0 * kPi / s.theta_i_count);
    EXPECT_GT(std::fabs(phi), kPi - 2.0 * kTwoPi / s.phi_count);
}

TEST(Bake, CancelStopsWithAnError) {
    int calls = 0;
    const auto t = bake_tables(blonde(), {}, small_options(), [&](float) { return ++calls < 3; });
    ASSERT_FALSE(t.ok());
    EXPECT_EQ(t.error().message, "cancelled");
    EXPECT_EQ(calls, 3);
}

TEST(Bake, CancelIsPromptBeforeTheSetUp) {
    // Progress 0 comes before the dual-scattering set-up: a cancel there stops at once.
    int calls = 0;
    const auto t = bake_tables(blonde(), {}, small_options(), [&](float fraction) {
        ++calls;
        EXPECT_EQ(fraction, 0.0f);
        return false;
    });
    ASSERT_FALSE(t.ok());
    EXPECT_EQ(t.error().message, "cancelled");
    EXPECT_EQ(calls, 1);
}

TEST(Bake, RefusesBadOptions) {
    BakeOptions o = small_options();
    o.theta_i_count = 0;
    auto t = bake_tables(blonde(), {}, o);
    ASSERT_FALSE(t.ok());
    EXPECT_NE(t.error().message.find("theta_i_count must be an integer in [2, 4096]"), std::string::npos);
    o = small_options();
    o.n_h_values = {4, 2};
    EXPECT_NE(bake_tables(blonde(), {}, o).error().message.find("strictly increasing"), std::string::npos);
    o = small_options();
    o.source = "magic";
    EXPECT_NE(bake_tables(blonde(), {}, o).error().message.find("source must be"), std::string::npos);
    o = small_options();
    o.source = "gaussian";
    o.n_h_values = {3};
    EXPECT_NE(bake_tables(blonde(), {}, o).error().message.find("n_h in {1, 2, 4, 8, 16}"), std::string::npos);
    o = small_options();
    o.theta_r_count = 1000;
    o.theta_i_count = 4000;
    o.phi_count = 4000;
    EXPECT_NE(bake_tables(blonde(), {}, o).error().message.find("cells; at most"), std::string::npos);
}

TEST(Bake, RefusesBeforeBakingWhatNoTableFileCouldHold) {
    // 4M far rows of two φ cells are within the table limits, but padded to the near part's
    // 91 columns they are not an image a file holds: refused before any progress.
    BakeOptions o = small_options();
    o.theta_r_count = 1024;
    o.theta_i_count = 4096;
    o.phi_count = 2;
    o.n_h_values = {1, 2};
    int calls = 0;
    const ChiangFiber fiber = ChiangFiber::create({}).value();
    const auto t = bake_tables(fiber, chiang_parameters({}), o, [&](float) { return ++calls > 0; });
    ASSERT_FALSE(t.ok());
    EXPECT_NE(t.error().message.find("the image would be 91x4194788 pixels"), std::string::npos)
        << t.error().message;
    EXPECT_EQ(calls, 0);
}

}  // namespace
}  // namespace hairis
