// The near-field table: its pdf is the density it samples (χ² at θ_o on a node, between
// nodes and near grazing, at several h), its lobe integrals are right, and it follows
// luminance(f·cos) more closely than the analytic sampler does.
#include "sampling/near_field_table.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "chi2.h"
#include "core/frame.h"
#include "core/quadrature.h"
#include "fiber/fresnel.h"
#include "sampler_at.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Sample3;

std::shared_ptr<const ChiangFiber> fiber(float roughness = 0.3f, float offset_deg = 2.0f,
                                         float coat = 0.0f) {
    ChiangParams p;
    p.roughness = roughness;
    p.offset = float(radians(offset_deg));
    p.coat = coat;
    return std::make_shared<const ChiangFiber>(ChiangFiber::create(p).value());
}

Vec3 view_at(double theta_o_deg) { return direction_of(float(radians(theta_o_deg)), -float(kHalfPi)); }

// θ_o (degrees) on a node (nodes every 1.5°), between nodes, and near grazing.
const double kThetaO[] = {-36.0, 0.7, 40.2, 87.5, -89.9};
const float kH[] = {0.35f, -0.9f};
constexpr int kFamily = 5 * 2 + 2;

TEST(NearFieldTable, PdfIsTheDensityItSamples) {
    const auto table = std::make_shared<const NearFieldTable>(NearFieldTable::create(fiber()).value());
    Chi2Options options;
    options.test_count = kFamily;
    for (int k = 0; k <= table->theta_i_cells(); ++k)
        options.theta_breaks.push_back(-kHalfPi + kPi * k / table->theta_i_cells());
    for (double theta_o : kThetaO) {
        for (float h : kH) {
            const Vec3 wo = view_at(theta_o);
            const auto r = testing::chi2_direction_test(
                [&](Sample3 u) -> std::optional<Vec3> {
                    auto s = table->sample(wo, h, u.u0, u.u1, u.u2);
                    return s ? std::optional<Vec3>(s->wi) : std::nullopt;
                },
                [&](Vec3 wi) { return double(table->pdf(wi, wo, h)); }, options);
            EXPECT_TRUE(r.passed) << "theta_o " << theta_o << " h " << h << ": " << r.message;
            EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << "theta_o " << theta_o << " h " << h;
            EXPECT_EQ(r.failed_samples, 0);
        }
    }
}

TEST(NearFieldTable, ExactForARoughCoatedFiberWithALargeTilt) {
    // The sampler wrapper alone (its mixture with the multiple table is χ²-tested in
    // strategy_test), with a rough coated fiber at a large tilt.
    const auto table = std::make_shared<const NearFieldTable>(
        NearFieldTable::create(fiber(0.6f, 8.0f, 0.5f)).value());
    const NearFieldTableSampler sampler(table);
    Chi2Options options;
    options.test_count = kFamily;
    for (int k = 0; k <= table->theta_i_cells(); ++k)
        options.theta_breaks.push_back(-kHalfPi + kPi * k / table->theta_i_cells());
    for (double theta_o : {-60.0, 20.0}) {
        const testing::SamplerAt at(sampler, view_at(theta_o), 0.7f);
        const auto r = testing::chi2_sampler_test(at, options);
        EXPECT_TRUE(r.passed) << "theta_o " << theta_o << ": " << r.message;
    }
}

