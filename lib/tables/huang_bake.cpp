#include "tables/huang_bake.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <optional>
#include <vector>

#include "core/frame.h"
#include "sampling/huang_absorption_table.h"

namespace hairis {

namespace {

// splitmix64's finalizer: a per-cell LCG seed from the cell's index.
std::uint32_t cell_seed(std::uint64_t index) {
    std::uint64_t z = index + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return std::uint32_t((z ^ (z >> 31)) >> 32);
}

// What f is evaluated from at one view node.
struct NodeView {
    std::optional<HuangExpectation> expectation;
    std::optional<HuangPoint> point;  // Huang's frame = this point's frame (normal on y)
    std::optional<HuangExpectation> f;  // the f part's (HuangBakeOptions::f)
};

}  // namespace

Status HuangBakeOptions::validate() const {
    if (Status s = first_error(check::count_in_range("theta_o_count", theta_o_count, 1, kMaxThetaRNodes),
                               check::count_in_range("phi_o_count", phi_o_count, 1, kMaxPhiONodes),
                               check::count_in_range("theta_i_count", theta_i_count, 1, kMaxTableAxisCells),
                               check::count_in_range("phi_count", phi_count, 1, kMaxTableAxisCells),
                               check::count_in_range("points", points, 1, 16),
                               check::count_in_range("first_order", first_order, 1, 32),
                               check::count_in_range("second_order", second_order, 1, 32),
                               check::count_in_range("estimates", estimates, 1, 1024),
                               check::count_in_range("threads", threads, 0, 1024),
                               check::count_in_range("f_first_order", f_first_order, 1, 32),
                               check::count_in_range("f_second_order", f_second_order, 1, 32),
                               check::count_in_range("f_tt_order", f_tt_order, 0, 32),
                               check::count_in_range("f_refinement", f_refinement, 1, kMaxHuangFRefinement)))
        return s;
    if (const int finest = std::max({f_first_order, f_second_order, f_tt_order}) * f_refinement; finest > 32)
        return Error{"f_refinement " + std::to_string(f_refinement) + " makes the f part's finest order " +
                     std::to_string(finest) + "; at most 32"};
    if (!absorption_nodes.empty()) {
        if (!f) return Error{"the absorption part (absorption_nodes) needs the f part (f)"};
        if (Status s = check_huang_absorption_nodes(absorption_nodes, "absorption_nodes")) return s;
    }
    if (evaluator != "expectation" && evaluator != "estimate")
        return Error{"evaluator must be \"expectation\" or \"estimate\" (got \"" + evaluator + "\")"};
    const long long cells = (long long)theta_o_count * phi_o_count * theta_i_count * phi_count;
    if (cells > kMaxTableCells)
        return Error{"theta_o_count × phi_o_count × theta_i_count × phi_count = " + std::to_string(cells) +
                     " cells; at most " + std::to_string(kMaxTableCells) + " are allowed"};
    return std::nullopt;
}

std::vector<float> huang_phi_o_nodes(int count) {
    if (count <= 1) return {float(kHalfPi)};
    std::vector<float> nodes(static_cast<std::size_t>(count));
    for (int k = 0; k < count; ++k) nodes[std::size_t(k)] = float(kHalfPi * k / (count - 1));
    return nodes;
}

namespace {

bool p_is_one(const HuangBakeOptions &o) { return o.points == 1; }

// huang_dual_scattering keeps the averages of this many fibers (the oldest goes first).
constexpr std::size_t kHuangDualCacheSize = 16;

Expected<HuangTableSet> bake_in_arena(const HuangFiber &fiber, const HuangBakeOptions &o, const ProgressFn &progress) {
    HuangTableSet t;
    t.parameters = huang_parameters(fiber.params());
    t.theta_o_nodes = theta_r_nodes(o.theta_o_count);
    t.phi_o_nodes = huang_phi_o_nodes(fiber.aspect_ratio() == 1.0 ? 1 : o.phi_o_count);
    t.theta_i_count = o.theta_i_count;
    t.phi_count = o.phi_count;
    const int n_r = o.theta_o_count, n_q = int(t.phi_o_nodes.size()), n_i = o.theta_i_count, n_j = o.phi_count;
    t.values.assign(std::size_t(n_q) * n_r * n_i * n_j, 0.0f);
    const bool expectation = o.evaluator == "expectation";
    HuangQuadrature rule;
    rule.first_order = o.first_order;
    rule.second_order = o.second_order;
    rule.tt_order = o.f_tt_order;
    HuangQuadrature f_rule;
    f_rule.first_order = o.f_first_order * o.f_refinement;
    f_rule.second_order = o.f_second_order * o.f_refinement;
    f_rule.tt_order = o.f_tt_order * o.f_refinement;
    // The sampling values reuse the f part's evaluations when both use one rule at one point.
    const bool shared_rule = o.f && expectation && p_is_one(o) && f_rule.first_order == o.first_order &&
                             f_rule.second_order == o.second_order && f_rule.tt_order == o.f_tt_order;
    if (o.f) {
        t.f.assign(3 * t.values.size(), 0.0f);
        t.f_refinement = o.f_refinement;
    }
    // The absorption part's values come from the f part's chains, coloured at each node.
    const std::vector<double> absorptions(o.absorption_nodes.begin(), o.absorption_nodes.end());
    const std::size_t n_k = absorptions.size();
    if (n_k > 0) {
        t.absorption_nodes = o.absorption_nodes;
        t.absorption.assign(n_k * t.values.size(), 0.0f);
    }
    const int p = o.points;
    std::atomic<bool> bad{false};

    // One θ_o node at a time keeps progress and cancel responsive; every cell is computed
    // alone (its own seed), so the result does not depend on the thread count.
    std::vector<NodeView> views(static_cast<std::size_t>(n_q));
    for (int r = 0; r < n_r; ++r) {
        if (progress && !progress(float(r) / float(n_r))) return Error{"cancelled", ErrorKind::Cancelled};
        const float theta_o = t.theta_o_nodes[std::size_t(r)];
        tbb::parallel_for(0, n_q, [&](int q) {
            const Vec3 wo = direction_of(theta_o, t.phi_o_nodes[std::size_t(q)]);
            NodeView &v = views[std::size_t(q)];
            if (o.f) v.f.emplace(fiber.expectation(HuangHit{wo, 0.0f, 1.0f}, f_rule, absorptions));
            if (shared_rule) {
                v.expectation.reset();
            } else if (expectation) {
                v.expectation.emplace(fiber.expectation(HuangHit{wo, 0.0f, 1.0f}, rule));
            } else {
                FiberHit hit;
                hit.wo = wo;
                hit.normal = {0.0f, 1.0f, 0.0f};
                v.point.emplace(fiber, hit);
            }
        });
        tbb::parallel_for(0, n_q * n_i, [&](int row) {
            const int q = row / n_i, i = row % n_i;
            const NodeView &v = views[std::size_t(q)];
            const double phi_o = t.phi_o_nodes[std::size_t(q)];
            const double s0 = std::sin(-kHalfPi + kPi * i / n_i), s1 = std::sin(-kHalfPi + kPi * (i + 1) / n_i);
            const std::size_t first = ((std::size_t(q) * n_r + std::size_t(r)) * n_i + std::size_t(i)) * n_j;
            for (int j = 0; j < n_j; ++j) {
                CyclesLcg lcg{cell_seed(first + std::size_t(j))};
                double sum = 0.0;
                if (o.f) {
                    // The cell's midpoint in sin θ_i and φ (the p = 1 point).
                    const double theta_i = std::asin(std::clamp(0.5 * (s0 + s1), -1.0, 1.0));
                    const double phi = -kPi + kTwoPi * (j + 0.5) / n_j;
                    double rest_at[kMaxHuangAbsorptionNodes];
                    const std::array<Rgb, 4> lobes =
                        v.f->lobes(direction_of(float(theta_i), float(phi_o + phi)), n_k ? rest_at : nullptr);
                    const Rgb rest = lobes[1] + lobes[2] + lobes[3];
                    float *out = &t.f[3 * (first + std::size_t(j))];
                    out[0] = rest.r;
                    out[1] = rest.g;
                    out[2] = rest.b;
                    if (!(std::isfinite(rest.r) && std::isfinite(rest.g) && std::isfinite(rest.b) && rest.r >= 0.0f &&
                          rest.g >= 0.0f && rest.b >= 0.0f))
                        bad = true;
                    if (shared_rule) sum = luminance(lobes[0] + rest);
                    for (std::size_t k = 0; k < n_k; ++k) {
                        const float value = float(rest_at[k]);
                        t.absorption[n_k * (first + std::size_t(j)) + k] = value;
                        if (!(std::isfinite(value) && value >= 0.0f)) bad = true;
                    }
                }
                for (int a = 0; a < (shared_rule ? 0 : p); ++a) {
                    const double theta_i = std::asin(std::clamp(s0 + (s1 - s0) * (a + 0.5) / p, -1.0, 1.0));
                    for (int b = 0; b < p; ++b) {
                        const double phi = -kPi + kTwoPi * (j + (b + 0.5) / p) / n_j;
                        const Vec3 wi = direction_of(float(theta_i), float(phi_o + phi));
                        if (expectation) {
                            sum += luminance(v.expectation->f(wi));
                        } else {
                            for (int e = 0; e < o.estimates; ++e) sum += luminance(v.point->f_estimate(wi, lcg));
                        }
                    }
                }
                const double value = shared_rule ? sum : sum / (double(p) * p * (expectation ? 1 : o.estimates));
                if (!(std::isfinite(value) && value >= 0.0)) bad = true;
                t.values[first + std::size_t(j)] = float(value);
            }
        });
        if (bad) return Error{"the fiber's f is not finite and non-negative at theta_o node " + std::to_string(r) +
                              " (a bug in the fiber model)"};
    }
    if (progress && !progress(1.0f)) return Error{"cancelled", ErrorKind::Cancelled};
    return t;
}

}  // namespace

Expected<HuangTableSet> bake_huang_table(const HuangFiber &fiber, const HuangBakeOptions &options,
                                         const ProgressFn &progress) {
    if (Status s = options.validate()) return *s;
    tbb::task_arena arena(options.threads > 0 ? options.threads : int(tbb::task_arena::automatic));
    Expected<HuangTableSet> result = Error{"not run"};
    arena.execute([&] { result = bake_in_arena(fiber, options, progress); });
    return result;
}

Expected<std::shared_ptr<const DualScattering>> huang_dual_scattering(const HuangFiber &fiber) {
    static std::mutex mutex;
    static std::deque<std::pair<std::string, std::shared_ptr<const DualScattering>>> cache;
    const std::string key = canonical_parameters(huang_parameters(fiber.params()));
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto &entry : cache)
        if (entry.first == key) return entry.second;
    // Dual scattering integrates f over directions, where the coarse rule's ripples cancel.
    HuangQuadrature rule;
    rule.first_order = 4;
    rule.second_order = 3;
    Expected<HuangFiber> evaluated = HuangFiber::create(fiber.params(), rule);
    if (!evaluated) return evaluated.error();
    DualScatteringParams params;
    params.theta_count = 16;
    params.theta_panels = 8;
    params.phi_panels = 4;
    Expected<DualScattering> made = DualScattering::create(evaluated.value(), params);
    if (!made) return made.error();
    auto dual = std::make_shared<const DualScattering>(std::move(made).value());
    if (cache.size() == kHuangDualCacheSize) cache.pop_front();
    cache.emplace_back(key, dual);
    return dual;
}

