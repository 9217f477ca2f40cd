#include "sampling/near_field_table.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/frame.h"
#include "core/quadrature.h"

namespace hairis {

namespace {

constexpr int kMaxPanelsPerCell = 64;
// Beyond this many lobe widths from its peak, M_p is below e^(−40²/2) of the peak: one panel
// per cell is plenty there, so narrow lobes cost fine panels only near the peak.
constexpr double kFinePanelReach = 40.0;

// Where lobe p's integrand M_p(θ | θ_o)·cos θ peaks in [−π/2, π/2], to within a few widths:
// d'Eon's M peaks at θ + δ_p = −θ_o. Both signs of θ_o and δ are tried (the best is kept),
// so the estimate does not hang on a sign convention; a peak outside the domain clamps to
// its edge.
double lobe_peak(const ChiangFiber &fiber, int p, double theta_o) {
    static constexpr double kTiltFactor[4] = {2.0, 1.0, 4.0, 0.0};  // |δ_p| / α
    const double delta = kTiltFactor[p] * double(fiber.params().offset);
    const double sin_o = std::sin(theta_o);
    double best = -kHalfPi, best_value = -1.0;
    for (double o : {theta_o, -theta_o})
        for (double d : {delta, -delta}) {
            const double theta = std::clamp(o + d, -kHalfPi, kHalfPi);
            const double value = fiber.lobe_longitudinal(p, std::sin(theta), sin_o) * std::cos(theta);
            if (value > best_value) best_value = value, best = theta;
        }
    return best;
}

// Only a : b matters. Edges whose sum could overflow (a table file may hold any finite
// value) or whose products underflow are scaled so that the larger is 1, as the sampler
// (sample_cell_shape) scales them.
void scale_edges(float &a, float &b) {
    const float larger = a > b ? a : b;
    if (larger > 0.0f && (larger < 1e-18f || larger > 1e18f)) {
        a /= larger;
        b /= larger;
    }
}

// Inside a cell the density is linear in t ∈ [0, 1] between the edge values a and b:
// g(t) = 2((1 − t)a + tb)/(a + b), uniform when both are zero. The cell's mass comes from
// the exact integral, so a lobe narrower than a cell keeps its mass even when M_p at both
// edges underflows.
float cell_shape(float a, float b, float t) {
    scale_edges(a, b);
    const float sum = a + b;
    return sum > 0.0f ? 2.0f * ((1.0f - t) * a + t * b) / sum : 1.0f;
}

// Quadrature panels for [a, b] of a lobe `width` wide peaking at `peak`: narrow enough for
// the lobe within kFinePanelReach widths of its peak, one 8-point panel elsewhere.
int panel_count(double width, double peak, double a, double b) {
    const double distance = peak < a ? a - peak : (peak > b ? peak - b : 0.0);
    return distance > kFinePanelReach * width
               ? 1
               : std::clamp(int(std::ceil((b - a) / (0.5 * width))), 1, kMaxPanelsPerCell);
}

// ∫_a^b M_p(θ | θ_o)·cos θ dθ on panel_count() panels.
double cell_mass(const ChiangFiber &fiber, int p, double sin_theta_o, double peak, double a, double b) {
    const int panels = panel_count(std::sqrt(fiber.lobe_variance(p)), peak, a, b);
    const double step = (b - a) / panels;
    double sum = 0;
    for (int j = 0; j < panels; ++j) {
        sum += GaussLegendre::rule(8).integrate(a + j * step, a + (j + 1) * step, [&](double theta) {
            return fiber.lobe_longitudinal(p, std::sin(theta), sin_theta_o) * std::cos(theta);
        });
    }
    return sum;
}

}  // namespace

Expected<NearFieldTable> NearFieldTable::create(std::shared_ptr<const ChiangFiber> fiber,
                                                const NearFieldTableOptions &options) {
    if (!fiber) return Error{"NearFieldTable: the fiber must not be null"};
    if (Status s = first_error(
            check::count_in_range("theta_o_nodes", options.theta_o_nodes, 2, kMaxThetaRNodes),
            check::count_in_range("theta_i_cells", options.theta_i_cells, 4, kMaxTableAxisCells)))
        return *s;
    for (LobeSampling m : options.lobe_sampling)
        if (m != LobeSampling::Auto && m != LobeSampling::Table && m != LobeSampling::Cone)
            return Error{"NearFieldTable: lobe_sampling must be Auto, Table or Cone"};
    NearFieldTable table;
    table.fiber_ = std::move(fiber);

    const int nodes = options.theta_o_nodes, cells = options.theta_i_cells;
    if (Status s = table.set_grid(nodes, cells)) return *s;
    const std::vector<float> &theta_o = table.nodes_.values();

    // Cell masses, one row per (node, lobe); rows are independent, so the result does not
    // depend on how TBB splits them.
    const int rows = nodes * 4;
    std::vector<double> mass(size_t(rows) * size_t(cells));
    const ChiangFiber &f = *table.fiber_;
    tbb::parallel_for(0, rows, [&](int row) {
        const int r = row / 4, p = row % 4;
        const double sin_o = std::sin(double(theta_o[size_t(r)]));
        const double peak = lobe_peak(f, p, double(theta_o[size_t(r)]));
        for (int k = 0; k < cells; ++k) {
            const double a = -kHalfPi + kPi * k / cells, b = -kHalfPi + kPi * (k + 1) / cells;
            mass[size_t(row) * size_t(cells) + size_t(k)] = cell_mass(f, p, sin_o, peak, a, b);
        }
    });
    // What the table file stores, rounded to float once here so that a loaded table is this one.
    auto data = std::make_shared<NearFieldData>();
    data->theta_o_nodes = nodes;
    data->theta_i_cells = cells;
    data->mass.assign(mass.begin(), mass.end());
    // M_p at the cell edges: the shape of the density inside each cell (linear in sin θ).
    data->edge.assign(size_t(rows) * size_t(cells + 1), 0.0f);
    tbb::parallel_for(0, rows, [&](int row) {
        const int r = row / 4, p = row % 4;
        const double sin_o = std::sin(double(theta_o[size_t(r)]));
        for (int k = 0; k <= cells; ++k) {
            const double value = f.lobe_longitudinal(p, std::sin(-kHalfPi + kPi * k / cells), sin_o);
            data->edge[size_t(row) * size_t(cells + 1) + size_t(k)] = float(value);
        }
    });
    data->integral.assign(size_t(rows), 0.0f);
    for (int row = 0; row < rows; ++row) {
        double sum = 0;
        for (int k = 0; k < cells; ++k) sum += mass[size_t(row) * size_t(cells) + size_t(k)];
        // Zero is a real answer: at roughness ~0.001 a lobe whose peak lies past the domain's
        // edge (TT at θ_o = −90°) has an in-domain mass below the smallest double. Its
        // selection weight is then zero (its row falls back to uniform, unused).
        if (!(sum >= 0.0) || !std::isfinite(sum))
            return Error{"NearFieldTable: lobe " + std::to_string(row % 4) + " at θ_o node " +
                         std::to_string(row / 4) + " has a non-finite mass (internal error)"};
        data->integral[size_t(row)] = float(sum);
    }
    data->cone.assign(size_t(rows), 0);
    // The CDFs of the stored (float) masses, as from_data builds them; the probes below read them.
    table.data_ = data;
    if (Status s = table.set_cdfs()) return *s;

    // Per node and lobe, the table row or the cone, whichever is closer to M_p over the
    // θ_o around the node: the sum of both adjacent intervals' divergences, each averaged
    // over its interval by Simpson's rule on t ∈ {0, ¼, ½} (symmetric about ½ to first
    // order): the table is exact at a node and least accurate halfway. Every interval is
    // probed, as the better choice can flip within a few nodes (probing every 4th chose the
    // cone for TT at θ_o = 70°, roughness 0.2, where the rows are far better).
    // Without probing: a lobe wider than kWideCells cells is followed by the table to ~10⁻⁶
    // while the cone still misplaces it by its tilt. (The residual is not tilted: the cone
    // samples exactly Cycles' M_p there, and is taken wherever the row is not good enough.)
    constexpr double kWideCells = 8.0;
    // A lobe's relative variance under 10⁻³ is lost next to the variance that the offset h
    // alone contributes: there the row is kept even if the cone would be
    // closer, as the cone costs time (M_p evaluated at every pdf) for nothing a render sees.
    constexpr double kGoodEnough = 1e-3;
    std::array<bool, 4> probe{};
    for (int p = 0; p < 4; ++p) probe[size_t(p)] = !(std::sqrt(f.lobe_variance(p)) > kWideCells * kPi / cells);
    const int intervals = nodes - 1;
    std::vector<Divergences> d(size_t(intervals) * 4);
    tbb::parallel_for(0, intervals * 4, [&](int i) {
        const int r = i / 4, p = i % 4;
        if (!probe[size_t(p)] || options.lobe_sampling[size_t(p)] != LobeSampling::Auto) return;
        Divergences sum;
        for (const auto &[t, weight] : {std::pair{0.0f, 1.0}, std::pair{0.25f, 4.0}, std::pair{0.5f, 1.0}}) {
            const Divergences at = table.divergences(r, p, t);
            sum.table += weight / 6.0 * at.table;
            sum.cone += weight / 6.0 * at.cone;
        }
        d[size_t(i)] = sum;
    });
    for (int r = 0; r < nodes; ++r) {
        for (int p = 0; p < 4; ++p) {
            Divergences sum;
            for (int i : {r - 1, r})
                if (i >= 0 && i < intervals) {
                    sum.table += d[size_t(i) * 4 + size_t(p)].table;
                    sum.cone += d[size_t(i) * 4 + size_t(p)].cone;
                }
            const LobeSampling m = options.lobe_sampling[size_t(p)];
            const int adjacent = (r > 0) + (r < intervals);
            const bool closer = probe[size_t(p)] && sum.table > kGoodEnough * adjacent && sum.cone < sum.table;
            data->cone[size_t(r) * 4 + size_t(p)] = m == LobeSampling::Cone || (m == LobeSampling::Auto && closer);
        }
    }
    return table;
}

Status NearFieldData::validate() const {
    const std::string what = "near-field table: ";
    if (Status s = first_error(check::count_in_range("theta_o nodes", theta_o_nodes, 2, kMaxThetaRNodes),
                               check::count_in_range("theta_i cells", theta_i_cells, 4, kMaxTableAxisCells)))
        return Error{what + s->message, ErrorKind::InvalidTable};
    const size_t r = size_t(rows()), k = size_t(theta_i_cells);
    if (mass.size() != r * k || edge.size() != r * (k + 1) || integral.size() != r || cone.size() != r)
        return Error{what + "holds " + std::to_string(mass.size()) + " masses, " + std::to_string(edge.size()) +
                         " edges, " + std::to_string(integral.size()) + " integrals and " + std::to_string(cone.size()) +
                         " cone flags; " + std::to_string(theta_o_nodes) + " nodes of " + std::to_string(theta_i_cells) +
                         " cells need " + std::to_string(r * k) + ", " + std::to_string(r * (k + 1)) + ", " +
                         std::to_string(r) + " and " + std::to_string(r),
                     ErrorKind::InvalidTable};
    for (const std::vector<float> *values : {&mass, &edge, &integral})
        for (size_t i = 0; i < values->size(); ++i)
            if (!((*values)[i] >= 0.0f) || !std::isfinite((*values)[i]))
                return Error{what + (values == &mass ? "mass " : values == &edge ? "edge value " : "integral ") +
                                 std::to_string(i) + " must be finite and >= 0",
                             ErrorKind::InvalidTable};
    for (size_t i = 0; i < cone.size(); ++i)
        if (cone[i] > 1) return Error{what + "cone flag " + std::to_string(i) + " must be 0 or 1", ErrorKind::InvalidTable};
    return std::nullopt;
}

Expected<NearFieldTable> NearFieldTable::from_data(std::shared_ptr<const ChiangFiber> fiber,
                                                   std::shared_ptr<const NearFieldData> data) {
    if (!fiber) return Error{"NearFieldTable: the fiber must not be null"};
    if (!data) return Error{"NearFieldTable: no data"};
    if (Status s = data->validate()) return *s;
    NearFieldTable table;
    table.fiber_ = std::move(fiber);
    if (Status s = table.set_grid(data->theta_o_nodes, data->theta_i_cells)) return *s;
    table.data_ = std::move(data);
    if (Status s = table.set_cdfs()) return Error{"near-field table: " + s->message, ErrorKind::InvalidTable};
    return table;
}

Status NearFieldTable::set_grid(int nodes, int cells) {
    std::vector<float> theta_o(static_cast<size_t>(nodes));
    for (int r = 0; r < nodes; ++r) theta_o[size_t(r)] = float(-kHalfPi + kPi * r / (nodes - 1));
    theta_o.front() = -float(kHalfPi);
    theta_o.back() = float(kHalfPi);
    Expected<ThetaRNodes> made_nodes = ThetaRNodes::create(theta_o);
    if (!made_nodes) return made_nodes.error();
    nodes_ = std::move(made_nodes).value();
    Expected<LongitudinalCells> made_cells = LongitudinalCells::create(cells);
    if (!made_cells) return made_cells.error();
    cells_ = std::move(made_cells).value();
    return std::nullopt;
}

Status NearFieldTable::set_cdfs() {
    const int cells = data_->theta_i_cells;
    Expected<DiscreteCdfs> cdfs = DiscreteCdfs::create(data_->rows(), cells, [&](int row, double *w) {
        std::copy_n(data_->mass.begin() + std::ptrdiff_t(row) * cells, cells, w);
    });
    if (!cdfs) return cdfs.error();
    cdfs_ = std::move(cdfs).value();
    return std::nullopt;
}

NearFieldTable::Divergences NearFieldTable::divergences(int r, int p, float t_node) const {
    // χ² divergences ∫ t²/q d(sin θ_i) − 1 of the blend of rows r and r + 1 (q_table) and of
    // the cone (q_cone) from the lobe's normalized M_p (t = M_p / I_p) at θ_o a fraction
    // t_node of the way from node r to r + 1: the lobe's relative variance under each.
    const int cells = cells_.count();
    const ChiangFiber &f = *fiber_;
    const double lower = double(nodes_.values()[size_t(r)]), upper = double(nodes_.values()[size_t(r) + 1]);
    const double theta_o = lower + double(t_node) * (upper - lower);
    const double sin_o = std::sin(theta_o), peak = lobe_peak(f, p, theta_o);
    const double width = std::sqrt(f.lobe_variance(p));
    const chiang::Cone cone = f.lobe_cone(p, sin_o);
    // Points where M_p is below 1e-12 of its peak carry no mass that matters; there a
    // candidate's density may underflow to 0 first, which would read as an infinite divergence.
    const double negligible = 1e-12 * f.lobe_longitudinal(p, std::sin(peak), sin_o);
    double integral = 0, sum_table = 0, sum_cone = 0;
    for (int k = 0; k < cells; ++k) {
        const double a = -kHalfPi + kPi * k / cells, b = -kHalfPi + kPi * (k + 1) / cells;
        const int panels = panel_count(width, peak, a, b);
        const double step = (b - a) / panels;
        const float *e0 = edge(r * 4 + p) + k, *e1 = edge((r + 1) * 4 + p) + k;
        const double pmf0 = double(1.0f - t_node) * cdfs_.pmf(r * 4 + p, k);
        const double pmf1 = double(t_node) * cdfs_.pmf((r + 1) * 4 + p, k);
        for (int j = 0; j < panels; ++j)
            GaussLegendre::rule(8).for_each(a + j * step, a + (j + 1) * step, [&](double theta, double weight) {
                const double s = std::sin(theta), w = weight * std::cos(theta);
                const double m = f.lobe_longitudinal(p, s, sin_o);
                if (!(m > negligible)) return;
                const float t = std::clamp(float((s - cells_.sin_edge(k)) / cells_.sin_width(k)), 0.0f, 1.0f);
                const double q_table = (pmf0 * cell_shape(e0[0], e0[1], t) + pmf1 * cell_shape(e1[0], e1[1], t)) /
                                       double(cells_.sin_width(k));
                const double q_cone = cone.density(s, cos_from_sin(s));
                integral += w * m;
                sum_table += q_table > 0.0 ? w * m * m / q_table : std::numeric_limits<double>::infinity();
                sum_cone += q_cone > 0.0 ? w * m * m / q_cone : std::numeric_limits<double>::infinity();
            });
    }
    if (!(integral > 0.0)) return {};
    return {sum_table / (integral * integral) - 1.0, sum_cone / (integral * integral) - 1.0};
}

size_t NearFieldTable::memory_bytes() const {
    const size_t rows = size_t(cdfs_.count()), cells = size_t(cdfs_.size());
    // CDF floats plus a guide of at least as many 16-bit entries, and the integrals.
    return rows * (2 * (cells + 1) * sizeof(float) + cells * 2) +
           data_->mass.size() * sizeof(float) + data_->edge.size() * sizeof(float) + rows * (sizeof(float) + 1);
}

namespace {

float clamp_unit(float u) { return u > 0.0f ? (u < kOneMinusEpsilon ? u : kOneMinusEpsilon) : 0.0f; }

// Inverse of g's CDF: t = u(a + b)/(a + sqrt((1 − u)a² + ub²)), stable also for a = b.
float sample_cell_shape(float a, float b, float u) {
    // Edges of a lobe narrower than its cell can be ~10⁻²⁹, whose square is 0 in float (which
    // made the sampler uniform where the density was linear): scale_edges.
    scale_edges(a, b);
    const float sum = a + b;
    if (!(sum > 0.0f)) return u;
    const float root = std::sqrt((1.0f - u) * a * a + u * b * b);
    const float denominator = a + root;
    return denominator > 0.0f ? u * sum / denominator : u;
}

}  // namespace

NearFieldTable::Prepared NearFieldTable::prepare(const ChiangPoint &fiber, bool own_cones) const {
    Prepared q;
    q.fiber = &fiber;
    if (own_cones && &fiber.lobes() != &fiber_->lobes())
        for (int p = 0; p < 4; ++p)
            if (!fiber.lobes().same_longitudinal(p, fiber_->lobes())) q.own_cones |= 1u << unsigned(p);
    q.blend = nodes_.locate(safe_asin(float(fiber.sin_theta_o())));
    // Lobe weights luminance(A_p)·I_p at both nodes, normalized per node.
    double a[4];
    for (int p = 0; p < 4; ++p) a[p] = double(luminance(fiber.attenuation(p)));
    for (int side = 0; side < 2; ++side) {
        const int r = std::min(q.blend.lower + side, nodes_.count() - 1);
        const float *integral = &data_->integral[size_t(r) * 4];
        double w[4], total = 0;
        for (int p = 0; p < 4; ++p) total += (w[p] = a[p] * integral[p]);
        for (int p = 0; p < 4; ++p) q.weight[side][p] = float(total > 0 ? w[p] / total : (p == 0 ? 1.0 : 0.0));
    }
    return q;
}

float NearFieldTable::density(const Prepared &q, Vec3 wi) const {
    if (!LongitudinalCells::contains_sin(wi.x)) return 0.0f;
    const ChiangPoint &fiber = *q.fiber;
    const int k = cells_.cell_of_sin(wi.x);
    const double phi = fiber.relative_azimuth(wi);
    double azimuthal[4];
    for (int p = 0; p < 3; ++p) azimuthal[p] = fiber.lobes().azimuthal().density(wrap_angle(phi - fiber.shift(p)));
    azimuthal[3] = kInvTwoPi;
    const float t_in_cell = std::clamp((wi.x - cells_.sin_edge(k)) / cells_.sin_width(k), 0.0f, 1.0f);

    // Per unit sin θ_i: a table row's cell mass over the cell's width, or a cone lobe's M_p.
    double longitudinal[4] = {-1, -1, -1, -1};  // cone lobes: computed once, at first use
    double pdf = 0;
    const float node_weight[2] = {1.0f - q.blend.t, q.blend.t};
    for (int side = 0; side < 2; ++side) {
        if (!(node_weight[side] > 0.0f)) continue;
        const int r = q.blend.lower + side;
        double d = 0;
        for (int p = 0; p < 4; ++p) {
            if (!(q.weight[side][p] > 0.0f)) continue;
            double m = 0;
            if (((q.own_cones >> unsigned(p)) & 1u) || data_->cone[size_t(r) * 4 + size_t(p)]) {
                if (longitudinal[p] < 0) longitudinal[p] = fiber.cone(p).density(double(wi.x), cos_from_sin(double(wi.x)));
                m = longitudinal[p];
            } else {
                const float *e = edge(r * 4 + p) + k;
                m = double(cdfs_.pmf(r * 4 + p, k)) * double(cell_shape(e[0], e[1], t_in_cell)) /
                    double(cells_.sin_width(k));
            }
            d += double(q.weight[side][p]) * m * azimuthal[p];
        }
        pdf += double(node_weight[side]) * d;
    }
    return float(pdf);
}

std::optional<DirectionSample> NearFieldTable::sample(const Prepared &q, float u0, float u1, float u2) const {
    const ChiangPoint &fiber = *q.fiber;
    // u2 chooses the node (lower with probability 1 − t), then the lobe.
    float u = clamp_unit(u2);
    int side = 0;
    if (q.blend.t > 0.0f) {
        const float lower = 1.0f - q.blend.t;
        if (u < lower) {
            u = u / lower;
        } else {
            u = (u - lower) / q.blend.t;
            side = 1;
        }
        u = clamp_unit(u);
    }
    const int r = q.blend.lower + side;
    const float *w = q.weight[side];
    int p = 0;
    while (p < 3 && (u >= w[p] || !(w[p] > 0.0f))) {
        u -= w[p];
        ++p;
    }
    while (p > 0 && !(w[p] > 0.0f)) --p;  // rounding left u past the last positive lobe

    float sin_theta = 0, cos_theta = 1;
    if (((q.own_cones >> unsigned(p)) & 1u) || data_->cone[size_t(r) * 4 + size_t(p)]) {
        // What is left of u inside the lobe's interval picks the cone's cosine; u1 the angle.
        const double u_cone = w[p] > 0.0f ? std::clamp(double(u) / double(w[p]), 0.0, 1.0) : 0.0;
        sin_theta = off_axis(float(fiber.cone(p).sample(u_cone, double(clamp_unit(u1)))));
        cos_theta = std::sqrt((1.0f - sin_theta) * (1.0f + sin_theta));
    } else {
        const CellChoice c = cdfs_.sample(r * 4 + p, u1);
        const float *e = edge(r * 4 + p) + c.index;
        const LongitudinalCells::Point point = cells_.point_in_cell(
            c.index, std::min(sample_cell_shape(e[0], e[1], c.fraction), kOneMinusEpsilon));
        sin_theta = point.sin_theta;
        cos_theta = point.cos_theta;
    }
    double phi = -kPi + kTwoPi * double(clamp_unit(u0));  // residual: uniform
    if (p < 3) phi = fiber.shift(p) + fiber.lobes().azimuthal().sample(clamp_unit(u0));

    DirectionSample s;
    s.wi = fiber.direction(sin_theta, cos_theta, phi);
    s.lobe = p;
    s.pdf = density(q, s.wi);
    if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) return std::nullopt;
    return s;
}

