// HuangTable on synthetic values (no fiber): χ² between nodes and in every quadrant, the fold,
// the bilinear mixture of warped slices (against a formula computed here), the warp itself,
// lobes that follow the view between nodes, a one-node (circular) table, a one-cell table
// against its closed form, and validation.
#include "sampling/huang_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "chi2.h"
#include "core/frame.h"
#include "sampling/table_set.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Sample3;

constexpr int kThetaO = 5, kPhiO = 3, kThetaI = 12, kPhi = 16;
constexpr int kChi2Tests = 7;  // Chi2InEveryQuadrant 6 + SingleNodeTurnsWithTheView 1

std::vector<float> theta_o_nodes() {
    std::vector<float> n;
    for (int r = 0; r < kThetaO; ++r) n.push_back(float(radians(-60.0 + 30.0 * r)));
    return n;
}
std::vector<float> phi_o_nodes(int count) {
    if (count == 1) return {float(kHalfPi)};
    std::vector<float> n;
    for (int q = 0; q < count; ++q) n.push_back(float(kHalfPi * q / (count - 1)));
    return n;
}

// A lobe whose position and width change with both view nodes, plus zero cells.
std::vector<float> synthetic_values(int phi_o_count) {
    std::vector<float> v;
    for (int q = 0; q < phi_o_count; ++q)
        for (int r = 0; r < kThetaO; ++r)
            for (int i = 0; i < kThetaI; ++i)
                for (int j = 0; j < kPhi; ++j) {
                    const double theta = -kHalfPi + kPi * (i + 0.5) / kThetaI, phi = -kPi + kTwoPi * (j + 0.5) / kPhi;
                    const double centre = 0.4 * q - 1.0 + 0.3 * r, width = 0.5 + 0.2 * q;
                    const double x = std::exp(-sqr(phi - centre) / (2 * sqr(width)) - sqr(theta + 0.2 * r - 0.4) / 0.3);
                    v.push_back(x < 0.02 ? 0.0f : float(x + 0.1 * (i % 3)));
                }
    return v;
}

const HuangTable &table(int phi_o_count = kPhiO) {
    static const HuangTable three =
        HuangTable::create(theta_o_nodes(), phi_o_nodes(kPhiO), kThetaI, kPhi, synthetic_values(kPhiO)).value();
    static const HuangTable one =
        HuangTable::create(theta_o_nodes(), phi_o_nodes(1), kThetaI, kPhi, synthetic_values(1)).value();
    return phi_o_count == 1 ? one : three;
}

// The azimuth in Huang's frame of relative azimuth φ of the query's folded frame.
double unfolded_azimuth(const HuangTableQuery &q, double phi) {
    const double a = std::atan2(double(q.sin_phi_o), double(q.cos_phi_o)) + phi;
    return std::atan2(q.sign_z * std::sin(a), q.sign_y * std::cos(a));
}

void expect_chi2(const HuangTable &t, Vec3 wo, const std::string &what) {
    const HuangTableQuery q = t.locate(wo);
    Chi2Options options;
    options.test_count = kChi2Tests;
    // The density jumps at each weighted node's cell edges, mapped back through its warp, and
    // its Jacobian at the warp's anchor.
    for (int n = 0; n < 2; ++n)
        for (int k = 0; k <= kThetaI; ++k) options.theta_breaks.push_back(q.warp[n].from_node(-kHalfPi + kPi * k / kThetaI));
    options.theta_breaks.push_back(q.warp[0].anchor);
    for (int k = 0; k <= kPhi; ++k) options.phi_breaks.push_back(unfolded_azimuth(q, -kPi + kTwoPi * k / kPhi));
    const auto r = testing::chi2_direction_test(
        [&](Sample3 u) -> std::optional<Vec3> {
            const auto s = t.sample(q, u.u0, u.u1, u.u2);
            if (!s) return std::nullopt;
            EXPECT_EQ(s->pdf, t.pdf(q, s->wi)) << what;
            return s->wi;
        },
        [&](Vec3 wi) { return double(t.pdf(q, wi)); }, options);
    std::printf("[chi2] %s: %s\n", what.c_str(), r.message.c_str());
    EXPECT_TRUE(r.passed) << what << ": " << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << what;
    EXPECT_EQ(r.failed_samples, 0) << what;
}

