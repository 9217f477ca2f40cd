#include "render/render.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
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
                       check::count_in_range("dual_bounce_limit", s.dual_bounce_limit, 0, 1),
                       check::in_range("filter_glossy", s.filter_glossy, 0.0, 10.0),
                       check::in_range("clamp_direct", s.clamp_direct, 0.0, 3.4e38),
                       check::in_range("clamp_indirect", s.clamp_indirect, 0.0, 3.4e38),
                       check::count_in_range("pixel_filter", s.pixel_filter, 0, 2),
                       check::in_range("pixel_filter_width", s.pixel_filter_width, 0.001, 10.0),
                       check::in_range("exposure", s.exposure, 0.0, 10.0));
}

// Dual scattering needs every hair material's dual-scattering data and multiple table.
Status check_integrator(const Scene &scene, const RenderSettings &s) {
    if (s.integrator != int(Integrator::DualScattering)) return std::nullopt;
    const std::vector<Material> &materials = scene.materials();
    for (std::size_t m = 0; m < materials.size(); ++m)
        if (const auto *hair = std::get_if<HairMaterial>(&materials[m])) {
            if (hair->mixture)
                return Error{"integrator=dual_scattering: hair material " + std::to_string(m) + " mixes " +
                             std::to_string(hair->mixture->size()) + " hair closures (a Mix or Add Shader); dual "
                             "scattering shades one Principled Hair BSDF per material: render it with "
                             "integrator=path"};
            if (!hair->dual || !hair->multiple)
                return Error{"integrator=dual_scattering: hair material " + std::to_string(m) +
                             " has no " + (hair->dual ? "multiple-scattering table" : "dual-scattering data") +
                             " (HairMaterial::dual and ::multiple are needed; integrator=path needs neither)"};
        }
    return std::nullopt;
}

struct Tile {
    int x0, y0, x1, y1;
};

// The pixels a render covers: x0 <= x < x1, y0 <= y < y1 (row 0 the bottom one).
struct Region {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
    std::size_t pixels() const { return std::size_t(width()) * std::size_t(height()); }
};

Expected<Region> region_of(const std::vector<int> &r, int width, int height) {
    if (r.size() != 4) return Error{"region must be 4 integers x0,y0,x1,y1"};
    if (r[0] == 0 && r[1] == 0 && r[2] == 0 && r[3] == 0) return Region{0, 0, width, height};
    if (r[0] < 0 || r[1] < 0 || r[2] > width || r[3] > height || r[0] >= r[2] || r[1] >= r[3])
        return Error{"region must be x0,y0,x1,y1 with 0 <= x0 < x1 <= " + std::to_string(width) +
                     " and 0 <= y0 < y1 <= " + std::to_string(height) + " (0,0,0,0: the whole image)"};
    return Region{r[0], r[1], r[2], r[3]};
}

// The data passes render_progressive writes beside rgba.
enum class PassKind { Depth, Normal, DenoisingAlbedo, DenoisingNormal };
constexpr const char *kPassNames[] = {"depth", "normal", "denoising_albedo", "denoising_normal"};
int channels(PassKind kind) { return kind == PassKind::Depth ? 1 : 3; }

Expected<std::vector<PassKind>> passes_of(const std::string &text) {
    std::vector<PassKind> kinds;
    std::size_t begin = 0;
    while (begin < text.size()) {
        std::size_t end = text.find(',', begin);
        if (end == std::string::npos) end = text.size();
        const std::string name = text.substr(begin, end - begin);
        int kind = -1;
        for (int k = 0; k < 4; ++k)
            if (name == kPassNames[k]) kind = k;
        if (kind < 0)
            return Error{"passes must be names among depth, normal, denoising_albedo, denoising_normal "
                         "separated by ',' (got \"" + name + "\")"};
        kinds.push_back(PassKind(kind));
        begin = end + 1;
    }
    return kinds;
}

// Cycles' adaptive sampling (scene/integrator.cpp get_adaptive_sampling and
// integrator/adaptive_sampling.cpp): pixels are checked after the sample of index s when
// s > min_samples and s % 16 == 15.
struct Adaptive {
    static constexpr int kStep = 16;
    bool use = false;
    float threshold = 0;  // Cycles' scaled threshold (5 × the Noise Threshold)
    int min_samples = 0;