TEST(NearFieldTable, CellMassesAreTheLobesIntegralsOnANode) {
    // On a θ_o node the density's mass in θ_i cell k is Σ_p w_p · ∫_cell M_p cos θ dθ / I_p
    // with w_p ∝ luminance(A_p)·I_p: checked against the fiber's M_p by fine quadrature and
    // A_p in closed form, independently of the table's CDFs and cell shapes.
    const auto f = fiber(0.25f, 3.0f);
    const NearFieldTable table = NearFieldTable::create(f).value();
    const int cells = table.theta_i_cells();
    for (double theta_o_deg : {-45.0, 0.0, 61.5}) {  // nodes every 1.5°
        const double theta_o = radians(theta_o_deg);
        const float h = 0.3f;
        const ChiangPoint point = f->at({view_at(theta_o_deg), h});
        const NearFieldTable::Prepared q = table.prepare(point);
        ASSERT_LT(q.blend.t, 1e-4f) << "not a node: " << theta_o_deg;
        // A_p of the fiber (σ_a default) in closed form.
        const double gamma_o = std::asin(double(h)), eta = f->params().ior;
        const double fr = fresnel_dielectric(std::cos(theta_o) * std::cos(gamma_o), eta);
        const double k = std::cos(theta_o) / std::sqrt(eta * eta - sqr(std::sin(theta_o)));
        const double cos_theta_t = std::sqrt(1 - sqr(std::sin(theta_o) / eta));
        double a[4] = {};
        for (int c = 0; c < 3; ++c) {
            const double t = std::exp(-f->params().sigma_a[c] * 2 * std::sqrt(1 - sqr(h * k)) / cos_theta_t);
            const double ac[4] = {fr, sqr(1 - fr) * t, sqr(1 - fr) * t * t * fr, sqr(1 - fr) * t * t * fr * t * fr / (1 - t * fr)};
            for (int p = 0; p < 4; ++p) a[p] += (c == 0 ? 0.2126 : c == 1 ? 0.7152 : 0.0722) * ac[p];
        }
        std::vector<double> lobe_cells[4];
        double integral[4] = {}, w[4], total = 0;
        for (int p = 0; p < 4; ++p) {
            for (int kc = 0; kc < cells; ++kc) {
                const double lo = -kHalfPi + kPi * kc / cells, hi = -kHalfPi + kPi * (kc + 1) / cells;
                double m = 0;
                for (int j = 0; j < 64; ++j)
                    m += GaussLegendre::rule(12).integrate(lo + (hi - lo) * j / 64, lo + (hi - lo) * (j + 1) / 64, [&](double t) {
                        return f->lobe_longitudinal(p, std::sin(t), std::sin(theta_o)) * std::cos(t);
                    });
                lobe_cells[p].push_back(m);
                integral[p] += m;
            }
            total += (w[p] = a[p] * integral[p]);
        }
        // The density's mass per cell, by quadrature over (sin θ, φ) of density().
        for (int kc = 0; kc < cells; kc += 7) {
            const double s0 = std::sin(-kHalfPi + kPi * kc / cells), s1 = std::sin(-kHalfPi + kPi * (kc + 1) / cells);
            double mass = 0;
            for (int j = 0; j < 8; ++j)
                mass += GaussLegendre::rule(8).integrate(s0 + (s1 - s0) * j / 8, s0 + (s1 - s0) * (j + 1) / 8, [&](double st) {
                    // N_p is ~0.1 wide: 128 panels over φ resolve it.
                    double ring = 0;
                    const double ct = std::sqrt(std::max(0.0, 1 - st * st));
                    for (int panel = 0; panel < 128; ++panel)
                        ring += GaussLegendre::rule(8).integrate(-kPi + kTwoPi * panel / 128, -kPi + kTwoPi * (panel + 1) / 128,
                                                                 [&](double phi) {
                                                                     return double(table.density(q, point.direction(st, ct, phi)));
                                                                 });
                    return ring;
                });
            double expected = 0;
            for (int p = 0; p < 4; ++p) expected += w[p] / total * lobe_cells[p][std::size_t(kc)] / integral[p];
            // The CDFs are floats: a cell keeps its mass to a few ulps of 1 (piecewise.h).
            EXPECT_NEAR(mass, expected, 2e-3 * expected + 3e-7) << "theta_o " << theta_o_deg << " cell " << kc;
        }
    }
}

