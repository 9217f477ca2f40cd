// Dual scattering (Zinke, Yuksel, Weber, Keyser 2008, "Dual Scattering Approximation for Fast
// Multiple Scattering in Hair") for any FiberModel, with a FIXED number n_h of fibers between
// the light and the shading point (no shadow rays, no deep opacity maps).
//
// Conventions (fiber.h, frame.h): directions point away from the shading point; θ is measured
// from the fiber's normal plane; φ = φ_i − φ_o is the relative azimuth. "Forward" scattering
// leaves on the far side of the fiber, |φ| > π/2 (the TT lobe sits at φ = ±π); "backward"
// scattering is |φ| < π/2.
//
// Precomputation (deterministic quadrature, one table entry per θ node, parallel with oneTBB;
// the numbers do not depend on the thread count). θ_L is the inclination of the direction
// towards the light (the paper's θ_d — NOT Marschner's difference angle; the paper reuses the
// symbol, as "Efficient Implementation of the Dual Scattering Model in RenderMan" points out).
// Equation numbers below are the paper's, as public implementations cite them.
//
//   a_f,p(θ_L) = <∫_{|φ−φ_L|>π/2} f_p(ω, ω_L) |cos θ| dω>_{φ_L}   forward fraction of lobe p
//   a_b,p(θ_L) = <∫_{|φ−φ_L|<π/2} f_p(ω, ω_L) |cos θ| dω>_{φ_L}   backward fraction of lobe p
//   ā_f = Σ_p a_f,p + t,  ā_b = Σ_p a_b,p      (paper eqs. 6 and 11; <·>_{φ_L} averages the
//                                               light's azimuth around an eccentric fiber)
//         DECISION: a crossing meets a Huang fiber only on its projected ellipse, a fraction
//         w(ω_L) = FiberModel::projected_width of the curve's width (Cycles makes hits outside
//         it transparent), and f is per hit on the fiber. So each a_f,p and a_b,p carries the
//         factor w(ω_L) inside the azimuthal average, and t = <1 − w(ω_L)>_{φ_L}, the light
//         that goes on unscattered, joins ā_f with shift 0 and width 0 (it dilutes ᾱ_f and
//         β̄_f² below). w = 1 (t = 0) for Chiang and Marschner.
//         DECISION: light from ω_L scatters into ω with f(ω_L, ω); by reciprocity we integrate
//         f(ω, ω_L) instead, i.e. lobe_f_cos(p, ω, ω_L) over ω with ω_L in the viewer's slot:
//         the white-furnace integral the models are built to keep ≤ 1. Cycles/Chiang's f·cos θ_i
//         is not exactly reciprocal, and its integral over the OUTGOING direction exceeds 1 for
//         a grazing light (the d'Eon M_p is normalised over θ_i), which made ā_f^n_h grow with
//         n_h near grazing.
//   ᾱ_f = Σ a_f,p α_p / ā_f,   β̄_f² = Σ a_f,p β_p² / ā_f   (and _b alike; α_p, β_p from
//                                               FiberModel::lobe_shape; the widths are averaged
//                                               as variances, which is what a mixture of
//                                               equal-mean Gaussians has)
//         LobeShape is read as fiber.h defines it: shift and standard deviation of a Gaussian
//         in θ_h = (θ_i + θ_o)/2, for every model.
//   Measured lobe shapes (models whose lobe_shapes_analytic() is false, e.g. Huang's GGX
//   lobes): α_p and β_p² are the mean and variance of θ_h under lobe p's energy density
//   f_p|cos θ| dω (channels summed), pooled over the light inclinations θ_L with weight cos θ_L,
//   from the same quadrature as a_f,p and a_b,p.
//   Ā_b = ā_b ā_f²/(1−ā_f²) + ā_b³ ā_f²/(1−ā_f²)³                                  (eq. 14)
//   Δ̄_b = ᾱ_b (1 − 2ā_b²/(1−ā_f²)²) + ᾱ_f (2(1−ā_f²)² + 4ā_f²ā_b²)/(1−ā_f²)³     (eq. 16)
//   σ̄_b = (1 + d_b ā_f²) (ā_b √(2β̄_f²+β̄_b²) + ā_b³ √(2β̄_f²+3β̄_b²)) / (ā_b + ā_b³)  (eq. 17)
//         DECISION: the paper prints the denominator as ā_b + ā_b³(2β̄_f + 3β̄_b), which adds a
//         number to an angle; we read it as the normalisation of the ā_b / ā_b³ weighted mean
//         of the two path-class widths in the numerator and drop the (2β̄_f + 3β̄_b) factor.
//   In these geometric series ā_f and ā_b are clamped to [0, max_series_attenuation] so that
//   1 − ā_f² stays away from 0 (a model that is not energy conserving can reach ā_f ≥ 1;
//   clamped_entries() counts where that happened — the results there are not meaningful).
//
//   T_f(θ_L, n_h)  = d_f ā_f(θ_L)^n_h              forward transmittance
//   σ_f²(θ_L, n_h) = n_h β̄_f(θ_L)²                 forward longitudinal spread
//         NOTE: the seed's source used σ_f² = n_h β̄_f (no square); we use the paper's form:
//         the variances of the n_h independent forward-scattering events add up.
//
// Crossings (crossing_attenuation; the renderer multiplies it strand by strand). The paper's
// volume is hair lying across the light's way, where scattering into the backward azimuths
// turns light around. Scattering keeps a ray on its fiber's specular cone: it reverses the light's travel
// across the fiber and keeps its travel along it. So of the light a strand scatters back, the
// share that travels along the fiber, sin²θ (θ the light's inclination to that strand), goes on
// with the forward light:
//   a(θ) = ā_f(θ) + sin²θ ā_b(θ),
// ā_f for light across the fiber (the paper's), ā_f + ā_b along it, where forward and backward
// azimuths head the same way. DECISION: sin²θ, the axial share of the direction's energy, is
// the simplest weight with both limits; on hair standing straight off a sphere (the light
// travels along the strands to the points below) the paper's ā_f left DUAL dark and this does
// not, while it barely moves hair lying or leaning at random.
// The distributions and the baked multiple-scattering tables keep the paper's T_f = d_f ā_f^n_h
// (the seed's S_multiple): with a(θ) their many-strand rows would all peak at grazing θ_i,
// where light runs along the fibers; they only shape where the renderer's samples go.
//
//   N_p^G(θ_d): the lobe's azimuthal function averaged over the forward azimuths (the paper's
//   N_p^G, eq. 25, a constant in φ). A FiberModel only exposes f_p·cos θ_i, so we extract it:
//   with G_p(θ_i, θ_o) = (1/π) ∫_{|φ|>π/2} f_p cos θ_i dφ (the lobe averaged over forward
//   azimuths) and Marschner's difference angle θ_d = (θ_o − θ_i)/2, on the line θ_d = const,
//     N_p^G(θ_d) = ∫ G_p dθ_h / ∫ g(θ_h − α_p; β_p²) cos θ_i / cos²θ_d dθ_h,
//   θ_h over [−π/2 + |θ_d|, π/2 − |θ_d|]. For a separable model f_p = M_p(θ_h) N_p(θ_d, φ) /
//   cos²θ_d with a Gaussian M_p (Marschner) this is exactly the forward average of N_p; for
//   any other model (Chiang's M_p is not a Gaussian in θ_h) it is the value that preserves the
//   lobe's forward-scattered energy at σ_f = 0.
//
// Shading (paper §4.3 / Fig. 6, with directFraction = 0 for n_h ≥ 1 and 1 for n_h = 0):
//   θ_h = (θ_i + θ_o)/2, θ_d = (θ_o − θ_i)/2, tables looked up at θ_L = θ_i,
//   f_back^direct  = Ā_b g(θ_h − Δ̄_b; σ̄_b²)        / (π cos²θ_d)
//   f_back^scatter = Ā_b g(θ_h − Δ̄_b; σ̄_b² + σ_f²) / (π cos²θ_d)
//         DECISION: the paper prints 2 Ā_b (...) — Marschner's normalisation, whose lobes are
//         unit Gaussians in θ_h and so carry twice their energy over θ_i (see energy_scale).
//         Single scattering f_s here is an energy-conserving fiber (Chiang) and f_s^scatter is
//         normalised like it (N_p^G below), so f_back is too: half the printed value, which
//         keeps the paper's balance between f_back and f_s (its d_b = 0.7 was chosen with both
//         in Marschner's normalisation). The bias left is measured in the dual-scattering docs.
//   f_s^scatter    = Σ_p g(θ_h − α_p; β_p² + σ_f²) N_p^G(θ_d) / cos²θ_d      (M_p^G N_p^G)
//   n_h ≥ 1: F = T_f d_f (f_s^scatter + π d_b f_back^scatter)          (F_direct = 0)
//   n_h = 0: F = d_b f_back^direct (the local multiple scattering; single scattering f_s is
//            the direct distribution and is not part of this term; T_f(0) = 1, so the global
//            term (T_f − directFraction)·… vanishes)
//   multiple_f_cos = F · cos θ_i.
// g(x; v) is the normalised Gaussian exp(−x²/2v)/√(2πv). Every term is independent of φ, so
// the azimuthal average that multiple_f_cos promises is the term itself.
//
// energy_scale (default 1) multiplies the model's f before anything is tabulated; see
// DualScatteringParams (Marschner 2003 needs 0.5).
//
// Measure: multiple_f_cos(θ_i, θ_o, n_h) is per unit solid angle of ω_i (like
// FiberModel::f_cos), and already averaged over φ, so
//   ∫_{S²} multiple_f_cos dω_i = 2π ∫_{−π/2}^{π/2} multiple_f_cos(θ_i, θ_o, n_h) cos θ_i dθ_i
// is the multiple-scattering albedo seen from θ_o. Its absolute scale follows the paper's
// normalisations (the 2/π of f_back, the π d_b of F_scatter) on top of the model's energy.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "core/expected.h"
#include "core/quadrature.h"
#include "fiber/fiber.h"
#include "core/math.h"

