#include "fiber/chiang.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "chi2.h"
#include "core/frame.h"
#include "core/quadrature.h"
#include "core/scratch.h"
#include "fiber/fresnel.h"

namespace hairis {
namespace {

// ---------------------------------------------------------------------------------------
// Quadrature used by the tests: composite Gauss–Legendre between breakpoints that are graded
// around known peaks (lobe centres), so that narrow lobes are resolved without Monte Carlo.

struct Rule {
    std::vector<double> x, w;
};

// n-point Gauss–Legendre on [−1, 1] (core/quadrature.h, tested there).
Rule gauss_legendre(int n) {
    const GaussLegendre &gl = GaussLegendre::rule(n);
    return {gl.nodes, gl.weights};
}

struct Peak {
    double centre, width;
};

// Breakpoints over [lo, hi]: a uniform grid of about base_step, plus centre ± width·m for
// each peak with m growing geometrically (wrapped into [lo, hi) when periodic, where the
// antipode of each peak, a kink of a wrapped function, is added too).
std::vector<double> graded_breaks(double lo, double hi, double base_step,
                                  const std::vector<Peak> &peaks, bool periodic = false,
                                  double max_multiple = 200.0, double growth = 1.4) {
    std::vector<double> breaks;
    const int n = int(std::ceil((hi - lo) / base_step));
    for (int i = 0; i <= n; ++i) breaks.push_back(lo + (hi - lo) * i / n);
    auto add = [&](double x) {
        if (periodic) x = lo + std::fmod(std::fmod(x - lo, hi - lo) + (hi - lo), hi - lo);
        if (x > lo && x < hi) breaks.push_back(x);
    };
    for (const Peak &peak : peaks) {
        if (periodic) add(peak.centre + 0.5 * (hi - lo));
        add(peak.centre);
        for (double m = 0.5; m * peak.width < hi - lo && m <= max_multiple; m *= growth) {
            add(peak.centre - m * peak.width);
            add(peak.centre + m * peak.width);
        }
    }
    std::sort(breaks.begin(), breaks.end());
    breaks.erase(std::unique(breaks.begin(), breaks.end(),
                             [](double a, double b) { return b - a < 1e-12; }),
                 breaks.end());
    return breaks;
}

// Nodes and weights of the composite rule over the breakpoints.
Rule composite(const std::vector<double> &breaks, const Rule &rule) {
    Rule out;
    for (std::size_t i = 0; i + 1 < breaks.size(); ++i) {
        const double c = 0.5 * (breaks[i] + breaks[i + 1]), h = 0.5 * (breaks[i + 1] - breaks[i]);
        for (std::size_t j = 0; j < rule.x.size(); ++j) {
            out.x.push_back(c + h * rule.x[j]);
            out.w.push_back(h * rule.w[j]);
        }
    }
    return out;
}

double integrate(const std::function<double(double)> &f, const Rule &rule) {
    double sum = 0;
    for (std::size_t i = 0; i < rule.x.size(); ++i) sum += rule.w[i] * f(rule.x[i]);
    return sum;
}

const Rule &gl8() {
    static const Rule rule = gauss_legendre(8);
    return rule;
}
const Rule &gl16() {
    static const Rule rule = gauss_legendre(16);
    return rule;
}

constexpr double kCyclesPhiO = -kHalfPi;  // every ω_o has φ_o = −π/2 in Cycles' frame

Vec3 direction(double theta, double phi) { return direction_of(float(theta), float(phi)); }

ChiangFiber make_fiber(const ChiangParams &params) {
    Expected<ChiangFiber> fiber = ChiangFiber::create(params);
    EXPECT_TRUE(fiber.ok()) << (fiber.ok() ? "" : fiber.error().message);
    return fiber.value();
}

double cycles_v(double beta) {
    beta = std::clamp(beta, 0.001, 1.0);
    return sqr(0.726 * beta + 0.812 * beta * beta + 3.7 * std::pow(beta, 20.0));
}

double cycles_s(double beta) {
    beta = std::clamp(beta, 0.001, 1.0);
    return std::sqrt(kPi / 8.0) * (0.265 * beta + 1.194 * beta * beta + 5.372 * std::pow(beta, 22.0));
}

// ---------------------------------------------------------------------------------------
// Parameters.

TEST(ChiangParams, DefaultsAreAccepted) {
    Expected<ChiangFiber> fiber = ChiangFiber::create({});
    ASSERT_TRUE(fiber.ok()) << fiber.error().message;
    EXPECT_EQ(fiber.value().name(), "chiang2016");
    EXPECT_EQ(fiber.value().lobe_count(), 4);
}

TEST(ChiangParams, RangeEndsAreAccepted) {
    ChiangParams p;
    p.sigma_a = Rgb(0.0f);
    p.roughness = 0.0f;
    p.radial_roughness = 1.0f;
    p.coat = 1.0f;
    p.ior = 1.0001f;
    p.offset = float(kHalfPi);
    EXPECT_TRUE(ChiangFiber::create(p).ok());
    p.roughness = 1.0f;
    p.radial_roughness = 0.0f;
    p.coat = 0.0f;
    p.offset = -float(kHalfPi);
    EXPECT_TRUE(ChiangFiber::create(p).ok());
}

TEST(ChiangParams, EachInvalidParameterIsRefusedByName) {
    const float nan = std::nanf("");
    const float inf = INFINITY;
    struct Case {
        std::function<void(ChiangParams &)> spoil;
        std::string name;
    };
    const std::vector<Case> cases = {
        {[](ChiangParams &p) { p.sigma_a.r = -0.1f; }, "sigma_a.r"},
        {[&](ChiangParams &p) { p.sigma_a.g = nan; }, "sigma_a.g"},
        {[&](ChiangParams &p) { p.sigma_a.b = inf; }, "sigma_a.b"},
        {[](ChiangParams &p) { p.roughness = 1.5f; }, "roughness"},
        {[](ChiangParams &p) { p.roughness = -0.01f; }, "roughness"},
        {[&](ChiangParams &p) { p.roughness = nan; }, "roughness"},
        {[](ChiangParams &p) { p.radial_roughness = 2.0f; }, "radial_roughness"},
        {[&](ChiangParams &p) { p.radial_roughness = -inf; }, "radial_roughness"},
        {[](ChiangParams &p) { p.coat = -0.5f; }, "coat"},
        {[](ChiangParams &p) { p.coat = 1.01f; }, "coat"},
        {[](ChiangParams &p) { p.ior = 1.0f; }, "ior"},
        {[](ChiangParams &p) { p.ior = 0.5f; }, "ior"},
        {[&](ChiangParams &p) { p.ior = nan; }, "ior"},
        {[&](ChiangParams &p) { p.ior = inf; }, "ior"},
        {[](ChiangParams &p) { p.offset = 1.6f; }, "offset"},
        {[&](ChiangParams &p) { p.offset = nan; }, "offset"},
    };
    for (const Case &c : cases) {
        ChiangParams p;
        c.spoil(p);
        Expected<ChiangFiber> fiber = ChiangFiber::create(p);
        ASSERT_FALSE(fiber.ok()) << c.name;
        EXPECT_NE(fiber.error().message.find(c.name), std::string::npos)
            << "message '" << fiber.error().message << "' does not name " << c.name;
    }
}

TEST(ChiangParams, RoughnessMappingsAreCycles) {
    for (double beta : {0.0, 0.0005, 0.001, 0.1, 0.3, 0.7, 1.0}) {
        EXPECT_NEAR(chiang::longitudinal_variance(beta), cycles_v(beta), 1e-12 * cycles_v(beta) + 1e-18);
        EXPECT_NEAR(chiang::logistic_scale(beta), cycles_s(beta), 1e-12 * cycles_s(beta));
    }
    // v(1) = (0.726 + 0.812 + 3.7)², s(1) = √(π/8)·(0.265 + 1.194 + 5.372).
    EXPECT_NEAR(chiang::longitudinal_variance(1.0), sqr(5.238), 1e-9);
    EXPECT_NEAR(chiang::logistic_scale(1.0), std::sqrt(kPi / 8.0) * 6.831, 1e-9);

    ChiangParams p;
    p.roughness = 0.4f;
    p.radial_roughness = 0.25f;
    p.coat = 0.5f;
    const ChiangFiber fiber = make_fiber(p);
    const double v = cycles_v(0.4f);
    EXPECT_NEAR(fiber.lobe_variance(kLobeR), cycles_v((1.0 - 0.5) * double(0.4f)), 1e-12);
    EXPECT_NEAR(fiber.lobe_variance(kLobeTT), 0.25 * v, 1e-12);
    EXPECT_NEAR(fiber.lobe_variance(kLobeTRT), 4.0 * v, 1e-12);
    EXPECT_NEAR(fiber.lobe_variance(kLobeResidual), 4.0 * v, 1e-12);
    EXPECT_EQ(fiber.lobe_variance(4), 0.0);
    EXPECT_NEAR(fiber.logistic_scale(), cycles_s(0.25f), 1e-12);

    // A full coat leaves R at Cycles' minimum roughness 0.001.
    p.coat = 1.0f;
    EXPECT_NEAR(make_fiber(p).lobe_variance(kLobeR), cycles_v(0.001), 1e-15);
}

// Cycles' bsdf_hair_chiang_blur: v, v_m0 and s each become max(blur, value), the mapped values
// compared with the blur itself; below all three nothing changes.
TEST(ChiangFiber, BlurRaisesEachMappedRoughnessToTheBlur) {
    ChiangParams p;
    p.roughness = 0.4f;
    p.radial_roughness = 0.25f;
    p.coat = 0.5f;
    const ChiangFiber fiber = make_fiber(p);
    const double v = cycles_v(0.4f), v_m0 = cycles_v(0.5 * double(0.4f)), s = cycles_s(0.25f);
    ASSERT_LT(v_m0, s);
    ASSERT_LT(s, v);
    EXPECT_FALSE(fiber.lobes().blurred(0.5 * v_m0).has_value());
    const double between = 0.5 * (s + v);  // above v_m0 and s, below v
    const std::optional<ChiangLobes> wide = fiber.lobes().blurred(between);
    ASSERT_TRUE(wide.has_value());
    EXPECT_DOUBLE_EQ(wide->lobe_variance(kLobeR), between);
    EXPECT_DOUBLE_EQ(wide->lobe_variance(kLobeTT), 0.25 * v);
    EXPECT_DOUBLE_EQ(wide->logistic_scale(), between);
    EXPECT_DOUBLE_EQ(wide->azimuthal().scale(), between);
    const std::optional<ChiangLobes> all = fiber.lobes().blurred(0.5);
    ASSERT_TRUE(all.has_value());
    EXPECT_DOUBLE_EQ(all->lobe_variance(kLobeTRT), 4.0 * 0.5);
    // A point of the widened lobes says so, and its density is still a density: the
    // analytic sampler's pdf integrates to 1 over the sphere.
    ScratchBuffer scratch;
    FiberHit hit{safe_normalize(Vec3{0.3f, 0.5f, 0.8f}), 0.2f};
    hit.blur_roughness = 0.3f;
    const FiberPoint &point = fiber.prepare(hit, scratch);
    ASSERT_NE(point.chiang_point(), nullptr);
    EXPECT_TRUE(point.chiang_point()->blurred());
    double integral = 0;
    const int n = 400;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < 2 * n; ++j) {
            const double sin_t = -1.0 + 2.0 * (i + 0.5) / n, cos_t = std::sqrt(1.0 - sin_t * sin_t);
            const double phi = kPi * (-1.0 + (j + 0.5) / n);
            const Vec3 wi{float(sin_t), float(cos_t * std::cos(phi)), float(cos_t * std::sin(phi))};
            integral += point.chiang_point()->pdf(wi) * (2.0 / n) * (kPi / n);
        }
    EXPECT_NEAR(integral, 1.0, 2e-3);
    hit.blur_roughness = 0.0f;
    EXPECT_FALSE(fiber.prepare(hit, scratch).chiang_point()->blurred());
}

TEST(ChiangParams, LobeShapeFollowsWhereTheLobePeaks) {
    ChiangParams p;
    p.roughness = 0.05f;  // narrow lobes: the peak of M_p is sharp
    p.offset = float(radians(3.0));
    p.sigma_a = Rgb(0.0f);
    const ChiangFiber fiber = make_fiber(p);
    const double theta_o = radians(20.0);
    const Vec3 wo = direction(theta_o, kCyclesPhiO);
    const float h = 0.2f;
    const double gamma_o = std::asin(double(h));
    const double k = std::cos(theta_o) / std::sqrt(sqr(double(p.ior)) - sqr(std::sin(theta_o)));
    const double gamma_t = std::asin(h * k);
    for (int lobe = 0; lobe < 3; ++lobe) {
        const double phi = chiang::azimuthal_shift(lobe, gamma_o, gamma_t);
        double best = -1, best_theta = 0;
        for (double theta_i = -kHalfPi; theta_i <= kHalfPi; theta_i += radians(0.005)) {
            const double value = fiber.at({wo, h}).lobe_f(lobe, direction(theta_i, kCyclesPhiO + phi)).g;
            if (value > best) {
                best = value;
                best_theta = theta_i;
            }
        }
        const LobeShape shape = fiber.lobe_shape(lobe);
        // The shape is in θ_h = (θ_i + θ_o)/2 (fiber.h).
        EXPECT_NEAR(0.5 * (best_theta + theta_o), shape.alpha, radians(0.05)) << "lobe " << lobe;
        EXPECT_NEAR(shape.beta, 0.5 * std::sqrt(fiber.lobe_variance(lobe)), 1e-7);
    }
    EXPECT_NEAR(fiber.lobe_shape(kLobeR).alpha, -p.offset, 1e-7);
    EXPECT_NEAR(fiber.lobe_shape(kLobeTT).alpha, 0.5 * p.offset, 1e-7);
    EXPECT_NEAR(fiber.lobe_shape(kLobeTRT).alpha, 2.0 * p.offset, 1e-7);
    EXPECT_EQ(fiber.lobe_shape(kLobeResidual).alpha, 0.0f);
}

// ---------------------------------------------------------------------------------------
// M_p.

TEST(ChiangLongitudinal, LogBesselI0MatchesTheStandardLibrary) {
    for (double x = 0.0; x < 700.0; x = x < 20 ? x + 0.173 : x * 1.07) {
        const double reference = std::log(std::cyl_bessel_i(0.0, x));
        EXPECT_NEAR(chiang::log_bessel_i0(x), reference, 1e-13 * std::max(1.0, reference)) << "x = " << x;
    }
    // Both sides of the switch between the two series.
    for (double x : {19.999999, 20.0, 20.000001}) {
        EXPECT_NEAR(chiang::log_bessel_i0(x), std::log(std::cyl_bessel_i(0.0, x)), 1e-13 * x);
    }
    EXPECT_NEAR(chiang::log_bessel_i0(1e6), 1e6 - 0.5 * std::log(kTwoPi * 1e6), 1e-6);
}

TEST(ChiangLongitudinal, MatchesTheClosedForm) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> angle(-kHalfPi, kHalfPi);
    for (double v : {0.02, 0.0846, 0.3, 1.0, 5.0, 110.0}) {
        for (int i = 0; i < 50; ++i) {
            const double ti = angle(rng), to = angle(rng);
            const double expected = std::exp(-std::sin(ti) * std::sin(to) / v) *
                                    std::cyl_bessel_i(0.0, std::cos(ti) * std::cos(to) / v) /
                                    (2.0 * v * std::sinh(1.0 / v));
            const double actual = chiang::longitudinal_scattering(std::sin(ti), std::cos(ti), std::sin(to),
                                                                  std::cos(to), v);
            EXPECT_NEAR(actual, expected, 1e-11 * expected) << "v " << v;
        }
    }
}

