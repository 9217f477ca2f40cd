#include "render/surface_material.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "fiber/fresnel.h"
#include "render/ggx_albedo.h"

namespace hairis {

namespace {

// Cycles' CLOSURE_WEIGHT_CUTOFF: closures with a weight below it are not made.
constexpr float kCutoff = 1e-5f;
// The smallest α hairis evaluates: α² just above Cycles 3.4's mirror threshold (1e-7).
constexpr float kMinAlpha = 3.2e-4f;

float saturate(float x) { return std::clamp(x, 0.0f, 1.0f); }
Rgb saturate(Rgb c) { return {saturate(c.r), saturate(c.g), saturate(c.b)}; }
Rgb max0(Rgb c) { return {std::max(c.r, 0.0f), std::max(c.g, 0.0f), std::max(c.b, 0.0f)}; }
Rgb min1(Rgb c) { return {std::min(c.r, 1.0f), std::min(c.g, 1.0f), std::min(c.b, 1.0f)}; }
float average(Rgb c) { return (c.r + c.g + c.b) / 3.0f; }
Rgb mix(Rgb a, Rgb b, float t) { return a * (1.0f - t) + b * t; }
Rgb divide(Rgb a, Rgb b) { return {a.r / b.r, a.g / b.g, a.b / b.b}; }
bool is_one(Rgb c) { return c.r == 1.0f && c.g == 1.0f && c.b == 1.0f; }
Rgb pow(Rgb c, float e) { return {std::pow(c.r, e), std::pow(c.g, e), std::pow(c.b, e)}; }
float clamp_alpha(float alpha) { return std::max(alpha, kMinAlpha); }

float schlick_weight(float c) {
    const float m = saturate(1.0f - c);
    return sqr(sqr(m)) * m;
}

float f0_from_ior(float ior) { return sqr((ior - 1.0f) / (ior + 1.0f)); }
float ior_from_f0(float f0) {
    const float s = std::sqrt(std::clamp(f0, 0.0f, 0.99f));
    return (1.0f + s) / (1.0f - s);
}
// The Fresnel coordinate of Cycles' 3D tables.
float ior_coordinate(float ior) { return std::sqrt(std::fabs((ior - 1.0f) / (ior + 1.0f))); }

// Kulla and Conty's fit of the cosine-weighted average dielectric Fresnel (Cycles'
// fresnel_dielectric_Fss).
float dielectric_fss(float eta) {
    if (eta < 1.0f) return 0.997118f + eta * (0.1014f - eta * (0.965241f + eta * 0.130607f));
    return (eta - 1.0f) / (4.08567f + 1.00071f * eta);
}

// F82-tint: b from f0 and the tint at cos θ = 1/7, and its cosine-weighted average.
Rgb f82_tint_b(Rgb f0, Rgb tint) {
    const float f = 6.0f / 7.0f;
    const float f5 = sqr(sqr(f)) * f;
    const Rgb schlick = mix(f0, Rgb(1.0f), f5);
    return schlick * (7.0f / (f5 * f)) * (Rgb(1.0f) - tint);
}
Rgb f82_fss(Rgb f0, Rgb b) { return mix(f0, Rgb(1.0f), 1.0f / 21.0f) - b * (1.0f / 126.0f); }

// Cycles 4.x's microfacet_ggx_preserve_energy: energy_scale = 1/E and the weight's darkening
// by the multiple-bounce Fresnel Fss.
void preserve_energy(SurfaceLobe &lobe, float rough, float mu, Rgb fss) {
    const GgxAlbedoTables &t = GgxAlbedoTables::tables();
    const float e = std::max(t.e(rough, mu), 1e-4f);
    const float e_avg = t.e_avg(rough);
    const float missing = (1.0f - e) / e;
    lobe.energy_scale = 1.0f + missing;
    if (!is_one(fss)) {
        const Rgb fms = divide(fss * e_avg, Rgb(1.0f) - fss * (1.0f - e_avg));
        const Rgb darkening = (Rgb(1.0f) + fms * missing) / lobe.energy_scale;
        lobe.weight *= darkening;
    }
}

// Cycles 4.x's closure_layering_weight: what a layer of albedo `albedo` leaves of `weight`.
Rgb layering_weight(Rgb albedo, Rgb weight) {
    float m = 0.0f;
    for (int c = 0; c < 3; ++c)
        if (weight[c] != 0.0f) m = std::max(m, albedo[c] / weight[c]);
    return weight * saturate(1.0f - m);
}

SurfaceLobe diffuse_lobe(SurfaceLobeKind kind, Rgb weight, float roughness = 0.0f) {
    SurfaceLobe l;
    l.kind = kind;
    l.weight = weight;
    l.roughness = roughness;
    l.select = std::fabs(average(weight));
    return l;
}

SurfaceLobe ggx_lobe(Rgb weight, float alpha, MicrofacetShadowing shadowing,
                     MicrofacetFresnel fresnel) {
    SurfaceLobe l;
    l.kind = SurfaceLobeKind::Microfacet;
    l.weight = weight;
    l.distribution = MicrofacetDistribution::Ggx;
    l.shadowing = shadowing;
    l.fresnel = fresnel;
    l.alpha = clamp_alpha(alpha);
    l.shadowing_alpha2 = l.alpha * l.alpha;
    l.below_ng_is_zero = shadowing == MicrofacetShadowing::Correlated;
    return l;
}

// Cycles 4.3+'s Oren–Nayar with its multiple-scattering colour for ω_o.
SurfaceLobe oren_nayar_lobe(Rgb weight, float sigma, Rgb color, float cos_o) {
    SurfaceLobe l = diffuse_lobe(SurfaceLobeKind::OrenNayar, weight, saturate(sigma));
    const float pi = float(kPi);
    const float a = 1.0f / (pi + l.roughness * (0.5f * pi - 2.0f / 3.0f)), b = l.roughness * a;
    const Rgb albedo = saturate(color);
    const float e_avg = a * pi + ((2.0f * pi - 5.6f) / 3.0f) * b;
    const Rgb ems = divide(albedo * albedo * (float(kInvPi) * e_avg / (1.0f - e_avg)),
                           Rgb(1.0f) - albedo * (1.0f - e_avg));
    const float nv = std::max(cos_o, 0.0f);
    float g;
    if (nv < 1e-6f) {
        g = (0.5f * pi - 2.0f / 3.0f) - nv;
    } else {
        const float s = std::sqrt(std::max(0.0f, 1.0f - nv * nv)), theta = std::acos(nv);
        g = s * (theta - 2.0f / 3.0f - s * nv) + (2.0f / 3.0f) * (s / nv) * (1.0f - s * s * s);
    }
    l.multiscatter = ems * (1.0f - (a * pi + b * g));
    return l;
}

// Builds the lobes of one tree for one shading point.
class LobeBuilder {
  public:
    LobeBuilder(const std::vector<SurfaceNode> &nodes, const SurfaceShadingPoint &p, SurfaceBsdf &bsdf)
        : nodes_(nodes), p_(p), bsdf_(bsdf), wo_(bsdf.local_wo()) {}

