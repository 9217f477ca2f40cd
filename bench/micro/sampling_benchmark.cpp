// Google Benchmark: sample+pdf per strategy and fiber evaluation, one thread.
#include <benchmark/benchmark.h>

#include <random>

#include "core/frame.h"
#include "fiber/marschner.h"
#include "study_common.h"

namespace hairis::bench {
namespace {

const StudySetup &setup() {
    static const StudySetup s = make_setup();
    return s;
}

struct Queries {
    std::vector<Vec3> views;
    std::vector<float> h, u;
    explicit Queries(int count) : views(size_t(count)), h(size_t(count)), u(3 * size_t(count)) {
        std::mt19937_64 rng(7);
        std::uniform_real_distribution<float> d(0.0f, 1.0f);
        for (size_t k = 0; k < views.size(); ++k) {
            views[k] = direction_of(float(kPi) * (d(rng) - 0.5f), -float(kHalfPi));
            h[k] = 2.0f * d(rng) - 1.0f;
            for (size_t j = 0; j < 3; ++j) u[3 * k + j] = d(rng);
        }
    }
};

// Times `vertex` on the BSDF of strategy `which` prepared at each of 4096 fixed queries, the
// preparation included.
template <typename Vertex>
void time_vertices(benchmark::State &state, int which, const Vertex &vertex) {
    const auto samplers = all_samplers(setup());
    const Strategy &s = *samplers[size_t(which)].sampler;
    state.SetLabel(samplers[size_t(which)].name);
    const Queries q(4096);
    ScratchBuffer scratch;
    size_t k = 0;
    for (auto _ : state) {
        scratch.reset();
        const float value = vertex(s.at(q.views[k], q.h[k], scratch), q, k);
        benchmark::DoNotOptimize(value);
        k = (k + 1) & 4095;
    }
    state.SetItemsProcessed(state.iterations());
}

// Per direction, as a path vertex pays it: prepare the BSDF at the hit, draw ω_i (f comes
// with it) and evaluate the density there (what MIS against a light needs).
void sample_and_pdf(benchmark::State &state, int which) {
    time_vertices(state, which, [](const HairBsdf &bsdf, const Queries &q, size_t k) {
        const auto smp = bsdf.sample(q.u[3 * k], q.u[3 * k + 1], q.u[3 * k + 2]);
        return smp ? smp->f.g + bsdf.pdf(smp->wi) : 0.0f;
    });
}
BENCHMARK_CAPTURE(sample_and_pdf, uniform, 0);
BENCHMARK_CAPTURE(sample_and_pdf, analytic, 1);
BENCHMARK_CAPTURE(sample_and_pdf, gaussian, 3);
BENCHMARK_CAPTURE(sample_and_pdf, table_far_direct, 4);
BENCHMARK_CAPTURE(sample_and_pdf, table_far_mixture, 5);
BENCHMARK_CAPTURE(sample_and_pdf, table_near_direct, 6);
BENCHMARK_CAPTURE(sample_and_pdf, table_near_mixture, 7);

// What a path vertex pays for hair: prepare the BSDF, f and pdf at a light sample's direction
// (next-event estimation with MIS), then a BSDF sample with its f.
void path_vertex(benchmark::State &state, int which) {
    time_vertices(state, which, [](const HairBsdf &bsdf, const Queries &q, size_t k) {
        float light_pdf = 0.0f;
        const Rgb light_f = bsdf.f_and_pdf(q.views[(k + 1) & 4095], light_pdf);
        const auto smp = bsdf.sample(q.u[3 * k], q.u[3 * k + 1], q.u[3 * k + 2]);
        return light_f.g + light_pdf + (smp ? smp->f.g + smp->pdf : 0.0f);
    });
}
BENCHMARK_CAPTURE(path_vertex, analytic, 1);
BENCHMARK_CAPTURE(path_vertex, table_near_direct, 6);

// Times query(q, k) over 4096 fixed random queries.
template <typename Query>
void time_queries(benchmark::State &state, const Query &query) {
    const Queries q(4096);
    size_t k = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(query(q, k));
        k = (k + 1) & 4095;
    }
}

void chiang_near_field(benchmark::State &state) {
    time_queries(state, [](const Queries &q, size_t k) {
        return setup().fiber->f_cos_near(direction_of(0.3f, 1.0f + q.u[k]), q.views[k], q.h[k]);
    });
}
BENCHMARK(chiang_near_field);

// The two halves of chiang_near_field: preparing the fiber at a hit, and f there.
void chiang_prepare(benchmark::State &state) {
    time_queries(state, [](const Queries &q, size_t k) { return setup().fiber->at({q.views[k], q.h[k]}); });
}
BENCHMARK(chiang_prepare);

void chiang_f_prepared(benchmark::State &state) {
    const Queries views(4096);
    const ChiangPoint point = setup().fiber->at({views.views[7], views.h[7]});
    time_queries(state, [&](const Queries &q, size_t k) { return point.f(direction_of(0.3f, 1.0f + q.u[k])); });
}
BENCHMARK(chiang_f_prepared);

void chiang_far_field(benchmark::State &state) {
    time_queries(state, [](const Queries &q, size_t k) {
        return setup().fiber->f_cos(direction_of(0.3f, 1.0f + q.u[k]), q.views[k]);
    });
}
BENCHMARK(chiang_far_field);

void marschner_far_field(benchmark::State &state) {
    static const MarschnerFiber m = MarschnerFiber::create(MarschnerParams::blonde()).value();
    time_queries(state, [](const Queries &q, size_t k) {
        return m.f_cos(direction_of(0.3f, 1.0f + q.u[k]), q.views[k]);
    });
}
BENCHMARK(marschner_far_field);

}  // namespace
}  // namespace hairis::bench
