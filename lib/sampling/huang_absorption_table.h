// The absorption part of a Huang table (huang_table.h): the baked f of TT, TRT and TRRT+ for
// strands whose absorption differs from the fiber's (Random Color, Hair Info driving Melanin or
// Color), so that a renderer shades them with Cycles' mean f and no noise, as it shades the
// fiber itself with the f part (huang_f_table.h).
//
// One function serves every channel. Cycles' Huang eval colours each microfacet chain by
// exp(−σ·length) (TRRT+ by a series in it) and nothing else on a chain depends on σ, so one
// channel of f·|cos θ_i| is a function G(σ) of that channel's absorption alone, the same for
// R, G and B. The bake evaluates G at K nodes σ_k at the f part's points, colouring the f
// part's own chains at each node (HuangFiber::expectation with absorptions).
//
// Interpolation in σ. G is a mixture of exp(−σ·ℓ) over chain lengths ℓ, so log G is smooth
// and convex. The nodes are even in log(σ + 1/4), and log G is read with Catmull-Rom weights in
// that variable (linearly in G where a neighbour is 0), log-linearly and never rising beyond
// the last node. Just above σ = 0 Cycles' TRRT+ series drops steeply (its pole lies just below
// 0 for a lossless fiber under total internal reflection) over a range no grid of nodes
// follows: below the first node reads() says no, and such strands keep Cycles' eval.
//
// A strand reads the fiber's f part plus G(σ_strand) − G(σ_fiber) per channel: the errors of
// the two reads cancel for strands near the fiber's absorption, and a strand of the fiber's
// absorption gets the f part exactly.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "core/expected.h"
#include "core/math.h"
#include "sampling/huang_f_table.h"
#include "sampling/huang_table.h"

namespace hairis {

class HuangAbsorptionTable {
  public:
    /// The absorption part of `set`; refuses a set that is invalid or has none.
    static Expected<HuangAbsorptionTable> create(const HuangTableSet &set);

    /// Whether difference() holds for these absorptions: in each channel they are equal or
    /// both at or above the first node.
    bool reads(const std::array<double, 3> &strand, const std::array<double, 3> &fiber) const;
    /// G(σ) per channel: f·|cos θ_i| of TT, TRT and TRRT+ of a fiber of absorption `sigma` (and
    /// the set's other parameters) at ω_i for the view `q` was located for; a σ below the first
    /// node reads as the first node.
    Rgb f_cos(const HuangTableQuery &q, Vec3 wi, const std::array<double, 3> &sigma) const;
    /// G(strand) − G(fiber) per channel, 0 where the two are equal.
    Rgb difference(const HuangTableQuery &q, Vec3 wi, const std::array<double, 3> &strand,
                   const std::array<double, 3> &fiber) const {
        return difference(grid_.read(q, wi), strand, fiber);
    }
    /// The same from the grid's read (which the f part of the same set shares).
    Rgb difference(const HuangGridRead &read, const std::array<double, 3> &strand,
                   const std::array<double, 3> &fiber) const;
    const std::vector<float> &nodes() const { return nodes_; }
    std::size_t memory_bytes() const {
        return values_.size() * sizeof(float) + axis_.size() * sizeof(double) + grid_.memory_bytes();
    }

  private:
    // The nodes [first, last] that interpolate() reads for some absorptions.
    struct Nodes {
        int first, last;
    };
    HuangAbsorptionTable() = default;
    // An absorption on the node axis: x = log(σ + shift), σ raised to the first node, and the
    // segment [j, j + 1] that holds x, or the last one.
    struct Place {
        double x;
        int j;
    };
    Place place(double sigma) const;
    // The nodes interpolate() reads at `p`, joined with `nodes`.
    Nodes nodes_read(Place p, Nodes nodes) const;
    // The node values of G at a read in `nodes`, each clamped at 0; the others are not set.
    void gather(const HuangGridRead &read, Nodes nodes, float *g) const;
    // G at `p` from its node values (those of nodes_read(p)).
    double interpolate(const float *g, Place p) const;

    HuangFGrid grid_;
    std::vector<float> nodes_;
    std::vector<double> axis_;  // log(σ_k + kHuangAbsorptionShift)
    std::vector<float> values_;
};

/// The shift of the interpolation variable log(σ + shift).
inline constexpr double kHuangAbsorptionShift = 0.25;

/// `count` absorption nodes even in log(σ + kHuangAbsorptionShift) from `first` to `last`.
std::vector<float> huang_absorption_nodes(int count = 12, double first = 1.0 / 64.0, double last = 12.0);

}  // namespace hairis
