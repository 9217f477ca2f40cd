// The hair path tracer behind the "Hairis" render engine: renders a Scene the way Cycles
// renders the same Blender scene (same light units, curve shape, hair BSDF and bounce count;
// lights and Chiang as the materials' Cycles version says, Huang as Cycles 4.5/5.0).
//
// Integrator (per camera sample; the vertex where the camera ray lands has depth 0):
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
//    Cycles' "Filter Glossy" (Blender's default 1.0) blurs hair seen after a diffuse or
//    glossy bounce; hairis never blurs: compare against Cycles with Filter Glossy 0.
//  - Max bounces as Cycles' "Max Bounces: Total" (scene/integrator.cpp stores max_bounce + 1
//    "so that a bounce of 0 indicates no global illumination, only direct illumination"):
//    vertices of depth ≤ max_bounces are shaded (next-event estimation + a BSDF-sampled
//    continuation); the continuation ray of the last shaded vertex still collects MIS-weighted
//    emission, then the path ends. max_bounces = 0 is direct lighting only.
//  - Next-event estimation at every shaded vertex: one light chosen as LightSet::sample
//    documents (uniformly among lamps, the environment world being one, Cycles 3.4's choice;
//    emissive triangles by area),
//    a shadow ray (hair, like everything, is opaque to it), MIS with the BSDF's density.
//  - BSDF sampling: surfaces sample their lobes as one mixture with its exact density
//    (surface_bsdf.h; a Lambertian surface: the cosine-weighted hemisphere around the normal
//    facing ω_o). Hair samples through its material's HairShading: at each hit one HairBsdf
//    (the fiber model and its strategy's sampler prepared once, lib/sampling/hair_bsdf.h) in
//    the fiber frame of frame.h (FiberFrame::from_tangent_and_view(tangent, ω_o), Cycles'
//    frame) at h = dot(cross(Ng, X), Z) (Cycles' bsdf_principled_hair_setup for 3D curves);
//    the light sample takes f and pdf from it in one call, the BSDF sample comes with f, and
//    the throughput is multiplied by f·|cos θ_i| / pdf.
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
//  - Russian roulette from depth rr_start_bounce on, with Cycles' survival probability
//    min(1, sqrt(max throughput component)) and division by it (unbiased).
//  - integrator=dual_scattering: at hair vertices next-event estimation is replaced by the
//    dual-scattering estimate (render/dual_scattering_integrator.h: light, probe and
//    multiple-table samples whose shadow rays let hair through), the continuation is drawn as
//    above and a continuation that then reaches hair ends there. Meshes are path-traced.
//  - A contribution that is NaN or infinite is dropped (counted in RenderStats), never
//    accumulated; a non-finite throughput ends the path (counted too).
//
// Determinism: every random number is rng.h's SobolSampleRng (padded Owen-scrambled Sobol,
// stratified per pixel), a pure function of (seed, pixel, sample, dimension); pixel
// = y·width + x with y = 0 the bottom row, and each pixel accumulates its samples in sample
// order in double precision, so the image is bit-identical for any thread count and tile
// schedule.
//
// Threads and cancelling: the image is cut into tile_size² tiles rendered by oneTBB on at most
// `threads` threads (a task arena). Each tile renders all samples of its pixels, one pass of
// one sample per pixel at a time, and checks the cancel flag before every pass, so a cancel
// takes effect within one pass of one tile (milliseconds). The progress callback is only ever
// called on the thread that called render(), about every 50 ms; returning false cancels.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>

#include "core/expected.h"
#include "fiber/fiber_point.h"
#include "render/scene.h"

