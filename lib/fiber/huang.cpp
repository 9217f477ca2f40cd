#include "fiber/huang.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>

#include "core/quadrature.h"
#include "fiber/chiang.h"
#include "fiber/fresnel.h"
#include "fiber/ggx.h"
#include "fiber/ggx_glass_albedo.h"

namespace hairis {

namespace {

using Colour = std::array<double, 3>;

constexpr double kTirSlack = 1e-5;     // Cycles' tolerance in its exit TIR tests
constexpr double kUClamp = 0.999;      // |h/R| limit of the integration interval (§6 step 5)
constexpr double kRStep = 0.7;         // Simpson step / α for R
constexpr double kResidualStep = 0.8;  // ... for TT, TRT, TRRT+

Colour colour_of(Rgb c) { return {c.r, c.g, c.b}; }
Rgb rgb_of(const Colour &c) { return {float(c[0]), float(c[1]), float(c[2])}; }

double cos_theta(Vec3d w) { return std::sqrt(w.x * w.x + w.z * w.z); }
double dir_phi(Vec3d w) { return std::atan2(w.x, w.z); }

// The cross-section geometry of §3 for aspect ratio b (circular when b == 1).
struct Ellipse {
    double b = 1, e2 = 0;
    bool circular() const { return b == 1.0; }
    // Φ(γ): azimuth of the outward normal at P(γ).
    double phi_of(double gamma) const {
        return circular() ? gamma : std::atan2(b * std::sin(gamma), std::cos(gamma));
    }
    // Γ(φ), the inverse of Φ.
    double gamma_of(double phi) const {
        return circular() ? phi : std::atan2(std::sin(phi), b * std::cos(phi));
    }
    // n(τ', γ): the normal at P(γ) tilted longitudinally by τ'.
    Vec3d normal(double tilt, double gamma) const {
        double sp = std::sin(gamma), cp = std::cos(gamma);
        if (!circular()) {
            const double x = b * sp, z = cp, len = std::hypot(x, z);
            sp = x / len;
            cp = z / len;
        }
        const double ct = std::cos(tilt);
        return {sp * ct, std::sin(tilt), cp * ct};
    }
    // n(τ', γ) and n(0, γ) from one sine and cosine of γ, with cos τ' and sin τ' given: the
    // same values as normal(τ', γ) and normal(0, γ).
    void normals(double cos_tilt, double sin_tilt, double gamma, Vec3d &tilted, Vec3d &untilted) const {
        double sp = std::sin(gamma), cp = std::cos(gamma);
        if (!circular()) {
            const double x = b * sp, z = cp, len = std::hypot(x, z);
            sp = x / len;
            cp = z / len;
        }
        tilted = {sp * cos_tilt, sin_tilt, cp * cos_tilt};
        untilted = {sp, 0.0, cp};
    }
    Vec3d point(double gamma) const { return {std::sin(gamma), 0.0, b * std::cos(gamma)}; }
    double arc(double gamma) const {
        return e2 == 0.0 ? 1.0 : std::sqrt(1.0 - e2 * std::sin(gamma) * std::sin(gamma));
    }
};

bool visible(Vec3d p, Vec3d q, Vec3d m, Vec3d h) {
    return dot(p, h) > 0.0 && dot(p, m) > 0.0 && dot(q, h) > 0.0 && dot(q, m) > 0.0;
}
bool visible(Vec3d p, Vec3d m, Vec3d h) { return dot(p, h) > 0.0 && dot(p, m) > 0.0; }

double fresnel(double c, double eta) { return fresnel_dielectric(std::fabs(c), eta); }

// TRRT+'s geometric series of §6.2: T R² T̄ A³ / (1 − A(1 − T̄)), T̄ = max(1 − R, 1e-5).
double residual_term(double t, double r, double a) {
    const double t_avg = std::max(1.0 - r, 1e-5);
    return t * r * r * t_avg * a * a * a / (1.0 - a * (1.0 - t_avg));
}
Colour residual_series(double t, double r, const Colour &a) {
    return {residual_term(t, r, a[0]), residual_term(t, r, a[1]), residual_term(t, r, a[2])};
}

}  // namespace

// ---------------------------------------------------------------------------------------
// The closure state shared by eval, the expectation and the sampler.

namespace {

struct Closure {
    double alpha, eta, tilt;
    Ellipse ellipse;
    Colour sigma;
    double m_r, m_tt, m_trt;
    float sqrt_alpha;
    Vec3d v;  // view, closure coordinates
    double sin_phi_v, cos_phi_v;
    // cos and sin of the tilt τ (entry mesonormals) and of −τ (inner ones), set by closure_of.
    double cos_tilt = 1, sin_tilt = 0, cos_inner_tilt = 1, sin_inner_tilt = 0;

