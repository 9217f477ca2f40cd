// Chiang et al. 2016's hair fiber model as Cycles 3.4's Principled Hair BSDF evaluates it,
// with an exact analytic importance sampler.
//
// The model (per lobe p: R = 0, TT = 1, TRT = 2, residual TRRT+ = 3), for ω_o, ω_i in the
// fiber frame of frame.h and the offset h = sin γ_o:
//
//   f_p(ω_i, ω_o, h)·|cos θ_i| = A_p(θ_o, h) · M_p(θ_i, θ_o) · N_p(φ − Φ(p, h)),
//
//   M_p  d'Eon 2011's longitudinal function with variance v_p (R: the coat's v_m0, TT: v/4,
//        TRT and residual: 4v). The cuticle tilt α (Cycles' "Offset") is applied as Cycles
//        does, by rotating θ_i: R uses θ_i + 2α, TT θ_i − α, TRT θ_i − 4α, the residual none.
//   N_p  the logistic of scale s, trimmed to [−π, π], centred on Φ(p, h) = 2pγ_t − 2γ_o + pπ;
//        the residual uses 1/(2π).
//   A_p  Fresnel at cos θ_o cos γ_o and transmittance T = exp(−σ_a · 2cos γ_t / cos θ_t):
//        A_0 = F, A_1 = (1 − F)²T, A_2 = A_1·TF, A_3 = A_2·TF/(1 − TF).
//
// The far field (the FiberModel interface) averages the near field over h ∈ [−1, 1].
//
// Energy: Cycles' tilt on θ_i does not preserve ∫ M_p cos θ_i dθ_i (= ∫ M(θ') cos(θ' − δ_p)
// ≈ cos δ_p − sin δ_p tan θ_o), so with α ≠ 0 a clear fiber's albedo is not 1: at α = 2° it is
// off by ~2% at θ_o = ±30°, ~5% at ±60° and tens of percent at ±85° (the albedo is exactly 1
// only at α = 0). The sampler tilts θ_o instead, and its pdf integrates to 1.
//
// Deviation from Cycles' floating-point code, on purpose: M_p is evaluated exactly (to double
// precision) in log space. Cycles' Bessel I0 truncates its series after ten terms and its
// large-argument branch keeps only half of the 1/(8x) correction, which underestimates M_p
// by up to ~2% where cos θ_i cos θ_o / v ≈ 12 (e.g. the R lobe at the default roughness 0.3).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include "hairis/expected.h"
#include "hairis/fiber.h"
#include "hairis/math.h"

namespace hairis {

namespace chiang {
/// The logistic density of scale s > 0 restricted to [−π, π] and renormalized there, with
/// its constants (the mass inside [−π, π], the CDF at −π) computed once.
class TrimmedLogistic {
  public:
    TrimmedLogistic() = default;
    explicit TrimmedLogistic(double s);
    /// Density at x ∈ [−π, π]: e/(s(1 + e)²) / mass with e = e^{−|x|/s} (cannot overflow).
    double density(double x) const {
        const double e = std::exp(-std::fabs(x) / s_);
        return e / (s_ * ((1.0 + e) * (1.0 + e))) * norm_;
    }
    /// Inverse CDF: u ∈ [0, 1] to x ∈ [−π, π].
    double sample(double u) const;
    double scale() const { return s_; }
    /// 1 / ∫_{−π}^{π} of the untrimmed logistic.
    double norm() const { return norm_; }

  private:
    double s_ = 1, norm_ = 1, mass_ = 1, cdf_lo_ = 0;
};

/// The parts of d'Eon's longitudinal function that depend on the variance v only: κ = 1/v and
/// log(csch(κ)/(2v)) (see chiang::longitudinal_scattering).
struct LongitudinalConstants {
    double kappa = 1;
    double log_normalization = 0;
};
}  // namespace chiang

/// Parameters in Cycles' internal form (the PrincipledHairBSDF closure before its setup).
struct ChiangParams {
    /// Absorption coefficient per unit fiber radius (Cycles' bsdf->sigma), each channel >= 0.
    Rgb sigma_a{0.245531f, 0.52f, 1.365f};
    /// Longitudinal roughness β_m ("Roughness") in [0, 1]; Cycles clamps it to [0.001, 1].
    float roughness = 0.3f;
    /// Azimuthal roughness β_n ("Radial Roughness") in [0, 1]; clamped to [0.001, 1].
    float radial_roughness = 0.3f;
    /// Coat in [0, 1]: the R lobe's roughness is (1 − coat)·β_m (clamped to [0.001, 1]).
    float coat = 0.0f;
    /// Index of refraction of the fiber, > 1 (keratin: 1.55).
    float ior = 1.55f;
    /// Cuticle tilt α in radians (Cycles' "Offset"), in [−π/2, π/2] like Blender's socket.
    /// Human hair is about 2°–4°; the model stays finite over the whole range.
    float offset = float(radians(2.0));
};

/// One sample of the analytic strategy: a direction, its solid-angle density, the
/// Cycles-exact f·|cos θ_i| there, and the lobe it was drawn from.
struct ChiangSample {
    Vec3 wi;
    float pdf = 0;
    Rgb f_cos;
    int lobe = 0;
};

/// The Chiang 2016 fiber (Cycles 3.4's "Chiang" Principled Hair BSDF).
class ChiangFiber final : public FiberModel {
  public:
    /// Validates every parameter (finite, in range) and applies Cycles' clamps and roughness
    /// mappings. Errors name the parameter and its allowed range.
    static Expected<ChiangFiber> create(const ChiangParams &params);