    explicit Adaptive(const RenderSettings &s) {
        use = s.adaptive_threshold > 0.0f;
        if (!use) return;
        // Cycles' automatic minimum: threshold 0.1 -> 32, 0.01 -> 64, 0.001 -> 128.
        min_samples = s.adaptive_min_samples > 0
                          ? std::max(4, s.adaptive_min_samples)
                          : std::max(4, int(std::ceil(16.0f / std::pow(s.adaptive_threshold, 0.3f))));
        threshold = s.adaptive_threshold * 5.0f;
    }
    bool need_filter(int sample) const {
        return use && sample > min_samples && (sample & (kStep - 1)) == kStep - 1;
    }
    // Of `count` samples from index `start`, those up to and including the next check.
    int align(int start, int count) const {
        if (!use) return count;
        const int first = (min_samples + 1) | (kStep - 1);
        if (start + count <= first) return count;
        const int next = std::max(first, start | (kStep - 1));
        return std::min(next - start + 1, count);
    }
};

// Cycles' sample_is_class_A: the half of the samples the error estimate compares against.
bool class_a(int sample) { return __builtin_popcount(unsigned(sample) & 0xaaaaaaaau) & 1; }

// Where a camera sample's data passes come from: the camera's frame (Cycles' camera space:
// x right, y up, z along the view).
struct CameraFrame {
    Vec3 origin, right, up, forward;
    explicit CameraFrame(const Camera &camera) {
        const Mat4 &m = camera.camera_to_world();
        origin = m.column(3);
        right = safe_normalize(m.column(0));
        up = safe_normalize(m.column(1));
        forward = -safe_normalize(m.column(2));
    }
};

// Every pixel's sums over its samples (region pixels, row by row), what the image and the
// passes are averages of.
struct Film {
    Region region;
    std::vector<PassKind> kinds;
    int pass_floats = 0;  // per pixel
    bool adaptive = false;
    double exposure = 1.0;        // Cycles' Film > Exposure, applied when the image is read
    std::vector<double> sum;      // RGBA
    std::vector<float> half;      // RGB of the class-A samples, doubled (adaptive only)
    std::vector<double> pass;     // pass_floats per pixel
    std::vector<int> count;       // samples done
    std::vector<std::uint8_t> converged;

    Film(const Region &r, std::vector<PassKind> passes, bool use_adaptive)
        : region(r), kinds(std::move(passes)), adaptive(use_adaptive) {
        for (PassKind k : kinds) pass_floats += channels(k);
        const std::size_t n = r.pixels();
        sum.assign(n * 4, 0.0);
        if (adaptive) half.assign(n * 3, 0.0f);
        pass.assign(n * std::size_t(pass_floats), 0.0);
        count.assign(n, 0);
        converged.assign(n, 0);
    }
    std::size_t index(int x, int y) const {
        return std::size_t(y - region.y0) * std::size_t(region.width()) + std::size_t(x - region.x0);
    }
    std::size_t bytes() const {
        return sum.size() * sizeof(double) + half.size() * sizeof(float) + pass.size() * sizeof(double) +
               count.size() * (sizeof(int) + 1);
    }

    void add(std::size_t i, int sample, Rgb l, float alpha, const FirstHit &first, const CameraFrame &camera) {
        double *p = &sum[i * 4];
        p[0] += l.r;
        p[1] += l.g;
        p[2] += l.b;
        p[3] += alpha;
        if (adaptive && class_a(sample)) {
            float *h = &half[i * 3];
            h[0] += 2.0f * l.r;
            h[1] += 2.0f * l.g;
            h[2] += 2.0f * l.b;
        }
        double *q = pass.data() + i * std::size_t(pass_floats);
        for (PassKind k : kinds) {
            Vec3 v{0, 0, 0};
            if (k == PassKind::Depth) {
                // Cycles writes its Z pass at sample 0 only, and reads "nothing" as 1e10.
                if (sample == 0) q[0] = first.found ? double(dot(first.position - camera.origin, camera.forward)) : 1e10;
            } else if (first.found && k == PassKind::Normal) {
                v = first.normal;
            } else if (k == PassKind::DenoisingNormal) {
                const Vec3 n = first.denoising_normal;
                v = Vec3{dot(n, camera.right), dot(n, camera.up), dot(n, camera.forward)};
            } else if (k == PassKind::DenoisingAlbedo) {
                v = Vec3{first.albedo.r, first.albedo.g, first.albedo.b};
            }
            if (k != PassKind::Depth) {
                q[0] += v.x;
                q[1] += v.y;
                q[2] += v.z;
            }
            q += channels(k);
        }
    }

