#include "sampling/huang_table_sampler.h"

namespace hairis {

namespace {

class HuangTablePoint final : public SamplerPoint {
  public:
    HuangTablePoint(const HuangTable &table, const HuangPoint &fiber)
        : table_(&table), fiber_(&fiber), query_(table.locate(fiber.to_huang(fiber.hit().wo))) {}
    HuangTablePoint(const HuangTable &table, const HuangTabulatedPoint &point)
        : table_(&table), fiber_(&point.huang()), query_(point.query()) {}

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

Expected<HuangTableSampler> HuangTableSampler::create(std::shared_ptr<const HuangTabulatedFiber> model) {
    if (!model) return Error{"Huang table sampler: no tabulated Huang fiber was given"};
    // The model holds the fiber and the table by shared_ptr; the sampler shares the model.
    HuangTableSampler s(nullptr, nullptr);
    s.table_ = std::shared_ptr<const HuangTable>(model, &model->table());
    s.tabulated_ = std::move(model);
    return s;
}

const SamplerPoint &HuangTableSampler::at(const FiberHit &, const FiberPoint *fiber, ScratchBuffer &scratch) const {
    // model() made `fiber`: a HuangTabulatedPoint for a tabulated model, else a HuangPoint.
    if (tabulated_) return scratch.make<HuangTablePoint>(*table_, static_cast<const HuangTabulatedPoint &>(*fiber));
    return scratch.make<HuangTablePoint>(*table_, static_cast<const HuangPoint &>(*fiber));
}

}  // namespace hairis
