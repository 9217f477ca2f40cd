// A fiber's scattering at one shading point (pbrt-v4 builds a HairBxDF per hit the same way):
// what depends on where the ray met the fiber is computed once, and f is evaluated from it for
// any number of ω_i (the light sample, the BSDF sample).
#pragma once

#include <cstdint>

#include "core/math.h"
#include "core/scratch.h"

namespace hairis {

struct HairInputValues;
class HuangFiber;
class HuangPoint;
class ChiangPoint;
class StrandInputReader;

/// Where a ray met a fiber, in the fiber frame of frame.h (x = tangent).
struct FiberHit {
    Vec3 wo;      ///< unit direction towards the viewer
    float h = 0;  ///< offset across the fiber, in [−1, 1] (frame.h)
    /// The curve's normal attribute in the same frame (Huang: the ellipse's major axis after
    /// removing its tangential part); zero when the curve has none. Chiang ignores it.
    Vec3 normal{};
    /// Cycles' pixel_coverage: half the pixel footprint in fiber radii for camera rays, 1 for
    /// every other ray (Huang's near field iff the projected radius exceeds it). Chiang
    /// ignores it.
    float pixel_coverage = 1;
    /// Seeds models whose f is a Monte Carlo estimate (Huang, like Cycles' per-shading-point
    /// LCG); hashed with wo and h, so 0 is a valid seed. Chiang ignores it.
    std::uint32_t seed = 0;
    /// The material's node inputs that vary per strand, at this hit (hair_inputs.h), or null:
    /// the material's own values. Must outlive what is prepared from the hit.
    const HairInputValues *inputs = nullptr;
    /// Cycles' Filter Glossy at this hit: the roughness its bsdf_blur raises the closure's
    /// roughness parameters to (render/filter_glossy.h); 0: none. Read by the Principled Hair
    /// models (ChiangStrands, HuangStrands).
    float blur_roughness = 0;
};

/// A sampled incident direction and the density it was drawn from.
struct DirectionSample {
    Vec3 wi;        ///< unit direction towards the light, fiber frame
    float pdf = 0;  ///< solid-angle density of wi, > 0
    int lobe = -1;  ///< the lobe drawn from, when the sampler knows it (−1 otherwise)
};

/// A fiber model prepared at one hit. Trivially destructible (lives in a ScratchBuffer).
class FiberPoint {
  public:
    /// f(ω_i, ω_o, h)·|cos θ_i| for this hit: the value the path tracer multiplies by.
    virtual Rgb f(Vec3 wi) const = 0;
    /// True when the ray passes the fiber without scattering (Cycles' Huang closure outside
    /// the ellipse inscribed in the round tube): the renderer continues it unchanged.
    virtual bool transparent() const { return false; }
    /// Cycles' bsdf_albedo of the closure at this hit per unit closure weight, what its
    /// denoising albedo pass sums (Cycles' default for a closure without its own: 1).
    virtual Rgb albedo() const { return Rgb{1.0f}; }
    /// True when Cycles' denoising normal pass reads the fiber tangent here rather than the
    /// closure normal (its Huang closure, which it counts as far-field hair).
    virtual bool tangent_is_denoising_normal() const { return false; }
    /// Cycles' Huang closure of this hit's own fiber, or null: a renderer that samples Huang
    /// with Cycles' sampler samples and shades with it.
    virtual const HuangPoint *huang_point() const { return nullptr; }
    /// The Chiang fiber of this hit, or null: Cycles' pdf of a Chiang closure is its density.
    virtual const ChiangPoint *chiang_point() const { return nullptr; }
    const FiberHit &hit() const { return hit_; }

  protected:
    explicit FiberPoint(const FiberHit &hit) : hit_(hit) {}
    FiberPoint(const FiberPoint &) = default;
    FiberPoint &operator=(const FiberPoint &) = default;
    ~FiberPoint() = default;

  private:
    FiberHit hit_;
};

/// A fiber model a renderer shades: it prepares a FiberPoint per hit.
class ShadingModel {
  public:
    virtual ~ShadingModel() = default;
    /// The model at `hit`, made in `scratch` (valid until its reset).
    virtual const FiberPoint &prepare(const FiberHit &hit, ScratchBuffer &scratch) const = 0;
    /// Whether prepare() reads FiberHit::normal, pixel_coverage and seed (a renderer may leave
    /// them at their defaults otherwise).
    virtual bool reads_orientation() const { return false; }
    /// This model as a HuangFiber, or null (a renderer may sample Huang with Cycles' own sampler).
    virtual const HuangFiber *as_huang() const { return nullptr; }
    /// What the model says about per-strand inputs, or null when it reads none.
    virtual const StrandInputReader *strand_inputs() const { return nullptr; }
};

}  // namespace hairis
