#include "render/render.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/scratch.h"
#include "render/path_integrator.h"

namespace hairis {

namespace {

Status validate(const RenderSettings &s) {
    return first_error(check::count_in_range("integrator", s.integrator, 0, 1),
                       check::count_in_range("samples", s.samples, 1, 1 << 24),
                       check::count_in_range("max_bounces", s.max_bounces, 0, 1024),
                       check::count_in_range("max_diffuse_bounces", s.max_diffuse_bounces, 0,
                                             1024),
                       check::count_in_range("max_glossy_bounces", s.max_glossy_bounces, 0,
                                             1024),
                       check::count_in_range("max_transmission_bounces",
                                             s.max_transmission_bounces, 0, 1024),
                       check::count_in_range("max_transparent_bounces",
                                             s.max_transparent_bounces, 0, 1024),
                       check::count_in_range("threads", s.threads, 0, 1024),
                       check::count_in_range("tile_size", s.tile_size, 1, 4096),
                       check::count_in_range("rr_start_bounce", s.rr_start_bounce, 1, 1024),
                       check::count_in_range("huang_sampling", s.huang_sampling, 0, 1),
                       check::count_in_range("dual_hair_volume", s.dual_hair_volume, 0, 1),
                       check::count_in_range("dual_exact_bounces", s.dual_exact_bounces, 0, 1024),
                       check::count_in_range("dual_bounce_limit", s.dual_bounce_limit, 0, 1));
}

// Dual scattering needs every hair material's dual-scattering data and multiple table.
Status check_integrator(const Scene &scene, const RenderSettings &s) {
    if (s.integrator != int(Integrator::DualScattering)) return std::nullopt;
    const std::vector<Material> &materials = scene.materials();
    for (std::size_t m = 0; m < materials.size(); ++m)
        if (const auto *hair = std::get_if<HairMaterial>(&materials[m]))
            if (!hair->dual || !hair->multiple)
                return Error{"integrator=dual_scattering: hair material " + std::to_string(m) +
                             " has no " + (hair->dual ? "multiple-scattering table" : "dual-scattering data") +
                             " (HairMaterial::dual and ::multiple are needed; integrator=path needs neither)"};
    return std::nullopt;
}

struct Tile {
    int x0, y0, x1, y1;
};

}  // namespace

Rgb render_sample(const Scene &scene, const RenderSettings &settings, int x, int y,
                  std::uint64_t sample, float *alpha) {
    PathCounters counters;
    ScratchBuffer scratch;
    float a = 1.0f;
    const Rgb l = PathIntegrator(scene, settings).li(x, y, sample, a, counters, scratch);
    if (alpha) *alpha = a;
    return l;
}

Status render(const Scene &scene, const RenderSettings &settings, float *rgba,
              const std::function<bool(float)> &progress, RenderStats *stats_out) {
    if (auto e = validate(settings)) return e;
    if (auto e = check_integrator(scene, settings)) return e;
    if (!rgba) return Error{"rgba must not be null"};
    const auto start = std::chrono::steady_clock::now();

    const int width = scene.camera().width(), height = scene.camera().height();
    const int ts = settings.tile_size;
    std::vector<Tile> tiles;
    for (int y0 = 0; y0 < height; y0 += ts)
        for (int x0 = 0; x0 < width; x0 += ts)
            tiles.push_back({x0, y0, std::min(x0 + ts, width), std::min(y0 + ts, height)});
    std::fill(rgba, rgba + std::size_t(width) * std::size_t(height) * 4, 0.0f);

    const int threads =
        settings.threads > 0 ? settings.threads : std::max(1, tbb::info::default_concurrency());
    const std::uint64_t total_passes =
        std::uint64_t(tiles.size()) * std::uint64_t(settings.samples);

    std::atomic<bool> cancel{false};
    std::atomic<std::uint64_t> passes_done{0}, camera_rays{0}, rays{0}, shadow_rays{0},
        dropped{0};

    const PathIntegrator integrator(scene, settings);
    auto render_tile = [&](const Tile &tile) {
        const int tw = tile.x1 - tile.x0, th = tile.y1 - tile.y0;
        std::vector<double> sum(std::size_t(tw) * std::size_t(th) * 4, 0.0);
        PathCounters counters;
        ScratchBuffer scratch;
        int done = 0;
        for (int s = 0; s < settings.samples; ++s) {
            if (cancel.load(std::memory_order_relaxed)) break;
            for (int y = tile.y0; y < tile.y1; ++y)
                for (int x = tile.x0; x < tile.x1; ++x) {
                    float alpha = 1.0f;
                    const Rgb l = integrator.li(x, y, std::uint64_t(s), alpha, counters, scratch);
                    double *p = &sum[(std::size_t(y - tile.y0) * std::size_t(tw) +
                                      std::size_t(x - tile.x0)) * 4];
                    p[0] += l.r;
                    p[1] += l.g;
                    p[2] += l.b;
                    p[3] += alpha;
                }
            ++done;
            passes_done.fetch_add(1, std::memory_order_relaxed);
        }
        if (done > 0) {
            const double inv = 1.0 / double(done);
            for (int y = tile.y0; y < tile.y1; ++y)
                for (int x = tile.x0; x < tile.x1; ++x) {
                    const double *p = &sum[(std::size_t(y - tile.y0) * std::size_t(tw) +
                                            std::size_t(x - tile.x0)) * 4];
                    float *out = rgba + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4;
                    for (int c = 0; c < 4; ++c) out[c] = float(p[c] * inv);
                }
        }
        camera_rays.fetch_add(std::uint64_t(done) * std::uint64_t(tw) * std::uint64_t(th));
        rays.fetch_add(counters.rays);
        shadow_rays.fetch_add(counters.shadow_rays);
        dropped.fetch_add(counters.dropped);
    };

    std::mutex mutex;
    std::condition_variable cv;
    bool finished = false;
    std::exception_ptr failure, callback_failure;
    std::thread worker;
    try {
        worker = std::thread([&] {
            try {
                tbb::task_arena arena(threads);
                arena.execute([&] {
                    tbb::parallel_for(
                        tbb::blocked_range<std::size_t>(0, tiles.size(), 1),
                        [&](const tbb::blocked_range<std::size_t> &r) {
                            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                                if (cancel.load(std::memory_order_relaxed)) return;
                                render_tile(tiles[i]);
                            }
                        },
                        tbb::simple_partitioner());
                });
            } catch (...) {
                failure = std::current_exception();
            }
            std::lock_guard<std::mutex> lock(mutex);
            finished = true;
            cv.notify_all();
        });
    } catch (const std::exception &e) {
        return Error{std::string("render: could not start the render thread: ") + e.what()};
    }