Expected<TableSet> bake_huang_tables(const HuangFiber &fiber, const BakeOptions &options, const ProgressFn &progress) {
    if (options.source != "exact")
        return Error{"source must be \"exact\" for a huang2022 fiber (got \"" + options.source +
                     "\"): its tables are the Huang table, baked from the fiber"};
    HuangBakeOptions o;
    o.theta_o_count = options.huang.theta_o;
    o.phi_o_count = options.huang.phi_o;
    o.theta_i_count = options.huang.theta_i;
    o.phi_count = options.huang.phi;
    o.threads = options.threads;
    o.f = options.huang_f;
    o.f_refinement = options.huang_f_refinement;
    if (options.huang_absorption) o.absorption_nodes = huang_absorption_nodes();
    if (Status s = o.validate()) return Error{"the Huang resolution (huang_theta_o, huang_phi_o, huang_theta_i, huang_phi): " + s->message};
    // The file's image: one row per (φ_o node, θ_o node, θ_i cell), refused before the bake.
    const long long rows = (long long)(fiber.aspect_ratio() == 1.0 ? 1 : o.phi_o_count) * o.theta_o_count *
                           o.theta_i_count *
                           (1 + (o.f ? 1 : 0) + (int(o.absorption_nodes.size()) + 3) / 4);  // the f and absorption parts
    const long long multiple_rows = options.huang_multiple ? (long long)options.theta_r_count * options.theta_i_count : 0;
    if (Status s = TableImageSize{std::max<long long>(o.phi_count, (long long)options.n_h_values.size()),
                                  rows + multiple_rows}.validate())
        return *s;
    if (options.huang_multiple && options.n_h_values.empty())
        return Error{"huang_multiple needs at least one n_h value"};
    if (HuangTable::bytes_needed(o.theta_o_count, o.phi_o_count, o.theta_i_count, o.phi_count) > kMaxSamplingTableBytes)
        return Error{"the Huang table (huang_theta_o x huang_phi_o x huang_theta_i x huang_phi) would need more than " +
                     std::to_string(kMaxSamplingTableBytes) + " bytes; bake fewer cells"};
    // The Huang table takes progress to 0.8 when the multiple part follows.
    const float table_share = options.huang_multiple ? 0.8f : 1.0f;
    ProgressFn table_progress;
    if (progress) table_progress = [&](float f) { return progress(f * table_share); };
    Expected<HuangTableSet> baked = bake_huang_table(fiber, o, table_progress);
    if (!baked) return baked.error();
    TableSet t;
    t.model = fiber.name();
    t.source = "exact";
    t.parameters = baked.value().parameters;
    t.huang = std::make_shared<const HuangTableSet>(std::move(baked).value());
    if (options.huang_multiple) {
        tbb::task_arena arena(options.threads > 0 ? options.threads : int(tbb::task_arena::automatic));
        Expected<std::shared_ptr<const DualScattering>> dual = Error{"not run"};
        arena.execute([&] { dual = huang_dual_scattering(fiber); });
        if (!dual) return Error{"dual scattering: " + dual.error().message};
        t.theta_r_nodes = theta_r_nodes(options.theta_r_count);
        t.theta_i_count = options.theta_i_count;
        t.n_h_values = options.n_h_values;
        const size_t slice = options.n_h_values.size() * size_t(options.theta_i_count);
        t.multiple.assign(size_t(options.theta_r_count) * slice, 0.0f);
        for (int r = 0; r < options.theta_r_count; ++r) {
            if (progress && !progress(0.9f + 0.1f * float(r) / float(options.theta_r_count)))
                return Error{"cancelled", ErrorKind::Cancelled};
            Status s;
            arena.execute([&] { s = bake_multiple_slice(*dual.value(), t.theta_r_nodes[size_t(r)], options,
                                                        &t.multiple[size_t(r) * slice]); });
            if (s) return *s;
        }
        if (progress && !progress(1.0f)) return Error{"cancelled", ErrorKind::Cancelled};
    }
    if (Status s = t.validate()) return Error{"the baked Huang table is invalid (a bug): " + s->message};
    return t;
}

}  // namespace hairis
