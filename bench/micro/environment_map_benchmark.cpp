// Google Benchmark: building the environment map of a 2048 × 1024 HDRI, and sample, pdf and
// eval per call, one thread (part of hairis_benchmarks).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>
#include <random>
#include <vector>

#include "render/environment_map.h"

namespace hairis::bench {
namespace {

constexpr int kWidth = 2048, kHeight = 1024;

// A sky-like image: a smooth gradient, a noisy ground and a small very bright sun.
EnvironmentImage sky() {
    std::vector<float> rgb(size_t(kWidth) * kHeight * 3);
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<float> d(0.0f, 1.0f);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const float v = (y + 0.5f) / kHeight;
            float *p = &rgb[(size_t(y) * kWidth + size_t(x)) * 3];
            const float base = v > 0.5f ? 0.3f + 0.7f * v : 0.1f * d(rng);
            const bool sun = std::abs(x - 1400) < 4 && std::abs(y - 800) < 4;
            p[0] = sun ? 5e4f : base;
            p[1] = sun ? 4.5e4f : base;
            p[2] = sun ? 4e4f : 1.2f * base;
        }
    return std::move(EnvironmentImage::create(kWidth, kHeight, std::move(rgb))).value();
}

const EnvironmentImage &image() {
    static const EnvironmentImage i = sky();
    return i;
}

EnvironmentDesc desc(bool rotated) {
    EnvironmentDesc d;
    d.image = image();
    if (rotated)
        d.world_to_texture =
            mapping_node_transform({MappingType::Point, {0, 0, 0}, {0.1f, 0.2f, 1.3f}, {1, 1, 1}})
                .value();
    return d;
}

const EnvironmentMap &map(bool rotated) {
    static const EnvironmentMap plain = std::move(EnvironmentMap::create(desc(false))).value();
    static const EnvironmentMap turned = std::move(EnvironmentMap::create(desc(true))).value();
    return rotated ? turned : plain;
}

void build(benchmark::State &state) {
    const int threads = int(state.range(0));
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    for (auto _ : state) {
        state.PauseTiming();
        EnvironmentDesc d = desc(false);  // the copy of the image is not timed
        state.ResumeTiming();
        auto m = EnvironmentMap::create(std::move(d));
        benchmark::DoNotOptimize(m);
    }
}
BENCHMARK(build)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

struct Numbers {
    std::vector<float> u;
    std::vector<Vec3> dirs;
    Numbers() : u(8192), dirs(4096) {
        std::mt19937_64 rng(7);
        std::uniform_real_distribution<float> d(0.0f, 1.0f);
        for (float &x : u) x = d(rng);
        for (Vec3 &w : dirs) {
            const float z = 2 * d(rng) - 1, phi = float(kTwoPi) * d(rng), r = std::sqrt(1 - z * z);
            w = {r * std::cos(phi), r * std::sin(phi), z};
        }
    }
};

// Times query(map, numbers, k) over 4096 fixed random numbers, on the map that range(0) picks.
template <typename Query>
void time_queries(benchmark::State &state, const Query &query) {
    const EnvironmentMap &m = map(state.range(0) != 0);
    const Numbers n;
    size_t k = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(query(m, n, k));
        k = (k + 1) & 4095;
    }
    state.SetItemsProcessed(state.iterations());
}

void sample(benchmark::State &state) {
    time_queries(state, [](const EnvironmentMap &m, const Numbers &n, size_t k) {
        return m.sample(n.u[2 * k], n.u[2 * k + 1]);
    });
}
BENCHMARK(sample)->Arg(0)->Arg(1);

void pdf(benchmark::State &state) {
    time_queries(state, [](const EnvironmentMap &m, const Numbers &n, size_t k) { return m.pdf(n.dirs[k]); });
}
BENCHMARK(pdf)->Arg(0)->Arg(1);

void eval(benchmark::State &state) {
    time_queries(state, [](const EnvironmentMap &m, const Numbers &n, size_t k) { return m.eval(n.dirs[k]); });
}
BENCHMARK(eval)->Arg(0)->Arg(1);

}  // namespace
}  // namespace hairis::bench