TEST(NearFieldTable, LobeIntegralsAreOneWithoutTiltAndTrackTheTiltWithIt) {
    // d'Eon's M is normalized over cos θ_i dθ_i: without a tilt every lobe integrates to 1,
    // which checks the tabulation's quadrature.
    const NearFieldTable flat = NearFieldTable::create(fiber(0.3f, 0.0f)).value();
    for (int r = 0; r < flat.theta_o_nodes(); ++r)
        for (int p = 0; p < 4; ++p) EXPECT_NEAR(flat.lobe_integral(r, p), 1.0, 1e-6) << r << " " << p;
    // With Cycles' tilt on θ_i the integral is ≈ cos δ − sin δ tan θ_o (chiang.h), e.g. R
    // (δ = 2α) at θ_o = 60°.
    const NearFieldTable tilted = NearFieldTable::create(fiber(0.3f, 5.0f)).value();
    const int r60 = 100;  // −90° + 100·1.5° = 60°
    const double delta = radians(10.0);
    EXPECT_NEAR(tilted.lobe_integral(r60, 0), std::cos(delta) - std::sin(delta) * std::tan(radians(60.0)), 0.02);
    EXPECT_NEAR(tilted.lobe_integral(r60, 3), 1.0, 1e-6);  // the residual is not tilted
}

TEST(NearFieldTable, NarrowLobesKeepTheirMassAndLobesPastTheEdgeHaveNone) {
    // Roughness 0 (Blender's slider allows it; Cycles clamps to 0.001): lobes ~4e-4 rad wide
    // in cells of 2°. Without a tilt each lobe still integrates to 1 at every node.
    const NearFieldTable flat = NearFieldTable::create(fiber(0.0f, 0.0f)).value();
    for (int r = 0; r < flat.theta_o_nodes(); ++r)
        for (int p = 0; p < 4; ++p) EXPECT_NEAR(flat.lobe_integral(r, p), 1.0, 1e-6) << r << " " << p;
    // With a tilt, TT's peak at θ_o = −90° lies past the edge: its mass underflows to zero,
    // which the table takes as a zero selection weight (it refused the fiber before; found
    // by fuzzing). Inside the range the tilted integrals stay close to 1.
    const NearFieldTable tilted = NearFieldTable::create(fiber(0.0f, 2.0f)).value();
    EXPECT_EQ(tilted.lobe_integral(0, 1), 0.0);
    const int r0 = (tilted.theta_o_nodes() - 1) / 2;  // θ_o = 0
    for (int p = 0; p < 4; ++p) EXPECT_NEAR(tilted.lobe_integral(r0, p), 1.0, 0.01) << p;
}

TEST(NearFieldTable, ExactAtRoughnessZero) {
    // Most lobes draw from the cone here, ~4·10⁻⁴ rad wide: the expected counts need
    // quadrature breaks every 10⁻⁴ rad around each lobe's peak, at θ_i = ±θ_o ± δ_p.
    const auto table = std::make_shared<const NearFieldTable>(NearFieldTable::create(fiber(0.0f)).value());
    const double alpha = radians(2.0);
    for (double theta_o : {-90.0, -30.0, 89.9}) {
        Chi2Options options;
        options.test_count = 3;
        for (int k = 0; k <= table->theta_i_cells(); ++k)
            options.theta_breaks.push_back(-kHalfPi + kPi * k / table->theta_i_cells());
        for (double sign : {-1.0, 1.0})
            for (double delta : {0.0, alpha, -alpha, 2 * alpha, -2 * alpha, 4 * alpha, -4 * alpha})
                for (int j = -60; j <= 60; ++j) {
                    const double b = sign * radians(theta_o) + delta + 1e-4 * j;
                    if (std::fabs(b) < kHalfPi) options.theta_breaks.push_back(b);
                }
        std::sort(options.theta_breaks.begin(), options.theta_breaks.end());
        const Vec3 wo = view_at(theta_o);
        const auto r = testing::chi2_direction_test(
            [&](Sample3 u) -> std::optional<Vec3> {
                auto s = table->sample(wo, 0.35f, u.u0, u.u1, u.u2);
                return s ? std::optional<Vec3>(s->wi) : std::nullopt;
            },
            [&](Vec3 wi) { return double(table->pdf(wi, wo, 0.35f)); }, options);
        EXPECT_TRUE(r.passed) << "theta_o " << theta_o << ": " << r.message;
        EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << "theta_o " << theta_o;
    }
}

