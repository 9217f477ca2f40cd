// Chiang et al. 2016's hair fiber model as Cycles' Principled Hair BSDF evaluates it (3.4's
// semantics and 4.2's), with an exact analytic importance sampler.
//
// The model (per lobe p: R = 0, TT = 1, TRT = 2, residual TRRT+ = 3), for ω_o, ω_i in the
// fiber frame of frame.h and the offset h = sin γ_o:
//
//   f_p(ω_i, ω_o, h)·|cos θ_i| = A_p(θ_o, h) · M_p(θ_i, θ_o) · N_p(φ − Φ(p, h)),
//
//   M_p  d'Eon 2011's longitudinal function with variance v_p (R: the coat's v_m0, TT: v/4,
//        TRT and residual: 4v), tilted by the cuticle angle α (Cycles' "Offset") with
//        δ_p = (2α, −α, −4α) for R, TT, TRT (the residual is not tilted). Cycles 3.4 tilts θ_i:
//        M(θ_i + δ_p, θ_o); Cycles 4.2 and later tilt θ_o: M(θ_i, θ_o + δ_p) ("cones").
//   N_p  the logistic of scale s, trimmed to [−π, π], centred on Φ(p, h) = 2pγ_t − 2γ_o + pπ;
//        the residual uses 1/(2π).
//   A_p  Fresnel at cos θ_o cos γ_o and transmittance T = exp(−σ_a · 2cos γ_t / cos θ_t):
//        A_0 = F, A_1 = (1 − F)²T, A_2 = A_1·TF, A_3 = A_2·TF/(1 − TF).
//
// The far field (the FiberModel interface) averages the near field over h ∈ [−1, 1].
//
// Energy: a tilt on θ_i does not preserve ∫ M_p cos θ_i dθ_i, so with 3.4's semantics and
// α ≠ 0 a clear fiber's albedo is not 1; with 4.2's (tilt on θ_o) it is.
//
// The sampler tilts θ_o (pbrt-v4's order): its pdf Σ_p w_p M_p(θ_i | θ_o + δ_p) N_p is exact
// and, with 4.2's semantics, proportional to luminance(f) up to the lobe weights.
//
// Deviation from Cycles' floating-point code, on purpose: M_p is evaluated to double precision
// (Boost's I0, in log space where a factor would overflow), where Cycles' truncated Bessel I0
// series underestimates it near its switch to the asymptotic form.
#pragma once

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.h"
#include "core/math.h"
#include "fiber/fiber.h"
#include "fiber/fiber_point.h"

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
/// log(csch(κ)/(2v)).
struct LongitudinalConstants {
    double v = 1;
    double kappa = 1;
    double log_normalization = 0;
};

/// sin and |cos| of an angle.
struct SinCos {
    double sin = 0, cos = 1;
};

/// d'Eon's longitudinal function about one axis θ_c: the density per unit sin θ_i
///   M(θ_i | θ_c) = csch(κ)κ/2 · exp(−κ sin θ_i sin θ_c) · I0(κ cos θ_i cos θ_c)
/// (M(θ_i, θ_o) of the paper with θ_o = θ_c), and its exact sampler.
class Cone {
  public:
    Cone(SinCos axis, const LongitudinalConstants &constants) : axis_(axis), c_(&constants) {}
    double density(double sin_theta_i, double cos_theta_i) const;
    /// sin θ_i from two uniform numbers: the cosine to the cone axis (u_cone), then the angle
    /// about it (u_about).
    double sample(double u_cone, double u_about) const;
    SinCos axis() const { return axis_; }

  private:
    SinCos axis_;
    const LongitudinalConstants *c_;
};

/// Cycles' longitudinal roughness mapping: β clamped to [0.001, 1], then
/// v = (0.726β + 0.812β² + 3.7β²⁰)².
double longitudinal_variance(double roughness);
/// Cycles' azimuthal roughness mapping: β clamped to [0.001, 1], then
/// s = sqrt(π/8)·(0.265β + 1.194β² + 5.372β²²).
double logistic_scale(double radial_roughness);
/// log I0(x) for x >= 0, to double precision (series, then the asymptotic expansion): for
/// arguments where I0 itself overflows.
double log_bessel_i0(double x);
/// The constants of variance v > 0.
LongitudinalConstants longitudinal_constants(double v);
/// d'Eon's M(θ_i, θ_o) with variance v (Cone's density with the axis at θ_o). Cosines >= 0.
double longitudinal_scattering(double sin_theta_i, double cos_theta_i, double sin_theta_o,
                               double cos_theta_o, double v);