    double scale(double mu, double eta_rel) const {
        return GgxGlassAlbedo::tables().energy_scale(sqrt_alpha, float(mu), float(eta_rel));
    }
    // γ(u) on the visible branch, u = h/R (§3).
    double gamma_of_u(double u) const {
        if (ellipse.circular()) return -std::asin(u);
        return std::atan2(v.z, -ellipse.b * v.x) - std::acos(-u);
    }
    double h_of_phi(double phi) const {
        if (ellipse.circular()) return -std::sin(phi);
        const double g = ellipse.gamma_of(phi);
        return -cos_phi_v * std::sin(g) + ellipse.b * sin_phi_v * std::cos(g);
    }
    // |dγ/dh| per unit of absolute h (0 where Cycles' safe_divide gives 0).
    double jacobian(double gamma) const {
        const double d = ellipse.circular()
                             ? std::cos(gamma)
                             : cos_phi_v * std::cos(gamma) + ellipse.b * sin_phi_v * std::sin(gamma);
        return d == 0.0 ? 0.0 : 1.0 / d;
    }
};

// The entry interface of a TT/TRT chain for one microfacet h1 (§6.2 steps 2–6).
struct Entry {
    bool ok = false;
    Vec3d wt, n2, m2;
    double gamma2 = 0, phi_t_mapped = 0;
    double t1 = 0, s1 = 0, s2 = 0, g1o = 0, cos_m1 = 0, cos_o1 = 0, cos_m2 = 0;
    double ct = 1, path = 0;  // at = exp(σ / ct · path)
    Colour at{};
};

Entry entry(const Closure &c, double gamma1, Vec3d n1, Vec3d m1, Vec3d h1) {
    Entry e;
    const double cos_h1 = dot(c.v, h1);
    if (!(cos_h1 > 0.0)) return e;
    e.cos_m1 = dot(c.v, n1);
    e.t1 = 1.0 - fresnel(cos_h1, c.eta);
    if (!ggx::refract(c.v, h1, c.eta, e.wt)) return e;
    e.s1 = c.scale(e.cos_m1, c.eta);
    const double phi_t = dir_phi(e.wt);
    e.phi_t_mapped = c.ellipse.phi_of(phi_t);
    e.gamma2 = 2.0 * e.phi_t_mapped - gamma1;
    c.ellipse.normals(c.cos_inner_tilt, c.sin_inner_tilt, e.gamma2, e.n2, e.m2);
    e.cos_o1 = dot(-e.wt, n1);
    e.cos_m2 = dot(-e.wt, e.n2);
    e.g1o = ggx::shadowing_ratio(c.alpha, e.cos_m1, e.cos_o1);
    if (!visible(c.v, -e.wt, n1, h1) || !visible(c.v, -e.wt, m1, h1)) return e;
    // Cycles' literal chord term: +2cos(γ1 − φ_t) (negative inside) for circles.
    const double path = c.ellipse.circular()
                            ? 2.0 * std::cos(gamma1 - phi_t)
                            : -length(c.ellipse.point(gamma1) - c.ellipse.point(e.gamma2 + kPi));
    const double ct = cos_theta(e.wt);
    for (int k = 0; k < 3; ++k) e.at[k] = std::exp(c.sigma[k] / ct * path);
    e.ct = ct;
    e.path = path;
    e.s2 = c.scale(e.cos_m2, 1.0 / c.eta);
    e.ok = true;
    return e;
}

// TT's exit towards l (§6.2 step 7) without the node weight and the multiplier·ℓ(γ2).
double tt_exit(const Closure &c, const Vec3d &wt, const Vec3d &n2, double cos_m2, Vec3d l) {
    const double inv_eta = 1.0 / c.eta;
    if (!(dot(l, wt) >= inv_eta - kTirSlack)) return 0.0;
    const Vec3d hh = -wt + inv_eta * l;
    const double rcp = 1.0 / length(hh);
    const Vec3d h2 = hh * rcp;
    const double cos_mh2 = dot(n2, h2);
    if (!(cos_mh2 >= 0.0)) return 0.0;
    const double cos_hi2 = dot(-wt, h2), cos_ho2 = dot(-l, h2), cos_mo2 = dot(-l, n2);
    const double t2 = 1.0 - fresnel(cos_hi2, inv_eta);
    return t2 * ggx::distribution(c.alpha, cos_mh2) * ggx::shadowing_g2(c.alpha, cos_m2, cos_mo2) *
           cos_hi2 * cos_ho2 * rcp * rcp;
}

// The internal reflection of a TRT chain for one microfacet h2 (§6.2 step 8, before l).
struct Bounce {
    bool ok = false, vis = false;
    Vec3d wtr, n3, m3;
    double r2 = 0, gamma3 = 0, cos_m3 = 0, s3 = 0, g2o = 0, cos_mo2 = 0;
    double ct = 1, path = 0;  // atr = exp(−σ / ct · path)
    Colour atr{};
};

Bounce bounce(const Closure &c, double gamma1, const Entry &e, Vec3d h2) {
    Bounce b;
    const double cos_h2 = dot(-e.wt, h2);
    if (!(cos_h2 > 0.0)) return b;
    b.ok = true;
    b.r2 = fresnel(cos_h2, 1.0 / c.eta);
    b.wtr = -ggx::reflect(e.wt, h2);
    b.vis = visible(-e.wt, -b.wtr, e.n2, h2) && visible(-e.wt, -b.wtr, e.m2, h2);
    if (!b.vis) return b;
    const double phi_tr = dir_phi(b.wtr);
    b.gamma3 = gamma1 - 2.0 * (e.phi_t_mapped - c.ellipse.phi_of(phi_tr)) + kPi;
    c.ellipse.normals(c.cos_inner_tilt, c.sin_inner_tilt, b.gamma3, b.n3, b.m3);
    b.cos_m3 = dot(b.n3, b.wtr);
    b.s3 = c.scale(b.cos_m3, 1.0 / c.eta);
    const double path = c.ellipse.circular()
                            ? 2.0 * std::fabs(std::cos(phi_tr - e.gamma2))
                            : length(c.ellipse.point(b.gamma3) - c.ellipse.point(e.gamma2));
    const double ct = cos_theta(b.wtr);
    for (int k = 0; k < 3; ++k) b.atr[k] = std::exp(-c.sigma[k] / ct * path);
    b.ct = ct;
    b.path = path;
    b.cos_mo2 = dot(-b.wtr, e.n2);
    b.g2o = ggx::shadowing_ratio(c.alpha, e.cos_m2, b.cos_mo2);
    return b;
}

// TRT's exit towards l (§6.2 step 8, after the TIR and visibility tests): T₃ D₃ G₃ c_hi3 c_ho3
// / |ĥ₃|² without the path's constant factors; 0 when the exit fails (TRRT+ still counts).
double trt_exit(const Closure &c, const Vec3d &wtr, const Vec3d &n3, const Vec3d &m3,
                double cos_m3, double s3, Vec3d l) {
    const double inv_eta = 1.0 / c.eta;
    const Vec3d hh = wtr + inv_eta * l;
    const double rcp = 1.0 / length(hh);
    const Vec3d h3 = hh * rcp;
    const double cos_mh3 = dot(n3, h3);
    if (cos_mh3 < 0.0 || !visible(wtr, -l, n3, h3) || !visible(wtr, -l, m3, h3)) return 0.0;
    const double cos_hi3 = dot(h3, wtr), cos_ho3 = dot(h3, -l);
    const double t3 = (1.0 - fresnel(cos_hi3, inv_eta)) * s3;
    return t3 * ggx::distribution(c.alpha, cos_mh3) *
           ggx::shadowing_g2(c.alpha, cos_m3, dot(n3, -l)) * cos_hi3 * cos_ho3 * rcp * rcp;
}

bool exit_tir(const Closure &c, const Vec3d &wtr, Vec3d l) {
    return dot(-wtr, l) < 1.0 / c.eta - kTirSlack;
}

// The expectation's exits, one per precomputed path and ω_i: tt_exit and trt_exit with what
// does not depend on ω_i (the Smith Λ of the path's own cosine, the exit's energy scale, the
// visibility of w_tr against the exit normals) computed once per path. tt_exit and trt_exit
// stay the literal transcription of Cycles' eval, so that the expectation is checked against
// an eval that does not share this code.
struct ExitTerms {
    double alpha, alpha2, inv_eta;

