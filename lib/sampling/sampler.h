// Direction samplers for a hair shading point. A Sampler belongs to a material and is shared
// by every thread; at a hit it prepares a SamplerPoint (what depends on ω_o and h, computed
// once) whose sample() and pdf() agree: pdf(sample(u).wi) is sample(u).pdf to float rounding,
// and pdf integrates to 1 over the sphere.
#pragma once

#include <optional>

#include "core/math.h"
#include "core/scratch.h"
#include "fiber/fiber_point.h"

namespace hairis {

/// A sampler prepared at one hit. Trivially destructible (lives in a ScratchBuffer).
class SamplerPoint {
  public:
    /// Draws ω_i from three uniform numbers in [0, 1); nullopt when no direction is produced.
    virtual std::optional<DirectionSample> sample(float u0, float u1, float u2) const = 0;
    /// The solid-angle density with which sample() produces ω_i.
    virtual float pdf(Vec3 wi) const = 0;

    /// `fiber`'s f·|cos θ_i| (zero when null) and pdf(wi), at one ω_i. A sampler that shares
    /// work with its model's f overrides this; the values are the same.
    virtual Rgb f_and_pdf(Vec3 wi, const FiberPoint *fiber, float &pdf) const {
        pdf = this->pdf(wi);
        return fiber ? fiber->f(wi) : Rgb{};
    }
    /// sample() and `fiber`'s f·|cos θ_i| at the drawn direction (zero when null).
    virtual std::optional<DirectionSample> sample_with_f(float u0, float u1, float u2,
                                                         const FiberPoint *fiber, Rgb &f) const {
        std::optional<DirectionSample> s = sample(u0, u1, u2);
        if (s) f = fiber ? fiber->f(s->wi) : Rgb{};
        return s;
    }

  protected:
    SamplerPoint() = default;
    SamplerPoint(const SamplerPoint &) = default;
    SamplerPoint &operator=(const SamplerPoint &) = default;
    ~SamplerPoint() = default;
};

/// A direction-sampling strategy for one material: immutable, thread-safe.
class Sampler {
  public:
    virtual ~Sampler() = default;

    /// The fiber model whose prepared points at() reads, or null when it reads none. A sampler
    /// built for a model is only ever given points of that model (hair_bsdf.h checks it).
    virtual const ShadingModel *model() const { return nullptr; }

    /// The sampler at `hit`, made in `scratch`; `fiber` is model()'s point at the same hit
    /// (null when model() is null).
    virtual const SamplerPoint &at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const = 0;
};

}  // namespace hairis