namespace hairis {

/// Parameters of the precomputation and of the shading formulas.
struct DualScatteringParams {
    float d_f = 0.7f;           ///< forward-scattering density factor, in [0, 1]
    float d_b = 0.7f;           ///< backward-scattering density factor, in [0, 1]
    int n_h = 2;                ///< default number of fibers between light and shading point, >= 0
    int theta_count = 32;       ///< table nodes over θ ∈ (−π/2, π/2) (cell centres), [2, 4096]
    int theta_panels = 24;      ///< quadrature panels over θ ∈ [−π/2, π/2], [1, 1024]
    int phi_panels = 8;         ///< quadrature panels per quarter turn of φ, [1, 1024]
    int points_per_panel = 4;   ///< Gauss–Legendre points per panel, [1, 16]
    int orientation_count = 4;  ///< light azimuths averaged for an eccentric fiber, [1, 256]
    float max_series_attenuation = 0.95f;  ///< clamp of ā_f, ā_b in Ā_b, Δ̄_b, σ̄_b, [0.5, 0.9999]
    /// Multiplies the model's f before tabulation, in (0, 1]. 1 for a model whose white-furnace
    /// albedo is ≤ 1 (Chiang). Marschner 2003's M_p is a unit-area Gaussian in θ_h, i.e. of
    /// area 2 over θ_i, so its fiber returns about twice the incident energy (blonde: ā_f > 1
    /// in red, where the series in Ā_b diverge); 0.5 puts it on the same footing.
    float energy_scale = 1.0f;
    float min_lobe_width = 1e-3f;          ///< β_p floor (radians) for N_p^G, [1e-6, 0.1]
    /// Measure every lobe's shift and width from f even when the model's lobe_shape() is
    /// analytic (models whose lobe_shapes_analytic() is false are always measured).
    bool measure_lobe_shapes = false;
};

/// The dual-scattering tables of one fiber model and the multiple-scattering term.
class DualScattering {
  public:
    /// Validates `params` (messages name the parameter and its range) and precomputes the
    /// tables. The model is not referenced afterwards.
    static Expected<DualScattering> create(const FiberModel &model, const DualScatteringParams &params);

