// A χ² goodness-of-fit test for direction samplers, in the style of Mitsuba 3's chi2.py.
//
// The sphere is cut into equal-solid-angle cells: uniform in sin θ = ω.x ∈ [−1, 1] and in
// φ ∈ [−π, π] (directions in the fiber frame of frame.h). Expected counts come from
// integrating pdf() over each cell with composite Simpson quadrature; cells whose expected
// count is under 5 are pooled; the p-value of the χ² statistic is compared against the
// significance level after a Šidák correction for the number of tests run.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/math.h"

namespace hairis::testing {

/// Uniform random numbers in [0, 1) handed to a sampler.
struct Sample3 {
    float u0, u1, u2;
};

struct Chi2Options {
    long long sample_count = 1000000;  ///< samples drawn
    int sin_theta_cells = 40;          ///< cells along sin θ
    int phi_cells = 80;                ///< cells along φ
    int simpson_points = 9;            ///< Simpson nodes per cell and axis (odd)
    double significance = 0.01;        ///< before the Šidák correction
    int test_count = 1;                ///< number of χ² tests in the family (Šidák)
    std::uint64_t seed = 0x5eed;       ///< random-number seed, fixed for reproducibility
    /// Angles (θ in [−π/2, π/2], φ in [−π, π]) where the pdf may jump, e.g. a table's cell
    /// edges: each cell's quadrature is split there, so piecewise-constant densities are
    /// integrated exactly.
    std::vector<double> theta_breaks, phi_breaks;
};

struct Chi2Result {
    bool passed = false;
    double statistic = 0;       ///< χ²
    int degrees_of_freedom = 0;
    double p_value = 0;
    double threshold = 0;       ///< p-values at or below this reject (after Šidák)
    double pdf_integral = 0;    ///< ∫ pdf over the sphere by the same quadrature
    long long failed_samples = 0;  ///< samples the sampler refused (nullopt or zero pdf)
    std::string message;        ///< why it failed, or a summary when it passed
};

/// Draws options.sample_count directions from `sample` and tests them against `pdf`.
/// `sample` returns a unit local direction, or nullopt when it produces no sample (such
/// samples count as missing mass: the test fails if pdf() does not account for it).
Chi2Result chi2_direction_test(const std::function<std::optional<Vec3>(Sample3)> &sample,
                               const std::function<double(Vec3)> &pdf,
                               const Chi2Options &options = {});

/// chi2_direction_test of a sampler at one point: `at.sample(u0, u1, u2)` returns an optional
/// sample with a direction wi, and `at.pdf(wi)` is its density.
template <typename At>
Chi2Result chi2_sampler_test(const At &at, const Chi2Options &options = {}) {
    return chi2_direction_test(
        [&](Sample3 u) -> std::optional<Vec3> {
            const auto s = at.sample(u.u0, u.u1, u.u2);
            return s ? std::optional<Vec3>(s->wi) : std::nullopt;
        },
        [&](Vec3 wi) { return double(at.pdf(wi)); }, options);
}

/// The same test on a 1D density over an interval [lo, hi] with equal-width cells.
Chi2Result chi2_interval_test(const std::function<std::optional<double>(double)> &sample,
                              const std::function<double(double)> &pdf, double lo, double hi,
                              int cells, const Chi2Options &options = {});

}  // namespace hairis::testing
