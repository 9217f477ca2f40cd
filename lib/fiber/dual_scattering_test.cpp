#include "fiber/dual_scattering.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include <tbb/task_arena.h>

#include "core/frame.h"

#include "fiber/chiang.h"
#include "fiber/huang.h"
#include "fiber/marschner.h"
#include "fiber/principled_hair.h"

namespace hairis {
namespace {

// ------------------------------------------------------------------------------------------
// Test-local fibers with known integrals.

/// Azimuthal profiles: N_0 = (1 + cos φ)/2π (backward-peaked, R-like), N_1 = (1 − cos φ)/2π
/// (forward-peaked, TT-like), N_2 = 1/2π (flat). Each integrates to 1 over the circle.
double test_n(int p, double phi) {
    if (p == 0) return (1.0 + std::cos(phi)) * kInvTwoPi;
    if (p == 1) return (1.0 - std::cos(phi)) * kInvTwoPi;
    return kInvTwoPi;
}
/// ∫ N_p over the forward half |φ| > π/2 and the backward half |φ| < π/2.
double test_n_forward(int p) {
    if (p == 0) return (kPi - 2.0) * kInvTwoPi;
    if (p == 1) return (kPi + 2.0) * kInvTwoPi;
    return 0.5;
}
double test_n_backward(int p) { return 1.0 - test_n_forward(p); }

const Rgb kScale[3] = {Rgb(0.08f), Rgb(0.35f, 0.25f, 0.12f), Rgb(0.12f, 0.08f, 0.04f)};
const LobeShape kShapes[3] = {{float(radians(-5)), float(radians(6))},
                              {float(radians(2.5)), float(radians(3))},
                              {float(radians(7.5)), float(radians(12))}};

double relative_phi(Vec3 wi, Vec3 wo) {
    return wrap_angle(double(angles_of(wi).phi) - double(angles_of(wo).phi));
}

/// Longitudinally flat fiber: f_p(ω_i, ω_o)·cos θ_i = c_p (1 − ½ sin²θ_o) N_p(φ) cos θ_i
/// (times an optional eccentric factor 1 + ½ cos(φ_i + φ_o)). For a light at θ_L, by
/// reciprocity (ω_L in the viewer's slot):
///   ∫_{H_f} f_p(ω, ω_L) |cos θ| dω = c_p (1 − ½ sin²θ_L) · (π/2) · ∫_fwd N_p dφ,
/// as ∫ cos²θ dθ = π/2.
class FlatFiber : public FiberModel {
  public:
    explicit FlatFiber(bool eccentric = false) : eccentric_(eccentric) {}
    std::string name() const override { return "test_flat"; }
    int lobe_count() const override { return 3; }
    Rgb lobe_f_cos(int p, Vec3 wi, Vec3 wo) const override {
        const FiberAngles ai = angles_of(wi), ao = angles_of(wo);
        double f = (1.0 - 0.5 * sqr(std::sin(double(ao.theta)))) * test_n(p, relative_phi(wi, wo));
        if (eccentric_) f *= 1.0 + 0.5 * std::cos(double(ai.phi) + double(ao.phi));
        return kScale[p] * float(f * std::cos(double(ai.theta)));
    }
    LobeShape lobe_shape(int p) const override { return kShapes[p]; }
    bool rotationally_symmetric() const override { return !eccentric_; }

    static Rgb expected_forward(int p, double theta_l) {
        return kScale[p] * float((1.0 - 0.5 * sqr(std::sin(theta_l))) * kHalfPi * test_n_forward(p));
    }
    static Rgb expected_backward(int p, double theta_l) {
        return kScale[p] * float((1.0 - 0.5 * sqr(std::sin(theta_l))) * kHalfPi * test_n_backward(p));
    }
    // ā_f and ā_b: the lobes' closed forms summed.
    static Rgb expected_forward(double theta_l) {
        Rgb sum;
        for (int p = 0; p < 3; ++p) sum += expected_forward(p, theta_l);
        return sum;
    }
    static Rgb expected_backward(double theta_l) {
        Rgb sum;
        for (int p = 0; p < 3; ++p) sum += expected_backward(p, theta_l);
        return sum;
    }

  private:
    bool eccentric_;
};

double gauss(double x, double var) { return std::exp(-0.5 * x * x / var) / std::sqrt(kTwoPi * var); }

/// Marschner-form fiber: f_p = ½ g(θ_h − α_p; β_p²) N_p(φ) / cos²θ_d (the ½ makes M_p a unit
/// area over θ_i, so that the albedo stays below 1 away from grazing angles).
class GaussianFiber : public FiberModel {
  public:
    std::string name() const override { return "test_gaussian"; }
    int lobe_count() const override { return 3; }
    Rgb lobe_f_cos(int p, Vec3 wi, Vec3 wo) const override {
        const double ti = angles_of(wi).theta, to = angles_of(wo).theta;
        const double th = 0.5 * (ti + to), td = 0.5 * (to - ti);
        const double m = gauss(th - kShapes[p].alpha, sqr(double(kShapes[p].beta)));
        const double f = 0.5 * m * test_n(p, relative_phi(wi, wo)) / sqr(std::cos(td));
        return kScale[p] * float(f * std::cos(ti));
    }
    LobeShape lobe_shape(int p) const override { return kShapes[p]; }
};

void expect_rgb_near(Rgb a, Rgb b, double tol, const std::string &what) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tol) << what << " channel " << c;
}

