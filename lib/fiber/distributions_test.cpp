#include "fiber/distributions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include <tbb/task_arena.h>

#include "core/frame.h"

#include "fiber/chiang.h"
#include "fiber/marschner.h"

namespace hairis {
namespace {

// ------------------------------------------------------------------------------------------
// A test-local fiber with Gaussian lobes: f_p·cos θ_i = ½ c_p g(θ_h − α_p; β_p²) N_p(φ) with
// N_R = (1 + cos φ)/2π (backward), N_TT ∝ exp(κ cos(φ − π)) (a forward lobe at φ = ±π),
// N_TRT = 1/2π. The ½ makes g a unit area over θ_i; without Marschner's 1/cos²θ_d the albedo
// falls off towards grazing angles (≈ Σ c_p cos θ_r), like an energy-conserving model's.

double gauss(double x, double var) { return std::exp(-0.5 * x * x / var) / std::sqrt(kTwoPi * var); }

const Rgb kScale[3] = {Rgb(0.08f), Rgb(0.35f, 0.25f, 0.12f), Rgb(0.12f, 0.08f, 0.04f)};
const LobeShape kShapes[3] = {{float(radians(-5)), float(radians(6))},
                              {float(radians(2.5)), float(radians(3))},
                              {float(radians(7.5)), float(radians(12))}};
constexpr double kKappa = 4.0;
// ∫_{−π}^{π} exp(κ cos x) dx = 2π I0(κ); I0(4) = 11.301921952136330.
constexpr double kVonMisesNorm = 1.0 / (kTwoPi * 11.301921952136330);

class TestFiber : public FiberModel {
  public:
    std::string name() const override { return "test_gaussian"; }
    int lobe_count() const override { return 3; }
    Rgb lobe_f_cos(int p, Vec3 wi, Vec3 wo) const override {
        const FiberAngles ai = angles_of(wi), ao = angles_of(wo);
        const double ti = ai.theta, to = ao.theta;
        const double phi = wrap_angle(double(ai.phi) - double(ao.phi));
        const double th = 0.5 * (ti + to), td = 0.5 * (to - ti);
        double n;
        if (p == 0) n = (1.0 + std::cos(phi)) * kInvTwoPi;
        else if (p == 1) n = std::exp(kKappa * std::cos(phi - kPi)) * kVonMisesNorm;
        else n = kInvTwoPi;
        (void)td;
        const double f_cos = 0.5 * gauss(th - kShapes[p].alpha, sqr(double(kShapes[p].beta))) * n;
        return kScale[p] * float(f_cos);
    }
    LobeShape lobe_shape(int p) const override { return kShapes[p]; }
};

template <typename T>
T value_of(Expected<T> e) {
    EXPECT_TRUE(e.ok()) << (e.ok() ? "" : e.error().message);
    return std::move(e).value();
}

/// Directional albedo ∫ luminance(f_cos(ω_i, ω_r)) dω_i by an independent rule: the
/// midpoint rule in (u = sin θ_i, φ_i), uniform in solid angle.
double independent_albedo(const FiberModel &model, double theta_r, double phi_r, int nu, int nphi) {
    const Vec3 wo = direction_of(float(theta_r), float(phi_r));
    double sum = 0;
    for (int a = 0; a < nu; ++a) {
        const double u = -1.0 + (a + 0.5) * 2.0 / nu;
        const double th = std::asin(u);
        double row = 0;
        for (int b = 0; b < nphi; ++b) {
            const double ph = -kPi + (b + 0.5) * kTwoPi / nphi;
            row += double(luminance(model.f_cos(direction_of(float(th), float(ph)), wo)));
        }
        sum += row;
    }
    return sum * (2.0 / nu) * (kTwoPi / nphi);
}

/// θ_i of the largest row of the azimuthal average of a grid, refined by theta_stats.
double theta_peak(const Grid2D &g, ThetaDensity density) {
    return value_of(theta_stats(azimuthal_average(g), density)).peak;
}

/// φ of the column with the largest sum of value · solid angle over θ_i.
double phi_peak(const Grid2D &g) {
    int best = 0;
    double best_v = -1;
    for (int j = 0; j < g.phi_count; ++j) {
        double s = 0;
        for (int i = 0; i < g.theta_count; ++i) s += g.value(i, j) * g.cell_solid_angle(i);
        if (s > best_v) {
            best_v = s;
            best = j;
        }
    }
    return g.phi_center(best);
}

double angular_distance(double a, double b) { return std::fabs(wrap_angle(a - b)); }

// ------------------------------------------------------------------------------------------

TEST(Distributions, InvalidGridsAreRefusedBeforeAllocating) {
    const TestFiber fiber;
    auto error_of = [&](DirectGridSpec s, double theta_r = 0.3) {
        Expected<Grid2D> g = direct_distribution(fiber, theta_r, 0.0, s);
        EXPECT_FALSE(g.ok());
        return g.ok() ? std::string() : g.error().message;
    };
    DirectGridSpec s;
    s.theta_count = 0;
    std::string m = error_of(s);
    EXPECT_NE(m.find("theta_count"), std::string::npos) << m;
    EXPECT_NE(m.find("[1, 4096]"), std::string::npos) << m;
    s = {};
    s.phi_count = 5000;
    m = error_of(s);
    EXPECT_NE(m.find("phi_count"), std::string::npos) << m;
    s = {};
    s.theta_count = 4096;
    s.phi_count = 4096;  // 2^24 cells: each axis is fine, the total is not
    m = error_of(s);
    EXPECT_NE(m.find("theta_count * phi_count"), std::string::npos) << m;
    EXPECT_NE(m.find("4194304"), std::string::npos) << m;
    s = {};
    s.quadrature_points = 0;
    EXPECT_NE(error_of(s).find("quadrature_points"), std::string::npos);
    s = {};
    s.quadrature_points = 17;
    EXPECT_NE(error_of(s).find("quadrature_points"), std::string::npos);
    s = {};
    s.lobe = 3;  // the test fiber has lobes 0..2
    m = error_of(s);
    EXPECT_NE(m.find("lobe"), std::string::npos) << m;
    s = {};
    s.orientation_count = 0;
    EXPECT_NE(direct_distribution_relative(fiber, 0.0, s).error().message.find("orientation_count"),
              std::string::npos);
    m = error_of({}, 2.0);
    EXPECT_NE(m.find("theta_r"), std::string::npos) << m;
    EXPECT_FALSE(direct_distribution(fiber, 0.0, std::nan(""), {}).ok());

    Expected<DualScattering> ds = DualScattering::create(fiber, {});
    ASSERT_TRUE(ds.ok());
    ThetaGridSpec t;
    t.theta_count = 0;
    EXPECT_NE(multiple_distribution(ds.value(), 0.0, 1, t).error().message.find("ThetaGridSpec::theta_count"),
              std::string::npos);
    t = {};
    t.theta_count = 100000;
    EXPECT_FALSE(multiple_distribution(ds.value(), 0.0, 1, t).ok());
    m = multiple_distribution(ds.value(), 0.0, -1, {}).error().message;
    EXPECT_NE(m.find("n_h"), std::string::npos) << m;
}

TEST(Distributions, ThetaStatsRecoverAGaussian) {
    // A marginal density that is a Gaussian (μ = 0.3, σ = 0.2) of total mass 0.5.
    Grid1D g;
    g.theta_count = 720;
    g.values.resize(720);
    const double mu = 0.3, sigma = 0.2, mass = 0.5;
    const double dth = kPi / g.theta_count;
    for (int i = 0; i < g.theta_count; ++i)
        g.values[std::size_t(i)] = mass * gauss(g.theta_center(i) - mu, sigma * sigma) * dth / g.cell_solid_angle(i);
    const ThetaStats s = value_of(theta_stats(g, ThetaDensity::kMarginal));
    EXPECT_NEAR(s.peak, mu, 1e-3);
    EXPECT_NEAR(s.stddev, sigma, 2e-3);
    EXPECT_NEAR(s.fwhm_sigma, sigma, 2e-3);
    EXPECT_NEAR(s.scale, mass, 1e-4);
    EXPECT_NEAR(g.integral(), mass, 1e-4);
    // Per steradian the same grid is a Gaussian divided by 2π cos θ: the peak moves outwards.
    const ThetaStats sr = value_of(theta_stats(g, ThetaDensity::kPerSteradian));
    EXPECT_GT(sr.peak, mu);
    Grid1D zero;
    zero.theta_count = 10;
    zero.values.assign(10, 0.0);
    EXPECT_FALSE(theta_stats(zero).ok());
    Grid1D bad;
    bad.theta_count = 10;
    EXPECT_FALSE(theta_stats(bad).ok());
}

TEST(Distributions, DirectDistributionSumsToTheDirectionalAlbedo) {
    const TestFiber fiber;
    for (double deg : {-50.0, 0.0, 30.0}) {
        const double theta_r = radians(deg);
        const Grid2D g = value_of(direct_distribution(fiber, theta_r, 0.4, {}));
        const double reference = independent_albedo(fiber, theta_r, 0.4, 1000, 360);
        EXPECT_NEAR(g.integral(), reference, 2e-3 * reference) << deg;
        EXPECT_NEAR(azimuthal_average(g).integral(), g.integral(), 1e-12) << deg;
        // The relative-azimuth grid of a symmetric fiber has the same total.
        const Grid2D rel = value_of(direct_distribution_relative(fiber, theta_r, {}));
        EXPECT_NEAR(rel.integral(), reference, 2e-3 * reference) << deg;
    }
}

// θ_i of the largest per-steradian azimuthal integral of TestFiber's f·cos θ_i at θ_r, from its
// closed form by a 0.01° scan over θ_i.
double test_fiber_peak(double theta_r) {
    double best = 0, best_value = -1;
    for (int k = -9000; k <= 9000; ++k) {
        const double theta_i = radians(0.01 * k);
        double value = 0;
        for (int p = 0; p < 3; ++p)
            value += double(luminance(kScale[p])) *
                     gauss(0.5 * (theta_i + theta_r) - kShapes[p].alpha, sqr(double(kShapes[p].beta)));
        if (value > best_value) {
            best_value = value;
            best = theta_i;
        }
    }
    return best;
}

TEST(Distributions, DirectDistributionLobesSitWhereTheSeedSeesThem) {
    const TestFiber fiber;
    for (double deg : {-60.0, -30.0, 0.0, 30.0, 60.0}) {
        const double theta_r = radians(deg);
        DirectGridSpec spec;
        spec.lobe = kLobeR;
        const Grid2D r = value_of(direct_distribution_relative(fiber, theta_r, spec));
        // The R lobe peaks at θ_h = α_R, i.e. θ_i = −θ_r + 2α_R.
        EXPECT_NEAR(theta_peak(r, ThetaDensity::kPerSteradian), -theta_r + 2 * kShapes[0].alpha, radians(1.5)) << deg;
        spec.lobe = kLobeTT;
        const Grid2D tt = value_of(direct_distribution_relative(fiber, theta_r, spec));
        EXPECT_LT(angular_distance(phi_peak(tt), kPi), radians(2.5)) << deg;
        // Absolute azimuth: opposite the viewer.
        const double phi_r = 0.7;
        const Grid2D tt_abs = value_of(direct_distribution(fiber, theta_r, phi_r, spec));
        EXPECT_LT(angular_distance(phi_peak(tt_abs), phi_r + kPi), radians(2.5)) << deg;
        // All lobes together peak where the closed form's azimuthal integral does:
        // Σ_p lum(c_p) g((θ_i + θ_r)/2 − α_p) per steradian (each N_p integrates to 1).
        const Grid2D all = value_of(direct_distribution_relative(fiber, theta_r, {}));
        EXPECT_NEAR(theta_peak(all, ThetaDensity::kPerSteradian), test_fiber_peak(theta_r), radians(0.1)) << deg;
    }
}

TEST(Distributions, GridsAreBitIdenticalForOneAndTwoThreads) {
    const TestFiber fiber;
    const DualScattering ds = value_of(DualScattering::create(fiber, {}));
    auto compute = [&](int threads) {
        tbb::task_arena arena(threads);
        std::vector<std::vector<double>> out;
        arena.execute([&] {
            out.push_back(value_of(direct_distribution(fiber, 0.3, 0.1, {})).values);
            out.push_back(value_of(direct_distribution_relative(fiber, -0.7, {})).values);
            for (int n : kStrandCounts) out.push_back(value_of(multiple_distribution(ds, 0.5, n, {})).values);
        });
        return out;
    };
    const auto one = compute(1), two = compute(2);
    ASSERT_EQ(one.size(), two.size());
    for (std::size_t k = 0; k < one.size(); ++k) {
        ASSERT_EQ(one[k].size(), two[k].size());
        for (std::size_t i = 0; i < one[k].size(); ++i) ASSERT_EQ(one[k][i], two[k][i]) << k << " " << i;
    }
}

// ------------------------------------------------------------------------------------------
// Multiple scattering: peak, width, scale (the seed's Tables 1 and 2).

/// The seed's θ_r ∈ {−90, −60, −30, 0, 30, 60, 90}°; ±90° is replaced by ±89.5°, where the
/// fiber frame still exists (at exactly ±90° the view runs along the fiber, φ_r is undefined
/// and the models divide by cos θ).
const double kThetaRDegrees[7] = {-89.5, -60, -30, 0, 30, 60, 89.5};

struct TableRow {
    double theta_r_deg;
    int n_h;
    ThetaStats marginal, per_sr;
};

std::vector<TableRow> multiple_table(const DualScattering &ds, const char *label) {
    std::vector<TableRow> rows;
    std::printf("\n%s — S_multiple(θ_i | θ_r, n_h), 180 cells, azimuth-averaged\n", label);
    std::printf("  marginal m(θ_i) = 2π cos θ_i S̄ (per radian): peak, σ about peak, FWHM-σ, scale = albedo\n");
    std::printf("  per-sr S̄(θ_i): peak, FWHM-σ, ∫S̄ dθ_i (angles in degrees, σ in radians)\n");
    std::printf("  %7s %4s | %8s %7s %7s %10s | %8s %7s %10s\n", "theta_r", "n_h", "peak", "sd_pk", "fwhm_s",
                "scale", "peak_sr", "fwhm_s", "scale_sr");
    for (double deg : kThetaRDegrees) {
        for (int n : kStrandCounts) {
            const Grid1D g = value_of(multiple_distribution(ds, radians(deg), n, {}));
            TableRow row{deg, n, value_of(theta_stats(g, ThetaDensity::kMarginal)),
                         value_of(theta_stats(g, ThetaDensity::kPerSteradian))};
            std::printf("  %7.1f %4d | %8.2f %7.3f %7.3f %10.3e | %8.2f %7.3f %10.3e\n", deg, n,
                        degrees(row.marginal.peak), row.marginal.stddev, row.marginal.fwhm_sigma, row.marginal.scale,
                        degrees(row.per_sr.peak), row.per_sr.fwhm_sigma, row.per_sr.scale);
            rows.push_back(row);
        }
    }
    return rows;
}

/// What the multiple-scattering peaks must satisfy (marginal density, degrees).
struct PeakRules {
    double max_abs_theta_r = 60;  ///< peaks are checked for |θ_r| up to this
    int max_n_h = 16;             ///< … and n_h up to this
    double slack = 6;             ///< degrees of slack (lobe shifts α_p, cell size)
    double n1_relative = 0.35;    ///< n_h = 1: |peak + θ_r| ≤ n1_relative·|θ_r| + slack
    bool towards_normal = true;   ///< |peak| does not grow with n_h (2° tolerance)
};

/// For every θ_r: the scale (albedo) decreases strictly as n_h grows. For |θ_r| ≤
/// max_abs_theta_r and n_h ≤ max_n_h: the peak lies on the far side of the normal plane
/// between −θ_r and 0 (with slack), near −θ_r for n_h = 1, and (towards_normal) moves towards
/// the normal plane as n_h grows.
void check_multiple_table(const std::vector<TableRow> &rows, const PeakRules &rules, const char *label) {
    for (std::size_t k = 0; k < rows.size(); ++k) {
        const TableRow &r = rows[k];
        const double peak = degrees(r.marginal.peak), tr = r.theta_r_deg;
        const bool same_theta = k > 0 && rows[k - 1].theta_r_deg == tr;
        if (same_theta) {
            EXPECT_LT(r.marginal.scale, rows[k - 1].marginal.scale) << label << " theta_r=" << tr << " n_h=" << r.n_h;
        }
        if (std::fabs(tr) > rules.max_abs_theta_r || r.n_h > rules.max_n_h) continue;
        const double sign = tr > 0 ? 1.0 : (tr < 0 ? -1.0 : 0.0);
        const double far_side = -peak * sign;  // > 0: on the far side of the normal plane
        if (sign != 0) {
            EXPECT_GE(far_side, -rules.slack) << label << " theta_r=" << tr << " n_h=" << r.n_h << " peak=" << peak;
            EXPECT_LE(far_side, std::fabs(tr) + rules.slack) << label << " theta_r=" << tr << " n_h=" << r.n_h << " peak=" << peak;
        } else {
            EXPECT_LE(std::fabs(peak), rules.slack) << label << " theta_r=0 n_h=" << r.n_h;
        }
        if (r.n_h == 1) {
            EXPECT_LE(std::fabs(peak + tr), rules.n1_relative * std::fabs(tr) + rules.slack)
                << label << " theta_r=" << tr << " n_h=1 peak=" << peak;
        }
        if (rules.towards_normal && same_theta && std::fabs(tr) >= 30) {
            EXPECT_LE(std::fabs(peak), std::fabs(degrees(rows[k - 1].marginal.peak)) + 2.0)
                << label << " theta_r=" << tr << " n_h=" << r.n_h;
        }
    }
}

TEST(Distributions, MultipleDistributionPeaksOppositeTheViewerAndDarkens) {
    const TestFiber fiber;
    const DualScattering ds = value_of(DualScattering::create(fiber, {}));
    const auto rows = multiple_table(ds, "test fiber");
    check_multiple_table(rows, PeakRules{}, "test fiber");
    // Σ value · solid angle equals an independent fine quadrature of the azimuth-averaged term.
    for (double deg : {-45.0, 10.0}) {
        const double theta_r = radians(deg);
        const Grid1D g = value_of(multiple_distribution(ds, theta_r, 2, {}));
        double ref = 0;
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            const double u = -1.0 + (i + 0.5) * 2.0 / n;  // midpoint in sin θ_i
            ref += double(luminance(ds.multiple_f_cos(float(std::asin(u)), float(theta_r), 2)));
        }
        ref *= kTwoPi * 2.0 / n;
        EXPECT_NEAR(g.integral(), ref, 1e-3 * ref) << deg;
    }
}

// ------------------------------------------------------------------------------------------
// The real models.

// `shifts`: where each lobe's M_p peaks in θ_i, relative to −θ_r (R, TT, TRT).
void check_direct_real(const FiberModel &model, const char *label, const std::array<double, 3> &shifts) {
    const double r_shift = shifts[0];
    for (double deg : {-60.0, -30.0, 0.0, 30.0, 60.0}) {
        const double theta_r = radians(deg);
        DirectGridSpec spec;
        spec.quadrature_points = 2;  // 2° cells: enough to locate the lobes, and 2.25× faster
        spec.orientation_count = 4;  // eccentric Marschner: 4 viewer azimuths suffice for peaks
        spec.lobe = kLobeR;
        const Grid2D r = value_of(direct_distribution_relative(model, theta_r, spec));
        const double peak = theta_peak(r, ThetaDensity::kPerSteradian);
        // The cos θ factors of the models move the per-steradian peak outwards at large |θ_r|.
        EXPECT_NEAR(peak, -theta_r + r_shift, radians(3) + 0.1 * std::fabs(theta_r)) << label << " theta_r=" << deg;
        spec.lobe = kLobeTT;
        const Grid2D tt = value_of(direct_distribution_relative(model, theta_r, spec));
        EXPECT_LT(angular_distance(phi_peak(tt), kPi), radians(4)) << label << " theta_r=" << deg;
        spec.lobe = -1;
        const Grid2D all = value_of(direct_distribution_relative(model, theta_r, spec));
        const double all_peak = theta_peak(all, ThetaDensity::kPerSteradian);
        std::printf("%s direct theta_r=%5.1f: R-lobe peak %6.2f deg, all-lobe peak %6.2f deg, TT azimuth %6.1f deg, "
                    "albedo %.4f\n",
                    label, deg, degrees(peak), degrees(all_peak), degrees(phi_peak(tt)), all.integral());
        EXPECT_NEAR(all_peak, -theta_r, radians(20)) << label << " theta_r=" << deg;
        // A sum of unimodal profiles peaks between its terms' peaks: within the lobes' closed-form
        // peaks, widened as the R check is for the per-steradian cosines and the 2° cells.
        const double slack = radians(3) + 0.1 * std::fabs(theta_r);
        EXPECT_GE(all_peak, -theta_r + *std::min_element(shifts.begin(), shifts.end()) - slack)
            << label << " theta_r=" << deg;
        EXPECT_LE(all_peak, -theta_r + *std::max_element(shifts.begin(), shifts.end()) + slack)
            << label << " theta_r=" << deg;
    }
}

void check_albedo_real(const FiberModel &model, const char *label) {
    for (double deg : {-40.0, 50.0}) {
        const double theta_r = radians(deg);
        const Grid2D g = value_of(direct_distribution(model, theta_r, -kHalfPi, {}));
        const double reference = independent_albedo(model, theta_r, -kHalfPi, 400, 240);
        std::printf("%s albedo theta_r=%5.1f: grid %.6f, independent %.6f\n", label, deg, g.integral(), reference);
        EXPECT_NEAR(g.integral(), reference, 5e-3 * reference) << label << " theta_r=" << deg;
    }
}

DualScattering time_default_grids(const FiberModel &model, const char *label, const DualScatteringParams &params) {
    auto t0 = std::chrono::steady_clock::now();
    const Grid2D g = value_of(direct_distribution_relative(model, radians(30), {}));
    auto t1 = std::chrono::steady_clock::now();
    DualScattering ds = value_of(DualScattering::create(model, params));
    auto t2 = std::chrono::steady_clock::now();
    const Grid1D m = value_of(multiple_distribution(ds, radians(30), 4, {}));
    auto t3 = std::chrono::steady_clock::now();
    auto s = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
    std::printf("%s timings (%d threads max): direct_distribution_relative 90x180x3x3 %.3f s; "
                "DualScattering::create %.3f s; multiple_distribution 180x4 %.4f s\n",
                label, tbb::this_task_arena::max_concurrency(), s(t0, t1), s(t1, t2), s(t2, t3));
    EXPECT_GT(g.integral(), 0);
    EXPECT_GT(m.integral(), 0);
    return ds;
}

ChiangFiber cycles_default_chiang() {
    ChiangParams params;
    params.sigma_a = Rgb(0.245531f, 0.52f, 1.365f);
    params.roughness = 0.3f;
    params.radial_roughness = 0.3f;
    params.ior = 1.55f;
    params.offset = float(radians(2));
    return value_of(ChiangFiber::create(params));
}

TEST(DistributionsRealModels, ChiangDirect) {
    const ChiangFiber fiber = cycles_default_chiang();
    // Cycles 3.4 tilts lobe p by δ_p = 2α, −α, −4α: M_p peaks at θ_i = −θ_r − δ_p.
    const double alpha = radians(2);
    check_direct_real(fiber, "chiang", {-2 * alpha, alpha, 4 * alpha});
    check_albedo_real(fiber, "chiang");
}

TEST(DistributionsRealModels, ChiangMultiple) {
    const ChiangFiber fiber = cycles_default_chiang();
    const DualScattering ds = time_default_grids(fiber, "chiang", {});
    check_multiple_table(multiple_table(ds, "chiang (Cycles defaults)"), PeakRules{}, "chiang");
}

TEST(DistributionsRealModels, MarschnerDirect) {
    const MarschnerFiber fiber = value_of(MarschnerFiber::create(MarschnerParams::blonde()));
    // M_p(θ_h − α_p) peaks at θ_i = 2α_p − θ_r.
    const MarschnerParams &m = fiber.params();
    check_direct_real(fiber, "marschner", {2 * m.alpha_r, 2 * m.alpha_tt, 2 * m.alpha_trt});
    check_albedo_real(fiber, "marschner");
}

TEST(DistributionsRealModels, MarschnerMultiple) {
    const MarschnerFiber fiber = value_of(MarschnerFiber::create(MarschnerParams::blonde()));
    // Marschner's M_p has area 2 over θ_i (see DualScatteringParams::energy_scale).
    DualScatteringParams params;
    params.energy_scale = 0.5f;
    const DualScattering ds = time_default_grids(fiber, "marschner", params);
    // Marschner's 1/cos²θ_d makes ā_f largest at grazing light (θ_i → ±87°), where the peaks
    // of the larger n_h go for |θ_r| = 60°: the peak rules are only asserted up to n_h = 2.
    PeakRules rules;
    rules.max_n_h = 2;
    rules.slack = 10;  // α_TT = 3.75° shifts the TT-dominated peak by 2α_TT = 7.5°
    rules.towards_normal = false;
    check_multiple_table(multiple_table(ds, "marschner (blonde, energy_scale 0.5)"), rules, "marschner");
}

}  // namespace
}  // namespace hairis
