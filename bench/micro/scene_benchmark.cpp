// Google Benchmark: Scene::build (hairis' curve layout + Embree BVH of round Catmull-Rom
// curves) for 10k, 100k and 1M synthetic strands of 9 points on a unit sphere, as the
// add-on's particle hair would give them (bench/studies/export_study/export_study.py measures the whole Blender
// path). The SceneDesc is made outside the timed region; Scene::build takes it by value.
//
// The second argument is the BVH's build quality (BvhQuality: 0 low, 1 medium, 2 high).
//
// Counters: build_s (SceneStats::build_seconds, validation + layout + BVH), embree_peak_MB
// (Embree's peak allocation during the build), scene_MB (hairis' own buffers), peak_MB (their
// sum: what hairis_render_stats.peak_memory_bytes counts for the scene), input_MB (the
// SceneDesc's points, radii and offsets).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <memory>
#include <string>

#include "hair_ball.h"
#include "render/scene.h"
#include "sampling/analytic_sampler.h"
#include "sampling/hair_bsdf.h"

namespace hairis::bench {
namespace {

SceneDesc strand_scene(std::size_t count, BvhQuality quality) {
    SceneDesc desc;
    desc.bvh_quality = quality;
    auto fiber = std::make_shared<const ChiangFiber>(ChiangFiber::create(ChiangParams{}).value());
    desc.materials.push_back(HairMaterial{HairShading::create(fiber, std::make_shared<const AnalyticSampler>(fiber)).value()});
    // Roots on the unit sphere, 0.4 long, radius 0.01 at the root down to 0.002 at the tip.
    StrandShape shape;
    shape.length = 0.4f;
    shape.spread = 0.3f;
    shape.droop = -0.2f;
    shape.root_radius = 0.01f;
    shape.tip_radius = 0.002f;
    desc.curves.push_back(ball_strands(count, shape));
    desc.suns.push_back(SunLight{});
    desc.camera.camera_to_world = Mat4::translation({0, 0, 5});
    desc.camera.width = 16;
    desc.camera.height = 16;
    return desc;
}

void scene_build_strands(benchmark::State &state) {
    const std::size_t count = std::size_t(state.range(0));
    const SceneDesc prototype = strand_scene(count, BvhQuality(state.range(1)));
    const double input_bytes = double(prototype.curves[0].points.size() * sizeof(Vec3) +
                                      prototype.curves[0].radii.size() * sizeof(float) +
                                      prototype.curves[0].first.size() * sizeof(std::uint32_t));
    SceneStats last;
    for (auto _ : state) {
        state.PauseTiming();
        SceneDesc desc = prototype;  // Scene::build consumes its input
        state.ResumeTiming();
        auto scene = Scene::build(std::move(desc));
        if (!scene) {
            state.SkipWithError(scene.error().message.c_str());
            return;
        }
        last = scene.value().stats();
        state.PauseTiming();
        { Scene discard = std::move(scene).value(); }  // the Embree teardown is not timed
        state.ResumeTiming();
    }
    constexpr double MB = 1024.0 * 1024.0;
    state.counters["build_s"] = last.build_seconds;
    state.counters["segments"] = double(last.curve_segments);
    state.counters["embree_peak_MB"] = double(last.embree_peak_bytes) / MB;
    state.counters["embree_MB"] = double(last.embree_bytes) / MB;
    state.counters["scene_MB"] = double(last.scene_bytes) / MB;
    state.counters["peak_MB"] = double(last.estimated_peak_bytes) / MB;
    state.counters["input_MB"] = input_bytes / MB;
    state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(count));
    static const char *qualities[] = {"low", "medium", "high"};
    state.SetLabel(std::to_string(count) + " strands x " + std::to_string(kBallStrandPoints) +
                   " points, " + qualities[state.range(1)] + " BVH");
}
BENCHMARK(scene_build_strands)
    ->ArgsProduct({{10000, 100000, 1000000}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

}  // namespace
}  // namespace hairis::bench
