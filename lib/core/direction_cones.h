// Unit directions grouped into narrow cones, so that one threshold test, dot(d, l) < c, over
// all of them decides whole cones at once and looks at single directions only near the edge
// of the cap it cuts. Huang's TRT and TRRT+ paths use it for the total internal reflection
// of their exits: most cones of a view lie wholly inside or outside an exit's cap.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/vec3d.h"

namespace hairis {

class DirectionCones {
  public:
    struct Cone {
        std::uint32_t begin = 0, end = 0;       ///< the members are order()[begin, end)
        Vec3d axis{0.0, 0.0, 1.0};              ///< unit
        double cos_radius = 1, sin_radius = 0;  ///< no member is farther from the axis
        bool decidable = true;                  ///< false when a member is not finite
    };
    /// Where a cone's members lie against the test dot(d, l) < c.
    enum class Side { Below, AtOrAbove, Mixed };

    DirectionCones() = default;
    /// Groups unit directions by the cells of a grid of `bands` equal bands of z and
    /// 2·`bands` sectors of longitude about z; an empty cell makes no cone. A direction that
    /// is not finite goes to the first cell, whose cone is then never decided.
    explicit DirectionCones(const std::vector<Vec3d> &directions, int bands = 12);

    const std::vector<Cone> &cones() const { return cones_; }
    /// The input's indices, cone after cone, ascending within a cone.
    const std::vector<std::uint32_t> &order() const { return order_; }

    /// The test dot(d, l) < c prepared once for deciding many cones: |l| and the margin do not
    /// depend on the cone.
    class Threshold {
      public:
        Threshold(Vec3d l, double c);
        /// Below when dot(d, l) < c for every member, AtOrAbove when for none, else Mixed. A
        /// cone is decided only with a margin far above rounding, so a decision never
        /// disagrees with the test computed member by member (l need not be exactly unit).
        Side side(const Cone &cone) const;

      private:
        Vec3d l_;
        double c_ = 0, len_ = 1, margin_ = 0;
        bool usable_ = false;  // |l| positive and finite
    };
    /// Threshold(l, c).side(cone).
    static Side side(const Cone &cone, Vec3d l, double c) { return Threshold(l, c).side(cone); }

  private:
    std::vector<Cone> cones_;
    std::vector<std::uint32_t> order_;
};

inline DirectionCones::Side DirectionCones::Threshold::side(const Cone &cone) const {
    // A member at angle ≤ ρ from the axis, the axis at δ from l: the member's angle to l is in
    // [max(0, δ − ρ), min(π, δ + ρ)], and dot(d, l) = |l| cos of it.
    if (!cone.decidable || !usable_) return Side::Mixed;
    const double cos_delta = std::clamp(dot(cone.axis, l_) / len_, -1.0, 1.0);
    const double sin_delta = std::sqrt(1.0 - cos_delta * cos_delta);
    const double highest = cos_delta >= cone.cos_radius ? 1.0
                                                        : cos_delta * cone.cos_radius + sin_delta * cone.sin_radius;
    const double lowest = cos_delta <= -cone.cos_radius ? -1.0
                                                        : cos_delta * cone.cos_radius - sin_delta * cone.sin_radius;
    if (len_ * highest < c_ - margin_) return Side::Below;
    if (len_ * lowest >= c_ + margin_) return Side::AtOrAbove;
    return Side::Mixed;
}

}  // namespace hairis
