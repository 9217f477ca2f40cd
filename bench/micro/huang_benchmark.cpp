// Google Benchmark of the Huang pieces: the far-field expectation per ω_o and per ω_i, and per
// renderer hit prepare, f (one Cycles eval), Cycles' sampler and a per-strand control variate's
// correction, for default, rough and smooth roughness and aspect 1, 0.85, 0.5; and the f a
// render shades with from a baked table, for the node's strands and for strands of their own
// colour (the absorption part).
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "core/frame.h"
#include "core/scratch.h"
#include "fiber/hair_inputs.h"
#include "fiber/huang.h"
#include "fiber/huang_strands.h"
#include "fiber/principled_hair.h"
#include "sampling/huang_absorption_table.h"
#include "sampling/huang_tabulated_fiber.h"
#include "tables/huang_bake.h"

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

// Blender's default Huang node under Melanin, its table baked with the default options and the
// absorption part, once for every run of BM_TabulatedF.
struct Tabulated {
    std::shared_ptr<const HuangFiber> fiber;
    std::shared_ptr<const HuangTabulatedFiber> model;
    PrincipledHairNode node;
};

const Tabulated &tabulated() {
    static const Tabulated t = [] {
        Tabulated out;
        out.node.parametrization = HairParametrization::Melanin;
        out.fiber = std::make_shared<const HuangFiber>(HuangFiber::create(to_huang_params(out.node).value()).value());
        auto strands = std::make_shared<const HuangStrands>(HuangStrands::create(out.node, out.fiber).value());
        HuangBakeOptions o;
        o.absorption_nodes = huang_absorption_nodes();
        auto table = std::make_shared<const HuangSamplingTable>(
            HuangSamplingTable::from(bake_huang_table(*out.fiber, o).value()).value());
        out.model = std::make_shared<const HuangTabulatedFiber>(
            HuangTabulatedFiber::create(out.fiber, table, strands).value());
        return out;
    }();
    return t;
}

// f at a prepared hit, per ω_i: range(0) 0 for a strand of the node's colour, 1 for one of
// another melanin (read from the absorption part).
void BM_TabulatedF(benchmark::State &state) {
    const Tabulated &t = tabulated();
    float melanin = t.node.melanin * 0.75f;
    HairInputValues inputs;
    inputs.set(HairInput::Melanin, &melanin);
    FiberHit hit = hit_of();
    if (state.range(0) == 1) hit.inputs = &inputs;
    const std::vector<Vec3> dirs = directions();
    ScratchBuffer scratch;
    const FiberPoint &p = t.model->prepare(hit, scratch);
    std::size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(p.f(dirs[i++ % dirs.size()]));
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
BENCHMARK(BM_TabulatedF)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hairis

BENCHMARK_MAIN();