    void visit(int index, Rgb w) {
        if (!(w.max_component() > 0.0f)) return;
        const SurfaceNode &node = nodes_[std::size_t(index)];
        if (const auto *mix = std::get_if<MixShaderNode>(&node)) {
            const float f = saturate(mix->factor);
            visit(mix->first, w * (1.0f - f));
            visit(mix->second, w * f);
        } else if (const auto *add = std::get_if<AddShaderNode>(&node)) {
            visit(add->first, w);
            visit(add->second, w);
        } else if (const auto *d = std::get_if<DiffuseBsdfNode>(&node)) {
            diffuse(*d, w);
        } else if (const auto *g = std::get_if<GlossyBsdfNode>(&node)) {
            glossy(*g, w);
        } else if (const auto *pr = std::get_if<PrincipledBsdfNode>(&node)) {
            if (pr->cycles == CyclesVersion::V3_4)
                principled_34(*pr, w);
            else
                principled_4(*pr, w);
        }
    }

  private:
    void add(const SurfaceLobe &l) { bsdf_.add(l); }

    void diffuse(const DiffuseBsdfNode &d, Rgb w) {
        const Rgb color = d.color.at(p_.u, p_.v);
        const Rgb weight = w * color;
        if (d.cycles == CyclesVersion::V3_4) {
            add(d.roughness == 0.0f ? diffuse_lobe(SurfaceLobeKind::Lambert, weight)
                                    : diffuse_lobe(SurfaceLobeKind::OrenNayar34, weight, d.roughness));
        } else {
            add(d.roughness < kCutoff ? diffuse_lobe(SurfaceLobeKind::Lambert, weight)
                                      : oren_nayar_lobe(weight, d.roughness, color, wo_.z));
        }
    }