    // tt_exit for one path.
    double tt(const Vec3d &wt, const Vec3d &n2, double lambda2, const Vec3d &l) const {
        if (!(dot(l, wt) >= inv_eta - kTirSlack)) return 0.0;
        const Vec3d hh = -wt + inv_eta * l;
        const double rcp = 1.0 / length(hh);
        const Vec3d h2 = hh * rcp;
        const double cos_mh2 = dot(n2, h2);
        if (!(cos_mh2 >= 0.0)) return 0.0;
        const double cos_hi2 = dot(-wt, h2), cos_ho2 = dot(-l, h2), cos_mo2 = dot(-l, n2);
        return (1.0 - fresnel(cos_hi2, inv_eta)) * ggx::distribution(alpha, cos_mh2) /
               (1.0 + lambda2 + ggx::smith_lambda(alpha, cos_mo2)) * cos_hi2 * cos_ho2 * rcp * rcp;
    }
    // trt_exit for one path whose w_tr faces n3 and m3, without the energy scale: T₃ D₃ G₃
    // c_hi3 c_ho3 / |ĥ₃|² written over one common denominator (ĥ₃ = w_tr + l/η unnormalized,
    // Fresnel's two ratios, GGX's D and the Smith G₂ of §6.2), one division per term.
    double trt(const Vec3d &wtr, const Vec3d &n3, const Vec3d &m3, double lambda3, const Vec3d &l) const {
        const double cos_ln3 = dot(l, n3), cos_lm3 = dot(l, m3);
        if (!(cos_ln3 < 0.0) || !(cos_lm3 < 0.0)) return 0.0;
        const Vec3d hh = wtr + inv_eta * l;
        const double len2 = dot(hh, hh), len = std::sqrt(len2);
        const double n_h = dot(n3, hh), i_h = dot(hh, wtr), o_h = -dot(hh, l);
        if (n_h < 0.0 || !(i_h > 0.0) || !(o_h > 0.0)) return 0.0;
        // Fresnel at cos_hi3 = i_h / |ĥ|, leaving the fiber: T = 1 − ½(a²/b² + e²/d²).
        const double c = i_h / len;
        const double sin2_t = (1.0 - c * c) / (inv_eta * inv_eta);
        if (sin2_t >= 1.0) return 0.0;
        const double cos_t = std::sqrt(1.0 - sin2_t);
        const double a = c - inv_eta * cos_t, b = c + inv_eta * cos_t;
        const double e = inv_eta * c - cos_t, d = inv_eta * c + cos_t;
        const double b2d2 = b * b * d * d;
        const double t_num = b2d2 - 0.5 * (a * a * d * d + e * e * b * b);
        // D = α² / (π q²), q = 1 − c² + α² c² at c = cos_mh3 = n_h / |ĥ|.
        const double c2 = std::min(n_h * n_h / len2, 1.0);
        const double q = (1.0 - c2) + alpha2 * c2;
        // 1 + Λ(cos_m3) + Λ(cos_mo3), Λ(c) = ½(√(1 + α² tan²) − 1) = ½(√(c² + α²(1 − c²)) / |c| − 1).
        const double co = std::fabs(cos_ln3), co2 = co * co;
        const double g_num = co * (0.5 + lambda3) + (co2 >= 1.0 ? 0.5 * co : 0.5 * std::sqrt(co2 + alpha2 * (1.0 - co2)));
        return t_num * alpha2 * i_h * o_h * co / (b2d2 * kPi * q * q * g_num * len2 * len2);
    }
};

}  // namespace

namespace {

Closure closure_of(const HuangFiber &f, const huang::View &v) {
    const double b = f.aspect_ratio();
    Closure c{f.roughness(), f.ior(), f.tilt(), Ellipse{b, 1.0 - b * b}, f.sigma(),
              f.m_r(), f.m_tt(), f.m_trt(), std::sqrt(float(f.roughness())), v.v,
              v.sin_phi_v, v.cos_phi_v};
    c.cos_tilt = std::cos(c.tilt);
    c.sin_tilt = std::sin(c.tilt);
    c.cos_inner_tilt = std::cos(-c.tilt);
    c.sin_inner_tilt = std::sin(-c.tilt);
    return c;
}

// Huang's frame (x tangent, y major axis, z = x × y) → closure coordinates (§0), then the
// circular rotation about the tangent.
Vec3d to_closure(const huang::View &v, Vec3 w) {
    const Vec3d c{double(w.y), double(w.x), -double(w.z)};
    return safe_normalize(Vec3d{v.rot_c * c.x - v.rot_s * c.z, c.y, v.rot_s * c.x + v.rot_c * c.z});
}

Vec3 from_closure(const huang::View &v, Vec3d r) {
    const Vec3d c{v.rot_c * r.x + v.rot_s * r.z, r.y, -v.rot_s * r.x + v.rot_c * r.z};
    return Vec3d{c.y, c.x, -c.z}.to_float();
}

// A Simpson node of §6: γ(u_k), its weight c_k·J(γ_k), meso- and macronormal at entry.
struct SimpsonNode {
    double gamma = 0, weight = 0;
    Vec3d meso, macro;
};

SimpsonNode simpson_node(const Closure &c, const huang::View &v, int intervals, double delta, int k) {
    SimpsonNode node;
    node.gamma = c.gamma_of_u(v.u_min + k * delta);
    node.weight = ((k == 0 || k == intervals) ? 0.5 : double(k % 2 + 1)) * c.jacobian(node.gamma);
    c.ellipse.normals(c.cos_tilt, c.sin_tilt, node.gamma, node.meso, node.macro);
    return node;
}

// §6.1 without the division by cos θ_v·d.
double r_lobe(const Closure &c, const huang::View &v, Vec3d l) {
    if (c.m_r <= 0.0 || v.r_intervals == 0) return 0.0;
    const Vec3d wh = safe_normalize(c.v + l);
    const double f = fresnel(dot(c.v, wh), c.eta);
    double sum = 0.0;
    for (int k = 0; k <= v.r_intervals; ++k) {
        const SimpsonNode node = simpson_node(c, v, v.r_intervals, v.r_delta, k);
        const Vec3d mbar{node.meso.x, 0.0, node.meso.z};
        if (!visible(c.v, l, mbar, wh)) continue;
        const double cos_mv = dot(node.meso, c.v);
        sum += node.weight * c.ellipse.arc(node.gamma) * c.scale(cos_mv, c.eta) *
               ggx::distribution(c.alpha, dot(node.meso, wh)) *
               ggx::shadowing_g2(c.alpha, cos_mv, dot(node.meso, l));
    }
    return c.m_r * 0.25 * f * (2.0 / 3.0) * v.r_delta * sum;
}

// tan τ · tan θ_l < −1: no mesonormal faces l (§6 step 1).
bool faces_no_mesonormal(const Closure &c, Vec3d l) {
    return std::tan(c.tilt) * (l.y / cos_theta(l)) < -1.0;
}

std::uint32_t hash_bits(std::uint32_t h, std::uint32_t x) {
    // One round of a 32-bit integer mix (splitmix-style constants).
    h ^= x + 0x9e3779b9u + (h << 6) + (h >> 2);
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}

std::uint32_t float_bits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// HuangFiber

Expected<HuangFiber> HuangFiber::create(const HuangParams &params, const HuangQuadrature &far_field) {
    const HuangParams &p = params;
    if (Status s = first_error(
            check::non_negative("sigma_a.r", p.sigma_a.r), check::non_negative("sigma_a.g", p.sigma_a.g),
            check::non_negative("sigma_a.b", p.sigma_a.b), check::in_range("roughness", p.roughness, 0.0, 1.0),
            check::finite("ior", p.ior), check::in_range("offset", p.offset, -kHalfPi, kHalfPi),
            check::finite("aspect_ratio", p.aspect_ratio),
            check::in_range("reflection", p.reflection, 0.0, 1000.0),
            check::in_range("transmission", p.transmission, 0.0, 1000.0),
            check::in_range("secondary_reflection", p.secondary_reflection, 0.0, 1000.0),
            check::count_in_range("first_order", far_field.first_order, 1, GaussLegendre::kMaxPoints),
            check::count_in_range("second_order", far_field.second_order, 1, GaussLegendre::kMaxPoints),
            check::count_in_range("simpson_refinement", far_field.simpson_refinement, 1, 64)))
        return *s;
    if (!(p.ior > 1.0f && p.ior <= 1000.0f))
        return Error{"ior must be in (1, 1000] (got " + std::to_string(p.ior) + ")"};
    if (!(p.aspect_ratio > 0.0f && p.aspect_ratio <= 1000.0f))
        return Error{"aspect_ratio must be in (0, 1000] (got " + std::to_string(p.aspect_ratio) + ")"};
    if (p.reflection == 0.0f && p.transmission == 0.0f && p.secondary_reflection == 0.0f)
        return Error{"reflection, transmission and secondary_reflection are all 0: Cycles allocates "
                     "no closure then (no scattering, not even transparency); at least one must be > 0"};
    HuangFiber f;
    f.params_ = p;
    f.far_field_ = far_field;
    f.alpha_ = std::clamp(double(p.roughness), 0.001, 1.0);
    f.eta_ = p.ior;
    f.tilt_ = -double(p.offset);
    f.aspect_ = p.aspect_ratio > 1.0f ? 1.0 / double(p.aspect_ratio) : double(p.aspect_ratio);
    f.sigma_ = colour_of(p.sigma_a);
    f.m_r_ = p.reflection;
    f.m_tt_ = p.transmission;
    f.m_trt_ = p.secondary_reflection;
    return f;
}

Vec3 HuangFiber::fallback_major_axis(Vec3 tangent) {
    const Vec3d t{tangent};
    Vec3d c, a;
    ggx::orthonormal_basis(t, c, a);  // c = normalize(s × t), a = t × c
    return a.to_float();
}

Vec3 HuangFiber::major_axis(Vec3 tangent, Vec3 normal) {
    const Vec3d t{tangent}, n{normal};
    const Vec3d a = safe_normalize(cross(t, safe_normalize(cross(n, t))));
    const bool usable = std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z) &&
                        (a.x != 0.0 || a.y != 0.0 || a.z != 0.0);
    return usable ? a.to_float() : Vec3{};
}

LobeShape HuangFiber::lobe_shape(int p) const {
    // Reflection off a mesonormal tilted by τ = −offset sends θ_o to 2τ − θ_o, so R peaks at
    // θ_h = τ; TT and TRT shift the other way by about half and three halves of it
    // (Marschner's ratios). Widths: a GGX slope's Beckmann-equivalent deviation α/√2 for R,
    // half and twice that for TT and TRT; TRRT+ has d'Eon's M with variance 4α.
    const double offset = params_.offset, beta_r = alpha_ / std::sqrt(2.0);
    switch (p) {
        case 0: return {float(-offset), float(beta_r)};
        case 1: return {float(0.5 * offset), float(0.5 * beta_r)};
        case 2: return {float(1.5 * offset), float(2.0 * beta_r)};
        case 3: return {0.0f, float(std::sqrt(alpha_))};
        default: return {};
    }
}

huang::View HuangFiber::make_view(const HuangHit &hit, int simpson_refinement) const {
    huang::View p;
    p.h = hit.h;
    Vec3d v = to_closure(p, hit.wo);
    const double ct_v = cos_theta(v);
    if (!(ct_v > 0.0) || !std::isfinite(ct_v)) return p;  // along the fiber: no frame
    if (aspect_ == 1.0) {
        // Cycles' circular frame has the view at φ = 0.
        p.rot_c = v.z / ct_v;
        p.rot_s = v.x / ct_v;
        v = to_closure(p, hit.wo);
    }
    p.v = v;
    p.sin_phi_v = v.x / ct_v;
    p.cos_phi_v = v.z / ct_v;
    const double e2 = 1.0 - aspect_ * aspect_;
    p.radius = e2 == 0.0 ? 1.0 : std::sqrt(1.0 - e2 * v.x * v.x / (v.x * v.x + v.z * v.z));
    if (std::fabs(double(hit.h)) >= p.radius) {
        p.transparent = true;
        return p;
    }
    p.near = p.radius > double(hit.pixel_coverage);

    const Closure c = closure_of(*this, p);
    const double arg = -std::tan(tilt_) * (v.y / ct_v);
    if (!(arg <= 1.0)) return p;  // no mesonormal faces the view
    const double half_span = std::acos(std::max(arg, 0.0));
    const double phi_v = aspect_ == 1.0 ? 0.0 : dir_phi(v);
    double lo = c.h_of_phi(phi_v + half_span), hi = c.h_of_phi(phi_v - half_span);
    double d = 2.0;
    if (p.near) {
        const double r = p.radius, pc = hit.pixel_coverage;
        const double n_lo = std::max(-r, double(hit.h) - pc), n_hi = std::min(r, double(hit.h) + pc);
        d = (n_hi - n_lo) / r;
        lo = std::max(lo, n_lo);
        hi = std::min(hi, n_hi);
    }
    lo = std::max(lo / p.radius, -kUClamp);
    hi = std::min(hi / p.radius, kUClamp);
    if (!(lo < hi)) return p;
    p.empty = false;
    p.u_min = lo;
    p.u_max = hi;
    p.denominator = ct_v * d;
    const int refine = std::max(1, simpson_refinement);
    auto intervals = [&](double step, int &n, double &delta) {
        const double res = step * alpha_ / refine, range = hi - lo;
        n = 2 * int(std::ceil(range / res * 0.5));
        delta = range / n;
    };
    if (m_r_ > 0.0) intervals(kRStep, p.r_intervals, p.r_delta);
    if (m_tt_ > 0.0 || m_trt_ > 0.0) intervals(kResidualStep, p.res_intervals, p.res_delta);
    return p;
}

HuangExpectation HuangFiber::expectation(const HuangHit &hit, const HuangQuadrature &q,
                                         const std::vector<double> &absorptions) const {
    HuangExpectation out(*this);
    out.absorptions_ = absorptions;
    const std::size_t n_extra = absorptions.size();
    out.tir_only_.count = n_extra;
    out.trrt_always_extra_.assign(n_extra, 0.0);
    std::vector<double> at_extra(n_extra), trrt_extra(n_extra);
    out.view_ = make_view(hit, q.simpson_refinement);
    const huang::View &p = out.view_;
    if (p.empty || p.res_intervals == 0) return out;
    const Closure c = closure_of(*this, p);
    // The expectation over the microfacet chains: product rules over the visible normals of
    // the entry and, for TRT/TRRT+, of the internal reflection (also when −w_t is below the
    // internal mesonormal: Cycles' sampler still draws there, ggx.h).
    for (int k = 0; k <= p.res_intervals; ++k) {
        const SimpsonNode node = simpson_node(c, p, p.res_intervals, p.res_delta, k);
        // The entry's visibility tests jump where −w_t crosses the meso- or macronormal plane.
        auto entry_events = [&](Vec3d h1) {
            Vec3d wt;
            if (!ggx::refract(p.v, h1, eta_, wt)) wt = -p.v;
            return std::array<double, 2>{-dot(wt, node.meso), -dot(wt, node.macro)};
        };
        auto add_tt = [&](const Entry &e, double base) {
            HuangExpectation::TtPath path;
            path.wt = e.wt;
            path.n2 = e.n2;
            path.lambda2 = ggx::smith_lambda(alpha_, e.cos_m2);
            path.coefficient = base * m_tt_ * c.ellipse.arc(e.gamma2) * e.t1 * e.s1 * e.s2 * e.g1o * e.cos_m1 / e.cos_o1;
            path.colour = e.at;
            out.tt_.push_back(path);
            for (std::size_t a = 0; a < n_extra; ++a) out.tt_extra_.push_back(std::exp(absorptions[a] / e.ct * e.path));
        };
        const int tt_order = q.tt_order > 0 ? q.tt_order : q.first_order;
        if (m_tt_ > 0.0 && tt_order != q.first_order)
            for (const ggx::VisibleNode &first :
                 ggx::visible_rule_split(alpha_, p.v, node.meso, tt_order, tt_order, q.scan, entry_events)) {
                const Entry e = entry(c, node.gamma, node.meso, node.macro, first.h);
                if (e.ok) add_tt(e, node.weight * first.weight);
            }
        for (const ggx::VisibleNode &first :
             ggx::visible_rule_split(alpha_, p.v, node.meso, q.first_order, q.first_order, q.scan, entry_events)) {
            const Entry e = entry(c, node.gamma, node.meso, node.macro, first.h);
            if (!e.ok) continue;
            const double base = node.weight * first.weight;
            if (m_tt_ > 0.0 && tt_order == q.first_order) add_tt(e, base);
            if (m_trt_ <= 0.0) continue;
            // The entry's colour at each extra absorption, shared by its internal reflections.
            for (std::size_t a = 0; a < n_extra; ++a) at_extra[a] = std::exp(absorptions[a] / e.ct * e.path);
            // The internal reflection: Fresnel's kink at the critical angle and the visibility
            // tests of the reflected direction against the inner meso- and macronormal.
            const double critical = 1.0 - 1.0 / (eta_ * eta_);
            auto bounce_events = [&](Vec3d h2) {
                const double cos_h2 = -dot(e.wt, h2);
                const Vec3d reflected = ggx::reflect(e.wt, h2);  // = −w_tr
                return std::array<double, 3>{cos_h2 * cos_h2 - critical, dot(reflected, e.n2), dot(reflected, e.m2)};
            };
            for (const ggx::VisibleNode &second :
                 ggx::visible_rule_split(alpha_, -e.wt, e.n2, q.second_order, q.second_order, q.scan, bounce_events)) {
                const Bounce b = bounce(c, node.gamma, e, second.h);
                if (!b.ok) continue;
                const double weight = base * second.weight;
                Colour trrt = residual_series(e.t1, b.r2, e.at);
                for (double &x : trrt) x *= weight;
                for (std::size_t a = 0; a < n_extra; ++a) trrt_extra[a] = weight * residual_term(e.t1, b.r2, at_extra[a]);
                if (!b.vis) {
                    out.tir_only_.push_back(-b.wtr, trrt, trrt_extra.data());
                    continue;
                }
                for (int i = 0; i < 3; ++i) out.trrt_always_[i] += trrt[i];
                for (std::size_t a = 0; a < n_extra; ++a) out.trrt_always_extra_[a] += trrt_extra[a];
                // trt_exit is 0 for every ω_i unless w_tr faces both exit normals.
                if (!(b.cos_m3 > 0.0) || !(dot(b.wtr, b.m3) > 0.0)) continue;
                HuangExpectation::TrtPath path;
                path.wtr = b.wtr;
                path.n3 = b.n3;
                path.m3 = b.m3;
                path.lambda3 = ggx::smith_lambda(alpha_, b.cos_m3);
                path.coefficient = weight * m_trt_ * c.ellipse.arc(b.gamma3) * e.t1 * e.s1 * b.r2 *
                                   e.s2 * e.g1o * b.g2o * e.cos_m1 * e.cos_m2 / (e.cos_o1 * b.cos_mo2) * b.s3;
                for (int i = 0; i < 3; ++i) path.colour[i] = e.at[i] * b.atr[i];
                out.trt_.push_back(path);
                for (std::size_t a = 0; a < n_extra; ++a)
                    out.trt_extra_.push_back(at_extra[a] * std::exp(-absorptions[a] / b.ct * b.path));
            }
        }
    }
    out.group_paths();
    return out;
}

double HuangFiber::projected_width(Vec3 w) const {
    const double e2 = 1.0 - aspect_ * aspect_;
    const double y2 = double(w.y) * w.y, across = y2 + double(w.z) * w.z;
    if (e2 == 0.0 || !(across > 0.0)) return 1.0;
    return std::sqrt(std::max(0.0, 1.0 - e2 * y2 / across));
}

std::unique_ptr<const FarFieldView> HuangFiber::view(Vec3 wo) const {
    return std::make_unique<HuangFarField>(*this, wo, far_field_);
}

Rgb HuangFiber::lobe_f_cos(int p, Vec3 wi, Vec3 wo) const {
    if (p < 0 || p > 3) return {};
    return expectation({wo, 0.0f, 1.0f}, far_field_).lobes(wi)[std::size_t(p)];
}

Rgb HuangFiber::f_cos(Vec3 wi, Vec3 wo) const { return expectation({wo, 0.0f, 1.0f}, far_field_).f(wi); }

// ---------------------------------------------------------------------------------------
// HuangExpectation

std::array<Rgb, 4> HuangExpectation::lobes(Vec3 wi, double *rest) const {
    std::array<Rgb, 4> out{};
    const std::size_t n_extra = rest ? absorptions_.size() : 0;
    // Sums per extra absorption: TT, TRT and TRRT+ (each n_extra), on the stack for the
    // absorption parts a table may hold.
    constexpr std::size_t kOnStack = 32;
    double extra_sums[3 * kOnStack];
    std::vector<double> extra_heap;
    double *extra = extra_sums;
    if (n_extra > kOnStack) {
        extra_heap.assign(3 * n_extra, 0.0);
        extra = extra_heap.data();
    }
    std::fill(extra, extra + 3 * n_extra, 0.0);
    double *tt_e = extra, *trt_e = extra + n_extra, *trrt_e = extra + 2 * n_extra;
    if (rest) std::fill(rest, rest + absorptions_.size(), 0.0);
    const huang::View &p = view_;
    if (p.empty) return out;
    const HuangFiber &fiber = *fiber_;
    const Closure c = closure_of(fiber, p);
    const Vec3d l = to_closure(p, wi);
    if (faces_no_mesonormal(c, l)) return out;
    out[0] = Rgb(float(r_lobe(c, p, l) / p.denominator));
    if (p.res_intervals == 0) return out;
    const double factor = (2.0 / 3.0) * p.res_delta / p.denominator;
    const double inv_eta2 = 1.0 / (c.eta * c.eta);
    Colour tt{}, trt{}, trrt = trrt_always_;
    const ExitTerms exits{c.alpha, c.alpha * c.alpha, 1.0 / c.eta};
    for (std::size_t j = 0; j < tt_.size(); ++j) {
        const TtPath &path = tt_[j];
        const double x = path.coefficient * exits.tt(path.wt, path.n2, path.lambda2, l);
        if (!std::isfinite(x)) continue;
        for (int k = 0; k < 3; ++k) tt[k] += x * path.colour[k];
        const double *colour = tt_extra_.data() + j * n_extra;
        for (std::size_t k = 0; k < n_extra; ++k) tt_e[k] += x * colour[k];
    }
    // A TRT exit below cos_min from −w_tr is totally reflected (exit_tir).
    const double cos_min = 1.0 / c.eta - kTirSlack;
    const DirectionCones::Threshold tir(l, cos_min);
    for (const DirectionCones::Cone &cone : trt_cones_.cones()) {
        const DirectionCones::Side side = tir.side(cone);
        if (side == DirectionCones::Side::Below) continue;
        for (std::uint32_t j = cone.begin; j < cone.end; ++j) {
            const TrtPath &path = trt_[j];
            if (side == DirectionCones::Side::Mixed && exit_tir(c, path.wtr, l)) continue;
            const double x = path.coefficient * exits.trt(path.wtr, path.n3, path.m3, path.lambda3, l);
            if (!std::isfinite(x)) continue;
            for (int k = 0; k < 3; ++k) trt[k] += x * path.colour[k];
            const double *colour = trt_extra_.data() + std::size_t(j) * n_extra;
            for (std::size_t k = 0; k < n_extra; ++k) trt_e[k] += x * colour[k];
        }
    }
    const std::array<double, 3> reflecting = tir_only_.sum_reflecting(l, cos_min, n_extra ? trrt_e : nullptr);
    for (int k = 0; k < 3; ++k) trrt[k] += reflecting[k];
    for (std::size_t k = 0; k < n_extra; ++k) trrt_e[k] += trrt_always_extra_[k];
    const double m = chiang::longitudinal_scattering(p.v.y, cos_theta(p.v), l.y, cos_theta(l), 4.0 * c.alpha);
    const double trrt_factor = m * kInvTwoPi * (2.0 / kPi);
    // A chain that leaves at the edge of total internal reflection can come out a rounding
    // error below zero (Cycles' own terms do too); a lobe is never negative.
    for (int k = 0; k < 3; ++k) {
        tt[k] = std::max(0.0, tt[k] * factor * inv_eta2);
        trt[k] = std::max(0.0, trt[k] * factor * inv_eta2);
        trrt[k] = std::max(0.0, trrt[k] * factor * trrt_factor);
    }
    for (std::size_t k = 0; k < n_extra; ++k)
        rest[k] = std::max(0.0, tt_e[k] * factor * inv_eta2) + std::max(0.0, trt_e[k] * factor * inv_eta2) +
                  std::max(0.0, trrt_e[k] * factor * trrt_factor);
    out[1] = rgb_of(tt);
    out[2] = rgb_of(trt);
    out[3] = rgb_of(trrt);
    return out;
}

void HuangExpectation::TirPaths::push_back(Vec3d minus_wtr, const std::array<double, 3> &trrt,
                                           const double *trrt_extra) {
    extra.insert(extra.end(), trrt_extra, trrt_extra + count);
    x.push_back(minus_wtr.x);
    y.push_back(minus_wtr.y);
    z.push_back(minus_wtr.z);
    r.push_back(trrt[0]);
    g.push_back(trrt[1]);
    b.push_back(trrt[2]);
}

void HuangExpectation::TirPaths::group() {
    std::vector<Vec3d> directions(x.size());
    for (std::size_t k = 0; k < x.size(); ++k) directions[k] = {x[k], y[k], z[k]};
    cones = DirectionCones(directions);
    auto permute = [&](std::vector<double> &column) {
        std::vector<double> out(column.size());
        for (std::size_t k = 0; k < out.size(); ++k) out[k] = column[cones.order()[k]];
        column.swap(out);
    };
    for (std::vector<double> *column : {&x, &y, &z, &r, &g, &b}) permute(*column);
    std::vector<double> ordered(extra.size());
    for (std::size_t k = 0; k < x.size(); ++k)
        std::copy_n(extra.begin() + std::ptrdiff_t(cones.order()[k] * count), count, ordered.begin() + std::ptrdiff_t(k * count));
    extra.swap(ordered);
    cone_sums.assign(cones.cones().size(), {0.0, 0.0, 0.0});
    cone_extra.assign(cones.cones().size() * count, 0.0);
    for (std::size_t c = 0; c < cone_sums.size(); ++c)
        for (std::uint32_t k = cones.cones()[c].begin; k < cones.cones()[c].end; ++k) {
            cone_sums[c][0] += r[k];
            cone_sums[c][1] += g[k];
            cone_sums[c][2] += b[k];
            for (std::size_t e = 0; e < count; ++e) cone_extra[c * count + e] += extra[k * count + e];
        }
}

std::array<double, 3> HuangExpectation::TirPaths::sum_reflecting(Vec3d l, double cos_min, double *sums) const {
    double sr = 0.0, sg = 0.0, sb = 0.0;
    const std::size_t n = sums ? count : 0;
    const DirectionCones::Threshold threshold(l, cos_min);
    for (std::size_t c = 0; c < cone_sums.size(); ++c) {
        const DirectionCones::Cone &cone = cones.cones()[c];
        switch (threshold.side(cone)) {
        case DirectionCones::Side::Below:
            sr += cone_sums[c][0];
            sg += cone_sums[c][1];
            sb += cone_sums[c][2];
            for (std::size_t e = 0; e < n; ++e) sums[e] += cone_extra[c * count + e];
            break;
        case DirectionCones::Side::AtOrAbove:
            break;
        case DirectionCones::Side::Mixed:
            for (std::uint32_t k = cone.begin; k < cone.end; ++k) {
                const double keep = x[k] * l.x + y[k] * l.y + z[k] * l.z < cos_min ? 1.0 : 0.0;
                sr += keep * r[k];
                sg += keep * g[k];
                sb += keep * b[k];
                for (std::size_t e = 0; e < n; ++e) sums[e] += keep * extra[k * count + e];
            }
            break;
        }
    }
    return {sr, sg, sb};
}

void HuangExpectation::group_paths() {
    std::vector<Vec3d> directions(trt_.size());
    for (std::size_t k = 0; k < trt_.size(); ++k) directions[k] = -trt_[k].wtr;
    trt_cones_ = DirectionCones(directions);
    std::vector<TrtPath> ordered(trt_.size());
    for (std::size_t k = 0; k < ordered.size(); ++k) ordered[k] = trt_[trt_cones_.order()[k]];
    trt_.swap(ordered);
    const std::size_t n = absorptions_.size();
    std::vector<double> extra(trt_extra_.size());
    for (std::size_t k = 0; k < trt_.size(); ++k)
        std::copy_n(trt_extra_.begin() + std::ptrdiff_t(trt_cones_.order()[k] * n), n, extra.begin() + std::ptrdiff_t(k * n));
    trt_extra_.swap(extra);
    tir_only_.group();
}

Rgb HuangExpectation::f(Vec3 wi) const {
    const std::array<Rgb, 4> l = lobes(wi);
    return l[0] + l[1] + l[2] + l[3];
}

HuangFarField::HuangFarField(const HuangFiber &fiber, Vec3 wo, const HuangQuadrature &quadrature)
    : expectation_(fiber.expectation({wo, 0.0f, 1.0f}, quadrature)) {
    static std::atomic<std::uint64_t> next_id{1};
    id_ = next_id.fetch_add(1, std::memory_order_relaxed);
}

Rgb HuangFarField::lobe_f_cos(int p, Vec3 wi) const {
    if (p < 0 || p > 3) return {};
    // Sweeps ask for the lobes of one ω_i in turn: keep the last ω_i's four per thread, keyed
    // by the view's id (not its address, which a later view may reuse).
    struct Last {
        std::uint64_t view = 0;
        Vec3 wi;
        std::array<Rgb, 4> lobes{};
    };
    thread_local Last last;
    if (last.view != id_ || std::memcmp(&last.wi, &wi, sizeof(Vec3)) != 0) {
        last.view = id_;
        last.wi = wi;
        last.lobes = expectation_.lobes(wi);
    }
    return last.lobes[std::size_t(p)];
}

// ---------------------------------------------------------------------------------------
// HuangPoint

HuangPoint::HuangPoint(const HuangFiber &fiber, const FiberHit &hit) : FiberPoint(hit), fiber_(&fiber) {
    if (fiber.aspect_ratio() != 1.0) {
        const Vec3 a = HuangFiber::major_axis({1, 0, 0}, hit.normal);
        const double len = std::hypot(double(a.y), double(a.z));
        // No usable normal: the major axis on the renderer's y (Cycles' ray frame).
        if (len > 0.0) {
            frame_c_ = a.y / len;
            frame_s_ = a.z / len;
        }
    }
    view_ = fiber.make_view(huang_hit());
    std::uint32_t seed = hash_bits(hit.seed, float_bits(hit.wo.x));
    seed = hash_bits(seed, float_bits(hit.wo.y));
    seed = hash_bits(seed, float_bits(hit.wo.z));
    lcg_.state = hash_bits(seed, float_bits(hit.h));
}

Rgb HuangPoint::albedo() const {
    // Cycles' closure frame (N, tangent, Z = N × tangent) in the hit's fiber frame (x the
    // tangent, y = x × ω_o): N is y for a round fiber, else the major axis; h stays the offset
    // measured from y, as Cycles keeps it when it turns N to the major axis.
    const FiberHit &hit = this->hit();
    Vec3 n{0.0f, 1.0f, 0.0f};
    const Vec3 major{0.0f, hit.normal.y, hit.normal.z};
    if (fiber_->aspect_ratio() != 1.0 && dot(major, major) > 0.0f) n = safe_normalize(major);
    const Vec3 z{0.0f, n.z, -n.y};
    const Vec3d i{dot(hit.wo, n), hit.wo.x, dot(hit.wo, z)};
    const double h = hit.h, eta = fiber_->ior();
    const double cos_i = h * i.x + std::sqrt(std::max(0.0, 1.0 - h * h)) * i.z;
    // Cycles' fresnel_dielectric takes |cos_i| with the same η: where an elliptic fiber's
    // macro normal faces away from the view (cos_i < 0) it does not swap the indices.
    const double f = fresnel(cos_i, eta);
    const double cos_t = -std::sqrt(std::max(0.0, eta * eta - 1.0 + cos_i * cos_i)) / eta;
    const double wt_y = -i.y / eta;  // the refracted view's tangent part (refract_angle)
    auto channel = [&](int c) {
        const double t = std::exp(2.0 * fiber_->sigma()[std::size_t(c)] * cos_t / (1.0 - wt_y * wt_y));
        return float((t - 2.0 * f * t + f) / (1.0 - f * t));
    };
    return {channel(0), channel(1), channel(2)};
}

Vec3 HuangPoint::to_huang(Vec3 w) const {
    const double c = frame_c_, s = frame_s_;
    return {w.x, float(c * w.y + s * w.z), float(-s * w.y + c * w.z)};
}

Vec3 HuangPoint::from_huang(Vec3 w) const {
    const double c = frame_c_, s = frame_s_;
    return {w.x, float(c * w.y - s * w.z), float(s * w.y + c * w.z)};
}

HuangHit HuangPoint::huang_hit() const {
    return {to_huang(hit().wo), hit().h, hit().pixel_coverage};
}

Rgb HuangPoint::f_reflection(Vec3 wi) const {
    const huang::View &p = view_;
    if (p.empty) return {};
    const Closure c = closure_of(*fiber_, p);
    const Vec3d l = to_closure(p, to_huang(wi));
    if (faces_no_mesonormal(c, l)) return {};
    return Rgb(float(r_lobe(c, p, l) / p.denominator));
}

namespace {

// The TT, TRT and TRRT+ sums of one Cycles eval (§7) before the closure's common factors.
struct ResidualSums {
    Colour tt{}, trt{}, trrt{};
};

// The Simpson nodes' microfacet chains of one Cycles eval at l, drawn from `lcg` as Cycles
// draws them: their sums for the closure's σ in `own` and, when `other_sigma` is given, for
// that σ along the same chains in `other` (the geometry does not depend on σ).
void chain_sums(const Closure &c, const huang::View &p, Vec3d l, CyclesLcg &lcg, const Colour *other_sigma,
                ResidualSums &own, ResidualSums *other) {
    for (int k = 0; k <= p.res_intervals && p.res_intervals > 0; ++k) {
        const SimpsonNode node = simpson_node(c, p, p.res_intervals, p.res_delta, k);
        const double u1 = lcg.next(), u2 = lcg.next();
        const Vec3d h1 = ggx::sample_visible(c.alpha, c.v, node.meso, u1, u2);
        const Entry e = entry(c, node.gamma, node.meso, node.macro, h1);
        if (!e.ok) continue;
        Colour at_other{};
        if (other_sigma)
            for (int i = 0; i < 3; ++i) at_other[i] = std::exp((*other_sigma)[i] / e.ct * e.path);
        const double w = node.weight;
        if (c.m_tt > 0.0) {
            const double x = w * c.m_tt * c.ellipse.arc(e.gamma2) * e.t1 * e.s1 * e.s2 * e.g1o *
                             e.cos_m1 / e.cos_o1 * tt_exit(c, e.wt, e.n2, e.cos_m2, l);
            if (std::isfinite(x))
                for (int i = 0; i < 3; ++i) {
                    own.tt[i] += x * e.at[i];
                    if (other) other->tt[i] += x * at_other[i];
                }
        }
        if (c.m_trt <= 0.0) continue;
        const double u3 = lcg.next(), u4 = lcg.next();
        const Vec3d h2 = ggx::sample_visible(c.alpha, -e.wt, e.n2, u3, u4);
        const Bounce b = bounce(c, node.gamma, e, h2);
        if (!b.ok) continue;
        const Colour q = residual_series(e.t1, b.r2, e.at);
        const Colour q_other = other ? residual_series(e.t1, b.r2, at_other) : Colour{};
        const bool tir = exit_tir(c, b.wtr, l);
        if (!tir && !b.vis) continue;
        if (!tir) {
            const double x = w * c.m_trt * c.ellipse.arc(b.gamma3) * e.t1 * e.s1 * b.r2 * e.s2 * e.g1o *
                             b.g2o * e.cos_m1 * e.cos_m2 / (e.cos_o1 * b.cos_mo2) *
                             trt_exit(c, b.wtr, b.n3, b.m3, b.cos_m3, b.s3, l);
            if (std::isfinite(x))
                for (int i = 0; i < 3; ++i) {
                    own.trt[i] += x * e.at[i] * b.atr[i];
                    if (other) other->trt[i] += x * at_other[i] * std::exp(-(*other_sigma)[i] / b.ct * b.path);
                }
        }
        for (int i = 0; i < 3; ++i) {
            own.trrt[i] += w * q[i];
            if (other) other->trrt[i] += w * q_other[i];
        }
    }
}

// f·|cos θ_i| from R and the chains' sums (§7's closing factors).
Colour assemble(const Closure &c, const huang::View &p, Vec3d l, double r, const ResidualSums &s) {
    const double m = chiang::longitudinal_scattering(p.v.y, cos_theta(p.v), l.y, cos_theta(l), 4.0 * c.alpha);
    const double factor = (2.0 / 3.0) * p.res_delta;
    const double inv_eta2 = 1.0 / (c.eta * c.eta);
    Colour sum;
    for (int i = 0; i < 3; ++i)
        sum[i] = (r + factor * ((s.tt[i] + s.trt[i]) * inv_eta2 + s.trrt[i] * m * kInvTwoPi * (2.0 / kPi))) /
                 p.denominator;
    return sum;
}

}  // namespace

Rgb HuangPoint::f_estimate(Vec3 wi, CyclesLcg &lcg) const {
    const huang::View &p = view_;
    if (p.empty) return {};
    const Closure c = closure_of(*fiber_, p);
    const Vec3d l = to_closure(p, to_huang(wi));
    if (faces_no_mesonormal(c, l)) return {};
    const double r = r_lobe(c, p, l);
    ResidualSums own;
    chain_sums(c, p, l, lcg, nullptr, own, nullptr);
    return rgb_of(assemble(c, p, l, r, own));
}

Rgb HuangPoint::f_estimate_difference(Vec3 wi, CyclesLcg &lcg, const HuangFiber &other) const {
    const huang::View &p = view_;
    if (p.empty) return {};
    const Closure c = closure_of(*fiber_, p);
    const Vec3d l = to_closure(p, to_huang(wi));
    if (faces_no_mesonormal(c, l)) return {};
    ResidualSums own, alt;
    chain_sums(c, p, l, lcg, &other.sigma(), own, &alt);
    const Colour a = assemble(c, p, l, 0.0, own), b = assemble(c, p, l, 0.0, alt);
    return rgb_of({a[0] - b[0], a[1] - b[1], a[2] - b[2]});
}

std::optional<HuangCyclesSample> HuangPoint::sample_cycles(float u_lobe, float u_offset,
                                                                  float u_microfacet,
                                                                  CyclesLcg &lcg) const {
    const huang::View &view = view_;
    if (view.transparent || !(cos_theta(view.v) > 0.0)) return std::nullopt;
    const HuangFiber &fiber = *fiber_;
    const Closure c = closure_of(fiber, view);
    const Vec3d v_ = view.v;
    const double alpha_ = c.alpha, eta_ = c.eta, tilt_ = c.tilt, m_r_ = c.m_r, m_tt_ = c.m_tt, m_trt_ = c.m_trt;
    const Colour &sigma_ = c.sigma;
    const double s1u = u_microfacet, s1v = lcg.next();
    const double s2u = lcg.next(), s2v = lcg.next();
    const double s3u = lcg.next(), s3v = lcg.next();
    const double inv_eta = 1.0 / eta_;

    const double u = view.near ? view.h / view.radius : 2.0 * double(u_offset) - 1.0;
    const double gamma1 = c.gamma_of_u(u);
    const Vec3d m1 = c.ellipse.normal(0.0, gamma1);
    const Vec3d n1 = c.ellipse.normal(tilt_, gamma1);
    const double cos_m1 = dot(n1, v_);
    if (cos_m1 < 0.0 || dot(m1, v_) < 0.0) return std::nullopt;

    // R.
    const Vec3d h1 = ggx::sample_visible(alpha_, v_, n1, s1u, s1v);
    const Vec3d wr = 2.0 * dot(v_, h1) * h1 - v_;
    if (!visible(v_, m1, h1)) return std::nullopt;
    const double r1 = fresnel(dot(v_, h1), eta_);
    const double s1 = c.scale(cos_m1, eta_);
    const double r_value = m_r_ * r1 * s1 * (visible(wr, m1, h1) ? 1.0 : 0.0) *
                           ggx::shadowing_ratio(alpha_, cos_m1, dot(n1, wr));

    // TT.
    Vec3d wt;
    ggx::refract(v_, h1, eta_, wt);
    const double phi_t = dir_phi(wt), phi_t_mapped = c.ellipse.phi_of(phi_t);
    const double gamma2 = 2.0 * phi_t_mapped - gamma1;
    const Vec3d n2 = c.ellipse.normal(-tilt_, gamma2), m2 = c.ellipse.normal(0.0, gamma2);
    const Vec3d h2 = ggx::sample_visible(alpha_, -wt, n2, s2u, s2v);
    const Vec3d wtr = -ggx::reflect(wt, h2);
    Colour tt{}, trt{}, trrt{};
    Vec3d wtt, wtrt, wtrrt;
    const double cos_m2 = dot(-wt, n2);
    if (cos_m2 > 0.0 && visible(-wt, m1, h1) && visible(-wt, m2, h2)) {
        const double path = c.ellipse.circular()
                                ? 2.0 * std::cos(phi_t - gamma1)
                                : -length(c.ellipse.point(gamma1) - c.ellipse.point(gamma2 + kPi));
        Colour at;
        for (int k = 0; k < 3; ++k) at[k] = std::exp(sigma_[k] / cos_theta(wt) * path);
        const double r2 = fresnel(dot(-wt, h2), inv_eta);
        const double t1 = (1.0 - r1) * s1 * ggx::shadowing_ratio(alpha_, cos_m1, dot(n1, -wt));
        const double t2 = 1.0 - r2;
        const double s2 = c.scale(cos_m2, inv_eta);
        const bool exits = ggx::refract(-wt, h2, inv_eta, wtt);
        if (exits && dot(n2, -wtt) > 0.0 && t2 > 0.0 && visible(-wtt, m2, h2)) {
            const double x = m_tt_ * t1 * t2 * s2 * ggx::shadowing_ratio(alpha_, cos_m2, dot(n2, -wtt));
            for (int k = 0; k < 3; ++k) tt[k] = x * at[k];
        }
        // TRT.
        const double phi_tr = dir_phi(wtr);
        const double gamma3 = gamma1 - 2.0 * (phi_t_mapped - c.ellipse.phi_of(phi_tr)) + kPi;
        const Vec3d n3 = c.ellipse.normal(-tilt_, gamma3);
        const Vec3d h3 = ggx::sample_visible(alpha_, wtr, n3, s3u, s3v);
        const double r3 = fresnel(dot(wtr, h3), inv_eta);
        const bool exits3 = ggx::refract(wtr, h3, inv_eta, wtrt);
        const double cos_m3 = dot(n3, wtr);
        if (cos_m3 > 0.0) {
            const double path2 = c.ellipse.circular()
                                     ? 2.0 * std::fabs(std::cos(phi_tr - gamma2))
                                     : length(c.ellipse.point(gamma2) - c.ellipse.point(gamma3));
            Colour atr;
            for (int k = 0; k < 3; ++k) atr[k] = std::exp(-sigma_[k] / cos_theta(wtr) * path2);
            const double tr_scalar = t1 * r2 * s2 * c.scale(cos_m3, inv_eta) *
                                     ggx::shadowing_ratio(alpha_, cos_m2, dot(n2, -wtr));
            const double t3 = 1.0 - r3;
            const Vec3d n3bar{n3.x, 0.0, n3.z};
            if (exits3 && t3 > 0.0 && visible(wtr, -wtrt, n3bar, h3)) {
                const double x = m_trt_ * tr_scalar * t3 * ggx::shadowing_ratio(alpha_, cos_m3, dot(n3, -wtrt));
                for (int k = 0; k < 3; ++k) trt[k] = x * at[k] * atr[k];
            }
            // TRRT+: d'Eon's cone about the view's specular cone, uniform azimuth.
            const double zeta = std::max(double(lcg.next()), 1e-5);
            const double v4 = 4.0 * alpha_;
            const double fac = 1.0 + v4 * std::log(zeta + (1.0 - zeta) * std::exp(-0.5 / alpha_));
            const double sin_t = -fac * v_.y + cos_from_sin(fac) * std::cos(kTwoPi * lcg.next()) * cos_theta(v_);
            const double cos_t = cos_from_sin(sin_t);
            const double phi = kTwoPi * lcg.next();
            wtrrt = Vec3d{std::sin(phi) * cos_t, sin_t, std::cos(phi) * cos_t};
            const double t_avg = std::max(0.5 * (t2 + t3), 1e-5);
            const double g = ggx::shadowing_ratio(alpha_, cos_m3, dot(n3, -ggx::reflect(wtr, h3)));
            for (int k = 0; k < 3; ++k) {
                const double a_avg = std::sqrt(at[k] * atr[k]);
                const double a_res = a_avg * t_avg / (1.0 - a_avg * (1.0 - t_avg));
                trrt[k] = tr_scalar * at[k] * atr[k] * r3 * a_res * g;
            }
        }
    }
    auto mean = [](const Colour &x) { return (x[0] + x[1] + x[2]) / 3.0; };
    const double e_r = r_value, e_tt = mean(tt), e_trt = mean(trt), e_trrt = mean(trrt);
    const double total = e_r + e_tt + e_trt + e_trrt;
    if (total == 0.0 || !std::isfinite(total)) return std::nullopt;
    const double pick = double(u_lobe) * total;
    HuangCyclesSample out;
    auto weight = [&](const Colour &x, double e) {
        return Rgb(float(x[0] / e * total), float(x[1] / e * total), float(x[2] / e * total));
    };
    if (pick < e_r) {
        out.lobe = 0;
        out.wi = from_huang(from_closure(view, wr));
        out.weight = Rgb(float(total));
    } else if (pick < e_r + e_tt) {
        out.lobe = 1;
        out.wi = from_huang(from_closure(view, wtt));
        out.weight = weight(tt, e_tt);
    } else if (pick < e_r + e_tt + e_trt) {
        out.lobe = 2;
        out.wi = from_huang(from_closure(view, wtrt));
        out.weight = weight(trt, e_trt);
    } else {
        out.lobe = 3;
        out.wi = from_huang(from_closure(view, wtrrt));
        out.weight = weight(trrt, e_trrt);
    }
    return out;
}

}  // namespace hairis
