#include "fiber/chiang_strands.h"

namespace hairis {

Expected<ChiangStrands> ChiangStrands::create(const PrincipledHairNode &node) {
    Expected<ChiangParams> params = to_chiang_params(node);
    if (!params) return params.error();
    Expected<ChiangFiber> fiber = ChiangFiber::create(params.value());
    if (!fiber) return fiber.error();
    ChiangStrands strands;
    strands.node_ = node;
    strands.fiber_ = std::make_shared<const ChiangFiber>(std::move(fiber).value());
    return strands;
}

Expected<ChiangParams> ChiangStrands::params(const HairInputValues &inputs) const {
    return to_chiang_params(with_inputs(node_, inputs));
}

const ChiangLobes &ChiangStrands::lobes(const HairInputValues *inputs, ScratchBuffer &scratch) const {
    if (!inputs || inputs->given == 0) return fiber_->lobes();
    const Expected<ChiangParams> p = params(*inputs);
    if (!p) return fiber_->lobes();
    return scratch.make<ChiangLobes>(ChiangLobes::derive(fiber_->lobes(), p.value()));
}

const ChiangPoint &ChiangStrands::point(const FiberHit &hit, ScratchBuffer &scratch) const {
    const ChiangLobes &own = lobes(hit.inputs, scratch);
    if (hit.blur_roughness > 0.0f)
        if (std::optional<ChiangLobes> wide = own.blurred(hit.blur_roughness))
            return scratch.make<ChiangPoint>(scratch.make<ChiangLobes>(*wide), hit, true);
    return scratch.make<ChiangPoint>(own, hit);
}

}  // namespace hairis
