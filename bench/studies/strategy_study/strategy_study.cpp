// The strategies side by side in one run (issue 6's variance study):
//
//  1. Near field (what a renderer shades, Cycles' f at the hit's h): relative variance per
//     sample of the luminance estimate of ∫ f cos dω_i for each strategy over a θ_r grid, for
//     blonde, brunette and black Principled Hair at two roughnesses, and the efficiency
//     1 / (variance × time per prepare+sample+pdf).
//  2. Far field (h-averaged f, what the 2D tables tabulate) for the Cycles-default fiber.
//  3. Multiple scattering: the same estimate of ∫ F_multiple cos dω_i at n_h ∈ {1, 2, 4, 8, 16},
//     and the multiple table sampling the layer's term (Ā_b cut at 1, 2, 4 strands behind).
//  4. Resolution sweeps: near-field table (θ_o nodes × θ_i cells) and far-field tables
//     (θ_r × θ_i × φ), variance against memory.
//
//   Y = luminance(f(ω_i)) / pdf(ω_i),  ω_i ~ pdf,  h ~ U[−1, 1];  relative variance = Var Y / (E Y)²
//
// Usage: strategy_study [samples per θ_r, default 100000] [output folder, default: stdout only]
// Writes strategy_study.md and strategy_study.json into the folder (scripts/bench plots them).
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
#include <thread>

#include "fiber/dual_scattering.h"
#include "core/frame.h"
#include "sampling/analytic_sampler.h"
#include "report.h"
#include "study_common.h"

using namespace hairis;