    void glossy(const GlossyBsdfNode &g, Rgb w) {
        const Rgb color = max0(g.color.at(p_.u, p_.v));
        const float r = saturate(g.roughness);
        const bool v34 = g.cycles == CyclesVersion::V3_4;
        SurfaceLobe l = ggx_lobe(w * color, r * r,
                                 v34 ? MicrofacetShadowing::Separable : MicrofacetShadowing::Correlated,
                                 MicrofacetFresnel::One);
        if (g.multiscatter) preserve_energy(l, r, wo_.z, color);
        l.select = std::fabs(average(l.weight));
        add(l);
    }

    void principled_34(const PrincipledBsdfNode &pr, Rgb w) {
        const Rgb base = pr.base_color.at(p_.u, p_.v);
        const float metallic = pr.metallic, roughness = pr.roughness, specular = pr.specular;
        const float diffuse_weight = 1.0f - saturate(metallic);

        // Diffuse (the subsurface colour mix stands for the BSSRDF).
        const float ss = pr.subsurface;
        const Rgb mixed = pr.subsurface_color * ss + base * (1.0f - ss);
        if (std::fabs(average(mixed)) > kCutoff) {
            if (ss <= kCutoff && diffuse_weight > kCutoff)
                add(diffuse_lobe(SurfaceLobeKind::PrincipledDiffuse, w * base * diffuse_weight, roughness));
            else if (ss > kCutoff)
                add(diffuse_lobe(SurfaceLobeKind::PrincipledDiffuse, w * mixed * diffuse_weight, roughness));
        }

        // Sheen.
        if (diffuse_weight > kCutoff && pr.sheen > kCutoff) {
            const float lum = luminance(base);
            const Rgb tint = lum > 0.0f ? base / lum : Rgb(1.0f);
            const Rgb color = Rgb(1.0f - pr.sheen_tint) + tint * pr.sheen_tint;
            SurfaceLobe l = diffuse_lobe(SurfaceLobeKind::Sheen34, w * pr.sheen * color * diffuse_weight);
            l.select *= wo_.z > 0.0f ? schlick_weight(wo_.z) * wo_.z : 0.0f;
            add(l);
        }

        // Specular reflection.
        if (specular > kCutoff || metallic > kCutoff) {
            SurfaceLobe l = ggx_lobe(w, roughness * roughness, MicrofacetShadowing::Separable,
                                     MicrofacetFresnel::Interpolated34);
            l.ior = 2.0f / (1.0f - std::sqrt(std::max(0.0f, 0.08f * specular))) - 1.0f;
            const float lum = 0.3f * base.r + 0.6f * base.g + 0.1f * base.b;
            const Rgb tint = lum > 0.0f ? base / lum : Rgb(1.0f);
            const Rgb tmp = Rgb(1.0f - pr.specular_tint) + tint * pr.specular_tint;
            l.f0 = saturate(tmp * (specular * 0.08f) * (1.0f - metallic) + base * metallic);
            if (pr.multiscatter && roughness > 0.075f) {
                // Cycles 3.4's random-walk multiscatter GGX, approximated by 4.x's compensation.
                preserve_energy(l, std::sqrt(l.alpha), wo_.z, mix(l.f0, Rgb(1.0f), 1.0f / 21.0f));
            }
            l.select = std::fabs(average(l.weight)) * average(fresnel_at_normal(l));
            add(l);
        }

        // Clearcoat.
        if (pr.coat > kCutoff) {
            SurfaceLobe l;
            l.kind = SurfaceLobeKind::Microfacet;
            l.weight = w;
            l.distribution = MicrofacetDistribution::Gtr1;
            l.shadowing = MicrofacetShadowing::Separable;
            l.shadowing_alpha2 = 0.0625f;
            l.alpha = clamp_alpha(saturate(pr.coat_roughness * pr.coat_roughness));
            l.fresnel = MicrofacetFresnel::Interpolated34;
            l.f0 = Rgb(0.04f);
            l.ior = 1.5f;
            l.fresnel_scale = 0.25f * pr.coat;
            l.sampling = MicrofacetSampling::Cycles34Clearcoat;
            l.select = std::fabs(average(w)) * average(fresnel_at_normal(l));
            add(l);
        }
    }

