// Huang, Hullin and Hanika 2022's microfacet hair fiber model ("A Microfacet-based Hair
// Scattering Model") as Cycles 4.5.0 and 5.0.0 evaluate it: the Principled Hair BSDF with
// model Huang. docs/huang.md is the specification this file implements; section numbers (§)
// refer to it.
//
// Frames. Huang's frame (HuangFiber's FiberModel interface, HuangExpectation): x = the unit
// tangent (root to tip), y = the ellipse's major axis, z = x × y. The renderer's frame
// (FiberHit, HuangPoint): frame.h's x = tangent, y = normalize(x × ω_o), z = x × y, with the
// curve normal given in it (FiberHit::normal); the point rotates into Huang's frame itself.
// For a circular fiber (aspect ratio 1) only the relative azimuth matters and Cycles puts the
// major axis on normalize(tangent × ω_o), i.e. the renderer's y.
//
// Values. Every f is Cycles' "eval": f(ω_i, ω_o)·|cos θ_i| per unit solid angle of ω_i, the
// radiance scattered towards ω_o per unit irradiance, averaged over the fiber's projected
// width (far field) or over the part of it a pixel sees (near field, §6). Cycles' eval is
// random (one GGX visible-normal sample per Simpson node for TT, two for TRT and TRRT+, §6.2,
// §7): HuangExpectation is its expectation by deterministic quadrature over those microfacet
// samples; HuangPoint::f_estimate replays one Cycles eval from Cycles' LCG, and HuangPoint::f
// is such an unbiased one-sample estimate of the expectation (its own LCG, seeded per hit).
//
// Deviations from Cycles' floating-point code, on purpose: double precision and exact
// trigonometry (Cycles: float and fast_sincos); d'Eon's M in the TRRT+ term evaluated exactly
// (Cycles truncates its Bessel series); the GGX glass albedo table computed by quadrature
// (ggx_glass_albedo.h) instead of read from Cycles' Monte Carlo table.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/direction_cones.h"
#include "core/expected.h"
#include "core/math.h"
#include "core/vec3d.h"
#include "fiber/fiber.h"
#include "fiber/fiber_point.h"

