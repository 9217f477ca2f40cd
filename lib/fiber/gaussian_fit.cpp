#include "fiber/gaussian_fit.h"

#include <boost/math/tools/minima.hpp>
#include <cmath>
#include <limits>

#include "core/math.h"

namespace hairis {

namespace {

double normal(double theta, double mean, double sigma) {
    const double z = (theta - mean) / sigma;
    return std::exp(-0.5 * z * z) / (sigma * std::sqrt(kTwoPi));
}

// Best scale and the residual sum of squares for a given (μ, σ): s = <g, y> / <g, g>.
struct Residual {
    double scale, sum_sq;
};

Residual residual(const std::vector<double> &x, const std::vector<double> &y, double mean,
                  double sigma) {
    double gy = 0, gg = 0, yy = 0;
    for (size_t k = 0; k < x.size(); ++k) {
        const double g = normal(x[k], mean, sigma);
        gy += g * y[k];
        gg += g * g;
        yy += y[k] * y[k];
    }
    const double s = gg > 0 ? std::max(0.0, gy / gg) : 0.0;
    return {s, std::max(0.0, yy - 2.0 * s * gy + s * s * gg)};
}

}  // namespace

double scaled_gaussian(const GaussianFit &fit, double theta) {
    return fit.scale * normal(theta, fit.mean, fit.sigma);
}

Expected<GaussianFit> fit_scaled_gaussian(const std::vector<double> &x, const std::vector<double> &y,
                                          std::optional<double> fixed_mean, double sigma_min,
                                          double sigma_max) {
    if (x.size() != y.size() || x.size() < 3)
        return Error{"a Gaussian fit needs at least 3 points and as many x as y values"};
    for (size_t k = 0; k < x.size(); ++k)
        if (!std::isfinite(x[k]) || !std::isfinite(y[k]))
            return Error{"a Gaussian fit needs finite data (point " + std::to_string(k) + ")"};
    if (Status s = first_error(check::greater_than("sigma_min", sigma_min, 0.0),
                               check::greater_than("sigma_max", sigma_max, sigma_min)))
        return *s;
    const double x_lo = *std::min_element(x.begin(), x.end());
    const double x_hi = *std::max_element(x.begin(), x.end());

    // σ is searched on a log scale; μ over the data's range.
    auto best_mean_for = [&](double sigma, double mean_lo, double mean_hi) {
        if (fixed_mean) return std::pair<double, double>{*fixed_mean, residual(x, y, *fixed_mean, sigma).sum_sq};
        const auto r = boost::math::tools::brent_find_minima(
            [&](double m) { return residual(x, y, m, sigma).sum_sq; }, mean_lo, mean_hi, 40);
        return std::pair<double, double>{r.first, r.second};
    };

    // Coarse grid to bracket the global minimum.
    constexpr int kSigmaSteps = 48, kMeanSteps = 96;
    double best = std::numeric_limits<double>::infinity(), best_log_sigma = 0, best_mean = 0;
    const double log_lo = std::log(sigma_min), log_hi = std::log(sigma_max);
    for (int a = 0; a <= kSigmaSteps; ++a) {
        const double log_sigma = log_lo + (log_hi - log_lo) * a / kSigmaSteps;
        for (int b = 0; b <= (fixed_mean ? 0 : kMeanSteps); ++b) {
            const double mean = fixed_mean ? *fixed_mean : x_lo + (x_hi - x_lo) * b / kMeanSteps;
            const double r = residual(x, y, mean, std::exp(log_sigma)).sum_sq;
            if (r < best) best = r, best_log_sigma = log_sigma, best_mean = mean;
        }
    }
    // Refine: Brent over log σ around the bracket, with the best μ for each σ.
    const double d_log = (log_hi - log_lo) / kSigmaSteps, d_mean = (x_hi - x_lo) / kMeanSteps;
    const double mean_lo = std::max(x_lo, best_mean - 2 * d_mean), mean_hi = std::min(x_hi, best_mean + 2 * d_mean);
    const auto refined = boost::math::tools::brent_find_minima(
        [&](double log_sigma) { return best_mean_for(std::exp(log_sigma), mean_lo, mean_hi).second; },
        std::max(log_lo, best_log_sigma - d_log), std::min(log_hi, best_log_sigma + d_log), 40);

    GaussianFit fit;
    fit.sigma = std::exp(refined.first);
    fit.mean = best_mean_for(fit.sigma, mean_lo, mean_hi).first;
    const Residual r = residual(x, y, fit.mean, fit.sigma);
    fit.scale = r.scale;
    fit.rms_error = std::sqrt(r.sum_sq / double(x.size()));
    double yy = 0;
    for (double v : y) yy += v * v;
    fit.relative_error = yy > 0 ? fit.rms_error / std::sqrt(yy / double(x.size())) : 0.0;
    return fit;
}

}  // namespace hairis
