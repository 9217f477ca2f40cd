// A hair material's BSDF at one hit: the fiber model's point (f) and the sampler's point
// (sample, pdf), prepared once and shared by the light sample and the BSDF sample.
#pragma once

#include <memory>
#include <optional>

#include "core/expected.h"
#include "core/scratch.h"
#include "fiber/fiber_point.h"
#include "sampling/sampler.h"

namespace hairis {

/// A sampled direction, its density and f·|cos θ_i| there.
struct BsdfSample {
    Vec3 wi;
    Rgb f;
    float pdf = 0;
    int lobe = -1;
};

/// The BSDF at one hit. Valid while the scratch buffer it was made in is not reset.
class HairBsdf {
  public:
    HairBsdf(const FiberPoint *fiber, const SamplerPoint &sampler) : fiber_(fiber), sampler_(&sampler) {}
    /// f·|cos θ_i|; zero without a fiber model (a bare sampler).
    Rgb f(Vec3 wi) const { return fiber_ ? fiber_->f(wi) : Rgb{}; }
    /// The ray passes the fiber without scattering (FiberPoint::transparent).
    bool transparent() const { return fiber_ && fiber_->transparent(); }
    /// The fiber model at the hit (null for a bare sampler).
    const FiberPoint *fiber() const { return fiber_; }
    /// The density sample() draws from.
    float pdf(Vec3 wi) const { return sampler_->pdf(wi); }
    /// f(wi) and pdf(wi) together (what a light sample needs), computed in one pass where the
    /// sampler shares work with the fiber model.
    Rgb f_and_pdf(Vec3 wi, float &pdf) const { return sampler_->f_and_pdf(wi, fiber_, pdf); }
    /// A direction with its density and f; nullopt when none is produced.
    std::optional<BsdfSample> sample(float u0, float u1, float u2) const {
        Rgb f;
        const std::optional<DirectionSample> s = sampler_->sample_with_f(u0, u1, u2, fiber_, f);
        if (!s) return std::nullopt;
        return BsdfSample{s->wi, f, s->pdf, s->lobe};
    }

  private:
    const FiberPoint *fiber_;
    const SamplerPoint *sampler_;
};

/// A fiber model bound to the sampler that draws ω_i for it: what a hair material shades with.
class HairShading {
  public:
    /// Refuses a null sampler, and a sampler built for another model than `model` (which may be
    /// null only for samplers that read no fiber).
    static Expected<HairShading> create(std::shared_ptr<const ShadingModel> model, std::shared_ptr<const Sampler> sampler);

    /// The BSDF at `hit`, made in `scratch`.
    HairBsdf at(const FiberHit &hit, ScratchBuffer &scratch) const {
        const FiberPoint *fiber = model_ ? &model_->prepare(hit, scratch) : nullptr;
        return HairBsdf(fiber, sampler_->at(hit, fiber, scratch));
    }
    const ShadingModel *model() const { return model_.get(); }
    const Sampler &sampler() const { return *sampler_; }

  private:
    HairShading() = default;
    std::shared_ptr<const ShadingModel> model_;
    std::shared_ptr<const Sampler> sampler_;
};

}  // namespace hairis
