#include "hairis/near_field_table.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "hairis/frame.h"

namespace hairis {

namespace {

// 8-point Gauss–Legendre on [−1, 1] (symmetric half).
constexpr double kNodes[4] = {0.18343464249564980, 0.52553240991632899, 0.79666647741362674,
                              0.96028985649753623};
constexpr double kWeights[4] = {0.36268378337836198, 0.31370664587788729, 0.22238103445337447,
                                0.10122853629037626};
constexpr int kMaxPanelsPerCell = 64;

// ∫_a^b M_p(θ | θ_o)·cos θ dθ, on panels narrow enough for the lobe's width.
double cell_mass(const ChiangFiber &fiber, int p, double sin_theta_o, double a, double b) {
    const double width = std::sqrt(fiber.lobe_variance(p));
    const int panels = std::clamp(int(std::ceil((b - a) / (0.5 * width))), 1, kMaxPanelsPerCell);
    const double step = (b - a) / panels;
    double sum = 0;
    for (int j = 0; j < panels; ++j) {
        const double mid = a + (j + 0.5) * step, half = 0.5 * step;
        for (int n = 0; n < 4; ++n) {
            for (double sign : {-1.0, 1.0}) {
                const double theta = mid + sign * half * kNodes[n];
                sum += kWeights[n] * half * fiber.longitudinal(p, std::sin(theta), sin_theta_o) *
                       std::cos(theta);
            }
        }
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
    table.s_ = table.fiber_->logistic_scale();

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
        for (int k = 0; k < cells; ++k) {
            const double a = -kHalfPi + kPi * k / cells, b = -kHalfPi + kPi * (k + 1) / cells;
            mass[size_t(row) * size_t(cells) + size_t(k)] = cell_mass(f, p, sin_o, a, b);
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
        if (!(sum > 0.0) || !std::isfinite(sum))
            return Error{"NearFieldTable: lobe " + std::to_string(row % 4) + " at θ_o node " +
                         std::to_string(row / 4) + " has no finite positive mass"};
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

// Lobe-selection weights at one node: luminance(A_p)·I_p, normalized.
struct NodeWeights {
    float w[4];
};

NodeWeights node_weights(const ChiangFiber::LobeGeometry &g, const double *integral) {
    NodeWeights n{};
    double a[4], total = 0;
    for (int p = 0; p < 4; ++p) total += (a[p] = double(luminance(g.attenuation[size_t(p)])) * integral[p]);
    for (int p = 0; p < 4; ++p) n.w[p] = float(total > 0 ? a[p] / total : (p == 0 ? 1.0 : 0.0));
    return n;
}

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

float NearFieldTable::density(Vec3 wi, Vec3 wo, const ChiangFiber::LobeGeometry &g) const {
    if (!LongitudinalCells::contains_sin(wi.x)) return 0.0f;
    const float theta_o = safe_asin(wo.x);
    const NodeBlend b = nodes_.locate(theta_o);
    const int k = cells_.cell_of_sin(wi.x);
    const double phi = wrap_angle(std::atan2(double(wi.z), double(wi.y)) -
                                  std::atan2(double(wo.z), double(wo.y)));
    double azimuthal[4];
    for (int p = 0; p < 3; ++p)
        azimuthal[p] = chiang::trimmed_logistic(wrap_angle(phi - g.shift[size_t(p)]), s_);
    azimuthal[3] = kInvTwoPi;
    const double per_sin = 1.0 / double(cells_.sin_width(k));
    const float t_in_cell = std::clamp((wi.x - cells_.sin_edge(k)) / cells_.sin_width(k), 0.0f, 1.0f);

    double pdf = 0;
    const float node_weight[2] = {1.0f - b.t, b.t};
    for (int side = 0; side < 2; ++side) {
        if (!(node_weight[side] > 0.0f)) continue;
        const int r = b.lower + side;
        const NodeWeights w = node_weights(g, &integral_[size_t(r) * 4]);
        double d = 0;
        for (int p = 0; p < 4; ++p)
            if (w.w[p] > 0.0f) {
                const float *e = edge(r * 4 + p) + k;
                d += double(w.w[p]) * double(cdfs_.pmf(r * 4 + p, k)) *
                     double(cell_shape(e[0], e[1], t_in_cell)) * azimuthal[p];
            }
        pdf += double(node_weight[side]) * d * per_sin;
    }
    return float(pdf);
}

float NearFieldTable::pdf(Vec3 wi, Vec3 wo, float h) const {
    return density(wi, wo, fiber_->lobe_geometry(wo, h));
}

std::optional<NearFieldSample> NearFieldTable::sample(Vec3 wo, float h, float u0, float u1,
                                                      float u2) const {
    const ChiangFiber::LobeGeometry g = fiber_->lobe_geometry(wo, h);
    const NodeBlend b = nodes_.locate(safe_asin(wo.x));
    // u2 chooses the node (lower with probability 1 − t), then the lobe.
    float u = clamp_unit(u2);
    int r = b.lower;
    if (b.t > 0.0f) {
        const float lower = 1.0f - b.t;
        if (u < lower) {
            u = u / lower;
        } else {
            u = (u - lower) / b.t;
            ++r;
        }
        u = clamp_unit(u);
    }
    const NodeWeights w = node_weights(g, &integral_[size_t(r) * 4]);
    int p = 0;
    while (p < 3 && (u >= w.w[p] || !(w.w[p] > 0.0f))) {
        u -= w.w[p];
        ++p;
    }
    while (p > 0 && !(w.w[p] > 0.0f)) --p;  // rounding left u past the last positive lobe

    const CellChoice c = cdfs_.sample(r * 4 + p, u1);
    const float *e = edge(r * 4 + p) + c.index;
    const LongitudinalCells::Point point =
        cells_.point_in_cell(c.index, std::min(sample_cell_shape(e[0], e[1], c.fraction), kOneMinusEpsilon));
    double phi = -kPi + kTwoPi * double(clamp_unit(u0));  // residual: uniform
    if (p < 3) phi = g.shift[size_t(p)] + chiang::sample_trimmed_logistic(clamp_unit(u0), s_);
    const double phi_i = std::atan2(double(wo.z), double(wo.y)) + phi;

    NearFieldSample s;
    s.wi = Vec3{point.sin_theta, float(point.cos_theta * std::cos(phi_i)),
                float(point.cos_theta * std::sin(phi_i))};
    s.lobe = p;
    s.pdf = density(s.wi, wo, g);
    if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf)) return std::nullopt;
    return s;
}

std::optional<DirectionSample> NearFieldTableSampler::sample(Vec3 wo, float h, float u0, float u1,
                                                             float u2) const {
    std::optional<NearFieldSample> s = table_->sample(wo, h, u0, u1, u2);
    if (!s) return std::nullopt;
    return DirectionSample{s->wi, s->pdf};
}

}  // namespace hairis
