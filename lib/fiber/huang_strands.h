// A hair material's Huang fiber whose node inputs vary from strand to strand and along a
// strand (Hair Info, Cycles' per-strand random number, attributes), as ChiangStrands is for
// Chiang: at a hit with inputs, the node with those inputs mapped as Cycles maps it
// (to_huang_params), made in the scratch buffer; at a hit without, the node's own fiber.
#pragma once

#include <memory>

#include "core/expected.h"
#include "core/scratch.h"
#include "fiber/fiber_point.h"
#include "fiber/hair_inputs.h"
#include "fiber/huang.h"
#include "fiber/principled_hair.h"

namespace hairis {

class HuangStrands final : public ShadingModel, public StrandInputReader {
  public:
    /// `fiber` must be the node's own fiber (to_huang_params(node)); it is made when null.
    /// Refuses what to_huang_params and HuangFiber::create refuse.
    static Expected<HuangStrands> create(const PrincipledHairNode &node,
                                         std::shared_ptr<const HuangFiber> fiber = nullptr);

    /// The strand's HuangPoint: Cycles' one-sample eval of the strand's own fiber.
    const FiberPoint &prepare(const FiberHit &hit, ScratchBuffer &scratch) const override {
        return scratch.make<HuangPoint>(fiber_at(hit.inputs, scratch, hit.blur_roughness), hit);
    }
    /// The fiber of a hit with `inputs`: the node's own for null (or no input given), else
    /// made in `scratch`; its roughness raised to `blur_roughness` (Filter Glossy,
    /// FiberHit::blur_roughness) where below it. Inputs the scene refused never reach here;
    /// should one, the node's own fiber is used.
    const HuangFiber &fiber_at(const HairInputValues *inputs, ScratchBuffer &scratch,
                               float blur_roughness = 0) const;

    /// Huang reads what Chiang reads under the node's parametrization but for Radial
    /// Roughness and Coat, which the model does not have.
    bool reads_input(HairInput input) const override;
    const StrandInputReader *strand_inputs() const override { return this; }
    bool reads_orientation() const override { return true; }
    /// The node's own fiber: Cycles' sampler and the tables work from it.
    const HuangFiber *as_huang() const override { return fiber_.get(); }
    const std::shared_ptr<const HuangFiber> &fiber() const { return fiber_; }
    const PrincipledHairNode &node() const { return node_; }

  private:
    HuangStrands() = default;
    const HuangFiber &inputs_fiber(const HairInputValues *inputs, ScratchBuffer &scratch) const;
    PrincipledHairNode node_;
    std::shared_ptr<const HuangFiber> fiber_;
};

}  // namespace hairis
