// Google Benchmark of the Huang pieces: the far-field expectation per ω_o and per ω_i, and per
// renderer hit prepare, f (one Cycles eval), Cycles' sampler and a per-strand control variate's
// correction, for default, rough and smooth roughness and aspect 1, 0.85, 0.5.
#include <benchmark/benchmark.h>

#include <vector>

#include "core/frame.h"
#include "core/scratch.h"
#include "fiber/huang.h"

namespace hairis {
namespace {

HuangFiber fiber_of(const benchmark::State &state) {
    HuangParams p;
    p.roughness = float(state.range(0)) / 100.0f;
    p.aspect_ratio = float(state.range(1)) / 100.0f;
    return HuangFiber::create(p).value();
}

FiberHit hit_of() {
    FiberHit hit;
    hit.wo = {0.3f, 0.0f, -0.954f};
    hit.normal = {0.0f, 0.8f, 0.6f};
    return hit;
}

std::vector<Vec3> directions() {
    std::vector<Vec3> dirs;
    for (int i = 0; i < 256; ++i)
        dirs.push_back(direction_of(float(-1.4 + 2.8 * ((i * 37) % 256) / 256.0), float(-3.1 + 6.2 * i / 256.0)));
    return dirs;
}

HuangQuadrature rule_of(const benchmark::State &state) {
    HuangQuadrature q;
    q.first_order = int(state.range(2));
    q.second_order = int(state.range(3));
    return q;
}

void BM_ExpectationPerView(benchmark::State &state) {
    const HuangFiber fiber = fiber_of(state);
    const HuangPoint point = fiber.at(hit_of());
    const HuangQuadrature q = rule_of(state);
    for (auto _ : state) benchmark::DoNotOptimize(fiber.expectation(point.huang_hit(), q));
}

void BM_ExpectationPerDirection(benchmark::State &state) {
    const HuangFiber fiber = fiber_of(state);
    const HuangPoint point = fiber.at(hit_of());
    const HuangExpectation e = fiber.expectation(point.huang_hit(), rule_of(state));
    const std::vector<Vec3> dirs = directions();
    std::size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(e.f(point.to_huang(dirs[i++ % dirs.size()])));
}

void BM_PrepareAndTwoEvals(benchmark::State &state) {
    const HuangFiber fiber = fiber_of(state);
    const FiberHit hit = hit_of();
    const std::vector<Vec3> dirs = directions();
    ScratchBuffer scratch;
    std::size_t i = 0;
    for (auto _ : state) {
        const FiberPoint &p = fiber.prepare(hit, scratch);
        benchmark::DoNotOptimize(p.f(dirs[i++ % dirs.size()]));
        benchmark::DoNotOptimize(p.f(dirs[i++ % dirs.size()]));
        scratch.reset();
    }
}

void BM_CyclesSampler(benchmark::State &state) {
    const HuangFiber fiber = fiber_of(state);
    const HuangPoint point = fiber.at(hit_of());
    CyclesLcg lcg{3};
    for (auto _ : state) benchmark::DoNotOptimize(point.sample_cycles(lcg.next(), lcg.next(), lcg.next(), lcg));
}

// A strand that differs from the node in absorption only: the control variate's correction
// (the strand's eval minus the node's along the same chains) as two evals replaying one stream,
// and as HuangPoint::f_estimate_difference's one pass.
HuangFiber darker_of(const benchmark::State &state) {
    HuangParams p;
    p.roughness = float(state.range(0)) / 100.0f;
    p.aspect_ratio = float(state.range(1)) / 100.0f;
    p.sigma_a = {0.6f, 1.1f, 2.4f};
    return HuangFiber::create(p).value();
}

void BM_StrandCorrectionTwoEvals(benchmark::State &state) {
    const HuangFiber node = fiber_of(state), strand = darker_of(state);
    const HuangPoint node_point = node.at(hit_of()), strand_point = strand.at(hit_of());
    const std::vector<Vec3> dirs = directions();
    CyclesLcg lcg{3};
    std::size_t i = 0;
    for (auto _ : state) {
        const Vec3 wi = dirs[i++ % dirs.size()];
        CyclesLcg replay = lcg;
        benchmark::DoNotOptimize(strand_point.f_estimate(wi, lcg) - node_point.f_estimate(wi, replay));
    }
}

void BM_StrandCorrectionOnePass(benchmark::State &state) {
    const HuangFiber node = fiber_of(state), strand = darker_of(state);
    const HuangPoint strand_point = strand.at(hit_of());
    const std::vector<Vec3> dirs = directions();
    CyclesLcg lcg{3};
    std::size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(strand_point.f_estimate_difference(dirs[i++ % dirs.size()], lcg, node));
}

void roughness_aspect(benchmark::internal::Benchmark *b) {
    for (int r : {30, 80, 5})
        for (int a : {100, 85, 50}) b->Args({r, a, 4, 3});
}

BENCHMARK(BM_ExpectationPerView)->Apply(roughness_aspect)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExpectationPerDirection)->Apply(roughness_aspect)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PrepareAndTwoEvals)->Apply(roughness_aspect)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CyclesSampler)->Apply(roughness_aspect)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StrandCorrectionTwoEvals)->Apply(roughness_aspect)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StrandCorrectionOnePass)->Apply(roughness_aspect)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hairis

BENCHMARK_MAIN();
