#include "seed_fits.h"

#include <algorithm>
#include <cmath>

#include "core/frame.h"
#include "seed_tables.h"

namespace hairis::cli {

namespace {

// Relative L2 distance between the data and a fixed shape g scaled optimally (shape only).
double shape_error(const std::vector<double> &x, const std::vector<double> &y, double mean, double sigma) {
    GaussianFit g{1.0, sigma, mean, 0, 0};
    double gy = 0, gg = 0, yy = 0;
    for (size_t k = 0; k < x.size(); ++k) {
        const double v = scaled_gaussian(g, x[k]);
        gy += v * y[k];
        gg += v * v;
        yy += y[k] * y[k];
    }
    const double s = gy / gg;
    return std::sqrt(std::max(0.0, yy - 2 * s * gy + s * s * gg) / yy);
}

}  // namespace

Expected<std::vector<MultipleFitRow>> fit_multiple(const DualScattering &ds, const std::vector<int> &strands,
                                                   int theta_count) {
    std::vector<MultipleFitRow> rows;
    ThetaGridSpec spec;
    spec.theta_count = theta_count;
    for (int n_h : strands) {
        for (double theta_r_deg : kSeedThetaR) {
            const double theta_r = evaluated_theta_r(theta_r_deg);
            Expected<Grid1D> g = multiple_distribution(ds, theta_r, n_h, spec);
            if (!g) return g.error();
            MultipleFitRow row{n_h, theta_r_deg, {}, 0, g.value().integral(), {}, {}};
            for (int i = 0; i < g.value().theta_count; ++i) {
                row.theta.push_back(g.value().theta_center(i));
                row.profile.push_back(g.value().values[size_t(i)]);
            }
            const auto peak = std::max_element(row.profile.begin(), row.profile.end());
            row.peak_deg = degrees(row.theta[size_t(peak - row.profile.begin())]);
            Expected<GaussianFit> fit = fit_scaled_gaussian(row.theta, row.profile);
            if (!fit) return Error{"fit n_h " + std::to_string(n_h) + ": " + fit.error().message};
            row.fit = fit.value();
            rows.push_back(std::move(row));
        }
    }
    return rows;
}

Expected<std::vector<DirectFitRow>> fit_direct(const FiberModel &model, int theta_count, int phi_count,
                                               int quadrature_points) {
    std::vector<DirectFitRow> rows;
    DirectGridSpec spec;
    spec.theta_count = theta_count;
    spec.phi_count = phi_count;
    spec.quadrature_points = quadrature_points;
    for (double theta_r_deg : kSeedThetaR) {
        const double theta_r = evaluated_theta_r(theta_r_deg);
        Expected<Grid2D> g = direct_distribution_relative(model, theta_r, spec);
        if (!g) return g.error();
        const Grid2D &grid = g.value();
        // θ profile per steradian (azimuthal average) and φ profile (solid-angle weighted
        // average over θ), both as the seed's figures show them.
        std::vector<double> theta, theta_profile, psi, psi_profile;
        for (int i = 0; i < grid.theta_count; ++i) {
            double sum = 0;
            for (int j = 0; j < grid.phi_count; ++j) sum += grid.value(i, j);
            theta.push_back(grid.theta_center(i));
            theta_profile.push_back(sum / grid.phi_count);
        }
        for (int j = 0; j < grid.phi_count; ++j) {
            double sum = 0, weight = 0;
            for (int i = 0; i < grid.theta_count; ++i) {
                sum += grid.value(i, j) * grid.cell_solid_angle(i);
                weight += grid.cell_solid_angle(i);
            }
            psi.push_back(wrap_angle(grid.phi_center(j) - kPi));
            psi_profile.push_back(sum / weight);
        }
        // Sort ψ so the profile is a function on [−π, π].
        std::vector<size_t> order(psi.size());
        for (size_t k = 0; k < order.size(); ++k) order[k] = k;
        std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return psi[a] < psi[b]; });
        std::vector<double> psi_sorted, psi_values;
        for (size_t k : order) psi_sorted.push_back(psi[k]), psi_values.push_back(psi_profile[k]);

        Expected<GaussianFit> l = fit_scaled_gaussian(theta, theta_profile, -theta_r);
        Expected<GaussianFit> a = fit_scaled_gaussian(psi_sorted, psi_values, 0.0);
        if (!l || !a) return (!l ? l.error() : a.error());
        rows.push_back({theta_r_deg, l.value(), a.value(), 0.52 + sqr(theta_r_deg / 180.0),
                        shape_error(theta, theta_profile, -theta_r, 0.22),
                        shape_error(theta, theta_profile, -theta_r, 0.44)});
    }
    return rows;
}

}  // namespace hairis::cli
