#include "sampling/analytic_sampler.h"

namespace hairis {

namespace {

class AnalyticPoint final : public SamplerPoint {
  public:
    explicit AnalyticPoint(const ChiangPoint &fiber) : fiber_(&fiber) {}
    std::optional<DirectionSample> sample(float u0, float u1, float u2) const override {
        return fiber_->sample(u0, u1, u2);
    }
    float pdf(Vec3 wi) const override { return fiber_->pdf(wi); }
    // `fiber` is fiber_ (HairBsdf pairs a sampler point with its own model's point).
    Rgb f_and_pdf(Vec3 wi, const FiberPoint *, float &pdf) const override {
        return fiber_->f_and_pdf(wi, pdf);
    }
    std::optional<DirectionSample> sample_with_f(float u0, float u1, float u2, const FiberPoint *,
                                                 Rgb &f) const override {
        return fiber_->sample_with_f(u0, u1, u2, f);
    }

  private:
    const ChiangPoint *fiber_;
};

}  // namespace

const SamplerPoint &AnalyticSampler::at(const FiberHit &, const FiberPoint *fiber, ScratchBuffer &scratch) const {
    // model() is a ChiangFiber or ChiangStrands, so `fiber` is one of its ChiangPoints.
    return analytic_point(static_cast<const ChiangPoint &>(*fiber), scratch);
}

const SamplerPoint &analytic_point(const ChiangPoint &fiber, ScratchBuffer &scratch) {
    return scratch.make<AnalyticPoint>(fiber);
}

}  // namespace hairis
