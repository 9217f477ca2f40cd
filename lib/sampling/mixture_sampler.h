// The one-sample mixture (1 − w)·p_a + w·p_b of two samplers (Mitsuba's BlendBSDF idea): u2
// picks the component and, rescaled, is reused inside it; the pdf is the mixture's.
#pragma once

#include <memory>

#include "core/expected.h"
#include "sampling/sampler.h"

namespace hairis {

class MixtureSampler final : public Sampler {
  public:
    /// Refuses null components, w outside [0, 1] and components built for different models.
    static Expected<MixtureSampler> create(std::shared_ptr<const Sampler> a, std::shared_ptr<const Sampler> b,
                                           float weight_b);
    const ShadingModel *model() const override { return a_->model() ? a_->model() : b_->model(); }
    const SamplerPoint &at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const override;
    float weight_b() const { return w_; }

  private:
    MixtureSampler() = default;
    std::shared_ptr<const Sampler> a_, b_;
    float w_ = 0;
};

}  // namespace hairis