TEST(ChiangLongitudinal, TinyVarianceNeitherOverflowsNorNaNs) {
    // v = 0.001 and Cycles' smallest mapped variance (β = 0.001, v ≈ 5.3e-7).
    for (double v : {0.001, cycles_v(0.001), 1e-9}) {
        double peak = 0;
        for (double to = -kHalfPi; to <= kHalfPi; to += 0.05) {
            for (double ti = -kHalfPi; ti <= kHalfPi; ti += 0.0007) {
                const double m = chiang::longitudinal_scattering(std::sin(ti), std::cos(ti), std::sin(to),
                                                                 std::cos(to), v);
                ASSERT_TRUE(std::isfinite(m)) << "v " << v << " ti " << ti << " to " << to;
                ASSERT_GE(m, 0.0);
            }
            peak = std::max(peak, chiang::longitudinal_scattering(std::sin(-to), std::cos(-to),
                                                                  std::sin(to), std::cos(to), v));
        }
        // At the specular cone M ≈ 1/(√(2πv)·cos θ) for small v: large but finite.
        EXPECT_GT(peak, 0.3 / std::sqrt(kTwoPi * v));
        EXPECT_TRUE(std::isfinite(peak));
    }
}

// ∫ M_p(θ_i) cos θ_i dθ_i for the untilted d'Eon function, resolved around its peak −θ_o.
double longitudinal_integral(double theta_o, double v, double tilt = 0.0) {
    const double width = std::min(std::sqrt(v), 0.5);
    const Rule rule =
        composite(graded_breaks(-kHalfPi, kHalfPi, 0.1, {{-theta_o - tilt, width}}), gl16());
    return integrate(
        [&](double ti) {
            const double tilted = ti + tilt;  // Cycles: sin(θ_i + δ), |cos(θ_i + δ)|
            return chiang::longitudinal_scattering(std::sin(tilted), std::fabs(std::cos(tilted)),
                                                   std::sin(theta_o), std::cos(theta_o), v) *
                   std::cos(ti);
        },
        rule);
}