    // Cycles 3.4's bsdf_microfacet_fresnel_color: the interpolated Fresnel at ω_o·n.
    Rgb fresnel_at_normal(const SurfaceLobe &l) const {
        const float c = std::clamp(wo_.z, 0.0f, 1.0f);
        const float f0 = fresnel_dielectric(1.0f, l.ior);
        const float s = (fresnel_dielectric(c, l.ior) - f0) / (1.0f - f0);
        return (l.f0 * (1.0f - s) + Rgb(s)) * l.fresnel_scale;
    }

    void principled_4(const PrincipledBsdfNode &pr, Rgb w) {
        const GgxAlbedoTables &tables = GgxAlbedoTables::tables();
        const Rgb base = max0(pr.base_color.at(p_.u, p_.v));
        const Rgb clamped_base = min1(base);
        const float metallic = saturate(pr.metallic), ss = saturate(pr.subsurface);
        const float level = std::max(pr.specular, 0.0f), roughness = saturate(pr.roughness);
        const Rgb tint = max0(pr.specular_tint_color);
        const float ior = std::max(pr.ior, 1e-5f);
        const float alpha = roughness * roughness;
        const float mu = wo_.z;

        // Coat.
        const float coat = std::max(pr.coat, 0.0f);
        if (coat > kCutoff) {
            const float coat_roughness = saturate(pr.coat_roughness);
            const float coat_ior = std::max(pr.coat_ior, 1.0f);
            SurfaceLobe l = ggx_lobe(w * coat, coat_roughness * coat_roughness,
                                     MicrofacetShadowing::Correlated, MicrofacetFresnel::Dielectric);
            l.ior = coat_ior;
            preserve_energy(l, coat_roughness, mu, Rgb(dielectric_fss(coat_ior)));
            const float estimate =
                coat_ior > 1.0f
                    ? f0_from_ior(coat_ior) +
                          (1.0f - f0_from_ior(coat_ior)) *
                              tables.s_ior(coat_roughness, mu, ior_coordinate(coat_ior))
                    : fresnel_dielectric(std::clamp(mu, 0.0f, 1.0f), coat_ior);
            l.select = std::fabs(average(l.weight)) * estimate;
            add(l);
            w = layering_weight(l.weight * estimate, w);
            const Rgb coat_tint = max0(pr.coat_tint);
            if (!is_one(coat_tint)) {
                const float cos_t = std::sqrt(std::max(0.0f, 1.0f - sqr(1.0f / coat_ior) * (1.0f - mu * mu)));
                w *= mix(Rgb(1.0f), pow(coat_tint, 1.0f / cos_t), coat);
            }
        }

        // Metallic.
        if (metallic > kCutoff) {
            SurfaceLobe l = ggx_lobe(w * metallic, alpha, MicrofacetShadowing::Correlated,
                                     MicrofacetFresnel::F82Tint);
            l.f0 = clamped_base;
            const Rgb f82 = min1(tint);
            l.f82_b = is_one(f82) ? Rgb(0.0f) : f82_tint_b(l.f0, f82);
            if (pr.multiscatter) preserve_energy(l, roughness, mu, f82_fss(l.f0, l.f82_b));
            const Rgb estimate = mix(l.f0, Rgb(1.0f), tables.s_exponent(roughness, mu, 0.5f));
            l.select = std::fabs(average(l.weight)) * average(estimate);
            add(l);
            w *= 1.0f - metallic;
        }

        // Specular: the IOR Level scales F0.
        float eta = ior, f0 = f0_from_ior(eta);
        if (level != 0.5f) {
            f0 *= 2.0f * level;
            eta = ior_from_f0(f0);
            if (ior < 1.0f) eta = 1.0f / eta;
        }
        if (eta != 1.0f) {
            SurfaceLobe l = ggx_lobe(w, alpha, MicrofacetShadowing::Correlated, MicrofacetFresnel::SchlickIor);
            l.ior = eta;
            l.f0 = saturate(tint * f0);
            if (pr.multiscatter) {
                const float real_f0 = f0_from_ior(eta);
                const float s = saturate((dielectric_fss(eta) - real_f0) / (1.0f - real_f0));
                preserve_energy(l, roughness, mu, mix(l.f0, Rgb(1.0f), s));
            }
            const Rgb estimate = mix(l.f0, Rgb(1.0f), tables.s_ior(roughness, mu, ior_coordinate(eta)));
            l.select = std::fabs(average(l.weight)) * average(estimate);
            add(l);
            w = layering_weight(l.weight * estimate, w);
        }

        // Diffuse (min(base, 1) × subsurface stands for the BSSRDF).
        if (pr.diffuse_roughness < kCutoff) {
            add(diffuse_lobe(SurfaceLobeKind::Lambert, (base * (1.0f - ss) + clamped_base * ss) * w));
        } else {
            add(oren_nayar_lobe(base * (1.0f - ss) * w, pr.diffuse_roughness, base, mu));
            add(diffuse_lobe(SurfaceLobeKind::Lambert, clamped_base * ss * w));
        }
    }