// Between θ_o and φ_o nodes in each of the four quadrants, past the outer θ_o node, and on a
// node of both.
TEST(HuangTable, Chi2InEveryQuadrant) {
    const HuangTable &t = table();
    const double theta = radians(-20.0), phi = radians(27.0);
    expect_chi2(t, direction_of(float(theta), float(phi)), "first quadrant");
    expect_chi2(t, direction_of(float(theta), float(kPi - phi)), "second quadrant");
    expect_chi2(t, direction_of(float(theta), float(phi - kPi)), "third quadrant");
    expect_chi2(t, direction_of(float(theta), float(-phi)), "fourth quadrant");
    expect_chi2(t, direction_of(float(radians(80.0)), float(radians(-100.0))), "past the last theta_o node");
    expect_chi2(t, direction_of(float(radians(30.0)), float(kHalfPi / 2)), "on nodes");
}

// One φ_o node (a circular fiber): the density turns with the view about the tangent.
TEST(HuangTable, SingleNodeTurnsWithTheView) {
    const HuangTable &t = table(1);
    expect_chi2(t, direction_of(0.3f, -2.0f), "single node");
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const Vec3 wo = direction_of(0.3f, 0.4f);
    for (float turn : {0.7f, 2.9f, -1.3f}) {
        const HuangTableQuery a = t.locate(wo), b = t.locate(direction_of(0.3f, 0.4f + turn));
        for (int k = 0; k < 50; ++k) {
            const auto s = t.sample(a, u(rng), u(rng), u(rng));
            ASSERT_TRUE(s.has_value());
            const FiberAngles w = angles_of(s->wi);
            EXPECT_NEAR(t.pdf(b, direction_of(w.theta, w.phi + turn)), s->pdf, 1e-4f * s->pdf) << turn;
        }
    }
}

// The four mirror images of a view sample the mirror images of each other's directions from
// the same numbers, with the same density.
TEST(HuangTable, MirroredViewsSampleMirroredDirections) {
    const HuangTable &t = table();
    const Vec3 wo = direction_of(0.2f, 0.5f);
    const HuangTableQuery q = t.locate(wo);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (float sy : {1.0f, -1.0f})
        for (float sz : {1.0f, -1.0f}) {
            const HuangTableQuery m = t.locate({wo.x, sy * wo.y, sz * wo.z});
            EXPECT_EQ(m.sign_y, sy);
            EXPECT_EQ(m.sign_z, sz);
            for (int k = 0; k < 100; ++k) {
                const float u0 = u(rng), u1 = u(rng), u2 = u(rng);
                const auto a = t.sample(q, u0, u1, u2), b = t.sample(m, u0, u1, u2);
                ASSERT_TRUE(a && b);
                EXPECT_EQ(b->wi.x, a->wi.x);
                EXPECT_EQ(b->wi.y, sy * a->wi.y);
                EXPECT_EQ(b->wi.z, sz * a->wi.z);
                EXPECT_EQ(b->pdf, a->pdf);
            }
        }
}

// The warp of θ_i from a view at θ_o onto the node θ_n, and its Jacobian dΩ_n/dΩ, written out
// here: piecewise linear, −π/2 ↦ −π/2, −θ_o ↦ −θ_n, π/2 ↦ π/2.
double warp(double theta_o, double theta_n, double theta_i) {
    return theta_i < -theta_o ? -kHalfPi + (theta_i + kHalfPi) * (kHalfPi - theta_n) / (kHalfPi - theta_o)
                              : kHalfPi - (kHalfPi - theta_i) * (kHalfPi + theta_n) / (kHalfPi + theta_o);
}
double warp_jacobian(double theta_o, double theta_n, double theta_i) {
    const double slope = theta_i < -theta_o ? (kHalfPi - theta_n) / (kHalfPi - theta_o) : (kHalfPi + theta_n) / (kHalfPi + theta_o);
    return slope * std::cos(warp(theta_o, theta_n, theta_i)) / std::cos(theta_i);
}

