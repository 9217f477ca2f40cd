#include "sampling/huang_table_sampler.h"

namespace hairis {

namespace {

class HuangTablePoint final : public SamplerPoint {
  public:
    HuangTablePoint(const HuangTable &table, const HuangPoint &fiber)
        : table_(&table), fiber_(&fiber), query_(table.locate(fiber.to_huang(fiber.hit().wo))) {}

    std::optional<DirectionSample> sample(float u0, float u1, float u2) const override {
        std::optional<DirectionSample> s = table_->sample(query_, u0, u1, u2);
        if (s) s->wi = fiber_->from_huang(s->wi);
        return s;
    }
    float pdf(Vec3 wi) const override { return table_->pdf(query_, fiber_->to_huang(wi)); }

  private:
    const HuangTable *table_;
    const HuangPoint *fiber_;
    HuangTableQuery query_;
};

}  // namespace

Expected<HuangTableSampler> HuangTableSampler::create(std::shared_ptr<const HuangFiber> fiber,
                                                      std::shared_ptr<const HuangTable> table) {
    if (!fiber) return Error{"Huang table sampler: no Huang fiber was given"};
    if (!table) return Error{"Huang table sampler: no Huang table was given"};
    return HuangTableSampler(std::move(fiber), std::move(table));
}

const SamplerPoint &HuangTableSampler::at(const FiberHit &, const FiberPoint *fiber, ScratchBuffer &scratch) const {
    // model() is the fiber, so `fiber` is one of its HuangPoints.
    return scratch.make<HuangTablePoint>(*table_, static_cast<const HuangPoint &>(*fiber));
}

}  // namespace hairis
