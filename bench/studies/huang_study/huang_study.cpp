// The strategies for the Huang fiber side by side, and the sweeps that chose the Huang bake:
//
//  1. Bake evaluator and resolution for Blender's default Huang node: bake time on 1 and 2
//     threads, memory, and the relative variance of the table strategy.
//  2. UNIFORM, Cycles' own sampler and TABLE over θ_o, φ_o, aspect ratio and roughness.
//  3. The uniform sphere's weight in TABLE's mixture (the support guarantee) and its cost.
//  4. The near field (camera rays on hair wider than the pixel) sampled with the far-field table.
//  5. Time per sample.
//  6. TABLE weighted with the renderer's f (one Cycles eval, a Monte Carlo estimate).
//  7. The tails of TABLE's and Cycles' sample weights.
//  8. The noise of one Cycles eval, lobe by lobe.
//  9. The baked f (renders' Huang f) against the expectation: error, bake time, memory, speed.
//
// The integrand is luminance(f) with f = HuangExpectation (f·cos θ_i, the expectation of
// Cycles' eval) at the rule (6,4). For samplers with a density the relative variance of
// Y = luminance(f)/pdf is computed exactly for that f, without Monte Carlo noise:
//   Var Y / (E Y)² = ∫ f²/pdf dω / (∫ f dω)² − 1,
// by the midpoint rule on a grid aligned with the table's cells (so that the table's density
// is constant on each grid cell); it is infinite when pdf = 0 where f > 0. Cycles' sampler has no density: Y is its
// own weight (luminance), whose mean is Cycles' sampled energy, not ∫ f (docs/huang.md §8);
// its relative variance and mean come from Monte Carlo. A Monte Carlo check of the table's
// variance is in section 2.
//
// Usage: huang_study [output folder (writes huang_study.md)] [full | quick] [sections 1-9 and a, e.g. 135a]
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/frame.h"
#include "core/scratch.h"
#include "fiber/huang.h"
#include "fiber/principled_hair.h"
#include "sampling/hair_bsdf.h"
#include "sampling/huang_f_table.h"
#include "sampling/huang_table_sampler.h"
#include "sampling/strategy.h"
#include "tables/huang_bake.h"
#include "report.h"

using namespace hairis;

