#include "hairis/chiang.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <vector>

#include "hairis/frame.h"
#include "hairis/fresnel.h"

namespace hairis {

namespace {

using Channels = std::array<double, 3>;

constexpr double kSqrtPiOver8 = 0.62665706865775012560;

// 8-point Gauss–Legendre rule on [−1, 1]: symmetric nodes and their weights.
constexpr double kGaussNodes[4] = {0.18343464249564980, 0.52553240991632899,
                                   0.79666647741362674, 0.96028985649753623};
constexpr double kGaussWeights[4] = {0.36268378337836198, 0.31370664587788729,
                                     0.22238103445337447, 0.10122853629037626};

// Far field, fixed rule (see far_slice): panel width in units of s, its cap (radians), and
// the most nodes per lobe before the graded rule is cheaper.
constexpr double kFixedPanelPerScale = 2.0;
constexpr double kFixedMaxPanel = 0.25;
constexpr int kMaxFixedNodes = 800;

double luminance(const Channels &c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

Rgb to_rgb(const Channels &c) { return {float(c[0]), float(c[1]), float(c[2])}; }

Channels scaled(const Channels &c, double k) { return {c[0] * k, c[1] * k, c[2] * k}; }

// The logistic density of scale s (not trimmed). Written with e^{−|x|/s} so that it cannot
// overflow; it is an even, smooth function of x (= sech²(x/2s)/(4s)).
double logistic(double x, double s) {
    const double e = std::exp(-std::fabs(x) / s);
    return e / (s * sqr(1.0 + e));
}

// Mass of the logistic inside [−π, π]: 1 − 2·CDF(−π) = tanh(π/2s).
double logistic_mass(double s) { return std::tanh(kPi / (2.0 * s)); }

// Rotates (sin θ, cos θ) by the angle whose sine and cosine are given, and folds the
// cosine to |cos|: an angle pushed past ±π/2 reads as its mirror image, as in Cycles.
struct SinCos {
    double sin = 0, cos = 1;
};
SinCos rotate(double sin_theta, double cos_theta, const SinCos &by) {
    return {sin_theta * by.cos + cos_theta * by.sin,
            std::fabs(cos_theta * by.cos - sin_theta * by.sin)};
}

std::atomic<std::uint64_t> g_next_fiber_id{1};

}  // namespace

// ---------------------------------------------------------------------------------------
// Building blocks.

namespace chiang {

double longitudinal_variance(double roughness) {
    const double b = std::clamp(roughness, 0.001, 1.0);
    const double b2 = b * b, b4 = b2 * b2, b8 = b4 * b4, b16 = b8 * b8;
    return sqr(0.726 * b + 0.812 * b2 + 3.7 * (b16 * b4));
}

double logistic_scale(double radial_roughness) {
    const double b = std::clamp(radial_roughness, 0.001, 1.0);
    const double b2 = b * b, b4 = b2 * b2, b8 = b4 * b4, b16 = b8 * b8;
    return kSqrtPiOver8 * (0.265 * b + 1.194 * b2 + 5.372 * (b16 * b4 * b2));
}

double log_bessel_i0(double x) {
    // Up to x = 20 the power series needs at most ~60 terms and loses nothing to
    // cancellation; beyond, the asymptotic series is accurate to ~e^{−2x}.
    x = std::fabs(x);
    if (x <= 20.0) {
        // Σ (x²/4)^k / (k!)²: all terms positive, so the sum is accurate to rounding.
        const double quarter_x2 = 0.25 * x * x;
        double term = 1.0, sum = 1.0;
        for (int k = 1; k < 200; ++k) {
            term *= quarter_x2 / (double(k) * double(k));
            sum += term;
            if (term <= 1e-17 * sum) break;
        }
        return std::log(sum);
    }
    // I0(x) ~ e^x / sqrt(2πx) · Σ a_k x^{−k}, a_k = a_{k−1}(2k − 1)²/(8k). For x > 20 the
    // terms shrink below 1e-17 before they start to grow again.
    double term = 1.0, sum = 1.0;
    const double inv_8x = 1.0 / (8.0 * x);
    for (int k = 1; k < 60; ++k) {
        const double next = term * sqr(2.0 * k - 1.0) * inv_8x / k;
        if (next >= term) break;
        term = next;
        sum += term;
        if (term <= 1e-17 * sum) break;
    }
    return x - 0.5 * std::log(kTwoPi * x) + std::log(sum);
}

double longitudinal_scattering(double sin_theta_i, double cos_theta_i, double sin_theta_o,
                               double cos_theta_o, double v) {
    return longitudinal_scattering(sin_theta_i, cos_theta_i, sin_theta_o, cos_theta_o,
                                   longitudinal_constants(v));
}

LongitudinalConstants longitudinal_constants(double v) {
    LongitudinalConstants c;
    c.kappa = 1.0 / v;
    // log(csch(κ)/(2v)) = log κ − κ − log(1 − e^{−2κ}), finite for every κ > 0.
    c.log_normalization = std::log(c.kappa) - c.kappa - std::log(-std::expm1(-2.0 * c.kappa));
    return c;
}

double longitudinal_scattering(double sin_theta_i, double cos_theta_i, double sin_theta_o,
                               double cos_theta_o, const LongitudinalConstants &c) {
    const double log_value = c.log_normalization - c.kappa * sin_theta_i * sin_theta_o +
                             log_bessel_i0(c.kappa * cos_theta_i * cos_theta_o);
    return std::exp(log_value);
}

double sample_cone_cosine(double u, double v) {
    // 1 + v·log(u + (1 − u)e^{−2/v}), with the logarithm's argument written as
    // 1 + (1 − u)(e^{−2/v} − 1) so that u → 1 keeps full precision.
    const double x = (1.0 - u) * std::expm1(-2.0 / v);
    if (x <= -1.0) return -1.0;
    return std::clamp(1.0 + v * std::log1p(x), -1.0, 1.0);
}

TrimmedLogistic::TrimmedLogistic(double s)
    : s_(s), norm_(1.0 / logistic_mass(s)), mass_(logistic_mass(s)),
      // CDF(−π) = 1/(1 + e^{π/s}); e^{π/s} may overflow to +inf, which correctly gives 0.
      cdf_lo_(1.0 / (1.0 + std::exp(kPi / s))) {}

double TrimmedLogistic::sample(double u) const {
    const double q = std::clamp(u, 0.0, 1.0) * mass_ + cdf_lo_;
    if (q <= 0.0) return -kPi;
    if (q >= 1.0) return kPi;
    // The logistic's quantile s·log(q / (1 − q)).
    return std::clamp(s_ * (std::log(q) - std::log1p(-q)), -kPi, kPi);
}

double trimmed_logistic(double x, double s) { return TrimmedLogistic(s).density(x); }

double sample_trimmed_logistic(double u, double s) { return TrimmedLogistic(s).sample(u); }

double azimuthal_shift(int p, double gamma_o, double gamma_t) {
    return 2.0 * p * gamma_t - 2.0 * gamma_o + p * kPi;
}

}  // namespace chiang

// ---------------------------------------------------------------------------------------
// Per-ω_o and per-h quantities.

struct ChiangFiber::Outgoing {
    double sin_theta = 0, cos_theta = 1, phi = 0;
    // sin γ_t = k · sin γ_o with k = cos θ_o / sqrt(η² − sin² θ_o) (1/η' of Bravais).
    double k = 0;
    // T = exp(−σ · path_scale · cos γ_t): the chord 2cos γ_t projected back by 1/cos θ_t.
    double path_scale = 2;
    // θ_o + δ_p for the sampler's cones, δ = (2α, −α, −4α); |cos| as Cycles.
    std::array<SinCos, 3> cone;
};

struct ChiangFiber::Attenuation {
    std::array<Channels, 4> a{};
    double gamma_o = 0, gamma_t = 0;
};

Expected<ChiangFiber> ChiangFiber::create(const ChiangParams &p) {
    const double max_offset = double(float(kHalfPi));  // the float nearest π/2 is accepted
    if (Status error = first_error(
            check::non_negative("sigma_a.r", p.sigma_a.r),
            check::non_negative("sigma_a.g", p.sigma_a.g),
            check::non_negative("sigma_a.b", p.sigma_a.b),
            check::in_range("roughness", p.roughness, 0.0, 1.0),
            check::in_range("radial_roughness", p.radial_roughness, 0.0, 1.0),
            check::in_range("coat", p.coat, 0.0, 1.0),
            check::greater_than("ior", p.ior, 1.0),
            check::in_range("offset", p.offset, -max_offset, max_offset))) {
        return *error;
    }

    ChiangFiber fiber;
    fiber.params_ = p;
    // Cycles' setup: clamp β_m, reduce it by the coat for R only, clamp again, then map.
    const double beta_m = std::clamp(double(p.roughness), 0.001, 1.0);
    const double beta_m0 = std::clamp((1.0 - double(p.coat)) * beta_m, 0.001, 1.0);
    fiber.v_ = chiang::longitudinal_variance(beta_m);
    fiber.v_m0_ = chiang::longitudinal_variance(beta_m0);
    fiber.s_ = chiang::logistic_scale(p.radial_roughness);
    fiber.eta_ = p.ior;
    fiber.alpha_ = p.offset;
    // The lobes' tilts δ_p = (2α, −α, −4α): Cycles adds them to θ_i, the sampler to θ_o.
    const double tilts[3] = {2.0 * fiber.alpha_, -fiber.alpha_, -4.0 * fiber.alpha_};
    for (int i = 0; i < 3; ++i) {
        fiber.tilt_sin_[i] = std::sin(tilts[i]);
        fiber.tilt_cos_[i] = std::cos(tilts[i]);
    }
    fiber.sigma_ = {p.sigma_a.r, p.sigma_a.g, p.sigma_a.b};
    fiber.azimuthal_ = chiang::TrimmedLogistic(fiber.s_);
    for (int lobe = 0; lobe < 4; ++lobe)
        fiber.longitudinal_[std::size_t(lobe)] = chiang::longitudinal_constants(fiber.lobe_variance(lobe));
    const double panel = std::min(kFixedPanelPerScale * fiber.s_, kFixedMaxPanel);
    const int panels = int(std::ceil(kPi / panel));
    fiber.fixed_panels_ = 8 * panels <= kMaxFixedNodes ? panels : 0;
    fiber.id_ = g_next_fiber_id.fetch_add(1, std::memory_order_relaxed);
    return fiber;
}

double ChiangFiber::lobe_variance(int p) const {
    switch (p) {
        case kLobeR: return v_m0_;
        case kLobeTT: return 0.25 * v_;
        case kLobeTRT:
        case kLobeResidual: return 4.0 * v_;
        default: return 0.0;
    }
}

LobeShape ChiangFiber::lobe_shape(int p) const {
    // Cycles evaluates M_p(θ_i + δ_p, θ_o) with δ = (2α, −α, −4α); d'Eon's M peaks where its
    // two angles are opposite, θ_i + δ_p = −θ_o, i.e. θ_i + θ_o = −δ_p, and is close to a
    // Gaussian in θ_i + θ_o of variance v_p. fiber.h wants the shape in θ_h = (θ_i + θ_o)/2:
    // both the shift and the width halve.
    static constexpr double kShiftPerAlpha[4] = {-2.0, 1.0, 4.0, 0.0};
    if (p < 0 || p > 3) return {};
    return {float(0.5 * kShiftPerAlpha[p] * alpha_), float(0.5 * std::sqrt(lobe_variance(p)))};
}

ChiangFiber::Outgoing ChiangFiber::outgoing_cones(double sin_theta_o) const {
    Outgoing o;
    o.sin_theta = std::clamp(sin_theta_o, -1.0, 1.0);
    o.cos_theta = cos_from_sin(o.sin_theta);
    for (int p = 0; p < 3; ++p) o.cone[p] = rotate(o.sin_theta, o.cos_theta, {tilt_sin_[p], tilt_cos_[p]});
    return o;
}

ChiangFiber::Outgoing ChiangFiber::outgoing(Vec3 wo) const {
    Outgoing o = outgoing_cones(double(wo.x));
    o.phi = std::atan2(double(wo.z), double(wo.y));
    o.k = o.cos_theta / std::sqrt(eta_ * eta_ - o.sin_theta * o.sin_theta);
    const double cos_theta_t = cos_from_sin(o.sin_theta / eta_);
    o.path_scale = 2.0 / cos_theta_t;
    return o;
}

ChiangFiber::Attenuation ChiangFiber::attenuation_at(const Outgoing &o, double h) const {
    Attenuation at;
    h = std::clamp(h, -1.0, 1.0);
    const double cos_gamma_o = cos_from_sin(h);
    const double sin_gamma_t = h * o.k;
    const double cos_gamma_t = cos_from_sin(sin_gamma_t);
    at.gamma_o = safe_asin(h);
    at.gamma_t = safe_asin(sin_gamma_t);

    const double f = fresnel_dielectric(o.cos_theta * cos_gamma_o, eta_);
    for (int c = 0; c < 3; ++c) {
        const double t = std::exp(-sigma_[c] * o.path_scale * cos_gamma_t);
        const double tf = t * f;
        at.a[0][c] = f;                 // R: one reflection
        at.a[1][c] = sqr(1.0 - f) * t;  // TT: in, one chord, out
        at.a[2][c] = at.a[1][c] * tf;   // TRT: one more chord and reflection
        // TRRT+: the geometric series of further chords, zero where it diverges (Cycles'
        // safe_divide; TF = 1 only at grazing incidence on a clear fiber, where A_2 = 0).
        const double denominator = 1.0 - tf;
        at.a[3][c] = denominator != 0.0 ? at.a[2][c] * tf / denominator : 0.0;
    }
    return at;
}

double ChiangFiber::tilted_longitudinal(int p, double sin_theta_i, double cos_theta_i,
                                        const Outgoing &o) const {
    if (p == kLobeResidual) {
        return chiang::longitudinal_scattering(sin_theta_i, cos_theta_i, o.sin_theta,
                                               o.cos_theta, longitudinal_[std::size_t(p)]);
    }
    // Cycles rotates θ_i by δ_p.
    const SinCos tilted = rotate(sin_theta_i, cos_theta_i, {tilt_sin_[p], tilt_cos_[p]});
    return chiang::longitudinal_scattering(tilted.sin, tilted.cos, o.sin_theta, o.cos_theta,
                                           longitudinal_[std::size_t(p)]);
}

double ChiangFiber::sampling_longitudinal(int p, double sin_theta_i, double cos_theta_i,
                                          const Outgoing &o) const {
    // The sampler's M_p: the same δ_p applied to θ_o instead (pbrt-v4's order), which makes
    // M_p the exact marginal density of the sampled sin θ_i.
    const SinCos cone = p < 3 ? o.cone[p] : SinCos{o.sin_theta, o.cos_theta};
    return chiang::longitudinal_scattering(sin_theta_i, cos_theta_i, cone.sin, cone.cos,
                                           longitudinal_[std::size_t(p)]);
}

// ---------------------------------------------------------------------------------------
// Near field.

Rgb ChiangFiber::lobe_f_cos_near(int p, Vec3 wi, Vec3 wo, float h) const {
    if (p < 0 || p > 3) return {};
    const Outgoing o = outgoing(wo);
    const Attenuation at = attenuation_at(o, h);
    const double sin_theta_i = std::clamp(double(wi.x), -1.0, 1.0);
    const double cos_theta_i = cos_from_sin(sin_theta_i);
    const double longitudinal = tilted_longitudinal(p, sin_theta_i, cos_theta_i, o);
    double azimuthal = kInvTwoPi;
    if (p < 3) {
        const double phi = std::atan2(double(wi.z), double(wi.y)) - o.phi;
        const double shift = chiang::azimuthal_shift(p, at.gamma_o, at.gamma_t);
        azimuthal = azimuthal_.density(wrap_angle(phi - shift));
    }
    return to_rgb(scaled(at.a[p], longitudinal * azimuthal));
}

Rgb ChiangFiber::f_cos_near(Vec3 wi, Vec3 wo, float h) const {
    const Outgoing o = outgoing(wo);
    const Attenuation at = attenuation_at(o, h);
    const double sin_theta_i = std::clamp(double(wi.x), -1.0, 1.0);
    const double cos_theta_i = cos_from_sin(sin_theta_i);
    const double phi = std::atan2(double(wi.z), double(wi.y)) - o.phi;
    Channels sum{};
    for (int p = 0; p < 4; ++p) {
        double weight = tilted_longitudinal(p, sin_theta_i, cos_theta_i, o);
        if (p < 3) {
            const double shift = chiang::azimuthal_shift(p, at.gamma_o, at.gamma_t);
            weight *= azimuthal_.density(wrap_angle(phi - shift));
        } else {
            weight *= kInvTwoPi;
        }
        for (int c = 0; c < 3; ++c) sum[c] += at.a[p][c] * weight;
    }
    return to_rgb(sum);
}

Rgb ChiangFiber::attenuation(int p, Vec3 wo, float h) const {
    if (p < 0 || p > 3) return {};
    return to_rgb(attenuation_at(outgoing(wo), h).a[p]);
}

ChiangFiber::LobeGeometry ChiangFiber::lobe_geometry(Vec3 wo, float h) const {
    const Attenuation at = attenuation_at(outgoing(wo), h);
    LobeGeometry g;
    for (int p = 0; p < 4; ++p) g.attenuation[size_t(p)] = to_rgb(at.a[size_t(p)]);
    for (int p = 0; p < 3; ++p) g.shift[size_t(p)] = chiang::azimuthal_shift(p, at.gamma_o, at.gamma_t);
    return g;
}

double ChiangFiber::longitudinal(int p, double sin_theta_i, double sin_theta_o) const {
    if (p < 0 || p > 3) return 0.0;
    Outgoing o;
    o.sin_theta = std::clamp(sin_theta_o, -1.0, 1.0);
    o.cos_theta = cos_from_sin(o.sin_theta);
    sin_theta_i = std::clamp(sin_theta_i, -1.0, 1.0);
    return tilted_longitudinal(p, sin_theta_i, cos_from_sin(sin_theta_i), o);
}

namespace {

std::array<double, 4> selection_weights(const std::array<Channels, 4> &a) {
    std::array<double, 4> w{};
    double total = 0;
    for (int p = 0; p < 4; ++p) total += (w[p] = luminance(a[p]));
    // A_0 = F > 0 for every η > 1, so the total is positive.
    for (double &x : w) x /= total;
    return w;
}

}  // namespace

std::array<float, 4> ChiangFiber::lobe_probabilities(Vec3 wo, float h) const {
    const std::array<double, 4> w = selection_weights(attenuation_at(outgoing(wo), h).a);
    return {float(w[0]), float(w[1]), float(w[2]), float(w[3])};
}

// ---------------------------------------------------------------------------------------
// The analytic sampler.

float ChiangFiber::pdf(Vec3 wi, Vec3 wo, float h) const {
    const Outgoing o = outgoing(wo);
    const Attenuation at = attenuation_at(o, h);
    const std::array<double, 4> w = selection_weights(at.a);
    const double sin_theta_i = std::clamp(double(wi.x), -1.0, 1.0);
    const double cos_theta_i = cos_from_sin(sin_theta_i);
    const double phi = std::atan2(double(wi.z), double(wi.y)) - o.phi;
    double density = 0;
    for (int p = 0; p < 4; ++p) {
        if (w[p] <= 0) continue;
        double term = w[p] * sampling_longitudinal(p, sin_theta_i, cos_theta_i, o);
        if (p < 3) {
            const double shift = chiang::azimuthal_shift(p, at.gamma_o, at.gamma_t);
            term *= azimuthal_.density(wrap_angle(phi - shift));
        } else {
            term *= kInvTwoPi;
        }
        density += term;
    }
    return float(density);
}

// d'Eon: the cosine t to the cone axis (at θ = −θ'_o), then a uniform angle about it; the
// projection onto the fiber axis is sin θ_i.
double ChiangFiber::cone_sample(int p, const Outgoing &o, double u_cone, double u_about) const {
    const SinCos cone = p < 3 ? o.cone[p] : SinCos{o.sin_theta, o.cos_theta};
    const double t = chiang::sample_cone_cosine(u_cone, lobe_variance(p));
    return std::clamp(-t * cone.sin + cos_from_sin(t) * std::cos(kTwoPi * u_about) * cone.cos, -1.0, 1.0);
}

double ChiangFiber::sample_lobe_sin_theta(int p, double sin_theta_o, double u_cone, double u_about) const {
    if (p < 0 || p > 3) return 0.0;
    return cone_sample(p, outgoing_cones(sin_theta_o), std::clamp(u_cone, 0.0, 1.0), u_about);
}

double ChiangFiber::lobe_sampling_density(int p, double sin_theta_i, double sin_theta_o) const {
    if (p < 0 || p > 3) return 0.0;
    sin_theta_i = std::clamp(sin_theta_i, -1.0, 1.0);
    return sampling_longitudinal(p, sin_theta_i, cos_from_sin(sin_theta_i), outgoing_cones(sin_theta_o));
}

std::optional<ChiangSample> ChiangFiber::sample(Vec3 wo, float h, float u0, float u1,
                                                float u2) const {
    const Outgoing o = outgoing(wo);
    const Attenuation at = attenuation_at(o, h);
    const std::array<double, 4> w = selection_weights(at.a);

    // Lobe from u2; what is left of u2 inside the chosen lobe's interval is reused for M_p.
    int last = 3;
    while (last > 0 && w[last] <= 0) --last;
    double u = std::clamp(double(u2), 0.0, 1.0);
    int p = 0;
    while (p < last && u >= w[p]) u -= w[p++];
    const double u_longitudinal = std::clamp(u / w[p], 0.0, 1.0);

    const double sin_theta_i = off_axis(float(cone_sample(p, o, u_longitudinal, u1)));
    const double cos_theta_i = cos_from_sin(sin_theta_i);

    double phi = kTwoPi * u0;  // residual: uniform
    if (p < 3) {
        phi = chiang::azimuthal_shift(p, at.gamma_o, at.gamma_t) +
              azimuthal_.sample(u0);
    }
    const double phi_i = o.phi + phi;

    ChiangSample result;
    result.wi = Vec3{float(sin_theta_i), float(cos_theta_i * std::cos(phi_i)),
                     float(cos_theta_i * std::sin(phi_i))};
    result.lobe = p;
    result.pdf = pdf(result.wi, wo, h);
    if (!(result.pdf > 0.0f) || !std::isfinite(result.pdf)) return std::nullopt;
    result.f_cos = f_cos_near(result.wi, wo, h);
    return result;
}

// ---------------------------------------------------------------------------------------
// Far field: ½∫ A_p(h) N_p(φ − Φ(p, h)) dh with h = sin γ, so dh = cos γ dγ and the
// integrand is smooth up to the fiber's edges.
//
// Only N_p depends on φ. For one ω_o, the factors ½ w_j cos γ_j A_p(γ_j) and Φ(p, γ_j) at
// fixed Gauss–Legendre nodes γ_j are therefore computed once (the "slice", remembered per
// thread for the last (fiber, θ_o) since tables sweep many ω_i for one ω_o), and each call
// only sums logistics. |dΦ/dγ| <= 2, so in γ the logistic bump is at least s wide: panels
// of kFixedPanelPerScale·s resolve it. When s is so small that this needs too many nodes,
// the graded rule below integrates around the bumps instead.

namespace {

// Graded rule: panels never exceed this width (radians), so that the smooth factors
// (Fresnel, transmittance, the bend of Φ) are resolved by the 8-point rule; a run of panels
// stops once what remains is provably below kTailFraction of what has been integrated.
constexpr double kGradedMaxPanel = 0.25;
constexpr double kTailFraction = 1e-8;

// Φ(p, γ) and its first two derivatives for sin γ_t = k sin γ.
struct Deflection {
    int p;
    double k;