TEST(ChiangLongitudinal, EachLobeIntegratesToOne) {
    for (float roughness : {0.0f, 0.001f, 0.05f, 0.3f, 0.7f, 1.0f}) {
        for (float coat : {0.0f, 0.6f}) {
            ChiangParams p;
            p.roughness = roughness;
            p.coat = coat;
            const ChiangFiber fiber = make_fiber(p);
            for (int lobe = 0; lobe < 4; ++lobe) {
                const double v = fiber.lobe_variance(lobe);
                for (double theta_o_deg : {-85.0, -40.0, 0.0, 30.0, 80.0, 89.0}) {
                    const double integral = longitudinal_integral(radians(theta_o_deg), v);
                    ASSERT_TRUE(std::isfinite(integral));
                    EXPECT_NEAR(integral, 1.0, 2e-6) << "roughness " << roughness << " coat " << coat
                                                     << " lobe " << lobe << " v " << v << " θo "
                                                     << theta_o_deg;
                }
            }
        }
    }
}

TEST(ChiangLongitudinal, CyclesTiltOnThetaIDoesNotPreserveTheIntegral) {
    // Documentation of Cycles' model: with the tilt on θ_i, ∫ M(θ_i + δ, θ_o) cos θ_i dθ_i
    // = ∫ M(θ') cos(θ' − δ) ≈ cos δ − sin δ·tan θ_o instead of 1 (M's mass sits at θ' ≈ −θ_o).
    // This is why the white furnace of the Cycles-exact f is only 1 at offset 0 (or θ_o = 0).
    const double v = cycles_v(0.3);
    for (double theta_o_deg : {-60.0, -30.0, 0.0, 30.0, 60.0}) {
        const double theta_o = radians(theta_o_deg);
        for (double delta : {radians(4.0), radians(-2.0), radians(-8.0)}) {
            const double integral = longitudinal_integral(theta_o, v, delta);
            const double first_order = std::cos(delta) - std::sin(delta) * std::tan(theta_o);
            // Same direction and size within a factor of 2 (the first-order estimate ignores
            // the spread of tan θ under M and the lobe's cut at ±π/2).
            const double ratio = (integral - 1.0) / (first_order - 1.0);
            EXPECT_GT(ratio, 0.5) << "θo " << theta_o_deg << " δ " << degrees(delta) << " ∫ " << integral;
            EXPECT_LT(ratio, 2.0) << "θo " << theta_o_deg << " δ " << degrees(delta) << " ∫ " << integral;
            std::printf("[ tilt ] θo %+5.0f δ %+3.0f°: ∫ M(θi+δ) cos θi dθi = %.5f (first order %.5f)\n",
                        theta_o_deg, degrees(delta), integral, first_order);
        }
    }
}

// ---------------------------------------------------------------------------------------
// N_p and the attenuation.

TEST(ChiangAzimuthal, TrimmedLogisticIntegratesToOne) {
    for (double beta : {0.0, 0.02, 0.1, 0.3, 0.7, 1.0}) {
        const double s = chiang::logistic_scale(beta);
        for (double centre : {0.0, 1.3, -2.9, kPi}) {
            const Rule rule =
                composite(graded_breaks(-kPi, kPi, 0.1, {{centre, s}}, /*periodic=*/true), gl16());
            const double integral = integrate(
                [&](double phi) { return chiang::TrimmedLogistic(s).density(wrap_angle(phi - centre)); }, rule);
            EXPECT_NEAR(integral, 1.0, 1e-9) << "β_n " << beta << " s " << s << " centre " << centre;
        }
    }
}

TEST(ChiangAzimuthal, TrimmedLogisticSamplingInvertsItsCdf) {
    for (double beta : {0.001, 0.1, 0.3, 1.0}) {
        const double s = chiang::logistic_scale(beta);
        for (double u : {0.0, 1e-6, 0.1, 0.25, 0.5, 0.8, 0.999, 1.0}) {
            const double x = chiang::TrimmedLogistic(s).sample(u);
            ASSERT_GE(x, -kPi);
            ASSERT_LE(x, kPi);
            const Rule rule = composite(graded_breaks(-kPi, x, 0.05, {{0.0, s}}), gl16());
            const double cdf = x > -kPi ? integrate([&](double y) { return chiang::TrimmedLogistic(s).density(y); }, rule) : 0.0;
            EXPECT_NEAR(cdf, u, 1e-8) << "β_n " << beta << " u " << u;
        }
    }
}

