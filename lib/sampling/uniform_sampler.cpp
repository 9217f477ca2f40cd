#include "sampling/uniform_sampler.h"

#include <cmath>

#include "core/frame.h"

namespace hairis {

namespace {

class UniformPoint final : public SamplerPoint {
  public:
    std::optional<DirectionSample> sample(float u0, float u1, float) const override {
        const float x = off_axis(1.0f - 2.0f * u0);
        const float r = std::sqrt(std::max(0.0f, 1.0f - x * x));
        const float phi = float(kTwoPi) * u1;
        return DirectionSample{{x, r * std::cos(phi), r * std::sin(phi)}, float(kInvFourPi)};
    }
    float pdf(Vec3) const override { return float(kInvFourPi); }
};

}  // namespace

const SamplerPoint &UniformSampler::at(const FiberHit &, const FiberPoint *, ScratchBuffer &scratch) const {
    return scratch.make<UniformPoint>();
}

}  // namespace hairis
