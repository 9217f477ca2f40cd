// Per-strand node inputs (issue 13): the variance of each strategy for strands whose inputs
// differ from the material's own values, which are what the TABLE strategy's tables were
// baked for.
//
//   material: Melanin Concentration, melanin 0.5, redness 0.5, roughness 0.3 (radial 0.3),
//             offset 2°, for Cycles 3.4 (tilt on θ_i) and Cycles 4.2+ (tilt on θ_o)
//   strands:  roughness (and radial roughness, as Random Roughness varies both) in
//             {0.15, 0.2, 0.3, 0.45, 0.6} × melanin in {0.2, 0.5, 0.9}
//
// Strategies (f is always the strand's own):
//   analytic         the strand's own fiber (AnalyticSampler on ChiangStrands)
//   table            the policy (make_sampler with the strands): the strand's lobe weights and
//                    N_p, θ_i from the baked rows where the strand's M_p is the baked one, else
//                    from the strand's own cone
//   table, rows      the strand's lobe weights and N_p, θ_i always from the baked rows
//   table, as baked  the density of the material's own fiber at the hit (the strand ignored)
//
//   Y = luminance(f_strand(ω_i)) / pdf(ω_i),  relative variance = Var Y / (E Y)², conditional
//   on h and averaged over h ∈ {±0.95, ±0.6, ±0.2} (as strategy_study), median over θ_r.
//
// Also: the time to prepare the fiber at a hit, for the material's own fiber and for a strand
// whose melanin, or melanin and roughness, differ.
//
// Usage: strand_study [samples per θ_r and h, default 20000] [output folder]
// Writes strand_study.md into the folder.
#include <algorithm>
#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>

#include "core/frame.h"
#include "fiber/chiang_strands.h"
#include "sampling/analytic_sampler.h"
#include "sampling/near_field_table.h"
#include "report.h"
#include "study_common.h"

using namespace hairis;

namespace {

const double kThetaR[] = {-80, -60, -30, 0, 30, 60, 80};
const float kOffsets[] = {-0.95f, -0.6f, -0.2f, 0.2f, 0.6f, 0.95f};
const float kRoughness[] = {0.15f, 0.2f, 0.3f, 0.45f, 0.6f};
const float kMelanin[] = {0.2f, 0.5f, 0.9f};

bench::Report report;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// A strategy at one prepared hit: draws ω_i and reports its density.
using Draw = std::function<std::optional<DirectionSample>(float, float, float)>;
using Prepare = std::function<Draw(const ChiangPoint &strand, const ChiangPoint &base, ScratchBuffer &)>;

struct Material {
    std::shared_ptr<const ChiangStrands> strands;
    bench::StudySetup setup;
    std::shared_ptr<const NearFieldTable> table;
    std::shared_ptr<const Sampler> policy;  // TABLE through make_sampler
};

Material make_material(ChiangTilt tilt) {
    PrincipledHairNode node;
    node.parametrization = HairParametrization::Melanin;
    node.melanin = 0.5f;
    node.melanin_redness = 0.5f;
    node.roughness = 0.3f;
    node.radial_roughness = 0.3f;
    node.tilt = tilt;
    Material m;
    m.strands = std::make_shared<const ChiangStrands>(ChiangStrands::create(node).value());
    FiberSpec spec;
    spec.node = node;
    m.setup.spec = spec;
    m.setup.fiber = m.strands->fiber();
    m.setup.tables = bake_tables(*m.setup.fiber, spec.parameters().value(), BakeOptions{}).value();
    m.setup.sampling = SamplingTables::from(m.setup.tables).value();
    m.table = std::make_shared<const NearFieldTable>(
        NearFieldTable::from_data(m.setup.fiber, m.setup.sampling.near_field).value());
    StrategyInputs in;
    in.strands = m.strands;
    in.tables = &m.setup.sampling;
    m.policy = make_sampler(StrategyKind::Table, in).value();
    return m;
}

// E_h[Var(Y | h) / E(Y | h)²] at ω_o for one strand.
double relative_variance(const Material &m, const HairInputValues &inputs, Vec3 wo, long long per_h,
                         const Prepare &prepare) {
    std::mt19937_64 rng(1234);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    ScratchBuffer scratch;
    double total = 0;
    for (float h : kOffsets) {
        scratch.reset();
        FiberHit hit;
        hit.wo = wo;
        hit.h = h;
        hit.inputs = &inputs;
        const ChiangPoint &strand = m.strands->point(hit, scratch);
        const ChiangPoint base = m.setup.fiber->at({wo, h});
        const Draw draw = prepare(strand, base, scratch);
        double sum = 0, sum_sq = 0;
        for (long long k = 0; k < per_h; ++k) {
            const float u0 = u(rng), u1 = u(rng), u2 = u(rng);
            const std::optional<DirectionSample> s = draw(u0, u1, u2);
            double y = 0;
            if (s && s->pdf > 0) y = double(luminance(strand.f(s->wi))) / double(s->pdf);
            sum += y;
            sum_sq += y * y;
        }
        const double mean = sum / double(per_h);
        total += (sum_sq / double(per_h) - mean * mean) / (mean * mean);
    }
    return total / double(std::size(kOffsets));
}

struct Strategy {
    const char *name;
    Prepare prepare;
};

std::vector<Strategy> strategies(const Material &m) {
    const NearFieldTable *table = m.table.get();
    auto from_table = [table](bool own_cones, bool baked) {
        return [table, own_cones, baked](const ChiangPoint &strand, const ChiangPoint &base, ScratchBuffer &) -> Draw {
            const auto q = std::make_shared<NearFieldTable::Prepared>(table->prepare(baked ? base : strand, own_cones));
            // `base` lives on the caller's stack for the whole draw loop.
            return [table, q](float u0, float u1, float u2) { return table->sample(*q, u0, u1, u2); };
        };
    };
    const Sampler *policy = m.policy.get();
    return {
        {"analytic", [](const ChiangPoint &strand, const ChiangPoint &, ScratchBuffer &) -> Draw {
             return [&strand](float u0, float u1, float u2) { return strand.sample(u0, u1, u2); };
         }},
        {"table", [policy](const ChiangPoint &strand, const ChiangPoint &, ScratchBuffer &scratch) -> Draw {
             const SamplerPoint *point = &policy->at(strand.hit(), &strand, scratch);
             return [point](float u0, float u1, float u2) { return point->sample(u0, u1, u2); };
         }},
        {"table, rows", from_table(false, false)},
        {"table, as baked", from_table(false, true)},
    };
}

// Nanoseconds to prepare the fiber at a hit (best of three passes).
double prepare_ns(const ChiangStrands &strands, const HairInputValues *inputs) {
    const int n = 1 << 18;
    ScratchBuffer scratch;
    double best = 1e30, sink = 0;
    for (int repeat = 0; repeat < 3; ++repeat) {
        const auto start = std::chrono::steady_clock::now();
        for (int i = 0; i < n; ++i) {
            scratch.reset();
            FiberHit hit;
            hit.wo = direction_of(float(i % 100) * 0.01f - 0.5f, -float(kHalfPi));
            hit.h = float(i % 37) / 18.5f - 1.0f;
            hit.inputs = inputs;
            sink += strands.point(hit, scratch).lobe_probability(1);
        }
        best = std::min(best, std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count() / n);
    }
    if (sink < 0) std::puts("");
    return best;
}

}  // namespace

