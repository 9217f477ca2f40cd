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
#include "render/bsdf.h"
#include "render/render_settings.h"
#include "render/scene.h"

namespace hairis {

/// Renders `scene` into rgba (width·height·4 floats, bottom row first, as Blender's render
/// result wants; alpha in the 4th channel). `progress` (may be empty) receives the fraction
/// done; returning false cancels: render() then returns an error whose message starts with
/// "cancelled", sets stats->cancelled, and rgba holds the average of the samples finished so
/// far (zero for pixels not started). Invalid settings are refused before anything is
/// written. `stats` may be null.
Status render(const Scene &scene, const RenderSettings &settings, float *rgba,
              const std::function<bool(float progress)> &progress, RenderStats *stats);

/// The radiance estimate of one camera sample (for tests and debugging): the path of sample
/// `sample` through raster position (x + u, y + v) where (u, v) are the sample's own jitter.
/// `alpha` receives the sample's alpha when not null.
Rgb render_sample(const Scene &scene, const RenderSettings &settings, int x, int y,
                  std::uint64_t sample, float *alpha = nullptr);

}  // namespace hairis
