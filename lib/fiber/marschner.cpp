#include "fiber/marschner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/frame.h"

// Decisions where Marschner 2003 (and the implementations that followed it) are ambiguous:
//
// 1. θ_t, the longitudinal refraction angle of σ'_a = σ_a / cos θ_t, is taken at θ_d:
//    sin θ_t = sin θ_d / η. θ_d is the angle the far-field model uses for everything else
//    (Bravais indices, 1/cos² θ_d), and it keeps S symmetric under ω_i ↔ ω_o.
// 2. T = exp(−2σ'_a(1 + cos 2γ_t)) exactly as printed, with σ_a per unit radius. (The printed
//    exponent is 2σ'_a·(2 + 2 cos 2γ_t)/2 with 2 + 2 cos 2γ_t = (2 cos γ_t)², the squared
//    chord, where the geometric chord of a unit circle is 2 cos γ_t; we keep the paper's
//    formula, as the seed's source does. At h = 0 one segment attenuates by exp(−4σ'_a).)
// 3. The roots use Marschner's cubic; dφ/dh in N_p is the derivative of that same cubic,
//    (dφ/dγ_i)/cos γ_i, so that ∫N_p dφ = ½∫A dh holds exactly. A(p, h) uses the exact
//    γ_t = asin(h/η') (the cubic only locates the paths).
// 4. Eccentricity: η* replaces η everywhere in the TRT lobe (Bravais indices, roots, caustic,
//    Fresnel factors, γ_t and θ_t), i.e. TRT is computed for a circular fiber of index η*.
//    R and TT use η.
// 5. TRT caustic: h_c, φ_c and d²φ/dh² come from the cubic (its caustic exists iff η*' < 2,
//    like the exact one). Below 2: t = 1, Δh = min(Δh_M, 2·sqrt(2 w_c / |d²φ/dh²(h_c)|)).
//    At or above 2 (caustics merged): h_c = φ_c = 0, Δh = Δh_M and t = 1 − smoothstep(2,
//    2 + Δη', η*') — the glint FADES OUT over Δη' past the merge. This is continuous at η*' = 2
//    and suppresses the (non-integrable) merged caustic there; the other reading,
//    t = smoothstep(2, 2 + Δη', η*'), would jump from 1 to 0 at η*' = 2.
//    N_TRT = N_raw·(1 − t·ĝ(φ − φ_c))·(1 − t·ĝ(φ + φ_c)) + t·k_G·A(2, h_c)·Δh·(g(φ − φ_c) +
//    g(φ + φ_c)), g the normalized Gaussian of std w_c, ĝ = g/g(0), arguments wrapped.
// 6. Numerical floors: cos θ_d ≥ 1e-3 (S ∝ 1/cos² θ_d is singular when light and view look
//    along the fiber from opposite ends) and |dφ/dγ_i| ≥ 1e-5 (caustics of the plain sum).
//    Both only act where the model itself is singular; they keep every value finite.

namespace hairis {

namespace {

constexpr double kMinCosThetaD = 1e-3;
constexpr double kMinSlope = 1e-5;
constexpr double kSqrtTwoPi = 2.50662827463100050242;
constexpr double kPi3 = kPi * kPi * kPi;
// M_p is skipped in f_cos beyond this many β from its peak (relative size < e^{-72}).
constexpr double kLongitudinalCutoff = 12.0;

// An RGB triple in double precision for the internal arithmetic.
struct Rgbd {
    double v[3] = {0, 0, 0};

    Rgbd() = default;
    explicit Rgbd(double s) : v{s, s, s} {}

