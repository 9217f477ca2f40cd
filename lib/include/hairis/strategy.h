// Direction-sampling strategies for a hair shading point: every sample comes with the
// density it was actually drawn from.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "hairis/math.h"

namespace hairis {

/// The strategies hairis offers (the add-on's `strategy` setting and the C API's enum).
enum class StrategyKind { Uniform = 0, Analytic = 1, Gaussian = 2, Table = 3 };

/// "uniform", "analytic", "gaussian" or "table".
const char *strategy_name(StrategyKind kind);

/// A sampled incident direction and its density.
struct DirectionSample {
    Vec3 wi;        ///< unit direction towards the light, fiber frame (frame.h)
    float pdf = 0;  ///< solid-angle density of wi, > 0
};

/// Samples incident directions ω_i for a view direction ω_o at fiber offset h.
/// Directions are unit vectors in the fiber frame of frame.h. pdf(sample(u).wi) equals
/// sample(u).pdf to float rounding, and pdf integrates to 1 over the sphere.
class DirectionSampler {
  public:
    virtual ~DirectionSampler() = default;

    /// Which strategy this is.
    virtual StrategyKind kind() const = 0;

    /// Draws ω_i from three uniform numbers in [0, 1); nullopt when no direction is produced.
    virtual std::optional<DirectionSample> sample(Vec3 wo, float h, float u0, float u1,
                                                  float u2) const = 0;

    /// Solid-angle density with which sample() produces ω_i.
    virtual float pdf(Vec3 wi, Vec3 wo, float h) const = 0;
};

}  // namespace hairis
