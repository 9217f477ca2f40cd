#include "tables/bake.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <memory>

#include "fiber/distributions.h"
#include "fiber/chiang.h"
#include "fiber/dual_scattering.h"
#include "sampling/near_field_table.h"
#include "tables/huang_bake.h"

namespace hairis {

namespace {

// Cell average of a density over a (θ, φ) cell per unit solid angle, by a q×q midpoint
// rule in (sin θ, φ): the measure of a cell in sin θ is its solid angle.
template <typename Density>
double cell_average(const Density &density, double s0, double s1, double p0, double p1, int q) {
    double sum = 0.0;
    for (int a = 0; a < q; ++a) {
        const double s = s0 + (s1 - s0) * (a + 0.5) / q;
        const double theta = std::asin(std::clamp(s, -1.0, 1.0));
        for (int b = 0; b < q; ++b) sum += density(theta, p0 + (p1 - p0) * (b + 0.5) / q);
    }
    return sum / double(q * q);
}

}  // namespace

Status BakeOptions::validate() const {
    if (Status s = first_error(
            TableResolution{theta_r_count, theta_i_count, phi_count}.validate(),
            check::count_in_range("quadrature_points", quadrature_points, 1, 16),
            check::count_in_range("n_h count", (long long)n_h_values.size(), 1, 16),
            check::count_in_range("threads", threads, 0, 1024)))
        return s;
    if ((long long)n_h_values.size() > phi_count)
        return Error{"phi_count must be at least the number of n_h values"};
    for (size_t k = 0; k < n_h_values.size(); ++k) {
        if (Status s = check::count_in_range("n_h", n_h_values[k], 1, 1024)) return s;
        if (k > 0 && n_h_values[k] <= n_h_values[k - 1])
            return Error{"n_h values must be strictly increasing"};
    }
    if (huang_absorption && !huang_f) return Error{"huang_absorption needs huang_f: the absorption part corrects the f part"};
    if (source != "exact" && source != "gaussian")
        return Error{"source must be \"exact\" or \"gaussian\" (got \"" + source + "\")"};
    if (source == "gaussian") {
        if (Status s = seed.validate()) return s;
        for (int n_h : n_h_values)
            if (std::find(seed.n_h_values.begin(), seed.n_h_values.end(), n_h) == seed.n_h_values.end())
                return Error{"source \"gaussian\" has the seed's sigma for n_h in {1, 2, 4, 8, 16} only (got " +
                             std::to_string(n_h) + ")"};
    }
    return std::nullopt;
}

std::vector<float> theta_r_nodes(int count) {
    std::vector<float> nodes(size_t(std::max(count, 0)));
    for (int k = 0; k < count; ++k) nodes[size_t(k)] = float(-kHalfPi + kPi * (k + 0.5) / count);
    return nodes;
}

Status bake_multiple_slice(const DualScattering &dual, double theta_r, const BakeOptions &options, float *out) {
    ThetaGridSpec theta_spec;
    theta_spec.theta_count = options.theta_i_count;
    theta_spec.quadrature_points = std::max(options.quadrature_points, 2);
    const size_t n_i = size_t(options.theta_i_count);
    for (size_t k = 0; k < options.n_h_values.size(); ++k) {
        Expected<Grid1D> m = multiple_distribution(dual, theta_r, options.n_h_values[k], theta_spec);
        if (!m) return Error{"multiple distribution: " + m.error().message};
        for (size_t i = 0; i < n_i; ++i) out[k * n_i + i] = float(m.value().values[i]);
    }
    return std::nullopt;
}

namespace {

Expected<TableSet> bake_in_arena(const FiberModel &model,
                                 const std::vector<std::pair<std::string, double>> &parameters,
                                 const BakeOptions &options, const ProgressFn &progress) {
    TableSet t;
    t.model = model.name();
    t.source = options.source;
    t.parameters = parameters;
    t.theta_r_nodes = theta_r_nodes(options.theta_r_count);
    t.theta_i_count = options.theta_i_count;
    t.phi_count = options.phi_count;
    t.n_h_values = options.n_h_values;
    const int n_r = options.theta_r_count, n_i = options.theta_i_count, n_p = options.phi_count;
    const int n_k = int(options.n_h_values.size());
    t.direct.assign(size_t(n_r) * n_i * n_p, 0.0f);
    t.multiple.assign(size_t(n_r) * n_k * n_i, 0.0f);

    // Progress 0 comes before the dual-scattering set-up (seconds), so that a cancel there
    // is prompt too.
    if (progress && !progress(0.0f)) return Error{"cancelled"};
    std::unique_ptr<DualScattering> dual;
    if (options.source == "exact") {
        Expected<DualScattering> ds = DualScattering::create(model, DualScatteringParams{});
        if (!ds) return Error{"dual scattering: " + ds.error().message};
        dual = std::make_unique<DualScattering>(std::move(ds).value());
    }

    // One θ_r slice at a time keeps progress and cancel responsive; the work inside a slice
    // is parallel and each cell is computed alone, so the result is thread-count independent.
    for (int r = 0; r < n_r; ++r) {
        if (r > 0 && progress && !progress(float(r) / float(n_r))) return Error{"cancelled"};
        const double theta_r = t.theta_r_nodes[size_t(r)];
        float *direct = &t.direct[size_t(r) * n_i * n_p];
        float *multiple = &t.multiple[size_t(r) * n_k * n_i];
        if (options.source == "exact") {
            DirectGridSpec spec;
            spec.theta_count = n_i;
            spec.phi_count = n_p;
            spec.quadrature_points = options.quadrature_points;
            Expected<Grid2D> grid = direct_distribution_relative(model, theta_r, spec);
            if (!grid) return Error{"direct distribution: " + grid.error().message};
            for (size_t c = 0; c < grid.value().values.size(); ++c) direct[c] = float(grid.value().values[c]);
            if (Status s = bake_multiple_slice(*dual, theta_r, options, multiple)) return *s;
        } else {
            const SeedPdfParams &seed = options.seed;
            const int q = options.quadrature_points;
            tbb::parallel_for(0, n_i, [&](int i) {
                const double th0 = -kHalfPi + kPi * i / n_i, th1 = -kHalfPi + kPi * (i + 1) / n_i;
                const double s0 = std::sin(th0), s1 = std::sin(th1);
                for (int j = 0; j < n_p; ++j) {
                    const double p0 = -kPi + kTwoPi * j / n_p, p1 = -kPi + kTwoPi * (j + 1) / n_p;
                    direct[size_t(i) * n_p + j] = float(cell_average(
                        [&](double th, double ph) { return seed_direct_pdf(seed, theta_r, th, ph); }, s0, s1, p0, p1, q));
                }
                for (int k = 0; k < n_k; ++k) {
                    const int n_h = options.n_h_values[size_t(k)];
                    multiple[size_t(k) * n_i + i] = float(cell_average(
                        [&](double th, double) { return seed_multiple_pdf(seed, theta_r, th, n_h); }, s0, s1, 0.0, 1.0, q));
                }
            });
        }
    }
    // Chiang's near field, whatever the far part's source: what TABLE samples single
    // scattering from for a fiber (near_field_table.h).
    if (const ChiangFiber *chiang = model.as_chiang()) {
        Expected<NearFieldTable> near_field = NearFieldTable::create(std::make_shared<const ChiangFiber>(*chiang));
        if (!near_field) return Error{"near-field table: " + near_field.error().message};
        t.near_field = near_field.value().shared_data();
    }
    if (progress && !progress(1.0f)) return Error{"cancelled"};
    if (Status s = t.validate()) return Error{"baked tables are invalid (a bug): " + s->message};
    return t;
}

}  // namespace

Expected<TableSet> bake_tables(const FiberModel &model,
                               const std::vector<std::pair<std::string, double>> &parameters,
                               const BakeOptions &options, const ProgressFn &progress) {
    if (Status s = options.validate()) return *s;
    if (const HuangFiber *huang = model.as_huang()) {
        if (canonical_parameters(parameters) != canonical_parameters(huang_parameters(huang->params())))
            return Error{"the parameters \"" + canonical_parameters(parameters) + "\" are not the huang2022 fiber's"};
        return bake_huang_tables(*huang, options, progress);
    }
    // The file's image must hold the far part and, for Chiang, the near part: refused before
    // the bake rather than by the writer after it.
    const long long far_rows = (long long)options.theta_r_count * options.theta_i_count;
    TableImageSize image{options.phi_count, far_rows};
    if (model.as_chiang()) {
        const NearFieldTableOptions near;
        image.width = std::max<long long>(image.width, near.theta_i_cells + 1);
        image.height += 4ll * near.theta_o_nodes;
    }
    if (Status s = image.validate()) return *s;
    // All the parallel work, the dual-scattering precomputation included, runs in an arena of
    // options.threads slots (a local limit: a process-wide tbb::global_control would also
    // throttle, or be overridden by, whatever else the host runs at the same time).
    tbb::task_arena arena(options.threads > 0 ? options.threads : int(tbb::task_arena::automatic));
    Expected<TableSet> result = Error{"not run"};
    arena.execute([&] { result = bake_in_arena(model, parameters, options, progress); });
    return result;
}

}  // namespace hairis
