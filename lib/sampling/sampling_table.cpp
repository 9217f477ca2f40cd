#include "sampling/sampling_table.h"

#include <algorithm>
#include <string>

#include "core/frame.h"

namespace hairis {

namespace {

// u clamped to [0, 1), NaN to 0.
float unit(float u) {
    if (!(u > 0.0f)) return 0.0f;
    return u < kOneMinusEpsilon ? u : kOneMinusEpsilon;
}

// The node sample() draws from: the upper one with probability t.
int choose_node(NodeBlend b, float u) { return unit(u) < b.t ? b.lower + 1 : b.lower; }

// (1 − t)·pdf(lower) + t·pdf(lower + 1), evaluating only the nodes that carry weight (the
// skipped term is exactly zero, so this equals the full formula bit for bit).
template <typename NodePdf>
float blend(NodeBlend b, NodePdf &&node_pdf) {
    if (b.t <= 0.0f) return node_pdf(b.lower);
    if (b.t >= 1.0f) return node_pdf(b.lower + 1);
    return (1.0f - b.t) * node_pdf(b.lower) + b.t * node_pdf(b.lower + 1);
}

Error prefixed(const char *owner, const Error &e) {
    return Error{std::string(owner) + ": " + e.message};
}

std::string bytes_text(long long bytes) {
    return std::to_string(bytes) + " bytes (limit " + std::to_string(kMaxSamplingTableBytes) + ")";
}

// Refuses values that do not hold `cells` entries (`shape` says how they are laid out) or
// that hold a negative or non-finite entry, which name_of(n) names.
template <typename NameOf>
Status check_values(const char *owner, const std::vector<float> &values, long long cells,
                    const char *shape, NameOf name_of) {
    if ((long long)values.size() != cells)
        return Error{std::string(owner) + ": values must hold " + shape + " = " +
                     std::to_string(cells) + " entries (got " + std::to_string(values.size()) +
                     ")"};
    for (size_t n = 0; n < values.size(); ++n)
        if (!(std::isfinite(values[n]) && values[n] >= 0.0f))
            return prefixed(owner, *check::non_negative(name_of(n).c_str(), double(values[n])));
    return std::nullopt;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ThetaRNodes

Expected<ThetaRNodes> ThetaRNodes::create(const std::vector<float> &nodes) {
    if (Status s = check::count_in_range("theta_r node count", (long long)nodes.size(), 1,
                                         kMaxThetaRNodes))
        return *s;
    const double half_pi = double(float(kHalfPi));  // π/2 rounded up to float is allowed
    for (size_t k = 0; k < nodes.size(); ++k) {
        const std::string name = "theta_r_nodes[" + std::to_string(k) + "]";
        if (Status s = check::in_range(name.c_str(), nodes[k], -half_pi, half_pi)) return *s;
        if (k > 0 && !(nodes[k] > nodes[k - 1]))
            return Error{"theta_r_nodes must be strictly increasing (theta_r_nodes[" +
                         std::to_string(k) + "] = " + std::to_string(nodes[k]) +
                         " <= theta_r_nodes[" + std::to_string(k - 1) +
                         "] = " + std::to_string(nodes[k - 1]) + ")"};
    }
    ThetaRNodes n;
    n.nodes_ = nodes;
    const int count = int(nodes.size());
    if (count >= 2) {
        n.inv_interval_.resize(size_t(count) - 1);
        for (int k = 0; k + 1 < count; ++k)
            n.inv_interval_[size_t(k)] =
                float(1.0 / (double(nodes[size_t(k) + 1]) - double(nodes[size_t(k)])));
        const double span = double(nodes.back()) - double(nodes.front());
        const double h = span / (count - 1);
        bool uniform = true;
        for (int k = 0; k < count && uniform; ++k)
            uniform =
                std::fabs(double(nodes[size_t(k)]) - (double(nodes.front()) + k * h)) <= 1e-3 * h;
        n.uniform_ = uniform;
        n.inv_spacing_ = float(1.0 / h);
    }
    return n;
}

int ThetaRNodes::search(float theta_r) const {
    return int(std::upper_bound(nodes_.begin(), nodes_.end(), theta_r) - nodes_.begin()) - 1;
}

// ---------------------------------------------------------------------------------------------
// LongitudinalCells

Expected<LongitudinalCells> LongitudinalCells::create(int count) {
    if (Status s = check::count_in_range("theta_i_count", count, 1, kMaxTableAxisCells)) return *s;
    LongitudinalCells c;
    c.count_ = count;
    c.sin_edges_.resize(size_t(count) + 1);
    for (int k = 0; k <= count; ++k)
        c.sin_edges_[size_t(k)] = float(std::sin(-kHalfPi + kPi * k / count));
    c.sin_edges_.front() = -1.0f;
    c.sin_edges_.back() = 1.0f;
    c.last_sin_.resize(size_t(count));
    for (int k = 0; k < count; ++k) {
        if (!(c.sin_width(k) > 0.0f))
            return Error{"theta_i_count = " + std::to_string(count) +
                         " leaves a cell with no width in sin(theta) at float precision"};
        c.last_sin_[size_t(k)] =
            k + 1 == count ? kOneMinusEpsilon : std::nextafter(c.sin_edges_[size_t(k) + 1], -2.0f);
        if (!(c.last_sin_[size_t(k)] >= (k == 0 ? -kOneMinusEpsilon : c.sin_edges_[size_t(k)])))
            return Error{"theta_i_count = " + std::to_string(count) +
                         " leaves a cell with no width in sin(theta) at float precision"};
    }
    // Guide over s ∈ [−1, 1] with 4·count (rounded up to 2^m) buckets: entry g is the cell of
    // the bucket's lower end; cell_of_sin() corrects by stepping, which stays short because
    // the buckets are narrower than all but the few cells nearest the poles.
    int buckets = 1;
    while (buckets < 4 * count) buckets <<= 1;
    c.guide_.resize(size_t(buckets));
    c.guide_scale_ = float(buckets) * 0.5f;
    c.guide_max_ = buckets - 1;
    int k = 0;
    for (int g = 0; g < buckets; ++g) {
        const double lower = -1.0 + 2.0 * g / buckets;
        while (k + 1 < count && double(c.sin_edges_[size_t(k) + 1]) <= lower) ++k;
        c.guide_[size_t(g)] = std::uint16_t(k);
    }
    return c;
}

// ---------------------------------------------------------------------------------------------
// AzimuthTrig

AzimuthTrig::AzimuthTrig() : angle_(kSteps), cos_(kSteps), sin_(kSteps) {
    for (int k = 0; k < kSteps; ++k) {
        const float a = float(-kPi + kTwoPi * k / kSteps);
        angle_[size_t(k)] = a;
        cos_[size_t(k)] = float(std::cos(double(a)));
        sin_[size_t(k)] = float(std::sin(double(a)));
    }
}

// ---------------------------------------------------------------------------------------------
// DirectTable

Expected<DirectTable> DirectTable::create(const std::vector<float> &theta_r_nodes,
                                          int theta_i_count, int phi_count,
                                          const std::vector<float> &values) {
    constexpr const char *kOwner = "DirectTable";
    Expected<ThetaRNodes> nodes = ThetaRNodes::create(theta_r_nodes);
    if (!nodes) return prefixed(kOwner, nodes.error());
    if (Status s = first_error(
            check::count_in_range("theta_i_count", theta_i_count, 1, kMaxTableAxisCells),
            check::count_in_range("phi_count", phi_count, 1, kMaxTableAxisCells)))
        return prefixed(kOwner, *s);

    const long long node_count = nodes.value().count();
    const long long rows = node_count * theta_i_count;
    const long long cells = rows * phi_count;
    const long long bytes =
        cells * (long long)sizeof(float) + DiscreteCdfs::bytes_needed(rows, phi_count) +
        DiscreteCdfs::bytes_needed(node_count, theta_i_count) + rows * (long long)sizeof(float);
    if (bytes > kMaxSamplingTableBytes)
        return Error{std::string(kOwner) + ": " + std::to_string(node_count) + " nodes × " +
                     std::to_string(theta_i_count) + " × " + std::to_string(phi_count) +
                     " cells would need " + bytes_text(bytes)};
    const auto direct_cell = [&](size_t n) {
        const size_t j = n % size_t(phi_count), i = (n / size_t(phi_count)) % size_t(theta_i_count),
                     r = n / (size_t(phi_count) * size_t(theta_i_count));
        return "values[node " + std::to_string(r) + ", theta_i cell " + std::to_string(i) +
               ", phi cell " + std::to_string(j) + "]";
    };
    if (Status s = check_values(kOwner, values, cells, "node count × theta_i_count × phi_count",
                                direct_cell))
        return *s;

    DirectTable t;
    t.nodes_ = std::move(nodes).value();
    Expected<LongitudinalCells> theta = LongitudinalCells::create(theta_i_count);
    if (!theta) return prefixed(kOwner, theta.error());
    t.theta_ = std::move(theta).value();
    Expected<UniformCells> phi = UniformCells::create(-float(kPi), float(kPi), phi_count);
    if (!phi) return prefixed(kOwner, phi.error());
    t.phi_ = std::move(phi).value();

    const size_t slice = size_t(theta_i_count) * size_t(phi_count);
    t.slice_fallback_.assign(size_t(node_count), 0);
    for (size_t r = 0; r < size_t(node_count); ++r) {
        const auto begin = values.begin() + std::ptrdiff_t(r * slice);
        t.slice_fallback_[r] =
            std::all_of(begin, begin + std::ptrdiff_t(slice), [](float v) { return v == 0.0f; });
    }
    // An all-zero slice is replaced by the constant 1 per steradian: the uniform sphere.
    auto value_at = [&](size_t r, size_t i, size_t j) -> double {
        return t.slice_fallback_[r]
                   ? 1.0
                   : double(values[(r * size_t(theta_i_count) + i) * size_t(phi_count) + j]);
    };

    Expected<DiscreteCdfs> conditional =
        DiscreteCdfs::create(int(rows), phi_count, [&](int row, double *w) {
            const size_t r = size_t(row) / size_t(theta_i_count),
                         i = size_t(row) % size_t(theta_i_count);
            for (size_t j = 0; j < size_t(phi_count); ++j) w[j] = value_at(r, i, j);
        });
    if (!conditional) return prefixed(kOwner, conditional.error());
    // A row's probability is its values × the cells' solid angle Δ(sin θ)·Δφ.
    Expected<DiscreteCdfs> marginal =
        DiscreteCdfs::create(int(node_count), theta_i_count, [&](int r, double *w) {
            for (int i = 0; i < theta_i_count; ++i) {
                double sum = 0.0;
                for (size_t j = 0; j < size_t(phi_count); ++j)
                    sum += value_at(size_t(r), size_t(i), j);
                w[i] = sum * double(t.theta_.sin_width(i));
            }
        });
    if (!marginal) return prefixed(kOwner, marginal.error());
    t.conditional_ = std::move(conditional).value();
    t.marginal_ = std::move(marginal).value();

    // pdf per steradian in cell (i, j) = P(row i) / Δ(sin θ_i) × P(j | i) × phi_count / 2π.
    t.row_factor_.resize(size_t(rows));
    for (int r = 0; r < int(node_count); ++r)
        for (int i = 0; i < theta_i_count; ++i)
            t.row_factor_[size_t(r) * size_t(theta_i_count) + size_t(i)] =
                float(double(t.marginal_.pmf(r, i)) / double(t.theta_.sin_width(i)) *
                      double(t.phi_.inv_width()));
    t.values_ = values;
    return t;
}

float DirectTable::cell_pdf(NodeBlend b, int i, int j) const {
    return blend(b, [&](int r) { return node_cell_pdf(r, i, j); });
}

TableSample DirectTable::sample(float theta_o, float u0, float u1, float u2) const {
    return sample(nodes_.locate(theta_o), u0, u1, u2);
}

TableSample DirectTable::sample(NodeBlend b, float u0, float u1, float u2) const {
    const int r = choose_node(b, u2);
    const CellChoice ci = marginal_.sample(r, u0);
    const CellChoice cj = conditional_.sample(r * theta_.count() + ci.index, u1);
    const LongitudinalCells::Point p = theta_.point_in_cell(ci.index, ci.fraction);
    TableSample s;
    s.sin_theta_i = p.sin_theta;
    s.cos_theta_i = p.cos_theta;
    s.phi = phi_.point_in_cell(cj.index, cj.fraction);
    trig_(s.phi, s.cos_phi, s.sin_phi);
    s.pdf = cell_pdf(b, ci.index, cj.index);
    return s;
}

float DirectTable::pdf_sin(float theta_o, float sin_theta_i, float phi) const {
    return pdf_sin(nodes_.locate(theta_o), sin_theta_i, phi);
}

float DirectTable::pdf_sin(NodeBlend b, float sin_theta_i, float phi) const {
    if (!LongitudinalCells::contains_sin(sin_theta_i)) return 0.0f;
    if (!phi_.contains(phi)) {
        if (!std::isfinite(phi)) return 0.0f;
        phi = std::clamp(wrap_angle(phi), phi_.lo(), phi_.hi());
    }
    return cell_pdf(b, theta_.cell_of_sin(sin_theta_i), phi_.cell_of(phi));
}

// ---------------------------------------------------------------------------------------------
// MultipleTable

Expected<MultipleTable> MultipleTable::create(const std::vector<float> &theta_r_nodes,
                                              const std::vector<int> &n_h_values, int theta_i_count,
                                              const std::vector<float> &values) {
    constexpr const char *kOwner = "MultipleTable";
    Expected<ThetaRNodes> nodes = ThetaRNodes::create(theta_r_nodes);
    if (!nodes) return prefixed(kOwner, nodes.error());
    if (Status s = first_error(
            check::count_in_range("n_h value count", (long long)n_h_values.size(), 1,
                                  kMaxStrandCounts),
            check::count_in_range("theta_i_count", theta_i_count, 1, kMaxTableAxisCells)))
        return prefixed(kOwner, *s);
    for (size_t k = 0; k < n_h_values.size(); ++k) {
        if (n_h_values[k] < 1)
            return Error{std::string(kOwner) + ": n_h_values[" + std::to_string(k) +
                         "] must be at least 1 (got " + std::to_string(n_h_values[k]) + ")"};
        if (k > 0 && n_h_values[k] <= n_h_values[k - 1])
            return Error{
                std::string(kOwner) + ": n_h_values must be strictly increasing (n_h_values[" +
                std::to_string(k) + "] = " + std::to_string(n_h_values[k]) + " <= n_h_values[" +
                std::to_string(k - 1) + "] = " + std::to_string(n_h_values[k - 1]) + ")"};
    }

    const long long node_count = nodes.value().count();
    const long long strands = (long long)n_h_values.size();
    const long long rows = node_count * strands;
    const long long cells = rows * theta_i_count;
    const long long bytes =
        cells * 2 * (long long)sizeof(float) + DiscreteCdfs::bytes_needed(rows, theta_i_count);
    if (bytes > kMaxSamplingTableBytes)
        return Error{std::string(kOwner) + ": " + std::to_string(cells) + " cells would need " +
                     bytes_text(bytes)};
    const auto multiple_cell = [&](size_t n) {
        const size_t i = n % size_t(theta_i_count), k = (n / size_t(theta_i_count)) % size_t(strands),
                     r = n / (size_t(theta_i_count) * size_t(strands));
        return "values[node " + std::to_string(r) + ", n_h " + std::to_string(n_h_values[k]) +
               ", theta_i cell " + std::to_string(i) + "]";
    };
    if (Status s = check_values(kOwner, values, cells, "node count × n_h count × theta_i_count",
                                multiple_cell))
        return *s;

    MultipleTable t;
    t.nodes_ = std::move(nodes).value();
    Expected<LongitudinalCells> theta = LongitudinalCells::create(theta_i_count);
    if (!theta) return prefixed(kOwner, theta.error());
    t.theta_ = std::move(theta).value();
    t.n_h_ = n_h_values;

    // A cell's probability is its value × solid angle Δ(sin θ)·2π; an all-zero slice becomes
    // uniform in the cells' weights, which is uniform per steradian only if the weights are
    // solid angles: so fall back explicitly.
    t.slice_fallback_.assign(size_t(rows), 0);
    Expected<DiscreteCdfs> cdfs =
        DiscreteCdfs::create(int(rows), theta_i_count, [&](int row, double *w) {
            const float *v = values.data() + size_t(row) * size_t(theta_i_count);
            const bool empty = std::all_of(v, v + theta_i_count, [](float x) { return x == 0.0f; });
            t.slice_fallback_[size_t(row)] = empty;
            for (int i = 0; i < theta_i_count; ++i)
                w[i] = (empty ? 1.0 : double(v[i])) * double(t.theta_.sin_width(i));
        });
    if (!cdfs) return prefixed(kOwner, cdfs.error());
    t.cdfs_ = std::move(cdfs).value();
    t.density_.resize(size_t(cells));
    for (int row = 0; row < int(rows); ++row)
        for (int i = 0; i < theta_i_count; ++i)
            t.density_[size_t(row) * size_t(theta_i_count) + size_t(i)] =
                float(double(t.cdfs_.pmf(row, i)) / (double(t.theta_.sin_width(i)) * kTwoPi));
    t.values_ = values;
    return t;
}

int MultipleTable::strand_index(int n_h) const {
    const auto it = std::find(n_h_.begin(), n_h_.end(), n_h);
    return it == n_h_.end() ? -1 : int(it - n_h_.begin());
}

float MultipleTable::cell_pdf(int strand, NodeBlend b, int i) const {
    const int strands = int(n_h_.size());
    return blend(b, [&](int r) {
        return density_[(size_t(r) * size_t(strands) + size_t(strand)) * size_t(theta_.count()) +
                        size_t(i)];
    });
}

TableSample MultipleTable::sample(int strand, float theta_o, float u0, float u1, float u2) const {
    return sample(strand, nodes_.locate(theta_o), u0, u1, u2);
}

TableSample MultipleTable::sample(int strand, NodeBlend b, float u0, float u1, float u2) const {
    if (strand < 0 || strand >= int(n_h_.size()))
        return TableSample{0.0f, 1.0f, 0.0f, 1.0f, 0.0f, 0.0f};
    const int r = choose_node(b, u2);
    const CellChoice ci = cdfs_.sample(r * int(n_h_.size()) + strand, u0);
    const LongitudinalCells::Point p = theta_.point_in_cell(ci.index, ci.fraction);
    TableSample s;
    s.sin_theta_i = p.sin_theta;
    s.cos_theta_i = p.cos_theta;
    s.phi = std::min(float(kTwoPi) * unit(u1) - float(kPi), float(kPi));
    trig_(s.phi, s.cos_phi, s.sin_phi);
    s.pdf = cell_pdf(strand, b, ci.index);
    return s;
}

float MultipleTable::pdf_sin(int strand, float theta_o, float sin_theta_i) const {
    return pdf_sin(strand, nodes_.locate(theta_o), sin_theta_i);
}

float MultipleTable::pdf_sin(int strand, NodeBlend b, float sin_theta_i) const {
    if (strand < 0 || strand >= int(n_h_.size()) || !LongitudinalCells::contains_sin(sin_theta_i))
        return 0.0f;
    return cell_pdf(strand, b, theta_.cell_of_sin(sin_theta_i));
}

}  // namespace hairis