// The paper's formulas, written out independently of the implementation.
struct HandTerms {
    double a_f, a_b, alpha_f, alpha_b, beta2_f, beta2_b, big_a_b, delta_b, sigma_b;
};
HandTerms hand_terms(double theta, int ch, double d_b) {
    HandTerms h{};
    double wf = 0, wb = 0, af_al = 0, ab_al = 0, af_be = 0, ab_be = 0;
    for (int p = 0; p < 3; ++p) {
        const double f = FlatFiber::expected_forward(p, theta)[ch];
        const double b = FlatFiber::expected_backward(p, theta)[ch];
        wf += f;
        wb += b;
        af_al += f * kShapes[p].alpha;
        ab_al += b * kShapes[p].alpha;
        af_be += f * sqr(double(kShapes[p].beta));
        ab_be += b * sqr(double(kShapes[p].beta));
    }
    h.a_f = wf;
    h.a_b = wb;
    h.alpha_f = af_al / wf;
    h.alpha_b = ab_al / wb;
    h.beta2_f = af_be / wf;
    h.beta2_b = ab_be / wb;
    const double af2 = wf * wf, ab = wb;
    h.big_a_b = ab * af2 / (1 - af2) + std::pow(ab, 3) * af2 / std::pow(1 - af2, 3);
    h.delta_b = h.alpha_b * (1 - 2 * ab * ab / sqr(1 - af2)) +
                h.alpha_f * (2 * sqr(1 - af2) + 4 * af2 * ab * ab) / std::pow(1 - af2, 3);
    h.sigma_b = (1 + d_b * af2) *
                (ab * std::sqrt(2 * h.beta2_f + h.beta2_b) + std::pow(ab, 3) * std::sqrt(2 * h.beta2_f + 3 * h.beta2_b)) /
                (ab + std::pow(ab, 3));
    return h;
}

DualScattering make(const FiberModel &model, DualScatteringParams params = {}) {
    Expected<DualScattering> ds = DualScattering::create(model, params);
    EXPECT_TRUE(ds.ok()) << (ds.ok() ? "" : ds.error().message);
    return std::move(ds).value();
}

// ------------------------------------------------------------------------------------------

TEST(GaussLegendre, IntegratesPolynomialsExactly) {
    for (int n : {1, 2, 3, 4, 7, 16}) {
        const GaussLegendre r = GaussLegendre::rule(n);
        double wsum = 0;
        for (double w : r.weights) wsum += w;
        EXPECT_NEAR(wsum, 2.0, 1e-13) << n;
        // ∫_{-1}^{1} x^(2n-2) dx = 2/(2n-1), exact for an n-point rule.
        double m = 0;
        for (std::size_t i = 0; i < r.nodes.size(); ++i) m += r.weights[i] * std::pow(r.nodes[i], 2 * n - 2);
        EXPECT_NEAR(m, 2.0 / (2 * n - 1), 1e-13) << n;
        for (std::size_t i = 1; i < r.nodes.size(); ++i) EXPECT_LT(r.nodes[i - 1], r.nodes[i]);
    }
    const QuadratureRule q = QuadratureRule::composite(0, kPi, 8, 4);
    double s = 0;
    for (std::size_t i = 0; i < q.x.size(); ++i) s += q.w[i] * std::sin(q.x[i]);
    EXPECT_NEAR(s, 2.0, 1e-12);
}

