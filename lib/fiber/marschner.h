// Marschner et al. 2003, "Light Scattering from Human Hair Fibers": the far-field model
//
//   S(ω_i, ω_o) = Σ_p M_p(θ_h) N_p(θ_d, φ, φ_h) / cos² θ_d,        p ∈ {R, TT, TRT}
//
// in the fiber frame of frame.h: θ_h = (θ_i + θ_o)/2, θ_d = (θ_o − θ_i)/2, φ = φ_i − φ_o
// (wrapped to [−π, π]) and φ_h = (φ_i + φ_o)/2, the half azimuth measured from the frame's Y
// axis, which is taken as the major axis of the elliptical cross-section.
//
//   M_p(θ_h) = g(β_p; θ_h − α_p), a normalized Gaussian in θ_h. With α_R < 0 the R lobe peaks
//              at θ_i = 2α_R − θ_o (= −θ_o − 15° by default), the TT lobe at 2α_TT − θ_o.
//   N_p      = Σ_roots A(p, h) / |2 dφ/dh| over the offsets h = sin γ_i whose exit azimuth
//              is φ (mod 2π), with Marschner's cubic φ(p, γ_i) ≈ (6pc/π − 2)γ_i − 8pc/π³ γ_i³ + pπ,
//              c = asin(1/η'), η' and η'' Bravais' indices at θ_d.
//   A(0, h)  = F(η', η'', γ_i),
//   A(p, h)  = (1 − F(η', η'', γ_i))² F(1/η', 1/η'', γ_t)^(p−1) T(σ'_a, h)^p,
//              T = exp(−2σ'_a(1 + cos 2γ_t)), σ'_a = σ_a / cos θ_t, sin θ_t = sin θ_d / η.
//
// The TRT lobe is computed for the eccentricity-adjusted index η*(φ_h) (Marschner §4.3) and
// has Marschner's caustic treatment: the singular caustics of the cubic at ±φ_c are faded
// out and replaced by glints k_G·A(2, h_c)·Δh·g(w_c; φ ∓ φ_c). See marschner.cpp for the
// decisions taken where the paper is ambiguous.
#pragma once

#include <string>

#include "core/expected.h"
#include "fiber/fiber.h"
#include "core/math.h"

namespace hairis {

/// Parameters of the Marschner model; angles in radians. Defaults are those of the seed's
/// source (a brunette fiber with the Marschner 2003 surface parameters).
struct MarschnerParams {
    /// Index of refraction of the fiber (cortex), > 1.
    double eta = 1.55;
    /// Absorption coefficient per unit fiber RADIUS (the fiber has radius 1 in the cross
    /// section, so a chord through the centre is 2 long), the unit of Marschner's
    /// T = exp(−2σ'_a(1 + cos 2γ_t)). Default: the brunette preset.
    Rgb sigma_a{0.432f, 0.612f, 0.98f};
    /// Longitudinal shifts α_p of the lobes (cuticle tilt): α_TT = −α_R/2, α_TRT = −3α_R/2
    /// (Marschner's relations; set all three when changing α_R). α_R < 0 tilts R towards the
    /// root when the frame's X points from root to tip.
    double alpha_r = radians(-7.5);
    double alpha_tt = radians(3.75);
    double alpha_trt = radians(11.25);
    /// Longitudinal widths β_p (standard deviations of M_p in θ_h).
    double beta_r = radians(7.5);
    double beta_tt = radians(3.725);
    double beta_trt = radians(15.0);
    /// Ratio a of the cross-section's axes (1 = circular); must exceed 1/√2 so that
    /// η*_1 = 2(η − 1)a² − η + 2 stays above 1.
    double eccentricity = 0.9;
    /// Glint scale factor k_G.
    double glint_scale = 0.4;
    /// Azimuthal width w_c of the caustic/glint Gaussians.
    double caustic_width = radians(1.5);
    /// Fade range Δη' over which the glint fades out once η*' exceeds 2 (the caustics merged).
    double caustic_fade = 0.3;
    /// Caustic intensity limit Δh_M.
    double caustic_limit = 0.5;