TEST(NearFieldTable, EachLobeSourceIsExact) {
    // Every lobe forced onto the cone (a rough tilted fiber: the cone misplaces the lobes,
    // which must not matter for exactness), and onto its table row at roughness 0 (the rows
    // smear the lobes over whole cells).
    NearFieldTableOptions cone, rows;
    cone.lobe_sampling = {LobeSampling::Cone, LobeSampling::Cone, LobeSampling::Cone, LobeSampling::Cone};
    rows.lobe_sampling = {LobeSampling::Table, LobeSampling::Table, LobeSampling::Table, LobeSampling::Table};
    const auto all_cone = std::make_shared<const NearFieldTable>(NearFieldTable::create(fiber(0.5f, 6.0f), cone).value());
    const auto all_rows = std::make_shared<const NearFieldTable>(NearFieldTable::create(fiber(0.0f), rows).value());
    for (int p = 0; p < 4; ++p) {
        EXPECT_TRUE(all_cone->uses_cone(60, p));
        EXPECT_FALSE(all_rows->uses_cone(60, p));
    }
    Chi2Options options;
    options.test_count = 4;
    for (int k = 0; k <= 90; ++k) options.theta_breaks.push_back(-kHalfPi + kPi * k / 90);
    for (const auto &table : {all_cone, all_rows}) {
        for (double theta_o : {-50.25, 88.0}) {
            const Vec3 wo = view_at(theta_o);
            const auto r = testing::chi2_direction_test(
                [&](Sample3 u) -> std::optional<Vec3> {
                    auto s = table->sample(wo, -0.4f, u.u0, u.u1, u.u2);
                    return s ? std::optional<Vec3>(s->wi) : std::nullopt;
                },
                [&](Vec3 wi) { return double(table->pdf(wi, wo, -0.4f)); }, options);
            EXPECT_TRUE(r.passed) << (table == all_cone ? "cones" : "rows") << " theta_o " << theta_o << ": " << r.message;
            EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << "theta_o " << theta_o;
        }
    }
}

TEST(NearFieldTable, ChoosesTheConeForNarrowLobesAndTheTableForWideOnes) {
    // Roughness 0: every lobe far narrower than a cell, which the rows smear. Roughness 0.05:
    // TT about a cell wide. Roughness 0.3 (Cycles' default) and 0.6: the rows follow every
    // lobe to well under 10⁻³, so they are kept (the cone would cost time at every pdf).
    const NearFieldTable smoothest = NearFieldTable::create(fiber(0.0f)).value();
    const NearFieldTable smooth = NearFieldTable::create(fiber(0.05f)).value();
    const int r0 = (smooth.theta_o_nodes() - 1) / 2;
    for (int p = 0; p < 4; ++p) EXPECT_TRUE(smoothest.uses_cone(r0, p)) << p;
    EXPECT_TRUE(smooth.uses_cone(r0, 1));
    for (float roughness : {0.3f, 0.6f}) {
        const NearFieldTable rough = NearFieldTable::create(fiber(roughness)).value();
        for (int r = 0; r < rough.theta_o_nodes(); ++r)
            for (int p = 0; p < 4; ++p) ASSERT_FALSE(rough.uses_cone(r, p)) << roughness << " " << r << " " << p;
    }
}

