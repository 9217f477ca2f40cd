#include "chi2.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/quadrature/gauss.hpp>
#include <cmath>
#include <numeric>
#include <random>
#include <sstream>
#include <vector>

namespace hairis::testing {

namespace {

// Uniform float in [0, 1) from the top 24 bits, so 1 is never returned.
float uniform_float(std::mt19937_64 &rng) { return float(rng() >> 40) * 0x1p-24f; }

// Composite Simpson weights for n (odd) equally spaced nodes over an interval of width h.
std::vector<double> simpson_weights(int n, double width) {
    std::vector<double> w(n);
    const double step = width / (n - 1);
    for (int i = 0; i < n; ++i) {
        const double c = (i == 0 || i == n - 1) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
        w[i] = c * step / 3.0;
    }
    return w;
}

// Quadrature nodes and weights over [a, b]. Without breakpoints: composite Simpson. With
// breakpoints: 7-point Gauss–Legendre on each piece between those inside — an open rule, so
// no node sits on a jump (where the pdf may take either side's value) and a density that
// is constant between breakpoints is integrated exactly.
struct Node {
    double x, w;
};
std::vector<Node> split_nodes(double a, double b, const std::vector<double> &breaks, int n) {
    std::vector<double> edges = {a};
    for (double t : breaks)
        if (t > a && t < b) edges.push_back(t);
    edges.push_back(b);
    std::sort(edges.begin(), edges.end());
    std::vector<Node> nodes;
    if (breaks.empty()) {
        const std::vector<double> w = simpson_weights(n, b - a);
        for (int i = 0; i < n; ++i) nodes.push_back({a + (b - a) * double(i) / (n - 1), w[size_t(i)]});
        return nodes;
    }
    using Rule = boost::math::quadrature::gauss<double, 7>;
    for (size_t k = 0; k + 1 < edges.size(); ++k) {
        const double lo = edges[k], hi = edges[k + 1];
        if (!(hi > lo)) continue;
        const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
        // Boost stores the non-negative abscissae; the rule is symmetric.
        for (size_t i = 0; i < Rule::abscissa().size(); ++i) {
            const double x = Rule::abscissa()[i], w = Rule::weights()[i] * half;
            nodes.push_back({mid + half * x, w});
            if (x != 0.0) nodes.push_back({mid - half * x, w});
        }
    }
    return nodes;
}

// Pools cells with expected counts under 5 (smallest first, as Mitsuba's chi2 does) and
// returns the χ² statistic and its degrees of freedom.
Chi2Result chi2_from_counts(const std::vector<double> &observed,
                            const std::vector<double> &expected, const Chi2Options &options) {
    Chi2Result result;
    std::vector<size_t> order(observed.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return expected[a] < expected[b]; });

    double pool_obs = 0, pool_exp = 0;
    double stat = 0, last_obs = -1, last_exp = -1;
    int cells = 0;
    for (size_t i : order) {
        if (expected[i] <= 0.0 && observed[i] > 0.0) {
            std::ostringstream msg;
            msg << "cell " << i << " has expected count 0 but " << observed[i]
                << " observed samples: the sampler reaches where pdf() is zero";
            result.message = msg.str();
            return result;
        }
        pool_obs += observed[i];
        pool_exp += expected[i];
        if (pool_exp >= 5.0) {
            stat += sqr(pool_obs - pool_exp) / pool_exp;
            last_obs = pool_obs;
            last_exp = pool_exp;
            ++cells;
            pool_obs = pool_exp = 0;
        }
    }
    if (pool_exp > 0.0 || pool_obs > 0.0) {
        // Leftover pool under 5: merge it into the last cell emitted.
        if (cells == 0) {
            result.message = "fewer than 5 expected samples in total: increase sample_count";
            return result;
        }
        stat -= sqr(last_obs - last_exp) / last_exp;
        stat += sqr(last_obs + pool_obs - (last_exp + pool_exp)) / (last_exp + pool_exp);
    }
    result.statistic = stat;
    result.degrees_of_freedom = cells - 1;
    if (result.degrees_of_freedom < 1) {
        result.message = "only one cell after pooling: use more cells or samples";
        return result;
    }
    boost::math::chi_squared dist(result.degrees_of_freedom);
    result.p_value = boost::math::cdf(boost::math::complement(dist, stat));
    const double alpha =
        1.0 - std::pow(1.0 - options.significance, 1.0 / std::max(1, options.test_count));
    result.threshold = alpha;
    result.passed = result.p_value > alpha;
    std::ostringstream msg;
    msg << "chi2 = " << stat << ", dof = " << result.degrees_of_freedom
        << ", p = " << result.p_value << " (reject below " << alpha << ")";
    result.message = msg.str();
    return result;
}

}  // namespace

