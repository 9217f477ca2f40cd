#include "sampling/huang_tabulated_fiber.h"

#include <algorithm>
#include <string>

#include "sampling/table_set.h"

namespace hairis {

namespace {

// Whether a strand differs from the node in its absorption only: Cycles draws the microfacet
// chains from the roughness, IOR, offset and aspect ratio, and the lobe multipliers scale
// them (HuangPoint::f_estimate_difference reads only the other fiber's absorption).
bool absorption_only(const HuangFiber &a, const HuangFiber &b) {
    return a.roughness() == b.roughness() && a.ior() == b.ior() && a.tilt() == b.tilt() &&
           a.aspect_ratio() == b.aspect_ratio() && a.m_r() == b.m_r() && a.m_tt() == b.m_tt() &&
           a.m_trt() == b.m_trt();
}

}  // namespace

HuangTabulatedPoint::HuangTabulatedPoint(const HuangTabulatedFiber &model, const FiberHit &hit,
                                         const HuangFiber *strand)
    : FiberPoint(hit), point_(strand ? *strand : model.fiber(), hit),
      query_(model.table().locate(point_.to_huang(hit.wo))), f_(&model.f_table()), lcg_(point_.lcg()) {
    if (!strand || strand == &model.fiber()) return;
    const bool absorption_differs = absorption_only(*strand, model.fiber());
    const HuangAbsorptionTable *part = model.absorption_table();
    if (absorption_differs && part && part->reads(strand->sigma(), model.fiber().sigma())) {
        absorption_ = part;
        node_fiber_ = &model.fiber();
    } else if (model.strand_shading() == StrandShading::ControlVariate && absorption_differs) {
        node_ = &model.fiber();
    } else {
        own_eval_ = true;
    }
}

Rgb HuangTabulatedPoint::f(Vec3 wi) const {
    if (point_.near_field() || own_eval_) return point_.f_estimate(wi, lcg_);
    const HuangGridRead read = f_->grid().read(query_, point_.to_huang(wi));
    const Rgb tabulated = f_->f_cos(read);
    if (absorption_) {
        // The node's baked f moved to the strand's absorption; never below 0.
        const Rgb moved = tabulated + absorption_->difference(read, point_.fiber().sigma(), node_fiber_->sigma());
        return point_.f_reflection(wi) + Rgb(std::max(moved.r, 0.0f), std::max(moved.g, 0.0f), std::max(moved.b, 0.0f));
    }
    if (!node_) return point_.f_reflection(wi) + tabulated;
    // The control variate: the strand's eval and the node's along the same chains, in one
    // pass; R cancels in the difference and is the same for both.
    return point_.f_estimate_difference(wi, lcg_, *node_) + point_.f_reflection(wi) + tabulated;
}

const FiberPoint &HuangTabulatedFiber::prepare(const FiberHit &hit, ScratchBuffer &scratch) const {
    const HuangFiber *strand = strands_ ? &strands_->fiber_at(hit.inputs, scratch, hit.blur_roughness) : nullptr;
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