// Relative variance of luminance(f·cos)/pdf under a sampler (a Monte Carlo estimate).
template <typename Sample>
double relative_variance(const ChiangFiber &f, Vec3 wo, float h, Sample &&sample, int n) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const auto s = sample(u(rng), u(rng), u(rng));
        double x = 0;
        if (s) x = double(luminance(f.f_cos_near(s->wi, wo, h))) / double(s->pdf);
        sum += x;
        sum2 += x * x;
    }
    const double mean = sum / n;
    return (sum2 / n - mean * mean) / (mean * mean);
}

auto table_sampler(const NearFieldTable &table, Vec3 wo, float h) {
    return [&table, wo, h](float a, float b, float c) { return table.sample(wo, h, a, b, c); };
}

auto analytic_sampler(const ChiangFiber &f, Vec3 wo, float h) {
    return [point = f.at({wo, h})](float a, float b, float c) { return point.sample(a, b, c); };
}

TEST(NearFieldTable, FollowsTheNearFieldCloserThanTheAnalyticSampler) {
    const auto f = fiber(0.3f, 2.0f);
    const NearFieldTable table = NearFieldTable::create(f).value();
    for (double theta_o : {-45.0, 0.0, 60.0}) {
        for (float h : {-0.6f, 0.2f}) {
            const Vec3 wo = view_at(theta_o);
            const double v_table = relative_variance(
                *f, wo, h, table_sampler(table, wo, h), 200000);
            const double v_analytic = relative_variance(
                *f, wo, h, analytic_sampler(*f, wo, h), 200000);
            EXPECT_LT(v_table, 0.5 * v_analytic) << "theta_o " << theta_o << " h " << h
                                                  << ": table " << v_table << ", analytic " << v_analytic;
        }
    }
}

TEST(NearFieldTable, SmoothFibersSampleBetterThanWithRowsAloneAndThanTheAnalyticSampler) {
    // Roughness 0.02 and 0.05, views from the side to near grazing. With rows alone these
    // had 10-100x the analytic sampler's variance, and exact poles (|sin θ_i| = 1, where φ is
    // undefined) made it 10³ at θ_o = 89°.
    NearFieldTableOptions rows;
    rows.lobe_sampling = {LobeSampling::Table, LobeSampling::Table, LobeSampling::Table, LobeSampling::Table};
    for (float roughness : {0.02f, 0.05f}) {
        const auto f = fiber(roughness, 2.0f);
        const NearFieldTable table = NearFieldTable::create(f).value();
        const NearFieldTable rows_only = NearFieldTable::create(f, rows).value();
        double v_table = 0, v_rows = 0, v_analytic = 0;
        for (double theta_o : {-45.0, 0.0, 40.2, 89.0}) {
            for (float h : {-0.6f, 0.8f}) {
                const Vec3 wo = view_at(theta_o);
                v_table += relative_variance(
                    *f, wo, h, table_sampler(table, wo, h), 100000);
                v_rows += relative_variance(
                    *f, wo, h, table_sampler(rows_only, wo, h), 100000);
                v_analytic += relative_variance(
                    *f, wo, h, analytic_sampler(*f, wo, h), 100000);
            }
        }
        EXPECT_LT(v_table, 0.5 * v_analytic) << roughness << ": table " << v_table << ", analytic " << v_analytic;
        EXPECT_LT(v_table, 0.5 * v_rows) << roughness << ": table " << v_table << ", rows alone " << v_rows;
    }
}