TEST(ChiangAzimuthal, EachLobeTimesItsAzimuthalIntegratesToTheAttenuation) {
    // ∫ lobe_f dφ = A_p · M_p(θ_i + δ_p, θ_o): N_p carries unit mass, A_p the energy.
    ChiangParams p;
    p.coat = 0.4f;
    p.offset = float(radians(3.0));
    const ChiangFiber fiber = make_fiber(p);
    const double deltas[4] = {2.0 * p.offset, -p.offset, -4.0 * p.offset, 0.0};
    for (double theta_o_deg : {-50.0, 10.0, 70.0}) {
        const double theta_o = radians(theta_o_deg);
        const Vec3 wo = direction(theta_o, kCyclesPhiO);
        const double theta_i = -theta_o + 0.1;
        for (float h : {-0.9f, 0.0f, 0.6f}) {
            for (int lobe = 0; lobe < 4; ++lobe) {
                const Rgb a = fiber.at({wo, h}).attenuation(lobe);
                const double tilted = theta_i + deltas[lobe];
                const double m = chiang::longitudinal_scattering(std::sin(tilted), std::fabs(std::cos(tilted)),
                                                                 std::sin(theta_o), std::cos(theta_o),
                                                                 fiber.lobe_variance(lobe));
                std::vector<Peak> peaks;
                for (int q = 0; q < 3; ++q) {
                    const double k = std::cos(theta_o) / std::sqrt(sqr(double(p.ior)) - sqr(std::sin(theta_o)));
                    peaks.push_back({chiang::azimuthal_shift(q, std::asin(double(h)), std::asin(h * k)),
                                     fiber.logistic_scale()});
                }
                const Rule rule = composite(graded_breaks(-kPi, kPi, 0.1, peaks, true), gl16());
                for (int c = 0; c < 3; ++c) {
                    const double integral = integrate(
                        [&](double phi) {
                            return double(fiber.at({wo, h}).lobe_f(lobe, direction(theta_i, kCyclesPhiO + phi))[c]);
                        },
                        rule);
                    EXPECT_NEAR(integral, a[c] * m, 2e-5 * a[c] * m + 1e-12)
                        << "lobe " << lobe << " θo " << theta_o_deg << " h " << h << " channel " << c;
                }
            }
        }
    }
}

TEST(ChiangAzimuthal, AttenuationMatchesChiangsClosedForm) {
    ChiangParams p;
    p.sigma_a = {0.3f, 0.9f, 2.0f};
    const ChiangFiber fiber = make_fiber(p);
    for (double theta_o_deg : {-70.0, 0.0, 45.0}) {
        const double theta_o = radians(theta_o_deg);
        const Vec3 wo = direction(theta_o, kCyclesPhiO);
        for (float h : {-1.0f, -0.5f, 0.0f, 0.8f, 1.0f}) {
            const double eta = p.ior;
            const double f = fresnel_dielectric(std::cos(theta_o) * std::sqrt(1.0 - double(h) * h), eta);
            const double eta_prime = std::sqrt(eta * eta - sqr(std::sin(theta_o))) / std::cos(theta_o);
            const double cos_gamma_t = std::sqrt(1.0 - sqr(h / eta_prime));
            const double cos_theta_t = std::sqrt(1.0 - sqr(std::sin(theta_o) / eta));
            for (int c = 0; c < 3; ++c) {
                const double t = std::exp(-p.sigma_a[c] * 2.0 * cos_gamma_t / cos_theta_t);
                const double a[4] = {f, sqr(1 - f) * t, sqr(1 - f) * t * t * f,
                                     sqr(1 - f) * t * t * f * t * f / (1 - t * f)};
                for (int lobe = 0; lobe < 4; ++lobe) {
                    EXPECT_NEAR(fiber.at({wo, h}).attenuation(lobe)[c], a[lobe], 1e-6 * a[lobe] + 1e-12)
                        << "lobe " << lobe << " h " << h;
                }
            }
        }
    }
}

// The closed-form model written out independently in double precision (d'Eon's M with the
// standard library's Bessel function, angles added directly), against ChiangPoint::f. With
// `sampler_weights` it is the analytic sampler's density instead: lobe weights luminance(A_p),
// M_p about the tilted θ_o.
std::array<double, 4> reference_lobes(const ChiangParams &p, Vec3 wi, Vec3 wo, double h, int channel,
                                      bool tilt_on_outgoing, bool sampler_weights = false) {
    const double beta_m = std::clamp(double(p.roughness), 0.001, 1.0);
    const double v = cycles_v(beta_m);
    const double v_lobe[4] = {cycles_v((1.0 - p.coat) * beta_m), v / 4, 4 * v, 4 * v};
    const double s = cycles_s(p.radial_roughness);
    const double alpha = p.offset;
    const double delta[4] = {2 * alpha, -alpha, -4 * alpha, 0};
    const double theta_o = std::asin(double(wo.x)), theta_i = std::asin(double(wi.x));
    const double phi = std::atan2(double(wi.z), double(wi.y)) - std::atan2(double(wo.z), double(wo.y));
    const double eta = p.ior;
    const double gamma_o = std::asin(h);
    const double eta_prime = std::sqrt(eta * eta - sqr(std::sin(theta_o))) / std::cos(theta_o);
    const double gamma_t = std::asin(h / eta_prime);
    const double theta_t = std::asin(std::sin(theta_o) / eta);
    const double f = fresnel_dielectric(std::cos(theta_o) * std::cos(gamma_o), eta);
    std::array<double, 4> lobes{};
    double luminance_total = 0;
    double a[4][3];
    for (int c = 0; c < 3; ++c) {
        const double t = std::exp(-p.sigma_a[c] * 2 * std::cos(gamma_t) / std::cos(theta_t));
        const double ac[4] = {f, sqr(1 - f) * t, sqr(1 - f) * t * t * f, sqr(1 - f) * t * t * f * t * f / (1 - t * f)};
        for (int lobe = 0; lobe < 4; ++lobe) a[lobe][c] = ac[lobe];
    }
    for (int lobe = 0; lobe < 4; ++lobe) luminance_total += 0.2126 * a[lobe][0] + 0.7152 * a[lobe][1] + 0.0722 * a[lobe][2];
    for (int lobe = 0; lobe < 4; ++lobe) {
        const bool outgoing = tilt_on_outgoing || sampler_weights;
        const double ti = outgoing ? theta_i : theta_i + delta[lobe];
        const double to = outgoing ? theta_o + delta[lobe] : theta_o;
        const double m = std::exp(-std::sin(ti) * std::sin(to) / v_lobe[lobe]) *
                         std::cyl_bessel_i(0.0, std::fabs(std::cos(ti)) * std::fabs(std::cos(to)) / v_lobe[lobe]) /
                         (2 * v_lobe[lobe] * std::sinh(1 / v_lobe[lobe]));
        double n = 1 / kTwoPi;
        if (lobe < 3) {
            const double x = std::remainder(phi - (2 * lobe * gamma_t - 2 * gamma_o + lobe * kPi), kTwoPi);
            const double e = std::exp(-std::fabs(x) / s);
            n = e / (s * sqr(1 + e)) / (1 - 2 / (1 + std::exp(kPi / s)));
        }
        const double weight = sampler_weights
                                  ? (0.2126 * a[lobe][0] + 0.7152 * a[lobe][1] + 0.0722 * a[lobe][2]) / luminance_total
                                  : a[lobe][channel];
        lobes[std::size_t(lobe)] = weight * m * n;
    }
    return lobes;
}