namespace {

bool quick = false;
bench::Report report;

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// CPU seconds of this process (all threads) or of the calling thread: what the work costs,
// whatever else shares the cores.
double cpu_seconds(clockid_t clock = CLOCK_PROCESS_CPUTIME_ID) {
    timespec t{};
    clock_gettime(clock, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string number(double v) {
    if (std::isinf(v)) return "inf";
    char b[32];
    std::snprintf(b, sizeof b, v < 0.01 ? "%.2e" : (v < 10 ? "%.3f" : "%.1f"), v);
    return b;
}

HuangParams params_of(float aspect, float roughness) {
    HuangParams p;  // Blender's default node; its default colour mapped with Huang's β = roughness
    p.aspect_ratio = aspect;
    p.roughness = roughness;
    p.sigma_a = principled_hair::sigma_from_reflectance({0.017513f, 0.005763f, 0.002059f}, roughness);
    return p;
}

// A renderer hit at θ_o whose view has azimuth φ_o in Huang's frame (major axis
// a = (0, cos ψ, sin ψ), φ_o = −π/2 − ψ, for ω_o = (sin θ_o, 0, −cos θ_o)).
FiberHit hit_at(double theta_o_deg, double phi_o_deg, float h = 0.0f, float pixel_coverage = 1.0f) {
    const double t = radians(theta_o_deg), psi = -kHalfPi - radians(phi_o_deg);
    FiberHit hit;
    hit.wo = {float(std::sin(t)), 0.0f, float(-std::cos(t))};
    hit.normal = {0.3f, float(std::cos(psi)), float(std::sin(psi))};
    hit.h = h;
    hit.pixel_coverage = pixel_coverage;
    hit.seed = 77;
    return hit;
}

// ---------------------------------------------------------------------------------------------
// f on a quadrature grid of one hit, aligned with a table's cells there: each of the table's
// θ_i cells (equal in θ) split into `sub` equal steps of sin θ_i, and each of its φ cells
// (equally spaced in the renderer's frame too: the fold and the frame rotation only mirror and
// turn them) into `sub` equal steps. The table's density is constant on every grid cell, so
// the midpoint rule only has f's variation to integrate.

struct Grid {
    std::vector<double> sin_edges;  // increasing from −1 to 1: where the table's density may jump in θ_i
    int phi_cells = 48, sub_theta = 2, sub_phi = 4;
    double phi_offset = -kPi;  // renderer azimuth of a φ cell edge
    int n_sin() const { return (int(sin_edges.size()) - 1) * sub_theta; }
    int n_phi() const { return phi_cells * sub_phi; }
    Vec3 direction(int k, int l) const {
        const int i = k / sub_theta, a = k % sub_theta;
        const double x = sin_edges[size_t(i)] + (sin_edges[size_t(i) + 1] - sin_edges[size_t(i)]) * (a + 0.5) / sub_theta;
        const double phi = phi_offset + kTwoPi * (l + 0.5) / n_phi(), r = std::sqrt(std::max(0.0, 1 - x * x));
        return {float(x), float(r * std::cos(phi)), float(r * std::sin(phi))};
    }
    double cell(int k) const {
        const size_t i = size_t(k / sub_theta);
        return (sin_edges[i + 1] - sin_edges[i]) / sub_theta * (kTwoPi / n_phi());
    }
};

// The grid aligned with `table` at `hit`: θ_i cell edges through both θ_o nodes' warps and the
// warps' anchor (so about two intervals per cell, each split in sub / 2), the φ cell edges in
// the renderer's frame (each cell split in sub).
Grid aligned(const HuangFiber &fiber, const HuangTable &table, const FiberHit &hit, int sub) {
    const HuangPoint point = fiber.at(hit);
    const HuangTableQuery q = table.locate(point.to_huang(hit.wo));
    const double a = std::atan2(q.sin_phi_o, q.cos_phi_o) - kPi;
    const Vec3 edge = point.from_huang({0.0f, q.sign_y * float(std::cos(a)), q.sign_z * float(std::sin(a))});
    Grid g;
    std::vector<double> theta{q.warp[0].anchor};
    for (const ThetaWarp &w : q.warp)
        for (int k = 0; k <= table.theta_i_count(); ++k) theta.push_back(w.from_node(-kHalfPi + kPi * k / table.theta_i_count()));
    for (double t : theta) g.sin_edges.push_back(std::sin(std::clamp(t, -kHalfPi, kHalfPi)));
    g.sin_edges.push_back(-1.0);
    g.sin_edges.push_back(1.0);
    std::sort(g.sin_edges.begin(), g.sin_edges.end());
    g.sin_edges.erase(std::unique(g.sin_edges.begin(), g.sin_edges.end(), [](double x, double y) { return y - x < 1e-9; }),
                      g.sin_edges.end());
    g.phi_cells = table.phi_count();
    g.sub_theta = std::max(1, sub / 2);
    g.sub_phi = sub;
    g.phi_offset = std::atan2(double(edge.z), double(edge.y));
    return g;
}

struct ViewF {
    FiberHit hit;
    Grid grid;
    std::vector<float> f;  // luminance(f) per grid cell
    double integral = 0;   // ∫ luminance(f) dω
};

HuangQuadrature study_rule() {
    HuangQuadrature q;
    q.first_order = 6;
    q.second_order = 4;
    return q;
}

ViewF view_f(const HuangFiber &fiber, const FiberHit &hit, Grid grid) {
    ViewF v;
    v.hit = hit;
    v.grid = grid;
    const HuangPoint point = fiber.at(hit);
    const HuangExpectation e = fiber.expectation(point.huang_hit(), study_rule());
    const int n_sin = grid.n_sin(), n_phi = grid.n_phi();
    v.f.assign(size_t(n_sin) * n_phi, 0.0f);
    tbb::parallel_for(0, n_sin, [&](int k) {
        for (int l = 0; l < n_phi; ++l) v.f[size_t(k) * n_phi + l] = luminance(e.f(point.to_huang(grid.direction(k, l))));
    });
    for (int k = 0; k < n_sin; ++k)
        for (int l = 0; l < n_phi; ++l) v.integral += double(v.f[size_t(k) * n_phi + l]) * grid.cell(k);
    return v;
}

// Exact relative variance of luminance(f)/pdf for a sampler's density (grid quadrature), and the
// share of ∫ f where the density is zero.
struct Variance {
    double relative = 0, uncovered = 0;
};

Variance grid_variance(const ViewF &v, const HairShading &shading) {
    ScratchBuffer scratch;
    const HairBsdf bsdf = shading.at(v.hit, scratch);
    double sum = 0, uncovered = 0;
    for (int k = 0; k < v.grid.n_sin(); ++k)
        for (int l = 0; l < v.grid.n_phi(); ++l) {
            const double f = v.f[size_t(k) * v.grid.n_phi() + l];
            if (!(f > 0)) continue;
            const double p = bsdf.pdf(v.grid.direction(k, l));
            if (p > 0)
                sum += f * f / p * v.grid.cell(k);
            else
                uncovered += f * v.grid.cell(k);
        }
    if (v.integral <= 0) return {0, 0};
    return {uncovered > 0 ? std::numeric_limits<double>::infinity() : sum / (v.integral * v.integral) - 1.0,
            uncovered / v.integral};
}

// Cycles' sampler at the hit: mean and relative variance of luminance(weight) (Monte Carlo).
struct CyclesMoments {
    double mean = 0, relative_variance = 0;
};

CyclesMoments cycles_moments(const HuangFiber &fiber, const FiberHit &hit, long long n) {
    const HuangPoint point = fiber.at(hit);
    CyclesLcg lcg{hit.seed * 2654435761u + 1u};
    std::mt19937_64 rng(hit.seed + 5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    double sum = 0, sum2 = 0;
    for (long long k = 0; k < n; ++k) {
        const auto s = point.sample_cycles(u(rng), u(rng), u(rng), lcg);
        const double y = s ? luminance(s->weight) : 0.0;
        sum += y;
        sum2 += y * y;
    }
    const double mean = sum / double(n);
    return {mean, mean > 0 ? (sum2 / double(n) - mean * mean) / (mean * mean) : 0.0};
}

// Monte Carlo relative variance of luminance(f)/pdf with the given sampler (for checking).
double mc_variance(const HuangFiber &fiber, const HairShading &shading, const FiberHit &hit, int n) {
    const HuangPoint point = fiber.at(hit);
    const HuangExpectation e = fiber.expectation(point.huang_hit(), study_rule());
    ScratchBuffer scratch;
    const HairBsdf bsdf = shading.at(hit, scratch);
    std::mt19937_64 rng(4242);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    // Sampling is cheap and sequential; the expectation at the samples runs in parallel.
    std::vector<std::optional<BsdfSample>> samples;
    for (int k = 0; k < n; ++k) samples.push_back(bsdf.sample(u(rng), u(rng), u(rng)));
    std::vector<double> y(size_t(n), 0.0);
    tbb::parallel_for(0, n, [&](int k) {
        const auto &s = samples[size_t(k)];
        if (s) y[size_t(k)] = luminance(e.f(point.to_huang(s->wi))) / s->pdf;
    });
    double sum = 0, sum2 = 0;
    for (double x : y) sum += x, sum2 += x * x;
    const double mean = sum / n;
    return (sum2 / n - mean * mean) / (mean * mean);
}

// Monte Carlo relative variance of luminance(f)/pdf where f is what the renderer weights a BSDF
// sample with: one Cycles eval (HuangPoint::f, a Monte Carlo estimate of the expectation), drawn
// afresh per sample as at every shading point of a render.
double mc_variance_renderer_f(const HuangFiber &fiber, const HairShading &shading, const FiberHit &hit, int n,
                              int evals = 1) {
    ScratchBuffer scratch;
    std::mt19937_64 rng(4243);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    double sum = 0, sum2 = 0;
    for (int k = 0; k < n; ++k) {
        scratch.reset();
        FiberHit h = hit;
        h.seed = std::uint32_t(k) * 2654435761u + 7u;  // each sample its own shading point's LCG
        const HairBsdf bsdf = shading.at(h, scratch);
        const auto s = bsdf.sample(u(rng), u(rng), u(rng));
        double f = s ? double(luminance(s->f)) : 0.0;
        if (s && evals > 1) {
            // The mean of `evals` independent Cycles evals at the sampled direction.
            const HuangPoint &p = static_cast<const HuangPoint &>(fiber.prepare(h, scratch));
            CyclesLcg lcg{(h.seed ^ 0x9e3779b9u) * 0x85ebca6bu ^ (h.seed >> 13)};  // not a progression in k
            for (int e = 1; e < evals; ++e) f += double(luminance(p.f_estimate(s->wi, lcg)));
            f /= evals;
        }
        const double y = s ? f / double(s->pdf) : 0.0;
        sum += y;
        sum2 += y * y;
    }
    const double mean = sum / n;
    return mean > 0 ? (sum2 / n - mean * mean) / (mean * mean) : 0.0;
}

std::shared_ptr<const HuangFiber> make_fiber(const HuangParams &p) {
    return std::make_shared<const HuangFiber>(HuangFiber::create(p).value());
}

struct TableStrategy {
    HuangSamplingTable table;
    double bake_seconds = 0, bake_cpu_seconds = 0;
    HuangTableSet set;
};

TableStrategy bake(const HuangFiber &fiber, HuangBakeOptions o) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    TableStrategy s;
    s.set = bake_huang_table(fiber, o).value();
    s.bake_seconds = seconds_since(t0);
    s.bake_cpu_seconds = cpu_seconds() - c0;
    s.table = HuangSamplingTable::from(s.set).value();
    return s;
}

HairShading shading_of(std::shared_ptr<const HuangFiber> fiber, StrategyKind kind, const HuangSamplingTable *table,
                       float uniform_weight = kHuangUniformWeight) {
    StrategyInputs in;
    in.huang = fiber;
    in.huang_table = std::shared_ptr<const HuangSamplingTable>(std::shared_ptr<const HuangSamplingTable>(), table);  // not owned
    in.huang_uniform_weight = uniform_weight;
    return HairShading::create(fiber, make_sampler(kind, in).value()).value();
}

// TABLE as renders shade with it: the table's sampler weighted with the table's baked f.
HairShading baked_f_shading(std::shared_ptr<const HuangFiber> fiber, const HuangSamplingTable &table) {
    StrategyInputs in;
    in.huang = fiber;
    in.huang_table = std::make_shared<const HuangSamplingTable>(table);
    return make_hair_shading(StrategyKind::Table, in, fiber).value();
}

// ---------------------------------------------------------------------------------------------

struct ViewAngles {
    double theta_o, phi_o;
};

// Views for the sweeps: θ_o off the nodes, φ_o in all four quadrants.
const ViewAngles kSweepViews[] = {{-60, 11}, {-26, 37}, {0, 69}, {20, 160}, {46, -20}, {69, -115}, {-78, 52}, {33, 83}};

void section_sweep(const std::shared_ptr<const HuangFiber> &fiber) {
    report.print("## 1. Bake evaluator and resolution (Blender's default Huang node)\n\n"
          "Aspect 0.85, roughness 0.3, IOR 1.55, offset 2°, σ_a from the default colour at β = 0.3. Relative variance of the "
          "table strategy (uniform weight %.3g) at 8 views (θ_o, φ_o) = (−60, 11), (−26, 37), (0, 69), (20, 160), (46, −20), "
          "(69, −115), (−78, 52), (33, 83)°. Bake CPU = the CPU seconds of the 1-thread bake (the work, whatever shares "
          "the cores); wall times on 1 and 2 threads are upper bounds: this machine's 2 cores were shared with other jobs "
          "(load average up to 10) while the study ran. Memory = HuangTable::memory_bytes.\n\n",
          double(kHuangUniformWeight));
    // f on grids aligned with each cell structure, computed once per structure.
    std::map<std::pair<int, int>, std::vector<ViewF>> views;
    auto views_for = [&](const HuangTable &table) -> const std::vector<ViewF> & {
        std::vector<ViewF> &v = views[{table.theta_i_count(), table.phi_count()}];
        if (v.empty())
            for (const ViewAngles &a : kSweepViews) {
                const FiberHit hit = hit_at(a.theta_o, a.phi_o);
                v.push_back(view_f(*fiber, hit, aligned(*fiber, table, hit, quick ? 2 : 4)));
            }
        return v;
    };

    struct Config {
        std::string label;
        HuangBakeOptions o;
    };
    auto with = [](int r, int q, int ti, int tp, const std::string &evaluator, int first, int second, int points = 1,
                   int estimates = 1) {
        HuangBakeOptions o;
        o.theta_o_count = r;
        o.phi_o_count = q;
        o.theta_i_count = ti;
        o.phi_count = tp;
        o.evaluator = evaluator;
        o.first_order = first;
        o.second_order = second;
        o.points = points;
        o.estimates = estimates;
        return o;
    };
    const HuangBakeOptions d{};
    auto at_default = [&](const std::string &evaluator, int first, int second, int points = 1, int estimates = 1) {
        return with(d.theta_o_count, d.phi_o_count, d.theta_i_count, d.phi_count, evaluator, first, second, points, estimates);
    };
    std::vector<Config> configs = {
        {"expectation (1,1)", at_default("expectation", 1, 1)},
        {"expectation (3,1)", at_default("expectation", 3, 1)},
        {"expectation (3,2)", at_default("expectation", 3, 2)},
        {"expectation (4,3) (default)", at_default("expectation", 4, 3)},
        {"expectation (5,3)", at_default("expectation", 5, 3)},
        {"expectation (3,2), 2×2 points", at_default("expectation", 3, 2, 2)},
        {"expectation (4,3), 2×2 points", at_default("expectation", 4, 3, 2)},
        {"Cycles eval ×1", at_default("estimate", 3, 2, 1, 1)},
        {"Cycles eval ×4", at_default("estimate", 3, 2, 1, 4)},
        {"Cycles eval ×1, 2×2 points", at_default("estimate", 3, 2, 2, 1)},
    };
    const int resolutions[][4] = {{12, 4, 48, 64}, {18, 4, 48, 64}, {36, 4, 48, 64}, {24, 2, 48, 64}, {24, 3, 48, 64},
                                  {24, 6, 48, 64}, {24, 4, 24, 32}, {24, 4, 32, 48}, {24, 4, 64, 96}};
    for (const auto &r : resolutions)
        configs.push_back({std::to_string(r[0]) + " × " + std::to_string(r[1]) + " × " + std::to_string(r[2]) + " × " +
                               std::to_string(r[3]) + ", (4,3)",
                           with(r[0], r[1], r[2], r[3], "expectation", 4, 3)});
    if (quick) configs.resize(3);

    report.print("First the evaluator at the default resolution (%d × %d × %d × %d), then the resolution θ_o nodes × φ_o nodes × "
          "θ_i cells × φ cells with the default evaluator.\n\n",
          d.theta_o_count, d.phi_o_count, d.theta_i_count, d.phi_count);
    report.print("| evaluator; θ_o × φ_o nodes × θ_i × φ cells | bake CPU (s) | bake 1 thread (s) | bake 2 threads (s) | memory (MB) | "
          "median relative variance | max |\n|---|---|---|---|---|---|---|\n");
    for (Config &c : configs) {
        c.o.threads = 1;
        const TableStrategy one = bake(*fiber, c.o);
        c.o.threads = 2;
        const TableStrategy two = bake(*fiber, c.o);
        const HairShading shading = shading_of(fiber, StrategyKind::Table, &two.table);
        std::vector<double> v;
        for (const ViewF &view : views_for(*two.table.table)) v.push_back(grid_variance(view, shading).relative);
        report.print("| %s | %.2f | %.2f | %.2f | %.2f | %s | %s |\n", c.label.c_str(), one.bake_cpu_seconds, one.bake_seconds, two.bake_seconds,
              double(two.table.table->memory_bytes()) / 1e6, number(median(v)).c_str(),
              number(*std::max_element(v.begin(), v.end())).c_str());
    }
    report.print("\n");
}

// ---------------------------------------------------------------------------------------------

struct FiberCase {
    float aspect, roughness;
};
const FiberCase kFibers[] = {{0.85f, 0.3f}, {0.85f, 0.05f}, {0.85f, 0.8f}, {0.5f, 0.3f}, {0.5f, 0.05f},
                             {0.5f, 0.8f},  {1.0f, 0.3f},   {1.0f, 0.05f}, {1.0f, 0.8f}};
const double kThetaO[] = {-70, -35, 0, 30, 65};
const double kPhiO[] = {10, 40, 75};

void section_strategies() {
    report.print("## 2. Strategies over θ_o, φ_o, aspect ratio and roughness\n\n"
          "Per fiber the median over θ_o ∈ {−70, −35, 0, 30, 65}° × φ_o ∈ {10, 40, 75}° (circular fibers: θ_o only) of the "
          "relative variance per sample of the luminance estimate of ∫ f cos dω_i. TABLE = the policy's table strategy "
          "(default bake, uniform weight %.3g; bake = its CPU seconds; grid: 2 points per table cell and axis); Cycles = Cycles' own sampler with its own weight (%lld samples per view), "
          "whose mean is Cycles' sampled energy: the last column is its median mean / ∫ f (eval's energy).\n\n",
          double(kHuangUniformWeight), quick ? 20000LL : 200000LL);
    report.print("| aspect | roughness | bake (s) | UNIFORM | Cycles | TABLE | TABLE / Cycles | Cycles mean / ∫ f |\n"
          "|---|---|---|---|---|---|---|---|\n");
    std::vector<double> ratios;
    std::vector<std::string> detail;
    for (const FiberCase &c : kFibers) {
        if (quick && c.roughness != 0.3f) continue;
        const auto fiber = make_fiber(params_of(c.aspect, c.roughness));
        HuangBakeOptions o;
        o.threads = 2;
        const TableStrategy t = bake(*fiber, o);
        const HairShading uniform = shading_of(fiber, StrategyKind::Uniform, nullptr);
        const HairShading table = shading_of(fiber, StrategyKind::Table, &t.table);
        std::vector<double> vu, vc, vt, mean_ratio, ratio;
        for (double theta : kThetaO)
            for (double phi : kPhiO) {
                if (c.aspect == 1.0f && phi != kPhiO[0]) continue;
                const FiberHit hit = hit_at(theta, phi);
                const ViewF v = view_f(*fiber, hit, aligned(*fiber, *t.table.table, hit, 2));
                const CyclesMoments cy = cycles_moments(*fiber, hit, quick ? 20000 : 200000);
                vu.push_back(grid_variance(v, uniform).relative);
                vt.push_back(grid_variance(v, table).relative);
                vc.push_back(cy.relative_variance);
                mean_ratio.push_back(cy.mean / v.integral);
                ratio.push_back(vt.back() / vc.back());
                ratios.push_back(ratio.back());
                char line[256];
                std::snprintf(line, sizeof line, "| %.2f | %.2f | %+.0f | %.0f | %s | %s | %s | %.3f | %.3f |\n", c.aspect,
                              c.roughness, theta, phi, number(vu.back()).c_str(), number(vc.back()).c_str(),
                              number(vt.back()).c_str(), mean_ratio.back(), v.integral);
                detail.push_back(line);
            }
        report.print("| %.2f | %.2f | %.1f | %s | %s | %s | %s | %.3f |\n", c.aspect, c.roughness, t.bake_cpu_seconds,
              number(median(vu)).c_str(), number(median(vc)).c_str(), number(median(vt)).c_str(),
              number(median(ratio)).c_str(), median(mean_ratio));
    }
    report.print("\nMedian over all views of TABLE's variance / Cycles': %s (target ≤ 0.5); largest: %s.\n\n",
          number(median(ratios)).c_str(), number(*std::max_element(ratios.begin(), ratios.end())).c_str());
    report.print("<details><summary>Every view</summary>\n\n| aspect | roughness | θ_o | φ_o | UNIFORM | Cycles | TABLE | Cycles mean / ∫ f | ∫ f |\n"
          "|---|---|---|---|---|---|---|---|---|\n");
    for (const std::string &l : detail) report.print("%s", l.c_str());
    report.print("\n</details>\n\n");

    // Monte Carlo check of the quadrature at four views of the default fiber.
    const auto fiber = make_fiber(params_of(0.85f, 0.3f));
    HuangBakeOptions o;
    o.threads = 2;
    const TableStrategy t = bake(*fiber, o);
    const HairShading table = shading_of(fiber, StrategyKind::Table, &t.table);
    report.print("Monte Carlo check (default fiber, TABLE, %d samples each): ", quick ? 2000 : 20000);
    for (const ViewAngles &a : {ViewAngles{-35, 40}, ViewAngles{0, 10}, ViewAngles{30, 75}, ViewAngles{65, 40}}) {
        const FiberHit hit = hit_at(a.theta_o, a.phi_o);
        const double q2 = grid_variance(view_f(*fiber, hit, aligned(*fiber, *t.table.table, hit, 2)), table).relative;
        const double q4 = grid_variance(view_f(*fiber, hit, aligned(*fiber, *t.table.table, hit, 4)), table).relative;
        const double mc = mc_variance(*fiber, table, hit, quick ? 2000 : 20000);
        report.print("(%.0f°, %.0f°) quadrature %s (2 points per cell and axis) and %s (4), Monte Carlo %s; ", a.theta_o, a.phi_o,
              number(q2).c_str(), number(q4).c_str(), number(mc).c_str());
    }
    report.print("\n\n");
}

// ---------------------------------------------------------------------------------------------

void section_uniform_weight() {
    report.print("## 3. The uniform part of TABLE's mixture\n\n"
          "A baked cell can be zero where f is not (a lobe narrower than the cell, missed by the cell's evaluation points, or "
          "an evaluator that returns 0 there): the table alone then never samples there and the estimate is biased. TABLE "
          "therefore mixes the table with the uniform sphere, weight u. Median relative variance over the 8 sweep views "
          "and the largest share of ∫ f the table alone (u = 0) leaves uncovered.\n\n");
    const float weights[] = {0.0f, 0.003f, 0.01f, 0.03f, 0.1f};
    report.print("| fiber |");
    for (float w : weights) report.print(" u = %.3g |", double(w));
    report.print(" uncovered at u = 0 |\n|---|");
    for (size_t k = 0; k <= std::size(weights); ++k) report.print("---|");
    report.print("\n");
    for (const FiberCase &c : {FiberCase{0.85f, 0.3f}, FiberCase{0.5f, 0.05f}, FiberCase{1.0f, 0.8f}}) {
        const auto fiber = make_fiber(params_of(c.aspect, c.roughness));
        HuangBakeOptions o;
        o.threads = 2;
        const TableStrategy t = bake(*fiber, o);
        std::vector<ViewF> views;
        for (const ViewAngles &a : kSweepViews) {
            const FiberHit hit = hit_at(a.theta_o, a.phi_o);
            views.push_back(view_f(*fiber, hit, aligned(*fiber, *t.table.table, hit, 2)));
        }
        report.print("| aspect %.2f, roughness %.2f |", c.aspect, c.roughness);
        double uncovered = 0;
        for (float w : weights) {
            const HairShading s = shading_of(fiber, StrategyKind::Table, &t.table, w);
            std::vector<double> v;
            for (const ViewF &view : views) {
                const Variance r = grid_variance(view, s);
                v.push_back(r.relative);
                if (w == 0.0f) uncovered = std::max(uncovered, r.uncovered);
            }
            report.print(" %s |", number(median(v)).c_str());
        }
        report.print(" %s |\n", number(uncovered).c_str());
    }
    report.print("\n");
}

// ---------------------------------------------------------------------------------------------

void section_near_field() {
    report.print("## 4. Near field\n\n"
          "Camera rays on hair wider than the pixel: pixel coverage 0.1 (the pixel sees a fifth of the fiber's width "
          "around h), f = the near-field expectation at h, sampled with the far-field table (TABLE ignores h). Relative "
          "variance at the default fiber, per view the median over h ∈ {−0.9, −0.5, 0, 0.5, 0.9}·R; the far field at the "
          "same view for comparison, and Cycles' sampler in the near field (it starts its paths at h).\n\n");
    const auto fiber = make_fiber(params_of(0.85f, 0.3f));
    HuangBakeOptions o;
    o.threads = 2;
    const TableStrategy t = bake(*fiber, o);
    const HairShading table = shading_of(fiber, StrategyKind::Table, &t.table);
    const HairShading uniform = shading_of(fiber, StrategyKind::Uniform, nullptr);
    const int sub = quick ? 2 : 4;
    report.print("| θ_o | φ_o | TABLE far | TABLE near (median over h) | TABLE near (max) | UNIFORM near | Cycles near |\n"
          "|---|---|---|---|---|---|---|\n");
    std::vector<double> far_all, near_all, cycles_all;
    for (const ViewAngles &a : {ViewAngles{-35, 40}, ViewAngles{0, 10}, ViewAngles{30, 75}, ViewAngles{65, 40}, ViewAngles{-70, 10}}) {
        const FiberHit far_hit = hit_at(a.theta_o, a.phi_o);
        const double far = grid_variance(view_f(*fiber, far_hit, aligned(*fiber, *t.table.table, far_hit, sub)), table).relative;
        const double radius = fiber->at(hit_at(a.theta_o, a.phi_o)).projected_radius();
        std::vector<double> vt, vu, vc;
        for (double h : {-0.9, -0.5, 0.0, 0.5, 0.9}) {
            const FiberHit hit = hit_at(a.theta_o, a.phi_o, float(h * radius), 0.1f);
            const ViewF v = view_f(*fiber, hit, aligned(*fiber, *t.table.table, hit, sub));
            if (!(v.integral > 0)) continue;
            vt.push_back(grid_variance(v, table).relative);
            vu.push_back(grid_variance(v, uniform).relative);
            vc.push_back(cycles_moments(*fiber, hit, quick ? 20000 : 200000).relative_variance);
        }
        far_all.push_back(far);
        near_all.push_back(median(vt));
        cycles_all.push_back(median(vc));
        report.print("| %.0f | %.0f | %s | %s | %s | %s | %s |\n", a.theta_o, a.phi_o, number(far).c_str(), number(median(vt)).c_str(),
              number(*std::max_element(vt.begin(), vt.end())).c_str(), number(median(vu)).c_str(),
              number(median(vc)).c_str());
    }
    report.print("\nMedians: TABLE far %s, TABLE near %s, Cycles near %s.\n\n", number(median(far_all)).c_str(),
          number(median(near_all)).c_str(), number(median(cycles_all)).c_str());
}

// ---------------------------------------------------------------------------------------------

void section_renderer_f() {
    report.print("## 6. TABLE with the renderer's f\n\n"
          "The sections above weight TABLE's samples with the expectation of Cycles' eval; a render weights "
          "them with one Cycles eval (HuangPoint::f: Simpson nodes in h with one microfacet chain each), a "
          "Monte Carlo estimate whose own variance adds to the sampler's. Relative variance per sample "
          "(Monte Carlo, %d samples per view, each at its own shading point's LCG) of luminance(f)/pdf: "
          "TABLE with the expectation, TABLE with one eval and with the mean of four, TABLE with the baked f (what "
          "renders weight with: R exact, the other lobes interpolated from the table's baked expectation), and Cycles' "
          "sampler with its own weight.\n\n"
          "| aspect | roughness | view (θ_o, φ_o) | TABLE, expectation f | TABLE, one Cycles eval | TABLE, mean of 4 evals | "
          "TABLE, baked f | Cycles' sampler | TABLE (one eval) / Cycles | TABLE (baked f) / Cycles |\n"
          "|---|---|---|---|---|---|---|---|---|---|\n",
          quick ? 4000 : 40000);
    for (const FiberCase &c : {FiberCase{0.85f, 0.3f}, FiberCase{0.5f, 0.25f}, FiberCase{0.85f, 0.05f}}) {
        const auto fiber = make_fiber(params_of(c.aspect, c.roughness));
        HuangBakeOptions o;
        o.threads = 2;
        const TableStrategy t = bake(*fiber, o);
        const HairShading table = shading_of(fiber, StrategyKind::Table, &t.table);
        const HairShading baked = baked_f_shading(fiber, t.table);
        for (const ViewAngles &a : {ViewAngles{-35, 40}, ViewAngles{0, 10}, ViewAngles{30, 75}, ViewAngles{65, 40}}) {
            const FiberHit hit = hit_at(a.theta_o, a.phi_o);
            const int n = quick ? 4000 : 40000;
            const double expectation = mc_variance(*fiber, table, hit, n);
            const double one_eval = mc_variance_renderer_f(*fiber, table, hit, n);
            const double four_evals = mc_variance_renderer_f(*fiber, table, hit, n, 4);
            const double baked_f = mc_variance_renderer_f(*fiber, baked, hit, n);
            const double cycles = cycles_moments(*fiber, hit, n).relative_variance;
            report.print("| %.2f | %.2f | (%.0f°, %.0f°) | %s | %s | %s | %s | %s | %s | %s |\n", c.aspect, c.roughness, a.theta_o,
                  a.phi_o, number(expectation).c_str(), number(one_eval).c_str(), number(four_evals).c_str(),
                  number(baked_f).c_str(), number(cycles).c_str(), number(one_eval / cycles).c_str(),
                  number(baked_f / cycles).c_str());
        }
    }
    report.print("\n");
}

// The largest weights: max / mean and the share of the second moment from the top 0.1%.
struct Tail {
    double max_over_mean = 0, top_share = 0;
};
Tail tail_of(std::vector<double> w) {
    std::sort(w.begin(), w.end());
    double sum = 0, sum2 = 0, top2 = 0;
    const size_t top = w.size() - std::max<size_t>(1, w.size() / 1000);
    for (size_t k = 0; k < w.size(); ++k) {
        sum += w[k];
        sum2 += w[k] * w[k];
        if (k >= top) top2 += w[k] * w[k];
    }
    const double mean = sum / double(w.size());
    return {mean > 0 ? w.back() / mean : 0.0, sum2 > 0 ? top2 / sum2 : 0.0};
}

void section_tails() {
    report.print("## 7. The largest weights\n\n"
          "Per view, over %d samples: the largest weight over the mean, and the share of the second moment "
          "carried by the largest 0.1%% of the weights: TABLE with one Cycles eval (a render's BSDF sample) "
          "and Cycles' sampler with its own weight. Default fiber (aspect 0.85, roughness 0.3).\n\n"
          "| view (θ_o, φ_o) | TABLE max / mean | TABLE top 0.1%% share | Cycles max / mean | Cycles top 0.1%% share |\n"
          "|---|---|---|---|---|\n",
          quick ? 20000 : 200000);
    const auto fiber = make_fiber(params_of(0.85f, 0.3f));
    HuangBakeOptions o;
    o.threads = 2;
    const TableStrategy t = bake(*fiber, o);
    const HairShading table = shading_of(fiber, StrategyKind::Table, &t.table);
    const int n = quick ? 20000 : 200000;
    for (const ViewAngles &a : {ViewAngles{-85, 40}, ViewAngles{-60, 10}, ViewAngles{0, 40}, ViewAngles{60, 75},
                                ViewAngles{85, 40}}) {
        const FiberHit hit = hit_at(a.theta_o, a.phi_o);
        ScratchBuffer scratch;
        std::mt19937_64 rng(77);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        std::vector<double> wt, wc;
        const HuangPoint point = fiber->at(hit);
        CyclesLcg lcg{12345u};
        for (int k = 0; k < n; ++k) {
            scratch.reset();
            FiberHit h = hit;
            h.seed = std::uint32_t(k) * 2654435761u + 7u;
            const HairBsdf bsdf = table.at(h, scratch);
            const auto s = bsdf.sample(u(rng), u(rng), u(rng));
            wt.push_back(s ? double(luminance(s->f)) / double(s->pdf) : 0.0);
            const auto c = point.sample_cycles(u(rng), u(rng), u(rng), lcg);
            wc.push_back(c ? double(luminance(c->weight)) : 0.0);
        }
        const Tail tt = tail_of(wt), tc = tail_of(wc);
        report.print("| (%.0f°, %.0f°) | %.1f | %.3f | %.1f | %.3f |\n", a.theta_o, a.phi_o, tt.max_over_mean, tt.top_share,
              tc.max_over_mean, tc.top_share);
    }
    report.print("\n");
}

void section_eval_noise() {
    const int draws = quick ? 500 : 4000;
    report.print("## 8. The noise of one Cycles eval, lobe by lobe\n\n"
          "One Cycles eval (HuangPoint::f_estimate) at a fixed pair of directions, drawn %d times from the point's LCG, "
          "at 300 random (ω_o, ω_i) pairs, with the other lobes' multipliers at 0 (TRRT+ comes with TRT: both need "
          "the internal reflection). Per pair the relative variance Var/mean²; the table gives its median over the "
          "pairs where the lobe's mean is not 0, the energy-weighted figure Σ Var / Σ mean² (pairs weighted by their "
          "mean², as a sampler proportional to f weighs them), the largest draw over its pair's mean, and how many "
          "pairs reach the resolution of %d draws (relative variance within 1%% of %d − 1). Default fiber otherwise.\n\n"
          "| lobes | pairs | median relative variance | energy-weighted | largest draw / mean | pairs at the resolution |\n"
          "|---|---|---|---|---|---|\n",
          draws, draws, draws);
    struct Variant {
        const char *label;
        float r, tt, trt;
    };
    for (const Variant &v : {Variant{"all (R, TT, TRT + TRRT+)", 1, 1, 1}, Variant{"R", 1, 0, 0},
                             Variant{"TT", 0, 1, 0}, Variant{"TRT + TRRT+", 0, 0, 1}}) {
        HuangParams p = params_of(0.85f, 0.3f);
        p.reflection = v.r;
        p.transmission = v.tt;
        p.secondary_reflection = v.trt;
        const auto fiber = make_fiber(p);
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        double largest = 0, variance_sum = 0, mean2_sum = 0;
        std::vector<double> relative;
        int capped = 0;
        for (int d = 0; d < 300; ++d) {
            const double theta_o = 170.0 * (u(rng) - 0.5);
            const double phi_o = 360.0 * (u(rng) - 0.5);
            const float theta_i = 3.1f * (u(rng) - 0.5f);
            const float phi_i = 6.28f * (u(rng) - 0.5f);
            const HuangPoint point = fiber->at(hit_at(theta_o, phi_o));
            const Vec3 wi = direction_of(theta_i, phi_i);
            CyclesLcg lcg{std::uint32_t(d) * 7919u + 1u};
            double sum = 0, sum2 = 0, top = 0;
            for (int k = 0; k < draws; ++k) {
                const double y = luminance(point.f_estimate(wi, lcg));
                sum += y;
                sum2 += y * y;
                top = std::max(top, y);
            }
            const double mean = sum / draws, variance = std::max(0.0, sum2 / draws - mean * mean);
            if (!(mean > 0)) continue;
            relative.push_back(variance / (mean * mean));
            if (relative.back() >= 0.99 * (draws - 1)) ++capped;
            variance_sum += variance;
            mean2_sum += mean * mean;
            largest = std::max(largest, top / mean);
        }
        report.print("| %s | %zu | %s | %s | %.0f | %d |\n", v.label, relative.size(),
              number(relative.empty() ? 0.0 : median(relative)).c_str(),
              number(mean2_sum > 0 ? variance_sum / mean2_sum : 0.0).c_str(), largest, capped);
    }
    report.print("\n");
}

// Stratified integral over the sphere of the expectation's four lobes (luminance) at `hit`.
std::array<double, 4> eval_energy(const HuangFiber &fiber, const FiberHit &hit, int simpson_refinement, int points) {
    HuangQuadrature q;
    q.simpson_refinement = simpson_refinement;
    const HuangPoint point = fiber.at(hit);
    const HuangExpectation e = fiber.expectation(point.huang_hit(), q);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::array<double, 4> sum{};
    for (int m = 0; m < points; ++m) {
        const double z = 1.0 - 2.0 * (m + u(rng)) / points, phi = 2.0 * kPi * u(rng);
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const Vec3 wi{float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)};
        const std::array<Rgb, 4> lobes = e.lobes(point.to_huang(wi));
        for (int k = 0; k < 4; ++k) sum[size_t(k)] += luminance(lobes[size_t(k)]);
    }
    for (double &v : sum) v *= 4.0 * kPi / points;
    return sum;
}

void section_sampler_against_eval() {
    const int samples = quick ? 20000 : 400000, points = quick ? 3000 : 20000;
    report.print("## 10. Cycles' sampler against its eval\n\n"
          "Cycles weights a BSDF sample of Huang hair with its chained sampler's weight and a light sample with its "
          "eval (docs/huang.md §8, §9). Per lobe, the energy each carries at one view (luminance, φ_o = 0): the "
          "sampler's as the mean weight of %d samples (HuangPoint::sample_cycles), the eval's as its expectation "
          "integrated over the sphere (%d stratified directions), with Cycles' Simpson step and with that step "
          "divided by 16 (the continuous integral over the offset the sampler draws from). Where the two differ, a "
          "renderer that weights every path with the eval (TABLE with the baked f) converges to another image "
          "than Cycles.\n\n"
          "| fiber | θ_o | sampler R, TT, TRT, TRRT+ | eval R, TT, TRT, TRRT+ | sampler / eval | eval, step / 16 |\n"
          "|---|---|---|---|---|---|\n",
          samples, points);
    struct Config {
        const char *label;
        float aspect, roughness;
        Rgb color;
    };
    for (const Config &c : {Config{"default node (0.85, 0.3)", 0.85f, 0.3f, {0.017513f, 0.005763f, 0.002059f}},
                            Config{"blond (0.85, 0.3)", 0.85f, 0.3f, {0.55f, 0.4f, 0.25f}},
                            Config{"blue, aspect 0.5, roughness 0.25", 0.5f, 0.25f, {0.2f, 0.5f, 0.8f}}}) {
        HuangParams p = params_of(c.aspect, c.roughness);
        p.sigma_a = principled_hair::sigma_from_reflectance(c.color, c.roughness);
        const auto fiber = make_fiber(p);
        for (double theta_o : {0.0, 30.0, 60.0, 75.0}) {
            const FiberHit hit = hit_at(theta_o, 0.0);
            const HuangPoint point = fiber->at(hit);
            std::mt19937 rng(17);
            std::uniform_real_distribution<float> u(0.0f, 1.0f);
            CyclesLcg lcg = point.lcg();
            std::array<double, 4> sampler{};
            for (int n = 0; n < samples; ++n) {
                const float u0 = u(rng), u1 = u(rng), u2 = u(rng);
                const std::optional<HuangCyclesSample> s = point.sample_cycles(u0, u1, u2, lcg);
                if (s) sampler[size_t(s->lobe)] += luminance(s->weight) / samples;
            }
            const std::array<double, 4> eval = eval_energy(*fiber, hit, 1, points);
            const std::array<double, 4> fine = eval_energy(*fiber, hit, 16, quick ? 1000 : 4000);
            const double total_s = sampler[0] + sampler[1] + sampler[2] + sampler[3];
            const double total_e = eval[0] + eval[1] + eval[2] + eval[3];
            report.print("| %s | %.0f° | %.3f, %.3f, %.3f, %.3f | %.3f, %.3f, %.3f, %.3f | %.3f | %.3f |\n", c.label, theta_o,
                  sampler[0], sampler[1], sampler[2], sampler[3], eval[0], eval[1], eval[2], eval[3],
                  total_s / total_e, fine[0] + fine[1] + fine[2] + fine[3]);
        }
    }
    report.print("\n");
}

// Nanoseconds (thread CPU time) per sample on one thread, best of three passes over random hits.
template <typename PerHit>
double time_per_sample(PerHit &&per_hit) {
    const int n = quick ? 1 << 12 : 1 << 15;
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<FiberHit> hits(static_cast<size_t>(n));
    std::vector<float> us(size_t(3) * n);
    for (int k = 0; k < n; ++k) {
        hits[size_t(k)] = hit_at(180.0 * (u(rng) - 0.5), 360.0 * (u(rng) - 0.5));
        hits[size_t(k)].seed = std::uint32_t(k);
        for (int d = 0; d < 3; ++d) us[size_t(3) * k + d] = u(rng);
    }
    double best = 1e30;
    volatile float sink = 0;
    for (int pass = 0; pass < 3; ++pass) {
        float checksum = 0;
        const double t0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
        for (int k = 0; k < n; ++k) checksum += per_hit(hits[size_t(k)], &us[size_t(3) * k]);
        best = std::min(best, (cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - t0) * 1e9 / n);
        sink = sink + checksum;
    }
    return best;
}

void section_time() {
    report.print("## 5. Time per sample\n\n"
          "One thread (its CPU time), random views (θ_o, φ_o) over the sphere, best of three passes. TABLE and UNIFORM: prepare the hit "
          "(fiber point and sampler point), sample (the direction and its pdf), f there (one Cycles eval: HuangPoint::f) "
          "and one more pdf query; also sample + pdf alone. Cycles: prepare the fiber point and Cycles' sampler (its weight "
          "replaces f/pdf). In a path tracer with next-event estimation the light sample needs f (one Cycles eval) either "
          "way; the last column adds one f to Cycles' time for that comparison.\n\n"
          "| aspect | roughness | TABLE: prepare + sample + pdf + f (ns) | TABLE: sample + pdf (ns) | UNIFORM: prepare + sample + "
          "pdf + f (ns) | Cycles: prepare + sample (ns) | f alone (ns) | TABLE / Cycles | (TABLE + f) / (Cycles + f) |\n"
          "|---|---|---|---|---|---|---|---|---|\n");
    for (const FiberCase &c : {FiberCase{0.85f, 0.3f}, FiberCase{0.85f, 0.05f}, FiberCase{0.85f, 0.8f}, FiberCase{1.0f, 0.3f}}) {
        const auto fiber = make_fiber(params_of(c.aspect, c.roughness));
        HuangBakeOptions o;
        o.threads = 2;
        const TableStrategy t = bake(*fiber, o);
        const HairShading table = shading_of(fiber, StrategyKind::Table, &t.table);
        const HairShading uniform = shading_of(fiber, StrategyKind::Uniform, nullptr);
        ScratchBuffer scratch;
        auto full = [&](const HairShading &s) {
            return time_per_sample([&](const FiberHit &hit, const float *u) {
                scratch.reset();
                const HairBsdf b = s.at(hit, scratch);
                const auto d = b.sample(u[0], u[1], u[2]);
                return d ? d->pdf + luminance(d->f) + b.pdf(d->wi) : 0.0f;
            });
        };
        const double t_table = full(table), t_uniform = full(uniform);
        // The sampler alone at a prepared fiber point.
        const double t_sample = time_per_sample([&](const FiberHit &hit, const float *u) {
            scratch.reset();
            const FiberPoint &p = fiber->prepare(hit, scratch);
            const SamplerPoint &sp = table.sampler().at(hit, &p, scratch);
            const auto d = sp.sample(u[0], u[1], u[2]);
            return d ? d->pdf + sp.pdf(d->wi) : 0.0f;
        });
        const double t_prepare = time_per_sample([&](const FiberHit &hit, const float *) {
            scratch.reset();
            return float(static_cast<const HuangPoint &>(fiber->prepare(hit, scratch)).projected_radius());
        });
        const double t_cycles = time_per_sample([&](const FiberHit &hit, const float *u) {
            scratch.reset();
            const HuangPoint &p = static_cast<const HuangPoint &>(fiber->prepare(hit, scratch));
            CyclesLcg lcg{hit.seed};
            const auto s = p.sample_cycles(u[0], u[1], u[2], lcg);
            return s ? s->weight.g : 0.0f;
        });
        const double t_f = time_per_sample([&](const FiberHit &hit, const float *u) {
            scratch.reset();
            const FiberPoint &p = fiber->prepare(hit, scratch);
            return luminance(p.f(direction_of(float(kPi) * (u[0] - 0.5f), float(kTwoPi) * u[1])));
        }) - t_prepare;
        report.print("| %.2f | %.2f | %.0f | %.0f | %.0f | %.0f | %.0f | %.1f | %.2f |\n", c.aspect, c.roughness, t_table,
              t_sample - t_prepare, t_uniform, t_cycles, t_f, t_table / t_cycles, (t_table + t_f) / (t_cycles + t_f));
    }
    report.print("\n");
}

}  // namespace

// ---------------------------------------------------------------------------------------------

// The baked f against the expectation at a finer rule, over random views and a jittered grid of
// ω_i: R (analytic in the tabulated fiber) and the interpolated TT + TRT + TRRT+.
struct BakedFError {
    double r_max = 0;            // largest |R error| / R's peak in the view
    double l1 = 0, integral = 0;  // Σ|Δ| / Σ f and Σ f_baked / Σ f − 1 (TT + TRT + TRRT+)
    double rule_l1 = 0, rule_integral = 0;  // the same for the bake's rule itself, not interpolated
    double reading_l1 = 0;                  // Σ|f_baked − f at the bake's rule| / Σ f: the reading alone
    double max_relative = 0;     // largest |Δ| / f where f ≥ 5% of the view's peak
    double p99_relative = 0;     // its 99th percentile
};

BakedFError baked_f_error(const HuangFiber &fiber, const HairShading &baked, int views, int grid) {
    HuangQuadrature reference;
    reference.first_order = 8;
    reference.second_order = 6;
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    struct View {
        FiberHit hit;
        std::vector<Vec3> wi;
    };
    std::vector<View> all(static_cast<size_t>(views));
    for (View &v : all) {
        v.hit = hit_at(std::asin(2 * u(rng) - 1) * 180 / kPi, 360 * (u(rng) - 0.5));
        for (int i = 0; i < grid; ++i)
            for (int j = 0; j < 2 * grid; ++j)
                v.wi.push_back(direction_of(float(std::asin(-1 + 2 * (i + u(rng)) / grid)),
                                            float(-kPi + kPi * (j + u(rng)) / grid)));
    }
    struct Sums {
        double r_max = 0, abs = 0, ref = 0, tab = 0, rule_abs = 0, rule = 0, reading_abs = 0;
        std::vector<double> relative;
    };
    HuangQuadrature bake_rule;
    bake_rule.first_order = HuangBakeOptions{}.f_first_order;
    bake_rule.second_order = HuangBakeOptions{}.f_second_order;
    bake_rule.tt_order = HuangBakeOptions{}.f_tt_order;
    std::vector<Sums> sums(all.size());
    tbb::parallel_for(0, views, [&](int k) {
        const View &v = all[size_t(k)];
        ScratchBuffer scratch;
        const HuangPoint point = fiber.at(v.hit);
        const HuangExpectation e = fiber.expectation(point.huang_hit(), reference);
        const HuangExpectation at_rule = fiber.expectation(point.huang_hit(), bake_rule);
        const HairBsdf bsdf = baked.at(v.hit, scratch);
        std::vector<double> want, got, ruled;
        double r_peak = 0, r_err = 0, peak = 0;
        for (const Vec3 &wi : v.wi) {
            const std::array<Rgb, 4> lobes = e.lobes(point.to_huang(wi));
            const double r_ref = luminance(lobes[0]), r_got = luminance(point.f_reflection(wi));
            r_peak = std::max(r_peak, r_ref);
            r_err = std::max(r_err, std::fabs(r_got - r_ref));
            want.push_back(luminance(lobes[1] + lobes[2] + lobes[3]));
            const std::array<Rgb, 4> r = at_rule.lobes(point.to_huang(wi));
            ruled.push_back(luminance(r[1] + r[2] + r[3]));
            got.push_back(luminance(bsdf.f(wi)) - r_got);
            peak = std::max(peak, want.back());
        }
        Sums &out = sums[size_t(k)];
        out.r_max = r_peak > 0 ? r_err / r_peak : 0;
        for (size_t n = 0; n < want.size(); ++n) {
            out.abs += std::fabs(got[n] - want[n]);
            out.ref += want[n];
            out.tab += got[n];
            out.rule_abs += std::fabs(ruled[n] - want[n]);
            out.reading_abs += std::fabs(got[n] - ruled[n]);
            out.rule += ruled[n];
            if (want[n] >= 0.05 * peak && want[n] > 0) out.relative.push_back(std::fabs(got[n] - want[n]) / want[n]);
        }
    });
    BakedFError e;
    double abs = 0, ref = 0, tab = 0, rule_abs = 0, rule = 0, reading_abs = 0;
    std::vector<double> relative;
    for (const Sums &x : sums) {
        rule_abs += x.rule_abs;
        reading_abs += x.reading_abs;
        rule += x.rule;
        e.r_max = std::max(e.r_max, x.r_max);
        abs += x.abs;
        ref += x.ref;
        tab += x.tab;
        relative.insert(relative.end(), x.relative.begin(), x.relative.end());
    }
    e.l1 = abs / ref;
    e.integral = tab / ref - 1;
    e.rule_l1 = rule_abs / ref;
    e.rule_integral = rule / ref - 1;
    e.reading_l1 = reading_abs / ref;
    std::sort(relative.begin(), relative.end());
    if (!relative.empty()) {
        e.max_relative = relative.back();
        e.p99_relative = relative[size_t(0.99 * double(relative.size() - 1))];
    }
    return e;
}

// Median time of one f evaluation (ns), one thread: the baked f and one Cycles eval at the same
// random (hit, ω_i) pairs, interleaved pass by pass.
std::pair<double, double> f_time(const HuangFiber &fiber, const HairShading &baked) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    constexpr int n = 2000;
    std::vector<FiberHit> hits;
    std::vector<Vec3> wi;
    for (int k = 0; k < n; ++k) {
        hits.push_back(hit_at(180.0 * (u(rng) - 0.5), 360.0 * (u(rng) - 0.5)));
        wi.push_back(direction_of(float(std::asin(2 * u(rng) - 1)), float(kPi * (2 * u(rng) - 1))));
    }
    std::vector<double> t_baked, t_cycles;
    volatile float sink = 0;
    ScratchBuffer scratch;
    for (int pass = 0; pass < 5; ++pass) {
        // Both include preparing the point at the hit, once per evaluation.
        auto t0 = std::chrono::steady_clock::now();
        for (int k = 0; k < n; ++k) {
            scratch.reset();
            sink = sink + baked.at(hits[size_t(k)], scratch).f(wi[size_t(k)]).r;
        }
        t_baked.push_back(seconds_since(t0) / n * 1e9);
        t0 = std::chrono::steady_clock::now();
        for (int k = 0; k < n; ++k) sink = sink + fiber.at(hits[size_t(k)]).f(wi[size_t(k)]).r;
        t_cycles.push_back(seconds_since(t0) / n * 1e9);
    }
    std::sort(t_baked.begin(), t_baked.end());
    std::sort(t_cycles.begin(), t_cycles.end());
    return {t_baked[2], t_cycles[2]};
}