    double value(double gamma) const {
        return 2.0 * p * safe_asin(k * std::sin(gamma)) - 2.0 * gamma + p * kPi;
    }
    double slope(double gamma) const {
        const double cos_gamma_t = cos_from_sin(k * std::sin(gamma));
        return 2.0 * p * k * std::cos(gamma) / cos_gamma_t - 2.0;
    }
    double curvature(double gamma) const {
        const double sin_g = std::sin(gamma), cos_g = std::cos(gamma);
        const double sin_t = k * sin_g, cos_t = cos_from_sin(sin_t);
        const double dgamma_t = k * cos_g / cos_t;
        return 2.0 * p * (-k * sin_g * cos_t + k * cos_g * sin_t * dgamma_t) / (cos_t * cos_t);
    }

    // The γ in [a, b] where Φ = target, for Φ monotone on [a, b] and the target between its
    // end values: Newton's method kept inside a shrinking bracket.
    double solve(double a, double b, double target) const {
        if (p == 0) return std::clamp(-0.5 * target, a, b);  // Φ = −2γ
        double lo = a, hi = b;
        double f_lo = value(a) - target;
        const double f_hi = value(b) - target;
        if (f_lo == 0.0) return a;
        if (f_hi == 0.0) return b;
        double x = a + (b - a) * f_lo / (f_lo - f_hi);
        for (int iteration = 0; iteration < 60; ++iteration) {
            const double f = value(x) - target;
            if (f == 0.0) return x;
            if ((f < 0.0) == (f_lo < 0.0)) {
                lo = x;
                f_lo = f;
            } else {
                hi = x;
            }
            const double d = slope(x);
            double next = d != 0.0 ? x - f / d : 0.5 * (lo + hi);
            if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
            if (std::fabs(next - x) <= 1e-14 || hi - lo <= 1e-14) return next;
            x = next;
        }
        return x;
    }
};

// Where Φ(2, γ) turns (TRT's caustics): sin²γ = (4k² − 1)/(3k²), when k > 1/2.
double caustic_gamma(double k) { return std::asin(std::sqrt((4.0 * k * k - 1.0) / (3.0 * k * k))); }

}  // namespace

struct ChiangFiber::FarSlice {
    std::uint64_t id = 0;
    double sin_theta = 2.0;  // the key with id; 2 marks an empty slice
    Channels residual{};     // ½∫ A_3 cos γ dγ
    int node_count = 0;      // per lobe; 0 with the graded rule
    std::vector<double> shift;   // [p·n + j]: Φ(p, γ_j) wrapped to [−π, π]
    std::vector<double> weight;  // [(p·n + j)·3 + c]: ½ w_j cos γ_j A_p(γ_j)_c
    std::array<Channels, 3> total_weight{};  // Σ_j weight, per lobe: ½∫ A_p cos γ dγ

