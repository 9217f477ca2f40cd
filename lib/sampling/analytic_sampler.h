// Chiang 2016's lobe sampling (as Cycles and pbrt sample, with the exact pdf of chiang.h).
#pragma once

#include <memory>

#include "fiber/chiang.h"
#include "sampling/sampler.h"

namespace hairis {

class AnalyticSampler final : public Sampler {
  public:
    explicit AnalyticSampler(std::shared_ptr<const ChiangFiber> fiber) : fiber_(std::move(fiber)) {}
    const ShadingModel *model() const override { return fiber_.get(); }
    const SamplerPoint &at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const override;

  private:
    std::shared_ptr<const ChiangFiber> fiber_;
};

}  // namespace hairis