/// Inverts the CDF of the cosine t of the angle to the cone axis, p(t) ∝ exp(t/v) on
/// [−1, 1] (d'Eon's sampling): t = 1 + v·log(u + (1 − u)·exp(−2/v)).
double sample_cone_cosine(double u, double v);
/// The azimuthal deflection Φ(p, h) = 2p·γ_t − 2γ_o + pπ.
double azimuthal_shift(int p, double gamma_o, double gamma_t);
/// (sin, |cos|) of θ + δ: an angle pushed past ±π/2 reads as its mirror image, as in Cycles.
SinCos rotate(SinCos theta, SinCos delta);
}  // namespace chiang

/// Which Cycles evaluates the model: where the cuticle tilt is applied in f.
enum class ChiangTilt {
    Incident,  ///< Cycles 3.4 to 4.1: M(θ_i + δ_p, θ_o)
    Outgoing,  ///< Cycles 4.2 and later: M(θ_i, θ_o + δ_p) (fix for #114780)
};

/// "cycles3.4" or "cycles4.2".
const char *chiang_tilt_name(ChiangTilt tilt);

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
    /// Cuticle tilt α in radians (the node's "Offset"), in [−π/2, π/2] like Blender's socket.
    float offset = float(radians(2.0));
    /// Whose evaluation of the tilt: Cycles 3.4's or 4.2's.
    ChiangTilt tilt = ChiangTilt::Incident;
};

class ChiangFiber;

/// The constants of one parameter set that f and the samplers read: the mapped variances and
/// logistic, the cuticle tilts, σ_a and η. Trivially destructible, so that the parameters of
/// one hit (a strand's own, chiang_strands.h) can live in a ScratchBuffer.
class ChiangLobes {
  public:
    /// Validates every parameter (finite, in range) and applies Cycles' clamps and roughness
    /// mappings. Errors name the parameter and its allowed range.
    static Expected<ChiangLobes> create(const ChiangParams &params);
    /// The lobes of `params`, which must be valid (as create() accepts them; not checked):
    /// the constants of the parameters that equal `base`'s are copied from it, the others
    /// computed, so the result equals create(params)'s.
    static ChiangLobes derive(const ChiangLobes &base, const ChiangParams &params);
    /// Cycles' bsdf_hair_chiang_blur (Filter Glossy): the mapped variances v and v_m0 and the
    /// logistic scale s each raised to `roughness` where below it, the mapped values compared
    /// with the roughness as Cycles compares them; nullopt when none rises. params() still
    /// names the inputs the lobes were made from.
    std::optional<ChiangLobes> blurred(double roughness) const;

    const ChiangParams &params() const { return params_; }
    /// The mapped longitudinal variance of lobe p (R: coat-reduced v_m0, TT: v/4, TRT and
    /// residual: 4v); 0 for p outside [0, 3].
    double lobe_variance(int p) const;
    /// The mapped logistic scale s.
    double logistic_scale() const { return s_; }
    /// N_p of R, TT and TRT: the trimmed logistic of scale s.
    const chiang::TrimmedLogistic &azimuthal() const { return azimuthal_; }
    /// True when lobe p's M_p is the same function as in `other` (same variance, tilt and
    /// tilt semantics), p in [0, 3].
    bool same_longitudinal(int p, const ChiangLobes &other) const;
    /// M_p as f evaluates it (tilt per params().tilt), per unit sin θ_i; 0 for p outside [0, 3].
    double lobe_longitudinal(int p, double sin_theta_i, double sin_theta_o) const;
    /// Lobe p's cone for a view at sin θ_o: d'Eon's M about θ_o + δ_p.
    chiang::Cone lobe_cone(int p, double sin_theta_o) const;

  private:
    friend class ChiangFiber;
    friend class ChiangPoint;
    friend class ChiangFarField;
    ChiangLobes() = default;
    /// longitudinal_ of lobe_variance(p), once the variances are set.
    void set_longitudinal_constants();

    /// The cone axes θ_o + δ_p of R, TT, TRT and θ_o for the residual.
    std::array<chiang::SinCos, 4> cones(chiang::SinCos o) const;
    /// M_p per params().tilt, with the cone axes already known.
    double tilted_longitudinal(int p, double sin_i, double cos_i, chiang::SinCos o,
                               chiang::SinCos cone) const;
    /// A_p and Φ_p at h for a view with Bravais ratio k and chord scale path_scale.
    void attenuation_at(double cos_theta_o, double k, double path_scale, double h,
                        std::array<std::array<double, 3>, 4> &a, double &gamma_o,
                        double &gamma_t) const;

    ChiangParams params_;
    double v_ = 0;      // mapped longitudinal variance
    double v_m0_ = 0;   // mapped variance of the (coated) R lobe
    double s_ = 0;      // mapped logistic scale
    double eta_ = 1.55;
    double alpha_ = 0;
    std::array<chiang::SinCos, 3> tilt_{};  // δ_p = (2α, −α, −4α)
    std::array<double, 3> sigma_{};
    chiang::TrimmedLogistic azimuthal_;  // N_p (R, TT, TRT)
    std::array<chiang::LongitudinalConstants, 4> longitudinal_{};  // of lobe_variance(p)
};

