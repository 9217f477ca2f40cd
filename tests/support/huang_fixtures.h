// Test helper: what the Huang tests share, a renderer hit and the options of a small bake.
#pragma once

#include <cmath>

#include "core/math.h"
#include "fiber/fiber.h"
#include "tables/huang_bake.h"

namespace hairis::testing {

/// A renderer hit at θ_o (degrees) whose curve normal puts the major axis at ψ from y.
inline FiberHit huang_hit(double theta_o_deg, double psi) {
    const double t = radians(theta_o_deg);
    FiberHit hit;
    hit.wo = {float(std::sin(t)), 0.0f, float(-std::cos(t))};
    hit.normal = {0.2f, float(std::cos(psi)), float(std::sin(psi))};
    return hit;
}

/// A Huang bake small enough for a unit test (8 θ_o nodes, 3 φ_o nodes, 16 × 24 cells) and fine
/// enough that its cells still resolve the lobes of a roughness-0.3 fiber.
inline HuangBakeOptions small_huang_bake() {
    HuangBakeOptions o;
    o.theta_o_count = 8;
    o.phi_o_count = 3;
    o.theta_i_count = 16;
    o.phi_count = 24;
    return o;
}

}  // namespace hairis::testing
