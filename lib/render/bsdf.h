// The BSDF of one path vertex, hair fiber or surface, as the path tracer shades it: the
// FiberHit Cycles would set up at a curve hit (frame, offset h, major axis, pixel coverage,
// seed), the material's prepared fiber and sampler (or Cycles' own Huang sampler), or a mesh
// material's lobes.
#pragma once

#include <cstdint>
#include <optional>

#include "core/frame.h"
#include "core/scratch.h"
#include "fiber/huang.h"
#include "render/scene.h"
#include "render/surface_bsdf.h"
#include "sampling/hair_bsdf.h"

namespace hairis {

/// Cycles' pixel_coverage for a camera ray (kernel/svm/closure.h, Huang): half the pixel
/// footprint at the hit in units of the curve radius there; +inf for a radius of 0 (never
/// near field).
float cycles_pixel_coverage(float footprint, float curve_radius);

/// The FiberHit the renderer gives a hair material at a curve hit, as Cycles sets up the
/// Principled Hair closure: ω_o and h = dot(cross(Ng, X), Z) (ribbons: h = −v) in the frame
/// FiberFrame::from_tangent_and_view, where a back-facing hit (the inside of a tube) turns Ng and
/// the tangent, as Cycles turns Ng, N and dP/du towards ω_o; the
/// major axis from the curve normal, or, where the curve has none (or it is parallel to the
/// tangent), Cycles' fallback frame around the world tangent (HuangFiber::fallback_major_axis);
/// pixel_coverage from `footprint` for camera rays, 1 for every other ray; `seed` for the
/// point's random numbers.
FiberHit cycles_fiber_hit(const SurfacePoint &sp, Vec3 wo, bool camera_ray, float footprint,
                          std::uint32_t seed);

/// The first hair hit of the camera ray through raster position (x + u, y + v), past hair it
/// crosses transparently, as the renderer sets it up (for tests); nullopt when the ray meets
/// no hair or meets something else first.
std::optional<FiberHit> camera_hair_hit(const Scene &scene, int x, int y, float u, float v);

/// What a hair BSDF needs besides the hit point: whether the ray is a camera ray (Cycles'
/// PATH_RAY_CAMERA, kept through transparent crossings), its footprint there, and the seed of
/// the point's random numbers.
struct HitContext {
    bool camera_ray = false;
    float footprint = 0;
    std::uint32_t seed = 0;
    bool cycles_huang = false;  ///< RenderSettings::huang_sampling == Cycles
    /// Filter Glossy's roughness at this vertex (render/filter_glossy.h); 0: none.
    float blur_roughness = 0;
};

/// Cycles turns Ng, N and dP/du towards ω_o at a back-facing hit (shader_setup_from_ray; on a
/// curve, the inside of the tube seen through its open end): the hair frame follows −tangent.
inline bool back_facing(const SurfacePoint &sp, Vec3 wo) { return dot(sp.normal, wo) < 0.0f; }

/// The fiber frame of a curve hit seen from `wo` (FiberFrame::from_tangent_and_view).
inline FiberFrame hair_frame(const SurfacePoint &sp, Vec3 wo) {
    return FiberFrame::from_tangent_and_view(back_facing(sp, wo) ? -sp.tangent : sp.tangent, wo);
}

/// The FiberHit of a curve hit. `frame`: hair_frame(sp, wo). `oriented`: fill the fields only
/// models that reads_orientation() use (Huang).
FiberHit fiber_hit(const SurfacePoint &sp, Vec3 wo, const FiberFrame &frame, const HitContext &context,
                   bool oriented = true);

/// What Cycles' film_write_denoising_features_surface reads from the closures of one vertex:
/// the closure-weighted average normal (world space; the tangent for Huang hair), the albedo
/// of the diffuse-like closures (every hair closure counts as one) and that of the specular
/// ones (lobe_is_specular), and whether the specular closures hold at least 3/4 of the sample
/// weight, in which case the passes look on to the next hit through them.
struct DenoisingFeatures {
    Vec3 normal{0, 0, 0};
    Rgb albedo{0.0f};
    Rgb specular_albedo{0.0f};
    bool specular = false;
};

/// A BSDF at a shading point: evaluation f·|cos θ_i|, its sampling density, and sampling.
/// Hair prepares its fiber and sampler once (hair_bsdf.h), in `scratch`; surfaces build their
/// lobes (surface_material.h) with both normals on ω_o's side, as Cycles flips them for back
/// faces.
class Bsdf {
  public:
    /// `inputs`: the hit's per-strand node inputs (hair), null for the material's own;
    /// `weights`: its per-strand closure weights (a hair mixture), null for the material's.
    Bsdf(const Material &material, const SurfacePoint &sp, Vec3 wo, const HitContext &context,
         const HairInputValues *inputs, ScratchBuffer &scratch, const ClosureWeights *weights = nullptr);

    bool black() const { return !is_hair() && surface_.black(); }
    bool is_hair() const { return hair_.has_value() || huang_ || mixture_.has_value(); }
    /// The ray passes without scattering (Huang outside its ellipse).
    bool transparent() const {
        return (hair_ && hair_->transparent()) || (huang_ && huang_->transparent()) ||
               (mixture_ && mixture_->transparent());
    }
    /// The prepared fiber and sampler (null for surfaces, hair mixtures and Cycles' Huang
    /// sampling).
    const HairBsdf *hair() const { return hair_ ? &*hair_ : nullptr; }
    const FiberFrame &frame() const { return frame_; }

    /// f·|cos θ_i| and the density with which sample() draws wi (Cycles' Huang: its eval, or
    /// the baked expectation of it, and pdf 1, what Cycles' MIS weighs with).
    Rgb eval(Vec3 wi, float &pdf) const {
        if (huang_) {
            pdf = 1.0f;
            return huang_f_->f(frame_.to_local(wi));
        }
        if (hair_) return hair_->f_and_pdf(frame_.to_local(wi), pdf);
        if (mixture_) return mixture_->f_and_pdf(frame_.to_local(wi), pdf);
        return surface_.eval(wi, pdf);
    }

    /// Draws wi; returns false when there is none. weight = f·|cos|/pdf (Cycles' Huang: its
    /// sampler's weight, with pdf 1); `glossy`: drawn from a surface's glossy lobe.
    /// `cycles_pdf` (may be null) receives the density Cycles records for the same bounce, which
    /// its Filter Glossy reads: a Chiang closure's own density (its eval's energy-weighted
    /// lobes), 1 for Huang, a surface's reported density, the sample's density otherwise; a
    /// mixture's closure-weighted mean.
    bool sample(float u0, float u1, float u2, Vec3 &wi, Rgb &weight, float &pdf, bool &glossy,
                float *cycles_pdf = nullptr) const;

    /// The denoising features of this vertex (Cycles' closures seen from ω_o).
    DenoisingFeatures denoising_features() const;

  private:
    std::optional<HairBsdf> hair_;
    std::optional<HairMixtureBsdf> mixture_;
    const HuangPoint *huang_ = nullptr;      // Cycles' Huang sampling: the closure it samples
    const FiberPoint *huang_f_ = nullptr;    // ... and the f it shades with (baked or Cycles')
    mutable CyclesLcg lcg_;              // its sampler's numbers beyond the path's three
    FiberFrame frame_;
    SurfaceBsdf surface_;
};

}  // namespace hairis