TEST(DualScattering, AttenuationsMatchHandComputedIntegrals) {
    const FlatFiber fiber;
    const DualScattering ds = make(fiber);
    for (int k = 0; k < ds.theta_count(); k += 7) {
        const double t = ds.table_theta(k);
        for (int p = 0; p < 3; ++p) {
            expect_rgb_near(ds.lobe_forward_attenuation(p, t), FlatFiber::expected_forward(p, t), 2e-6, "a_f,p");
            expect_rgb_near(ds.lobe_backward_attenuation(p, t), FlatFiber::expected_backward(p, t), 2e-6, "a_b,p");
        }
        expect_rgb_near(ds.forward_attenuation(t), FlatFiber::expected_forward(t), 5e-6, "a_f");
        expect_rgb_near(ds.backward_attenuation(t), FlatFiber::expected_backward(t), 5e-6, "a_b");
        for (int ch = 0; ch < 3; ++ch) {
            const HandTerms h = hand_terms(t, ch, ds.params().d_b);
            EXPECT_NEAR(ds.forward_shift(t)[ch], h.alpha_f, 1e-6);
            EXPECT_NEAR(ds.backward_shift(t)[ch], h.alpha_b, 1e-6);
            EXPECT_NEAR(ds.forward_width(t)[ch], std::sqrt(h.beta2_f), 1e-6);
            EXPECT_NEAR(ds.backward_width(t)[ch], std::sqrt(h.beta2_b), 1e-6);
            EXPECT_NEAR(ds.backscatter_attenuation(t)[ch], h.big_a_b, 1e-5);
            EXPECT_NEAR(ds.backscatter_shift(t)[ch], h.delta_b, 1e-5);
            EXPECT_NEAR(ds.backscatter_width(t)[ch], h.sigma_b, 1e-5);
        }
    }
    // Between nodes the tables interpolate linearly: close to the smooth hand values.
    for (double deg : {-61.3, -12.0, 0.4, 33.3, 70.7}) {
        const double t = radians(deg);
        expect_rgb_near(ds.forward_attenuation(t), FlatFiber::expected_forward(t), 1.5e-3, "a_f between nodes");
    }
}

TEST(DualScattering, CrossingsPassOnTheBackwardLightThatTravelsAlongTheFiber) {
    // a(θ) = ā_f + sin²θ ā_b against the flat fiber's closed forms (not the tables): the
    // paper's ā_f for light across the fiber, the whole scattered albedo ā_f + ā_b along it.
    const FlatFiber fiber;
    const DualScattering ds = make(fiber);
    for (int k = 0; k < ds.theta_count(); k += 5) {
        const double t = ds.table_theta(k);
        const Rgb expected = FlatFiber::expected_forward(t) + FlatFiber::expected_backward(t) * float(sqr(std::sin(t)));
        expect_rgb_near(ds.crossing_attenuation(t), expected, 5e-6, "a(θ)");
    }
    // Along the fiber nearly all the backward light goes on.
    const double last = ds.table_theta(ds.theta_count() - 1);
    EXPECT_GT(ds.crossing_attenuation(last).r, ds.forward_attenuation(last).r + 0.9f * ds.backward_attenuation(last).r);
}

TEST(DualScattering, EnergyScaleMultipliesTheModel) {
    const FlatFiber fiber;
    DualScatteringParams params;
    params.theta_count = 8;
    params.energy_scale = 0.5f;
    const DualScattering half = make(fiber, params);
    const double t = half.table_theta(3);
    for (int p = 0; p < 3; ++p)
        expect_rgb_near(half.lobe_forward_attenuation(p, t), FlatFiber::expected_forward(p, t) * 0.5f, 2e-6, "scaled a_f,p");
}

TEST(DualScattering, EccentricFiberIsAveragedOverOrientation) {
    const FlatFiber eccentric(true);
    DualScatteringParams params;
    params.theta_count = 8;
    params.orientation_count = 8;
    const DualScattering averaged = make(eccentric, params);
    params.orientation_count = 1;  // a single light azimuth: the eccentric factor is not averaged
    const DualScattering single = make(eccentric, params);
    const double t = averaged.table_theta(5);
    Rgb sum_f;
    for (int p = 0; p < 3; ++p) sum_f += FlatFiber::expected_forward(p, t);
    expect_rgb_near(averaged.forward_attenuation(t), sum_f, 5e-6, "orientation-averaged a_f");
    EXPECT_GT(std::fabs(single.forward_attenuation(t).r - sum_f.r), 1e-3);
}

TEST(DualScattering, TransmittanceAndSpreadFollowTheFormulasPerStrandCount) {
    const FlatFiber fiber;
    DualScatteringParams params;
    params.d_f = 0.6f;
    const DualScattering ds = make(fiber, params);
    for (double deg : {-50.0, 0.0, 25.0}) {
        const double t = radians(deg);
        const Rgb a_f = ds.forward_attenuation(t);
        const Rgb b_f = ds.forward_width(t);
        // n_h = 0: nothing between the light and the shading point.
        expect_rgb_near(ds.forward_transmittance(t, 0), Rgb(1.0f), 0, "T_f(0)");
        expect_rgb_near(ds.forward_spread_variance(t, 0), Rgb(0.0f), 0, "sigma_f^2(0)");
        for (int n : {1, 2, 3, 4, 8, 16}) {
            for (int ch = 0; ch < 3; ++ch) {
                EXPECT_NEAR(ds.forward_transmittance(t, n)[ch], 0.6 * std::pow(double(a_f[ch]), n), 1e-6);
                // The paper's σ_f² = n β̄_f² (not the seed's n β̄_f).
                EXPECT_NEAR(ds.forward_spread_variance(t, n)[ch], n * sqr(double(b_f[ch])), 1e-6);
            }
            EXPECT_LT(ds.forward_transmittance(t, n).g, ds.forward_transmittance(t, n - 1 > 0 ? n - 1 : 0).g);
        }
    }
}

