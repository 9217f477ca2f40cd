#include "fiber/distributions.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/frame.h"
#include "core/quadrature.h"

namespace hairis {

namespace {

Status check_theta_r(double theta_r) {
    return check::in_range("theta_r (radians)", theta_r, -kHalfPi, kHalfPi);
}

Status check_direct_spec(const FiberModel &model, const DirectGridSpec &s) {
    if (Status e = first_error(
            check::count_in_range("DirectGridSpec::theta_count", s.theta_count, 1, kMaxCellsPerAxis),
            check::count_in_range("DirectGridSpec::phi_count", s.phi_count, 1, kMaxCellsPerAxis),
            check::count_in_range("DirectGridSpec::theta_count * phi_count",
                                  (long long)s.theta_count * (long long)s.phi_count, 1, kMaxCells),
            check::count_in_range("DirectGridSpec::quadrature_points", s.quadrature_points, 1, 16),
            check::count_in_range("DirectGridSpec::orientation_count", s.orientation_count, 1, 1024),
            check::count_in_range("DirectGridSpec::lobe (-1 for all lobes)", s.lobe, -1,
                                  model.lobe_count() - 1)))
        return e;
    return std::nullopt;
}

Status check_theta_spec(const ThetaGridSpec &s) {
    return first_error(
        check::count_in_range("ThetaGridSpec::theta_count", s.theta_count, 1, kMaxCellsPerAxis),
        check::count_in_range("ThetaGridSpec::quadrature_points", s.quadrature_points, 1, 16));
}

double ring_solid_angle(double lo, double hi) { return kTwoPi * (std::sin(hi) - std::sin(lo)); }

// The Gauss–Legendre nodes of every cell of an axis: x[k·q + a] and w[k·q + a] (w including
// the cell's half width).
struct AxisNodes {
    std::vector<double> x, w;
    AxisNodes(double lo, double width, int cells, int q) {
        const GaussLegendre &gl = GaussLegendre::rule(q);
        for (int k = 0; k < cells; ++k)
            gl.for_each(lo + k * width, lo + (k + 1) * width, [&](double at, double weight) {
                x.push_back(at);
                w.push_back(weight);
            });
    }
};

// A far-field view and how a grid column c maps to it: relative azimuth c − relative_shift,
// absolute azimuth of ω_i c + absolute_shift.
struct ColumnView {
    std::unique_ptr<const FarFieldView> view;
    double relative_shift = 0, absolute_shift = 0;
};

// A (θ_i, φ) grid of cell averages per steradian of the mean over `views` of luminance(f·cos)
// (spec.lobe < 0: every lobe). Separable views are summed as outer products of their per-lobe
// θ_i and φ factors; the others are evaluated at every node.
Grid2D make_grid(const DirectGridSpec &spec, const std::vector<ColumnView> &views, int lobe_count) {
    Grid2D g;
    g.theta_count = spec.theta_count;
    g.phi_count = spec.phi_count;
    g.values.assign(std::size_t(spec.theta_count) * std::size_t(spec.phi_count), 0.0);
    const int q = spec.quadrature_points;
    const AxisNodes th(-kHalfPi, kPi / spec.theta_count, spec.theta_count, q);
    const AxisNodes ph(-kPi, kTwoPi / spec.phi_count, spec.phi_count, q);
    const int first = spec.lobe < 0 ? 0 : spec.lobe, last = spec.lobe < 0 ? lobe_count - 1 : spec.lobe;
    const double inv_views = 1.0 / double(views.size());
    const std::size_t nq = std::size_t(q);
    for (const ColumnView &cv : views) {
        const FarFieldView &view = *cv.view;
        if (view.separable()) {
            // Σ_p m_p(θ_i cell) · n_p(φ cell): each lobe's factors integrated over the cells.
            std::vector<double> m(std::size_t(spec.theta_count)), n(std::size_t(spec.phi_count));
            for (int p = first; p <= last; ++p) {
                tbb::parallel_for(0, spec.theta_count, [&](int i) {
                    double sum = 0;
                    for (std::size_t a = 0; a < nq; ++a) {
                        const std::size_t at = std::size_t(i) * nq + a;
                        sum += th.w[at] * std::cos(th.x[at]) * view.longitudinal(p, th.x[at]);
                    }
                    m[std::size_t(i)] = sum;
                });
                tbb::parallel_for(0, spec.phi_count, [&](int j) {
                    double sum = 0;
                    for (std::size_t b = 0; b < nq; ++b) {
                        const std::size_t at = std::size_t(j) * nq + b;
                        sum += ph.w[at] * double(luminance(view.azimuthal(p, ph.x[at] - cv.relative_shift)));
                    }
                    n[std::size_t(j)] = sum;
                });
                for (int i = 0; i < spec.theta_count; ++i) {
                    const double scale = m[std::size_t(i)] * inv_views / g.cell_solid_angle(i);
                    double *row = &g.values[std::size_t(i) * std::size_t(spec.phi_count)];
                    for (int j = 0; j < spec.phi_count; ++j) row[j] += scale * n[std::size_t(j)];
                }
            }
            continue;
        }
        tbb::parallel_for(0, spec.theta_count, [&](int i) {
            const double inv_omega = inv_views / g.cell_solid_angle(i);
            for (int j = 0; j < spec.phi_count; ++j) {
                double sum = 0;
                for (std::size_t a = 0; a < nq; ++a) {
                    const std::size_t ta = std::size_t(i) * nq + a;
                    double row = 0;
                    for (std::size_t b = 0; b < nq; ++b) {
                        const std::size_t pb = std::size_t(j) * nq + b;
                        const Vec3 wi = direction_of(float(th.x[ta]), float(ph.x[pb] + cv.absolute_shift));
                        Rgb v;
                        for (int p = first; p <= last; ++p) v += view.lobe_f_cos(p, wi);
                        row += ph.w[pb] * double(luminance(v));
                    }
                    sum += th.w[ta] * std::cos(th.x[ta]) * row;
                }
                g.values[std::size_t(i) * std::size_t(spec.phi_count) + std::size_t(j)] += sum * inv_omega;
            }
        });
    }
    return g;
}

}  // namespace

// ------------------------------------------------------------------------------------------
// Grid geometry

double Grid2D::theta_lo(int i) const { return -kHalfPi + i * kPi / theta_count; }
double Grid2D::theta_center(int i) const { return -kHalfPi + (i + 0.5) * kPi / theta_count; }
double Grid2D::phi_lo(int j) const { return -kPi + j * kTwoPi / phi_count; }
double Grid2D::phi_center(int j) const { return -kPi + (j + 0.5) * kTwoPi / phi_count; }
double Grid2D::cell_solid_angle(int i) const {
    return ring_solid_angle(theta_lo(i), theta_lo(i + 1)) / phi_count;
}
double Grid2D::integral() const {
    double total = 0;
    for (int i = 0; i < theta_count; ++i) {
        double row = 0;
        for (int j = 0; j < phi_count; ++j) row += value(i, j);
        total += row * cell_solid_angle(i);
    }
    return total;
}

double Grid1D::theta_lo(int i) const { return -kHalfPi + i * kPi / theta_count; }
double Grid1D::theta_center(int i) const { return -kHalfPi + (i + 0.5) * kPi / theta_count; }
double Grid1D::cell_solid_angle(int i) const { return ring_solid_angle(theta_lo(i), theta_lo(i + 1)); }
double Grid1D::integral() const {
    double total = 0;
    for (int i = 0; i < theta_count; ++i) total += values[std::size_t(i)] * cell_solid_angle(i);
    return total;
}

// ------------------------------------------------------------------------------------------
// Distributions

Expected<Grid2D> direct_distribution(const FiberModel &model, double theta_r, double phi_r,
                                     const DirectGridSpec &spec) {
    if (Status e = first_error(check_direct_spec(model, spec), check_theta_r(theta_r),
                               check::finite("phi_r (radians)", phi_r)))
        return *e;
    std::vector<ColumnView> views;
    views.push_back({model.view(direction_of(float(theta_r), float(phi_r))), phi_r, 0.0});
    return make_grid(spec, views, model.lobe_count());
}

Expected<Grid2D> direct_distribution_relative(const FiberModel &model, double theta_r,
                                              const DirectGridSpec &spec) {
    if (Status e = first_error(check_direct_spec(model, spec), check_theta_r(theta_r))) return *e;
    std::vector<double> phi_rs;
    if (model.rotationally_symmetric()) {
        phi_rs.push_back(-kHalfPi);
    } else {
        for (int k = 0; k < spec.orientation_count; ++k)
            phi_rs.push_back(-kPi + (k + 0.5) * kTwoPi / spec.orientation_count);
    }
    std::vector<ColumnView> views;
    for (const double p : phi_rs) views.push_back({model.view(direction_of(float(theta_r), float(p))), 0.0, p});
    return make_grid(spec, views, model.lobe_count());
}

Grid1D azimuthal_average(const Grid2D &grid) {
    Grid1D out;
    out.theta_count = grid.theta_count;
    out.values.assign(std::size_t(grid.theta_count), 0.0);
    for (int i = 0; i < grid.theta_count; ++i) {
        double row = 0;
        for (int j = 0; j < grid.phi_count; ++j) row += grid.value(i, j);
        out.values[std::size_t(i)] = row / grid.phi_count;
    }
    return out;
}

Expected<Grid1D> multiple_distribution(const DualScattering &ds, double theta_r, int n_h,
                                       const ThetaGridSpec &spec) {
    if (Status e = first_error(check_theta_spec(spec), check_theta_r(theta_r),
                               check::count_in_range("n_h", n_h, 0, 1 << 20)))
        return *e;
    Grid1D g;
    g.theta_count = spec.theta_count;
    g.values.assign(std::size_t(spec.theta_count), 0.0);
    const GaussLegendre &gl = GaussLegendre::rule(spec.quadrature_points);
    const double dth = kPi / spec.theta_count;
    tbb::parallel_for(tbb::blocked_range<int>(0, spec.theta_count), [&](const tbb::blocked_range<int> &cells) {
        for (int i = cells.begin(); i != cells.end(); ++i) {
            const double lo = g.theta_lo(i);
            double sum = 0;
            for (std::size_t a = 0; a < gl.nodes.size(); ++a) {
                const double th = lo + 0.5 * dth * (1.0 + gl.nodes[a]);
                const double s = double(luminance(ds.multiple_f_cos(float(th), float(theta_r), n_h)));
                sum += 0.5 * dth * gl.weights[a] * std::cos(th) * s;
            }
            g.values[std::size_t(i)] = kTwoPi * sum / g.cell_solid_angle(i);
        }
    });
    return g;
}

// ------------------------------------------------------------------------------------------
// Statistics

Expected<ThetaStats> theta_stats(const Grid1D &grid, ThetaDensity density) {
    if (Status e = check::count_in_range("Grid1D::theta_count", grid.theta_count, 1, kMaxCellsPerAxis)) return *e;
    if (grid.values.size() != std::size_t(grid.theta_count))
        return Error{"Grid1D::values must hold theta_count = " + std::to_string(grid.theta_count) +
                     " values (got " + std::to_string(grid.values.size()) + ")"};
    const int n = grid.theta_count;
    const double dth = kPi / n;
    std::vector<double> d(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        const double v = grid.values[std::size_t(i)];
        if (Status e = check::finite("Grid1D::values[i]", v)) return *e;
        d[std::size_t(i)] = density == ThetaDensity::kMarginal ? v * grid.cell_solid_angle(i) / dth : v;
    }
    const auto max_it = std::max_element(d.begin(), d.end());
    const int im = int(max_it - d.begin());
    const double dmax = *max_it;
    if (!(dmax > 0)) return Error{"theta_stats needs a distribution with a positive maximum (got all values <= 0)"};

    ThetaStats s;
    s.maximum = dmax;
    // Peak: parabola through the largest cell and its neighbours.
    double offset = 0;
    if (im > 0 && im < n - 1) {
        const double l = d[std::size_t(im - 1)], c = d[std::size_t(im)], r = d[std::size_t(im + 1)];
        const double den = l - 2 * c + r;
        if (den < 0) offset = std::clamp(0.5 * (l - r) / den, -0.5, 0.5);
    }
    s.peak = grid.theta_center(im) + offset * dth;
    // Scale and spread around the peak (the density is constant inside a cell).
    double mass = 0, m2 = 0;
    for (int i = 0; i < n; ++i) {
        const double x = grid.theta_center(i) - s.peak;
        mass += d[std::size_t(i)] * dth;
        m2 += d[std::size_t(i)] * (x * x * dth + dth * dth * dth / 12.0);
    }
    s.scale = mass;
    s.stddev = mass > 0 ? std::sqrt(std::max(0.0, m2 / mass)) : 0.0;
    // Full width at half maximum, linear interpolation between cell centres.
    const double half = 0.5 * dmax;
    double right = -1, left = -1;
    for (int i = im + 1; i < n; ++i) {
        if (d[std::size_t(i)] < half) {
            const double a = d[std::size_t(i - 1)], b = d[std::size_t(i)];
            right = grid.theta_center(i - 1) + dth * (a - half) / (a - b) - grid.theta_center(im);
            break;
        }
    }
    for (int i = im - 1; i >= 0; --i) {
        if (d[std::size_t(i)] < half) {
            const double a = d[std::size_t(i + 1)], b = d[std::size_t(i)];
            left = grid.theta_center(im) - (grid.theta_center(i + 1) - dth * (a - half) / (a - b));
            break;
        }
    }
    double fwhm;
    if (left >= 0 && right >= 0) fwhm = left + right;
    else if (left >= 0) fwhm = 2 * left;
    else if (right >= 0) fwhm = 2 * right;
    else fwhm = kPi;
    s.fwhm_sigma = fwhm / (2.0 * std::sqrt(2.0 * std::log(2.0)));
    return s;
}

}  // namespace hairis
