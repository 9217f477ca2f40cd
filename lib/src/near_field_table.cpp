#include "hairis/near_field_table.h"

#include <boost/math/quadrature/gauss.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "hairis/frame.h"

namespace hairis {

namespace {

using GaussLegendre8 = boost::math::quadrature::gauss<double, 8>;
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
            const double value = fiber.longitudinal(p, std::sin(theta), sin_o) * std::cos(theta);
            if (value > best_value) best_value = value, best = theta;
        }
    return best;
}

// ∫_a^b M_p(θ | θ_o)·cos θ dθ, on panels narrow enough for the lobe's width where the lobe
// is (within kFinePanelReach widths of its peak), one 8-point panel elsewhere.
double cell_mass(const ChiangFiber &fiber, int p, double sin_theta_o, double peak, double a, double b) {
    const double width = std::sqrt(fiber.lobe_variance(p));
    const double distance = peak < a ? a - peak : (peak > b ? peak - b : 0.0);
    const int panels = distance > kFinePanelReach * width
                           ? 1
                           : std::clamp(int(std::ceil((b - a) / (0.5 * width))), 1, kMaxPanelsPerCell);
    const double step = (b - a) / panels;
    double sum = 0;
    for (int j = 0; j < panels; ++j) {
        sum += GaussLegendre8::integrate(
            [&](double theta) {
                return fiber.longitudinal(p, std::sin(theta), sin_theta_o) * std::cos(theta);
            },
            a + j * step, a + (j + 1) * step);
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
    NearFieldTable table;
    table.fiber_ = std::move(fiber);

    const int nodes = options.theta_o_nodes, cells = options.theta_i_cells;
    std::vector<float> theta_o(static_cast<size_t>(nodes));
    for (int r = 0; r < nodes; ++r)
        theta_o[size_t(r)] = float(-kHalfPi + kPi * r / (nodes - 1));
    theta_o.front() = -float(kHalfPi);
    theta_o.back() = float(kHalfPi);
    Expected<ThetaRNodes> made_nodes = ThetaRNodes::create(theta_o);
    if (!made_nodes) return made_nodes.error();
    table.nodes_ = std::move(made_nodes).value();
    Expected<LongitudinalCells> made_cells = LongitudinalCells::create(cells);
    if (!made_cells) return made_cells.error();
    table.cells_ = std::move(made_cells).value();

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
    // M_p at the cell edges: the shape of the density inside each cell (linear in sin θ).
    table.edge_.assign(size_t(rows) * size_t(cells + 1), 0.0f);
    tbb::parallel_for(0, rows, [&](int row) {
        const int r = row / 4, p = row % 4;
        const double sin_o = std::sin(double(theta_o[size_t(r)]));
        for (int k = 0; k <= cells; ++k) {
            const double value = f.longitudinal(p, std::sin(-kHalfPi + kPi * k / cells), sin_o);
            table.edge_[size_t(row) * size_t(cells + 1) + size_t(k)] = float(value);
        }
    });
    table.integral_.assign(size_t(rows), 0.0);
    for (int row = 0; row < rows; ++row) {
        double sum = 0;
        for (int k = 0; k < cells; ++k) sum += mass[size_t(row) * size_t(cells) + size_t(k)];
        // Zero is a real answer: at roughness ~0.001 a lobe whose peak lies past the domain's
        // edge (TT at θ_o = −90°) has an in-domain mass below the smallest double. Its
        // selection weight is then zero (its row falls back to uniform, unused).
        if (!(sum >= 0.0) || !std::isfinite(sum))
            return Error{"NearFieldTable: lobe " + std::to_string(row % 4) + " at θ_o node " +
                         std::to_string(row / 4) + " has a non-finite mass (internal error)"};
        table.integral_[size_t(row)] = sum;
    }
    Expected<DiscreteCdfs> cdfs = DiscreteCdfs::create(rows, cells, [&](int row, double *w) {
        std::copy_n(mass.begin() + std::ptrdiff_t(row) * cells, cells, w);
    });
    if (!cdfs) return cdfs.error();
    table.cdfs_ = std::move(cdfs).value();
    return table;
}

size_t NearFieldTable::memory_bytes() const {
    const size_t rows = size_t(cdfs_.count()), cells = size_t(cdfs_.size());
    // CDF floats plus a guide of at least as many 16-bit entries, and the integrals.
    return rows * (2 * (cells + 1) * sizeof(float) + cells * 2) + integral_.size() * sizeof(double);
}

namespace {

float clamp_unit(float u) { return u > 0.0f ? (u < kOneMinusEpsilon ? u : kOneMinusEpsilon) : 0.0f; }

// Inside a cell the density is linear in t ∈ [0, 1] between the edge values a and b:
// g(t) = 2((1 − t)a + tb)/(a + b), uniform when both are zero. The cell's mass comes from
// the exact integral, so a lobe narrower than a cell keeps its mass even when M_p at both
// edges underflows.
float cell_shape(float a, float b, float t) {
    const float sum = a + b;
    return sum > 0.0f ? 2.0f * ((1.0f - t) * a + t * b) / sum : 1.0f;
}

// Inverse of g's CDF: t = u(a + b)/(a + sqrt((1 − u)a² + ub²)), stable also for a = b.
float sample_cell_shape(float a, float b, float u) {
    const float sum = a + b;
    if (!(sum > 0.0f)) return u;
    const float root = std::sqrt((1.0f - u) * a * a + u * b * b);
    const float denominator = a + root;
    return denominator > 0.0f ? u * sum / denominator : u;
}

}  // namespace

NearFieldTable::Prepared NearFieldTable::prepare(Vec3 wo, float h) const {
    Prepared q;
    const ChiangFiber::LobeGeometry g = fiber_->lobe_geometry(wo, h);
    for (int p = 0; p < 3; ++p) q.shift[p] = g.shift[size_t(p)];
    q.theta_o = safe_asin(wo.x);
    q.blend = nodes_.locate(q.theta_o);
    // Lobe weights luminance(A_p)·I_p at both nodes, normalized per node.
    for (int side = 0; side < 2; ++side) {
        const int r = std::min(q.blend.lower + side, nodes_.count() - 1);
        const double *integral = &integral_[size_t(r) * 4];
        double a[4], total = 0;
        for (int p = 0; p < 4; ++p)
            total += (a[p] = double(luminance(g.attenuation[size_t(p)])) * integral[p]);
        for (int p = 0; p < 4; ++p)
            q.weight[side][p] = float(total > 0 ? a[p] / total : (p == 0 ? 1.0 : 0.0));
    }
    // The view's azimuth as a rotation, so that φ = φ_i − φ_o needs one atan2.
    const double r = std::sqrt(double(wo.y) * wo.y + double(wo.z) * wo.z);
    q.cos_phi_o = r > 0 ? wo.y / r : 0.0;
    q.sin_phi_o = r > 0 ? wo.z / r : -1.0;
    return q;
}

float NearFieldTable::density(const Prepared &q, Vec3 wi) const {
    if (!LongitudinalCells::contains_sin(wi.x)) return 0.0f;
    const int k = cells_.cell_of_sin(wi.x);
    const double phi = std::atan2(wi.z * q.cos_phi_o - wi.y * q.sin_phi_o,
                                  wi.y * q.cos_phi_o + wi.z * q.sin_phi_o);
    double azimuthal[4];
    for (int p = 0; p < 3; ++p) azimuthal[p] = fiber_->azimuthal().density(wrap_angle(phi - q.shift[p]));
    azimuthal[3] = kInvTwoPi;
    const float t_in_cell = std::clamp((wi.x - cells_.sin_edge(k)) / cells_.sin_width(k), 0.0f, 1.0f);

    double pdf = 0;
    const float node_weight[2] = {1.0f - q.blend.t, q.blend.t};
    for (int side = 0; side < 2; ++side) {
        if (!(node_weight[side] > 0.0f)) continue;
        const int r = q.blend.lower + side;
        double d = 0;
        for (int p = 0; p < 4; ++p) {
            if (!(q.weight[side][p] > 0.0f)) continue;
            const float *e = edge(r * 4 + p) + k;
            d += double(q.weight[side][p]) * double(cdfs_.pmf(r * 4 + p, k)) *
                 double(cell_shape(e[0], e[1], t_in_cell)) * azimuthal[p];
        }
        pdf += double(node_weight[side]) * d;
    }
    return float(pdf / double(cells_.sin_width(k)));
}

float NearFieldTable::pdf(Vec3 wi, Vec3 wo, float h) const { return density(prepare(wo, h), wi); }

std::optional<NearFieldSample> NearFieldTable::sample(const Prepared &q, float u0, float u1,
                                                      float u2) const {
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

    const CellChoice c = cdfs_.sample(r * 4 + p, u1);
    const float *e = edge(r * 4 + p) + c.index;
    const LongitudinalCells::Point point = cells_.point_in_cell(
        c.index, std::min(sample_cell_shape(e[0], e[1], c.fraction), kOneMinusEpsilon));
    double phi = -kPi + kTwoPi * double(clamp_unit(u0));  // residual: uniform
    if (p < 3) phi = q.shift[p] + fiber_->azimuthal().sample(clamp_unit(u0));
    // φ_i = φ_o + φ, by rotation.
    const double c_phi = std::cos(phi), s_phi = std::sin(phi);
    const double cos_phi_i = q.cos_phi_o * c_phi - q.sin_phi_o * s_phi;
    const double sin_phi_i = q.sin_phi_o * c_phi + q.cos_phi_o * s_phi;

    NearFieldSample s;
    s.wi = Vec3{point.sin_theta, float(point.cos_theta * cos_phi_i), float(point.cos_theta * sin_phi_i)};
    s.lobe = p;
    s.pdf = density(q, s.wi);
    if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) return std::nullopt;
    return s;
}

std::optional<NearFieldSample> NearFieldTable::sample(Vec3 wo, float h, float u0, float u1,
                                                      float u2) const {
    return sample(prepare(wo, h), u0, u1, u2);
}

std::optional<DirectionSample> NearFieldTableSampler::sample(Vec3 wo, float h, float u0, float u1,
                                                             float u2) const {
    std::optional<NearFieldSample> s = table_->sample(wo, h, u0, u1, u2);
    if (!s) return std::nullopt;
    return DirectionSample{s->wi, s->pdf};
}

}  // namespace hairis