    Rgbd &operator+=(const Rgbd &o) {
        for (int i = 0; i < 3; ++i) v[i] += o.v[i];
        return *this;
    }
    Rgbd operator*(double s) const {
        Rgbd r;
        for (int i = 0; i < 3; ++i) r.v[i] = v[i] * s;
        return r;
    }
    Rgb to_rgb() const { return {float(v[0]), float(v[1]), float(v[2])}; }
};

double gaussian(double sigma, double x) {
    return std::exp(-0.5 * sqr(x / sigma)) / (sigma * kSqrtTwoPi);
}

double smoothstep(double edge0, double edge1, double x) {
    const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// fresnel_bravais() from the sine and cosine of the incidence angle (no trigonometry).
double polarized_reflectance(double eta, double sin_i, double cos_i, bool parallel) {
    const double sin_t = sin_i / eta;
    if (std::fabs(sin_t) >= 1.0) return 1.0;
    const double cos_t = std::sqrt(1.0 - sin_t * sin_t);
    const double r = parallel ? (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
                              : (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return r * r;
}

double bravais_reflectance(double eta_perp, double eta_par, double sin_i, double cos_i) {
    return 0.5 * (polarized_reflectance(eta_perp, sin_i, cos_i, false) +
                  polarized_reflectance(eta_par, sin_i, cos_i, true));
}

// The 2D problem in the normal plane: one index of refraction at one θ_d.
struct Section {
    double eta_perp = 1, eta_par = 1;  // Bravais η', η''
    double c = 0;                      // asin(1/η')
    double sigma_prime[3] = {0, 0, 0};  // σ_a / cos θ_t
};

Section make_section(double eta, double theta_d, const Rgb &sigma_a) {
    Section x;
    const double s = std::sin(theta_d);
    const double cos_d = std::max(std::fabs(std::cos(theta_d)), kMinCosThetaD);
    const double root = std::sqrt(eta * eta - s * s);  // η > 1 ≥ |sin θ_d|
    x.eta_perp = root / cos_d;
    x.eta_par = eta * eta * cos_d / root;
    x.c = std::asin(std::min(1.0, 1.0 / x.eta_perp));
    const double cos_t = std::sqrt(1.0 - sqr(s / eta));
    for (int i = 0; i < 3; ++i) x.sigma_prime[i] = double(sigma_a[i]) / cos_t;
    return x;
}

// A(p, h) for one section.
Rgbd attenuation_in(int p, double h, const Section &x) {
    h = std::clamp(h, -1.0, 1.0);
    const double cos_gi = std::sqrt(std::max(0.0, 1.0 - h * h));
    const double f_out = bravais_reflectance(x.eta_perp, x.eta_par, h, cos_gi);
    if (p == 0) return Rgbd(f_out);
    const double sin_gt = h / x.eta_perp;
    const double cos2_gt = std::max(0.0, 1.0 - sin_gt * sin_gt);
    double scale = sqr(1.0 - f_out);
    if (p > 1) {
        const double f_in =
            bravais_reflectance(1.0 / x.eta_perp, 1.0 / x.eta_par, sin_gt, std::sqrt(cos2_gt));
        for (int bounce = 1; bounce < p; ++bounce) scale *= f_in;
    }
    // T^p = exp(−2σ'(1 + cos 2γ_t))^p = exp(−4pσ' cos² γ_t).
    Rgbd a;
    for (int i = 0; i < 3; ++i) a.v[i] = scale * std::exp(-4.0 * p * x.sigma_prime[i] * cos2_gt);
    return a;
}

// Σ_roots A(p, h)/|2 dφ/dh| with dφ/dh = (dφ/dγ)/cos γ.
Rgbd azimuthal_in(int p, const Section &x, double phi) {
    double roots[marschner::kMaxRoots];
    const int n = marschner::solve_exit_azimuth(p, x.c, phi, roots);
    Rgbd sum;
    for (int r = 0; r < n; ++r) {
        const double gamma = roots[r];
        const double cos_g = std::cos(gamma);
        if (!(cos_g > 0.0)) continue;  // grazing offsets carry no energy
        const double slope =
            std::max(std::fabs(marschner::exit_azimuth_slope(p, x.c, gamma)), kMinSlope);
        sum += attenuation_in(p, std::sin(gamma), x) * (cos_g / (2.0 * slope));
    }
    return sum;
}

MarschnerCaustic caustic_in(const Section &x, const MarschnerParams &params) {
    MarschnerCaustic k;
    k.eta_perp = x.eta_perp;
    const double a = 12.0 * x.c / kPi - 2.0;  // dφ/dγ at γ = 0 for p = 2
    const double b = 16.0 * x.c / kPi3;
    if (a > 0.0) {
        // dφ/dγ = a − 3bγ² = 0: the fold of the cubic.
        const double gamma_c = std::sqrt(a / (3.0 * b));
        const double cos_c = std::cos(gamma_c);
        k.exists = true;
        k.h_c = std::sin(gamma_c);
        k.phi_c = std::fabs(wrap_angle(a * gamma_c - b * gamma_c * gamma_c * gamma_c));
        // d²φ/dh² = (d²φ/dγ²)/cos² γ where dφ/dγ = 0.
        const double d2 = 6.0 * b * gamma_c / (cos_c * cos_c);
        k.delta_h = d2 > 0.0 ? std::min(params.caustic_limit,
                                        2.0 * std::sqrt(2.0 * params.caustic_width / d2))
                             : params.caustic_limit;
        k.t = 1.0;
    } else {
        k.delta_h = params.caustic_limit;
        k.t = 1.0 - smoothstep(2.0, 2.0 + params.caustic_fade, x.eta_perp);
    }
    return k;
}

Rgbd azimuthal_trt(const Section &x, double phi, const MarschnerParams &params) {
    const Rgbd raw = azimuthal_in(2, x, phi);
    const MarschnerCaustic k = caustic_in(x, params);
    if (!(k.t > 0.0)) return raw;
    const double w = params.caustic_width;
    const double e1 = std::exp(-0.5 * sqr(wrap_angle(phi - k.phi_c) / w));  // g / g(0)
    const double e2 = std::exp(-0.5 * sqr(wrap_angle(phi + k.phi_c) / w));
    Rgbd result = raw * ((1.0 - k.t * e1) * (1.0 - k.t * e2));
    const double glint = k.t * params.glint_scale * k.delta_h * (e1 + e2) / (w * kSqrtTwoPi);
    if (glint > 1e-30) result += attenuation_in(2, k.h_c, x) * glint;  // else negligible
    return result;
}

// The angles of a direction pair; false for non-finite or zero input.
struct DirectionPair {
    double theta_i = 0, theta_o = 0;
    double cos_theta_i = 0;
    double phi = 0;          // φ_i − φ_o wrapped to [−π, π]
    double cos_two_phi_h = 1;  // cos(φ_i + φ_o)
};

bool decompose(Vec3 wi, Vec3 wo, DirectionPair &d) {
    const double xi = wi.x, yi = wi.y, zi = wi.z, xo = wo.x, yo = wo.y, zo = wo.z;
    if (!std::isfinite(xi + yi + zi + xo + yo + zo)) return false;
    // Float inputs squared in double cannot overflow: no need for hypot.
    const double ri = std::sqrt(yi * yi + zi * zi), ro = std::sqrt(yo * yo + zo * zo);
    const double li = std::sqrt(xi * xi + ri * ri), lo = std::sqrt(xo * xo + ro * ro);
    if (!(li > 0.0) || !(lo > 0.0)) return false;
    d.theta_i = std::atan2(xi, ri);
    d.theta_o = std::atan2(xo, ro);
    d.cos_theta_i = std::min(1.0, ri / li);
    const double phi_i = std::atan2(zi, yi), phi_o = std::atan2(zo, yo);
    d.phi = wrap_angle(phi_i - phi_o);
    d.cos_two_phi_h = std::cos(phi_i + phi_o);
    return true;
}

double lobe_alpha(const MarschnerParams &m, int p) {
    return p == kLobeR ? m.alpha_r : p == kLobeTT ? m.alpha_tt : m.alpha_trt;
}

double lobe_beta(const MarschnerParams &m, int p) {
    return p == kLobeR ? m.beta_r : p == kLobeTT ? m.beta_tt : m.beta_trt;
}

// Whether M_p(θ_h) is negligible (beyond kLongitudinalCutoff·β_p from its peak).
bool outside_lobe(const MarschnerParams &m, int p, double theta_h) {
    return std::fabs(theta_h - lobe_alpha(m, p)) > kLongitudinalCutoff * lobe_beta(m, p);
}

// Refuses values outside (lo, hi] (and non-finite ones), naming the parameter and range.
Status in_half_open(const char *name, double value, double lo, double hi) {
    if (std::isfinite(value) && value > lo && value <= hi) return std::nullopt;
    std::ostringstream out;
    out.precision(9);
    out << name << " must be in (" << lo << ", " << hi << "] (got " << value << ")";
    return Error{out.str()};
}

}  // namespace

// ---- marschner:: the cubic ------------------------------------------------------------------

namespace marschner {

double exit_azimuth(int p, double c, double gamma_i) {
    const double a = 6.0 * p * c / kPi - 2.0, b = 8.0 * p * c / kPi3;
    return (a - b * gamma_i * gamma_i) * gamma_i + p * kPi;
}

double exit_azimuth_slope(int p, double c, double gamma_i) {
    const double a = 6.0 * p * c / kPi - 2.0, b = 8.0 * p * c / kPi3;
    return a - 3.0 * b * gamma_i * gamma_i;
}

namespace {

// The root of g(γ) = aγ − bγ³ = y on [lo, hi], where g is monotone and g(lo), g(hi) bracket y:
// Newton steps, falling back to bisection whenever a step leaves the bracket.
double monotone_root(double a, double b, double y, double lo, double hi, double f_lo,
                     double f_hi) {
    if (f_lo == 0.0) return lo;
    if (f_hi == 0.0) return hi;
    double x = lo - f_lo * (hi - lo) / (f_hi - f_lo);  // regula falsi start
    for (int iteration = 0; iteration < 100; ++iteration) {
        const double fx = (a - b * x * x) * x - y;
        if (fx == 0.0) return x;
        if ((fx < 0.0) == (f_lo < 0.0)) {
            lo = x;
            f_lo = fx;
        } else {
            hi = x;
            f_hi = fx;
        }
        const double df = a - 3.0 * b * x * x;
        double next = df != 0.0 ? x - fx / df : 0.5 * (lo + hi);
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        if (std::fabs(next - x) <= 1e-14 * (1.0 + std::fabs(x)) || hi - lo <= 1e-15) return next;
        x = next;
    }
    return x;
}

}  // namespace

int solve_exit_azimuth(int p, double c, double phi, double roots[kMaxRoots]) {
    if (!std::isfinite(phi) || !(c >= 0.0 && c <= kHalfPi)) return 0;
    phi = wrap_angle(phi);  // keeps the branch count k small
    const double a = 6.0 * p * c / kPi - 2.0, b = 8.0 * p * c / kPi3;
    // Break [−π/2, π/2] into pieces on which g(γ) = aγ − bγ³ is monotone.
    double breaks[4];
    int count = 0;
    breaks[count++] = -kHalfPi;
    if (a > 0.0 && b > 0.0) {
        const double g_star = std::sqrt(a / (3.0 * b));
        if (g_star < kHalfPi) {
            breaks[count++] = -g_star;
            breaks[count++] = g_star;
        }
    }
    breaks[count++] = kHalfPi;
    double values[4];
    double g_min = std::numeric_limits<double>::infinity();
    double g_max = -g_min;
    for (int i = 0; i < count; ++i) {
        values[i] = (a - b * breaks[i] * breaks[i]) * breaks[i];
        g_min = std::min(g_min, values[i]);
        g_max = std::max(g_max, values[i]);
    }
    // Targets y = φ − pπ + 2πk within the range of g.
    const double base = phi - p * kPi;
    const long k_lo = long(std::ceil((g_min - base) / kTwoPi));
    const long k_hi = long(std::floor((g_max - base) / kTwoPi));
    int n = 0;
    for (long k = k_lo; k <= k_hi; ++k) {
        const double y = base + kTwoPi * double(k);
        for (int s = 0; s + 1 < count; ++s) {
            const double v0 = values[s], v1 = values[s + 1];
            if (y < std::min(v0, v1) || y > std::max(v0, v1)) continue;
            // An interior break point belongs to the piece on its right only.
            if (s + 2 < count && y == v1) continue;
            if (n == kMaxRoots) return n;
            roots[n++] = monotone_root(a, b, y, breaks[s], breaks[s + 1], v0 - y, v1 - y);
        }
    }
    return n;
}

}  // namespace marschner

// ---- MarschnerParams ----------------------------------------------------------------------

MarschnerParams MarschnerParams::blonde() {
    MarschnerParams p;
    p.sigma_a = Rgb{0.15f, 0.20f, 0.30f};
    return p;
}

MarschnerParams MarschnerParams::brunette() {
    MarschnerParams p;
    p.sigma_a = Rgb{0.432f, 0.612f, 0.98f};
    return p;
}

// ---- MarschnerFiber -----------------------------------------------------------------------

Expected<MarschnerFiber> MarschnerFiber::create(const MarschnerParams &p) {
    const double max_alpha = radians(30.0);
    const double max_beta = radians(45.0);
    const double min_eccentricity = std::sqrt(0.5);  // keeps η*_1 = 2(η−1)a² − η + 2 above 1
    const Status status = first_error(
        in_half_open("eta", p.eta, 1.0, 4.0),
        check::non_negative("sigma_a.r", p.sigma_a.r),
        check::non_negative("sigma_a.g", p.sigma_a.g),
        check::non_negative("sigma_a.b", p.sigma_a.b),
        check::in_range("alpha_r", p.alpha_r, -max_alpha, max_alpha),
        check::in_range("alpha_tt", p.alpha_tt, -max_alpha, max_alpha),
        check::in_range("alpha_trt", p.alpha_trt, -max_alpha, max_alpha),
        in_half_open("beta_r", p.beta_r, 0.0, max_beta),
        in_half_open("beta_tt", p.beta_tt, 0.0, max_beta),
        in_half_open("beta_trt", p.beta_trt, 0.0, max_beta),
        in_half_open("eccentricity", p.eccentricity, min_eccentricity, 1.0),
        check::in_range("glint_scale", p.glint_scale, 0.0, 10.0),
        in_half_open("caustic_width", p.caustic_width, 0.0, radians(45.0)),
        in_half_open("caustic_fade", p.caustic_fade, 0.0, 1.0),
        check::in_range("caustic_limit", p.caustic_limit, 0.0, 1.0));
    if (status) return *status;
    return MarschnerFiber(p);
}

MarschnerFiber::MarschnerFiber(const MarschnerParams &params) : params_(params) {
    const double eta = params_.eta, a2 = sqr(params_.eccentricity);
    eta_star_1_ = 2.0 * (eta - 1.0) * a2 - eta + 2.0;
    eta_star_2_ = 2.0 * (eta - 1.0) / a2 - eta + 2.0;
}

double MarschnerFiber::eta_star(double phi_h) const {
    return eta_star_from_cos(std::cos(2.0 * phi_h));
}

double MarschnerFiber::eta_star_from_cos(double cos_two_phi_h) const {
    if (params_.eccentricity == 1.0) return params_.eta;
    return 0.5 * ((eta_star_1_ + eta_star_2_) + cos_two_phi_h * (eta_star_1_ - eta_star_2_));
}

LobeShape MarschnerFiber::lobe_shape(int p) const {
    switch (p) {
        case kLobeR: return {float(params_.alpha_r), float(params_.beta_r)};
        case kLobeTT: return {float(params_.alpha_tt), float(params_.beta_tt)};
        case kLobeTRT: return {float(params_.alpha_trt), float(params_.beta_trt)};
        default: return {};
    }
}

double MarschnerFiber::longitudinal(int p, double theta_h) const {
    if (p < 0 || p > 2) return 0.0;
    return gaussian(lobe_beta(params_, p), theta_h - lobe_alpha(params_, p));
}

Rgb MarschnerFiber::attenuation(int p, double h, double theta_d, double phi_h) const {
    if (p < 0 || p > 2) return {};
    const double eta = p == kLobeTRT ? eta_star(phi_h) : params_.eta;
    return attenuation_in(p, h, make_section(eta, theta_d, params_.sigma_a)).to_rgb();
}

Rgb MarschnerFiber::azimuthal_without_caustic(int p, double theta_d, double phi,
                                              double phi_h) const {
    if (p < 0 || p > 2) return {};
    const double eta = p == kLobeTRT ? eta_star(phi_h) : params_.eta;
    return azimuthal_in(p, make_section(eta, theta_d, params_.sigma_a), wrap_angle(phi)).to_rgb();
}

Rgb MarschnerFiber::azimuthal(int p, double theta_d, double phi, double phi_h) const {
    if (p != kLobeTRT) return azimuthal_without_caustic(p, theta_d, phi, phi_h);
    const Section x = make_section(eta_star(phi_h), theta_d, params_.sigma_a);
    return azimuthal_trt(x, wrap_angle(phi), params_).to_rgb();
}

MarschnerCaustic MarschnerFiber::trt_caustic(double theta_d, double phi_h) const {
    return caustic_in(make_section(eta_star(phi_h), theta_d, params_.sigma_a), params_);
}

Rgb MarschnerFiber::scattering(int p, double theta_i, double theta_o, double phi,
                               double phi_h) const {
    if (p < 0 || p > 2) return {};
    const double theta_d = 0.5 * (theta_o - theta_i);
    const double cos_d = std::max(std::fabs(std::cos(theta_d)), kMinCosThetaD);
    const Rgb n = azimuthal(p, theta_d, phi, phi_h);
    return n * float(longitudinal(p, 0.5 * (theta_i + theta_o)) / (cos_d * cos_d));
}

Rgb MarschnerFiber::lobe_f_cos(int p, Vec3 wi, Vec3 wo) const {
    if (p < 0 || p > 2) return {};
    DirectionPair d;
    if (!decompose(wi, wo, d)) return {};
    const double theta_h = 0.5 * (d.theta_i + d.theta_o);
    const double theta_d = 0.5 * (d.theta_o - d.theta_i);
    if (outside_lobe(params_, p, theta_h)) return {};
    const double eta = p == kLobeTRT ? eta_star_from_cos(d.cos_two_phi_h) : params_.eta;
    const Section x = make_section(eta, theta_d, params_.sigma_a);
    const Rgbd n = p == kLobeTRT ? azimuthal_trt(x, d.phi, params_) : azimuthal_in(p, x, d.phi);
    const double cos_d = std::max(std::fabs(std::cos(theta_d)), kMinCosThetaD);
    return (n * (longitudinal(p, theta_h) * d.cos_theta_i / (cos_d * cos_d))).to_rgb();
}

Rgb MarschnerFiber::f_cos(Vec3 wi, Vec3 wo) const {
    DirectionPair d;
    if (!decompose(wi, wo, d)) return {};
    const double theta_h = 0.5 * (d.theta_i + d.theta_o);
    const double theta_d = 0.5 * (d.theta_o - d.theta_i);
    Rgbd sum;
    bool have_section = false;
    Section x;
    for (int p = kLobeR; p <= kLobeTT; ++p) {
        if (outside_lobe(params_, p, theta_h)) continue;
        if (!have_section) {
            x = make_section(params_.eta, theta_d, params_.sigma_a);
            have_section = true;
        }
        sum += azimuthal_in(p, x, d.phi) * longitudinal(p, theta_h);
    }
    if (!outside_lobe(params_, kLobeTRT, theta_h)) {
        if (params_.eccentricity != 1.0 || !have_section)
            x = make_section(eta_star_from_cos(d.cos_two_phi_h), theta_d, params_.sigma_a);
        sum += azimuthal_trt(x, d.phi, params_) * longitudinal(kLobeTRT, theta_h);
    }
    const double cos_d = std::max(std::fabs(std::cos(theta_d)), kMinCosThetaD);
    return (sum * (d.cos_theta_i / (cos_d * cos_d))).to_rgb();
}

}  // namespace hairis