void section_baked_f() {
    const int views = quick ? 6 : 48, grid = quick ? 16 : 32;
    report.print("## 9. The baked f against the expectation\n\n"
          "Renders shade Huang hair with R exactly (Cycles' R is deterministic) and TT + TRT + TRRT+ interpolated from the "
          "expectation baked beside the sampling table (the default bake: f part at the rule (%d,%d), TT's entry at %d). Against the "
          "expectation at the rule (8,6), over %d random far-field views × a jittered %d × %d grid of ω_i, in luminance: "
          "R's largest error over its peak; for TT + TRT + TRRT+ the L1 error Σ|Δ|/Σ f (the error light from every "
          "direction sees), the error of the integral Σ f_baked/Σ f − 1, and the largest and 99th-percentile relative "
          "error where f is at least 5%% of the view's peak (a narrow lobe's sides); the bake's rule alone (the expectation "
          "at that rule, not interpolated) for comparison, and the reading alone (the baked f against the expectation at "
          "the bake's own rule, L1). Bake: wall seconds on 2 threads of the "
          "default Huang bake (sampling and f parts, no multiple part); memory: the sampling table and the f part. Time: "
          "one f at a hit (preparing the point included), one thread, median of 5 interleaved passes.\n\n"
          "| aspect | roughness | bake (s) | memory (MB) | R max error | L1 | integral | max relative | 99%% relative | "
          "rule alone: L1 | rule alone: integral | reading alone: L1 | baked f (ns) | Cycles eval (ns) |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
          HuangBakeOptions{}.f_first_order, HuangBakeOptions{}.f_second_order, HuangBakeOptions{}.f_tt_order, views, grid,
          2 * grid);
    const FiberCase cases[] = {{0.85f, 0.3f}, {0.5f, 0.25f}, {1.0f, 0.3f}, {0.85f, 0.1f}, {0.5f, 0.1f},
                               {1.0f, 0.1f},  {0.85f, 0.8f}, {0.5f, 0.8f}};
    for (const FiberCase &c : cases) {
        if (quick && c.roughness == 0.8f) continue;
        const auto fiber = make_fiber(params_of(c.aspect, c.roughness));
        HuangBakeOptions o;
        o.threads = 2;
        const TableStrategy t = bake(*fiber, o);
        const HairShading baked = baked_f_shading(fiber, t.table);
        const BakedFError e = baked_f_error(*fiber, baked, views, grid);
        const auto [ns_baked, ns_cycles] = f_time(*fiber, baked);
        const double mb = double(t.table.table->memory_bytes() + t.table.f->memory_bytes()) / 1e6;
        report.print("| %.2f | %.2f | %.1f | %.1f | %s | %.2f%% | %+.2f%% | %.0f%% | %.1f%% | %.2f%% | %+.2f%% | %.2f%% | %.0f | %.0f |\n",
              c.aspect, c.roughness, t.bake_seconds, mb, number(e.r_max).c_str(), 100 * e.l1, 100 * e.integral,
              100 * e.max_relative, 100 * e.p99_relative, 100 * e.rule_l1, 100 * e.rule_integral, 100 * e.reading_l1,
              ns_baked, ns_cycles);
    }
    report.print("\n");
}