    const std::vector<SurfaceNode> &nodes_;
    const SurfaceShadingPoint &p_;
    SurfaceBsdf &bsdf_;
    Vec3 wo_;
};

// Lobes a node can produce at most, and its version (-1: none).
int lobe_bound(const SurfaceNode &node, const std::vector<int> &bounds) {
    if (const auto *mix = std::get_if<MixShaderNode>(&node))
        return bounds[std::size_t(mix->first)] + bounds[std::size_t(mix->second)];
    if (const auto *add = std::get_if<AddShaderNode>(&node))
        return bounds[std::size_t(add->first)] + bounds[std::size_t(add->second)];
    if (const auto *pr = std::get_if<PrincipledBsdfNode>(&node)) return pr->cycles == CyclesVersion::V3_4 ? 4 : 5;
    if (std::holds_alternative<EmissionNode>(node)) return 0;
    return 1;
}

int version_of(const SurfaceNode &node) {
    if (const auto *pr = std::get_if<PrincipledBsdfNode>(&node)) return int(pr->cycles);
    if (const auto *d = std::get_if<DiffuseBsdfNode>(&node)) return int(d->cycles);
    if (const auto *g = std::get_if<GlossyBsdfNode>(&node)) return int(g->cycles);
    return -1;
}

Status check_finite(const std::string &what, float v) {
    if (!std::isfinite(v)) return Error{what + " must be finite (got " + std::to_string(v) + ")"};
    return std::nullopt;
}
Status check_color(const std::string &what, Rgb c) {
    for (int k = 0; k < 3; ++k)
        if (!std::isfinite(c[k]) || c[k] < 0.0f)
            return Error{what + " must be finite and >= 0 (got " + std::to_string(c.r) + ", " +
                         std::to_string(c.g) + ", " + std::to_string(c.b) + ")"};
    return std::nullopt;
}

Status check_node(const SurfaceNode &node, const std::string &name) {
    if (const auto *pr = std::get_if<PrincipledBsdfNode>(&node)) {
        return first_error(check_color(name + " base color", pr->base_color.value),
                           check_finite(name + " metallic", pr->metallic),
                           check_finite(name + " roughness", pr->roughness),
                           check_finite(name + " ior", pr->ior),
                           check_finite(name + " specular", pr->specular),
                           check_finite(name + " specular tint", pr->specular_tint),
                           check_color(name + " specular tint", pr->specular_tint_color),
                           check_finite(name + " subsurface", pr->subsurface),
                           check_color(name + " subsurface color", pr->subsurface_color),
                           check_finite(name + " sheen", pr->sheen),
                           check_finite(name + " sheen tint", pr->sheen_tint),
                           check_finite(name + " coat", pr->coat),
                           check_finite(name + " coat roughness", pr->coat_roughness),
                           check_finite(name + " coat ior", pr->coat_ior),
                           check_color(name + " coat tint", pr->coat_tint),
                           check_finite(name + " diffuse roughness", pr->diffuse_roughness),
                           check_color(name + " emission", pr->emission));
    }
    if (const auto *d = std::get_if<DiffuseBsdfNode>(&node))
        return first_error(check_color(name + " color", d->color.value),
                           check_finite(name + " roughness", d->roughness));
    if (const auto *g = std::get_if<GlossyBsdfNode>(&node))
        return first_error(check_color(name + " color", g->color.value),
                           check_finite(name + " roughness", g->roughness));
    if (const auto *e = std::get_if<EmissionNode>(&node))
        return first_error(check_color(name + " color", e->color),
                           check_finite(name + " strength", e->strength),
                           e->strength < 0.0f ? Status(Error{name + " strength must be >= 0"}) : Status());
    if (const auto *m = std::get_if<MixShaderNode>(&node)) return check_finite(name + " factor", m->factor);
    return std::nullopt;
}

}  // namespace

Vec3 valid_reflection_normal(Vec3 ng, Vec3 wo, Vec3 n) {
    const Vec3 r = n * (2.0f * dot(n, wo)) - wo;
    const float iz = dot(wo, ng);
    const float threshold = std::min(0.9f * iz, 0.01f);
    if (dot(ng, r) >= threshold) return n;
    // The normal n' = sqrt(1 − q) x + sqrt(q) ng in the plane of n and ng whose reflection
    // makes `threshold` with ng: 2 (n'·ω_o)(n'·ng) − ω_o·ng = threshold, a quadratic in q
    // after squaring; the root that solves the unsquared equation has the sign of ω_o·x.
    const Vec3 x = safe_normalize(n - ng * dot(n, ng));
    if (!(dot(x, x) > 0.0f)) return n;
    const float ix = dot(wo, x);
    const float a = ix * ix + iz * iz;
    if (!(a > 0.0f)) return n;
    const float b = std::sqrt(std::max(0.0f, ix * ix * (a - threshold * threshold)));
    const float c = iz * threshold + a;
    const float q = std::clamp((ix < 0.0f ? c + b : c - b) / (2.0f * a), 0.0f, 1.0f);
    return safe_normalize(x * std::sqrt(1.0f - q) + ng * std::sqrt(q));
}

Expected<SurfaceMaterial> SurfaceMaterial::create(std::vector<SurfaceNode> nodes) {
    if (nodes.empty()) return Error{"surface material has no nodes"};
    SurfaceMaterial m;
    std::vector<int> bounds(nodes.size(), 0);
    int version = -1;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const std::string name = "surface node " + std::to_string(i);
        const SurfaceNode &node = nodes[i];
        auto child_ok = [&](int c) { return c >= 0 && std::size_t(c) < i; };
        if (const auto *mix = std::get_if<MixShaderNode>(&node)) {
            if (!child_ok(mix->first) || !child_ok(mix->second))
                return Error{name + " (Mix Shader): its inputs must be nodes before it, in [0, " +
                             std::to_string(i) + ") (got " + std::to_string(mix->first) + " and " +
                             std::to_string(mix->second) + ")"};
        }
        if (const auto *add = std::get_if<AddShaderNode>(&node)) {
            if (!child_ok(add->first) || !child_ok(add->second))
                return Error{name + " (Add Shader): its inputs must be nodes before it, in [0, " +
                             std::to_string(i) + ") (got " + std::to_string(add->first) + " and " +
                             std::to_string(add->second) + ")"};
        }
        if (auto e = check_node(node, name)) return *e;
        const int v = version_of(node);
        if (v >= 0) {
            if (version >= 0 && v != version)
                return Error{name + ": every BSDF node of a material must follow the same Cycles "
                                    "version (3.4 or 4.5)"};
            version = v;
        }
        bounds[i] = std::min(lobe_bound(node, bounds), 1 << 20);
    }
    if (bounds.back() > SurfaceBsdf::kMaxLobes)
        return Error{"surface material: its nodes can make " + std::to_string(bounds.back()) +
                     " BSDF lobes, more than the " + std::to_string(SurfaceBsdf::kMaxLobes) +
                     " a surface holds (fewer BSDF nodes under Mix and Add Shaders)"};
    m.max_lobes_ = bounds.back();
    m.cycles_ = version == 1 ? CyclesVersion::V4_5 : CyclesVersion::V3_4;