    // Cycles' film_adaptive_sampling_convergence_check for every pixel not yet converged,
    // then its box filter along rows and columns; returns the pixels still to sample.
    std::size_t check_convergence(float threshold) {
        const int w = region.width(), h = region.height();
        std::size_t active = 0;
        for (int y = 0; y < h; ++y) {
            bool row_converged = true;
            for (int x = 0; x < w; ++x) {
                const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
                if (!converged[i]) {
                    const double *s = &sum[i * 4];
                    const float *a = &half[i * 3];
                    const float scale = 1.0f / float(count[i]);
                    const float I[3] = {float(s[0]), float(s[1]), float(s[2])};
                    const float difference =
                        (std::fabs(I[0] - a[0]) + std::fabs(I[1] - a[1]) + std::fabs(I[2] - a[2])) * scale;
                    const float intensity = (I[0] + I[1] + I[2]) * scale;
                    const float normalize = intensity < 1.0f ? std::sqrt(intensity) : intensity;
                    converged[i] = difference / (0.0001f + normalize) < threshold;
                }
                if (!converged[i]) {
                    ++active;
                    row_converged = false;
                }
            }
            if (!row_converged) filter(std::size_t(y) * std::size_t(w), 1, w);
        }
        if (active > 0)
            for (int x = 0; x < w; ++x) filter(std::size_t(x), std::size_t(w), h);
        return active;
    }

    // Cycles' film_adaptive_sampling_filter_x/_y along `n` pixels from `first`, `stride` apart:
    // a converged pixel next to one that is not is sampled on.
    void filter(std::size_t first, std::size_t stride, int n) {
        bool prev = false;
        for (int k = 0; k < n; ++k) {
            const std::size_t i = first + std::size_t(k) * stride;
            if (!converged[i]) {
                if (k > 0 && !prev) converged[i - stride] = 0;
                prev = true;
            } else {
                if (prev) converged[i] = 0;
                prev = false;
            }
        }
    }

    // Writes every region pixel's averages (the depth pass as it is) into the output images
    // of `width`·`height` pixels.
    void resolve(std::size_t row_begin, std::size_t row_end, int width, int height, float *rgba, float *out) const {
        const std::size_t image = std::size_t(width) * std::size_t(height);
        for (std::size_t r = row_begin; r < row_end; ++r)
            for (int x = 0; x < region.width(); ++x) {
                const std::size_t i = r * std::size_t(region.width()) + std::size_t(x);
                if (count[i] == 0) continue;
                const std::size_t o = (std::size_t(region.y0) + r) * std::size_t(width) + std::size_t(region.x0 + x);
                const double inv = 1.0 / double(count[i]);
                // Cycles' Film > Exposure scales the light, not the coverage.
                for (int c = 0; c < 4; ++c) rgba[o * 4 + c] = float(sum[i * 4 + c] * (c < 3 ? inv * exposure : inv));
                const double *q = pass.data() + i * std::size_t(pass_floats);
                float *block = out;
                for (PassKind k : kinds) {
                    const int n = channels(k);
                    for (int c = 0; c < n; ++c)
                        block[o * std::size_t(n) + std::size_t(c)] = float(k == PassKind::Depth ? q[c] : q[c] * inv);
                    q += n;
                    block += image * std::size_t(n);
                }
            }
    }
};

// A render thread's counters and scratch memory, kept across rounds.
struct Worker {
    PathCounters counters;
    ScratchBuffer scratch;
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
              const std::function<bool(float)> &progress, RenderStats *stats) {
    UpdateFn update;
    if (progress) update = [&](float fraction, int, bool) { return progress(fraction); };
    RoundSchedule schedule;
    schedule.heartbeat_seconds = 0.05;
    schedule.final_update_when_cancelled = false;
    return render_progressive(scene, settings, rgba, nullptr, update, stats, schedule);
}

