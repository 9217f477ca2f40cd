// Chiang 2016's lobe sampling (as Cycles and pbrt sample, with the exact pdf of chiang.h).
#pragma once

#include <memory>

#include "fiber/chiang.h"
#include "fiber/chiang_strands.h"
#include "sampling/sampler.h"

namespace hairis {

/// Samples the hit's own ChiangPoint: for a material whose inputs vary per strand, each
/// strand's own fiber.
class AnalyticSampler final : public Sampler {
  public:
    explicit AnalyticSampler(std::shared_ptr<const ChiangFiber> fiber) : model_(std::move(fiber)) {}
    explicit AnalyticSampler(std::shared_ptr<const ChiangStrands> strands) : model_(std::move(strands)) {}
    const ShadingModel *model() const override { return model_.get(); }
    const SamplerPoint &at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const override;

  private:
    std::shared_ptr<const ShadingModel> model_;  // a ChiangFiber or ChiangStrands: ChiangPoints
};

/// The analytic sampler of one Chiang point, made in `scratch`: what a point no table fits
/// (Filter Glossy's widened lobes) samples with.
const SamplerPoint &analytic_point(const ChiangPoint &fiber, ScratchBuffer &scratch);

}  // namespace hairis