TEST(NearFieldTable, EdgeValuesOfAnyScaleGiveTheSameDensity) {
    // Only the ratio of a cell's two edge values shapes it, and a table file may scale a row's
    // edges by anything finite: up to the largest float (their sum overflows) or down into the
    // subnormals (their products underflow). The density must stay the unscaled table's, and
    // its sampler exact (found by fuzzing table files: the density was NaN or infinite).
    NearFieldTableOptions rows;
    rows.theta_o_nodes = 13;
    rows.theta_i_cells = 30;
    rows.lobe_sampling = {LobeSampling::Table, LobeSampling::Table, LobeSampling::Table, LobeSampling::Table};
    const auto f = fiber();
    const NearFieldTable table = NearFieldTable::create(f, rows).value();
    const NearFieldData &d = table.data();
    for (const bool up : {true, false}) {
        auto scaled = std::make_shared<NearFieldData>(d);
        const size_t width = size_t(d.theta_i_cells) + 1;
        for (int row = 0; row < d.rows(); ++row) {
            float *e = scaled->edge.data() + size_t(row) * width;
            const float largest = *std::max_element(e, e + width);
            float smallest = largest;
            for (size_t k = 0; k < width; ++k)
                if (e[k] > 0.0f) smallest = std::min(smallest, e[k]);
            ASSERT_GT(largest, 0.0f);
            // Up: the largest becomes FLT_MAX; down: the smallest positive one the smallest
            // normal float, 2^-126 (so every square is 0, and no edge loses digits).
            const double factor = up ? double(std::numeric_limits<float>::max()) / double(largest)
                                     : double(std::numeric_limits<float>::min()) / double(smallest);
            for (size_t k = 0; k < width; ++k) e[k] = float(std::min(double(e[k]) * factor, double(std::numeric_limits<float>::max())));
        }
        const auto loaded = std::make_shared<const NearFieldTable>(NearFieldTable::from_data(f, scaled).value());
        for (const double theta_o : {-52.0, 10.0, 71.5})
            for (int i = 0; i < 60; ++i)
                for (int j = 0; j < 12; ++j) {
                    const double s = -1.0 + (i + 0.5) / 30.0;
                    const Vec3 wi = direction_of(float(std::asin(s)), float(-kPi + kTwoPi * (j + 0.5) / 12));
                    const float expected = table.pdf(wi, view_at(theta_o), 0.3f), got = loaded->pdf(wi, view_at(theta_o), 0.3f);
                    ASSERT_TRUE(std::isfinite(got)) << (up ? "up" : "down") << " theta_o " << theta_o << " sin " << s;
                    ASSERT_NEAR(got, expected, 1e-5 * expected + 1e-12)
                        << (up ? "up" : "down") << " theta_o " << theta_o << " sin " << s;
                }
        Chi2Options options;
        options.test_count = 2;
        for (int k = 0; k <= 30; ++k) options.theta_breaks.push_back(-kHalfPi + kPi * k / 30);
        const Vec3 wo = view_at(10.0);
        const auto r = testing::chi2_direction_test(
            [&](Sample3 u) -> std::optional<Vec3> {
                auto smp = loaded->sample(wo, 0.3f, u.u0, u.u1, u.u2);
                return smp ? std::optional<Vec3>(smp->wi) : std::nullopt;
            },
            [&](Vec3 wi) { return double(loaded->pdf(wi, wo, 0.3f)); }, options);
        EXPECT_TRUE(r.passed) << (up ? "up" : "down") << ": " << r.message;
        EXPECT_EQ(r.failed_samples, 0);
    }
}

// A strand's own point (another melanin, roughness and radial roughness than the table's
// fiber): the density is exact with the strand's own cones for the lobes whose M_p is not the
// table's, and with the table's rows regardless; the own cones are far closer to f.
ChiangParams strand_params(const ChiangFiber &table_fiber, float roughness) {
    ChiangParams p = table_fiber.params();
    p.roughness = p.radial_roughness = roughness;
    p.sigma_a = {1.1f, 1.9f, 3.4f};
    return p;
}