// Between nodes the density is the bilinear mixture of the four neighbouring node views'
// densities, each at the direction warped onto its θ_o node (same relative azimuth) times the
// warp's Jacobian, with weights from the node positions.
TEST(HuangTable, BetweenNodesThePdfIsTheBilinearMixtureOfWarpedNodes) {
    const HuangTable &t = table();
    const double theta_o = double(float(radians(-20.0))), phi_o = radians(27.0);
    const double tt = (theta_o - double(float(radians(-30.0)))) / (double(float(radians(0.0))) - double(float(radians(-30.0))));
    const double ss = phi_o / (kHalfPi / 2);
    const HuangTableQuery q = t.locate(direction_of(float(theta_o), float(phi_o)));
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int k = 0; k < 200; ++k) {
        const float sin_i = 2.0f * u(rng) - 1.0f, rel = float(kTwoPi) * (u(rng) - 0.5f);
        const double theta_i = std::asin(double(sin_i));
        double mixture = 0.0;
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) {
                const double node_theta = double(float(radians(-30.0 + 30.0 * a))), node_phi = kHalfPi / 2 * b;
                const HuangTableQuery n = t.locate(direction_of(float(node_theta), float(node_phi)));
                const double w = (a ? tt : 1 - tt) * (b ? ss : 1 - ss);
                const double warped = warp(theta_o, node_theta, theta_i);
                mixture += w * t.pdf(n, direction_of(float(warped), float(node_phi + rel))) *
                           warp_jacobian(theta_o, node_theta, theta_i);
            }
        EXPECT_NEAR(t.pdf(q, direction_of(float(theta_i), float(phi_o + rel))), mixture, 2e-4 * mixture + 1e-6) << k;
    }
}

TEST(HuangTable, WarpFixesThePolesMapsTheConeAndKeepsSolidAngle) {
    const ThetaWarp w = ThetaWarp::between(0.3, 0.5);
    EXPECT_NEAR(w.to_node(-kHalfPi), -kHalfPi, 1e-12);
    EXPECT_NEAR(w.to_node(kHalfPi), kHalfPi, 1e-12);
    EXPECT_NEAR(w.to_node(-0.3), -0.5, 1e-12);
    for (double x : {-1.5, -0.9, -0.31, 0.2, 1.4}) {
        EXPECT_NEAR(w.from_node(w.to_node(x)), x, 1e-12);
        EXPECT_NEAR(w.jacobian(x), warp_jacobian(0.3, 0.5, x), 1e-12);
    }
    // A bijection of the sphere: ∫ (dΩ_node/dΩ) dΩ = 4π, i.e. ∫ J cos θ dθ = 2.
    double integral = 0.0;
    const int n = 200000;
    for (int k = 0; k < n; ++k) {
        const double x = -kHalfPi + kPi * (k + 0.5) / n;
        integral += w.jacobian(x) * std::cos(x) * kPi / n;
    }
    EXPECT_NEAR(integral, 2.0, 1e-5);
    // Views along the fiber keep bounded slopes (the anchor is clamped inside the poles).
    const HuangTableQuery q = table().locate(direction_of(float(kHalfPi), 0.3f));
    EXPECT_LT(q.warp[0].below, 10.0);
    EXPECT_LT(q.warp[0].above, 10.0);
}

// A narrow lobe on each node's specular cone θ_i = −θ_node: between two nodes the sampled θ_i
// follow the view's cone −θ_o, not the nodes'.
TEST(HuangTable, LobesFollowTheViewBetweenNodes) {
    std::vector<float> values;
    const int cells = 90;
    for (int q = 0; q < 2; ++q)
        for (int r = 0; r < kThetaO; ++r)
            for (int i = 0; i < cells; ++i)
                for (int j = 0; j < 8; ++j) {
                    const double theta = -kHalfPi + kPi * (i + 0.5) / cells;
                    values.push_back(float(std::exp(-sqr(theta + theta_o_nodes()[size_t(r)]) / (2 * sqr(0.02)))));
                }
    const HuangTable t = HuangTable::create(theta_o_nodes(), phi_o_nodes(2), cells, 8, values).value();
    for (double theta_o : {-0.4, 0.1, 0.7}) {
        const HuangTableQuery q = t.locate(direction_of(float(theta_o), 0.4f));
        std::mt19937 rng(21);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        int near_cone = 0;
        for (int k = 0; k < 4000; ++k) near_cone += std::fabs(std::asin(t.sample(q, u(rng), u(rng), u(rng))->wi.x) + theta_o) < 0.08;
        EXPECT_GT(near_cone, 0.95 * 4000) << theta_o;
    }
}