    /// The defaults with σ_a = (0.15, 0.20, 0.30) per unit radius.
    static MarschnerParams blonde();
    /// The defaults with σ_a = (0.432, 0.612, 0.98) per unit radius.
    static MarschnerParams brunette();
};

/// Where and how strong the TRT glints are for one θ_d and φ_h (see trt_caustic()).
struct MarschnerCaustic {
    double eta_perp = 0;    ///< Bravais η*' the TRT lobe uses
    bool exists = false;    ///< true when η*' < 2: two caustics at ±phi_c
    double h_c = 0;         ///< offset of the caustic (0 once merged)
    double phi_c = 0;       ///< azimuth of the caustic, in [0, π]
    double delta_h = 0;     ///< Δh = min(Δh_M, 2·sqrt(2 w_c / |d²φ/dh²(h_c)|))
    double t = 0;           ///< fade weight in [0, 1]
};

/// Marschner 2003 as a FiberModel. Evaluation is thread-safe (const, no caches).
class MarschnerFiber final : public FiberModel {
  public:
    /// Validates every parameter; the error names the parameter and its allowed range.
    static Expected<MarschnerFiber> create(const MarschnerParams &params);

    const MarschnerParams &params() const { return params_; }

    // FiberModel.
    std::string name() const override { return "marschner2003"; }
    int lobe_count() const override { return 3; }
    /// S_p(ω_i, ω_o)·|cos θ_i| for p ∈ {0, 1, 2}; 0 for any other p or non-finite input.
    Rgb lobe_f_cos(int p, Vec3 wi, Vec3 wo) const override;
    /// The sum of the three lobes, sharing the per-direction work.
    Rgb f_cos(Vec3 wi, Vec3 wo) const override;
    /// {α_p, β_p}; {0, 0} for p outside [0, 2].
    LobeShape lobe_shape(int p) const override;
    /// Only a circular fiber (eccentricity == 1) ignores the half azimuth φ_h.
    bool rotationally_symmetric() const override { return params_.eccentricity == 1.0; }

    // The model's factors, exposed for tests and tabulation. Angles in radians; p ∈ {0, 1, 2}.

    /// M_p(θ_h) = g(β_p; θ_h − α_p).
    double longitudinal(int p, double theta_h) const;
    /// N_p(θ_d, φ, φ_h), with the caustic treatment for TRT.
    Rgb azimuthal(int p, double theta_d, double phi, double phi_h) const;
    /// N_p as the plain sum over the roots (no caustic treatment; the TRT caustics are
    /// integrable singularities, kept finite by a floor on |dφ/dγ|).
    Rgb azimuthal_without_caustic(int p, double theta_d, double phi, double phi_h) const;
    /// A(p, h) at θ_d (and φ_h, which only matters for TRT through η*).
    Rgb attenuation(int p, double h, double theta_d, double phi_h) const;
    /// S_p = M_p N_p / cos² θ_d (without the cos θ_i of lobe_f_cos).
    Rgb scattering(int p, double theta_i, double theta_o, double phi, double phi_h) const;
    /// η*(φ_h) = ½((η*_1 + η*_2) + cos 2φ_h (η*_1 − η*_2)); η when eccentricity == 1.
    double eta_star(double phi_h) const;
    /// Caustic position, width and fade of the TRT lobe at θ_d, φ_h.
    MarschnerCaustic trt_caustic(double theta_d, double phi_h) const;

  private:
    explicit MarschnerFiber(const MarschnerParams &params);
    double eta_star_from_cos(double cos_two_phi_h) const;

    MarschnerParams params_;
    double eta_star_1_ = 0, eta_star_2_ = 0;
};

namespace marschner {

/// At most this many offsets map to one exit azimuth (3 per 2π-branch, ≤ 3 branches).
inline constexpr int kMaxRoots = 9;

/// Marschner's cubic exit azimuth φ(p, γ_i) ≈ (6pc/π − 2)γ_i − 8pc/π³ γ_i³ + pπ (unwrapped).
double exit_azimuth(int p, double c, double gamma_i);
/// dφ/dγ_i of the cubic.
double exit_azimuth_slope(int p, double c, double gamma_i);
/// Every γ_i ∈ [−π/2, π/2] with exit_azimuth(p, c, γ_i) ≡ phi (mod 2π), found on the cubic's
/// monotone pieces by bracketed Newton iteration (to ~1e-13). Returns the number of roots
/// written to `roots` (unsorted); 0 for a non-finite phi or c outside [0, π/2].
int solve_exit_azimuth(int p, double c, double phi, double roots[kMaxRoots]);

}  // namespace marschner

}  // namespace hairis
