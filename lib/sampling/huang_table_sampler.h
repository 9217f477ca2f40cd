// The Huang table (huang_table.h) as a sampler: at a hit it reads the HuangPoint's view in
// Huang's frame, samples ω_i there and rotates it back into the renderer's frame. It ignores
// h and the pixel coverage: near-field hits are sampled with the far-field density (still
// exact, since pdf() is the density sample() draws from). Built for a HuangTabulatedFiber,
// it samples for the points of that model and reuses the view they located in the table.
#pragma once

#include <memory>

#include "core/expected.h"
#include "fiber/huang.h"
#include "sampling/huang_table.h"
#include "sampling/huang_tabulated_fiber.h"
#include "sampling/sampler.h"

namespace hairis {

class HuangTableSampler final : public Sampler {
  public:
    /// Refuses a null fiber or table. The table should have been baked for `fiber` (the
    /// strategy policy checks that); any table is sampled exactly.
    static Expected<HuangTableSampler> create(std::shared_ptr<const HuangFiber> fiber,
                                              std::shared_ptr<const HuangTable> table);
    /// The sampler of a fiber shaded with its baked f: the model's own table.
    static Expected<HuangTableSampler> create(std::shared_ptr<const HuangTabulatedFiber> model);
    const ShadingModel *model() const override {
        return tabulated_ ? static_cast<const ShadingModel *>(tabulated_.get()) : fiber_.get();
    }
    /// `fiber` must be model()'s point at `hit` (a HuangPoint, or a HuangTabulatedPoint).
    const SamplerPoint &at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const override;
    const HuangTable &table() const { return *table_; }

  private:
    HuangTableSampler(std::shared_ptr<const HuangFiber> fiber, std::shared_ptr<const HuangTable> table)
        : fiber_(std::move(fiber)), table_(std::move(table)) {}
    std::shared_ptr<const HuangFiber> fiber_;
    std::shared_ptr<const HuangTable> table_;
    std::shared_ptr<const HuangTabulatedFiber> tabulated_;  // null: points are HuangPoints
};

}  // namespace hairis
