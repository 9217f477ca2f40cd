// The baked tables as samplers: the far-field direct table (2D over θ_i and φ per θ_r node)
// and the multiple-scattering table of one n_h (1D over θ_i, uniform in φ).
#pragma once

#include <memory>

#include "core/expected.h"
#include "sampling/sampler.h"
#include "sampling/sampling_table.h"

namespace hairis {

/// The direct table: ignores h (it holds f averaged over h).
class FarTableSampler final : public Sampler {
  public:
    explicit FarTableSampler(std::shared_ptr<const DirectTable> table) : table_(std::move(table)) {}
    const SamplerPoint &at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const override;

  private:
    std::shared_ptr<const DirectTable> table_;
};

/// The multiple-scattering table of n_h strands.
class MultipleTableSampler final : public Sampler {
  public:
    /// Refuses a null table and an n_h it does not hold.
    static Expected<MultipleTableSampler> create(std::shared_ptr<const MultipleTable> table, int n_h);
    const SamplerPoint &at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const override;

  private:
    MultipleTableSampler(std::shared_ptr<const MultipleTable> table, int strand)
        : table_(std::move(table)), strand_(strand) {}
    std::shared_ptr<const MultipleTable> table_;
    int strand_ = 0;
};

}  // namespace hairis