TEST(DualScattering, ForwardAzimuthalFunctionIsExtractedFromSeparableModels) {
    const GaussianFiber fiber;
    const DualScattering ds = make(fiber);
    for (int k = 4; k < ds.theta_count() - 4; k += 5) {
        const double td = ds.table_theta(k);
        for (int p = 0; p < 3; ++p) {
            // The forward average of N_p: (1/π) ∫_fwd N_p dφ.
            const Rgb expected = kScale[p] * float(0.5 * test_n_forward(p) * kInvPi);
            expect_rgb_near(ds.lobe_forward_azimuthal(p, td), expected, 1e-6, "N_p^G");
        }
    }
}

// The measured shape of a Gaussian lobe in θ_h against a fine midpoint rule over θ_i written
// out here: the density ½g(θ_h − α; β²)/cos²θ_d · cos²θ_i per θ_i (its ∫N dφ = 1), pooled
// over the table's θ_L with weight cos θ_L. The factor cos²θ_i/cos²θ_d narrows a 12° lobe by
// about 10% and pulls its mean in, so comparing with (α, β) alone would not test the moments;
// measuring θ_i instead of θ_h would double both.
TEST(DualScattering, MeasuredLobeShapesMatchAMidpointRule) {
    const GaussianFiber fiber;
    DualScatteringParams params;
    params.measure_lobe_shapes = true;
    const DualScattering ds = make(fiber, params);
    ASSERT_TRUE(ds.lobe_shapes_measured());
    EXPECT_FALSE(make(fiber).lobe_shapes_measured());
    const int n = 20000;
    for (int p = 0; p < 3; ++p) {
        double m0 = 0, m1 = 0, m2 = 0;
        for (int k = 0; k < ds.theta_count(); ++k) {
            const double theta_l = ds.table_theta(k);
            for (int i = 0; i < n; ++i) {
                const double theta_i = -kHalfPi + (i + 0.5) * kPi / n;
                const double theta_h = 0.5 * (theta_i + theta_l), theta_d = 0.5 * (theta_l - theta_i);
                const double w = std::cos(theta_l) * 0.5 *
                                 gauss(theta_h - kShapes[p].alpha, sqr(double(kShapes[p].beta))) /
                                 sqr(std::cos(theta_d)) * sqr(std::cos(theta_i));
                m0 += w;
                m1 += w * theta_h;
                m2 += w * theta_h * theta_h;
            }
        }
        const double alpha = m1 / m0, beta = std::sqrt(m2 / m0 - alpha * alpha);
        const LobeShape measured = ds.lobe_shape(p);
        EXPECT_NEAR(degrees(measured.alpha), degrees(alpha), 0.05) << "lobe " << p;
        EXPECT_NEAR(measured.beta / beta, 1.0, 0.01) << "lobe " << p;
        EXPECT_NEAR(degrees(measured.alpha), degrees(kShapes[p].alpha), 2.0) << "lobe " << p;
    }
}

TEST(DualScattering, MultipleTermAssemblesThePaperFormulas) {
    const GaussianFiber fiber;
    const DualScattering ds = make(fiber);
    const double d_f = ds.params().d_f, d_b = ds.params().d_b;
    for (int n : {0, 1, 2, 4, 16}) {
        for (double ti_deg : {-40.0, -5.0, 10.0}) {
            for (double to_deg : {-20.0, 0.0, 35.0}) {
                const double ti = radians(ti_deg), to = radians(to_deg);
                const double th = 0.5 * (ti + to), td = 0.5 * (to - ti);
                const double cd2 = sqr(std::cos(td));
                const Rgb got = ds.multiple_f_cos(float(ti), float(to), n);
                for (int ch = 0; ch < 3; ++ch) {
                    const double big_a = ds.backscatter_attenuation(ti)[ch];
                    const double delta = ds.backscatter_shift(ti)[ch];
                    const double sb2 = sqr(double(ds.backscatter_width(ti)[ch]));
                    double expected;
                    if (n == 0) {
                        // f_back: Ā_b g / (π cos²θ_d), half the paper's printed 2 Ā_b (header).
                        expected = d_b * big_a * gauss(th - delta, sb2) / (kPi * cd2) * std::cos(ti);
                    } else {
                        const double tf = d_f * std::pow(double(ds.forward_attenuation(ti)[ch]), n);
                        const double sf2 = n * sqr(double(ds.forward_width(ti)[ch]));
                        double fs = 0;
                        for (int p = 0; p < 3; ++p)
                            fs += gauss(th - kShapes[p].alpha, sqr(double(kShapes[p].beta)) + sf2) *
                                  0.5 * kScale[p][ch] * test_n_forward(p) * kInvPi / cd2;
                        const double fb = big_a * gauss(th - delta, sb2 + sf2) / (kPi * cd2);
                        expected = tf * d_f * (fs + kPi * d_b * fb) * std::cos(ti);
                    }
                    EXPECT_NEAR(got[ch], expected, 1e-5 + 1e-4 * std::fabs(expected))
                        << "n_h=" << n << " theta_i=" << ti_deg << " theta_o=" << to_deg << " ch=" << ch;
                }
            }
        }
    }
    EXPECT_EQ(ds.multiple_f_cos(0.1f, 0.2f, -1).r, 0.0f);
    // The default-n_h overload uses params().n_h.
    EXPECT_EQ(ds.multiple_f_cos(0.1f, 0.2f).g, ds.multiple_f_cos(0.1f, 0.2f, ds.params().n_h).g);
}

