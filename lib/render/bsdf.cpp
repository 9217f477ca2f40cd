#include "render/bsdf.h"

#include <algorithm>
#include <cmath>
#include <variant>

#include "fiber/chiang.h"
#include "sampling/analytic_sampler.h"

namespace hairis {

float cycles_pixel_coverage(float footprint, float curve_radius) {
    return curve_radius > 0.0f ? 0.5f * footprint / curve_radius : INFINITY;
}

FiberHit fiber_hit(const SurfacePoint &sp, Vec3 wo, const FiberFrame &frame, const HitContext &context,
                   bool oriented) {
    FiberHit hit;
    hit.wo = frame.to_local(wo);
    hit.blur_roughness = context.blur_roughness;
    const bool back = back_facing(sp, wo);
    const Vec3 ng = back ? -sp.normal : sp.normal, tangent = back ? -sp.tangent : sp.tangent;
    // Cycles: ribbons take h from the hit's place across the strip, round curves from Ng.
    hit.h = std::clamp(sp.is_ribbon ? -sp.curve_v : dot(cross(ng, frame.x), frame.z), -1.0f, 1.0f);
    if (!oriented) return hit;
    // Huang's major axis: the curve normal, or Cycles' arbitrary frame where there is none.
    const Vec3 axis = HuangFiber::major_axis(tangent, sp.curve_normal);
    hit.normal = frame.to_local(dot(axis, axis) > 0.0f ? axis : HuangFiber::fallback_major_axis(tangent));
    hit.pixel_coverage = context.camera_ray ? cycles_pixel_coverage(context.footprint, sp.curve_radius) : 1.0f;
    hit.seed = context.seed;
    return hit;
}

FiberHit cycles_fiber_hit(const SurfacePoint &sp, Vec3 wo, bool camera_ray, float footprint,
                          std::uint32_t seed) {
    return fiber_hit(sp, wo, hair_frame(sp, wo), HitContext{camera_ray, footprint, seed});
}

std::optional<FiberHit> camera_hair_hit(const Scene &scene, int x, int y, float u, float v) {
    const CameraRay cr = scene.camera().generate_ray(x, y, u, v);
    float tmin = cr.tmin;
    PrimRef skip;
    ScratchBuffer scratch;
    for (;;) {
        const std::optional<Hit> hit = scene.intersect(cr.origin, cr.direction, tmin, cr.tmax, skip);
        if (!hit) return std::nullopt;
        const SurfacePoint sp = scene.surface_point(cr.origin, cr.direction, *hit);
        const auto *hair = std::get_if<HairMaterial>(&scene.materials()[sp.material]);
        if (!hair) return std::nullopt;
        const FiberHit fh = cycles_fiber_hit(sp, -cr.direction, true, cr.footprint_at(hit->t), 0);
        scratch.reset();
        if (!hair->shading.at(fh, scratch).transparent()) return fh;
        tmin = hit->t;
        skip = sp.self;
    }
}

Bsdf::Bsdf(const Material &material, const SurfacePoint &sp, Vec3 wo, const HitContext &context,
           const HairInputValues *inputs, ScratchBuffer &scratch, const ClosureWeights *weights) {
    if (const auto *hair = std::get_if<HairMaterial>(&material)) {
        frame_ = hair_frame(sp, wo);
        if (hair->mixture) {
            // Every closure shades the same hit with the same inputs; Cycles' own Huang
            // sampler has no density to mix with, so mixtures use the material's strategy.
            FiberHit hit = fiber_hit(sp, wo, frame_, context);
            hit.inputs = inputs;
            mixture_.emplace(hair->mixture->at(hit, weights, scratch));
            return;
        }
        const ShadingModel *model = hair->shading.model();
        FiberHit hit = fiber_hit(sp, wo, frame_, context, !model || model->reads_orientation());
        hit.inputs = inputs;
        // Cycles' own Huang sampler samples the hit's own fiber (a strand's, with its inputs);
        // the model's point shades it (a tabulated model's with the baked f).
        if (context.cycles_huang && model && model->as_huang()) {
            huang_f_ = &model->prepare(hit, scratch);
            huang_ = huang_f_->huang_point();
        }
        if (huang_) {
            lcg_.state = hit.seed ^ 0x9e3779b9u;
            return;
        }
        // HairShading::at, except that lobes Filter Glossy widened take the analytic sampler:
        // the material's tables were baked for its own lobes.
        const FiberPoint *fiber = model ? &model->prepare(hit, scratch) : nullptr;
        const ChiangPoint *chiang = fiber ? fiber->chiang_point() : nullptr;
        hair_.emplace(fiber, chiang && chiang->blurred() ? analytic_point(*chiang, scratch)
                                                        : hair->shading.sampler().at(hit, fiber, scratch));
        return;
    }
    const bool back = back_facing(sp, wo);
    const Vec3 ng = back ? -sp.normal : sp.normal;
    if (const auto *surface = std::get_if<SurfaceMaterial>(&material)) {
        const Vec3 n = back ? -sp.shading_normal : sp.shading_normal;
        surface_ = surface->prepare({wo, n, ng, sp.u, sp.v, context.camera_ray});
        if (context.blur_roughness > 0.0f) surface_.blur(context.blur_roughness);
    } else {
        const auto &d = std::get<DiffuseMaterial>(material);
        surface_ = SurfaceBsdf(ng, ng, wo);
        SurfaceLobe lambert;
        lambert.kind = SurfaceLobeKind::Lambert;
        lambert.weight = d.albedo;
        lambert.select = 1.0f;
        surface_.add(lambert);
    }
}

namespace {

// The density Cycles records for a hair closure's sample at local ω_i: a Chiang closure's
// F_energy (the analytic sampler's density; with 3.4's tilt on θ_i Cycles' F_energy tilts θ_i
// where the sampler tilts θ_o, a difference of the cuticle angle), 1 for Huang, else `pdf`.
// `analytic`: `pdf` is already the analytic density (the closure's widened point drew ω_i).
float cycles_hair_pdf(const HairBsdf &hair, Vec3 local_wi, float pdf, bool analytic) {
    const FiberPoint *fiber = hair.fiber();
    if (!fiber) return pdf;
    if (const ChiangPoint *chiang = fiber->chiang_point()) return analytic ? pdf : chiang->pdf(local_wi);
    return fiber->huang_point() ? 1.0f : pdf;
}

}  // namespace

bool Bsdf::sample(float u0, float u1, float u2, Vec3 &wi, Rgb &weight, float &pdf, bool &glossy,
                  float *cycles_pdf) const {
    glossy = false;
    if (huang_) {
        const std::optional<HuangCyclesSample> s = huang_->sample_cycles(u0, u1, u2, lcg_);
        if (!s) return false;
        wi = safe_normalize(frame_.to_world(s->wi));
        pdf = 1.0f;
        if (cycles_pdf) *cycles_pdf = 1.0f;
        weight = s->weight;
        return dot(wi, wi) > 0.0f;
    }
    if (hair_ || mixture_) {
        const std::optional<BsdfSample> s = hair_ ? hair_->sample(u0, u1, u2) : mixture_->sample(u0, u1, u2);
        if (!s || !(s->pdf > 0.0f)) return false;
        wi = safe_normalize(frame_.to_world(s->wi));
        pdf = s->pdf;
        weight = s->f / pdf;
        if (cycles_pdf) {
            if (hair_) {
                const ChiangPoint *chiang = hair_->fiber() ? hair_->fiber()->chiang_point() : nullptr;
                *cycles_pdf = cycles_hair_pdf(*hair_, s->wi, pdf, chiang && chiang->blurred());
            } else {
                float sum = 0.0f, total = 0.0f;
                for (int k = 0; k < mixture_->size(); ++k) {
                    const float w = std::fabs(mixture_->weight(k));
                    sum += w * cycles_hair_pdf(mixture_->part(k), s->wi, mixture_->part(k).pdf(s->wi), false);
                    total += w;
                }
                *cycles_pdf = total > 0.0f ? sum / total : pdf;
            }
        }
        return dot(wi, wi) > 0.0f;
    }
    return surface_.sample(u0, u1, u2, wi, weight, pdf, &glossy, cycles_pdf);
}

DenoisingFeatures Bsdf::denoising_features() const {
    DenoisingFeatures d;
    float sum_weight = 0.0f, sum_diffuse = 0.0f;
    // One closure: its albedo, normal and sample weight (Cycles': |average(weight)|, times
    // the albedo estimate for microfacet closures).
    auto add = [&](Rgb albedo, Vec3 n, float sample_weight, bool specular) {
        d.normal = d.normal + n * sample_weight;
        sum_weight += sample_weight;
        if (specular) {
            d.specular_albedo += albedo;
        } else {
            d.albedo += albedo;
            sum_diffuse += sample_weight;
        }
    };
    // A hair closure: Cycles' transparent one where the ray passes, which is specular.
    auto add_fiber = [&](float w, const FiberPoint *fiber) {
        if (!fiber || fiber->transparent()) return add(Rgb(w), Vec3{0, 0, 0}, std::fabs(w), true);
        const Vec3 n = fiber->tangent_is_denoising_normal() ? frame_.x : frame_.y;
        add(fiber->albedo() * w, n, std::fabs(w), false);
    };
    if (huang_) {
        add_fiber(1.0f, huang_);
    } else if (hair_) {
        add_fiber(1.0f, hair_->fiber());
    } else if (mixture_) {
        for (int k = 0; k < mixture_->size(); ++k) add_fiber(mixture_->weight(k), mixture_->part(k).fiber());
    } else {
        for (int k = 0; k < surface_.lobe_count(); ++k) {
            const SurfaceLobe &l = surface_.lobe(k);
            const Rgb albedo = l.weight * lobe_denoising_albedo(l, surface_.local_wo());
            const Rgb sampled = l.kind == SurfaceLobeKind::Microfacet ? albedo : l.weight;
            add(albedo, surface_.normal(), std::fabs(sampled.r + sampled.g + sampled.b) / 3.0f, lobe_is_specular(l));
        }
    }
    // Cycles writes unless 3/4 or more of the sample weight is specular.
    d.specular = sum_weight > 0.0f && !(sum_diffuse * 4.0f > sum_weight);
    if (sum_weight > 0.0f) d.normal = d.normal / sum_weight;
    return d;
}

}  // namespace hairis
