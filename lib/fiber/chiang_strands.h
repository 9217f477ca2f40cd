// A hair material's Chiang fiber whose node inputs vary from strand to strand and along a
// strand: Hair Info, Cycles' per-strand random number or any attribute feeding the Principled
// Hair BSDF's inputs, given per curve or per point and interpolated at the hit (scene.h).
#pragma once

#include <memory>

#include "core/expected.h"
#include "core/scratch.h"
#include "fiber/chiang.h"
#include "fiber/fiber_point.h"
#include "fiber/hair_inputs.h"
#include "fiber/principled_hair.h"

namespace hairis {

/// At a hit that carries HairInputValues (FiberHit::inputs) the node with those inputs, mapped
/// as Cycles maps a node (to_chiang_params), as ChiangLobes made in the scratch buffer; at a
/// hit without, the node's own fiber. Every point it prepares is a ChiangPoint, so a sampler
/// built for it (analytic or near-field table) reads the strand's own point.
class ChiangStrands final : public ShadingModel, public StrandInputReader {
  public:
    /// The node's own fiber must be valid (to_chiang_params and ChiangFiber::create's errors).
    static Expected<ChiangStrands> create(const PrincipledHairNode &node);

    const FiberPoint &prepare(const FiberHit &hit, ScratchBuffer &scratch) const override {
        return point(hit, scratch);
    }
    /// The fiber at `hit`, with the hit's inputs when it has some, widened by its Filter Glossy
    /// blur (FiberHit::blur_roughness) where that raises a roughness.
    const ChiangPoint &point(const FiberHit &hit, ScratchBuffer &scratch) const;
    /// The constants for `inputs`: the node's own fiber's for null (or no input given), else
    /// made in `scratch`. Inputs outside their ranges (check_hair_input) are never handed to a
    /// shading point (the scene refuses them); should one be, the node's own values are used.
    const ChiangLobes &lobes(const HairInputValues *inputs, ScratchBuffer &scratch) const;
    /// The closure parameters for `inputs`, refused as to_chiang_params refuses them.
    Expected<ChiangParams> params(const HairInputValues &inputs) const;

    /// The inputs the node's parametrization reads (reads() in hair_inputs.h).
    bool reads_input(HairInput input) const override { return reads(node_.parametrization, input); }
    const StrandInputReader *strand_inputs() const override { return this; }
    /// The node with its own (unlinked) values.
    const PrincipledHairNode &node() const { return node_; }
    /// The node's own fiber: what the TABLE strategy's tables are baked for.
    const std::shared_ptr<const ChiangFiber> &fiber() const { return fiber_; }

  private:
    ChiangStrands() = default;
    PrincipledHairNode node_;
    std::shared_ptr<const ChiangFiber> fiber_;
};

}  // namespace hairis