TEST(DualScattering, MultipleTermDarkensWithMoreStrands) {
    const GaussianFiber fiber;
    const DualScattering ds = make(fiber);
    // Albedo of the multiple term for a viewer at θ_o = 20°: 2π ∫ multiple_f_cos cos θ_i dθ_i.
    auto albedo = [&](int n) {
        const QuadratureRule q = QuadratureRule::composite(-kHalfPi, kHalfPi, 200, 4);
        double s = 0;
        for (std::size_t i = 0; i < q.x.size(); ++i)
            s += q.w[i] * std::cos(q.x[i]) * double(luminance(ds.multiple_f_cos(float(q.x[i]), float(radians(20)), n)));
        return kTwoPi * s;
    };
    double previous = albedo(1);
    EXPECT_GT(previous, 0);
    for (int n : {2, 4, 8, 16}) {
        const double a = albedo(n);
        EXPECT_LT(a, previous) << n;
        previous = a;
    }
}

TEST(DualScattering, BackscatterCutAtDepthIsThePartialSeries) {
    // Ā_b with the series over the strands behind cut at `depth`: with x = ā_f² and
    // S = Σ_{i<depth} x^i (summed here term by term), ā_b x S + ā_b³ x S³; 0 with nothing
    // behind; the unbounded table's value for a deep layer.
    ChiangParams cp;
    cp.sigma_a = principled_hair::sigma_from_concentration(0.05, 0.05);  // blonde: ā_f up to 0.83
    cp.roughness = 0.3f;
    cp.radial_roughness = 0.3f;
    const ChiangFiber fiber = ChiangFiber::create(cp).value();
    const DualScattering ds = DualScattering::create(fiber, {}).value();
    ASSERT_EQ(ds.clamped_entries(), 0);
    // At table nodes, where Ā_b's table holds the paper's closed form of the same ā_f and ā_b.
    const int n = ds.theta_count();
    for (int k : {n / 2, n / 2 + 6, 5}) {
        const double theta = -kHalfPi + (k + 0.5) * kPi / n;
        const Rgb a_f = ds.forward_attenuation(theta), a_b = ds.backward_attenuation(theta);
        const Rgb unbounded = ds.backscatter_attenuation(theta);
        const Rgb none = ds.backscatter_attenuation(theta, 0);
        EXPECT_TRUE(none.r == 0.0f && none.g == 0.0f && none.b == 0.0f) << theta;
        for (int depth : {1, 2, 5}) {
            const Rgb cut = ds.backscatter_attenuation(theta, depth);
            for (int ch = 0; ch < 3; ++ch) {
                const double x = double(a_f[ch]) * a_f[ch], ab = a_b[ch];
                double sum = 0, power = 1;
                for (int i = 0; i < depth; ++i, power *= x) sum += power;
                const double want = ab * x * sum + ab * ab * ab * x * sum * sum * sum;
                EXPECT_NEAR(cut[ch], want, 1e-6 * want + 1e-9) << theta << " depth " << depth;
                EXPECT_LT(cut[ch], unbounded[ch]) << theta << " depth " << depth;
            }
        }
        const Rgb deep = ds.backscatter_attenuation(theta, 400);
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_NEAR(deep[ch], unbounded[ch], 1e-5 * unbounded[ch]) << theta << " ch " << ch;
    }
}

