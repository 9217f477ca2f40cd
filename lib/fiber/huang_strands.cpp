#include "fiber/huang_strands.h"

namespace hairis {

Expected<HuangStrands> HuangStrands::create(const PrincipledHairNode &node, std::shared_ptr<const HuangFiber> fiber) {
    if (!fiber) {
        Expected<HuangParams> params = to_huang_params(node);
        if (!params) return params.error();
        Expected<HuangFiber> made = HuangFiber::create(params.value());
        if (!made) return made.error();
        fiber = std::make_shared<const HuangFiber>(std::move(made).value());
    }
    HuangStrands strands;
    strands.node_ = node;
    strands.fiber_ = std::move(fiber);
    return strands;
}

const HuangFiber &HuangStrands::fiber_at(const HairInputValues *inputs, ScratchBuffer &scratch,
                                         float blur_roughness) const {
    const HuangFiber &own = inputs_fiber(inputs, scratch);
    // Cycles' bsdf_hair_huang_blur: the closure's roughness raised to the blur's.
    if (!(double(blur_roughness) > own.roughness())) return own;
    HuangParams params = own.params();
    params.roughness = blur_roughness;
    Expected<HuangFiber> wide = HuangFiber::create(params);
    if (!wide) return own;
    return scratch.make_polymorphic<HuangFiber>(std::move(wide).value());
}

const HuangFiber &HuangStrands::inputs_fiber(const HairInputValues *inputs, ScratchBuffer &scratch) const {
    if (!inputs || inputs->given == 0) return *fiber_;
    const Expected<HuangParams> params = to_huang_params(with_inputs(node_, *inputs));
    if (!params) return *fiber_;
    Expected<HuangFiber> strand = HuangFiber::create(params.value());
    if (!strand) return *fiber_;
    return scratch.make_polymorphic<HuangFiber>(std::move(strand).value());
}

bool HuangStrands::reads_input(HairInput input) const {
    if (input == HairInput::RadialRoughness || input == HairInput::Coat) return false;
    return reads(node_.parametrization, input);
}

}  // namespace hairis