    std::string name() const override { return "chiang2016"; }
    int lobe_count() const override { return 4; }

    /// Far field: (1/2)∫_{−1}^{1} lobe_f_cos_near(p, wi, wo, h) dh, by deterministic
    /// quadrature over γ_o with h = sin γ_o (relative accuracy ~1e-5). Zero for p outside
    /// [0, 3]. The part that depends on ω_o only is remembered per thread for the last θ_o,
    /// so sweeping many ω_i for one ω_o is fast (about 5 µs per f_cos at the defaults), and
    /// so are the azimuthal integrals already computed for that θ_o (keyed on the exact bits
    /// of φ; a table sweep meets each φ at least twice, at θ_i and −θ_i). Remembered values
    /// are bit-identical to recomputed ones. Thread-safe.
    Rgb lobe_f_cos(int p, Vec3 wi, Vec3 wo) const override;
    /// Far field summed over the four lobes (shares the per-ω_o work between lobes).
    Rgb f_cos(Vec3 wi, Vec3 wo) const override;
    /// The lobe's longitudinal shape for dual scattering as a Gaussian in θ_h = (θ_i + θ_o)/2
    /// (fiber.h): M_p peaks where θ_i + θ_o = −2α (R), +α (TT), +4α (TRT), 0 (residual) and is
    /// close to a Gaussian in θ_i + θ_o of variance v_p (d'Eon), so alpha is half that shift
    /// and beta = sqrt(v_p)/2.
    LobeShape lobe_shape(int p) const override;

    /// Near field at offset h = sin γ_o ∈ [−1, 1] (clamped; must be finite), Cycles-exact:
    /// the value of bsdf_principled_hair_eval. Directions are unit vectors in the fiber frame.
    Rgb f_cos_near(Vec3 wi, Vec3 wo, float h) const;
    /// One lobe of f_cos_near. Zero for p outside [0, 3].
    Rgb lobe_f_cos_near(int p, Vec3 wi, Vec3 wo, float h) const;

    /// Draws ω_i for the near field at offset h from three uniform numbers in [0, 1):
    /// the lobe with probability ∝ luminance(A_p) (u2, then reused for M_p), d'Eon's M_p
    /// sampling around the tilted cone (u1 for its azimuth about the cone axis), and the
    /// trimmed logistic around Φ(p, h) (u0; uniform for the residual).
    /// The tilt is applied to θ_o, in pbrt-v4's order (θ_o + 2α for R, θ_o − α for TT,
    /// θ_o − 4α for TRT), so that the density is exactly
    ///   pdf(ω_i) = Σ_p w_p M_p(θ_i; θ'_o,p, v_p) N_p(φ)
    /// per unit solid angle; the returned pdf is pdf(wi, wo, h). f_cos is Cycles-exact (tilt
    /// on θ_i), so pdf is close to but not exactly proportional to f_cos.
    /// Returns nullopt only when the density at the drawn direction is not positive.
    std::optional<ChiangSample> sample(Vec3 wo, float h, float u0, float u1, float u2) const;
    /// The density of sample() per unit solid angle.
    float pdf(Vec3 wi, Vec3 wo, float h) const;

    /// Lobe-selection probabilities at (ω_o, h): luminance(A_p) / Σ luminance(A_q).
    std::array<float, 4> lobe_probabilities(Vec3 wo, float h) const;
    /// Attenuation A_p at (ω_o, h) for p in [0, 3] (zero otherwise).
    Rgb attenuation(int p, Vec3 wo, float h) const;

    /// What the near field at (ω_o, h) needs besides M_p, computed once: every lobe's
    /// attenuation and the azimuthal centres Φ(p, h) of R, TT and TRT.
    struct LobeGeometry {
        std::array<Rgb, 4> attenuation;
        std::array<double, 3> shift{};
    };
    LobeGeometry lobe_geometry(Vec3 wo, float h) const;
    /// Cycles' tilted longitudinal function M_p(θ_i + δ_p, θ_o) of lobe p ∈ [0, 3] (density
    /// per cos θ_i dθ_i before the tilt), the factor of f_cos_near that does not depend on h.
    double longitudinal(int p, double sin_theta_i, double sin_theta_o) const;

    /// Lobe p's part of sample(): sin θ_i drawn from the sampler's M_p (d'Eon's cone about
    /// the direction tilted from θ_o by δ_p; u_cone picks its cosine, u_about the angle
    /// about it). For samplers that pick the lobe themselves (near_field_table.h).
    double sample_lobe_sin_theta(int p, double sin_theta_o, double u_cone, double u_about) const;
    /// The density of sample_lobe_sin_theta() per unit sin θ_i: the term pdf() uses for lobe p.
    double lobe_sampling_density(int p, double sin_theta_i, double sin_theta_o) const;