TEST(DualScattering, InvalidParametersAreRefused) {
    const FlatFiber fiber;
    auto error_of = [&](DualScatteringParams p) {
        Expected<DualScattering> ds = DualScattering::create(fiber, p);
        EXPECT_FALSE(ds.ok());
        return ds.ok() ? std::string() : ds.error().message;
    };
    DualScatteringParams p;
    p.n_h = -1;
    std::string m = error_of(p);
    EXPECT_NE(m.find("n_h"), std::string::npos) << m;
    EXPECT_NE(m.find("[0, "), std::string::npos) << m;
    p = {};
    p.d_f = 1.5f;
    m = error_of(p);
    EXPECT_NE(m.find("d_f"), std::string::npos) << m;
    EXPECT_NE(m.find("[0, 1]"), std::string::npos) << m;
    p = {};
    p.d_b = -0.1f;
    m = error_of(p);
    EXPECT_NE(m.find("d_b"), std::string::npos) << m;
    p = {};
    p.d_b = std::nanf("");
    EXPECT_NE(error_of(p).find("d_b"), std::string::npos);
    p = {};
    p.theta_count = 1;
    m = error_of(p);
    EXPECT_NE(m.find("theta_count"), std::string::npos) << m;
    EXPECT_NE(m.find("[2, 4096]"), std::string::npos) << m;
    p = {};
    p.theta_count = 100000;
    EXPECT_NE(error_of(p).find("theta_count"), std::string::npos);
    p = {};
    p.points_per_panel = 0;
    EXPECT_NE(error_of(p).find("points_per_panel"), std::string::npos);
    p = {};
    p.phi_panels = 5000;
    EXPECT_NE(error_of(p).find("phi_panels"), std::string::npos);
    p = {};
    p.orientation_count = 0;
    EXPECT_NE(error_of(p).find("orientation_count"), std::string::npos);
    p = {};
    p.max_series_attenuation = 1.0f;
    EXPECT_NE(error_of(p).find("max_series_attenuation"), std::string::npos);
    p = {};
    p.energy_scale = 0.0f;
    EXPECT_NE(error_of(p).find("energy_scale"), std::string::npos);
    p = {};
    p.energy_scale = 1.5f;
    m = error_of(p);
    EXPECT_NE(m.find("energy_scale"), std::string::npos) << m;
    EXPECT_NE(m.find("[0, 1]"), std::string::npos) << m;
    // Boundaries are allowed.
    p = {};
    p.n_h = 0;
    p.d_f = 0;
    p.d_b = 1;
    p.theta_count = 2;
    p.theta_panels = 4;
    p.phi_panels = 2;
    EXPECT_TRUE(DualScattering::create(fiber, p).ok());
}

TEST(DualScattering, TablesAreIdenticalForOneAndTwoThreads) {
    const GaussianFiber fiber;
    auto build = [&](int threads) {
        tbb::task_arena arena(threads);
        Expected<DualScattering> out = Error{""};
        arena.execute([&] { out = DualScattering::create(fiber, {}); });
        return std::move(out).value();
    };
    const DualScattering one = build(1), two = build(2);
    for (int k = 0; k < one.theta_count(); ++k) {
        const double t = one.table_theta(k);
        for (int ch = 0; ch < 3; ++ch) {
            EXPECT_EQ(one.forward_attenuation(t)[ch], two.forward_attenuation(t)[ch]);
            EXPECT_EQ(one.backscatter_width(t)[ch], two.backscatter_width(t)[ch]);
            for (int p = 0; p < 3; ++p) EXPECT_EQ(one.lobe_forward_azimuthal(p, t)[ch], two.lobe_forward_azimuthal(p, t)[ch]);
        }
    }
}

// The same with a real model, whose far field remembers values per thread (ChiangFiber):
// every table entry, compared bit for bit, at table nodes and between them.
TEST(DualScattering, ChiangTablesAreIdenticalForOneAndTwoThreads) {
    const ChiangFiber fiber = ChiangFiber::create(ChiangParams{}).value();
    DualScatteringParams params;  // coarse, to stay quick
    params.theta_count = 12;
    params.theta_panels = 8;
    params.phi_panels = 3;
    auto build = [&](int threads) {
        tbb::task_arena arena(threads);
        Expected<DualScattering> out = Error{""};
        arena.execute([&] { out = DualScattering::create(fiber, params); });
        return std::move(out).value();
    };
    const DualScattering one = build(1), two = build(2), again = build(2);
    auto same = [](Rgb a, Rgb b) { return std::memcmp(&a, &b, sizeof a) == 0; };
    for (int k = 0; 2 * k + 1 < 2 * one.theta_count(); ++k) {
        const double t = -kHalfPi + (k + 0.5) * kPi / (2 * one.theta_count());  // nodes and midpoints
        for (const DualScattering *other : {&two, &again}) {
            EXPECT_TRUE(same(one.forward_attenuation(t), other->forward_attenuation(t))) << k;
            EXPECT_TRUE(same(one.backward_attenuation(t), other->backward_attenuation(t))) << k;
            EXPECT_TRUE(same(one.forward_shift(t), other->forward_shift(t))) << k;
            EXPECT_TRUE(same(one.forward_width(t), other->forward_width(t))) << k;
            EXPECT_TRUE(same(one.backscatter_attenuation(t), other->backscatter_attenuation(t))) << k;
            EXPECT_TRUE(same(one.backscatter_shift(t), other->backscatter_shift(t))) << k;
            EXPECT_TRUE(same(one.backscatter_width(t), other->backscatter_width(t))) << k;
            for (int p = 0; p < one.lobe_count(); ++p) {
                EXPECT_TRUE(same(one.lobe_forward_attenuation(p, t), other->lobe_forward_attenuation(p, t)));
                EXPECT_TRUE(same(one.lobe_backward_attenuation(p, t), other->lobe_backward_attenuation(p, t)));
                EXPECT_TRUE(same(one.lobe_forward_azimuthal(p, t), other->lobe_forward_azimuthal(p, t)));
            }
            for (int n_h : {0, 1, 4})
                EXPECT_TRUE(same(one.multiple_f_cos(float(t), 0.3f, n_h), other->multiple_f_cos(float(t), 0.3f, n_h)));
        }
    }
}