// All mass in one cell: every sample lands in it (relative to the view), with the density 1
// over the cell's solid angle.
TEST(HuangTable, OneCellIsUniformOverItsSolidAngle) {
    const int i = 7, j = 3;
    std::vector<float> values(size_t(kPhiO) * kThetaO * kThetaI * kPhi, 0.0f);
    for (int rr = 0; rr < kThetaO; ++rr)
        for (int qq = 0; qq < kPhiO; ++qq) values[((size_t(qq) * kThetaO + rr) * kThetaI + i) * kPhi + j] = 2.5f;
    const HuangTable t = HuangTable::create(theta_o_nodes(), phi_o_nodes(kPhiO), kThetaI, kPhi, values).value();
    const double s0 = std::sin(-kHalfPi + kPi * i / kThetaI), s1 = std::sin(-kHalfPi + kPi * (i + 1) / kThetaI);
    const double expected = 1.0 / ((s1 - s0) * kTwoPi / kPhi);
    const double phi_o = 0.3;
    const HuangTableQuery query = t.locate(direction_of(0.0f, float(phi_o)));  // on a θ_o node: no warp
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int k = 0; k < 1000; ++k) {
        const auto s = t.sample(query, u(rng), u(rng), u(rng));
        ASSERT_TRUE(s.has_value());
        EXPECT_NEAR(s->pdf, expected, 1e-5 * expected);
        EXPECT_GE(s->wi.x, float(s0) - 1e-6f);
        EXPECT_LE(s->wi.x, float(s1) + 1e-6f);
        const double rel = wrap_angle(std::atan2(double(s->wi.z), double(s->wi.y)) - phi_o);
        EXPECT_GE(rel, -kPi + kTwoPi * j / kPhi - 1e-5);
        EXPECT_LE(rel, -kPi + kTwoPi * (j + 1) / kPhi + 1e-5);
    }
    EXPECT_EQ(t.pdf(query, direction_of(0.0f, float(phi_o + 2.0))), 0.0f);
}

TEST(HuangTable, RefusesInvalidInputByName) {
    const std::vector<float> th = theta_o_nodes(), ph = phi_o_nodes(kPhiO), v = synthetic_values(kPhiO);
    auto message = [](const Expected<HuangTable> &t) { return t.ok() ? std::string("(accepted)") : t.error().message; };
    EXPECT_NE(message(HuangTable::create(th, ph, kThetaI, kPhi, std::vector<float>(v.begin(), v.end() - 1)))
                  .find("values must hold"),
              std::string::npos);
    EXPECT_NE(message(HuangTable::create({0.2f, 0.1f}, ph, kThetaI, kPhi, v)).find("theta_o_nodes must be strictly increasing"),
              std::string::npos);
    EXPECT_NE(message(HuangTable::create(th, {0.0f, 2.0f}, kThetaI, kPhi, v)).find("phi_o_nodes[1] must be in [0, "),
              std::string::npos);
    EXPECT_NE(message(HuangTable::create(th, {}, kThetaI, kPhi, v)).find("phi_o_nodes count"), std::string::npos);
    EXPECT_NE(message(HuangTable::create(th, ph, 0, kPhi, v)).find("theta_i_count"), std::string::npos);
    std::vector<float> bad = v;
    bad[((size_t(2) * kThetaO + 1) * kThetaI + 4) * kPhi + 5] = std::nanf("");
    EXPECT_NE(message(HuangTable::create(th, ph, kThetaI, kPhi, bad))
                  .find("values[phi_o node 2, theta_o node 1, theta_i cell 4, phi cell 5] must be finite and >= 0"),
              std::string::npos)
        << message(HuangTable::create(th, ph, kThetaI, kPhi, bad));
    bad[((size_t(2) * kThetaO + 1) * kThetaI + 4) * kPhi + 5] = -1.0f;
    EXPECT_FALSE(HuangTable::create(th, ph, kThetaI, kPhi, bad).ok());
    // Sizes that could not be allocated are refused from the counts alone.
    std::vector<float> many_nodes(1000);
    for (size_t k = 0; k < many_nodes.size(); ++k) many_nodes[k] = float(-1.5 + 3.0 * k / 1000.0);
    const std::string huge = message(HuangTable::create(many_nodes, phi_o_nodes(200), 4096, 4096, {}));
    EXPECT_NE(huge.find("at most"), std::string::npos) << huge;
}