Chi2Result chi2_direction_test(const std::function<std::optional<Vec3>(Sample3)> &sample,
                               const std::function<double(Vec3)> &pdf,
                               const Chi2Options &options) {
    const int nx = options.sin_theta_cells, ny = options.phi_cells;
    const double cell_x = 2.0 / nx, cell_phi = kTwoPi / ny;

    // Observed counts.
    std::vector<double> observed(size_t(nx) * ny, 0.0);
    std::mt19937_64 rng(options.seed);
    long long failed = 0;
    for (long long s = 0; s < options.sample_count; ++s) {
        Sample3 u{uniform_float(rng), uniform_float(rng), uniform_float(rng)};
        std::optional<Vec3> w = sample(u);
        if (!w) {
            ++failed;
            continue;
        }
        const float len = length(*w);
        if (!std::isfinite(len) || std::fabs(len - 1.0f) > 1e-3f) {
            Chi2Result bad;
            std::ostringstream msg;
            msg << "sampler returned a non-unit direction (" << w->x << ", " << w->y << ", "
                << w->z << ")";
            bad.message = msg.str();
            return bad;
        }
        const double x = std::clamp(double(w->x), -1.0, 1.0);
        const double phi = std::atan2(double(w->z), double(w->y));
        const int ix = std::clamp(int((x + 1.0) / cell_x), 0, nx - 1);
        const int iy = std::clamp(int((phi + kPi) / cell_phi), 0, ny - 1);
        observed[size_t(ix) * ny + iy] += 1.0;
    }

    // Expected counts: Simpson quadrature of the pdf over each cell. A cell spans
    // [x0, x1] in sin θ; integrating over θ with dω = cos θ dθ dφ keeps the integrand smooth
    // for densities that are per dθ dφ divided by cos θ (singular at the poles in sin θ).
    const int n = options.simpson_points | 1;
    std::vector<double> expected(observed.size(), 0.0);
    double integral = 0.0;
    for (int ix = 0; ix < nx; ++ix) {
        const double t0 = std::asin(std::clamp(-1.0 + cell_x * ix, -1.0, 1.0));
        const double t1 = std::asin(std::clamp(-1.0 + cell_x * (ix + 1), -1.0, 1.0));
        const std::vector<Node> theta_nodes = split_nodes(t0, t1, options.theta_breaks, n);
        for (int iy = 0; iy < ny; ++iy) {
            const double p0 = -kPi + cell_phi * iy, p1 = p0 + cell_phi;
            const std::vector<Node> phi_nodes = split_nodes(p0, p1, options.phi_breaks, n);
            double cell = 0.0;
            for (const Node &a : theta_nodes) {
                const double x = std::sin(a.x), r = std::cos(a.x);
                if (r <= 0.0) continue;
                for (const Node &b : phi_nodes) {
                    const Vec3 w{float(x), float(r * std::cos(b.x)), float(r * std::sin(b.x))};
                    cell += a.w * b.w * pdf(w) * r;
                }
            }
            expected[size_t(ix) * ny + iy] = cell * double(options.sample_count);
            integral += cell;
        }
    }

    Chi2Result result = chi2_from_counts(observed, expected, options);
    result.pdf_integral = integral;
    result.failed_samples = failed;
    return result;
}

Chi2Result chi2_interval_test(const std::function<std::optional<double>(double)> &sample,
                              const std::function<double(double)> &pdf, double lo, double hi,
                              int cells, const Chi2Options &options) {
    const double width = (hi - lo) / cells;
    std::vector<double> observed(cells, 0.0);
    std::mt19937_64 rng(options.seed);
    long long failed = 0;
    for (long long s = 0; s < options.sample_count; ++s) {
        std::optional<double> x = sample(double(uniform_float(rng)));
        if (!x) {
            ++failed;
            continue;
        }
        if (!std::isfinite(*x) || *x < lo || *x > hi) {
            Chi2Result bad;
            std::ostringstream msg;
            msg << "sampler returned " << *x << " outside [" << lo << ", " << hi << "]";
            bad.message = msg.str();
            return bad;
        }
        observed[std::clamp(int((*x - lo) / width), 0, cells - 1)] += 1.0;
    }
    const int n = options.simpson_points | 1;
    const std::vector<double> w = simpson_weights(n, width);
    std::vector<double> expected(cells, 0.0);
    double integral = 0.0;
    for (int c = 0; c < cells; ++c) {
        double cell = 0.0;
        for (int a = 0; a < n; ++a) cell += w[a] * pdf(lo + width * (c + double(a) / (n - 1)));
        expected[c] = cell * double(options.sample_count);
        integral += cell;
    }
    Chi2Result result = chi2_from_counts(observed, expected, options);
    result.pdf_integral = integral;
    result.failed_samples = failed;
    return result;
}

}  // namespace hairis::testing