namespace hairis {

/// How hair vertices are shaded: path tracing (unbiased), or dual scattering
/// (render/dual_scattering_integrator.h), whose hair materials need HairMaterial::dual and
/// ::multiple.
enum class Integrator { Path = 0, DualScattering = 1 };

/// How Huang hair draws its BSDF samples.
enum class HuangSampling {
    /// The material's strategy (its sampler's exact density, MIS with it, f = Cycles' eval).
    Strategy = 0,
    /// Cycles 4.5/5.0's chained microfacet sampler with its own weight, and pdf 1 for MIS in
    /// both light and BSDF samples, as Cycles renders Huang. Its BSDF-sampled paths follow
    /// the sampler's weight, which is not Cycles' eval (docs/huang.md §8): what Cycles'
    /// images converge to, for comparing with them.
    Cycles = 1,
};

/// What the dual-scattering integrator takes the hair around a vertex to be.
enum class DualHairVolume {
    /// A layer over what is under it: the backscatter series (Ā_b) are cut at the strands a
    /// probe finds behind the vertex, and light meshes reflect onto the vertex through n ≥ 1
    /// strands is the global term (render/dual_scattering_integrator.h).
    Layer = 0,
    /// Zinke et al.'s semi-infinite hair volume: Ā_b unbounded, and the continuation ends at
    /// hair (mesh light reaches a hair vertex only where no strand is in the way).
    Unbounded = 1,
};

/// Which orders of scattering the dual-scattering vertex that closes a path adds.
enum class DualBounceLimit {
    /// Those the path tracer would reach: light that crossed n strands needs n more scattering
    /// events, and a backscatter series term through i strands behind 2i, within what Max
    /// Bounces and Max Transmission Bounces leave after the vertex (as Cycles ends its paths).
    Bounces = 0,
    /// Zinke et al.'s: every order, whatever the bounce limits.
    None = 1,
};

/// How Max Bounces: Transparent limits a path's transparent crossings, as each Cycles stores
/// the setting.
enum class TransparentLimit {
    /// Cycles up to 4.5 (kernel data transparent_max_bounce = setting + 1): setting + 1.
    PlusOne = 0,
    /// Cycles 5.0 (transparent_max_bounce = setting): the setting, and 1 for a setting of 0.
    Setting = 1,
};

/// The transparent surfaces a path may cross under `limit` with Max Bounces: Transparent
/// `setting` (>= 0); the surface after the last one ends the path.
int transparent_crossings(TransparentLimit limit, int setting);

/// How to render.
struct RenderSettings {
    /// An Integrator: "path" or "dual_scattering".
    int integrator = int(Integrator::Path);
    /// Samples per pixel, in [1, 2^24].
    int samples = 64;
    /// Cycles' Max Bounces (Total), in [0, 1024]; Blender's default is 12.
    int max_bounces = 12;
    /// Cycles' Max Bounces: Diffuse, in [0, 1024] (Blender's default 4): counts bounces drawn
    /// from a surface's diffuse lobes (Lambert, Oren–Nayar, Principled diffuse and sheen).
    int max_diffuse_bounces = 4;
    /// Cycles' Max Bounces: Glossy, in [0, 1024] (Blender's default 4): counts bounces drawn
    /// from a surface's microfacet (glossy) lobes.
    int max_glossy_bounces = 4;
    /// Cycles' Max Bounces: Transmission, in [0, 1024] (Blender's default 12): counts hair
    /// bounces. Cycles counts a hair bounce drawn from the R lobe as a glossy bounce (limit
    /// Max Bounces: Glossy, default 4) and the other lobes as transmission; a DirectionSampler
    /// does not say which lobe it drew from, so hairis counts every hair bounce here and has
    /// no glossy limit (paths with more than 4 R-lobe bounces are vanishingly rare).
    int max_transmission_bounces = 12;
    /// Same seed, same image.
    std::uint64_t seed = 0;
    /// Cycles' Max Bounces: Transparent, in [0, 1024] (Blender's default 8): a path crosses at
    /// most transparent_crossings(transparent_limit, this) transparent surfaces; the surface
    /// after the last one ends it (emission only).
    int max_transparent_bounces = 8;
    /// A TransparentLimit: "plus_one" (Cycles up to 4.5) or "setting" (Cycles 5.0).
    int transparent_limit = int(TransparentLimit::PlusOne);
    /// Threads to use, in [0, 1024]; 0 = oneTBB's default concurrency (all cores).
    int threads = 0;
    /// Tile edge in pixels, in [1, 4096].
    int tile_size = 16;
    /// Russian roulette applies at vertices of depth >= this, in [1, 1024]. Cycles with
    /// "Min Light Bounces" 0 (the default) stores min_bounce 1 and plays roulette from depth 2.
    int rr_start_bounce = 2;
    /// Blender's Film > Transparent: camera rays that miss everything add neither the world
    /// nor alpha (suns seen directly still add their disc, as in Cycles). Alpha is otherwise 1.
    bool film_transparent = false;
    /// A HuangSampling: how Huang hair samples directions (integrator=dual_scattering uses
    /// the strategy's sampler at the vertex that closes the path, whose MIS needs a density,
    /// which Cycles' sampler lacks; its exact bounces follow this setting).
    int huang_sampling = int(HuangSampling::Strategy);
    /// A DualHairVolume for integrator=dual_scattering: "layer" or "unbounded".
    int dual_hair_volume = int(DualHairVolume::Layer);
    /// integrator=dual_scattering: the path's first scattering vertices (depth < this, the
    /// camera's hit is depth 0) are path-traced as integrator=path traces them, and the first
    /// hair vertex at a depth >= this is shaded by dual scattering, which closes the path there
    /// (its light from other strands is the dual estimate's). In [0, 1024]; 0 is Zinke et al.'s
    /// dual scattering at the first hair hit. Each exact bounce leaves less of the light to the
    /// approximation: less bias, more noise (bench/results/dual_scattering.md measures both).
    int dual_exact_bounces = 3;
    /// A DualBounceLimit for integrator=dual_scattering: "bounces" or "none".
    int dual_bounce_limit = int(DualBounceLimit::Bounces);
};

/// The option names of RenderSettings (core/options.h's field descriptions).
template <typename Fields>
void describe(Fields &f, RenderSettings &s) {
    f.choice("integrator", s.integrator, {"path", "dual_scattering"});
    f.field("samples", s.samples, 1, 1 << 24);
    f.field("max_bounces", s.max_bounces, 0, 1024);
    f.field("max_diffuse_bounces", s.max_diffuse_bounces, 0, 1024);
    f.field("max_glossy_bounces", s.max_glossy_bounces, 0, 1024);
    f.field("max_transmission_bounces", s.max_transmission_bounces, 0, 1024);
    f.field("max_transparent_bounces", s.max_transparent_bounces, 0, 1024);
    f.choice("transparent_limit", s.transparent_limit, {"plus_one", "setting"});
    f.field("seed", s.seed);
    f.field("threads", s.threads, 0, 1024);
    f.field("tile_size", s.tile_size, 1, 4096);
    f.field("rr_start_bounce", s.rr_start_bounce, 1, 1024);
    f.field("film_transparent", s.film_transparent);
    f.choice("huang_sampling", s.huang_sampling, {"strategy", "cycles"});
    f.choice("dual_hair_volume", s.dual_hair_volume, {"layer", "unbounded"});
    f.field("dual_exact_bounces", s.dual_exact_bounces, 0, 1024);
    f.choice("dual_bounce_limit", s.dual_bounce_limit, {"bounces", "none"});
}

/// What a render did.
struct RenderStats {
    double seconds = 0;
    std::uint64_t camera_rays = 0;        ///< camera samples traced (= pixel samples done)
    std::uint64_t rays = 0;               ///< closest-hit rays (camera and continuation)
    std::uint64_t shadow_rays = 0;
    std::uint64_t dropped_samples = 0;    ///< NaN/inf contributions or throughputs dropped
    double samples_per_second = 0;        ///< camera_rays / seconds
    bool cancelled = false;               ///< the progress callback returned false
    float progress = 0;                   ///< fraction of the work done when render() returned
    std::uint64_t peak_memory_bytes = 0;  ///< scene estimate + render buffers
    int threads = 0;                      ///< threads actually allowed
};

/// Renders `scene` into rgba (width·height·4 floats, bottom row first, as Blender's render
/// result wants; alpha in the 4th channel). `progress` (may be empty) receives the fraction
/// done; returning false cancels: render() then returns an error whose message starts with
/// "cancelled", sets stats->cancelled, and rgba holds the average of the samples finished so
/// far (zero for pixels not started). Invalid settings are refused before anything is
/// written. `stats` may be null.
Status render(const Scene &scene, const RenderSettings &settings, float *rgba,
              const std::function<bool(float progress)> &progress, RenderStats *stats);

/// Cycles' pixel_coverage for a camera ray (kernel/svm/closure.h, Huang): half the pixel
/// footprint at the hit in units of the curve radius there; +inf for a radius of 0 (never
/// near field).
float cycles_pixel_coverage(float footprint, float curve_radius);

/// The FiberHit the renderer gives a hair material at a curve hit, as Cycles sets up the
/// Principled Hair closure: ω_o and h = dot(cross(Ng, X), Z) in the frame
/// FiberFrame::from_tangent_and_view, where a back-facing hit (the inside of a tube) turns Ng and
/// the tangent, as Cycles turns Ng, N and dP/du towards ω_o; the
/// major axis from the curve normal, or, where the curve has none (or it is parallel to the
/// tangent), Cycles' fallback frame around the world tangent (HuangFiber::fallback_major_axis);
/// pixel_coverage from `footprint` for camera rays, 1 for every other ray; `seed` for the
/// point's random numbers.
FiberHit cycles_fiber_hit(const SurfacePoint &sp, Vec3 wo, bool camera_ray, float footprint,
                          std::uint32_t seed);

/// The first hair hit of the camera ray through raster position (x + u, y + v), past hair it
/// crosses transparently, as the renderer sets it up (for tests); nullopt when the ray meets
/// no hair or meets something else first.
std::optional<FiberHit> camera_hair_hit(const Scene &scene, int x, int y, float u, float v);


/// The radiance estimate of one camera sample (for tests and debugging): the path of sample
/// `sample` through raster position (x + u, y + v) where (u, v) are the sample's own jitter.
/// `alpha` receives the sample's alpha when not null.
Rgb render_sample(const Scene &scene, const RenderSettings &settings, int x, int y,
                  std::uint64_t sample, float *alpha = nullptr);

}  // namespace hairis