namespace {

const double kThetaR[] = {-80, -60, -30, 0, 30, 60, 80};
constexpr int kThetaCount = 7;

struct Fiber {
    std::string name;
    std::string settings;  // key = value lines on top of the Cycles-default preset
};

const Fiber kFibers[] = {
    {"blonde, roughness 0.2", "parametrization = melanin\nmelanin = 0.15\nmelanin_redness = 0.6\nroughness = 0.2\n"},
    {"blonde, roughness 0.5", "parametrization = melanin\nmelanin = 0.15\nmelanin_redness = 0.6\nroughness = 0.5\n"},
    {"brunette, roughness 0.2", "parametrization = melanin\nmelanin = 0.55\nmelanin_redness = 0.7\nroughness = 0.2\n"},
    {"brunette, roughness 0.5", "parametrization = melanin\nmelanin = 0.55\nmelanin_redness = 0.7\nroughness = 0.5\n"},
    {"black, roughness 0.2", "parametrization = melanin\nmelanin = 0.95\nmelanin_redness = 0.3\nroughness = 0.2\n"},
    {"black, roughness 0.5", "parametrization = melanin\nmelanin = 0.95\nmelanin_redness = 0.3\nroughness = 0.5\n"},
};

std::string json_list(const std::vector<double> &v) {
    std::ostringstream s;
    s << "[";
    for (size_t k = 0; k < v.size(); ++k) s << (k ? ", " : "") << v[k];
    s << "]";
    return s.str();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// Relative variance of Y = integrand(ω_i, h) / pdf, ω_i ~ sampler, conditional on h and
// averaged over fixed offsets: E_h[Var(Y | h) / E(Y | h)²]. The albedo itself changes with h
// (Fresnel, path length); that part of the variance (about 0.03 for the Cycles default) is
// the same for every strategy and is integrated by the pixel's samples, not by the direction
// sampler, so it is left out. For integrands that do not depend on h this is the plain
// relative variance.
const float kOffsets[] = {-0.95f, -0.6f, -0.2f, 0.2f, 0.6f, 0.95f};

double relative_variance(const bench::Strategy &sampler, Vec3 wo, long long count,
                         const std::function<double(Vec3, float)> &integrand) {
    std::mt19937_64 rng(1234);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const long long per_h = std::max(1LL, count / static_cast<long long>(std::size(kOffsets)));
    double total = 0;
    for (float h : kOffsets) {
        double sum = 0, sum_sq = 0;
        for (long long k = 0; k < per_h; ++k) {
            const float u0 = u(rng), u1 = u(rng), u2 = u(rng);
            const auto s = sampler.sample(wo, h, u0, u1, u2);
            double y = 0;
            if (s && s->pdf > 0) y = integrand(s->wi, h) / double(s->pdf);
            sum += y;
            sum_sq += y * y;
        }
        const double mean = sum / double(per_h);
        total += (sum_sq / double(per_h) - mean * mean) / (mean * mean);
    }
    return total / double(std::size(kOffsets));
}

// Nanoseconds per prepare+sample+pdf on one thread, as a renderer spends them at a hit (one
// preparation at (ω_o, h), then one sample and its pdf; the best of three passes over random
// queries).
double time_per_sample(const bench::Strategy &sampler) {
    const int queries = 1 << 18;
    std::vector<Vec3> views(static_cast<size_t>(queries));
    std::vector<float> hs(static_cast<size_t>(queries)), us(3 * static_cast<size_t>(queries));
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (size_t k = 0; k < size_t(queries); ++k) {
        views[k] = direction_of(float(kPi) * (u(rng) - 0.5f), -float(kHalfPi));
        hs[k] = 2.0f * u(rng) - 1.0f;
        for (size_t d = 0; d < 3; ++d) us[3 * k + d] = u(rng);
    }
    double best = 1e30;
    volatile float sink = 0;
    for (int repeat = 0; repeat < 3; ++repeat) {
        float checksum = 0;
        const auto start = std::chrono::steady_clock::now();
        ScratchBuffer scratch;
        for (size_t i = 0; i < size_t(queries); ++i) {
            scratch.reset();
            const HairBsdf bsdf = sampler.at(views[i], hs[i], scratch);
            const auto s = bsdf.sample(us[3 * i], us[3 * i + 1], us[3 * i + 2]);
            if (s) checksum += bsdf.pdf(s->wi);
        }
        const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
        best = std::min(best, ns / queries);
        sink = sink + checksum;
    }
    return best;
}

struct Output {
    bench::Report md;
    std::ostringstream json;
    bool first_json = true;
    void section(const std::string &key, const std::string &value) {
        json << (first_json ? "" : ",\n") << "  \"" << key << "\": " << value;
        first_json = false;
    }
};

}  // namespace

int main(int argc, char **argv) {
    const std::optional<bench::StudyArguments> arguments =
        bench::study_arguments(argc, argv, 100000, 1000, "strategy_study");
    if (!arguments) return 1;
    const long long n = arguments->samples;
    const std::string &folder = arguments->folder;
    Output out;
    out.json << "{\n";
    out.md.print("# Strategy study\n\n%lld samples per θ_r; relative variance per sample of the luminance estimate of ∫ f cos dω_i "
               "(lower is better), conditional on the offset h and averaged over h ∈ {±0.95, ±0.6, ±0.2}; θ_r ∈ {−80, −60, −30, 0, 30, 60, 80}°. Default tables (31×64×64, "
               "n_h 1..16), near-field table 121 θ_o nodes × 90 θ_i cells; the mixture variants use w = 0.25 at n_h = 2.\n\n", n);

    // ---- 1. Near field, six fibers --------------------------------------------------------
    const bench::StudySetup cycles_default = bench::make_setup();
    std::vector<std::string> names;
    for (const auto &s : bench::all_samplers(cycles_default)) names.push_back(s.name);
    std::vector<double> ns_per_sample;
    for (const auto &s : bench::all_samplers(cycles_default)) ns_per_sample.push_back(time_per_sample(*s.sampler));

    out.md.print("## 1. Near field: median relative variance over θ_r\n\n| strategy |");
    for (const Fiber &f : kFibers) out.md.print(" %s |", f.name.c_str());
    out.md.print(" median of medians |\n|---|");
    for (int k = 0; k <= int(std::size(kFibers)); ++k) out.md.print("---|");
    out.md.print("\n");
    std::vector<std::vector<double>> medians(names.size());
    std::ostringstream per_theta;
    per_theta << "{";
    for (size_t fi = 0; fi < std::size(kFibers); ++fi) {
        FiberSpec spec = parse_fiber_spec(kFibers[fi].settings, FiberSpec::preset("cycles-default").value()).value();
        bench::StudySetup setup;
        setup.spec = spec;
        setup.fiber = std::make_shared<const ChiangFiber>(ChiangFiber::create(to_chiang_params(spec.node).value()).value());
        setup.tables = bake_tables(*setup.fiber, spec.parameters().value(), BakeOptions{}).value();
        setup.sampling = SamplingTables::from(setup.tables).value();
        const auto samplers = bench::all_samplers(setup);
        per_theta << (fi ? ", " : "") << "\"" << kFibers[fi].name << "\": {";
        for (size_t s = 0; s < samplers.size(); ++s) {
            std::vector<double> v;
            for (double t : kThetaR) {
                const Vec3 wo = direction_of(float(radians(t)), -float(kHalfPi));
                v.push_back(relative_variance(*samplers[s].sampler, wo, n, [&](Vec3 wi, float h) {
                    return double(luminance(setup.fiber->f_cos_near(wi, wo, h)));
                }));
            }
            medians[s].push_back(median(v));
            per_theta << (s ? ", " : "") << "\"" << samplers[s].name << "\": " << json_list(v);
        }
        per_theta << "}";
    }
    per_theta << "}";
    for (size_t s = 0; s < names.size(); ++s) {
        out.md.print("| %s |", names[s].c_str());
        for (double m : medians[s]) out.md.print(" %.3g |", m);
        out.md.print(" %.3g |\n", median(medians[s]));
    }
    out.section("theta_r_deg", json_list(std::vector<double>(std::begin(kThetaR), std::end(kThetaR))));
    out.section("near_field_variance", per_theta.str());

    out.md.print("\n## Time and efficiency (Cycles-default fiber, one thread, random θ_r and h)\n\n"
               "| strategy | ns per prepare+sample+pdf | million per second | near-field variance (median) | efficiency 1/(variance × µs) | vs analytic |\n|---|---|---|---|---|---|\n");
    std::vector<double> efficiency;
    for (size_t s = 0; s < names.size(); ++s) efficiency.push_back(1.0 / (median(medians[s]) * ns_per_sample[s] * 1e-3));
    for (size_t s = 0; s < names.size(); ++s)
        out.md.print("| %s | %.0f | %.2f | %.3g | %.3g | %.2f× |\n", names[s].c_str(), ns_per_sample[s], 1e3 / ns_per_sample[s],
              median(medians[s]), efficiency[s], efficiency[s] / efficiency[1]);
    {
        std::ostringstream names_json;
        names_json << "[";
        for (size_t s = 0; s < names.size(); ++s) names_json << (s ? ", " : "") << "\"" << names[s] << "\"";
        names_json << "]";
        out.section("strategies", names_json.str());
    }
    out.section("ns_per_sample", json_list(ns_per_sample));
    out.section("efficiency", json_list(efficiency));
    {
        std::vector<double> m;
        for (auto &v : medians) m.push_back(median(v));
        out.section("near_field_median", json_list(m));
    }

    // ---- 2. Far field -----------------------------------------------------------------------
    {
        const auto samplers = bench::all_samplers(cycles_default);
        out.md.print("\n## 2. Far field (h-averaged f, what the 2D tables tabulate), Cycles-default fiber\n\n| strategy |");
        for (double t : kThetaR) out.md.print(" %g° |", t);
        out.md.print(" median |\n|---|---|---|---|---|---|---|---|---|\n");
        std::vector<double> far_medians;
        for (const auto &s : samplers) {
            std::vector<double> v;
            for (double t : kThetaR) {
                const Vec3 wo = direction_of(float(radians(t)), -float(kHalfPi));
                v.push_back(relative_variance(*s.sampler, wo, std::max(1000LL, n / 10), [&](Vec3 wi, float) {
                    return double(luminance(cycles_default.fiber->f_cos(wi, wo)));
                }));
            }
            out.md.print("| %s |", s.name.c_str());
            for (double x : v) out.md.print(" %.3g |", x);
            out.md.print(" %.3g |\n", median(v));
            far_medians.push_back(median(v));
        }
        out.section("far_field_median", json_list(far_medians));
    }

    // ---- 3. Multiple scattering ---------------------------------------------------------------
    {
        const DualScattering dual = DualScattering::create(*cycles_default.fiber, DualScatteringParams{}).value();
        // The median over θ_r of the relative variance of luminance(term(θ_i, θ_r)) sampled by `sampler`.
        auto median_over_theta_r = [&](const bench::Strategy &sampler, auto term) {
            std::vector<double> v;
            for (double t : kThetaR) {
                const Vec3 wo = direction_of(float(radians(t)), -float(kHalfPi));
                v.push_back(relative_variance(sampler, wo, std::max(1000LL, n / 5), [&](Vec3 wi, float) {
                    return double(luminance(term(safe_asin(wi.x), float(radians(t)))));
                }));
            }
            return median(v);
        };
        const int n_h_values[] = {1, 2, 4, 8, 16};
        out.md.print("\n## 3. Multiple scattering (∫ F_multiple cos dω_i through n_h strands), median over θ_r\n\n"
                   "| strategy | n_h = 1 | 2 | 4 | 8 | 16 |\n|---|---|---|---|---|---|\n");
        const char *labels[] = {"uniform", "analytic (single-scattering lobes)", "gaussian (seed, w = 1)", "table (multiple, w = 1)"};
        std::ostringstream json;
        json << "{";
        for (int which = 0; which < 4; ++which) {
            out.md.print("| %s |", labels[which]);
            std::vector<double> row;
            for (int n_h : n_h_values) {
                StrategyInputs in;
                in.tables = &cycles_default.sampling;
                in.multiple_weight = 1.0f;
                in.n_h = n_h;
                const StrategyKind kinds[] = {StrategyKind::Uniform, StrategyKind::Analytic, StrategyKind::Gaussian, StrategyKind::Table};
                if (kinds[which] == StrategyKind::Analytic) in.chiang = cycles_default.fiber;
                const bench::Strategy sampler(make_sampler(kinds[which], in).value(), cycles_default.fiber);
                row.push_back(median_over_theta_r(sampler, [&](float theta_i, float theta_r) {
                    return dual.multiple_f_cos(theta_i, theta_r, n_h);
                }));
                out.md.print(" %.3g |", row.back());
            }
            out.md.print("\n");
            json << (which ? ", " : "") << "\"" << labels[which] << "\": " << json_list(row);
        }
        json << "}";
        out.section("multiple_median", json.str());

        // The layer (dual_hair_volume=layer) cuts Ā_b at the strands behind the vertex: the same
        // baked table (the unbounded term's) then samples a term it was not baked for.
        out.md.print("\nThe multiple table (baked for the unbounded term) sampling the layer's term, Ā_b cut at "
                   "`depth` strands behind:\n\n| depth | n_h = 1 | 2 | 4 | 8 | 16 |\n|---|---|---|---|---|---|\n");
        StrategyInputs in;
        in.tables = &cycles_default.sampling;
        in.multiple_weight = 1.0f;
        std::ostringstream layer_json;
        layer_json << "{";
        const int depths[] = {1, 2, 4, -1};
        for (int d = 0; d < 4; ++d) {
            const int depth = depths[d];
            out.md.print("| %s |", depth < 0 ? "unbounded" : std::to_string(depth).c_str());
            std::vector<double> row;
            for (int n_h : n_h_values) {
                in.n_h = n_h;
                const bench::Strategy sampler(make_sampler(StrategyKind::Table, in).value(), cycles_default.fiber);
                row.push_back(median_over_theta_r(sampler, [&](float theta_i, float theta_r) {
                    return dual.scattered_f_cos(theta_i, theta_r, dual.forward_transmittance(theta_i, n_h),
                                                dual.forward_spread_variance(theta_i, n_h), depth);
                }));
                out.md.print(" %.3g |", row.back());
            }
            out.md.print("\n");
            layer_json << (d ? ", " : "") << "\"" << depth << "\": " << json_list(row);
        }
        layer_json << "}";
        out.section("multiple_layer_median", layer_json.str());
    }

    // ---- 4. Resolution sweeps -------------------------------------------------------------------
    {
        out.md.print("\n## 4a. Near-field table resolution (Cycles-default fiber, w = 0): median variance and memory\n\n"
                   "| θ_o nodes | θ_i cells | median variance | memory (KiB) | build (ms, all cores) |\n|---|---|---|---|---|\n");
        std::ostringstream json;
        json << "[";
        bool first = true;
        for (int nodes : {16, 31, 61, 121}) {
            for (int cells : {45, 90, 180, 360}) {
                const auto start = std::chrono::steady_clock::now();
                const auto table = std::make_shared<const NearFieldTable>(
                    NearFieldTable::create(cycles_default.fiber, {nodes, cells}).value());
                const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
                StrategyInputs in;
                in.chiang = cycles_default.fiber;
                in.tables = &cycles_default.sampling;
                in.multiple_weight = 0.0f;
                in.near_field = table;
                const auto sampler = std::make_shared<const bench::Strategy>(make_sampler(StrategyKind::Table, in).value(), cycles_default.fiber);
                std::vector<double> v;
                // Between nodes as well as on them: θ_r shifted off the grid by 1.3°.
                for (double t : kThetaR) {
                    const Vec3 wo = direction_of(float(radians(t + 1.3)), -float(kHalfPi));
                    v.push_back(relative_variance(*sampler, wo, std::max(1000LL, n / 4), [&](Vec3 wi, float h) {
                        return double(luminance(cycles_default.fiber->f_cos_near(wi, wo, h)));
                    }));
                }
                out.md.print("| %d | %d | %.3g | %.0f | %.0f |\n", nodes, cells, median(v), table->memory_bytes() / 1024.0, ms);
                json << (first ? "" : ", ") << "{\"nodes\": " << nodes << ", \"cells\": " << cells << ", \"variance\": " << median(v)
                     << ", \"kib\": " << table->memory_bytes() / 1024.0 << "}";
                first = false;
            }
        }
        json << "]";
        out.section("near_field_resolution", json.str());
    }
    {
        out.md.print("\n## 4b. Far-field table resolution (Cycles-default fiber, w = 0, far-field integrand)\n\n"
                   "| θ_r × θ_i × φ | median variance | table floats (MiB) | bake (s, all cores) |\n|---|---|---|---|\n");
        std::ostringstream json;
        json << "[";
        bool first = true;
        const int sizes[][3] = {{15, 32, 32}, {31, 64, 64}, {61, 128, 128}};
        for (const auto &size : sizes) {
            BakeOptions options;
            options.theta_r_count = size[0];
            options.theta_i_count = size[1];
            options.phi_count = size[2];
            const auto start = std::chrono::steady_clock::now();
            const TableSet set = bake_tables(*cycles_default.fiber, cycles_default.spec.parameters().value(), options).value();
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            const SamplingTables sampling = SamplingTables::from(set).value();
            StrategyInputs in;
            in.tables = &sampling;
            in.multiple_weight = 0.0f;
            const auto sampler = std::make_shared<const bench::Strategy>(make_sampler(StrategyKind::Table, in).value(), cycles_default.fiber);
            std::vector<double> v;
            for (double t : kThetaR) {
                const Vec3 wo = direction_of(float(radians(t + 1.3)), -float(kHalfPi));
                v.push_back(relative_variance(*sampler, wo, std::max(1000LL, n / 10), [&](Vec3 wi, float) {
                    return double(luminance(cycles_default.fiber->f_cos(wi, wo)));
                }));
            }
            const double mib = double(set.direct.size() + set.multiple.size()) * 4.0 / (1024.0 * 1024.0);
            out.md.print("| %d × %d × %d | %.3g | %.1f | %.2f |\n", size[0], size[1], size[2], median(v), mib, seconds);
            json << (first ? "" : ", ") << "{\"size\": [" << size[0] << ", " << size[1] << ", " << size[2]
                 << "], \"variance\": " << median(v) << ", \"mib\": " << mib << ", \"bake_s\": " << seconds << "}";
            first = false;
        }
        json << "]";
        out.section("far_field_resolution", json.str());
    }

    // ---- 5. Smooth fibers ----------------------------------------------------------------------
    {
        out.md.print("\n## 5. Near field against roughness (Cycles-default fiber otherwise, w = 0)\n\n"
                   "Lobes narrower than the near-field table's cells (2°) and node spacing (1.5°) draw θ_i from the fiber's "
                   "cone sampler instead of their table row, chosen per node and lobe when the table is built "
                   "(near_field_table.h). θ_r ∈ {−88, −80, −60, −30, 0, 30, 60, 80, 88}°, 1.3° off the nodes.\n\n"
                   "| roughness | analytic (median / mean) | rows only | table: rows or cone | build (ms, all cores) |\n|---|---|---|---|---|\n");
        std::ostringstream json;
        json << "[";
        const double thetas[] = {-88, -80, -60, -30, 0, 30, 60, 80, 88};
        for (float roughness : {0.0f, 0.02f, 0.05f, 0.1f, 0.2f, 0.3f, 0.6f}) {
            FiberSpec spec = FiberSpec::preset("cycles-default").value();
            spec.node.roughness = roughness;
            const auto fiber = std::make_shared<const ChiangFiber>(ChiangFiber::create(to_chiang_params(spec.node).value()).value());
            NearFieldTableOptions rows_only;
            rows_only.lobe_sampling = {LobeSampling::Table, LobeSampling::Table, LobeSampling::Table, LobeSampling::Table};
            const auto start = std::chrono::steady_clock::now();
            const auto chosen = std::make_shared<const NearFieldTable>(NearFieldTable::create(fiber).value());
            const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            const auto rows = std::make_shared<const NearFieldTable>(NearFieldTable::create(fiber, rows_only).value());
            const bench::Strategy analytic(std::make_shared<const AnalyticSampler>(fiber), fiber);
            const bench::Strategy chosen_sampler(std::make_shared<const NearFieldTableSampler>(chosen), fiber);
            const bench::Strategy rows_sampler(std::make_shared<const NearFieldTableSampler>(rows), fiber);
            const bench::Strategy *samplers[] = {&analytic, &rows_sampler, &chosen_sampler};
            double med[3], mean[3];
            for (int k = 0; k < 3; ++k) {
                std::vector<double> v;
                for (double t : thetas) {
                    const Vec3 wo = direction_of(float(radians(t + (std::fabs(t) < 85 ? 1.3 : 0.0))), -float(kHalfPi));
                    v.push_back(relative_variance(*samplers[k], wo, std::max(1000LL, n / 4), [&](Vec3 wi, float h) {
                        return double(luminance(fiber->f_cos_near(wi, wo, h)));
                    }));
                }
                med[k] = median(v);
                mean[k] = 0;
                for (double x : v) mean[k] += x / double(v.size());
            }
            out.md.print("| %.2f | %.3g / %.3g | %.3g / %.3g | %.3g / %.3g | %.0f |\n", roughness, med[0], mean[0], med[1], mean[1],
                  med[2], mean[2], ms);
            json << (roughness > 0.0f ? ", " : "") << "{\"roughness\": " << roughness << ", \"analytic\": [" << med[0] << ", " << mean[0]
                 << "], \"rows\": [" << med[1] << ", " << mean[1] << "], \"table\": [" << med[2] << ", " << mean[2]
                 << "], \"build_ms\": " << ms << "}";
        }
        json << "]";
        out.section("roughness_sweep", json.str());
    }

    out.md.print("\nMachine: %u hardware threads.\n", std::thread::hardware_concurrency());
    out.json << "\n}\n";
    if (!folder.empty()) {
        std::ofstream md(folder + "/strategy_study.md"), json(folder + "/strategy_study.json");
        md << out.md.str();
        json << out.json.str();
        if (!md || !json) {
            std::fprintf(stderr, "strategy_study: could not write into %s\n", folder.c_str());
            return 1;
        }
    }
    return 0;
}
