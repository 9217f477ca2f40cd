// Google Benchmark: time per sample of the path tracer on a scene like bench/render_versions'
// "sphere" (1000 strands of particle-like hair on a diffuse sphere, and 12000 as dense as
// bench/dual_scattering_study's, under a sun and a dim world,
// 8 bounces, 96 × 96, one thread), per strategy and integrator (path, dual_scattering),
// without Blender. Each iteration renders
// kSamples samples per pixel; the counter ms_per_spp is its CPU time per sample per pixel
// of the whole image, the unit bench/render_versions reports.
#include <benchmark/benchmark.h>

#include <cmath>
#include <ctime>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "fiber/fiber_spec.h"
#include "fiber/principled_hair.h"
#include "render/dual_scattering_integrator.h"
#include "render/render.h"
#include "render/scene.h"
#include "sampling/strategy.h"
#include "tables/bake.h"

namespace hairis::bench {
namespace {

constexpr int kSamples = 16;
constexpr int kSize = 96;

// `count` strands of 9 points on the unit sphere, 0.5 long, leaning at random.
HairCurves sphere_strands(std::size_t count) {
    HairCurves c;
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    c.first.push_back(0);
    for (std::size_t s = 0; s < count; ++s) {
        const float z = 2.0f * u(rng) - 1.0f, phi = 6.2831853f * u(rng);
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        const Vec3 root{r * std::cos(phi), r * std::sin(phi), z};
        const Vec3 lean{0.4f * (u(rng) - 0.5f), 0.4f * (u(rng) - 0.5f), -0.3f};
        for (int k = 0; k < 9; ++k) {
            const float t = float(k) / 8.0f;
            c.points.push_back(root + (0.5f * t) * (root + t * lean));
            c.radii.push_back(0.004f + (0.001f - 0.004f) * t);
        }
        c.first.push_back(std::uint32_t(c.points.size()));
    }
    c.material = 0;
    return c;
}

// A UV sphere of radius 0.98 (under the roots).
TriangleMesh sphere_mesh(int rings, int segments) {
    TriangleMesh m;
    for (int i = 0; i <= rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const float theta = float(M_PI) * float(i) / float(rings);
            const float phi = 2.0f * float(M_PI) * float(j) / float(segments);
            m.positions.push_back(0.98f * Vec3{std::sin(theta) * std::cos(phi),
                                               std::sin(theta) * std::sin(phi), std::cos(theta)});
        }
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const std::uint32_t a = std::uint32_t(i * segments + j);
            const std::uint32_t b = std::uint32_t(i * segments + (j + 1) % segments);
            const std::uint32_t c = a + std::uint32_t(segments), d = b + std::uint32_t(segments);
            for (std::uint32_t k : {a, c, b, b, c, d}) m.indices.push_back(k);
        }
    m.materials = {1};
    return m;
}

Expected<Scene> sphere_scene(StrategyKind kind, Integrator integrator, std::size_t strands = 1000) {
    PrincipledHairNode node;
    node.parametrization = HairParametrization::Melanin;
    node.melanin = 0.25f;
    node.roughness = 0.3f;
    auto params = to_chiang_params(node);
    if (!params) return params.error();
    auto fiber_or = ChiangFiber::create(params.value());
    if (!fiber_or) return fiber_or.error();
    auto fiber = std::make_shared<const ChiangFiber>(std::move(fiber_or).value());
    StrategyInputs inputs;
    inputs.chiang = fiber;
    std::optional<SamplingTables> tables;
    const bool dual = integrator == Integrator::DualScattering;
    if (kind == StrategyKind::Table || dual) {
        auto baked = bake_tables(*fiber, chiang_parameters(params.value()), BakeOptions{});
        if (!baked) return baked.error();
        auto loaded = SamplingTables::from(baked.value());
        if (!loaded) return loaded.error();
        tables = std::move(loaded).value();
        if (kind == StrategyKind::Table) inputs.tables = &*tables;
    }
    auto sampler = make_sampler(kind, inputs);
    if (!sampler) return sampler.error();
    auto shading = HairShading::create(fiber, sampler.value());
    if (!shading) return shading.error();

    SceneDesc desc;
    HairMaterial hair{shading.value()};
    if (dual) {
        auto averages = DualScattering::create(*fiber, DualScatteringParams{});
        if (!averages) return averages.error();
        hair.dual = std::make_shared<const DualScattering>(std::move(averages).value());
        hair.multiple = tables->multiple;
    }
    desc.materials.push_back(std::move(hair));
    DiffuseMaterial skin;
    skin.albedo = {0.6f, 0.5f, 0.45f};
    desc.materials.push_back(skin);
    desc.curves.push_back(sphere_strands(strands));
    desc.meshes.push_back(sphere_mesh(24, 48));
    SunLight sun;
    sun.to_sun = safe_normalize(Vec3{0.5f, -0.6f, 0.6f});
    sun.strength = 3.0f;
    sun.angle = 0.05f;
    desc.suns.push_back(sun);
    desc.world.color = {0.2f, 0.22f, 0.25f};
    desc.world.strength = 0.3f;
    // Looking along +y at the origin from 6 m.
    const float to_world[16] = {1, 0, 0, 0, 0, 0, -1, -6, 0, 1, 0, 0, 0, 0, 0, 1};
    desc.camera.camera_to_world = Mat4::from_row_major(to_world);
    for (Vec3 &corner : desc.camera.frame) corner = Vec3{corner.x * 0.6f, corner.y * 0.6f, -1.0f};
    desc.camera.width = kSize;
    desc.camera.height = kSize;
    return Scene::build(std::move(desc));
}

void render_sphere(benchmark::State &state) {
    const auto kind = StrategyKind(state.range(0));
    const auto integrator = Integrator(state.range(1));
    const auto strands = std::size_t(state.range(2));
    auto scene = sphere_scene(kind, integrator, strands);
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
// bench/dual_scattering_study's), in directions uniform on the sphere: 0 intersect (closest
// hit), 1 occluded, 2 trace_through_hair (every crossing), 3 strands_before_mesh (capped at
// kMaxStrandsBehind). The counter crossings is the mean strand count per ray.
void hair_rays(benchmark::State &state) {
    const int query = int(state.range(0));
    auto scene = sphere_scene(StrategyKind::Analytic, Integrator::Path, 12000);
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
    state.SetLabel(names[query]);
}
BENCHMARK(hair_rays)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);

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
