#include "render/path_integrator.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <variant>

#include "core/rng.h"
#include "render/bsdf.h"
#include "render/sample_dims.h"

namespace hairis {

PathIntegrator::PathIntegrator(const Scene &scene, const RenderSettings &settings)
    : scene_(scene),
      settings_(settings),
      transparent_crossings_(transparent_crossings(TransparentLimit(settings.transparent_limit),
                                                   settings.max_transparent_bounces)),
      pixel_filter_(PixelFilterType(settings.pixel_filter), settings.pixel_filter_width) {}

namespace {

// Cycles' Normal pass at a surface: its shading normal turned towards the viewer, as Cycles
// turns N at a back-facing hit.
Vec3 first_hit_normal(const SurfacePoint &sp, Vec3 wo) {
    const Vec3 n = sp.shading_normal;
    return dot(sp.normal, wo) < 0.0f ? -n : n;
}

// Cycles' film_write_denoising_features_surface at a vertex the features still look for:
// writes them there (returns false, the features are done) or, through a specular vertex,
// carries the throughput on to the next (returns true).
bool write_denoising_features(const Bsdf &bsdf, FirstHit &first, Rgb &throughput) {
    const DenoisingFeatures d = bsdf.denoising_features();
    if (d.specular) {
        throughput *= d.specular_albedo;
        return true;
    }
    first.denoising_normal = d.normal;
    first.albedo += throughput * d.albedo;
    return false;
}

}  // namespace

Bsdf PathIntegrator::bsdf_at(const SurfacePoint &sp, const Material &material, Vec3 wo, int vertex,
                             float footprint, std::uint64_t seed, float blur_roughness,
                             const DualScatteringIntegrator &dual, ScratchBuffer &scratch) const {
    HitContext context;
    context.camera_ray = vertex == 0;
    context.footprint = footprint;
    context.seed = seed;
    context.blur_roughness = blur_roughness;
    // A vertex dual scattering may shade needs the strategy's sampler (its MIS needs a
    // density); the exact bounces before it are path-traced as integrator=path traces them.
    context.cycles_huang = settings_.huang_sampling == int(HuangSampling::Cycles) && !dual.may_shade(vertex);
    const HairInputValues *inputs = nullptr;
    const ClosureWeights *weights = nullptr;
    if (sp.is_curve) {
        HairInputValues values;
        ClosureWeights strand_weights;
        if (scene_.hair_inputs(sp, values, &strand_weights)) {
            inputs = &scratch.make<HairInputValues>(values);
            if (strand_weights.given) weights = &scratch.make<ClosureWeights>(strand_weights);
        }
    }
    return Bsdf(material, sp, wo, context, inputs, scratch, weights);
}

Rgb PathIntegrator::sample_ld(const SurfacePoint &sp, const Bsdf &bsdf, const SobolSampleRng &rng, int vertex,
                              PathCounters &counters) const {
    const auto ls = scene_.lights().sample(sp.position, rng.get(dim(vertex, kDimLightSelect)),
                                           rng.get(dim(vertex, kDimLightU)), rng.get(dim(vertex, kDimLightV)));
    if (!ls || !(ls->pdf > 0.0f)) return Rgb{0.0f};
    float light_dir_bsdf_pdf = 0.0f;
    const Rgb f = bsdf.eval(ls->wi, light_dir_bsdf_pdf);
    if (f.is_black()) return Rgb{0.0f};
    const float shadow_tmax = std::isinf(ls->distance) ? INFINITY : ls->distance * (1.0f - 1e-5f);
    ++counters.shadow_rays;
    const PrimRef target{ls->skip_geometry, ls->skip_primitive};
    if (scene_.occluded(sp.spawn_point(ls->wi), ls->wi, 0.0f, shadow_tmax, sp.self, target)) return Rgb{0.0f};
    const float w = ls->delta ? 1.0f : power_heuristic(ls->pdf, light_dir_bsdf_pdf);
    return f * ls->value * (w / ls->pdf);
}

bool PathIntegrator::count_bounce(PathState &path, bool hair, bool glossy) const {
    if (hair) return ++path.transmission_bounces > settings_.max_transmission_bounces;
    if (glossy) return ++path.glossy_bounces > settings_.max_glossy_bounces;
    return ++path.diffuse_bounces > settings_.max_diffuse_bounces;
}

Rgb PathIntegrator::li(int x, int y, std::uint64_t sample, float &alpha, PathCounters &counters,
                       ScratchBuffer &scratch, FirstHit *first) const {
    const Camera &camera = scene_.camera();
    const LightSet &lights = scene_.lights();
    const std::uint64_t pixel = std::uint64_t(y) * std::uint64_t(camera.width()) + std::uint64_t(x);
    // Stratified per pixel (jitter, light and BSDF pairs): hair is thinner than a pixel, and
    // stratifying where a sample lands in the pixel is what Cycles' Sobol patterns buy it.
    const SobolSampleRng rng(settings_.seed, pixel, sample);
    const SampleRng seeds(settings_.seed, pixel, sample);

    const CameraRay cr = camera.generate_ray(x, y, pixel_filter_.position(rng.get(kDimJitterU)),
                                             pixel_filter_.position(rng.get(kDimJitterV)));
    PathRay ray{cr.origin, cr.direction, cr.origin, cr.tmin, cr.tmax, PrimRef{}};
    PathState path(counters);
    path.clamp_direct = settings_.clamp_direct;
    path.clamp_indirect = settings_.clamp_indirect;
    DualScatteringIntegrator dual(scene_, settings_);
    alpha = 1.0f;
    // Cycles' PATH_RAY_DENOISING_FEATURES and denoising_feature_throughput: until the features
    // are written, the light the path meets also adds to the albedo.
    bool features = first != nullptr;
    Rgb feature_throughput(1.0f);
    auto reached = [&](Rgb light) {
        path.add_reached(light);
        if (features && !light.is_black()) first->albedo += feature_throughput * path.beta * light;
    };

    for (;;) {
        std::optional<Hit> hit;
        bool through_hair = false;  // a dual continuation that crossed strands to a mesh
        if (dual.traces_through_hair()) {
            if (!dual.trace_through_hair(path, ray, hit, through_hair)) break;
        } else {
            hit = scene_.intersect(ray.origin, ray.dir, ray.tmin, ray.tmax, ray.skip);
            ++counters.rays;
        }
        const float t_end = hit ? hit->t : ray.tmax;

        // Lamps are transparent: every one crossed before the surface contributes.
        if (!through_hair)
            reached(lights.lamps_along_ray(ray.origin, ray.dir, ray.tmin, t_end, path.prev_bsdf_pdf, path.use_mis,
                                           ray.from));

        if (!hit) {
            const bool transparent = path.vertex == 0 && settings_.film_transparent;
            if (transparent) alpha = 0.0f;
            reached(lights.escaped(ray.from, ray.dir, path.prev_bsdf_pdf, path.use_mis, !transparent));
            break;
        }

        const SurfacePoint sp = scene_.surface_point(ray.origin, ray.dir, *hit);
        if (dual.ends_at(sp)) break;
        const Material &material = scene_.materials()[sp.material];
        const Vec3 wo = -ray.dir;

        // Surface emission (mesh triangles are light-sampled, curves are not).
        if (const Rgb emission = material_emission(material); !emission.is_black() && !through_hair) {
            float w = 1.0f;
            if (path.use_mis && sp.is_light) {
                const float abs_cos = std::fabs(dot(sp.normal, ray.dir));
                w = power_heuristic(path.prev_bsdf_pdf, lights.emissive_triangle_pdf(hit->t, abs_cos));
            }
            reached(emission * w);
        }

        // A terminating ray shades nothing (Cycles evaluates no closures for it, so Huang's
        // transparency does not apply either).
        if (path.vertex > settings_.max_bounces || path.last_segment) break;

        scratch.reset();  // the previous vertex's BSDF is done with
        const Bsdf bsdf = bsdf_at(sp, material, wo, path.vertex, cr.footprint_at(hit->t),
                                  vertex_seed(seeds, path.vertex),
                                  glossy_blur_roughness(settings_.filter_glossy, path.min_ray_pdf), dual, scratch);
        if (bsdf.transparent()) {
            // The same ray goes on beyond this curve.
            path.last_segment = ++path.transparent_bounces >= transparent_crossings_;
            ray.tmin = hit->t;
            ray.skip = sp.self;
            continue;
        }
        if (first && path.vertex == 0) {
            first->found = true;
            first->position = sp.position;
            first->normal = first_hit_normal(sp, wo);
        }
        if (features) features = write_denoising_features(bsdf, *first, feature_throughput);
        if (bsdf.black()) break;

        // Light a mesh reflects onto the dual vertex the ray left.
        if (!dual.add_mesh_light(path, ray.dir, through_hair)) break;

        // Russian roulette.
        if (path.vertex >= settings_.rr_start_bounce) {
            const float q = std::min(1.0f, std::sqrt(path.beta.max_component()));
            if (!(rng.get(dim(path.vertex, kDimRoulette)) < q)) break;
            path.beta = path.beta / q;
        }

        // Next-event estimation (the dual-scattering estimate at the vertex that closes the path).
        const bool closes = dual.closes_path(material, bsdf, path);
        if (closes) {
            dual.add_light(path, sp, bsdf, wo, rng);
        } else if (!lights.empty()) {
            path.add(path.beta * sample_ld(sp, bsdf, rng, path.vertex, counters));
        }

        // Continue along a BSDF sample.
        const float u0 = rng.get(dim(path.vertex, kDimBsdf0)), u1 = rng.get(dim(path.vertex, kDimBsdf1)),
                    u2 = rng.get(dim(path.vertex, kDimBsdf2));
        Vec3 wi;
        Rgb weight;
        float scatter_pdf = 0.0f, cycles_pdf = INFINITY;
        bool glossy = false;
        float *filter = settings_.filter_glossy > 0.0f ? &cycles_pdf : nullptr;
        if (!(closes ? dual.sample_continuation(path, bsdf, wo, rng, u0, u1, u2, wi, weight, scatter_pdf, glossy)
                     : bsdf.sample(u0, u1, u2, wi, weight, scatter_pdf, glossy, filter)))
            break;
        if (filter) path.min_ray_pdf = std::min(path.min_ray_pdf, closes ? scatter_pdf : cycles_pdf);
        dual.leave(path, sp, bsdf, wo, wi);
        path.last_segment = count_bounce(path, bsdf.is_hair(), glossy);
        path.beta *= weight;
        if (!finite(path.beta)) {
            ++counters.dropped;
            break;
        }
        // A layer's continuation may carry the multiple term where f_s is 0: it decides there.
        if (path.beta.is_black() && !dual.traces_through_hair()) break;
        ray = PathRay{sp.spawn_point(wi), wi, sp.position, 0.0f, INFINITY, sp.self};
        path.prev_bsdf_pdf = scatter_pdf;
        path.use_mis = true;
        ++path.vertex;
    }
    return path.radiance;
}

}  // namespace hairis
