// The seed's analytic PDFs (its §"Finding a probability density function"), corrected:
//
//   f_ds = f_ds^L(θ_i) · f_ds^A(φ)   direct scattering
//     f_ds^L: a Gaussian in θ_i centred at −θ_r with σ_L. The seed's text says 0.22, its
//             formula 0.44; fitted to our direct distributions (hairis-bake fits,
//             the fits docs) σ_L is 0.17–0.26 for both models away from grazing, and 0.22
//             fits their shape better than 0.44, so the default is 0.22.
//     f_ds^A: a Gaussian in the relative azimuth φ = φ_i − φ_r centred on the TT lobe at
//             ±π (the seed's "φ_i + φ_r = ±2π" is a slip for ±π in its mirrored φ_r),
//             σ_A = 0.52 + (θ_r/π)²;
//   f_ms = a Gaussian in θ_i centred at −θ_r with σ' = σ(n_h) + |θ_r|/π (the seed's
//          θ_r/π goes negative for θ_r < 0; it means the magnitude), uniform in φ.
//
// Each Gaussian is normalized over its truncated domain (θ_i ∈ [−π/2, π/2], the azimuth
// offset from the lobe in [−π, π]), so p(θ_i, φ) integrates to 1 over dθ_i dφ; the solid-angle
// density is p / cos θ_i. Sampling inverts the truncated normal's CDF; sample and pdf share
// the same CDF code, so the reported density is the sampled one.
#pragma once

#include <vector>

#include "core/expected.h"

namespace hairis {

/// A normal distribution truncated to [lo, hi], sampled by inverting its CDF.
class TruncatedNormal {
  public:
    TruncatedNormal(double mean, double sigma, double lo, double hi);
    /// Density on [lo, hi] (0 outside).
    double pdf(double x) const;
    /// The x whose truncated CDF is u ∈ [0, 1].
    double sample(double u) const;

  private:
    double mean_, sigma_, lo_, hi_;
    double cdf_lo_, mass_;  // Φ(lo) and Φ(hi) − Φ(lo) of the untruncated normal
};

/// The seed's parameters, with Table 1's σ per n_h.
struct SeedPdfParams {
    double sigma_longitudinal = 0.22;  ///< σ_L of f_ds^L (radians): the seed's text value, chosen by fit
    double sigma_azimuthal_base = 0.52;  ///< σ_A = base + (θ_r/π)²
    std::vector<int> n_h_values = {1, 2, 4, 8, 16};
    std::vector<double> sigma_multiple = {0.44, 0.41, 0.37, 0.34, 0.29};  ///< Table 1

    /// Refuses non-positive or non-finite widths and mismatched tables.
    Status validate() const;
};

/// The seed's direct-scattering PDF f_ds per steradian of ω_i, for view angle θ_r.
double seed_direct_pdf(const SeedPdfParams &params, double theta_r, double theta_i, double phi);

/// The seed's multiple-scattering PDF f_ms per steradian of ω_i, for n_h strands.
double seed_multiple_pdf(const SeedPdfParams &params, double theta_r, double theta_i, int n_h);

/// The truncated normal of f_ds^L and f_ms in θ_i: centred at −θ_r with σ, on [−π/2, π/2].
TruncatedNormal seed_longitudinal(double theta_r, double sigma);
/// f_ds^A in the offset ψ = wrap(φ − π) from the TT lobe: σ_A = base + (θ_r/π)², on [−π, π].
TruncatedNormal seed_azimuthal(const SeedPdfParams &params, double theta_r);
/// Table 1's σ for n_h, or −1 when params has none for it.
double seed_sigma_multiple(const SeedPdfParams &params, int n_h);

}  // namespace hairis