// A set of the synthetic values (no f part).
HuangTableSet synthetic_set() {
    HuangTableSet set;
    set.parameters = huang_parameters(HuangParams{});
    set.theta_o_nodes = theta_o_nodes();
    set.phi_o_nodes = phi_o_nodes(kPhiO);
    set.theta_i_count = kThetaI;
    set.phi_count = kPhi;
    set.values = synthetic_values(kPhiO);
    return set;
}

TEST(HuangSamplingTable, RefusesAnotherModelAndKeepsTheParameters) {
    HuangTableSet set = synthetic_set();
    const Expected<HuangSamplingTable> ok = HuangSamplingTable::from(set);
    ASSERT_TRUE(ok.ok()) << ok.error().message;
    EXPECT_EQ(ok.value().parameters, canonical_parameters(huang_parameters(HuangParams{})));
    EXPECT_NE(ok.value().parameters.find("aspect_ratio=0.850000024"), std::string::npos) << ok.value().parameters;
    set.model = "chiang2016";
    const Expected<HuangSamplingTable> other = HuangSamplingTable::from(set);
    ASSERT_FALSE(other.ok());
    EXPECT_EQ(other.error().kind, ErrorKind::InvalidTable);
    set.model = "huang2022";
    set.values.pop_back();
    const Expected<HuangSamplingTable> short_values = HuangSamplingTable::from(set);
    ASSERT_FALSE(short_values.ok());
    EXPECT_EQ(short_values.error().kind, ErrorKind::InvalidTable);
}

// The absorption part: 2 to kMaxHuangAbsorptionNodes increasing nodes in (0, kMaxHuangAbsorption],
// K finite non-negative values per cell, only beside an f part; each refusal names what is wrong.
TEST(HuangTableSet, ValidatesTheAbsorptionPartByName) {
    HuangTableSet set = synthetic_set();
    set.f.assign(3 * set.values.size(), 0.5f);
    set.absorption_nodes = {0.1f, 0.5f, 2.0f};
    set.absorption.assign(3 * set.values.size(), 0.25f);
    EXPECT_FALSE(set.validate().has_value());
    EXPECT_TRUE(set.has_absorption());
    auto refusal = [](HuangTableSet s) {
        const Status status = s.validate();
        return status ? status->message : std::string("(accepted)");
    };
    HuangTableSet bad = set;
    bad.absorption_nodes = {0.1f};
    bad.absorption.assign(bad.values.size(), 0.25f);
    EXPECT_NE(refusal(bad).find("absorption_nodes must hold 2 to 32 absorption nodes (got 1)"), std::string::npos) << refusal(bad);
    bad = set;
    bad.absorption_nodes = {0.1f, 0.1f, 2.0f};
    EXPECT_NE(refusal(bad).find("absorption_nodes[1] (0.100000001) must be in (0, 1000]"), std::string::npos) << refusal(bad);
    bad.absorption_nodes = {0.0f, 0.5f, 2.0f};
    EXPECT_NE(refusal(bad).find("absorption_nodes[0]"), std::string::npos) << refusal(bad);
    bad.absorption_nodes = {0.1f, 0.5f, 2000.0f};
    EXPECT_NE(refusal(bad).find("absorption_nodes[2] (2000)"), std::string::npos) << refusal(bad);
    bad = set;
    bad.absorption.pop_back();
    EXPECT_NE(refusal(bad).find("3 values per cell"), std::string::npos) << refusal(bad);
    bad = set;
    bad.absorption[7] = -1.0f;
    EXPECT_NE(refusal(bad).find("entry 7 (cell 2, node 1)"), std::string::npos) << refusal(bad);
    bad = set;
    bad.f.clear();
    EXPECT_NE(refusal(bad).find("needs the f part"), std::string::npos) << refusal(bad);
    bad = set;
    bad.absorption_nodes.clear();
    EXPECT_NE(refusal(bad).find("no absorption nodes"), std::string::npos) << refusal(bad);
}

}  // namespace
}  // namespace hairis