/// The Chiang fiber at one hit (ω_o, h): the attenuations, azimuthal centres, lobe weights and
/// cones computed once; f, the analytic sampler and its density read them.
class ChiangPoint final : public FiberPoint {
  public:
    ChiangPoint(const ChiangFiber &fiber, const FiberHit &hit);
    /// The fiber of `lobes` at the hit; `lobes` must outlive the point. `blurred`: the lobes
    /// are a material's widened by Filter Glossy (ChiangLobes::blurred), which samplers baked
    /// for the material do not follow.
    ChiangPoint(const ChiangLobes &lobes, const FiberHit &hit, bool blurred = false);

    /// f·|cos θ_i| (near field, as Cycles' bsdf_principled_hair_eval).
    Rgb f(Vec3 wi) const override;
    /// One lobe of f; zero for p outside [0, 3].
    Rgb lobe_f(int p, Vec3 wi) const;

    /// The analytic sampler: the lobe with probability lobe_probability(p) (u2, then reused
    /// for M_p), sin θ_i from the lobe's cone (u1 the angle about it) and φ from the trimmed
    /// logistic around Φ(p, h) (u0; uniform for the residual). nullopt when the density at
    /// the drawn direction is not positive.
    std::optional<DirectionSample> sample(float u0, float u1, float u2) const;
    /// Its density per steradian: Σ_p w_p M_p(θ_i | cone_p) N_p(φ − Φ_p).
    float pdf(Vec3 wi) const;
    /// f(wi) and pdf(wi) in one pass (the same values): ω_i is resolved once, N_p is shared,
    /// and so is M_p where the tilt is on θ_o.
    Rgb f_and_pdf(Vec3 wi, float &pdf) const;
    /// sample() with f·|cos θ_i| at the drawn direction (f_and_pdf's).
    std::optional<DirectionSample> sample_with_f(float u0, float u1, float u2, Rgb &f) const;

    /// Cycles' bsdf_hair_chiang_albedo: exp(−√σ_a · albedo_roughness_scale(v)) + F(cos θ_o cos γ_o),
    /// with the mapped longitudinal variance v where the node's mapping reads β_n (as Cycles
    /// does); Cycles 3.4's (ChiangTilt::Incident) has no F term.
    Rgb albedo() const override;
    /// A_p (p in [0, 3]).
    Rgb attenuation(int p) const;
    /// luminance(A_p) / Σ luminance(A_q): the analytic sampler's lobe weights.
    float lobe_probability(int p) const { return float(weight_[std::size_t(p)]); }
    /// Φ(p, h) for p in [0, 2].
    double shift(int p) const { return shift_[std::size_t(p)]; }
    /// Lobe p's cone (ChiangFiber::lobe_cone at this θ_o), p in [0, 3].
    chiang::Cone cone(int p) const;
    /// φ_i − φ_o of a direction (one atan2).
    double relative_azimuth(Vec3 wi) const;
    /// The direction at sin θ_i and relative azimuth φ.
    Vec3 direction(double sin_theta_i, double cos_theta_i, double phi) const;
    double sin_theta_o() const { return o_.sin; }
    double cos_theta_o() const { return o_.cos; }
    /// The parameters' constants this point reads.
    const ChiangLobes &lobes() const { return *lobes_; }
    const ChiangPoint *chiang_point() const override { return this; }
    /// Whether the lobes are Filter Glossy's widening of the material's.
    bool blurred() const { return blurred_; }

  private:
    double longitudinal(int p, double sin_i, double cos_i) const;
    // The analytic sampler's direction for (u0, u1, u2) and the lobe it came from.
    Vec3 draw(float u0, float u1, float u2, int &lobe) const;

    const ChiangLobes *lobes_;
    chiang::SinCos o_;
    double cos_phi_o_ = 0, sin_phi_o_ = -1;
    std::array<std::array<double, 3>, 4> a_{};
    std::array<double, 3> shift_{};
    std::array<double, 4> weight_{};
    std::array<chiang::SinCos, 4> cone_{};
    bool blurred_ = false;
};

/// The far field at one θ_o, factored per lobe: f_p·|cos θ_i| = M_p(θ_i | θ_o) · N̄_p(φ) with
/// N̄_p(φ) = ½∫ A_p(h) N_p(φ − Φ(p, h)) dh (RGB).
class ChiangFarField final : public FarFieldView {
  public:
    /// The far field seen from ω_o (φ = φ_i − φ_o is measured from ω_o's azimuth).
    ChiangFarField(const ChiangFiber &fiber, Vec3 wo);
    Rgb lobe_f_cos(int p, Vec3 wi) const override;
    bool separable() const override { return true; }
    double longitudinal(int p, double theta_i) const override;
    Rgb azimuthal(int p, double phi) const override;