    {
        std::unique_lock<std::mutex> lock(mutex);
        bool first = true;
        while (!finished) {
            if (!first) cv.wait_for(lock, std::chrono::milliseconds(50));
            first = false;
            if (finished) break;
            if (progress && !cancel.load()) {
                const float fraction = float(double(passes_done.load()) / double(total_passes));
                lock.unlock();
                bool go_on = false;
                try {
                    go_on = progress(fraction);
                } catch (...) {
                    // Never leave the worker running: stop it and report the exception.
                    callback_failure = std::current_exception();
                }
                lock.lock();
                if (!go_on) cancel.store(true);
            }
        }
    }
    worker.join();

    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const bool cancelled = cancel.load();
    const float fraction = float(double(passes_done.load()) / double(total_passes));
    if (!cancelled && progress && !failure) {
        try {
            progress(1.0f);
        } catch (...) {
            callback_failure = std::current_exception();
        }
    }
    if (stats_out) {
        RenderStats &st = *stats_out;
        st = RenderStats{};
        st.seconds = seconds;
        st.camera_rays = camera_rays.load();
        st.rays = rays.load();
        st.shadow_rays = shadow_rays.load();
        st.dropped_samples = dropped.load();
        st.samples_per_second = seconds > 0 ? double(st.camera_rays) / seconds : 0.0;
        st.cancelled = cancelled;
        st.progress = fraction;
        st.threads = threads;
        st.peak_memory_bytes =
            std::uint64_t(scene.stats().estimated_peak_bytes) +
            std::uint64_t(threads) * std::uint64_t(ts) * std::uint64_t(ts) * 4 * sizeof(double) +
            std::uint64_t(tiles.size()) * sizeof(Tile);
    }
    if (callback_failure && !failure) failure = callback_failure;
    if (failure) {
        try {
            std::rethrow_exception(failure);
        } catch (const std::exception &e) {
            return Error{std::string("render failed: ") + e.what()};
        } catch (...) {
            return Error{"render failed: unknown exception"};
        }
    }
    if (cancelled)
        return Error{"cancelled by the progress callback after " +
                     std::to_string(int(fraction * 100.0f)) + "% of the work"};
    return std::nullopt;
}

}  // namespace hairis