std::optional<DirectionSample> NearFieldTable::sample(Vec3 wo, float h, float u0, float u1, float u2) const {
    const ChiangPoint fiber = fiber_->at({wo, h});
    return sample(prepare(fiber), u0, u1, u2);
}

float NearFieldTable::pdf(Vec3 wi, Vec3 wo, float h) const {
    const ChiangPoint fiber = fiber_->at({wo, h});
    return density(prepare(fiber), wi);
}

namespace {

class NearFieldPoint final : public SamplerPoint {
  public:
    NearFieldPoint(const NearFieldTable &table, const ChiangPoint &fiber) : table_(&table), q_(table.prepare(fiber)) {}
    std::optional<DirectionSample> sample(float u0, float u1, float u2) const override {
        return table_->sample(q_, u0, u1, u2);
    }
    float pdf(Vec3 wi) const override { return table_->density(q_, wi); }

  private:
    const NearFieldTable *table_;
    NearFieldTable::Prepared q_;
};

}  // namespace

const SamplerPoint &NearFieldTableSampler::at(const FiberHit &, const FiberPoint *fiber, ScratchBuffer &scratch) const {
    // model() is the table's fiber or the strands, so `fiber` is one of their ChiangPoints.
    return scratch.make<NearFieldPoint>(*table_, static_cast<const ChiangPoint &>(*fiber));
}

}  // namespace hairis