TEST(NearFieldTable, AStrandsPointIsSampledExactlyWithOrWithoutItsOwnCones) {
    const auto f = fiber(0.3f, 2.0f);
    const auto table = std::make_shared<const NearFieldTable>(NearFieldTable::create(f).value());
    Chi2Options options;
    options.test_count = 2 * 2 * 2;
    for (int k = 0; k <= table->theta_i_cells(); ++k)
        options.theta_breaks.push_back(-kHalfPi + kPi * k / table->theta_i_cells());
    for (float roughness : {0.15f, 0.6f}) {
        const ChiangLobes strand = ChiangLobes::derive(f->lobes(), strand_params(*f, roughness));
        for (bool own : {true, false})
            for (double theta_o : {40.2, -75.0}) {
                const ChiangPoint point(strand, {view_at(theta_o), 0.35f});
                const NearFieldTable::Prepared q = table->prepare(point, own);
                EXPECT_EQ(q.own_cones, own ? 0xFu : 0u);
                const auto r = testing::chi2_direction_test(
                    [&](Sample3 u) -> std::optional<Vec3> {
                        auto s = table->sample(q, u.u0, u.u1, u.u2);
                        return s ? std::optional<Vec3>(s->wi) : std::nullopt;
                    },
                    [&](Vec3 wi) { return double(table->density(q, wi)); }, options);
                EXPECT_TRUE(r.passed) << "roughness " << roughness << " own cones " << own << " theta_o " << theta_o
                                      << ": " << r.message;
                EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
                EXPECT_EQ(r.failed_samples, 0);
            }
    }
    // The table's own fiber (and a strand of only another melanin) keeps every row.
    const ChiangPoint own_point = f->at({view_at(10.0), 0.1f});
    EXPECT_EQ(table->prepare(own_point).own_cones, 0u);
    ChiangParams darker = f->params();
    darker.sigma_a = {2.0f, 3.0f, 4.0f};
    const ChiangLobes dark = ChiangLobes::derive(f->lobes(), darker);
    EXPECT_EQ(table->prepare(ChiangPoint(dark, {view_at(10.0), 0.1f})).own_cones, 0u);
    ChiangParams coated = f->params();
    coated.coat = 0.5f;  // only R's M_p changes
    const ChiangLobes coat = ChiangLobes::derive(f->lobes(), coated);
    EXPECT_EQ(table->prepare(ChiangPoint(coat, {view_at(10.0), 0.1f})).own_cones, 1u << kLobeR);
}

TEST(NearFieldTable, AStrandsOwnConesFollowItFarCloserThanTheTablesRows) {
    const auto f = fiber(0.3f, 2.0f);
    const NearFieldTable table = NearFieldTable::create(f).value();
    for (float roughness : {0.15f, 0.6f}) {
        const auto strand = std::make_shared<const ChiangFiber>(ChiangFiber::create(strand_params(*f, roughness)).value());
        for (double theta_o : {-45.0, 30.0}) {
            const Vec3 wo = view_at(theta_o);
            const float h = 0.3f;
            const ChiangPoint point = strand->at({wo, h});
            const NearFieldTable::Prepared own = table.prepare(point, true), rows = table.prepare(point, false);
            auto draw = [&table](const NearFieldTable::Prepared &q) {
                return [&table, &q](float a, float b, float c) { return table.sample(q, a, b, c); };
            };
            const double v_own = relative_variance(*strand, wo, h, draw(own), 100000);
            const double v_rows = relative_variance(*strand, wo, h, draw(rows), 100000);
            EXPECT_LT(v_own, 0.1 * v_rows) << "roughness " << roughness << " theta_o " << theta_o << ": own cones "
                                           << v_own << ", rows " << v_rows;
        }
    }
}

TEST(NearFieldTable, RefusesBadResolutions) {
    EXPECT_FALSE(NearFieldTable::create(fiber(), {1, 180}).ok());
    EXPECT_FALSE(NearFieldTable::create(fiber(), {61, 2}).ok());
    EXPECT_FALSE(NearFieldTable::create(fiber(), {61, 1 << 20}).ok());
    EXPECT_FALSE(NearFieldTable::create(nullptr).ok());
}

}  // namespace
}  // namespace hairis
