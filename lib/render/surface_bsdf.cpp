#include "render/surface_bsdf.h"

#include <algorithm>
#include <cmath>

#include "fiber/fresnel.h"
#include "render/lights.h"
#include "render/microfacet.h"

namespace hairis {

namespace {

constexpr float kPiF = float(kPi);
constexpr float kInvPiF = float(kInvPi);

float schlick_weight(float c) {
    const float m = std::clamp(1.0f - c, 0.0f, 1.0f);
    const float m2 = m * m;
    return m2 * m2 * m;
}

Rgb clamp01(Rgb c) {
    return {std::clamp(c.r, 0.0f, 1.0f), std::clamp(c.g, 0.0f, 1.0f), std::clamp(c.b, 0.0f, 1.0f)};
}

// Fujii's G(cos θ) of the improved Oren–Nayar albedo E(c) = Aπ + B G(c).
float oren_nayar_g(float c) {
    if (c < 1e-6f) return (0.5f * kPiF - 2.0f / 3.0f) - c;
    const float s = std::sqrt(std::max(0.0f, 1.0f - c * c));
    const float theta = std::acos(std::clamp(c, -1.0f, 1.0f));
    return s * (theta - 2.0f / 3.0f - s * c) + (2.0f / 3.0f) * (s / c) * (1.0f - s * s * s);
}

// The Oren–Nayar t term (shared by both versions).
float oren_nayar_t(Vec3 wo, Vec3 wi, float ci, float co) {
    float t = dot(wi, wo) - ci * co;
    if (t > 0.0f) t /= std::max(ci, co) + 1.17549435e-38f;
    return t;
}

Rgb microfacet_fresnel(const SurfaceLobe &l, float c) {
    switch (l.fresnel) {
        case MicrofacetFresnel::One:
            return Rgb(1.0f);
        case MicrofacetFresnel::Interpolated34: {
            const float f0 = fresnel_dielectric(1.0f, l.ior);
            const float s = (fresnel_dielectric(c, l.ior) - f0) / (1.0f - f0);
            return (l.f0 * (1.0f - s) + Rgb(s)) * l.fresnel_scale;
        }
        case MicrofacetFresnel::SchlickIor: {
            const float f0 = sqr((l.ior - 1.0f) / (l.ior + 1.0f));
            const float s = std::clamp((fresnel_dielectric(c, l.ior) - f0) / (1.0f - f0), 0.0f, 1.0f);
            return l.f0 + (Rgb(1.0f) - l.f0) * s;
        }
        case MicrofacetFresnel::F82Tint: {
            const float m = std::clamp(1.0f - c, 0.0f, 1.0f);
            const float m5 = sqr(sqr(m)) * m;
            return clamp01(l.f0 + (Rgb(1.0f) - l.f0) * m5 - l.f82_b * (c * m5 * m));
        }
        case MicrofacetFresnel::Dielectric:
            return Rgb(fresnel_dielectric(c, l.ior));
    }
    return Rgb(1.0f);
}

Rgb eval_microfacet(const SurfaceLobe &l, Vec3 wo, Vec3 wi, float &pdf, float *reported) {
    pdf = 0.0f;
    if (reported) *reported = 0.0f;
    if (!(wo.z > 0.0f) || !(wi.z > 0.0f)) return {};
    const Vec3 sum = wo + wi;
    const Vec3 h = safe_normalize(sum);
    if (!(h.z > 0.0f)) return {};
    const float c = std::clamp(dot(wi, h), 0.0f, 1.0f);
    float d;
    const float a2 = l.shadowing_alpha2;
    float reports;
    if (l.distribution == MicrofacetDistribution::Gtr1) {
        d = microfacet::gtr1_d(l.alpha, sum);
        if (l.sampling == MicrofacetSampling::Cycles34Clearcoat) {
            pdf = microfacet::ggx_reflection_pdf(wo, wi, l.alpha);
            reports = microfacet::ggx_g1(a2, wo.z) * d / (4.0f * wo.z);
        } else {
            pdf = reports = microfacet::gtr1_reflection_pdf(wo, wi, l.alpha);
        }
    } else {
        const float alpha2 = l.alpha * l.alpha;
        d = microfacet::ggx_d(alpha2, sum);
        pdf = reports = microfacet::ggx_g1(alpha2, wo.z) * d / (4.0f * wo.z);
    }
    if (reported) *reported = reports;
    const float g = l.shadowing == MicrofacetShadowing::Separable
                        ? microfacet::ggx_g1(a2, wo.z) * microfacet::ggx_g1(a2, wi.z)
                        : 1.0f / (1.0f + microfacet::ggx_lambda(a2, wo.z) +
                                  microfacet::ggx_lambda(a2, wi.z));
    return microfacet_fresnel(l, c) * (d * g * l.energy_scale / (4.0f * wo.z));
}

}  // namespace

Rgb lobe_denoising_albedo(const SurfaceLobe &l, Vec3 wo) {
    return l.kind == SurfaceLobeKind::Microfacet ? microfacet_fresnel(l, std::clamp(wo.z, 0.0f, 1.0f)) : Rgb(1.0f);
}

bool lobe_is_specular(const SurfaceLobe &l) {
    return l.kind == SurfaceLobeKind::Microfacet && l.alpha * l.alpha <= sqr(0.075f);
}

Rgb eval_lobe(const SurfaceLobe &l, Vec3 wo, Vec3 wi, float &pdf, float *reported) {
    if (l.kind == SurfaceLobeKind::Microfacet) return eval_microfacet(l, wo, wi, pdf, reported);
    const float ci = wi.z;
    if (!(ci > 0.0f)) {
        pdf = 0.0f;
        if (reported) *reported = 0.0f;
        return {};
    }
    pdf = ci * kInvPiF;
    if (reported) *reported = pdf;
    switch (l.kind) {
        case SurfaceLobeKind::Lambert:
            return Rgb(ci * kInvPiF);
        case SurfaceLobeKind::PrincipledDiffuse: {
            const float fo = schlick_weight(wo.z), fi = schlick_weight(ci);
            const float rr = l.roughness * (dot(wi, wo) + 1.0f);
            const float f = (1.0f - 0.5f * fo) * (1.0f - 0.5f * fi) + rr * (fi + fo + fi * fo * (rr - 1.0f));
            return Rgb(kInvPiF * ci * f);
        }
        case SurfaceLobeKind::OrenNayar34: {
            const float sigma = std::clamp(l.roughness, 0.0f, 1.0f);
            const float a = 1.0f / (kPiF + ((3.0f * kPiF - 4.0f) / 6.0f) * sigma), b = sigma * a;
            const float co = std::max(wo.z, 0.0f);
            return Rgb(ci * (a + b * oren_nayar_t(wo, wi, ci, co)));
        }
        case SurfaceLobeKind::OrenNayar: {
            const float sigma = std::clamp(l.roughness, 0.0f, 1.0f);
            const float a = 1.0f / (kPiF + sigma * (0.5f * kPiF - 2.0f / 3.0f)), b = sigma * a;
            if (!(b > 0.0f)) return Rgb(ci * kInvPiF);
            const float co = std::max(wo.z, 0.0f);
            const float single = a + b * oren_nayar_t(wo, wi, ci, co);
            const float e_i = a * kPiF + b * oren_nayar_g(ci);
            return (Rgb(single) + l.multiscatter * (1.0f - e_i)) * ci;
        }
        case SurfaceLobeKind::Sheen34: {
            if (wo.z < 0.0f) return {};
            const Vec3 h = safe_normalize(wo + wi);
            return Rgb(schlick_weight(dot(wi, h)) * ci);
        }
        case SurfaceLobeKind::Microfacet:
            break;
    }
    return {};
}

bool sample_lobe(const SurfaceLobe &l, Vec3 wo, float u0, float u1, Vec3 &wi) {
    if (l.kind == SurfaceLobeKind::Microfacet) {
        if (!(wo.z > 0.0f)) return false;
        Vec3 h;
        if (l.distribution == MicrofacetDistribution::Gtr1 && l.sampling == MicrofacetSampling::Exact) {
            h = microfacet::sample_gtr1(l.alpha, u0, u1);
            if (!(dot(wo, h) > 0.0f)) return false;
        } else {
            h = microfacet::sample_ggx_visible(wo, l.alpha, u0, u1);
        }
        wi = safe_normalize(microfacet::reflect(wo, h));
        return wi.z > 0.0f;
    }
    float x, y;
    concentric_disk(u0, u1, x, y);
    wi = {x, y, std::sqrt(std::max(0.0f, 1.0f - x * x - y * y))};
    return wi.z > 0.0f;
}

SurfaceBsdf::SurfaceBsdf(Vec3 n, Vec3 ng, Vec3 wo) : n_(n), ng_(ng) {
    orthonormal_basis(n_, a_, b_);
    wo_ = to_local(wo);
}

bool SurfaceBsdf::add(const SurfaceLobe &lobe) {
    if (lobe.weight.r == 0.0f && lobe.weight.g == 0.0f && lobe.weight.b == 0.0f) return true;
    if (count_ >= kMaxLobes) return false;
    SurfaceLobe &l = lobes_[std::size_t(count_++)];
    l = lobe;
    l.select = std::isfinite(lobe.select) && lobe.select > 0.0f ? lobe.select : 0.0f;
    select_total_ += l.select;
    return true;
}

void SurfaceBsdf::defend_selection(float share) {
    const float floor = share * select_total_;
    select_total_ = 0.0f;
    for (int k = 0; k < count_; ++k) {
        SurfaceLobe &l = lobes_[std::size_t(k)];
        if (l.select > 0.0f) l.select = std::max(l.select, floor);
        select_total_ += l.select;
    }
}

Rgb SurfaceBsdf::eval_local(Vec3 wi, float ng_cos, float &pdf, float *reported) const {
    Rgb f;
    float q = 0.0f, r = 0.0f;
    for (int k = 0; k < count_; ++k) {
        const SurfaceLobe &l = lobes_[std::size_t(k)];
        if (l.below_ng_is_zero && !(ng_cos >= 0.0f)) continue;
        float lobe_pdf = 0.0f, lobe_reported = 0.0f;
        const Rgb v = eval_lobe(l, wo_, wi, lobe_pdf, &lobe_reported);
        f += l.weight * v;
        q += l.select * lobe_pdf;
        r += l.select * lobe_reported;
    }
    const bool reachable = ng_cos > 0.0f && select_total_ > 0.0f;
    pdf = reachable ? q / select_total_ : 0.0f;
    if (reported) *reported = reachable ? r / select_total_ : 0.0f;
    return f;
}

Rgb SurfaceBsdf::eval(Vec3 wi, float &pdf, float *reported) const {
    return eval_local(to_local(wi), dot(ng_, wi), pdf, reported);
}

bool SurfaceBsdf::sample(float u0, float u1, float u2, Vec3 &wi, Rgb &weight, float &pdf,
                         bool *glossy, float *reported_pdf) const {
    if (black()) return false;
    // The lobe whose cumulative selection weight first exceeds u2 · total.
    const float target = u2 * select_total_;
    int chosen = -1;
    float cumulative = 0.0f;
    for (int k = 0; k < count_; ++k) {
        const float s = lobes_[std::size_t(k)].select;
        if (!(s > 0.0f)) continue;
        chosen = k;
        cumulative += s;
        if (target < cumulative) break;
    }
    if (chosen < 0) return false;
    Vec3 local;
    if (!sample_lobe(lobes_[std::size_t(chosen)], wo_, u0, u1, local)) return false;
    wi = safe_normalize(to_world(local));
    const float ng_cos = dot(ng_, wi);
    if (!(ng_cos > 0.0f)) return false;
    float reported = 0.0f;
    const Rgb f = eval_local(local, ng_cos, pdf, &reported);
    if (!(pdf > 0.0f) || !(reported > 0.0f)) return false;
    weight = f / reported;
    if (glossy) *glossy = lobes_[std::size_t(chosen)].kind == SurfaceLobeKind::Microfacet;
    if (reported_pdf) *reported_pdf = reported;
    return true;
}

void SurfaceBsdf::blur(float roughness) {
    for (int k = 0; k < count_; ++k) {
        SurfaceLobe &l = lobes_[std::size_t(k)];
        if (l.kind != SurfaceLobeKind::Microfacet || !(roughness > l.alpha)) continue;
        // GGX's shadowing follows α; GTR1 (3.4's clearcoat) keeps its fixed one.
        if (l.distribution == MicrofacetDistribution::Ggx) l.shadowing_alpha2 = roughness * roughness;
        l.alpha = roughness;
    }
}

}  // namespace hairis
