#include "fiber/chiang.h"

#include <boost/math/special_functions/bessel.hpp>
#include <boost/math/tools/roots.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/frame.h"
#include "core/quadrature.h"
#include "fiber/fresnel.h"
#include "fiber/principled_hair.h"

namespace hairis {

namespace {

using Channels = std::array<double, 3>;
using chiang::SinCos;

constexpr double kSqrtPiOver8 = 0.62665706865775012560;

// Far field, fixed rule (see ChiangFarField): panel width in units of s, its cap (radians),
// and the most nodes per lobe before the graded rule is cheaper.
constexpr double kFixedPanelPerScale = 2.0;
constexpr double kFixedMaxPanel = 0.25;
constexpr int kMaxFixedNodes = 800;
constexpr int kPanelPoints = 8;

double luminance(const Channels &c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

Rgb to_rgb(const Channels &c) { return {float(c[0]), float(c[1]), float(c[2])}; }

Channels scaled(const Channels &c, double k) { return {c[0] * k, c[1] * k, c[2] * k}; }

// The logistic density of scale s (not trimmed), written with e^{−|x|/s} so that it cannot
// overflow: an even, smooth function of x (= sech²(x/2s)/(4s)).
double logistic(double x, double s) {
    const double e = std::exp(-std::fabs(x) / s);
    return e / (s * sqr(1.0 + e));
}

// Mass of the logistic inside [−π, π]: 1 − 2·CDF(−π) = tanh(π/2s).
double logistic_mass(double s) { return std::tanh(kPi / (2.0 * s)); }

SinCos sin_cos_of(double sin_theta) {
    const double s = std::clamp(sin_theta, -1.0, 1.0);
    return {s, cos_from_sin(s)};
}

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
    // I0(x) ~ e^x / sqrt(2πx) · Σ a_k x^{−k}, a_k = a_{k−1}(2k − 1)²/(8k).
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

LongitudinalConstants longitudinal_constants(double v) {
    LongitudinalConstants c;
    c.v = v;
    c.kappa = 1.0 / v;
    // log(csch(κ)/(2v)) = log κ − κ − log(1 − e^{−2κ}), finite for every κ > 0.
    c.log_normalization = std::log(c.kappa) - c.kappa - std::log(-std::expm1(-2.0 * c.kappa));
    return c;
}

namespace {
// Boost computes in double (its default promotes doubles to long double, which is slower).
constexpr auto kDoublePolicy = boost::math::policies::policy<boost::math::policies::promote_double<false>>();
}  // namespace

double Cone::density(double sin_theta_i, double cos_theta_i) const {
    const double log_prefactor = c_->log_normalization - c_->kappa * sin_theta_i * axis_.sin;
    const double x = c_->kappa * cos_theta_i * axis_.cos;
    // Boost's I0 directly while neither factor can overflow or underflow; log space beyond.
    if (x < 600.0 && log_prefactor > -600.0 && log_prefactor < 600.0)
        return std::exp(log_prefactor) * boost::math::cyl_bessel_i(0, x, kDoublePolicy);
    return std::exp(log_prefactor + log_bessel_i0(x));
}

double Cone::sample(double u_cone, double u_about) const {
    // d'Eon: the cosine t to the cone axis (at θ = −θ_c), then a uniform angle about it; the
    // projection onto the fiber axis is sin θ_i.
    const double t = sample_cone_cosine(std::clamp(u_cone, 0.0, 1.0), c_->v);
    return std::clamp(-t * axis_.sin + cos_from_sin(t) * std::cos(kTwoPi * u_about) * axis_.cos, -1.0, 1.0);
}

double longitudinal_scattering(double sin_theta_i, double cos_theta_i, double sin_theta_o,
                               double cos_theta_o, double v) {
    const LongitudinalConstants c = longitudinal_constants(v);
    return Cone({sin_theta_o, cos_theta_o}, c).density(sin_theta_i, cos_theta_i);
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

double azimuthal_shift(int p, double gamma_o, double gamma_t) {
    return 2.0 * p * gamma_t - 2.0 * gamma_o + p * kPi;
}

SinCos rotate(SinCos theta, SinCos delta) {
    return {theta.sin * delta.cos + theta.cos * delta.sin,
            std::fabs(theta.cos * delta.cos - theta.sin * delta.sin)};
}

}  // namespace chiang

const char *chiang_tilt_name(ChiangTilt tilt) {
    return tilt == ChiangTilt::Outgoing ? "cycles4.2" : "cycles3.4";
}

// ---------------------------------------------------------------------------------------
// The fiber.

namespace {

// Cycles' setup: clamp β_m, reduce it by the coat for R only, clamp again, then map.
void set_longitudinal(const ChiangParams &p, double &v, double &v_m0) {
    const double beta_m = std::clamp(double(p.roughness), 0.001, 1.0);
    const double beta_m0 = std::clamp((1.0 - double(p.coat)) * beta_m, 0.001, 1.0);
    v = chiang::longitudinal_variance(beta_m);
    v_m0 = chiang::longitudinal_variance(beta_m0);
}

}  // namespace

Expected<ChiangLobes> ChiangLobes::create(const ChiangParams &p) {
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
    if (p.tilt != ChiangTilt::Incident && p.tilt != ChiangTilt::Outgoing)
        return Error{"tilt must be Cycles 3.4's (incident) or 4.2's (outgoing)"};

    ChiangLobes lobes;
    lobes.params_ = p;
    set_longitudinal(p, lobes.v_, lobes.v_m0_);
    lobes.s_ = chiang::logistic_scale(p.radial_roughness);
    lobes.eta_ = p.ior;
    lobes.alpha_ = p.offset;
    const double tilts[3] = {2.0 * lobes.alpha_, -lobes.alpha_, -4.0 * lobes.alpha_};
    for (int i = 0; i < 3; ++i) lobes.tilt_[std::size_t(i)] = {std::sin(tilts[i]), std::cos(tilts[i])};
    lobes.sigma_ = {p.sigma_a.r, p.sigma_a.g, p.sigma_a.b};
    lobes.azimuthal_ = chiang::TrimmedLogistic(lobes.s_);
    lobes.set_longitudinal_constants();
    return lobes;
}

void ChiangLobes::set_longitudinal_constants() {
    for (int lobe = 0; lobe < 3; ++lobe)
        longitudinal_[std::size_t(lobe)] = chiang::longitudinal_constants(lobe_variance(lobe));
    longitudinal_[kLobeResidual] = longitudinal_[kLobeTRT];  // both 4v
}

ChiangLobes ChiangLobes::derive(const ChiangLobes &base, const ChiangParams &p) {
    ChiangLobes lobes = base;
    const ChiangParams &b = base.params_;
    lobes.params_ = p;
    lobes.sigma_ = {p.sigma_a.r, p.sigma_a.g, p.sigma_a.b};
    lobes.eta_ = p.ior;
    if (p.roughness != b.roughness || p.coat != b.coat) {
        set_longitudinal(p, lobes.v_, lobes.v_m0_);
        lobes.set_longitudinal_constants();
    }
    if (p.radial_roughness != b.radial_roughness) {
        lobes.s_ = chiang::logistic_scale(p.radial_roughness);
        lobes.azimuthal_ = chiang::TrimmedLogistic(lobes.s_);
    }
    if (p.offset != b.offset) {
        lobes.alpha_ = p.offset;
        const double tilts[3] = {2.0 * lobes.alpha_, -lobes.alpha_, -4.0 * lobes.alpha_};
        for (int i = 0; i < 3; ++i) lobes.tilt_[std::size_t(i)] = {std::sin(tilts[i]), std::cos(tilts[i])};
    }
    return lobes;
}

std::optional<ChiangLobes> ChiangLobes::blurred(double roughness) const {
    if (!(roughness > v_ || roughness > v_m0_ || roughness > s_)) return std::nullopt;
    ChiangLobes lobes = *this;
    lobes.v_ = std::max(roughness, v_);
    lobes.v_m0_ = std::max(roughness, v_m0_);
    if (roughness > s_) {
        lobes.s_ = roughness;
        lobes.azimuthal_ = chiang::TrimmedLogistic(lobes.s_);
    }
    lobes.set_longitudinal_constants();
    return lobes;
}

bool ChiangLobes::same_longitudinal(int p, const ChiangLobes &other) const {
    if (p < 0 || p > 3) return false;
    if (lobe_variance(p) != other.lobe_variance(p)) return false;
    if (p == kLobeResidual) return true;  // never tilted
    return params_.tilt == other.params_.tilt && alpha_ == other.alpha_;
}

Expected<ChiangFiber> ChiangFiber::create(const ChiangParams &p) {
    Expected<ChiangLobes> lobes = ChiangLobes::create(p);
    if (!lobes) return lobes.error();
    ChiangFiber fiber;
    fiber.lobes_ = std::move(lobes).value();
    const double panel = std::min(kFixedPanelPerScale * fiber.lobes_.s_, kFixedMaxPanel);
    const int panels = int(std::ceil(kPi / panel));
    fiber.fixed_panels_ = kPanelPoints * panels <= kMaxFixedNodes ? panels : 0;
    return fiber;
}

double ChiangLobes::lobe_variance(int p) const {
    switch (p) {
        case kLobeR: return v_m0_;
        case kLobeTT: return 0.25 * v_;
        case kLobeTRT:
        case kLobeResidual: return 4.0 * v_;
        default: return 0.0;
    }
}

LobeShape ChiangFiber::lobe_shape(int p) const {
    const double alpha_ = lobes_.alpha_;
    // M_p peaks where its two angles are opposite: θ_i + θ_o = −δ_p with δ = (2α, −α, −4α),
    // for either tilt semantics; fiber.h wants the shape in θ_h = (θ_i + θ_o)/2.
    static constexpr double kShiftPerAlpha[4] = {-2.0, 1.0, 4.0, 0.0};
    if (p < 0 || p > 3) return {};
    return {float(0.5 * kShiftPerAlpha[p] * alpha_), float(0.5 * std::sqrt(lobes_.lobe_variance(p)))};
}

std::array<SinCos, 4> ChiangLobes::cones(SinCos o) const {
    return {chiang::rotate(o, tilt_[0]), chiang::rotate(o, tilt_[1]), chiang::rotate(o, tilt_[2]), o};
}

double ChiangLobes::tilted_longitudinal(int p, double sin_i, double cos_i, SinCos o, SinCos cone) const {
    const chiang::LongitudinalConstants &c = longitudinal_[std::size_t(p)];
    if (params_.tilt == ChiangTilt::Outgoing || p == kLobeResidual) return chiang::Cone(cone, c).density(sin_i, cos_i);
    // Cycles 3.4 rotates θ_i by δ_p.
    const SinCos tilted = chiang::rotate({sin_i, cos_i}, tilt_[std::size_t(p)]);
    return chiang::Cone(o, c).density(tilted.sin, tilted.cos);
}

double ChiangLobes::lobe_longitudinal(int p, double sin_theta_i, double sin_theta_o) const {
    if (p < 0 || p > 3) return 0.0;
    const SinCos o = sin_cos_of(sin_theta_o), i = sin_cos_of(sin_theta_i);
    return tilted_longitudinal(p, i.sin, i.cos, o, cones(o)[std::size_t(p)]);
}

chiang::Cone ChiangLobes::lobe_cone(int p, double sin_theta_o) const {
    const int q = std::clamp(p, 0, 3);
    return chiang::Cone(cones(sin_cos_of(sin_theta_o))[std::size_t(q)], longitudinal_[std::size_t(q)]);
}

void ChiangLobes::attenuation_at(double cos_theta_o, double k, double path_scale, double h,
                                 std::array<Channels, 4> &a, double &gamma_o, double &gamma_t) const {
    h = std::clamp(h, -1.0, 1.0);
    const double cos_gamma_o = cos_from_sin(h);
    const double sin_gamma_t = h * k;
    const double cos_gamma_t = cos_from_sin(sin_gamma_t);
    gamma_o = safe_asin(h);
    gamma_t = safe_asin(sin_gamma_t);
    const double f = fresnel_dielectric(cos_theta_o * cos_gamma_o, eta_);
    for (int c = 0; c < 3; ++c) {
        const double t = std::exp(-sigma_[std::size_t(c)] * path_scale * cos_gamma_t);
        const double tf = t * f;
        a[0][std::size_t(c)] = f;                 // R: one reflection
        a[1][std::size_t(c)] = sqr(1.0 - f) * t;  // TT: in, one chord, out
        a[2][std::size_t(c)] = a[1][std::size_t(c)] * tf;  // TRT: one more chord and reflection
        // TRRT+: the geometric series of further chords, zero where it diverges (Cycles'
        // safe_divide; TF = 1 only at grazing incidence on a clear fiber, where A_2 = 0).
        const double denominator = 1.0 - tf;
        a[3][std::size_t(c)] = denominator != 0.0 ? a[2][std::size_t(c)] * tf / denominator : 0.0;
    }
}

// ---------------------------------------------------------------------------------------
// Near field at one hit.

namespace {

// sin γ_t = k · sin γ_o with k = cos θ_o / sqrt(η² − sin² θ_o) (1/η' of Bravais); the chord
// 2cos γ_t is projected back by 1/cos θ_t.
double bravais_ratio(SinCos o, double eta) { return o.cos / std::sqrt(eta * eta - o.sin * o.sin); }
double chord_scale(SinCos o, double eta) { return 2.0 / cos_from_sin(o.sin / eta); }

}  // namespace

ChiangPoint::ChiangPoint(const ChiangFiber &fiber, const FiberHit &hit) : ChiangPoint(fiber.lobes(), hit) {}

const FiberPoint &ChiangFiber::prepare(const FiberHit &hit, ScratchBuffer &scratch) const {
    if (hit.blur_roughness > 0.0f)
        if (std::optional<ChiangLobes> wide = lobes_.blurred(hit.blur_roughness))
            return scratch.make<ChiangPoint>(scratch.make<ChiangLobes>(*wide), hit, true);
    return scratch.make<ChiangPoint>(*this, hit);
}

ChiangPoint::ChiangPoint(const ChiangLobes &lobes, const FiberHit &hit, bool blurred)
    : FiberPoint(hit), lobes_(&lobes), o_(sin_cos_of(double(hit.wo.x))), blurred_(blurred) {
    const double r = std::sqrt(double(hit.wo.y) * hit.wo.y + double(hit.wo.z) * hit.wo.z);
    cos_phi_o_ = r > 0 ? hit.wo.y / r : 0.0;
    sin_phi_o_ = r > 0 ? hit.wo.z / r : -1.0;
    double gamma_o = 0, gamma_t = 0;
    lobes.attenuation_at(o_.cos, bravais_ratio(o_, lobes.eta_), chord_scale(o_, lobes.eta_), double(hit.h), a_,
                         gamma_o, gamma_t);
    for (int p = 0; p < 3; ++p) shift_[std::size_t(p)] = chiang::azimuthal_shift(p, gamma_o, gamma_t);
    double total = 0;
    for (int p = 0; p < 4; ++p) total += (weight_[std::size_t(p)] = luminance(a_[std::size_t(p)]));
    // A_0 = F > 0 for every η > 1, so the total is positive.
    for (double &w : weight_) w /= total;
    cone_ = lobes.cones(o_);
}

double ChiangPoint::relative_azimuth(Vec3 wi) const {
    return std::atan2(wi.z * cos_phi_o_ - wi.y * sin_phi_o_, wi.y * cos_phi_o_ + wi.z * sin_phi_o_);
}

Vec3 ChiangPoint::direction(double sin_theta_i, double cos_theta_i, double phi) const {
    const double c = std::cos(phi), s = std::sin(phi);
    const double cos_phi_i = cos_phi_o_ * c - sin_phi_o_ * s;
    const double sin_phi_i = sin_phi_o_ * c + cos_phi_o_ * s;
    return {float(sin_theta_i), float(cos_theta_i * cos_phi_i), float(cos_theta_i * sin_phi_i)};
}

double ChiangPoint::longitudinal(int p, double sin_i, double cos_i) const {
    return lobes_->tilted_longitudinal(p, sin_i, cos_i, o_, cone_[std::size_t(p)]);
}

chiang::Cone ChiangPoint::cone(int p) const {
    return chiang::Cone(cone_[std::size_t(p)], lobes_->longitudinal_[std::size_t(p)]);
}

Rgb ChiangPoint::albedo() const {
    const double h = double(hit().h);
    // Cycles 4.x adds the Fresnel factor; 3.4 (whose tilt is on θ_i) has the absorption alone.
    const double f = lobes_->params_.tilt == ChiangTilt::Outgoing
                         ? fresnel_dielectric(o_.cos * std::sqrt(std::max(0.0, 1.0 - h * h)), lobes_->eta_)
                         : 0.0;
    const double scale = principled_hair::albedo_roughness_scale(lobes_->v_);
    auto channel = [&](int c) { return float(std::exp(-std::sqrt(lobes_->sigma_[std::size_t(c)]) * scale) + f); };
    return {channel(0), channel(1), channel(2)};
}

Rgb ChiangPoint::attenuation(int p) const { return p >= 0 && p < 4 ? to_rgb(a_[std::size_t(p)]) : Rgb{}; }

Rgb ChiangPoint::lobe_f(int p, Vec3 wi) const {
    if (p < 0 || p > 3) return {};
    const SinCos i = sin_cos_of(double(wi.x));
    const double azimuthal = p < 3 ? lobes_->azimuthal_.density(wrap_angle(relative_azimuth(wi) - shift_[std::size_t(p)]))
                                   : kInvTwoPi;
    return to_rgb(scaled(a_[std::size_t(p)], longitudinal(p, i.sin, i.cos) * azimuthal));
}

Rgb ChiangPoint::f(Vec3 wi) const {
    const SinCos i = sin_cos_of(double(wi.x));
    const double phi = relative_azimuth(wi);
    Channels sum{};
    for (int p = 0; p < 4; ++p) {
        double weight = longitudinal(p, i.sin, i.cos);
        weight *= p < 3 ? lobes_->azimuthal_.density(wrap_angle(phi - shift_[std::size_t(p)])) : kInvTwoPi;
        for (int c = 0; c < 3; ++c) sum[std::size_t(c)] += a_[std::size_t(p)][std::size_t(c)] * weight;
    }
    return to_rgb(sum);
}

float ChiangPoint::pdf(Vec3 wi) const {
    const SinCos i = sin_cos_of(double(wi.x));
    const double phi = relative_azimuth(wi);
    double density = 0;
    for (int p = 0; p < 4; ++p) {
        const double w = weight_[std::size_t(p)];
        if (w <= 0) continue;
        double term = w * cone(p).density(i.sin, i.cos);
        term *= p < 3 ? lobes_->azimuthal_.density(wrap_angle(phi - shift_[std::size_t(p)])) : kInvTwoPi;
        density += term;
    }
    return float(density);
}

Rgb ChiangPoint::f_and_pdf(Vec3 wi, float &pdf) const {
    const SinCos i = sin_cos_of(double(wi.x));
    const double phi = relative_azimuth(wi);
    const bool cones_tilted = lobes_->params_.tilt == ChiangTilt::Outgoing;
    Channels sum{};
    double density = 0;
    for (int p = 0; p < 4; ++p) {
        const double azimuthal =
            p < 3 ? lobes_->azimuthal_.density(wrap_angle(phi - shift_[std::size_t(p)])) : kInvTwoPi;
        const double w = weight_[std::size_t(p)];
        // tilted_longitudinal is the cone's density where the tilt is on θ_o, and for p = 3.
        const bool shared = cones_tilted || p == kLobeResidual;
        const double cone_density = (w > 0 || shared) ? cone(p).density(i.sin, i.cos) : 0.0;
        const double weight = (shared ? cone_density : longitudinal(p, i.sin, i.cos)) * azimuthal;
        for (int c = 0; c < 3; ++c) sum[std::size_t(c)] += a_[std::size_t(p)][std::size_t(c)] * weight;
        if (w > 0) {
            double term = w * cone_density;
            term *= azimuthal;
            density += term;
        }
    }
    pdf = float(density);
    return to_rgb(sum);
}

Vec3 ChiangPoint::draw(float u0, float u1, float u2, int &lobe) const {
    // Lobe from u2; what is left of u2 inside the chosen lobe's interval is reused for M_p.
    int last = 3;
    while (last > 0 && weight_[std::size_t(last)] <= 0) --last;
    double u = std::clamp(double(u2), 0.0, 1.0);
    int p = 0;
    while (p < last && u >= weight_[std::size_t(p)]) u -= weight_[std::size_t(p++)];
    const double u_longitudinal = std::clamp(u / weight_[std::size_t(p)], 0.0, 1.0);
    const double sin_theta_i = off_axis(float(cone(p).sample(u_longitudinal, u1)));
    const double phi = p < 3 ? shift_[std::size_t(p)] + lobes_->azimuthal_.sample(u0) : kTwoPi * double(u0);
    lobe = p;
    return direction(sin_theta_i, cos_from_sin(sin_theta_i), phi);
}

std::optional<DirectionSample> ChiangPoint::sample(float u0, float u1, float u2) const {
    DirectionSample result;
    result.wi = draw(u0, u1, u2, result.lobe);
    result.pdf = pdf(result.wi);
    if (!(result.pdf > 0.0f) || !std::isfinite(result.pdf)) return std::nullopt;
    return result;
}

std::optional<DirectionSample> ChiangPoint::sample_with_f(float u0, float u1, float u2, Rgb &f) const {
    DirectionSample result;
    result.wi = draw(u0, u1, u2, result.lobe);
    f = f_and_pdf(result.wi, result.pdf);
    if (!(result.pdf > 0.0f) || !std::isfinite(result.pdf)) return std::nullopt;
    return result;
}

// ---------------------------------------------------------------------------------------
// Far field: ½∫ A_p(h) N_p(φ − Φ(p, h)) dh with h = sin γ, so dh = cos γ dγ and the
// integrand is smooth up to the fiber's edges.
//
// Only N_p depends on φ. For one θ_o, the factors ½ w_j cos γ_j A_p(γ_j) and Φ(p, γ_j) at
// fixed Gauss–Legendre nodes γ_j are computed once, and each φ only sums logistics.
// |dΦ/dγ| <= 2, so in γ the logistic bump is at least s wide: panels of kFixedPanelPerScale·s
// resolve it. When s is so small that this needs too many nodes, the graded rule integrates
// around the bumps instead.

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
    // end values (Boost's safeguarded Newton).
    double solve(double a, double b, double target) const {
        if (p == 0) return std::clamp(-0.5 * target, a, b);  // Φ = −2γ
        const double f_a = value(a) - target, f_b = value(b) - target;
        if (f_a == 0.0) return a;
        if (f_b == 0.0) return b;
        std::uintmax_t iterations = 60;
        const double guess = std::clamp(a + (b - a) * f_a / (f_a - f_b), a, b);
        return boost::math::tools::newton_raphson_iterate(
            [&](double x) { return std::make_pair(value(x) - target, slope(x)); }, guess, a, b,
            std::numeric_limits<double>::digits - 4, iterations);
    }
};

// Where Φ(2, γ) turns (TRT's caustics): sin²γ = (4k² − 1)/(3k²), when k > 1/2.
double caustic_gamma(double k) { return std::asin(std::sqrt((4.0 * k * k - 1.0) / (3.0 * k * k))); }

// The edges of the pieces of [−π/2, π/2] on which Φ(p, γ) is monotone: one piece, or three
// for TRT when the caustic exists (k > 1/2). Returns the number of edges.
int monotone_pieces(int p, double k, double cuts[4]) {
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

}  // namespace

ChiangFarField::ChiangFarField(const ChiangFiber &fiber, Vec3 wo)
    : fiber_(&fiber), o_(sin_cos_of(double(wo.x))), k_(bravais_ratio(o_, fiber.lobes_.eta_)),
      path_scale_(chord_scale(o_, fiber.lobes_.eta_)) {
    const double r = std::sqrt(double(wo.y) * wo.y + double(wo.z) * wo.z);
    cos_phi_o_ = r > 0 ? wo.y / r : 0.0;
    sin_phi_o_ = r > 0 ? wo.z / r : -1.0;
    const int panels = fiber.fixed_panels_ > 0 ? fiber.fixed_panels_ : 6;  // the residual is smooth
    const int n = kPanelPoints * panels;
    node_count_ = fiber.fixed_panels_ > 0 ? n : 0;
    shift_.assign(std::size_t(3 * node_count_), 0.0);
    weight_.assign(std::size_t(9 * node_count_), 0.0);
    const GaussLegendre &gl = GaussLegendre::rule(kPanelPoints);
    const double panel_width = kPi / panels;
    int j = 0;
    std::array<Channels, 4> a;
    double gamma_o = 0, gamma_t = 0;
    for (int panel = 0; panel < panels; ++panel) {
        gl.for_each(-kHalfPi + panel * panel_width, -kHalfPi + (panel + 1) * panel_width, [&](double gamma, double w) {
            const double weight = 0.5 * w * std::cos(gamma);
            fiber.lobes_.attenuation_at(o_.cos, k_, path_scale_, std::sin(gamma), a, gamma_o, gamma_t);
            for (int c = 0; c < 3; ++c) residual_[std::size_t(c)] += weight * a[3][std::size_t(c)];
            if (node_count_ > 0) {
                for (int p = 0; p < 3; ++p) {
                    const std::size_t index = std::size_t(p * n + j);
                    shift_[index] = wrap_angle(chiang::azimuthal_shift(p, gamma_o, gamma_t));
                    for (int c = 0; c < 3; ++c) {
                        weight_[3 * index + std::size_t(c)] = weight * a[std::size_t(p)][std::size_t(c)];
                        total_weight_[std::size_t(p)][std::size_t(c)] += weight * a[std::size_t(p)][std::size_t(c)];
                    }
                }
            }
            ++j;
        });
    }
}

double ChiangFarField::longitudinal(int p, double theta_i) const {
    return fiber_->lobe_longitudinal(p, std::sin(theta_i), o_.sin);
}

Rgb ChiangFarField::azimuthal(int p, double phi) const {
    if (p < 0 || p > 3) return {};
    if (p == kLobeResidual) return to_rgb(scaled(residual_, kInvTwoPi));
    phi = wrap_angle(phi);
    return to_rgb(node_count_ > 0 ? azimuthal_fixed(p, phi) : azimuthal_graded(p, phi));
}

Rgb ChiangFarField::lobe_f_cos(int p, Vec3 wi) const {
    if (p < 0 || p > 3) return {};
    const SinCos i = sin_cos_of(double(wi.x));
    const double longitudinal = fiber_->lobe_longitudinal(p, i.sin, o_.sin);
    if (p == kLobeResidual) return to_rgb(scaled(residual_, longitudinal * kInvTwoPi));
    const double phi = std::atan2(wi.z * cos_phi_o_ - wi.y * sin_phi_o_, wi.y * cos_phi_o_ + wi.z * sin_phi_o_);
    return to_rgb(scaled(node_count_ > 0 ? azimuthal_fixed(p, phi) : azimuthal_graded(p, phi), longitudinal));
}

std::array<double, 3> ChiangFarField::azimuthal_fixed(int p, double phi) const {
    const ChiangFiber &fiber = *fiber_;
    const int n = node_count_;
    const double *shift = shift_.data() + std::size_t(p * n);
    const double *weight = weight_.data() + std::size_t(3 * p * n);
    const double inv_s = 1.0 / fiber.lobes_.s_;
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
    const double scale = fiber.lobes_.azimuthal_.norm() * inv_s;
    Channels result{sum[0] * scale, sum[1] * scale, sum[2] * scale};

    // N has a kink where φ − Φ wraps through ±π, which the fixed nodes straddle: its slope
    // jumps by 2N(π)·tanh(π/2s)/s there, times |Φ'| <= 2 in γ. The error of a panel of width
    // H across it is of order that jump·H²·(the panel's weight); when that is not negligible
    // next to the result (φ far from every peak of the lobe), the panels holding a kink are
    // integrated again, split at it.
    const int panels = fiber.fixed_panels_;
    const double panel_width = kPi / panels;
    const double kink_slope_jump =
        4.0 * logistic(kPi, fiber.lobes_.s_) * fiber.lobes_.azimuthal_.norm() * std::tanh(kHalfPi / fiber.lobes_.s_) * inv_s;
    bool negligible = true;
    for (int c = 0; c < 3; ++c) {
        const double kink_error = kink_slope_jump * panel_width * panel_width * total_weight_[std::size_t(p)][std::size_t(c)];
        if (kink_error > 1e-6 * result[std::size_t(c)]) negligible = false;
    }
    if (negligible) return result;

    const Deflection deflection{p, k_};
    double cuts[4];
    const int cut_count = monotone_pieces(p, k_, cuts);
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
        const Channels fixed = fixed_panel(p, phi, panel);
        const Channels left = exact_panel(p, phi, start, kink);
        const Channels right = exact_panel(p, phi, kink, end);
        for (int c = 0; c < 3; ++c) result[std::size_t(c)] += left[std::size_t(c)] + right[std::size_t(c)] - fixed[std::size_t(c)];
    }
    return result;
}

std::array<double, 3> ChiangFarField::fixed_panel(int p, double phi, int panel) const {
    const int n = node_count_;
    Channels sum{};
    for (int j = kPanelPoints * panel; j < kPanelPoints * (panel + 1); ++j) {
        const std::size_t index = std::size_t(p * n + j);
        const double bump = fiber_->lobes_.azimuthal_.density(wrap_angle(phi - shift_[index]));
        for (int c = 0; c < 3; ++c) sum[std::size_t(c)] += weight_[3 * index + std::size_t(c)] * bump;
    }
    return sum;
}

std::array<double, 3> ChiangFarField::exact_panel(int p, double phi, double a, double b) const {
    Channels sum{};
    if (!(b > a)) return sum;
    std::array<Channels, 4> att;
    double gamma_o = 0, gamma_t = 0;
    GaussLegendre::rule(kPanelPoints).for_each(a, b, [&](double gamma, double w) {
        fiber_->lobes_.attenuation_at(o_.cos, k_, path_scale_, std::sin(gamma), att, gamma_o, gamma_t);
        const double shift = chiang::azimuthal_shift(p, gamma_o, gamma_t);
        const double weight = 0.5 * w * std::cos(gamma) * fiber_->lobes_.azimuthal_.density(wrap_angle(phi - shift));
        for (int c = 0; c < 3; ++c) sum[std::size_t(c)] += weight * att[std::size_t(p)][std::size_t(c)];
    });
    return sum;
}

// The graded rule. The γ range is cut where Φ turns (TRT's caustics), at the peaks
// (Φ ≡ φ mod 2π) and where φ − Φ wraps through ±π; on each resulting interval N is monotone,
// and Gauss–Legendre panels grow geometrically from its larger end, starting at the bump's
// half-width.
std::array<double, 3> ChiangFarField::azimuthal_graded(int p, double phi) const {
    const ChiangFiber &fiber = *fiber_;
    const Deflection deflection{p, k_};
    const double s = fiber.lobes_.s_;
    const GaussLegendre &gl = GaussLegendre::rule(kPanelPoints);
    std::array<Channels, 4> att;
    double gamma_o = 0, gamma_t = 0;

    // A_p(γ) cos γ N(φ − Φ(γ)) per channel.
    auto integrand = [&](double gamma, Channels &out) {
        fiber.lobes_.attenuation_at(o_.cos, k_, path_scale_, std::sin(gamma), att, gamma_o, gamma_t);
        const double shift = chiang::azimuthal_shift(p, gamma_o, gamma_t);
        const double common = std::cos(gamma) * logistic(wrap_angle(phi - shift), s) * fiber.lobes_.azimuthal_.norm();
        for (int c = 0; c < 3; ++c) out[std::size_t(c)] = att[std::size_t(p)][std::size_t(c)] * common;
    };
    auto logistic_at = [&](double gamma) {
        return logistic(wrap_angle(phi - deflection.value(gamma)), s) * fiber.lobes_.azimuthal_.norm();
    };

    double cuts[4];
    const int cut_count = monotone_pieces(p, k_, cuts);
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
        for (int i = 1; i < point_count; ++i)  // insertion sort of at most 4 points
            for (int j = i; j > 0 && points[j] < points[j - 1]; --j) std::swap(points[j], points[j - 1]);

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
                gl.for_each(position, position + panel_width, [&](double x, double w) {
                    Channels value;
                    integrand(start + direction * x, value);
                    for (int ch = 0; ch < 3; ++ch) accumulated[std::size_t(ch)] += w * value[std::size_t(ch)];
                });
                position += panel_width;
                if (++panel >= 2) width *= 2.0;  // panels w, w, 2w, 4w, ...
                if (position < length) {
                    // A_p <= 1 and cos γ <= 1, and N only decreases from here on.
                    const double bound = (length - position) * logistic_at(start + direction * position);
                    const double smallest = std::min({accumulated[0], accumulated[1], accumulated[2]});
                    if (bound <= kTailFraction * smallest) break;
                }
            }
            for (int ch = 0; ch < 3; ++ch) total[std::size_t(ch)] += accumulated[std::size_t(ch)];
        }
    }
    return scaled(total, 0.5);
}

std::unique_ptr<const FarFieldView> ChiangFiber::view(Vec3 wo) const {
    return std::make_unique<ChiangFarField>(*this, wo);
}

Rgb ChiangFiber::lobe_f_cos(int p, Vec3 wi, Vec3 wo) const { return ChiangFarField(*this, wo).lobe_f_cos(p, wi); }

Rgb ChiangFiber::f_cos(Vec3 wi, Vec3 wo) const {
    const ChiangFarField view(*this, wo);
    Rgb sum;
    for (int p = 0; p < 4; ++p) sum += view.lobe_f_cos(p, wi);
    return sum;
}

}  // namespace hairis
