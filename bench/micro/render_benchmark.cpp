// Google Benchmark: time per sample of the path tracer on a scene like bench/studies/render_versions/render_versions'
// "sphere" (bench/common/hair_ball.h: 1000 strands of particle-like hair on a diffuse sphere, 12000
// as dense as bench/studies/dual_scattering_study/dual_scattering_study's and 40000, under a sun and a dim world, 8 bounces,
// 96 × 96, one thread), per strategy and integrator (path, dual_scattering), without
// Blender. Each iteration renders
// kSamples samples per pixel; the counter ms_per_spp is its CPU time per sample per pixel
// of the whole image, the unit bench/studies/render_versions/render_versions reports.
#include <benchmark/benchmark.h>

#include <cmath>
#include <ctime>
#include <random>
#include <string>
#include <vector>

#include "hair_ball.h"
#include "render/render.h"
#include "render/scene.h"
#include "sampling/strategy.h"

namespace hairis::bench {
namespace {

constexpr int kSamples = 16;
constexpr int kSize = 96;

void render_sphere(benchmark::State &state) {
    const auto kind = StrategyKind(state.range(0));
    const auto integrator = Integrator(state.range(1));
    const auto strands = std::size_t(state.range(2));
    HairBall ball;
    ball.strands = strands;
    ball.size = kSize;
    auto scene = hair_ball_scene(ball, kind, integrator == Integrator::DualScattering);
    if (!scene) {
        state.SkipWithError(scene.error().message.c_str());
        return;
    }
    RenderSettings settings;
    settings.integrator = int(integrator);
    settings.samples = kSamples;
    settings.max_bounces = 8;
    settings.max_transmission_bounces = 8;
    settings.max_diffuse_bounces = 8;
    settings.threads = 1;
    std::vector<float> rgba(std::size_t(kSize) * kSize * 4);
    RenderStats stats;
    double cpu_seconds = 0.0;
    for (auto _ : state) {
        const std::clock_t start = std::clock();
        const Status status = render(scene.value(), settings, rgba.data(), {}, &stats);
        if (status) {
            state.SkipWithError(status->message.c_str());
            return;
        }
        cpu_seconds += double(std::clock() - start) / CLOCKS_PER_SEC;
        ++settings.seed;
        benchmark::DoNotOptimize(rgba.data());
    }
    const double samples = double(stats.camera_rays);
    state.counters["ms_per_spp"] = 1e3 * cpu_seconds / double(state.iterations()) / kSamples;
    state.counters["rays_per_sample"] = double(stats.rays) / samples;
    state.counters["shadow_rays_per_sample"] = double(stats.shadow_rays) / samples;
    state.SetLabel(std::string(strategy_name(kind)) +
                   (integrator == Integrator::DualScattering ? ", dual" : ", path") + ", " +
                   std::to_string(strands) + " strands");
}
// Time per ray of each query from hair points in a dense ball (12000 strands, as
// bench/studies/dual_scattering_study/dual_scattering_study's), in directions uniform on the sphere: 0 intersect (closest
// hit), 1 occluded, 2 trace_through_hair (every crossing), 3 strands_before_mesh (capped at
// kMaxStrandsBehind). The counter crossings is the mean strand count per ray. The second
// argument is the BVH's build quality (BvhQuality: 0 low, 1 medium, 2 high).
void hair_rays(benchmark::State &state) {
    const int query = int(state.range(0));
    HairBall ball;
    ball.strands = 12000;
    ball.bvh_quality = BvhQuality(state.range(1));
    auto scene = hair_ball_scene(ball, StrategyKind::Analytic, false);
    if (!scene) {
        state.SkipWithError(scene.error().message.c_str());
        return;
    }
    const Scene &s = scene.value();
    // Ray origins: where rays from outside the ball towards its centre first hit hair.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    auto sphere_dir = [&] {
        const float z = 2.0f * u(rng) - 1.0f, phi = 6.2831853f * u(rng);
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        return Vec3{r * std::cos(phi), r * std::sin(phi), z};
    };
    std::vector<SurfacePoint> points;
    while (points.size() < 4096) {
        const Vec3 from = 3.0f * sphere_dir(), dir = safe_normalize(0.3f * sphere_dir() - from);
        const auto hit = s.intersect(from, dir, 0.0f, INFINITY, {});
        if (!hit) continue;
        const SurfacePoint sp = s.surface_point(from, dir, *hit);
        if (sp.is_curve) points.push_back(sp);
    }
    std::vector<Vec3> dirs(points.size());
    for (Vec3 &d : dirs) d = sphere_dir();
    std::vector<StrandCrossing> crossings;
    std::size_t k = 0, rays = 0, strands = 0;
    for (auto _ : state) {
        const SurfacePoint &sp = points[k % points.size()];
        const Vec3 dir = dirs[k % dirs.size()];
        ++k;
        switch (query) {
        case 0: benchmark::DoNotOptimize(s.intersect(sp.spawn_point(dir), dir, 0.0f, INFINITY, sp.self)); break;
        case 1: benchmark::DoNotOptimize(s.occluded(sp.spawn_point(dir), dir, 0.0f, INFINITY, sp.self, {})); break;
        case 2:
            benchmark::DoNotOptimize(
                s.trace_through_hair(sp.spawn_point(dir), dir, 0.0f, INFINITY, sp.self, {}, crossings));
            strands += crossings.size();
            break;
        default:
            strands += std::size_t(s.strands_before_mesh(sp.spawn_point(dir), dir, 0.0f, INFINITY, sp.self,
                                                         kMaxStrandsBehind, crossings));
        }
        ++rays;
    }
    state.counters["crossings"] = double(strands) / double(std::max<std::size_t>(rays, 1));
    static const char *names[] = {"intersect", "occluded", "trace_through_hair", "strands_before_mesh"};
    static const char *qualities[] = {"low", "medium", "high"};
    state.SetLabel(std::string(names[query]) + ", " + qualities[state.range(1)] + " BVH");
}
BENCHMARK(hair_rays)->ArgsProduct({{0, 1, 2, 3}, {1}})->Args({0, 0})->Args({0, 2})->Unit(benchmark::kMicrosecond);

BENCHMARK(render_sphere)
    ->Args({int(StrategyKind::Analytic), int(Integrator::Path), 1000})
    ->Args({int(StrategyKind::Table), int(Integrator::Path), 1000})
    ->Args({int(StrategyKind::Table), int(Integrator::DualScattering), 1000})
    ->Args({int(StrategyKind::Table), int(Integrator::Path), 12000})
    ->Args({int(StrategyKind::Table), int(Integrator::DualScattering), 12000})
    ->Args({int(StrategyKind::Table), int(Integrator::Path), 40000})
    ->Args({int(StrategyKind::Table), int(Integrator::DualScattering), 40000})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

}  // namespace
}  // namespace hairis::bench