int main(int argc, char **argv) {
    const std::string folder = argc > 1 ? argv[1] : "";
    quick = argc > 2 && std::string(argv[2]) == "quick";
    const std::string sections = argc > 3 ? argv[3] : "123456789a";
    auto run = [&](char section) { return sections.find(section) != std::string::npos; };
    tbb::task_arena arena(2);
    arena.execute([&] {
        report.print("# Huang study\n\nGenerated by bench/huang_study%s. f = HuangExpectation at the rule (6,4) (its L1 error against "
              "the reference rule (16,12) is about 1%% at roughness 0.3); variances by grid quadrature (see the file's "
              "header) unless marked Monte Carlo. Default bake: %d θ_o × %d φ_o nodes × %d θ_i × %d φ cells, evaluator "
              "%s (%d,%d), %d point per cell.\n\n",
              quick ? " (quick mode: coarse grids, few configurations)" : "", HuangBakeOptions{}.theta_o_count,
              HuangBakeOptions{}.phi_o_count, HuangBakeOptions{}.theta_i_count, HuangBakeOptions{}.phi_count,
              HuangBakeOptions{}.evaluator.c_str(), HuangBakeOptions{}.first_order, HuangBakeOptions{}.second_order,
              HuangBakeOptions{}.points);
        const auto t0 = std::chrono::steady_clock::now();
        if (run('1')) section_sweep(make_fiber(params_of(0.85f, 0.3f)));
        if (run('2')) section_strategies();
        if (run('3')) section_uniform_weight();
        if (run('4')) section_near_field();
        if (run('5')) section_time();
        if (run('6')) section_renderer_f();
        if (run('7')) section_tails();
        if (run('8')) section_eval_noise();
        if (run('9')) section_baked_f();
        if (run('a')) section_sampler_against_eval();
        report.print("Total study time %.0f s.\n", seconds_since(t0));
    });
    if (!folder.empty()) {
        std::ofstream md(folder + "/huang_study.md");
        md << report.str();
        if (!md) {
            std::fprintf(stderr, "huang_study: could not write into %s\n", folder.c_str());
            return 1;
        }
    }
    return 0;
}
