#include "fiber/seed_pdfs.h"

#include <algorithm>
#include <boost/math/special_functions/erf.hpp>
#include <cmath>

#include "core/frame.h"

namespace hairis {

namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440;

double normal_cdf(double z) { return 0.5 * std::erfc(-z * kInvSqrt2); }

// The truncated normal of the longitudinal part of f_ds and f_ms.
TruncatedNormal longitudinal(double theta_r, double sigma) {
    return TruncatedNormal(-theta_r, sigma, -kHalfPi, kHalfPi);
}

double sigma_azimuthal(const SeedPdfParams &p, double theta_r) {
    return p.sigma_azimuthal_base + sqr(theta_r * kInvPi);
}

// The azimuthal Gaussian is centred on the TT lobe: its variable is the offset
// ψ = wrap(φ − π) ∈ [−π, π].
TruncatedNormal azimuthal(const SeedPdfParams &p, double theta_r) {
    return TruncatedNormal(0.0, sigma_azimuthal(p, theta_r), -kPi, kPi);
}

double sigma_multiple_of(const SeedPdfParams &p, int n_h) {
    for (size_t k = 0; k < p.n_h_values.size(); ++k)
        if (p.n_h_values[k] == n_h) return p.sigma_multiple[k];
    return -1.0;
}

// Per steradian from per dθ dφ.
double per_steradian(double density, double cos_theta_i) {
    return cos_theta_i > 0.0 ? density / cos_theta_i : 0.0;
}


}  // namespace

TruncatedNormal::TruncatedNormal(double mean, double sigma, double lo, double hi)
    : mean_(mean), sigma_(sigma), lo_(lo), hi_(hi) {
    cdf_lo_ = normal_cdf((lo - mean) / sigma);
    mass_ = normal_cdf((hi - mean) / sigma) - cdf_lo_;
}

double TruncatedNormal::pdf(double x) const {
    // Angles that went through float may land a rounding error past the bounds.
    constexpr double kSlack = 1e-6;
    if (x < lo_ - kSlack || x > hi_ + kSlack || !(mass_ > 0.0)) return 0.0;
    const double z = (x - mean_) / sigma_;
    return std::exp(-0.5 * z * z) / (sigma_ * std::sqrt(kTwoPi) * mass_);
}

double TruncatedNormal::sample(double u) const {
    const double p = std::clamp(cdf_lo_ + u * mass_, 1e-300, 1.0 - 1e-16);
    const double x = mean_ + sigma_ * std::sqrt(2.0) * boost::math::erf_inv(2.0 * p - 1.0);
    return std::clamp(x, lo_, hi_);
}

Status SeedPdfParams::validate() const {
    if (Status s = first_error(check::greater_than("sigma_longitudinal", sigma_longitudinal, 0.0),
                               check::greater_than("sigma_azimuthal_base", sigma_azimuthal_base, 0.0)))
        return s;
    if (n_h_values.size() != sigma_multiple.size() || n_h_values.empty())
        return Error{"n_h_values and sigma_multiple must be non-empty and of equal length"};
    for (size_t k = 0; k < n_h_values.size(); ++k) {
        if (Status s = first_error(check::count_in_range("n_h", n_h_values[k], 1, 1024),
                                   check::greater_than("sigma_multiple", sigma_multiple[k], 0.0)))
            return s;
    }
    return std::nullopt;
}

double seed_direct_pdf(const SeedPdfParams &p, double theta_r, double theta_i, double phi) {
    const double psi = wrap_angle(phi - kPi);
    return per_steradian(longitudinal(theta_r, p.sigma_longitudinal).pdf(theta_i) *
                             azimuthal(p, theta_r).pdf(psi),
                         std::cos(theta_i));
}

double seed_multiple_pdf(const SeedPdfParams &p, double theta_r, double theta_i, int n_h) {
    const double sigma = sigma_multiple_of(p, n_h);
    if (sigma <= 0.0) return 0.0;
    const double sigma_prime = sigma + std::fabs(theta_r) * kInvPi;
    return per_steradian(longitudinal(theta_r, sigma_prime).pdf(theta_i) * kInvTwoPi,
                         std::cos(theta_i));
}

TruncatedNormal seed_longitudinal(double theta_r, double sigma) { return longitudinal(theta_r, sigma); }
TruncatedNormal seed_azimuthal(const SeedPdfParams &params, double theta_r) { return azimuthal(params, theta_r); }
double seed_sigma_multiple(const SeedPdfParams &params, int n_h) { return sigma_multiple_of(params, n_h); }

}  // namespace hairis