namespace hairis {

/// The closure's parameters, as Cycles' SVM hands them to bsdf_hair_huang_setup.
struct HuangParams {
    /// Absorption coefficient per unit fiber radius (the ellipse's major semi-axis), each
    /// channel >= 0: the transmittance along a path of length L radii is exp(−σ_a L).
    Rgb sigma_a{0.245531f, 0.52f, 1.365f};
    /// GGX roughness α, the node's Roughness after the random factor, in [0, 1]; Cycles clamps
    /// it to [0.001, 1].
    float roughness = 0.3f;
    /// Index of refraction of the fiber, in (1, 1000].
    float ior = 1.55f;
    /// The node's Offset in radians, in [−π/2, π/2], before Cycles negates it (τ = −offset).
    float offset = float(radians(2.0));
    /// Minor / major axis, in (0, 1000]. Values above 1 are replaced by their inverse, as
    /// Cycles does; Cycles' accompanying swap of the axes is a no-op (§2.3).
    float aspect_ratio = 0.85f;
    /// Lobe multipliers (Reflection, Transmission, Secondary Reflection), each in [0, 1000]
    /// and not all zero. TRRT+ follows Secondary Reflection's on/off state only (§6.2).
    float reflection = 1, transmission = 1, secondary_reflection = 1;
};

/// Where a ray met the fiber, in Huang's frame (x = tangent, y = major axis).
struct HuangHit {
    Vec3 wo;  ///< unit direction towards the viewer
    /// Signed offset of the ray from the fiber axis in units of the major semi-axis (§2.4).
    /// |h| >= the projected radius makes Cycles treat the hit as transparent.
    float h = 0;
    /// Half the pixel footprint in fiber radii (§1.4); 1 for all but camera rays. Near field
    /// iff the projected radius exceeds it.
    float pixel_coverage = 1;
};

/// Cycles' per-shading-point linear congruential generator (kernel/sample/lcg.h): the state
/// advances as s ← 1103515245 s + 12345 (mod 2³²) and yields float(s)·2⁻³² ∈ [0, 1].
struct CyclesLcg {
    std::uint32_t state = 0;
    float next() {
        state = 1103515245u * state + 12345u;
        return float(state) * 0x1p-32f;
    }
};

/// One direction of Cycles' chained sampler (§8): the direction (renderer's frame), its weight
/// ("eval" with pdf 1: an estimate of f/pdf for a density Cycles never computes) and the
/// lobe (0 R, 1 TT, 2 TRT, 3 TRRT+).
struct HuangCyclesSample {
    Vec3 wi;
    Rgb weight;
    int lobe = 0;
};

/// Quadrature of HuangExpectation over the microfacet samples of Cycles' eval.
struct HuangQuadrature {
    int first_order = 8;   ///< Gauss nodes per angle for the entry microfacet (order², ≤ 32)
    int second_order = 5;  ///< ... for the internal-reflection microfacet of TRT/TRRT+
    /// ... for the entry microfacet of TT alone (0: first_order). TT's one-microfacet chains are
    /// cheap and its lobe is the brightest, so a finer rule there buys accuracy for little time.
    int tt_order = 0;
    int scan = 8;          ///< points per ψ line bracketing the events the rules split at
    /// Divides Cycles' Simpson steps (0.7α, 0.8α); 1 = Cycles. Only for studying the
    /// discretization: any other value is no longer Cycles' function.
    int simpson_refinement = 1;
};

class HuangFiber;

/// Everything of Cycles' closure that depends on the view only (§2, §6 steps 1–5), in
/// Cycles' closure frame (x = major axis, y = tangent, z = x × y).
namespace huang {
struct View {
    bool empty = true;        ///< no visible h (eval 0), or transparent
    bool transparent = false; ///< |h| >= projected radius: Cycles' transparent closure
    bool near = false;        ///< projected radius > pixel coverage
    double radius = 1;        ///< projected radius R (§2.5)
    double denominator = 1;   ///< cos θ_v · d
    Vec3d v;                  ///< view in closure coordinates
    double sin_phi_v = 0, cos_phi_v = 1, h = 0;
    double rot_c = 1, rot_s = 0;  ///< circular: rotation about the tangent putting φ_v at 0
    double u_min = 0, u_max = 0;  ///< the clamped integration interval of u = h/R
    int r_intervals = 0, res_intervals = 0;
    double r_delta = 0, res_delta = 0;
};
}  // namespace huang

/// Cycles' eval at one (ω_o, hit), in expectation over its microfacet samples: the chains up
/// to the last interface are precomputed (product Gauss rules over the visible-normal
/// densities, HuangQuadrature), f(ω_i) sums their exits.
class HuangExpectation {
  public:
    /// f·|cos θ_i| (ω_i in Huang's frame), all lobes.
    Rgb f(Vec3 wi) const;
    /// R, TT, TRT, TRRT+. With `rest` (an expectation built with absorptions, HuangFiber::
    /// expectation): rest[k] = TT + TRT + TRRT+ of one channel of the fiber with absorption
    /// absorptions[k] instead of its own, from the same chains.
    std::array<Rgb, 4> lobes(Vec3 wi, double *rest = nullptr) const;
    /// The absorptions `rest` is computed at.
    const std::vector<double> &absorptions() const { return absorptions_; }
    const huang::View &view() const { return view_; }
    /// Precomputed paths (TT exits, TRT exits, TRRT+ terms counted only under total internal
    /// reflection), for cost studies.
    std::size_t tt_paths() const { return tt_.size(); }
    std::size_t trt_paths() const { return trt_.size(); }
    std::size_t tir_paths() const { return tir_only_.x.size(); }

  private:
    friend class HuangFiber;
    /// f adds coefficient·colour·T₂·D₂·G₂·c_hi2·c_ho2/|ĥ₂|²; Λ(cos_m2) does not depend on ω_i,
    /// so it is computed once per path.
    struct TtPath {
        Vec3d wt, n2;
        double coefficient = 0, lambda2 = 0;
        std::array<double, 3> colour{};
    };
    /// One TRT exit (its TRRT+ term is in trrt_always_); the coefficient includes the exit's
    /// energy scale. Only paths whose w_tr faces both exit normals are kept: the others never
    /// pass the exit's visibility test.
    struct TrtPath {
        Vec3d wtr, n3, m3;
        double coefficient = 0, lambda3 = 0;
        std::array<double, 3> colour{};
    };
    /// TRRT+ terms that count only when the exit is totally reflecting, as columns grouped
    /// by the direction −w_tr, with each cone's sum: most cones count wholly or not at all.
    struct TirPaths {
        std::vector<double> x, y, z;  ///< −w_tr
        std::vector<double> r, g, b;  ///< the TRRT+ term
        std::vector<double> extra;    ///< the term at each extra absorption (`count` per term)
        std::size_t count = 0;
        DirectionCones cones;
        std::vector<std::array<double, 3>> cone_sums;
        std::vector<double> cone_extra;  ///< `count` per cone
        void push_back(Vec3d minus_wtr, const std::array<double, 3> &trrt, const double *trrt_extra);
        void group();
        /// Σ of the terms whose exit towards l is totally reflecting (dot(−w_tr, l) < cos_min);
        /// with `extra`, their extra terms' sums too (added to extra[0..count)).
        std::array<double, 3> sum_reflecting(Vec3d l, double cos_min, double *extra = nullptr) const;
    };
    /// Orders the TRT paths by cone of −w_tr and groups the TRRT+ terms; called once built.
    void group_paths();
    explicit HuangExpectation(const HuangFiber &fiber) : fiber_(&fiber) {}