    // Emission: constant weights, so one radiance for the whole material.
    std::vector<Rgb> weights(nodes.size(), Rgb(0.0f));
    weights.back() = Rgb(1.0f);
    for (std::size_t i = nodes.size(); i-- > 0;) {
        const Rgb w = weights[i];
        if (!(w.max_component() > 0.0f)) continue;
        const SurfaceNode &node = nodes[i];
        if (const auto *mix = std::get_if<MixShaderNode>(&node)) {
            const float f = saturate(mix->factor);
            weights[std::size_t(mix->first)] += w * (1.0f - f);
            weights[std::size_t(mix->second)] += w * f;
        } else if (const auto *add = std::get_if<AddShaderNode>(&node)) {
            weights[std::size_t(add->first)] += w;
            weights[std::size_t(add->second)] += w;
        } else if (const auto *e = std::get_if<EmissionNode>(&node)) {
            m.emission_ += w * e->color * e->strength;
        } else if (const auto *pr = std::get_if<PrincipledBsdfNode>(&node)) {
            m.emission_ += w * pr->emission;
        }
    }
    m.nodes_ = std::move(nodes);
    return m;
}

Expected<SurfaceMaterial> SurfaceMaterial::combine(const SurfaceMaterial &a, const SurfaceMaterial &b,
                                                   std::optional<float> factor) {
    std::vector<SurfaceNode> nodes = a.nodes_;
    const int offset = int(nodes.size());
    for (SurfaceNode node : b.nodes_) {
        if (auto *mix = std::get_if<MixShaderNode>(&node)) {
            mix->first += offset;
            mix->second += offset;
        } else if (auto *add = std::get_if<AddShaderNode>(&node)) {
            add->first += offset;
            add->second += offset;
        }
        nodes.push_back(node);
    }
    const int first = offset - 1, second = int(nodes.size()) - 1;
    if (factor)
        nodes.push_back(MixShaderNode{*factor, first, second});
    else
        nodes.push_back(AddShaderNode{first, second});
    return create(std::move(nodes));
}

SurfaceBsdf SurfaceMaterial::prepare(const SurfaceShadingPoint &p) const {
    const Vec3 n = cycles_ == CyclesVersion::V3_4 ? valid_reflection_normal(p.ng, p.wo, p.n) : p.n;
    SurfaceBsdf bsdf(n, p.ng, p.wo);
    LobeBuilder(nodes_, p, bsdf).visit(int(nodes_.size()) - 1, Rgb(1.0f));
    if (cycles_ == CyclesVersion::V3_4 && p.camera_hit) bsdf.defend_selection(0.125f);
    return bsdf;
}

}  // namespace hairis
