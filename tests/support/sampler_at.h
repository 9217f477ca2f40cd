// Test helper: a sampler prepared at one hit, with its fiber's point when it reads one.
#pragma once

#include <memory>
#include <optional>
#include <utility>

#include "core/scratch.h"
#include "sampling/hair_bsdf.h"

namespace hairis::testing {

class SamplerAt {
  public:
    /// `inputs` (may be null) are the hit's per-strand node inputs; they must outlive this.
    SamplerAt(const Sampler &sampler, Vec3 wo, float h = 0.0f, const HairInputValues *inputs = nullptr) {
        FiberHit hit{wo, h};
        hit.inputs = inputs;
        const FiberPoint *fiber = sampler.model() ? &sampler.model()->prepare(hit, scratch_) : nullptr;
        fiber_ = fiber;
        point_ = &sampler.at(hit, fiber, scratch_);
    }
    SamplerAt(const SamplerAt &) = delete;
    SamplerAt &operator=(const SamplerAt &) = delete;

    std::optional<DirectionSample> sample(float u0, float u1, float u2) const { return point_->sample(u0, u1, u2); }
    float pdf(Vec3 wi) const { return point_->pdf(wi); }
    /// The fiber's f there (zero for samplers that read no fiber).
    Rgb f(Vec3 wi) const { return fiber_ ? fiber_->f(wi) : Rgb{}; }

  private:
    ScratchBuffer scratch_;
    const FiberPoint *fiber_ = nullptr;
    const SamplerPoint *point_ = nullptr;
};

}  // namespace hairis::testing