int main(int argc, char **argv) {
    const std::optional<bench::StudyArguments> arguments =
        bench::study_arguments(argc, argv, 20000, 1000, "strand_study");
    if (!arguments) return 1;
    const long long per_h = arguments->samples;
    const std::string &folder = arguments->folder;
    report.print("# Strand study\n\nRelative variance per sample of the luminance estimate of ∫ f cos dω_i for strands whose "
          "inputs differ from the material's (melanin 0.5, redness 0.5, roughness and radial roughness 0.3, offset "
          "2°: what the tables are baked for); %lld samples per θ_r and h, conditional on h ∈ {±0.95, ±0.6, ±0.2}, "
          "median over θ_r ∈ {−80, −60, −30, 0, 30, 60, 80}°. f is the strand's own in every column.\n\n",
          per_h);
    for (ChiangTilt tilt : {ChiangTilt::Incident, ChiangTilt::Outgoing}) {
        const Material m = make_material(tilt);
        const std::vector<Strategy> list = strategies(m);
        report.print("## %s\n\n| strand roughness | melanin |", tilt == ChiangTilt::Incident ? "Cycles 3.4 (tilt on θ_i)"
                                                                                     : "Cycles 4.2+ (tilt on θ_o)");
        for (const Strategy &s : list) report.print(" %s |", s.name);
        report.print("\n|---|---|");
        for (size_t k = 0; k < list.size(); ++k) report.print("---|");
        report.print("\n");
        for (float roughness : kRoughness)
            for (float melanin : kMelanin) {
                HairInputValues inputs;
                inputs.set(HairInput::Roughness, &roughness);
                inputs.set(HairInput::RadialRoughness, &roughness);
                inputs.set(HairInput::Melanin, &melanin);
                report.print("| %.2f | %.1f |", double(roughness), double(melanin));
                for (const Strategy &s : list) {
                    std::vector<double> v;
                    for (double t : kThetaR)
                        v.push_back(relative_variance(m, inputs, direction_of(float(radians(t)), -float(kHalfPi)),
                                                      per_h, s.prepare));
                    report.print(" %.3g |", median(v));
                }
                report.print("\n");
            }
        report.print("\n");
    }

    const Material m = make_material(ChiangTilt::Incident);
    HairInputValues melanin_only, both;
    const float melanin = 0.7f, roughness = 0.4f;
    melanin_only.set(HairInput::Melanin, &melanin);
    both.set(HairInput::Melanin, &melanin);
    both.set(HairInput::Roughness, &roughness);
    both.set(HairInput::RadialRoughness, &roughness);
    report.print("## Preparing the fiber at a hit (one thread)\n\n| fiber | ns per hit |\n|---|---|\n");
    report.print("| the material's own | %.0f |\n", prepare_ns(*m.strands, nullptr));
    report.print("| a strand's melanin | %.0f |\n", prepare_ns(*m.strands, &melanin_only));
    report.print("| a strand's melanin and roughness | %.0f |\n", prepare_ns(*m.strands, &both));

    if (!folder.empty()) {
        std::ofstream(folder + "/strand_study.md") << report.str();
        std::printf("wrote %s/strand_study.md\n", folder.c_str());
    }
    return 0;
}