    /// The validated parameters as given.
    const ChiangParams &params() const { return params_; }
    /// The mapped longitudinal variance of lobe p (R: coat-reduced v_m0, TT: v/4, TRT and
    /// residual: 4v); 0 for p outside [0, 3].
    double lobe_variance(int p) const;
    /// The mapped logistic scale s.
    double logistic_scale() const { return s_; }
    /// N_p of R, TT and TRT: the trimmed logistic of scale s.
    const chiang::TrimmedLogistic &azimuthal() const { return azimuthal_; }

  private:
    ChiangFiber() = default;

    struct Outgoing;
    struct Attenuation;
    struct FarSlice;

    Outgoing outgoing(Vec3 wo) const;
    Outgoing outgoing_cones(double sin_theta_o) const;  // θ and the cones only
    Attenuation attenuation_at(const Outgoing &o, double sin_gamma_o) const;
    double tilted_longitudinal(int p, double sin_theta_i, double cos_theta_i,
                               const Outgoing &o) const;
    double sampling_longitudinal(int p, double sin_theta_i, double cos_theta_i,
                                 const Outgoing &o) const;
    double cone_sample(int p, const Outgoing &o, double u_cone, double u_about) const;
    FarSlice &far_slice(const Outgoing &o) const;
    std::array<double, 3> far_azimuthal(int p, const Outgoing &o, double phi) const;
    std::array<double, 3> far_azimuthal_uncached(int p, const Outgoing &o, double phi,
                                                 const FarSlice &slice) const;
    std::array<double, 3> far_azimuthal_graded(int p, const Outgoing &o, double phi) const;
    std::array<double, 3> fixed_panel(int p, const FarSlice &slice, double phi, int panel) const;
    std::array<double, 3> exact_panel(int p, const Outgoing &o, double phi, double a,
                                      double b) const;

    ChiangParams params_;
    double v_ = 0;      // mapped longitudinal variance
    double v_m0_ = 0;   // mapped variance of the (coated) R lobe
    double s_ = 0;      // mapped logistic scale
    double eta_ = 1.55;
    double alpha_ = 0;
    std::array<double, 3> tilt_sin_{}, tilt_cos_{1, 1, 1};  // of δ_p = (2α, −α, −4α)
    std::array<double, 3> sigma_{};
    chiang::TrimmedLogistic azimuthal_;  // N_p (R, TT, TRT)
    std::array<chiang::LongitudinalConstants, 4> longitudinal_{};  // of lobe_variance(p)
    int fixed_panels_ = 0;      // far field: γ panels of the fixed rule, 0 = graded rule
    std::uint64_t id_ = 0;      // identifies these parameters in per-thread caches
};

/// The building blocks of the model, exposed for tests and for other samplers.
namespace chiang {

/// Cycles' longitudinal roughness mapping: β clamped to [0.001, 1], then
/// v = (0.726β + 0.812β² + 3.7β²⁰)².
double longitudinal_variance(double roughness);
/// Cycles' azimuthal roughness mapping: β clamped to [0.001, 1], then
/// s = sqrt(π/8)·(0.265β + 1.194β² + 5.372β²²).
double logistic_scale(double radial_roughness);

/// log I0(x) for x >= 0, to double precision (power series, then the asymptotic series).
double log_bessel_i0(double x);

/// d'Eon's longitudinal function with variance v > 0:
///   M(θ_i, θ_o) = csch(1/v)/(2v) · exp(−sin θ_i sin θ_o / v) · I0(cos θ_i cos θ_o / v),
/// a probability density in θ_i with respect to cos θ_i dθ_i. Evaluated in log space, so
/// that tiny v neither overflows nor produces NaN. Cosines must be >= 0.
double longitudinal_scattering(double sin_theta_i, double cos_theta_i, double sin_theta_o,
                               double cos_theta_o, double v);
/// The parts of longitudinal_scattering that depend on v only (see LongitudinalConstants).
LongitudinalConstants longitudinal_constants(double v);
/// longitudinal_scattering with longitudinal_constants(v) computed beforehand (the same
/// numbers, bit for bit).
double longitudinal_scattering(double sin_theta_i, double cos_theta_i, double sin_theta_o,
                               double cos_theta_o, const LongitudinalConstants &constants);

/// Inverts the CDF of the cosine t of the angle to the cone axis, p(t) ∝ exp(t/v) on
/// [−1, 1] (d'Eon's sampling): t = 1 + v·log(u + (1 − u)·exp(−2/v)).
double sample_cone_cosine(double u, double v);

/// TrimmedLogistic(s).density(x).
double trimmed_logistic(double x, double s);
/// TrimmedLogistic(s).sample(u).
double sample_trimmed_logistic(double u, double s);

/// The azimuthal deflection Φ(p, h) = 2p·γ_t − 2γ_o + pπ.
double azimuthal_shift(int p, double gamma_o, double gamma_t);

}  // namespace chiang

}  // namespace hairis