// ------------------------------------------------------------------------------------------
// The real models, when they are there.

void print_terms(const char *label, const DualScattering &ds) {
    std::printf("%s: theta_L   a_f(lum)  a_b(lum)  alpha_f  beta_f   A_b      Delta_b  sigma_b  [deg for angles]\n", label);
    for (double deg : {-80.0, -60.0, -30.0, 0.0, 30.0, 60.0, 80.0}) {
        const double t = radians(deg);
        std::printf("  %6.1f  %8.4f  %8.4f  %7.2f  %7.2f  %8.4f  %7.2f  %7.2f\n", deg,
                    luminance(ds.forward_attenuation(t)), luminance(ds.backward_attenuation(t)),
                    degrees(ds.forward_shift(t).g), degrees(ds.forward_width(t).g),
                    luminance(ds.backscatter_attenuation(t)), degrees(ds.backscatter_shift(t).g),
                    degrees(ds.backscatter_width(t).g));
    }
}

void check_real_model(const FiberModel &model, const char *label, const DualScatteringParams &params = {}) {
    const auto start = std::chrono::steady_clock::now();
    Expected<DualScattering> made = DualScattering::create(model, params);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(made.ok()) << made.error().message;
    const DualScattering &ds = made.value();
    std::printf("%s: DualScattering::create (energy_scale %.2f) took %.3f s\n", label, double(params.energy_scale), seconds);
    print_terms(label, ds);
    EXPECT_EQ(ds.clamped_entries(), 0) << label;
    for (double deg : {-60.0, -20.0, 0.0, 20.0, 60.0}) {
        const double t = radians(deg);
        for (int ch = 0; ch < 3; ++ch) {
            const double af = ds.forward_attenuation(t)[ch], ab = ds.backward_attenuation(t)[ch];
            EXPECT_GT(af, 0) << label << " " << deg;
            EXPECT_GT(ab, 0) << label << " " << deg;
            EXPECT_TRUE(std::isfinite(ds.backscatter_width(t)[ch]));
            EXPECT_GT(ds.backscatter_attenuation(t)[ch], 0);
        }
        // Hair scatters mostly forward (TT): ā_f > ā_b in the red channel for these fibers.
        EXPECT_GT(ds.forward_attenuation(t).r, ds.backward_attenuation(t).r) << label << " " << deg;
        for (int n = 1; n <= 16; n *= 2)
            EXPECT_LT(luminance(ds.forward_transmittance(t, n)), luminance(ds.forward_transmittance(t, n / 2 > 0 ? n / 2 : 0)) + 1e-9f);
    }
}

TEST(DualScatteringRealModels, Chiang) {
    ChiangParams params;
    params.sigma_a = Rgb(0.245531f, 0.52f, 1.365f);
    params.roughness = 0.3f;
    params.radial_roughness = 0.3f;
    params.ior = 1.55f;
    params.offset = float(radians(2));
    Expected<ChiangFiber> fiber = ChiangFiber::create(params);
    ASSERT_TRUE(fiber.ok()) << fiber.error().message;
    check_real_model(fiber.value(), "chiang");
}