    const HuangFiber *fiber_;
    huang::View view_;
    std::vector<TtPath> tt_;
    std::vector<TrtPath> trt_;
    DirectionCones trt_cones_;  ///< of −w_tr, over trt_ as ordered
    TirPaths tir_only_;
    std::array<double, 3> trrt_always_{};
    // Extra absorptions: the colour of each TT and TRT path and the TRRT+ sums at each of
    // them (absorptions_.size() per path, in the paths' order).
    std::vector<double> absorptions_, tt_extra_, trt_extra_, trrt_always_extra_;
};

/// The Huang fiber at one renderer hit. f is an unbiased estimate of HuangExpectation's f
/// (Cycles' one-sample eval, drawn from an LCG seeded from FiberHit::seed and the hit); the
/// replayable estimator and Cycles' sampler are kept for studies and comparisons.
class HuangPoint final : public FiberPoint {
  public:
    HuangPoint(const HuangFiber &fiber, const FiberHit &hit);

    /// One draw of Cycles' eval at wi (renderer's frame) from the point's own LCG.
    Rgb f(Vec3 wi) const override { return f_estimate(wi, lcg_); }
    /// The R lobe of Cycles' eval at wi (renderer's frame): deterministic, so it is exactly
    /// the R lobe of the expectation at this hit.
    Rgb f_reflection(Vec3 wi) const;
    /// One Cycles eval: the Simpson nodes with one microfacet chain per node drawn from `lcg`
    /// exactly as Cycles consumes it (§7). Its mean over draws is the expectation.
    Rgb f_estimate(Vec3 wi, CyclesLcg &lcg) const;
    /// f_estimate(wi, lcg) minus the eval of `other` that replays the same stream, in one
    /// pass. `other` must draw the same microfacet chains (the same roughness, IOR, offset,
    /// aspect ratio and lobe multipliers): only its absorption is read. R cancels.
    Rgb f_estimate_difference(Vec3 wi, CyclesLcg &lcg, const HuangFiber &other) const;
    /// Cycles' sampler (§8): u_lobe = rand.x, u_offset = rand.y (far field), u_microfacet =
    /// rand.z, the rest from `lcg`. nullopt where Cycles returns pdf 0 (or is transparent).
    std::optional<HuangCyclesSample> sample_cycles(float u_lobe, float u_offset, float u_microfacet,
                                                   CyclesLcg &lcg) const;

    /// |h| >= the projected radius: Cycles replaces the closure by a transparent one.
    bool transparent() const override { return view_.transparent; }
    /// Cycles' bsdf_hair_huang_albedo: (A − 2FA + F) / (1 − FA) with F the Fresnel factor at the
    /// macro normal of h and A the absorption along the chord the refracted view crosses.
    Rgb albedo() const override;
    bool tangent_is_denoising_normal() const override { return true; }
    const HuangPoint *huang_point() const override { return this; }
    bool near_field() const { return view_.near; }
    double projected_radius() const { return view_.radius; }
    /// The hit's ω_o in Huang's frame, and a renderer-frame direction in it.
    Vec3 to_huang(Vec3 w) const;
    Vec3 from_huang(Vec3 w) const;
    /// The HuangHit this point evaluates (for HuangFiber::expectation).
    HuangHit huang_hit() const;
    const HuangFiber &fiber() const { return *fiber_; }
    /// The point's LCG as its next eval will start it (seeded per hit).
    CyclesLcg lcg() const { return lcg_; }

  private:
    const HuangFiber *fiber_;
    huang::View view_;
    double frame_c_ = 1, frame_s_ = 0;  // renderer (y, z) → Huang (y, z): rotation about x
    mutable CyclesLcg lcg_;
};

/// The far field seen from one ω_o: a HuangExpectation at pixel coverage 1 (not separable).
class HuangFarField final : public FarFieldView {
  public:
    HuangFarField(const HuangFiber &fiber, Vec3 wo, const HuangQuadrature &quadrature);
    Rgb lobe_f_cos(int p, Vec3 wi) const override;
    const HuangExpectation &expectation() const { return expectation_; }

