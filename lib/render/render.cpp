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

#include "core/frame.h"
#include "core/rng.h"
#include "core/scratch.h"
#include "render/bsdf.h"
#include "render/dual_scattering_integrator.h"
#include "render/sample_dims.h"
#include "fiber/huang.h"

namespace hairis {

namespace {

bool finite(Rgb c) { return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b); }
struct Counters {
    std::uint64_t rays = 0, shadow_rays = 0, dropped = 0;
    DualWork dual;
};

// One camera sample's path. Returns the radiance; alpha receives the sample's coverage.
Rgb trace_path(const Scene &scene, const RenderSettings &settings, int x, int y,
               std::uint64_t sample, float &alpha, Counters &counters, ScratchBuffer &scratch) {
    const Camera &camera = scene.camera();
    const LightSet &lights = scene.lights();
    const std::uint64_t pixel = std::uint64_t(y) * std::uint64_t(camera.width()) + std::uint64_t(x);
    // Stratified per pixel (jitter, light and BSDF pairs): hair is thinner than a pixel, and
    // stratifying where a sample lands in the pixel is what Cycles' Sobol patterns buy it.
    const SobolSampleRng rng(settings.seed, pixel, sample);
    const SampleRng seeds(settings.seed, pixel, sample);

    const CameraRay cr = camera.generate_ray(x, y, rng.get(kDimJitterU), rng.get(kDimJitterV));
    Vec3 origin = cr.origin, dir = cr.direction;
    Vec3 from = cr.origin;  // the vertex the ray left: where its light sample was drawn
    float tmin = cr.tmin, tmax = cr.tmax;
    PrimRef skip;
    Rgb beta(1.0f), radiance;
    float bsdf_pdf = 0.0f;
    bool use_mis = false;  // camera rays take emission at full weight
    int diffuse_bounces = 0, glossy_bounces = 0, transmission_bounces = 0, transparent_bounces = 0;
    const int crossings = transparent_crossings(TransparentLimit(settings.transparent_limit),
                                                settings.max_transparent_bounces);
    bool last_segment = false;  // a bounce limit was reached: only emission at the next hit
    const bool dual = settings.integrator == int(Integrator::DualScattering);
    const bool dual_layer = settings.dual_hair_volume == int(DualHairVolume::Layer);
    struct {
        const DualScattering *dual = nullptr;  // set when the ray left a hair vertex shaded by dual scattering
        FiberFrame frame;
        float theta_o = 0;
        StrandsBehind depth;  // Ā_b's cut for the continuation's global term (DualWork::last_depth)
        Rgb beta;  // the path's throughput at that vertex
        Vec3 behind_origin;  // the vertex's spawn point along −ω_i (ω_i: the continuation)
        PrimRef self;
        int bounces_left = -1;  // DualVertex::bounces_left
    } dual_from;
    alpha = 1.0f;

    auto add = [&](Rgb contribution) {
        if (!finite(contribution)) {
            ++counters.dropped;
            return;
        }
        radiance += contribution;
    };

    // depth counts scattering vertices; a transparent crossing keeps it (and the camera ray).
    for (int depth = 0;;) {
        std::optional<Hit> hit;
        bool through_hair = false;  // a dual continuation that crossed strands to a mesh
        if (dual_from.dual && dual_layer) {
            // Light meshes reflect onto the hair vertex through n ≥ 1 strands is the dual
            // estimate's global term: T_f d_f (f_s^scatter + π d_b f_back^scatter) for the
            // sampled direction, in place of f_s (lamps, suns and the world beyond hair are M's).
            // Past the strands the mesh's bounces allow, nothing it reflects counts (hit unset).
            std::vector<StrandCrossing> &strands = counters.dual.continuation;
            hit = scene.trace_through_hair_within(origin, dir, tmin, tmax, skip, {},
                                                  bounces_after(dual_from.bounces_left, 1), strands);
            ++counters.rays;
            if (hit && hit->prim.geometry == PrimRef::kNone) hit.reset();  // untraceable: as intersect()
            if (!strands.empty()) {
                const Rgb lamps = lights.lamps_along_ray(origin, dir, tmin, strands[0].t, bsdf_pdf, use_mis, from);
                if (!lamps.is_black()) add(beta * lamps);
                if (!hit) break;
                const ForwardScattering forward =
                    gather_forward_scattering(scene, strands.data(), strands.size(), dir, *dual_from.dual);
                const float theta_i = theta_of(dual_from.frame, dir);
                // The mesh is a vertex of its own, after the strands: it must be one the path
                // tracer would shade.
                const int budget = bounces_after(dual_from.bounces_left, 1);
                const int behind =
                    dual_from.depth.depth(scene, forward.strands, budget, counters.dual.behind, counters.shadow_rays);
                const Rgb m = dual_multiple_f_cos(*dual_from.dual, theta_i, dual_from.theta_o, forward, behind, budget);
                beta = dual_from.beta * m / bsdf_pdf;
                if (beta.is_black() || !finite(beta)) break;
                through_hair = true;
                // The mesh's own bounces count the strands crossed, as the path tracer's would.
                if (dual_from.bounces_left >= 0) {
                    const int crossed = int(strands.size());
                    depth += crossed;
                    transmission_bounces += crossed;
                    last_segment = last_segment || transmission_bounces > settings.max_transmission_bounces;
                }
            }
        } else {
            hit = scene.intersect(origin, dir, tmin, tmax, skip);
            ++counters.rays;
        }
        const float t_end = hit ? hit->t : tmax;

        // Lamps are transparent: every one crossed before the surface contributes.
        if (!through_hair) {
            const Rgb lamps = lights.lamps_along_ray(origin, dir, tmin, t_end, bsdf_pdf, use_mis, from);
            if (!lamps.is_black()) add(beta * lamps);
        }

        if (!hit) {
            const bool transparent = depth == 0 && settings.film_transparent;
            if (transparent) alpha = 0.0f;
            const Rgb escaped = lights.escaped(from, dir, bsdf_pdf, use_mis, !transparent);
            if (!escaped.is_black()) add(beta * escaped);
            break;
        }

        const SurfacePoint sp = scene.surface_point(origin, dir, *hit);
        if (dual_from.dual && sp.is_curve) break;  // hair-to-hair light is the dual estimate's
        const Material &material = scene.materials()[sp.material];
        const Vec3 wo = -dir;

        // Surface emission (mesh triangles are light-sampled, curves are not).
        if (const Rgb emission = material_emission(material); !emission.is_black() && !through_hair) {
            float w = 1.0f;
            if (use_mis && sp.is_light) {
                const float abs_cos = std::fabs(dot(sp.normal, dir));
                w = power_heuristic(bsdf_pdf, lights.emissive_triangle_pdf(hit->t, abs_cos));
            }
            add(beta * emission * w);
        }

        // A terminating ray shades nothing (Cycles evaluates no closures for it, so Huang's
        // transparency does not apply either).
        if (depth > settings.max_bounces || last_segment) break;

        scratch.reset();  // the previous vertex's BSDF is done with
        HitContext context;
        context.camera_ray = depth == 0;
        context.footprint = cr.footprint_at(hit->t);
        context.seed = vertex_seed(seeds, depth);
        // A dual vertex needs the strategy's sampler (its MIS needs a density); the exact
        // bounces before it are path-traced as integrator=path traces them.
        context.cycles_huang = settings.huang_sampling == int(HuangSampling::Cycles) &&
                               !(dual && depth >= settings.dual_exact_bounces);
        const HairInputValues *inputs = nullptr;
        if (sp.is_curve) {
            HairInputValues values;
            if (scene.hair_inputs(sp, values)) inputs = &scratch.make<HairInputValues>(values);
        }
        const Bsdf bsdf(material, sp, wo, context, inputs, scratch);
        if (bsdf.transparent()) {
            // The same ray goes on beyond this curve.
            last_segment = ++transparent_bounces >= crossings;
            tmin = hit->t;
            skip = sp.self;
            continue;
        }
        if (bsdf.black()) break;

        // A mesh a layer vertex sees with no strand in the way sends it light as a lamp does,
        // F = f_s + d_b f_back^direct: what the mesh reflects also carries the local multiple
        // term over the continuation's density, Ā_b cut at the strands behind the vertex along
        // this light's travel, −ω_i (the mesh's emission above is f_s's alone: emitters' M is
        // the light and table samples').
        if (dual_from.dual && dual_layer && !through_hair) {
            // The mesh is a vertex of its own after the strands behind and back: the cut.
            const int budget = bounces_after(dual_from.bounces_left, 1);
            StrandsBehind behind_mesh{dual_from.behind_origin, -dir, dual_from.self, strands_behind_cap(budget)};
            const int behind = behind_mesh.depth(scene, 0, budget, counters.dual.behind, counters.rays);
            const float theta_i = theta_of(dual_from.frame, dir);
            const Rgb m = dual_from.dual->local_f_cos(theta_i, dual_from.theta_o, behind);
            beta += dual_from.beta * m / bsdf_pdf;
            if (!finite(beta)) break;
        }

        // Russian roulette.
        if (depth >= settings.rr_start_bounce) {
            const float q = std::min(1.0f, std::sqrt(beta.max_component()));
            if (!(rng.get(dim(depth, kDimRoulette)) < q)) break;
            beta = beta / q;
        }

        // Next-event estimation.
        // render() refuses hair without dual-scattering data; render_sample() path-traces it.
        const auto *hair = dual ? std::get_if<HairMaterial>(&material) : nullptr;
        const bool dual_vertex = hair && hair->dual && hair->multiple && bsdf.hair() &&
                                 depth >= settings.dual_exact_bounces;
        // The scattering events the path tracer would still add after a dual vertex.
        const int dual_bounces_left =
            dual_vertex && settings.dual_bounce_limit == int(DualBounceLimit::Bounces)
                ? std::max(0, std::min(settings.max_bounces - depth,
                                       settings.max_transmission_bounces - transmission_bounces))
                : -1;
        if (dual_vertex) {
            DualVertex v;
            v.point = &sp;
            v.material = hair;
            v.bsdf = bsdf.hair();
            v.frame = bsdf.frame();
            v.wo = wo;
            v.layer = dual_layer;
            v.bounces_left = dual_bounces_left;
            const std::uint64_t before = counters.dual.rays;
            add(beta * dual_scattering_light(scene, v, dual_random(rng, depth), counters.dual));
            counters.shadow_rays += counters.dual.rays - before;
        } else if (!lights.empty()) {
            const auto ls = lights.sample(sp.position, rng.get(dim(depth, kDimLightSelect)),
                                          rng.get(dim(depth, kDimLightU)),
                                          rng.get(dim(depth, kDimLightV)));
            if (ls && ls->pdf > 0.0f) {
                float pdf_bsdf = 0.0f;
                const Rgb f = bsdf.eval(ls->wi, pdf_bsdf);
                if (!f.is_black()) {
                    const float shadow_tmax =
                        std::isinf(ls->distance) ? INFINITY : ls->distance * (1.0f - 1e-5f);
                    ++counters.shadow_rays;
                    const PrimRef target{ls->skip_geometry, ls->skip_primitive};
                    if (!scene.occluded(sp.spawn_point(ls->wi), ls->wi, 0.0f, shadow_tmax,
                                        sp.self, target)) {
                        const float w = ls->delta ? 1.0f : power_heuristic(ls->pdf, pdf_bsdf);
                        add(beta * f * ls->value * (w / ls->pdf));
                    }
                }
            }
        }

        // Continue along a BSDF sample.
        Vec3 wi;
        Rgb weight;
        float pdf = 0.0f;
        bool glossy = false;
        if (dual_vertex && dual_layer) {
            // A layer's continuation also carries the light meshes send through strands, the
            // multiple term's: a one-sample mixture of the material's sampler and the vertex's
            // multiple table (DualVertex::layer; its light samples MIS against the same).
            const float u0 = rng.get(dim(depth, kDimBsdf0)), u1 = rng.get(dim(depth, kDimBsdf1)),
                        u2 = rng.get(dim(depth, kDimBsdf2));
            const MultipleTable &table = *hair->multiple;
            const int strand = counters.dual.last_strand_index;
            const Vec3 wo_local = bsdf.frame().to_local(wo);
            float pdf_bsdf = 0.0f, pdf_table = 0.0f;
            Rgb f_cos;
            if (rng.get(dual_dim(depth, kDimDualMixture)) < kDualMixture) {
                if (!bsdf.sample(u0, u1, u2, wi, weight, pdf_bsdf, glossy)) break;
                f_cos = weight * pdf_bsdf;
                pdf_table = multiple_table_pdf(table, strand, bsdf.frame(), wo_local, wi);
            } else {
                const MultipleTableSample t = sample_multiple_table(table, strand, bsdf.frame(), wo_local, u0, u1, u2);
                if (!(t.pdf > 0.0f)) break;
                wi = t.wi;
                pdf_table = t.pdf;
                f_cos = bsdf.eval(wi, pdf_bsdf);
            }
            pdf = dual_mixture_pdf(pdf_bsdf, pdf_table);
            if (!(pdf > 0.0f)) break;
            weight = f_cos / pdf;
        } else if (!bsdf.sample(rng.get(dim(depth, kDimBsdf0)), rng.get(dim(depth, kDimBsdf1)),
                                rng.get(dim(depth, kDimBsdf2)), wi, weight, pdf, glossy)) {
            break;
        }
        dual_from.dual = dual_vertex ? hair->dual.get() : nullptr;
        if (dual_vertex) {
            dual_from.frame = bsdf.frame();
            dual_from.theta_o = theta_of(bsdf.frame(), wo);
            dual_from.depth = counters.dual.last_depth;
            dual_from.beta = beta;
            dual_from.behind_origin = sp.spawn_point(-wi);
            dual_from.self = sp.self;
            dual_from.bounces_left = dual_bounces_left;
        }
        if (bsdf.is_hair())
            last_segment = ++transmission_bounces > settings.max_transmission_bounces;
        else if (glossy)
            last_segment = ++glossy_bounces > settings.max_glossy_bounces;
        else
            last_segment = ++diffuse_bounces > settings.max_diffuse_bounces;
        beta *= weight;
        if (!finite(beta)) {
            ++counters.dropped;
            break;
        }
        // A layer's continuation may carry the multiple term where f_s is 0: it decides there.
        if (beta.is_black() && !(dual_vertex && dual_layer)) break;
        origin = sp.spawn_point(wi);
        from = sp.position;
        dir = wi;
        tmin = 0.0f;
        tmax = INFINITY;
        skip = sp.self;
        bsdf_pdf = pdf;
        use_mis = true;
        ++depth;
    }
    return radiance;
}

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
    Counters counters;
    ScratchBuffer scratch;
    float a = 1.0f;
    const Rgb l = trace_path(scene, settings, x, y, sample, a, counters, scratch);
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

    auto render_tile = [&](const Tile &tile) {
        const int tw = tile.x1 - tile.x0, th = tile.y1 - tile.y0;
        std::vector<double> sum(std::size_t(tw) * std::size_t(th) * 4, 0.0);
        Counters counters;
        ScratchBuffer scratch;
        int done = 0;
        for (int s = 0; s < settings.samples; ++s) {
            if (cancel.load(std::memory_order_relaxed)) break;
            for (int y = tile.y0; y < tile.y1; ++y)
                for (int x = tile.x0; x < tile.x1; ++x) {
                    float alpha = 1.0f;
                    const Rgb l = trace_path(scene, settings, x, y, std::uint64_t(s), alpha,
                                             counters, scratch);
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