    const DualScatteringParams &params() const { return params_; }
    int lobe_count() const { return lobe_count_; }

    /// Table nodes: θ_k = −π/2 + (k + ½)π/theta_count. Lookups interpolate linearly between
    /// nodes and clamp outside [θ_0, θ_last].
    int theta_count() const { return params_.theta_count; }
    double table_theta(int k) const;

    // --- Per-lobe precomputed quantities (θ = light inclination θ_L unless noted) ---------
    Rgb lobe_forward_attenuation(int p, double theta) const;   ///< a_f,p
    Rgb lobe_backward_attenuation(int p, double theta) const;  ///< a_b,p
    /// 1 − FiberModel::projected_width averaged over the light's azimuths: the share of a
    /// crossing the light passes unscattered (0 for a fiber that fills its curve).
    double pass_through(double theta) const;
    /// N_p^G at Marschner's difference angle θ_d (see the header comment).
    Rgb lobe_forward_azimuthal(int p, double theta_d) const;
    /// α_p, β_p: the model's, or measured (see "Measured lobe shapes" above).
    LobeShape lobe_shape(int p) const;
    bool lobe_shapes_measured() const { return shapes_measured_; }

    // --- Averages (paper §4) ------------------------------------------------------------
    Rgb forward_attenuation(double theta) const;    ///< ā_f
    Rgb backward_attenuation(double theta) const;   ///< ā_b
    Rgb forward_shift(double theta) const;          ///< ᾱ_f (radians)
    Rgb backward_shift(double theta) const;         ///< ᾱ_b (radians)
    Rgb forward_width(double theta) const;          ///< β̄_f (radians)
    Rgb backward_width(double theta) const;         ///< β̄_b (radians)
    Rgb backscatter_attenuation(double theta) const;  ///< Ā_b
    Rgb backscatter_shift(double theta) const;        ///< Δ̄_b (radians)
    Rgb backscatter_width(double theta) const;        ///< σ̄_b (radians)

