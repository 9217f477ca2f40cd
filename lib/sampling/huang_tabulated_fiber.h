// Huang hair as a renderer shades it from its baked table: Cycles' expectation of f without
// Cycles' noise. R is Cycles' own (deterministic: a Simpson rule over h); TT, TRT and TRRT+,
// which Cycles estimates with one random microfacet chain per node, are read from the baked
// expectation (huang_f_table.h). Near-field hits (camera rays on hair wider than the pixel)
// keep Cycles' one-sample eval: the table holds the far field only.
//
// A strand whose inputs differ from the node's (HuangStrands) is shaded with its own f. When
// only its absorption differs and the table has an absorption part that reads it
// (huang_absorption_table.h), f = the baked f + the part's difference between the strand's
// absorption and the node's: no noise, whatever StrandShading says. Without that part the
// table is a control variate: f = the baked expectation + (the strand's Cycles eval − the
// node's), both evals following the same microfacet chains in one pass, so the correction has
// mean (strand − node) and little noise, at about one eval's cost. A strand of another
// roughness, IOR or offset draws other chains; it is shaded with its own Cycles eval. A
// renderer can ask for the strand's own eval wherever the absorption part does not serve
// (StrandShading::OwnEval).
#pragma once

#include <memory>

#include "core/expected.h"
#include "fiber/huang.h"
#include "fiber/huang_strands.h"
#include "sampling/huang_absorption_table.h"
#include "sampling/huang_f_table.h"
#include "sampling/huang_table.h"

namespace hairis {

class HuangTabulatedFiber;

/// How a strand whose inputs differ from the node's is shaded where the table's absorption
/// part does not serve it.
enum class StrandShading {
    ControlVariate,  ///< the baked f corrected where only the absorption differs
    OwnEval,         ///< the strand's own Cycles eval (one eval, noisier)
};

/// The tabulated fiber at one hit; also hands the table's located view to the table sampler.
class HuangTabulatedPoint final : public FiberPoint {
  public:
    /// `strand`: the hit's own fiber when its inputs differ from the node's, else null.
    HuangTabulatedPoint(const HuangTabulatedFiber &model, const FiberHit &hit, const HuangFiber *strand = nullptr);
    Rgb f(Vec3 wi) const override;
    bool transparent() const override { return point_.transparent(); }
    Rgb albedo() const override { return point_.albedo(); }
    bool tangent_is_denoising_normal() const override { return true; }
    const HuangPoint *huang_point() const override { return &point_; }
    /// Cycles' closure at the hit (its frame, R, the near-field eval).
    const HuangPoint &huang() const { return point_; }
    /// The view located in the table (HuangTable::locate of ω_o in Huang's frame).
    const HuangTableQuery &query() const { return query_; }

  private:
    HuangPoint point_;  // the strand's own fiber at the hit
    HuangTableQuery query_;
    const HuangFTable *f_;
    // A strand that differs from the node in absorption only, read from the table's
    // absorption part; and the two absorptions it reads.
    const HuangAbsorptionTable *absorption_ = nullptr;
    const HuangFiber *node_fiber_ = nullptr;
    // A strand that differs from the node in absorption only: the node's fiber, whose eval
    // along the strand's chains is the control variate.
    const HuangFiber *node_ = nullptr;
    bool own_eval_ = false;  // a strand of another geometry: its Cycles eval alone
    mutable CyclesLcg lcg_;
};

/// A Huang fiber shaded with its baked f (HuangSamplingTable::f).
class HuangTabulatedFiber final : public ShadingModel {
  public:
    /// Refuses a null fiber, a table without its f part, a table baked for other parameters
    /// and strands of another fiber. `strands` (optional): the material's per-strand inputs.
    static Expected<HuangTabulatedFiber> create(std::shared_ptr<const HuangFiber> fiber,
                                                std::shared_ptr<const HuangSamplingTable> table,
                                                std::shared_ptr<const HuangStrands> strands = nullptr,
                                                StrandShading strand_shading = StrandShading::ControlVariate);
    const FiberPoint &prepare(const FiberHit &hit, ScratchBuffer &scratch) const override;
    bool reads_orientation() const override { return true; }
    /// The fiber it tabulates: a renderer that samples Huang with Cycles' own sampler samples
    /// the point's huang_point() and still shades with the point's f.
    const HuangFiber *as_huang() const override { return fiber_.get(); }
    const StrandInputReader *strand_inputs() const override { return strands_.get(); }
    const HuangFiber &fiber() const { return *fiber_; }
    const HuangTable &table() const { return *table_->table; }
    const HuangFTable &f_table() const { return *table_->f; }
    /// The table's absorption part, or null.
    const HuangAbsorptionTable *absorption_table() const { return table_->absorption.get(); }
    StrandShading strand_shading() const { return strand_shading_; }

  private:
    HuangTabulatedFiber(std::shared_ptr<const HuangFiber> fiber, std::shared_ptr<const HuangSamplingTable> table,
                        std::shared_ptr<const HuangStrands> strands, StrandShading strand_shading)
        : fiber_(std::move(fiber)), table_(std::move(table)), strands_(std::move(strands)),
          strand_shading_(strand_shading) {}
    std::shared_ptr<const HuangFiber> fiber_;
    std::shared_ptr<const HuangSamplingTable> table_;
    std::shared_ptr<const HuangStrands> strands_;
    StrandShading strand_shading_;
};

}  // namespace hairis
