// Google Benchmark: baking the default table set (Cycles-default fiber, default BakeOptions).
#include <benchmark/benchmark.h>

#include "study_common.h"

namespace hairis::bench {
namespace {

void bake_default_tables(benchmark::State &state) {
    const FiberSpec spec = FiberSpec::preset("cycles-default").value();
    const auto model = spec.create_model().value();
    const auto params = spec.parameters().value();
    BakeOptions options;
    options.threads = int(state.range(0));
    for (auto _ : state) {
        auto t = bake_tables(*model, params, options);
        benchmark::DoNotOptimize(t);
    }
    state.SetLabel(std::to_string(options.theta_r_count) + "x" + std::to_string(options.theta_i_count) + "x" +
                   std::to_string(options.phi_count) + ", " + std::to_string(options.threads) + " threads");
}
BENCHMARK(bake_default_tables)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);

}  // namespace
}  // namespace hairis::bench
