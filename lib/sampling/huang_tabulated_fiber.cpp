#include "sampling/huang_tabulated_fiber.h"

#include <string>

#include "sampling/table_set.h"

namespace hairis {

namespace {

// Whether a strand's microfacet chains are the node's: Cycles draws them from the roughness,
// IOR, offset and aspect ratio only (absorption and the lobe multipliers scale them).
bool same_chains(const HuangFiber &a, const HuangFiber &b) {
    return a.roughness() == b.roughness() && a.ior() == b.ior() && a.tilt() == b.tilt() &&
           a.aspect_ratio() == b.aspect_ratio();
}

}  // namespace

HuangTabulatedPoint::HuangTabulatedPoint(const HuangTabulatedFiber &model, const FiberHit &hit,
                                         const HuangFiber *strand)
    : FiberPoint(hit), point_(strand ? *strand : model.fiber(), hit),
      query_(model.table().locate(point_.to_huang(hit.wo))), f_(&model.f_table()), lcg_(point_.lcg()) {
    if (!strand || strand == &model.fiber()) return;
    if (model.strand_shading() == StrandShading::ControlVariate && same_chains(*strand, model.fiber()))
        node_.emplace(model.fiber(), hit);
    else
        own_eval_ = true;
}

Rgb HuangTabulatedPoint::f(Vec3 wi) const {
    if (point_.near_field() || own_eval_) return point_.f_estimate(wi, lcg_);
    const Rgb tabulated = f_->f_cos(query_, point_.to_huang(wi));
    if (!node_) return point_.f_reflection(wi) + tabulated;
    // The control variate: both evals replay one stream of the LCG, so they draw the same
    // chains; R cancels in the difference and is the strand's own in its eval.
    CyclesLcg node_lcg = lcg_;
    const Rgb strand = point_.f_estimate(wi, lcg_);
    return strand - node_->f_estimate(wi, node_lcg) + node_->f_reflection(wi) + tabulated;
}

const FiberPoint &HuangTabulatedFiber::prepare(const FiberHit &hit, ScratchBuffer &scratch) const {
    const HuangFiber *strand = strands_ ? &strands_->fiber_at(hit.inputs, scratch) : nullptr;
    return scratch.make<HuangTabulatedPoint>(*this, hit, strand);
}

Expected<HuangTabulatedFiber> HuangTabulatedFiber::create(std::shared_ptr<const HuangFiber> fiber,
                                                          std::shared_ptr<const HuangSamplingTable> table,
                                                          std::shared_ptr<const HuangStrands> strands,
                                                          StrandShading strand_shading) {
    if (!fiber) return Error{"tabulated Huang fiber: no Huang fiber was given"};
    if (!table || !table->table) return Error{"tabulated Huang fiber: no Huang table was given"};
    if (!table->f)
        return Error{"tabulated Huang fiber: the Huang table has no baked f; bake the table again", ErrorKind::InvalidTable};
    const std::string parameters = canonical_parameters(huang_parameters(fiber->params()));
    if (table->parameters != parameters)
        return Error{"tabulated Huang fiber: the table was baked for \"" + table->parameters + "\", not for \"" +
                         parameters + "\"; bake a table for this fiber",
                     ErrorKind::InvalidTable};
    if (strands && strands->fiber() != fiber)
        return Error{"tabulated Huang fiber: the strands' node fiber is not the tabulated fiber"};
    return HuangTabulatedFiber(std::move(fiber), std::move(table), std::move(strands), strand_shading);
}

}  // namespace hairis
