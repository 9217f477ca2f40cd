// The expectation of Cycles' Huang eval, baked beside the Huang sampling table
// (huang_table.h) so that a renderer shades Huang hair with Cycles' mean f and no noise.
//
// What is stored. f·|cos θ_i| of the lobes Cycles evaluates stochastically (TT, TRT and
// TRRT+; R is deterministic and stays analytic, HuangPoint::f_reflection), RGB, at one point
// per cell of the sampling table: the midpoint in sin θ_i and in φ = φ_i − φ_o of cell (i, j)
// of θ_o node r and φ_o node q, in the sampling table's frame and fold.
//
// Interpolation. A value is a point sample of a smooth function, so the grid is read with
// cubic (Catmull-Rom) weights where its neighbours allow: bicubic in (sin θ_i, φ) within a
// slice (φ periodic; f·|cos θ_i| is 0 at the poles, which close the θ_i axis, linearly next to
// them), cubic across φ_o nodes (continued beyond the fold's edges by mirror images), and
// linear across θ_o nodes through the sampling table's warp (the lobes follow the specular
// cone θ_i = −θ_o, so slices are read at aligned θ_i, as the sampler reads them). Linear
// reading would blur the lobes between points, which the cubic mostly avoids at the same size.
// Between points the result is still an interpolation of the expectation, not the
// expectation: its error is a bias, measured against HuangExpectation in the tests.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "core/expected.h"
#include "core/math.h"
#include "sampling/huang_table.h"

namespace hairis {

class HuangFTable {
  public:
    /// The f part of `set` (HuangTableSet::f); refuses a set that is invalid or has none.
    static Expected<HuangFTable> create(const HuangTableSet &set);

    /// f·|cos θ_i| of TT, TRT and TRRT+ at ω_i (Huang's frame) for the view `q` was located
    /// for (by the HuangTable of the same set).
    Rgb f_cos(const HuangTableQuery &q, Vec3 wi) const;
    /// The stored value of φ_o node q, θ_o node r, cell (i, j).
    Rgb value(int q, int r, int i, int j) const;
    /// sin θ_i of the points of the θ_i cells.
    const std::vector<double> &sin_theta_points() const { return sin_points_; }
    std::size_t memory_bytes() const { return values_.size() * sizeof(float) + sin_points_.size() * sizeof(double); }

  private:
    // Four neighbouring points of one axis, from index `first`, and their weights.
    struct Stencil {
        int first;
        std::array<float, 4> w;
    };
    HuangFTable() = default;
    Stencil theta_i_stencil(double sin_theta) const;  // rows −1 and theta_i_count are the poles
    Stencil phi_stencil(double phi) const;            // columns wrap around
    // Bicubic in (sin θ_i, φ) within slice (q, r).
    Rgb slice(int q, int r, const Stencil &rows, const Stencil &columns) const;

    int theta_o_count_ = 0, theta_i_count_ = 0, phi_count_ = 0;
    std::vector<double> sin_points_;  // the θ_i cells' points
    std::vector<float> phi_o_nodes_;
    std::vector<float> values_;
};

/// The sin θ_i of the points of `theta_i_count` equal θ_i cells over [−π/2, π/2]: the midpoint
/// of each cell's sin θ_i range (where the bake evaluates f).
std::vector<double> huang_sin_theta_points(int theta_i_count);

}  // namespace hairis
