// The path tracer behind render(): one camera sample's path, as pbrt-v4's PathIntegrator::Li
// reads, rendering a Scene the way Cycles renders the same Blender scene (same light units,
// curve shape, hair BSDF and bounce count; lights and Chiang as the materials' Cycles version
// says, Huang as Cycles 4.5/5.0).
//
// Per camera sample (the vertex where the camera ray lands is vertex 0):
//  - Emission: a ray that reaches an emitter adds throughput × radiance, weighted by the power
//    heuristic against light sampling when the emitter can be light-sampled (point and spot
//    disks or spheres, area lights, suns with a disc, an Environment Texture world whose
//    Sampling is not None, emissive mesh triangles); camera rays and emitters that are never
//    light-sampled (a constant world, as in Cycles; a world with Sampling None; emissive
//    curves) take weight 1; delta lights cannot be hit. Lamps are transparent to rays, as in
//    Cycles (kernel/integrator/shade_light.h): every lamp crossed before the next surface
//    contributes.
//  - Diffuse, glossy and transmission limits the same way, per kind of bounce (see
//    RenderSettings).
//  - Filter Glossy and Clamping as Cycles applies them (render/filter_glossy.h): a vertex
//    widens its glossy closures by the least density Cycles would have recorded for the
//    path's BSDF samples (Bsdf::sample's cycles_pdf), and every contribution is clamped by
//    the bounce it belongs to.
//  - Max bounces as Cycles' "Max Bounces: Total" (scene/integrator.cpp stores max_bounce + 1
//    "so that a bounce of 0 indicates no global illumination, only direct illumination"):
//    vertices ≤ max_bounces are shaded (next-event estimation + a BSDF-sampled
//    continuation); the continuation ray of the last shaded vertex still collects MIS-weighted
//    emission, then the path ends. max_bounces = 0 is direct lighting only.
//  - Next-event estimation at every shaded vertex: one light chosen as LightSet::sample
//    documents (uniformly among lamps, the environment world being one, Cycles 3.4's choice;
//    emissive triangles by area),
//    a shadow ray (hair, like everything, is opaque to it), MIS with the BSDF's density.
//  - BSDF sampling: surfaces sample their lobes as one mixture with its exact density
//    (surface_bsdf.h; a Lambertian surface: the cosine-weighted hemisphere around the normal
//    facing ω_o). Hair samples through its material's HairShading: at each hit one HairBsdf
//    (the fiber model and its strategy's sampler prepared once, sampling/hair_bsdf.h) in
//    the fiber frame of frame.h (FiberFrame::from_tangent_and_view(tangent, ω_o), Cycles'
//    frame) at h = dot(cross(Ng, X), Z) (Cycles' bsdf_principled_hair_setup for 3D curves);
//    the light sample takes f and pdf from it in one call, the BSDF sample comes with f, and
//    the throughput is multiplied by f·|cos θ_i| / pdf (render/bsdf.h).
//    Where the curve set gives node inputs per curve or point (scene.h's CurveInput), f is
//    the strand's own fiber at the hit's interpolated inputs (chiang_strands.h), and so is
//    what the sampler follows.
//  - Huang hair (Cycles 4.5/5.0, kernel/svm/closure.h and bsdf_hair_huang_setup): the FiberHit
//    carries the curve normal (the ellipse's major axis; Cycles' fallback frame around the
//    world tangent where the curve has none, as for particle hair), pixel_coverage = half the
//    camera ray's footprint at the hit / the curve radius for camera rays (1 for all others:
//    the near field only where a fiber is wider than a pixel) and a per-vertex seed. Where
//    Huang is transparent (the ray passes outside the ellipse inscribed in the round tube)
//    the ray continues unchanged: no bounce, same camera flag, footprint and MIS state, the
//    curve skipped, counted against max_transparent_bounces. Rays past a bounce limit and
//    shadow rays see Huang hair opaque, as in Cycles (terminating rays evaluate no closures;
//    curves' shadow transparency is baked per point with a view through the axis, h = 0).
//  - Russian roulette from vertex rr_start_bounce on, with Cycles' survival probability
//    min(1, sqrt(max throughput component)) and division by it (unbiased).
//  - integrator=dual_scattering: at hair vertices next-event estimation is replaced by the
//    dual-scattering estimate (render/dual_scattering_integrator.h: light, probe and
//    multiple-table samples whose shadow rays let hair through), the continuation is drawn as
//    above and a continuation that then reaches hair ends there. Meshes are path-traced. The
//    path calls DualScatteringIntegrator's hooks for all of it.
//  - A contribution that is NaN or infinite is dropped (counted in PathCounters), never
//    accumulated; a non-finite throughput ends the path (counted too).
//
// Camera samples land in and around their pixel as Cycles' pixel filter places them
// (render/pixel_filter.h).
//
// Random numbers: render/sample_dims.h's dimensions of a SobolSampleRng per camera sample.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/rng.h"
#include "core/scratch.h"
#include "render/dual_scattering_integrator.h"
#include "render/filter_glossy.h"
#include "render/pixel_filter.h"
#include "render/render_settings.h"
#include "render/scene.h"

