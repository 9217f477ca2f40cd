#include "sampling/mixture_sampler.h"

#include <cmath>

namespace hairis {

namespace {

// w = 0 or 1 never prepares or evaluates the component without weight.
class MixturePoint final : public SamplerPoint {
  public:
    MixturePoint(const SamplerPoint *a, const SamplerPoint *b, float w) : a_(a), b_(b), w_(w) {}

    std::optional<DirectionSample> sample(float u0, float u1, float u2) const override {
        const float u = u2 > 0.0f ? (u2 < kOneMinusEpsilon ? u2 : kOneMinusEpsilon) : 0.0f;
        const bool from_b = u < w_;
        const float rest = from_b ? u / w_ : (u - w_) / (1.0f - w_);
        std::optional<DirectionSample> s = (from_b ? b_ : a_)->sample(u0, u1, rest < kOneMinusEpsilon ? rest : kOneMinusEpsilon);
        if (!s) return std::nullopt;
        const float other = from_b ? (w_ < 1.0f ? a_->pdf(s->wi) : 0.0f) : (w_ > 0.0f ? b_->pdf(s->wi) : 0.0f);
        s->pdf = from_b ? (1.0f - w_) * other + w_ * s->pdf : (1.0f - w_) * s->pdf + w_ * other;
        if (!(s->pdf > 0.0f) || !std::isfinite(s->pdf)) return std::nullopt;
        return s;
    }
    float pdf(Vec3 wi) const override {
        return (w_ < 1.0f ? (1.0f - w_) * a_->pdf(wi) : 0.0f) + (w_ > 0.0f ? w_ * b_->pdf(wi) : 0.0f);
    }

  private:
    const SamplerPoint *a_, *b_;
    float w_;
};

}  // namespace

Expected<MixtureSampler> MixtureSampler::create(std::shared_ptr<const Sampler> a, std::shared_ptr<const Sampler> b,
                                                float weight_b) {
    if (!a || !b) return Error{"mixture: both components must be given"};
    if (Status s = check::in_range("multiple_weight", weight_b, 0.0, 1.0)) return *s;
    if (a->model() && b->model() && a->model() != b->model())
        return Error{"mixture: the components were built for different fibers"};
    MixtureSampler m;
    m.a_ = std::move(a);
    m.b_ = std::move(b);
    m.w_ = weight_b;
    return m;
}

const SamplerPoint &MixtureSampler::at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const {
    const SamplerPoint *a = w_ < 1.0f ? &a_->at(hit, fiber, scratch) : nullptr;
    const SamplerPoint *b = w_ > 0.0f ? &b_->at(hit, fiber, scratch) : nullptr;
    return scratch.make<MixturePoint>(a, b, w_);
}

}  // namespace hairis