Rgb reference_f_cos(const ChiangParams &p, Vec3 wi, Vec3 wo, double h) {
    Rgb result;
    for (int c = 0; c < 3; ++c) {
        const std::array<double, 4> lobes = reference_lobes(p, wi, wo, h, c, p.tilt == ChiangTilt::Outgoing);
        (c == 0 ? result.r : c == 1 ? result.g : result.b) = float(lobes[0] + lobes[1] + lobes[2] + lobes[3]);
    }
    return result;
}

double reference_sampler_pdf(const ChiangParams &p, Vec3 wi, Vec3 wo, double h) {
    const std::array<double, 4> lobes = reference_lobes(p, wi, wo, h, 0, true, true);
    return lobes[0] + lobes[1] + lobes[2] + lobes[3];
}

TEST(ChiangNearField, MatchesTheClosedFormModel) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const ChiangParams cases[] = {
        {},
        {{0.1f, 0.2f, 0.4f}, 0.6f, 0.45f, 0.4f, 1.45f, float(radians(3.5))},
        {{2.0f, 3.0f, 5.0f}, 0.25f, 0.8f, 0.0f, 1.7f, float(radians(-4.0))},
        {{0.245531f, 0.52f, 1.365f}, 0.3f, 0.3f, 0.0f, 1.55f, float(radians(2.0)), ChiangTilt::Outgoing},
        {{0.1f, 0.2f, 0.4f}, 0.6f, 0.45f, 0.4f, 1.45f, float(radians(-4.0)), ChiangTilt::Outgoing},
    };
    for (const ChiangParams &p : cases) {
        const ChiangFiber fiber = make_fiber(p);
        for (int i = 0; i < 400; ++i) {
            const Vec3 wo = direction(std::asin(2 * unit(rng) - 1), kTwoPi * unit(rng));
            const Vec3 wi = direction(std::asin(2 * unit(rng) - 1), kTwoPi * unit(rng));
            const float h = float(2 * unit(rng) - 1);
            const Rgb expected = reference_f_cos(p, wi, wo, h);
            const Rgb actual = fiber.f_cos_near(wi, wo, h);
            const double pdf = fiber.at({wo, h}).pdf(wi);
            EXPECT_NEAR(pdf, reference_sampler_pdf(p, wi, wo, h), 2e-5 * pdf + 1e-30) << "sampler pdf, case " << i;
            Rgb lobes;
            for (int lobe = 0; lobe < 4; ++lobe) lobes += fiber.at({wo, h}).lobe_f(lobe, wi);
            // The one-pass evaluation a light sample uses, against the same references.
            float fused_pdf = -1.0f;
            const Rgb fused = fiber.at({wo, h}).f_and_pdf(wi, fused_pdf);
            EXPECT_NEAR(fused_pdf, reference_sampler_pdf(p, wi, wo, h), 2e-5 * pdf + 1e-30) << "fused pdf, case " << i;
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(actual[c], expected[c], 2e-5 * expected[c] + 1e-30) << "case " << i;
                EXPECT_NEAR(fused[c], expected[c], 2e-5 * expected[c] + 1e-30) << "fused f, case " << i;
                EXPECT_NEAR(lobes[c], actual[c], 1e-6 * actual[c] + 1e-30);
            }
            // sample_with_f: the drawn direction's f and density, by the references.
            Rgb sampled_f;
            const auto sample = fiber.at({wo, h}).sample_with_f(float(unit(rng)), float(unit(rng)),
                                                                  float(unit(rng)), sampled_f);
            ASSERT_TRUE(sample.has_value());
            const double sample_pdf = reference_sampler_pdf(p, sample->wi, wo, h);
            EXPECT_NEAR(sample->pdf, sample_pdf, 2e-5 * sample_pdf) << "sample_with_f pdf, case " << i;
            const Rgb sample_f = reference_f_cos(p, sample->wi, wo, h);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(sampled_f[c], sample_f[c], 2e-5 * sample_f[c] + 1e-30) << "sample_with_f f, case " << i;
        }
    }
    EXPECT_EQ(make_fiber({}).at({{0, 1, 0}, 0}).lobe_f(4, {1, 0, 0}).r, 0.0f);
    EXPECT_EQ(make_fiber({}).lobe_f_cos(-1, {1, 0, 0}, {0, 1, 0}).r, 0.0f);
}

// ---------------------------------------------------------------------------------------
// Far field.

TEST(ChiangFarField, EqualsTheNearFieldAveragedOverH) {
    // Brute force: a 20000-point midpoint rule over the near field's offset, at a handful of
    // direction pairs, for the fixed-node rule (default radial roughness) and the graded rule
    // (small radial roughness), clear and absorbing.
    ChiangParams fixed_rule;
    ChiangParams graded_rule;
    graded_rule.radial_roughness = 0.05f;
    graded_rule.sigma_a = Rgb(0.0f);
    graded_rule.coat = 0.3f;
    ChiangParams large_s;
    large_s.radial_roughness = 0.9f;
    large_s.offset = float(radians(-3.0));
    const std::vector<std::pair<double, double>> directions = {
        {radians(10.0), radians(-15.0)}, {radians(-45.0), radians(40.0)}, {radians(70.0), radians(-60.0)},
        {radians(-5.0), radians(3.0)},   {radians(30.0), radians(-31.0)}, {radians(-80.0), radians(75.0)}};
    const std::vector<double> phis = {0.0, 0.4, 1.7, 2.6, 3.1, -0.9, -2.2};
    for (const ChiangParams &p : {fixed_rule, graded_rule, large_s}) {
        const ChiangFiber fiber = make_fiber(p);
        for (const auto &[theta_o, theta_i] : directions) {
            const Vec3 wo = direction(theta_o, kCyclesPhiO);
            for (double phi : phis) {
                const Vec3 wi = direction(theta_i, kCyclesPhiO + phi);
                // Midpoint rule in γ (h = sin γ, dh = cos γ dγ): in h itself the logistic's
                // bump becomes arbitrarily thin at the edges, where dγ/dh diverges.
                const int n = 20000;
                double brute[4][3] = {};
                for (int k = 0; k < n; ++k) {
                    const double gamma = -kHalfPi + (k + 0.5) * kPi / n;
                    const double weight = 0.5 * std::cos(gamma) * kPi / n;
                    for (int lobe = 0; lobe < 4; ++lobe) {
                        const Rgb v = fiber.at({wo, float(std::sin(gamma))}).lobe_f(lobe, wi);
                        for (int c = 0; c < 3; ++c) brute[lobe][c] += weight * v[c];
                    }
                }
                Rgb total_far = fiber.f_cos(wi, wo);
                // The factors a sweep forms outer products of (fiber.h's separable view).
                const std::unique_ptr<const FarFieldView> view = fiber.view(wo);
                ASSERT_TRUE(view->separable());
                double total_brute[3] = {};
                for (int lobe = 0; lobe < 4; ++lobe) {
                    const Rgb far = fiber.lobe_f_cos(lobe, wi, wo);
                    const Rgb factored = view->azimuthal(lobe, phi) * float(view->longitudinal(lobe, theta_i));
                    for (int c = 0; c < 3; ++c) {
                        total_brute[c] += brute[lobe][c];
                        EXPECT_NEAR(far[c], brute[lobe][c], 1e-3 * brute[lobe][c] + 1e-25)
                            << "lobe " << lobe << " θo " << degrees(theta_o) << " θi " << degrees(theta_i)
                            << " φ " << phi << " β_n " << p.radial_roughness;
                        EXPECT_NEAR(factored[c], brute[lobe][c], 1e-3 * brute[lobe][c] + 1e-25) << "factors, lobe " << lobe;
                    }
                }
                for (int c = 0; c < 3; ++c) EXPECT_NEAR(total_far[c], total_brute[c], 1e-3 * total_brute[c]);
            }
        }
    }
}