Status render_progressive(const Scene &scene, const RenderSettings &settings, float *rgba, float *passes,
                          const UpdateFn &update, RenderStats *stats_out, const RoundSchedule &schedule) {
    if (auto e = validate(settings)) return e;
    if (auto e = first_error(check::in_range("time_limit", settings.time_limit, 0.0, 3.4e38),
                             check::in_range("adaptive_threshold", settings.adaptive_threshold, 0.0, 1.0),
                             check::count_in_range("adaptive_min_samples", settings.adaptive_min_samples, 0,
                                                   1 << 24)))
        return e;
    if (auto e = check_integrator(scene, settings)) return e;
    if (!rgba) return Error{"rgba must not be null"};
    const int width = scene.camera().width(), height = scene.camera().height();
    Expected<Region> region_or = region_of(settings.region, width, height);
    if (!region_or) return region_or.error();
    Expected<std::vector<PassKind>> kinds = passes_of(settings.passes);
    if (!kinds) return kinds.error();
    if (!kinds.value().empty() && !passes) return Error{"passes must not be null when settings ask for passes"};
    const auto start = std::chrono::steady_clock::now();
    const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };

    const Region region = region_or.value();
    const Adaptive adaptive(settings);
    Film film(region, kinds.value(), adaptive.use);
    film.exposure = settings.exposure;
    const std::size_t image = std::size_t(width) * std::size_t(height);
    std::fill(rgba, rgba + image * 4, 0.0f);
    if (passes) std::fill(passes, passes + image * std::size_t(film.pass_floats), 0.0f);

    const int ts = settings.tile_size;
    std::vector<Tile> tiles;
    for (int y0 = region.y0; y0 < region.y1; y0 += ts)
        for (int x0 = region.x0; x0 < region.x1; x0 += ts)
            tiles.push_back({x0, y0, std::min(x0 + ts, region.x1), std::min(y0 + ts, region.y1)});
    const int threads =
        settings.threads > 0 ? settings.threads : std::max(1, tbb::info::default_concurrency());
    const double total_work = double(region.pixels()) * double(settings.samples);

    std::atomic<bool> cancel{false};
    std::atomic<std::uint64_t> work_done{0}, work_skipped{0};
    const auto fraction = [&] {
        double f = (double(work_done.load()) + double(work_skipped.load())) / total_work;
        if (settings.time_limit > 0) f = std::max(f, elapsed() / settings.time_limit);
        return float(std::min(1.0, f));
    };

    const PathIntegrator integrator(scene, settings);
    const CameraFrame camera(scene.camera());
    const bool want_first = !film.kinds.empty();
    tbb::enumerable_thread_specific<Worker> workers;
    // One round over a tile: every pixel still sampled gets its next `n` samples (at most
    // settings.samples in all), one sample per pixel at a time, in sample order.
    auto render_tile = [&](const Tile &tile, int n) {
        Worker &w = workers.local();
        std::vector<int> target;
        for (int y = tile.y0; y < tile.y1; ++y)
            for (int x = tile.x0; x < tile.x1; ++x) {
                const std::size_t i = film.index(x, y);
                target.push_back(film.converged[i] ? film.count[i] : std::min(film.count[i] + n, settings.samples));
            }
        for (bool more = true; more && !cancel.load(std::memory_order_relaxed);) {
            more = false;
            std::uint64_t rendered = 0;
            std::size_t k = 0;
            for (int y = tile.y0; y < tile.y1; ++y)
                for (int x = tile.x0; x < tile.x1; ++x, ++k) {
                    const std::size_t i = film.index(x, y);
                    const int sample = film.count[i];
                    if (sample >= target[k]) continue;
                    float alpha = 1.0f;
                    FirstHit first;
                    const Rgb l = integrator.li(x, y, std::uint64_t(sample), alpha, w.counters, w.scratch,
                                                want_first ? &first : nullptr);
                    film.add(i, sample, l, alpha, first, camera);
                    film.count[i] = sample + 1;
                    more = more || sample + 1 < target[k];
                    ++rendered;
                }
            work_done.fetch_add(rendered, std::memory_order_relaxed);
        }
    };
    auto for_tiles = [&](tbb::task_arena &arena, int n) {
        arena.execute([&] {
            tbb::parallel_for(
                tbb::blocked_range<std::size_t>(0, tiles.size(), 1),
                [&](const tbb::blocked_range<std::size_t> &r) {
                    for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        if (cancel.load(std::memory_order_relaxed)) return;
                        render_tile(tiles[i], n);
                    }
                },
                tbb::simple_partitioner());
        });
    };
    auto resolve = [&](tbb::task_arena &arena) {
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, std::size_t(region.height()), 8),
                              [&](const tbb::blocked_range<std::size_t> &r) {
                                  film.resolve(r.begin(), r.end(), width, height, rgba, passes);
                              });
        });
    };

    // The worker renders the rounds; after each it resolves the image and, when there is an
    // update callback, waits until the calling thread has called it.
    std::mutex mutex;
    std::condition_variable cv;
    bool finished = false, round_ready = false, in_callback = false;
    int samples_done = 0;  // rounds finished: the samples every pixel never stopped has
    std::exception_ptr failure, callback_failure;
    std::thread worker;
    try {
        worker = std::thread([&] {
            try {
                tbb::task_arena arena(threads);
                int last_n = 0;
                double last_seconds = 0;
                int s0 = 0, last_s0 = 0;
                while (s0 < settings.samples) {
                    int n = schedule.one_round ? settings.samples - s0 : std::max(1, s0);
                    if (schedule.max_round_samples > 0) n = std::min(n, schedule.max_round_samples);
                    if (last_seconds > 0 && !schedule.one_round)
                        n = std::min(n, std::max(1, int(double(last_n) * schedule.round_seconds / last_seconds)));
                    n = adaptive.align(s0, std::min(n, settings.samples - s0));
                    const double round_start = elapsed();
                    for_tiles(arena, n);
                    last_seconds = elapsed() - round_start;
                    last_n = n;
                    if (cancel.load()) break;
                    s0 += n;
                    last_s0 = s0;
                    bool done = s0 >= settings.samples;
                    if (adaptive.need_filter(s0 - 1)) {
                        done = done || film.check_convergence(adaptive.threshold) == 0;
                        std::uint64_t skipped = 0;
                        for (std::size_t i = 0; i < film.count.size(); ++i)
                            if (film.converged[i]) skipped += std::uint64_t(settings.samples - film.count[i]);
                        work_skipped.store(skipped);
                    }
                    done = done || (settings.time_limit > 0 && elapsed() >= settings.time_limit);
                    if (done) break;
                    if (!update) continue;
                    std::unique_lock<std::mutex> lock(mutex);
                    cv.wait(lock, [&] { return !in_callback; });
                    resolve(arena);  // with the lock held: no callback reads the image meanwhile
                    samples_done = s0;
                    round_ready = true;
                    cv.notify_all();
                    cv.wait(lock, [&] { return !round_ready; });
                }
                std::unique_lock<std::mutex> lock(mutex);
                cv.wait(lock, [&] { return !in_callback; });
                resolve(arena);
                samples_done = last_s0;
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

    // The calling thread: update after every round, and at least every heartbeat.
    {
        std::unique_lock<std::mutex> lock(mutex);
        auto last_call = std::chrono::steady_clock::now() - std::chrono::hours(1);
        while (true) {
            const bool due = std::chrono::steady_clock::now() - last_call >=
                             std::chrono::duration<double>(schedule.heartbeat_seconds);
            if (round_ready || (update && due && !finished && !cancel.load())) {
                const int done = samples_done;
                in_callback = true;
                lock.unlock();
                bool go_on = true;
                if (update && !cancel.load()) {
                    try {
                        go_on = update(fraction(), done, false);
                    } catch (...) {
                        // Never leave the worker running: stop it and report the exception.
                        callback_failure = std::current_exception();
                        go_on = false;
                    }
                }
                lock.lock();
                if (!go_on) cancel.store(true);
                last_call = std::chrono::steady_clock::now();
                in_callback = round_ready = false;
                cv.notify_all();
                continue;
            }
            if (finished) break;
            cv.wait_for(lock, std::chrono::milliseconds(50));
        }
    }
    worker.join();

    const bool cancelled = cancel.load();
    const float done_fraction = cancelled ? fraction() : 1.0f;
    if (update && !failure && (!cancelled || schedule.final_update_when_cancelled)) {
        try {
            update(done_fraction, samples_done, true);
        } catch (...) {
            callback_failure = std::current_exception();
        }
    }
    if (stats_out) {
        RenderStats &st = *stats_out;
        st = RenderStats{};
        st.seconds = elapsed();
        st.camera_rays = work_done.load();
        for (const Worker &w : workers) {
            st.rays += w.counters.rays;
            st.shadow_rays += w.counters.shadow_rays;
            st.dropped_samples += w.counters.dropped;
        }
        st.samples_per_second = st.seconds > 0 ? double(st.camera_rays) / st.seconds : 0.0;
        st.cancelled = cancelled;
        st.progress = done_fraction;
        st.threads = threads;
        for (std::size_t i = 0; i < film.count.size(); ++i) {
            st.samples = std::max(st.samples, film.count[i]);
            if (film.converged[i] && film.count[i] < settings.samples) ++st.converged_pixels;
        }
        st.peak_memory_bytes = std::uint64_t(scene.stats().estimated_peak_bytes) + film.bytes() +
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
        return Error{"cancelled by the progress callback after " + std::to_string(int(done_fraction * 100.0f)) +
                     "% of the work"};
    return std::nullopt;
}

}  // namespace hairis