namespace hairis {

inline bool finite(Rgb c) { return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b); }

/// A render thread's counts and buffers, kept across its samples.
struct PathCounters {
    std::uint64_t rays = 0, shadow_rays = 0, dropped = 0;
    DualWork dual;  ///< the dual-scattering estimate's buffers and counts
};

/// The ray a path follows to its next vertex: from `origin` along unit `dir` over (tmin, tmax),
/// the primitive `skip` left out.
struct PathRay {
    Vec3 origin, dir;
    Vec3 from;  ///< the vertex the ray left: where its light sample was drawn
    float tmin = 0, tmax = INFINITY;
    PrimRef skip;
};

/// What a path carries from one vertex to the next.
struct PathState {
    explicit PathState(PathCounters &counters_) : counters(&counters_) {}

    /// The index of the vertex the ray goes to (the camera's hit is 0); a transparent crossing
    /// keeps it.
    int vertex = 0;
    Rgb beta{1.0f};  ///< the throughput
    Rgb radiance;
    /// The density of the BSDF sample that made the ray, for MIS of the emission it reaches.
    float prev_bsdf_pdf = 0;
    bool use_mis = false;  ///< false for the camera ray: emission at full weight
    int diffuse_bounces = 0, glossy_bounces = 0, transmission_bounces = 0, transparent_bounces = 0;
    bool last_segment = false;  ///< a bounce limit was reached: only emission at the next hit

    /// Cycles' Clamping: Direct and Indirect (RenderSettings; 0: off).
    float clamp_direct = 0, clamp_indirect = 0;
    /// The least density Cycles records for the path's BSDF samples so far (Filter Glossy).
    float min_ray_pdf = INFINITY;
    PathCounters *counters;

    /// Adds light scattered at the current vertex (next-event estimation there), clamped as
    /// Cycles clamps light at that bounce; a NaN or infinite one is dropped and counted.
    void add(Rgb contribution) { add_at_bounce(contribution, vertex); }
    /// Adds the light the ray meets, times the throughput (nothing when it is black), clamped
    /// as light at the bounce the ray left.
    void add_reached(Rgb light) {
        if (!light.is_black()) add_at_bounce(beta * light, vertex - 1);
    }

  private:
    // Cycles' film_clamp_light: Direct up to bounce 0 (the camera's vertex), Indirect beyond.
    void add_at_bounce(Rgb contribution, int bounce) {
        if (finite(contribution))
            radiance += clamp_contribution(contribution, bounce > 0 ? clamp_indirect : clamp_direct);
        else
            ++counters->dropped;
    }
};

/// What the data passes read where a camera path first meets a surface that is not
/// transparent (Huang hair the ray passes is not that surface), as Cycles writes them there,
/// and Cycles' denoising features: the normal at the first vertex that is not specular
/// (DenoisingFeatures) and the albedo summed along the way to it, light met included.
struct FirstHit {
    bool found = false;  ///< false: the camera ray met no such surface
    Vec3 position;
    Vec3 normal;  ///< the shading normal in world space, on the side of the ray's origin
    Vec3 denoising_normal{0, 0, 0};  ///< world space; 0 where the path found no such vertex
    Rgb albedo{0.0f};                ///< Cycles' denoising albedo
};

/// The path tracer of one render (settings validated by render()).
class PathIntegrator {
  public:
    PathIntegrator(const Scene &scene, const RenderSettings &settings);

    /// The radiance of camera sample `sample` through pixel (x, y) (pbrt's Li); alpha receives
    /// the sample's coverage. `scratch` holds each vertex's BSDF.
    /// `first` (may be null) receives the data passes' first surface.
    Rgb li(int x, int y, std::uint64_t sample, float &alpha, PathCounters &counters,
           ScratchBuffer &scratch, FirstHit *first = nullptr) const;

  private:
    /// The BSDF at a path vertex, with the strand's inputs and closure weights and Filter
    /// Glossy's widening, made in scratch.
    Bsdf bsdf_at(const SurfacePoint &sp, const Material &material, Vec3 wo, int vertex, float footprint,
                 std::uint64_t seed, float blur_roughness, const DualScatteringIntegrator &dual,
                 ScratchBuffer &scratch) const;
    /// Next-event estimation at a vertex (pbrt's SampleLd): one light sample, MIS-weighted
    /// against the BSDF's density, without the path's throughput.
    Rgb sample_ld(const SurfacePoint &sp, const Bsdf &bsdf, const SobolSampleRng &rng, int vertex,
                  PathCounters &counters) const;
    /// Counts a bounce against Cycles' limit for its kind (every hair bounce is transmission);
    /// true when the limit is passed.
    bool count_bounce(PathState &path, bool hair, bool glossy) const;

    const Scene &scene_;
    const RenderSettings &settings_;
    int transparent_crossings_;  ///< transparent_crossings() of the settings
    PixelFilter pixel_filter_;   ///< where in its pixel a camera sample lands
};

}  // namespace hairis
