// Uniform directions over the sphere: pdf 1/(4π).
#pragma once

#include "sampling/sampler.h"

namespace hairis {

class UniformSampler final : public Sampler {
  public:
    const SamplerPoint &at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const override;
};

}  // namespace hairis