    /// The share of light crossing a strand at inclination θ that goes on towards the point
    /// behind it: ā_f + sin²θ ā_b, at most 1 (see "Crossings" above); ā_f at θ = 0, as in the paper.
    Rgb crossing_attenuation(double theta) const;

    /// T_f = d_f ā_f^n_h for n_h ≥ 1; 1 for n_h = 0 (nothing in the way); 0 for n_h < 0 (the
    /// paper's, as the distributions and tables use it; the renderer's is crossing_attenuation's).
    Rgb forward_transmittance(double theta, int n_h) const;
    /// σ_f² = n_h β̄_f² (radians²); 0 for n_h ≤ 0.
    Rgb forward_spread_variance(double theta, int n_h) const;

    /// Number of (θ node, channel) entries where ā_f or ā_b exceeded max_series_attenuation
    /// and was clamped in Ā_b, Δ̄_b, σ̄_b (0 for a well-behaved model).
    int clamped_entries() const { return clamped_entries_; }

    /// The local multiple-scattering term of a point the light reaches directly (n_h = 0):
    /// d_b f_back^direct cos θ_i, per unit solid angle of ω_i (single scattering f_s is not in
    /// it). The same as multiple_f_cos(θ_i, θ_o, 0).
    /// `depth`: the strands behind the point that light can go on through and be scattered back
    /// from (backscatter_attenuation); negative for the paper's unbounded hair volume.
    Rgb local_f_cos(float theta_i, float theta_o, int depth = -1) const;
    /// The global term of light that crossed strands on its way, for a forward transmittance
    /// T_f (d_f included) and spread σ_f² (radians²) gathered strand by strand along the light's
    /// path: T_f d_f (f_s^scatter + π d_b f_back^scatter) cos θ_i, per channel. With
    /// T_f = forward_transmittance(θ_i, n) and σ_f² = forward_spread_variance(θ_i, n) it is
    /// multiple_f_cos(θ_i, θ_o, n) for n ≥ 1. Negative σ_f² is taken as 0.
    Rgb scattered_f_cos(float theta_i, float theta_o, Rgb transmittance, Rgb spread_variance,
                        int depth = -1) const;

    /// Ā_b at θ with the forward series cut at `depth` strands behind the point: the paper's
    /// Σ_{i≥1} ā_f^{2i} (first term) and its cube (third) summed over i ≤ depth, so with x = ā_f²
    /// Ā_b = ā_b x (1 − x^depth)/(1 − x) + ā_b³ x (1 − x^depth)³/(1 − x)³ (0 for depth 0);
    /// backscatter_attenuation(θ) for depth < 0. Light that goes deeper leaves the hair.
    Rgb backscatter_attenuation(double theta, int depth) const;

    /// The multiple-scattering term F·cos θ_i, averaged over azimuth, per unit solid angle of
    /// ω_i (see "Measure" above). n_h < 0 is a precondition violation and returns 0.
    Rgb multiple_f_cos(float theta_i, float theta_o, int n_h) const;
    /// The same with params().n_h.
    Rgb multiple_f_cos(float theta_i, float theta_o) const {
        return multiple_f_cos(theta_i, theta_o, params_.n_h);
    }

  private:
    DualScattering() = default;

    struct Rgbd {
        double v[3] = {0, 0, 0};
    };
    Rgbd lookup(const std::vector<Rgbd> &table, double theta, std::size_t offset = 0) const;
    Rgbd backscatter(double theta, int depth) const;
    Rgbd local_term(double theta_i, double theta_o, int depth) const;
    Rgbd scattered_term(double theta_i, double theta_o, const Rgbd &t_f, const Rgbd &s_f2,
                        int depth) const;
    static Rgb to_rgb(const Rgbd &c);
    // The steps of create(), in its order.
    struct Quadrature;
    struct ViewAlbedos;
    void integrate_albedos(const FiberModel &model, const Quadrature &rules);
    void integrate_spread(const FiberModel &model, const Quadrature &rules);
    void derive_terms();

    DualScatteringParams params_;
    int lobe_count_ = 0;
    int clamped_entries_ = 0;
    bool shapes_measured_ = false;
    std::vector<LobeShape> shapes_;
    // Per lobe, per θ node (index p * theta_count + k).
    std::vector<Rgbd> a_f_lobe_, a_b_lobe_, n_g_lobe_;
    std::vector<double> pass_;  // per θ node: the unscattered share of a crossing (1 − projected width)
    // Per θ node.
    std::vector<Rgbd> a_f_, a_b_, alpha_f_, alpha_b_, beta2_f_, beta2_b_;
    std::vector<Rgbd> big_a_b_, delta_b_, sigma2_b_;
};

}  // namespace hairis
