// The hair path tracer behind the "Hairis" render engine: renders a Scene the way Cycles
// renders the same Blender scene (same light units, curve shape, hair BSDF and bounce count;
// lights and Chiang as the materials' Cycles version says, Huang as Cycles 4.5/5.0).
//
// Integrator: one camera sample's path is render/path_integrator.h's PathIntegrator (with
// render/dual_scattering_integrator.h's hooks for integrator=dual_scattering), each vertex's
// BSDF render/bsdf.h's, its random numbers render/sample_dims.h's dimensions. This file keeps
// the image: tiles, threads, progress and statistics.
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

/// What render_progressive reports on the calling thread: the fraction done, the samples every
/// pixel still being refined has, and whether this is the last call; returning false stops
/// the render.
using UpdateFn = std::function<bool(float progress, int samples_done, bool final)>;

/// render() refining the whole image in rounds: after each round `update` (may be empty) is
/// called with rgba (and `passes`, may be null without passes) holding every pixel's average
/// so far (hairis_render_progressive in hairis_render.h says what the settings add).
/// How render_progressive cuts the samples into rounds and calls back (the image does not
/// depend on it).
struct RoundSchedule {
    /// Each round renders 1, 1, 2, 4, ... samples per pixel, fewer when the last round's pace
    /// says it would take longer than this.
    double round_seconds = 0.5;
    /// At most this many samples per round (0: no limit).
    int max_round_samples = 0;
    /// All samples in one round (the non-progressive render).
    bool one_round = false;
    /// The longest time without an update call.
    double heartbeat_seconds = 0.5;
    /// Whether the final update call comes after a cancel too.
    bool final_update_when_cancelled = true;
};

Status render_progressive(const Scene &scene, const RenderSettings &settings, float *rgba, float *passes,
                          const UpdateFn &update, RenderStats *stats, const RoundSchedule &schedule = {});

/// The radiance estimate of one camera sample (for tests and debugging): the path of sample
/// `sample` through raster position (x + u, y + v) where (u, v) are the sample's own jitter.
/// `alpha` receives the sample's alpha when not null.
Rgb render_sample(const Scene &scene, const RenderSettings &settings, int x, int y,
                  std::uint64_t sample, float *alpha = nullptr);

}  // namespace hairis