TEST(ChiangFarField, IsSymmetricInPhiAndFiniteEverywhere) {
    for (float radial : {0.0f, 0.05f, 0.3f, 1.0f}) {
        ChiangParams p;
        p.radial_roughness = radial;
        p.roughness = 0.0f;
        const ChiangFiber fiber = make_fiber(p);
        for (double theta_o = -kHalfPi; theta_o <= kHalfPi + 1e-9; theta_o += kPi / 12) {
            const Vec3 wo = direction(theta_o, kCyclesPhiO);
            for (double theta_i = -kHalfPi; theta_i <= kHalfPi + 1e-9; theta_i += kPi / 12) {
                for (double phi = 0.0; phi <= kPi + 1e-9; phi += kPi / 10) {
                    const Rgb plus = fiber.f_cos(direction(theta_i, kCyclesPhiO + phi), wo);
                    const Rgb minus = fiber.f_cos(direction(theta_i, kCyclesPhiO - phi), wo);
                    for (int c = 0; c < 3; ++c) {
                        ASSERT_TRUE(std::isfinite(plus[c]) && plus[c] >= 0.0f);
                        EXPECT_NEAR(plus[c], minus[c], 1e-4 * plus[c] + 1e-30);
                    }
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// White furnace: ∫ f_cos dω_i over the sphere by tensor-product quadrature over θ_i
// (measure cos θ_i dθ_i, i.e. d sin θ_i) and φ, graded around the lobes.

struct FurnaceCase {
    float roughness;
    double offset_deg;
    ChiangTilt tilt = ChiangTilt::Incident;
};

class ChiangWhiteFurnace : public ::testing::TestWithParam<FurnaceCase> {};

// The lobes' centres in θ_i and widths, for the θ_i grid.
std::vector<Peak> theta_peaks(const ChiangFiber &fiber, double theta_o) {
    const double alpha = fiber.params().offset;
    const double delta[4] = {2 * alpha, -alpha, -4 * alpha, 0};
    std::vector<Peak> peaks;
    for (int lobe = 0; lobe < 4; ++lobe) {
        const double centre = std::clamp(-theta_o - delta[lobe], -kHalfPi, kHalfPi);
        peaks.push_back({centre, std::min(0.4, std::sqrt(fiber.lobe_variance(lobe)))});
    }
    return peaks;
}

// ∫∫ f(θ_i, φ) cos θ_i dθ_i dφ per channel.
std::array<double, 3> sphere_integral(const std::function<Rgb(double, double)> &f, const Rule &theta_rule,
                                      const Rule &phi_rule) {
    std::array<double, 3> sum{};
    for (std::size_t i = 0; i < theta_rule.x.size(); ++i) {
        std::array<double, 3> inner{};
        for (std::size_t j = 0; j < phi_rule.x.size(); ++j) {
            const Rgb value = f(theta_rule.x[i], phi_rule.x[j]);
            for (int c = 0; c < 3; ++c) inner[std::size_t(c)] += phi_rule.w[j] * value[c];
        }
        for (int c = 0; c < 3; ++c) sum[std::size_t(c)] += theta_rule.w[i] * std::cos(theta_rule.x[i]) * inner[std::size_t(c)];
    }
    return sum;
}

double luminance(const std::array<double, 3> &c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// The predicted albedo of a clear fiber: Σ_p A_p c_p with c_p = ∫ M_p(θ_i + δ_p) cos θ_i dθ_i
// (1 without tilt), the A_p of a clear fiber in closed form (Σ A_p = 1) at the given h.
std::array<double, 4> clear_attenuation(double theta_o, double h, double eta) {
    const double f = fresnel_dielectric(std::cos(theta_o) * std::sqrt(std::max(0.0, 1 - h * h)), eta);
    return {f, sqr(1 - f), sqr(1 - f) * f, (1 - f) * f * f};
}

TEST_P(ChiangWhiteFurnace, AlbedoOfAClearFiber) {
    const FurnaceCase param = GetParam();
    ChiangParams p;
    p.sigma_a = Rgb(0.0f);
    p.roughness = param.roughness;
    p.offset = float(radians(param.offset_deg));
    p.tilt = param.tilt;
    const ChiangFiber fiber = make_fiber(p);
    ChiangParams absorbing = p;
    absorbing.sigma_a = {0.245531f, 0.52f, 1.365f};
    const ChiangFiber dark = make_fiber(absorbing);
    const double alpha = p.offset;
    const double delta[4] = {2 * alpha, -alpha, -4 * alpha, 0};
    const double s = fiber.logistic_scale();

    const std::vector<double> theta_o_list = {-85, -60, -30, 0, 30, 60, 85};
    const std::vector<double> h_list = {-0.8, 0.0, 0.5, 0.95};
    std::printf("[ furnace ] roughness %.1f offset %.0f°: albedo − 1 (luminance)\n", param.roughness,
                param.offset_deg);
    std::printf("[ furnace ]   θo   far        h=-0.8     h=0        h=0.5      h=0.95     | far predicted\n");
    for (double theta_o_deg : theta_o_list) {
        const double theta_o = radians(theta_o_deg);
        const Vec3 wo = direction(theta_o, kCyclesPhiO);
        // Lobes graded out to 8 widths (M is below e^{−30} of its peak beyond).
        const Rule theta_rule = composite(
            graded_breaks(-kHalfPi, kHalfPi, 0.4, theta_peaks(fiber, theta_o), false, 8.0, 2.0), gl8());

        double c[4];
        // Cycles 4.2's M_p about a tilted cone is still a density (its integral is 1).
        for (int lobe = 0; lobe < 4; ++lobe)
            c[lobe] = param.tilt == ChiangTilt::Outgoing ? 1.0 : longitudinal_integral(theta_o, fiber.lobe_variance(lobe), delta[lobe]);
        const bool exact = param.offset_deg == 0.0 || param.tilt == ChiangTilt::Outgoing;

        // Far field: the azimuthal profile is smooth on the scale of s.
        const Rule phi_far = composite(graded_breaks(-kPi, kPi, std::min(0.25, 2 * s), {}), gl8());
        const double far = luminance(sphere_integral(
            [&](double ti, double phi) { return fiber.f_cos(direction(ti, kCyclesPhiO + phi), wo); },
            theta_rule, phi_far));
        // Prediction: A_p averaged over h = sin γ.
        double predicted_far = 0;
        {
            const Rule gamma_rule = composite(graded_breaks(-kHalfPi, kHalfPi, 0.1, {}), gl16());
            for (int lobe = 0; lobe < 4; ++lobe) {
                const double mean_a = 0.5 * integrate(
                    [&](double g) { return clear_attenuation(theta_o, std::sin(g), p.ior)[std::size_t(lobe)] * std::cos(g); },
                    gamma_rule);
                predicted_far += mean_a * c[lobe];
            }
        }

        std::printf("[ furnace ] %5.0f  %+.2e", theta_o_deg, far - 1);
        EXPECT_NEAR(far, predicted_far, 2e-3) << "far field, θo " << theta_o_deg;
        if (exact) {
            EXPECT_NEAR(far, 1.0, 0.01) << "far field, θo " << theta_o_deg;
        }

        for (double h : h_list) {
            const double gamma_o = std::asin(h);
            const double k = std::cos(theta_o) / std::sqrt(sqr(double(p.ior)) - sqr(std::sin(theta_o)));
            std::vector<Peak> phi_peaks;
            for (int lobe = 0; lobe < 3; ++lobe) {
                phi_peaks.push_back({chiang::azimuthal_shift(lobe, gamma_o, std::asin(h * k)), s});
            }
            const Rule phi_near = composite(graded_breaks(-kPi, kPi, 0.4, phi_peaks, true, 16.0, 2.0), gl8());
            const double near = luminance(sphere_integral(
                [&](double ti, double phi) { return fiber.f_cos_near(direction(ti, kCyclesPhiO + phi), wo, float(h)); },
                theta_rule, phi_near));
            const std::array<double, 4> a = clear_attenuation(theta_o, h, p.ior);
            double predicted = 0;
            for (int lobe = 0; lobe < 4; ++lobe) predicted += a[std::size_t(lobe)] * c[lobe];
            std::printf("  %+.2e", near - 1);
            EXPECT_NEAR(near, predicted, 2e-3) << "near field, θo " << theta_o_deg << " h " << h;
            if (exact) {
                EXPECT_NEAR(near, 1.0, 0.01) << "near field, θo " << theta_o_deg << " h " << h;
            }

            if (exact) {
                // An absorbing fiber returns less, in every channel.
                const std::array<double, 3> albedo = sphere_integral(
                    [&](double ti, double phi) { return dark.f_cos_near(direction(ti, kCyclesPhiO + phi), wo, float(h)); },
                    theta_rule, phi_near);
                for (int channel = 0; channel < 3; ++channel) {
                    EXPECT_LE(albedo[std::size_t(channel)], 1.0 + 1e-3) << "absorbing, channel " << channel;
                    EXPECT_LT(albedo[std::size_t(channel)], near);
                }
            }
        }
        std::printf("  | %+.2e\n", predicted_far - 1);
        ::testing::Test::RecordProperty("far_albedo_error_theta_o_" + std::to_string(int(theta_o_deg)),
                                        std::to_string(far - 1));
    }
}

INSTANTIATE_TEST_SUITE_P(RoughnessAndOffset, ChiangWhiteFurnace,
                         ::testing::Values(FurnaceCase{0.3f, 0.0}, FurnaceCase{0.1f, 0.0},
                                           FurnaceCase{0.7f, 0.0}, FurnaceCase{0.3f, 2.0},
                                           FurnaceCase{0.1f, 2.0}, FurnaceCase{0.7f, 2.0},
                                           FurnaceCase{0.3f, 2.0, ChiangTilt::Outgoing},
                                           FurnaceCase{0.1f, 4.0, ChiangTilt::Outgoing},
                                           FurnaceCase{0.7f, 2.0, ChiangTilt::Outgoing}),
                         [](const ::testing::TestParamInfo<FurnaceCase> &case_info) {
                             return "roughness" + std::to_string(int(case_info.param.roughness * 10 + 0.5)) +
                                    "tenths_offset" + std::to_string(int(case_info.param.offset_deg)) + "deg" +
                                    (case_info.param.tilt == ChiangTilt::Outgoing ? "_cycles42" : "");
                         });

// ---------------------------------------------------------------------------------------
// The analytic sampler.

TEST(ChiangSampler, ChoosesLobesByLuminanceOfTheAttenuation) {
    ChiangParams p;
    p.coat = 0.5f;
    const ChiangFiber fiber = make_fiber(p);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    int lobe_counts[4] = {};
    const int n = 20000;
    const Vec3 wo = direction(radians(25.0), kCyclesPhiO);
    const float h = 0.3f;
    const ChiangPoint point = fiber.at({wo, h});
    for (int i = 0; i < n; ++i) {
        const std::optional<DirectionSample> sample = point.sample(unit(rng), unit(rng), unit(rng));
        ASSERT_TRUE(sample.has_value());
        ASSERT_NEAR(length(sample->wi), 1.0f, 1e-5f);
        ++lobe_counts[sample->lobe];
    }
    // Closed form: luminance(F, (1 − F)²T, ...) with the reference's attenuations.
    const double theta_o = radians(25.0), gamma_o = std::asin(double(h));
    const double f = fresnel_dielectric(std::cos(theta_o) * std::cos(gamma_o), double(p.ior));
    const double k = std::cos(theta_o) / std::sqrt(sqr(double(p.ior)) - sqr(std::sin(theta_o)));
    const double cos_theta_t = std::sqrt(1.0 - sqr(std::sin(theta_o) / p.ior));
    double a[4] = {};
    for (int c = 0; c < 3; ++c) {
        const double t = std::exp(-p.sigma_a[c] * 2.0 * std::sqrt(1.0 - sqr(h * k)) / cos_theta_t);
        const double weight = c == 0 ? 0.2126 : c == 1 ? 0.7152 : 0.0722;
        const double ac[4] = {f, sqr(1 - f) * t, sqr(1 - f) * t * t * f, sqr(1 - f) * t * t * f * t * f / (1 - t * f)};
        for (int lobe = 0; lobe < 4; ++lobe) a[lobe] += weight * ac[lobe];
    }
    const double total = a[0] + a[1] + a[2] + a[3];
    for (int lobe = 0; lobe < 4; ++lobe) {
        EXPECT_NEAR(point.lobe_probability(lobe), a[lobe] / total, 1e-6) << "lobe " << lobe;
        const double expected = n * a[lobe] / total;
        EXPECT_NEAR(lobe_counts[lobe], expected, 5 * std::sqrt(expected) + 1) << "lobe " << lobe;
    }
    // Edge values of the random numbers still give valid samples, with the reference density.
    for (float u0 : {0.0f, 0.99999994f})
        for (float u1 : {0.0f, 0.99999994f})
            for (float u2 : {0.0f, 0.99999994f}) {
                const std::optional<DirectionSample> sample = point.sample(u0, u1, u2);
                ASSERT_TRUE(sample.has_value());
                const double expected = reference_sampler_pdf(p, sample->wi, wo, h);
                EXPECT_NEAR(sample->pdf, expected, 1e-4 * expected);
            }
}

TEST(ChiangSampler, PdfIsProportionalToTheLuminanceOfFWithoutTiltOrWithCycles42sTilt) {
    // The sampler's M_p are tilted on θ_o, so pdf = luminance(f) / Σ_p luminance(A_p) when f's
    // are too (Cycles 4.2) or there is no tilt; Cycles 3.4's tilt on θ_i differs.
    struct Case {
        double offset_deg;
        ChiangTilt tilt;
        bool proportional;
    };
    for (const Case c : {Case{0.0, ChiangTilt::Incident, true}, Case{2.0, ChiangTilt::Incident, false},
                         Case{2.0, ChiangTilt::Outgoing, true}, Case{-6.0, ChiangTilt::Outgoing, true}}) {
        ChiangParams p;
        p.coat = 0.3f;
        p.offset = float(radians(c.offset_deg));
        p.tilt = c.tilt;
        const ChiangFiber fiber = make_fiber(p);
        std::mt19937 rng(5);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        double worst = 0;
        for (int i = 0; i < 2000; ++i) {
            const Vec3 wo = direction(std::asin(2 * unit(rng) - 1), kCyclesPhiO);
            const Vec3 wi = direction(std::asin(2 * unit(rng) - 1), kTwoPi * unit(rng));
            const ChiangPoint point = fiber.at({wo, float(2 * unit(rng) - 1)});
            double total = 0;
            for (int lobe = 0; lobe < 4; ++lobe) total += luminance(point.attenuation(lobe));
            const double expected = luminance(point.f(wi)) / total;
            const double pdf = point.pdf(wi);
            if (expected > 1e-20) worst = std::max(worst, std::fabs(pdf - expected) / expected);
        }
        if (c.proportional) EXPECT_LT(worst, 1e-5) << c.offset_deg;
        else EXPECT_GT(worst, 1e-3) << c.offset_deg;
    }
}

struct Chi2Case {
    double theta_o_deg;
    float h;
    float coat;
};

class ChiangChi2 : public ::testing::TestWithParam<Chi2Case> {};

constexpr Chi2Case kChi2Cases[] = {
    {-80, -0.4f, 0.0f}, {-40, -0.4f, 0.0f}, {0, -0.4f, 0.0f}, {35, -0.4f, 0.0f}, {82, -0.4f, 0.0f},
    {-80, 0.7f, 0.4f},  {-40, 0.7f, 0.4f},  {0, 0.7f, 0.4f},  {35, 0.7f, 0.4f},  {82, 0.7f, 0.4f},
};

TEST_P(ChiangChi2, AnalyticSamplerMatchesItsPdf) {
    const Chi2Case param = GetParam();
    ChiangParams p;  // Blender's absorption default, roughness 0.3, offset 2°
    p.coat = param.coat;
    const ChiangFiber fiber = make_fiber(p);
    const Vec3 wo = direction(radians(param.theta_o_deg), kCyclesPhiO);
    const ChiangPoint point = fiber.at({wo, param.h});

    testing::Chi2Options options;
    options.sample_count = 1000000;
    options.significance = 0.01;
    options.test_count = int(std::size(kChi2Cases));  // Šidák over the whole family
    options.seed = 0x5eed + std::uint64_t(param.theta_o_deg * 10 + 1000) * 7 + std::uint64_t(param.h * 100 + 200);
    const testing::Chi2Result result = testing::chi2_direction_test(
        [&](testing::Sample3 u) -> std::optional<Vec3> {
            const std::optional<DirectionSample> sample = point.sample(u.u0, u.u1, u.u2);
            if (!sample) return std::nullopt;
            return sample->wi;
        },
        [&](Vec3 wi) { return double(point.pdf(wi)); }, options);
    std::printf("[ chi2 ] θo %+5.0f h %+.1f coat %.1f: χ² %.1f dof %d p-value %.4f ∫pdf %.6f\n",
                param.theta_o_deg, param.h, param.coat, result.statistic, result.degrees_of_freedom,
                result.p_value, result.pdf_integral);
    ::testing::Test::RecordProperty("p_value", std::to_string(result.p_value));
    EXPECT_TRUE(result.passed) << result.message;
    EXPECT_EQ(result.failed_samples, 0);
    EXPECT_NEAR(result.pdf_integral, 1.0, 2e-3);
}

TEST(ChiangChi2Control, CyclesOrderTiltIsRejected) {
    // Negative control for the χ² family above: Cycles samples θ around the untilted cone and
    // then rotates it by −δ_p, without the Jacobian; against our exact pdf this must fail.
    ChiangParams p;
    const ChiangFiber fiber = make_fiber(p);
    const double theta_o = radians(60.0);
    const Vec3 wo = direction(theta_o, kCyclesPhiO);
    const float h = 0.2f;
    const double k = std::cos(theta_o) / std::sqrt(sqr(double(p.ior)) - sqr(std::sin(theta_o)));
    const double alpha = p.offset;
    const double delta[4] = {2 * alpha, -alpha, -4 * alpha, 0};
    const ChiangPoint point = fiber.at({wo, h});
    const std::array<float, 4> probability = {point.lobe_probability(0), point.lobe_probability(1),
                                              point.lobe_probability(2), point.lobe_probability(3)};

    testing::Chi2Options options;
    options.sample_count = 1000000;
    const testing::Chi2Result result = testing::chi2_direction_test(
        [&](testing::Sample3 u) -> std::optional<Vec3> {
            int lobe = 0;
            double rest = u.u2;
            while (lobe < 3 && rest >= probability[std::size_t(lobe)]) rest -= probability[std::size_t(lobe++)];
            const double t = chiang::sample_cone_cosine(std::clamp(rest / probability[std::size_t(lobe)], 0.0, 1.0),
                                                        fiber.lobe_variance(lobe));
            const double sin_theta = -t * std::sin(theta_o) +
                                     std::sqrt(std::max(0.0, 1 - t * t)) * std::cos(kTwoPi * u.u1) * std::cos(theta_o);
            const double theta_i = std::asin(std::clamp(sin_theta, -1.0, 1.0)) - delta[lobe];
            double phi = kTwoPi * u.u0;
            if (lobe < 3) {
                phi = chiang::azimuthal_shift(lobe, std::asin(double(h)), std::asin(h * k)) +
                      chiang::TrimmedLogistic(fiber.logistic_scale()).sample(u.u0);
            }
            // θ_i pushed past ±π/2 continues over the pole.
            const double wrapped = std::clamp(theta_i, -kHalfPi, kHalfPi);
            if (wrapped != theta_i) phi += kPi;
            return direction(theta_i > kHalfPi ? kPi - theta_i : theta_i < -kHalfPi ? -kPi - theta_i : theta_i,
                             kCyclesPhiO + phi);
        },
        [&](Vec3 wi) { return double(point.pdf(wi)); }, options);
    std::printf("[ chi2 control ] Cycles-order tilt: χ² %.1f dof %d p-value %.3g\n", result.statistic,
                result.degrees_of_freedom, result.p_value);
    EXPECT_FALSE(result.passed);
    EXPECT_LT(result.p_value, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Directions, ChiangChi2, ::testing::ValuesIn(kChi2Cases),
                         [](const ::testing::TestParamInfo<Chi2Case> &case_info) {
                             const int theta = int(case_info.param.theta_o_deg);
                             return std::string("theta") + (theta < 0 ? "minus" : "") + std::to_string(std::abs(theta)) +
                                    "_h" + (case_info.param.h < 0 ? "minus" : "") +
                                    std::to_string(int(std::fabs(case_info.param.h) * 10 + 0.5)) + "tenths";
                         });

}  // namespace
}  // namespace hairis