    // Memo of far_azimuthal for this slice: an open-addressing table keyed on the exact bits
    // of (p, φ); entries of older slices are told apart by their generation.
    struct MemoEntry {
        std::uint64_t phi_bits = 0;
        std::uint32_t generation = 0;  // 0: never used
        int p = 0;
        Channels value{};
    };
    // Slots in use: the first memo_slots (a power of two) of memo; the rest is storage kept
    // from earlier slices, whose entries are all of older generations.
    std::vector<MemoEntry> memo;
    std::size_t memo_slots = 0;
    std::uint32_t generation = 0;
    std::size_t memo_count = 0;

    void clear_memo() {
        memo_count = 0;
        memo_slots = 0;  // start small again: a small table stays in cache
        if (++generation == 0) {  // wrapped: forget every entry for real
            for (MemoEntry &e : memo) e.generation = 0;
            generation = 1;
        }
    }
};

ChiangFiber::FarSlice &ChiangFiber::far_slice(const Outgoing &o) const {
    thread_local FarSlice slice;
    if (slice.id == id_ && slice.sin_theta == o.sin_theta) return slice;

    slice.clear_memo();
    slice.id = id_;
    slice.sin_theta = o.sin_theta;
    const int panels = fixed_panels_ > 0 ? fixed_panels_ : 6;  // the residual is smooth
    const int n = 8 * panels;
    slice.node_count = fixed_panels_ > 0 ? n : 0;
    slice.shift.assign(std::size_t(3 * slice.node_count), 0.0);
    slice.weight.assign(std::size_t(9 * slice.node_count), 0.0);
    slice.residual = {};
    slice.total_weight = {};

    const double panel_width = kPi / panels;
    int j = 0;
    for (int panel = 0; panel < panels; ++panel) {
        const double centre = -kHalfPi + (panel + 0.5) * panel_width;
        for (int node = 0; node < 4; ++node) {
            for (double side : {-1.0, 1.0}) {
                const double gamma = centre + side * 0.5 * panel_width * kGaussNodes[node];
                const double weight = 0.5 * kGaussWeights[node] * 0.5 * panel_width * std::cos(gamma);
                const Attenuation at = attenuation_at(o, std::sin(gamma));
                for (int c = 0; c < 3; ++c) slice.residual[c] += weight * at.a[3][c];
                if (slice.node_count > 0) {
                    for (int p = 0; p < 3; ++p) {
                        const std::size_t index = std::size_t(p * n + j);
                        slice.shift[index] =
                            wrap_angle(chiang::azimuthal_shift(p, at.gamma_o, at.gamma_t));
                        for (int c = 0; c < 3; ++c) {
                            slice.weight[3 * index + std::size_t(c)] = weight * at.a[p][c];
                            slice.total_weight[p][c] += weight * at.a[p][c];
                        }
                    }
                }
                ++j;
            }
        }
    }
    return slice;
}

// The edges of the pieces of [−π/2, π/2] on which the deflection Φ(p, γ) is monotone: one
// piece, or three for TRT when the caustic exists (k > 1/2). Returns the number of edges.
static int monotone_pieces(int p, double k, double cuts[4]) {
    cuts[0] = -kHalfPi;
    if (p == 2 && k > 0.5) {
        const double caustic = caustic_gamma(k);
        cuts[1] = -caustic;
        cuts[2] = caustic;
        cuts[3] = kHalfPi;
        return 4;
    }
    cuts[1] = kHalfPi;
    return 2;
}

namespace {

// Memo slots: a power of two, from kMinMemoSlots for each new slice, doubled to stay at most
// half full, up to kMaxMemoSlots (2.6 MB per thread); a full memo stops remembering (the
// values are then computed as without it).
constexpr std::size_t kMinMemoSlots = 512;
constexpr std::size_t kMaxMemoSlots = std::size_t(1) << 16;

std::size_t memo_hash(std::uint64_t phi_bits, int p) {
    std::uint64_t h = (phi_bits + std::uint64_t(p + 1) * 0x9E3779B97F4A7C15ull) * 0xFF51AFD7ED558CCDull;
    return std::size_t(h ^ (h >> 29));
}

}  // namespace

std::array<double, 3> ChiangFiber::far_azimuthal(int p, const Outgoing &o, double phi) const {
    // The far field N_p is a pure function of (fiber, θ_o, p, φ), and table sweeps ask for the
    // same φ many times per θ_o (every θ_i and −θ_i give bit-identical φ), so the values are
    // remembered per slice. A remembered value is exactly the value the computation returns,
    // so results do not depend on the order of calls or on which thread makes them.
    FarSlice &slice = far_slice(o);
    std::uint64_t bits;
    std::memcpy(&bits, &phi, sizeof bits);
    using Entry = FarSlice::MemoEntry;
    if (slice.memo_slots == 0) {
        slice.memo_slots = kMinMemoSlots;
        if (slice.memo.size() < kMinMemoSlots) slice.memo.resize(kMinMemoSlots);
    }
    std::size_t mask = slice.memo_slots - 1;
    std::size_t index = memo_hash(bits, p) & mask;
    while (slice.memo[index].generation == slice.generation) {
        const Entry &e = slice.memo[index];
        if (e.phi_bits == bits && e.p == p) return e.value;
        index = (index + 1) & mask;
    }
    const Channels value = far_azimuthal_uncached(p, o, phi, slice);
    if (2 * (slice.memo_count + 1) > slice.memo_slots) {
        if (slice.memo_slots >= kMaxMemoSlots) return value;
        // Grow: take this slice's entries out, double the slots in use, put them back.
        thread_local std::vector<Entry> live;
        live.clear();
        for (std::size_t i = 0; i < slice.memo_slots; ++i) {
            Entry &e = slice.memo[i];
            if (e.generation == slice.generation) live.push_back(e);
            e.generation = 0;
        }
        slice.memo_slots *= 2;
        if (slice.memo.size() < slice.memo_slots) slice.memo.resize(slice.memo_slots);
        mask = slice.memo_slots - 1;
        for (const Entry &e : live) {
            std::size_t i = memo_hash(e.phi_bits, e.p) & mask;
            while (slice.memo[i].generation == slice.generation) i = (i + 1) & mask;
            slice.memo[i] = e;
        }
        index = memo_hash(bits, p) & mask;
        while (slice.memo[index].generation == slice.generation) index = (index + 1) & mask;
    }
    slice.memo[index] = Entry{bits, slice.generation, p, value};
    ++slice.memo_count;
    return value;
}

std::array<double, 3> ChiangFiber::far_azimuthal_uncached(int p, const Outgoing &o, double phi,
                                                          const FarSlice &slice) const {
    if (slice.node_count == 0) return far_azimuthal_graded(p, o, phi);
    const int n = slice.node_count;
    const double *shift = slice.shift.data() + std::size_t(p * n);
    const double *weight = slice.weight.data() + std::size_t(3 * p * n);
    const double inv_s = 1.0 / s_;
    double sum[3] = {0, 0, 0};
    for (int j = 0; j < n; ++j) {
        double x = phi - shift[j];  // both in [−π, π]: one turn of wrapping at most
        if (x > kPi) x -= kTwoPi;
        if (x < -kPi) x += kTwoPi;
        const double e = std::exp(-std::fabs(x) * inv_s);
        const double bump = e / sqr(1.0 + e);
        sum[0] += weight[3 * j] * bump;
        sum[1] += weight[3 * j + 1] * bump;
        sum[2] += weight[3 * j + 2] * bump;
    }
    const double scale = azimuthal_.norm() * inv_s;
    Channels result{sum[0] * scale, sum[1] * scale, sum[2] * scale};

    // N has a kink where φ − Φ wraps through ±π, which the fixed nodes straddle: its slope
    // jumps by 2N(π)·tanh(π/2s)/s there, times |Φ'| <= 2 in γ. The error of a panel of width
    // H across it is of order that jump·H²·(the panel's weight); when that is not negligible
    // next to the result (φ far from every peak of the lobe), the panels holding a kink are
    // integrated again, split at it.
    const int panels = fixed_panels_;
    const double panel_width = kPi / panels;
    const double kink_slope_jump = 4.0 * logistic(kPi, s_) * azimuthal_.norm() * std::tanh(kHalfPi / s_) * inv_s;
    bool negligible = true;
    for (int c = 0; c < 3; ++c) {
        const double kink_error = kink_slope_jump * panel_width * panel_width * slice.total_weight[p][c];
        if (kink_error > 1e-6 * result[c]) negligible = false;
    }
    if (negligible) return result;

    const Deflection deflection{p, o.k};
    double cuts[4];
    const int cut_count = monotone_pieces(p, o.k, cuts);
    int refined[3] = {-1, -1, -1};
    for (int piece = 0; piece + 1 < cut_count; ++piece) {
        const double a = cuts[piece], b = cuts[piece + 1];
        const double phi_a = deflection.value(a), phi_b = deflection.value(b);
        const double lo = std::min(phi_a, phi_b), hi = std::max(phi_a, phi_b);
        const double target = phi + kPi;
        const double lifted = target + kTwoPi * std::ceil((lo - target) / kTwoPi);
        if (lifted > hi) continue;
        const double kink = deflection.solve(a, b, lifted);
        const int panel = std::clamp(int(std::floor((kink + kHalfPi) / panel_width)), 0, panels - 1);
        if (panel == refined[0] || panel == refined[1] || panel == refined[2]) continue;
        refined[piece] = panel;
        const double start = -kHalfPi + panel * panel_width, end = start + panel_width;
        const Channels fixed = fixed_panel(p, slice, phi, panel);
        const Channels left = exact_panel(p, o, phi, start, kink);
        const Channels right = exact_panel(p, o, phi, kink, end);
        for (int c = 0; c < 3; ++c) result[c] += left[c] + right[c] - fixed[c];
    }
    return result;
}

std::array<double, 3> ChiangFiber::fixed_panel(int p, const FarSlice &slice, double phi,
                                               int panel) const {
    const int n = slice.node_count;
    Channels sum{};
    for (int j = 8 * panel; j < 8 * panel + 8; ++j) {
        const std::size_t index = std::size_t(p * n + j);
        const double bump = azimuthal_.density(wrap_angle(phi - slice.shift[index]));
        for (int c = 0; c < 3; ++c) sum[c] += slice.weight[3 * index + std::size_t(c)] * bump;
    }
    return sum;
}

std::array<double, 3> ChiangFiber::exact_panel(int p, const Outgoing &o, double phi, double a,
                                               double b) const {
    Channels sum{};
    if (!(b > a)) return sum;
    const double centre = 0.5 * (a + b), half = 0.5 * (b - a);
    for (int node = 0; node < 4; ++node) {
        for (double side : {-1.0, 1.0}) {
            const double gamma = centre + side * half * kGaussNodes[node];
            const Attenuation at = attenuation_at(o, std::sin(gamma));
            const double shift = chiang::azimuthal_shift(p, at.gamma_o, at.gamma_t);
            const double weight = 0.5 * kGaussWeights[node] * half * std::cos(gamma) *
                                  azimuthal_.density(wrap_angle(phi - shift));
            for (int c = 0; c < 3; ++c) sum[c] += weight * at.a[p][c];
        }
    }
    return sum;
}

// The graded rule. The γ range is cut where Φ turns (TRT's caustics), at the peaks
// (Φ ≡ φ mod 2π) and where φ − Φ wraps through ±π; on each resulting interval N is monotone,
// and Gauss–Legendre panels grow geometrically from its larger end, starting at the bump's
// half-width.
std::array<double, 3> ChiangFiber::far_azimuthal_graded(int p, const Outgoing &o, double phi) const {
    const Deflection deflection{p, o.k};
    const double s = s_;

    // A_p(γ) cos γ N(φ − Φ(γ)) per channel.
    auto integrand = [&](double gamma, Channels &out) {
        const double sin_g = std::sin(gamma), cos_g = std::cos(gamma);
        const double sin_t = o.k * sin_g, cos_t = cos_from_sin(sin_t);
        const double f = fresnel_dielectric(o.cos_theta * cos_g, eta_);
        const double shift = (p > 0 ? 2.0 * p * safe_asin(sin_t) : 0.0) - 2.0 * gamma + p * kPi;
        const double common = cos_g * logistic(wrap_angle(phi - shift), s) * azimuthal_.norm();
        for (int c = 0; c < 3; ++c) {
            double a = f;
            if (p > 0) {
                const double t = std::exp(-sigma_[c] * o.path_scale * cos_t);
                a = sqr(1.0 - f) * t;
                if (p == 2) a *= t * f;
            }
            out[c] = a * common;
        }
    };
    auto logistic_at = [&](double gamma) {
        return logistic(wrap_angle(phi - deflection.value(gamma)), s) * azimuthal_.norm();
    };

    // Monotone pieces of Φ.
    double cuts[4];
    const int cut_count = monotone_pieces(p, o.k, cuts);

    Channels total{};
    for (int piece = 0; piece + 1 < cut_count; ++piece) {
        const double a = cuts[piece], b = cuts[piece + 1];
        if (!(b > a)) continue;
        const double phi_a = deflection.value(a), phi_b = deflection.value(b);
        const double lo = std::min(phi_a, phi_b), hi = std::max(phi_a, phi_b);

        // Breakpoints: the piece's ends, the peak (Φ ≡ φ) and the wrap (Φ ≡ φ + π). A piece
        // spans less than 2π of Φ, so each target is met at most once.
        double points[4] = {a, b, 0, 0};
        int point_count = 2;
        for (double target : {phi, phi + kPi}) {
            const double lifted = target + kTwoPi * std::ceil((lo - target) / kTwoPi);
            if (lifted <= hi) points[point_count++] = deflection.solve(a, b, lifted);
        }
        for (int x = 1; x < point_count; ++x) {
            for (int y = x; y > 0 && points[y] < points[y - 1]; --y) std::swap(points[y], points[y - 1]);
        }

        for (int i = 0; i + 1 < point_count; ++i) {
            const double c = points[i], d = points[i + 1];
            const double length = d - c;
            if (!(length > 1e-15)) continue;

            const bool from_c = logistic_at(c) >= logistic_at(d);
            const double start = from_c ? c : d;
            const double direction = from_c ? 1.0 : -1.0;

            // The bump's half-width seen from the start: s/|Φ'|, or sqrt(2s/|Φ''|) where Φ
            // turns.
            const double slope = std::fabs(deflection.slope(start));
            const double curvature = std::fabs(deflection.curvature(start));
            double width = length;
            if (slope > 0) width = std::min(width, s / slope);
            if (curvature > 0) width = std::min(width, std::sqrt(2.0 * s / curvature));
            width = std::max(width, 1e-12);

            Channels accumulated{};
            double position = 0;
            int panel = 0;
            while (position < length) {
                const double panel_width = std::min({width, kGradedMaxPanel, length - position});
                const double centre = position + 0.5 * panel_width;
                const double half = 0.5 * panel_width;
                for (int j = 0; j < 4; ++j) {
                    for (double side : {-1.0, 1.0}) {
                        Channels value;
                        integrand(start + direction * (centre + side * half * kGaussNodes[j]), value);
                        for (int ch = 0; ch < 3; ++ch) accumulated[ch] += kGaussWeights[j] * half * value[ch];
                    }
                }
                position += panel_width;
                if (++panel >= 2) width *= 2.0;  // panels w, w, 2w, 4w, ...
                if (position < length) {
                    // A_p <= 1 and cos γ <= 1, and N only decreases from here on.
                    const double bound = (length - position) * logistic_at(start + direction * position);
                    const double smallest = std::min({accumulated[0], accumulated[1], accumulated[2]});
                    if (bound <= kTailFraction * smallest) break;
                }
            }
            for (int ch = 0; ch < 3; ++ch) total[ch] += accumulated[ch];
        }
    }
    return scaled(total, 0.5);
}

Rgb ChiangFiber::lobe_f_cos(int p, Vec3 wi, Vec3 wo) const {
    if (p < 0 || p > 3) return {};
    const Outgoing o = outgoing(wo);
    const double sin_theta_i = std::clamp(double(wi.x), -1.0, 1.0);
    const double cos_theta_i = cos_from_sin(sin_theta_i);
    const double longitudinal = tilted_longitudinal(p, sin_theta_i, cos_theta_i, o);
    if (p == kLobeResidual) return to_rgb(scaled(far_slice(o).residual, longitudinal * kInvTwoPi));
    const double phi = wrap_angle(std::atan2(double(wi.z), double(wi.y)) - o.phi);
    return to_rgb(scaled(far_azimuthal(p, o, phi), longitudinal));
}

Rgb ChiangFiber::f_cos(Vec3 wi, Vec3 wo) const {
    const Outgoing o = outgoing(wo);
    const double sin_theta_i = std::clamp(double(wi.x), -1.0, 1.0);
    const double cos_theta_i = cos_from_sin(sin_theta_i);
    const double phi = wrap_angle(std::atan2(double(wi.z), double(wi.y)) - o.phi);
    const double residual_longitudinal =
        tilted_longitudinal(kLobeResidual, sin_theta_i, cos_theta_i, o) * kInvTwoPi;
    Channels sum = scaled(far_slice(o).residual, residual_longitudinal);
    for (int p = 0; p < 3; ++p) {
        const double longitudinal = tilted_longitudinal(p, sin_theta_i, cos_theta_i, o);
        const Channels azimuthal = far_azimuthal(p, o, phi);
        for (int c = 0; c < 3; ++c) sum[c] += longitudinal * azimuthal[c];
    }
    return to_rgb(sum);
}

}  // namespace hairis
