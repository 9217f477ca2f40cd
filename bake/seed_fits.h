// Our versions of the seed's fits: scaled Gaussians fitted by least squares to our
// multiple-scattering profiles (Tables 1 and 2) and to the direct distribution (σ_L, σ_A).
#pragma once

#include <string>
#include <vector>

#include "fiber/distributions.h"
#include "fiber/dual_scattering.h"
#include "fiber/gaussian_fit.h"

namespace hairis::cli {

/// One fit of S_multiple(θ_i | θ_r, n_h) per steradian (the quantity the seed plots).
struct MultipleFitRow {
    int n_h;
    double theta_r_deg;        ///< the seed's θ_r (±90 evaluated at ±89)
    GaussianFit fit;           ///< mean in radians
    double peak_deg;           ///< where the profile peaks
    double albedo;             ///< ∫ S_multiple dω_i
    std::vector<double> theta; ///< cell centres (radians)
    std::vector<double> profile;
};

/// Fits for every n_h in `strands` and every θ_r of the seed's Table 2.
Expected<std::vector<MultipleFitRow>> fit_multiple(const DualScattering &ds, const std::vector<int> &strands,
                                                   int theta_count);

/// One direct fit at θ_r: σ_L of the θ_i profile (mean fixed at −θ_r, as the seed's f_ds^L)
/// and σ_A of the azimuthal profile around the TT lobe (mean fixed at φ = π).
struct DirectFitRow {
    double theta_r_deg;
    GaussianFit longitudinal;   ///< over θ_i, mean −θ_r
    GaussianFit azimuthal;      ///< over ψ = φ − π wrapped, mean 0
    double seed_sigma_a;        ///< 0.52 + (θ_r/π)²
    double error_sigma_l_022;   ///< relative L2 error of the seed's f_ds^L with σ = 0.22
    double error_sigma_l_044;   ///< ... with σ = 0.44
};

Expected<std::vector<DirectFitRow>> fit_direct(const FiberModel &model, int theta_count, int phi_count,
                                               int quadrature_points = 3);

}  // namespace hairis::cli