  private:
    HuangExpectation expectation_;
    std::uint64_t id_;  // unique per view: keys the per-thread cache of the last ω_i's lobes
};

/// The Huang 2022 fiber (Cycles 4.5/5.0 "Principled Hair BSDF", model Huang).
class HuangFiber final : public FiberModel, public ShadingModel {
  public:
    /// Validates every parameter; errors name the parameter and its allowed range.
    static Expected<HuangFiber> create(const HuangParams &params, const HuangQuadrature &far_field = {});

    std::string name() const override { return "huang2022"; }
    /// Overrides FiberModel's and ShadingModel's.
    const HuangFiber *as_huang() const override { return this; }
    /// R, TT, TRT, TRRT+.
    int lobe_count() const override { return 4; }
    /// The far field from ω_o (Huang's frame) with the quadrature given to create().
    std::unique_ptr<const FarFieldView> view(Vec3 wo) const override;
    /// One lobe of view(wo) (builds the view: slow per call).
    Rgb lobe_f_cos(int p, Vec3 wi, Vec3 wo) const override;
    Rgb f_cos(Vec3 wi, Vec3 wo) const override;
    /// A Gaussian in θ_h for dual scattering, from the mesonormal tilt and the GGX width
    /// (an approximation: GGX lobes are not Gaussian).
    LobeShape lobe_shape(int p) const override;
    bool lobe_shapes_analytic() const override { return false; }
    /// True only for aspect ratio 1.
    bool rotationally_symmetric() const override { return aspect_ == 1.0; }
    /// √(1 − e² w_y² / (w_y² + w_z²)), e² = 1 − aspect²: the projected radius Cycles'
    /// make_view compares |h| with (1 along the fiber's axis).
    double projected_width(Vec3 w) const override;

    /// The point for the renderer (in scratch).
    bool reads_orientation() const override { return true; }
    const FiberPoint &prepare(const FiberHit &hit, ScratchBuffer &scratch) const override {
        return scratch.make<HuangPoint>(*this, hit);
    }
    HuangPoint at(const FiberHit &hit) const { return HuangPoint(*this, hit); }
    /// The expectation of Cycles' eval at a hit in Huang's frame; with `absorptions`, also the
    /// colour of every chain at each of them (HuangExpectation::lobes' `rest`): the chains do
    /// not depend on the absorption, so one build serves fibers of any absorption.
    HuangExpectation expectation(const HuangHit &hit, const HuangQuadrature &quadrature = {},
                                 const std::vector<double> &absorptions = {}) const;
    /// Cycles' set-up of §2 and §6 steps 1–5 for a hit in Huang's frame.
    huang::View make_view(const HuangHit &hit, int simpson_refinement = 1) const;

    const HuangParams &params() const { return params_; }
    /// The aspect ratio in (0, 1] after the inversion rule.
    double aspect_ratio() const { return aspect_; }
    /// The clamped GGX roughness α in [0.001, 1].
    double roughness() const { return alpha_; }
    /// Cycles' tilt τ = −offset.
    double tilt() const { return tilt_; }
    double ior() const { return eta_; }
    const std::array<double, 3> &sigma() const { return sigma_; }
    /// The lobe multipliers as Cycles stores them.
    double m_r() const { return m_r_; }
    double m_tt() const { return m_tt_; }
    double m_trt() const { return m_trt_; }

    /// Cycles' major axis for a curve normal: `normal` made perpendicular to the unit tangent,
    /// normalize(t × normalize(n × t)); zero when that is zero or not finite.
    static Vec3 major_axis(Vec3 tangent, Vec3 normal);
    /// Cycles' frame when the curve has no normal (legacy particle hair writes zero normals):
    /// make_orthonormals of the world tangent t, c = normalize(s × t) with s = (1, 1, 1), or
    /// the cross product with its middle component negated when t's components are all equal;
    /// the major axis is t × c. A renderer passes it (in its local frame) as FiberHit::normal
    /// to reproduce Cycles' particle hair.
    static Vec3 fallback_major_axis(Vec3 tangent);

  private:
    HuangFiber() = default;
    friend class HuangPoint;
    friend class HuangExpectation;

    HuangParams params_;
    HuangQuadrature far_field_;
    double alpha_ = 0.3, eta_ = 1.55, tilt_ = 0, aspect_ = 1;
    std::array<double, 3> sigma_{};
    double m_r_ = 1, m_tt_ = 1, m_trt_ = 1;
};

}  // namespace hairis
