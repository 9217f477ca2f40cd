// The seed's Table 1 and Table 2 values, for printing them beside ours.
#pragma once

namespace hairis::cli {

/// The θ_r of the seed's figures and Table 2 (degrees). ±90° is a view along the fiber,
/// singular for both models: we evaluate it at ±kGrazingDegrees.
inline constexpr double kSeedThetaR[7] = {-90, -60, -30, 0, 30, 60, 90};
inline constexpr double kGrazingDegrees = 89.0;
inline constexpr double kSeedPhiR[5] = {180, 90, 0, -90, -180};
inline constexpr int kSeedStrands[5] = {1, 2, 4, 8, 16};

/// Table 1: σ per n_h ∈ {1, 2, 4, 8, 16}.
inline constexpr double kSeedTable1Sigma[5] = {0.44, 0.41, 0.37, 0.34, 0.29};

/// Table 2: (s, σ, μ-shift in degrees) per n_h ∈ {1, 2, 4, 8} and θ_r ∈ kSeedThetaR.
struct SeedFit {
    double scale, sigma, mu_shift_deg;
};
inline constexpr SeedFit kSeedTable2[4][7] = {
    {{1.0, 0.75, 0}, {10.0 / 67, 0.55, -34.5}, {1.0 / 9, 0.49, -20}, {2.0 / 19, 0.49, -1.2},
     {1.0 / 9, 0.49, 17.5}, {10.0 / 67, 0.55, 29}, {2.0, 0.65, 0}},
    {{0.4, 0.90, 0}, {100.0 / 965, 0.55, -38}, {1.0 / 12, 0.49, -20}, {1.0 / 125, 0.49, -1.2},
     {1.0 / 12, 0.49, 17.5}, {100.0 / 965, 0.55, 34}, {0.4, 0.90, 0}},
    {{1.0 / 15, 0.51, -61}, {10.0 / 205, 0.47, -43}, {1.0 / 25, 0.41, -22}, {10.0 / 255, 0.41, -1.2},
     {1.0 / 25, 0.41, 20}, {10.0 / 205, 0.47, 40}, {1.0 / 14, 0.52, 54}},
    {{1.0 / 60, 0.41, -70}, {1.0 / 70, 0.38, -49}, {1.0 / 73, 0.38, -25}, {1.0 / 78, 0.36, -1.2},
     {1.0 / 75, 0.38, 23}, {1.0 / 73, 0.38, 46}, {1.0 / 63, 0.41, 68}}};

/// θ_r in degrees → the angle we evaluate (radians), pulling ±90° in to ±89°.
inline double evaluated_theta_r(double degrees_in) {
    const double d = degrees_in > kGrazingDegrees ? kGrazingDegrees
                   : degrees_in < -kGrazingDegrees ? -kGrazingDegrees : degrees_in;
    return d * 3.14159265358979323846 / 180.0;
}

}  // namespace hairis::cli
