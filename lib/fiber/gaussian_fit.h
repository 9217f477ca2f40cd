// Least-squares fits of a scaled normalized Gaussian s·N(θ; μ, σ) to a sampled curve, as the
// seed fits its Table 1 and Table 2 by hand.
#pragma once

#include <optional>
#include <vector>

#include "core/expected.h"

namespace hairis {

/// The result of a fit: y(θ) ≈ scale · exp(−(θ − mean)²/(2σ²)) / (σ√(2π)).
struct GaussianFit {
    double scale = 0;
    double sigma = 0;
    double mean = 0;
    double rms_error = 0;       ///< sqrt(mean squared residual)
    double relative_error = 0;  ///< rms_error / rms of the data
};

/// s·N(θ; μ, σ) at θ.
double scaled_gaussian(const GaussianFit &fit, double theta);

/// Fits scale, σ and μ (or only scale and σ when `fixed_mean` is given) to the points
/// (x[k], y[k]) by least squares. The scale is solved in closed form for each (μ, σ) (it
/// enters linearly); μ and σ come from a coarse grid search refined by Brent's method
/// (Boost.Math), so the fit does not depend on a starting guess. σ is searched in
/// [sigma_min, sigma_max].
Expected<GaussianFit> fit_scaled_gaussian(const std::vector<double> &x, const std::vector<double> &y,
                                          std::optional<double> fixed_mean = std::nullopt,
                                          double sigma_min = 0.01, double sigma_max = 3.0);

}  // namespace hairis