// Huang's lobes are measured: reflection off scales tilted by the offset puts R's mean θ_h
// at −offset (Cycles' tilt), transmission shifts the other way, and R's spread is close to
// the GGX slope's Beckmann-equivalent α/√2 (within 20%: GGX's tails are heavier). A coarse
// quadrature keeps the test short; R's and TT's shifts move by under 0.1° with the full one
// (TRT's, a sum of several exit paths, is too sensitive to it to test here).
TEST(DualScatteringRealModels, HuangLobeShapesAreMeasured) {
    HuangParams p;  // Blender's default node: roughness 0.3, offset 2°
    HuangQuadrature rule;
    rule.first_order = 3;
    rule.second_order = 2;
    Expected<HuangFiber> fiber = HuangFiber::create(p, rule);
    ASSERT_TRUE(fiber.ok()) << fiber.error().message;
    DualScatteringParams params;
    params.theta_count = 16;
    params.theta_panels = 12;
    params.phi_panels = 4;
    params.orientation_count = 2;
    Expected<DualScattering> ds = DualScattering::create(fiber.value(), params);
    ASSERT_TRUE(ds.ok()) << ds.error().message;
    ASSERT_TRUE(ds.value().lobe_shapes_measured());
    const LobeShape r = ds.value().lobe_shape(0), tt = ds.value().lobe_shape(1), trt = ds.value().lobe_shape(2);
    std::printf("huang lobes: R (%.2f°, %.2f°), TT (%.2f°, %.2f°), TRT (%.2f°, %.2f°)\n", degrees(r.alpha),
                degrees(r.beta), degrees(tt.alpha), degrees(tt.beta), degrees(trt.alpha), degrees(trt.beta));
    EXPECT_NEAR(degrees(r.alpha), -degrees(p.offset), 0.5);
    EXPECT_GT(tt.alpha, 0.0f);
    EXPECT_NEAR(r.beta / (p.roughness / std::sqrt(2.0)), 1.0, 0.2);
    // The forward fraction dominates at normal incidence (TT), and both are below 1.
    const Rgb a_f = ds.value().forward_attenuation(0.0), a_b = ds.value().backward_attenuation(0.0);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(a_f[c], a_b[c]) << "channel " << c;
        EXPECT_LT(a_f[c] + a_b[c], 1.0f) << "channel " << c;
    }
}

// A crossing meets an elliptic Huang fiber only on its projected ellipse: the share the light
// passes, averaged over the light's azimuths φ_j around the fiber, is 1 − the ellipse's
// support function √(sin²φ + a² cos²φ) (major axis 1 along y, minor a along z), and it is the
// part of ā_f no lobe carries; a circular fiber passes nothing.
TEST(DualScatteringRealModels, HuangCrossingsPassOutsideTheProjectedEllipse) {
    HuangQuadrature rule;
    rule.first_order = 3;
    rule.second_order = 2;
    DualScatteringParams params;
    params.theta_count = 6;
    params.theta_panels = 6;
    params.phi_panels = 3;
    params.orientation_count = 3;
    for (const float aspect : {0.6f, 1.0f}) {
        HuangParams p;
        p.aspect_ratio = aspect;
        const HuangFiber fiber = HuangFiber::create(p, rule).value();
        const DualScattering ds = DualScattering::create(fiber, params).value();
        for (int k = 0; k < params.theta_count; ++k) {
            const double theta = ds.table_theta(k);
            double expected = 0;
            for (int j = 0; j < 3; ++j) {
                const double phi = -kPi + (j + 0.5) * kTwoPi / 3;
                expected += (1.0 - std::sqrt(sqr(std::sin(phi)) + sqr(double(aspect)) * sqr(std::cos(phi)))) / 3;
            }
            EXPECT_NEAR(ds.pass_through(theta), expected, 1e-6) << "aspect " << aspect << ", node " << k;
            Rgb lobes;
            for (int l = 0; l < ds.lobe_count(); ++l) lobes += ds.lobe_forward_attenuation(l, theta);
            const Rgb a_f = ds.forward_attenuation(theta);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(a_f[c] - lobes[c], expected, 1e-5) << "aspect " << aspect;
        }
        if (aspect == 1.0f) EXPECT_EQ(ds.pass_through(0.0), 0.0);
        else EXPECT_GT(ds.pass_through(0.0), 0.05);
    }
}

TEST(DualScatteringRealModels, MarschnerBlonde) {
    Expected<MarschnerFiber> fiber = MarschnerFiber::create(MarschnerParams::blonde());
    ASSERT_TRUE(fiber.ok()) << fiber.error().message;
    // Marschner's M_p has area 2 over θ_i: as it is, blonde's ā_f exceeds 1 in red and the
    // series of Ā_b diverge (clamped). Halving its energy makes the tables meaningful.
    DualScatteringParams raw;
    raw.theta_count = 8;
    Expected<DualScattering> unscaled = DualScattering::create(fiber.value(), raw);
    ASSERT_TRUE(unscaled.ok());
    std::printf("marschner-blonde, energy_scale 1: a_f(0) = (%.3f, %.3f, %.3f), clamped entries %d of %d\n",
                unscaled.value().forward_attenuation(0).r, unscaled.value().forward_attenuation(0).g,
                unscaled.value().forward_attenuation(0).b, unscaled.value().clamped_entries(), 3 * raw.theta_count);
    DualScatteringParams params;
    params.energy_scale = 0.5f;
    check_real_model(fiber.value(), "marschner-blonde", params);
}

}  // namespace
}  // namespace hairis