  private:
    std::array<double, 3> azimuthal_fixed(int p, double phi) const;
    std::array<double, 3> azimuthal_graded(int p, double phi) const;
    std::array<double, 3> fixed_panel(int p, double phi, int panel) const;
    std::array<double, 3> exact_panel(int p, double phi, double a, double b) const;

    const ChiangFiber *fiber_;
    chiang::SinCos o_;
    double cos_phi_o_ = 0, sin_phi_o_ = -1;
    double k_ = 0, path_scale_ = 2;
    int node_count_ = 0;             // per lobe; 0 with the graded rule
    std::vector<double> shift_;      // [p·n + j]: Φ(p, γ_j) wrapped to [−π, π]
    std::vector<double> weight_;     // [(p·n + j)·3 + c]: ½ w_j cos γ_j A_p(γ_j)_c
    std::array<std::array<double, 3>, 3> total_weight_{};  // Σ_j weight, per lobe
    std::array<double, 3> residual_{};  // ½∫ A_3 cos γ dγ
};

/// The Chiang 2016 fiber (Cycles' "Chiang" Principled Hair BSDF).
class ChiangFiber final : public FiberModel, public ShadingModel {
  public:
    /// Validates every parameter (finite, in range) and applies Cycles' clamps and roughness
    /// mappings. Errors name the parameter and its allowed range.
    static Expected<ChiangFiber> create(const ChiangParams &params);

    std::string name() const override { return "chiang2016"; }
    const ChiangFiber *as_chiang() const override { return this; }
    int lobe_count() const override { return 4; }

    /// The fiber at a hit.
    ChiangPoint at(const FiberHit &hit) const { return ChiangPoint(*this, hit); }
    /// The fiber at `hit`, widened by its Filter Glossy blur (FiberHit::blur_roughness) where
    /// that raises a roughness.
    const FiberPoint &prepare(const FiberHit &hit, ScratchBuffer &scratch) const override;
    /// f_cos of the near field at (ω_o, h): at({wo, h}).f(wi).
    Rgb f_cos_near(Vec3 wi, Vec3 wo, float h) const { return at({wo, h}).f(wi); }

    /// Far field: (1/2)∫_{−1}^{1} of the near field over h, by deterministic quadrature over
    /// γ_o with h = sin γ_o (relative accuracy ~1e-5).
    std::unique_ptr<const FarFieldView> view(Vec3 wo) const override;
    ChiangFarField far_field(Vec3 wo) const { return ChiangFarField(*this, wo); }
    Rgb lobe_f_cos(int p, Vec3 wi, Vec3 wo) const override;
    Rgb f_cos(Vec3 wi, Vec3 wo) const override;

    /// The lobe's longitudinal shape for dual scattering as a Gaussian in θ_h = (θ_i + θ_o)/2:
    /// M_p peaks where θ_i + θ_o = −2α (R), +α (TT), +4α (TRT), 0 (residual), close to a
    /// Gaussian in θ_i + θ_o of variance v_p, so alpha is half that shift and beta = sqrt(v_p)/2.
    LobeShape lobe_shape(int p) const override;

    /// M_p as f evaluates it (tilt per params().tilt), per unit sin θ_i; 0 for p outside [0, 3].
    double lobe_longitudinal(int p, double sin_theta_i, double sin_theta_o) const {
        return lobes_.lobe_longitudinal(p, sin_theta_i, sin_theta_o);
    }
    /// Lobe p's cone for a view at sin θ_o: d'Eon's M about θ_o + δ_p, the analytic sampler's
    /// M_p (and, with ChiangTilt::Outgoing, f's).
    chiang::Cone lobe_cone(int p, double sin_theta_o) const { return lobes_.lobe_cone(p, sin_theta_o); }

    /// The validated parameters as given.
    const ChiangParams &params() const { return lobes_.params(); }
    /// The mapped longitudinal variance of lobe p (R: coat-reduced v_m0, TT: v/4, TRT and
    /// residual: 4v); 0 for p outside [0, 3].
    double lobe_variance(int p) const { return lobes_.lobe_variance(p); }
    /// The mapped logistic scale s.
    double logistic_scale() const { return lobes_.logistic_scale(); }
    /// N_p of R, TT and TRT: the trimmed logistic of scale s.
    const chiang::TrimmedLogistic &azimuthal() const { return lobes_.azimuthal(); }
    /// The constants every point of this fiber reads.
    const ChiangLobes &lobes() const { return lobes_; }

  private:
    friend class ChiangFarField;
    ChiangFiber() = default;

    ChiangLobes lobes_;
    int fixed_panels_ = 0;  // far field: γ panels of the fixed rule, 0 = graded rule
};

}  // namespace hairis
