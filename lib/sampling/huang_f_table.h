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
#include <cstdint>
#include <vector>

#include "core/expected.h"
#include "core/math.h"
#include "sampling/huang_table.h"

namespace hairis {

/// The interpolation weights of one read of a Huang table's cell grid: the cells (indices in
/// HuangTableSet::values' order) and their weights, at most 2 θ_o × 4 φ_o × 4 × 4 of them.
struct HuangGridRead {
    static constexpr int kMaxPoints = 128;
    int count = 0;
    // Only the first `count` entries are set: a read is on every shading call's path.
    std::array<std::uint32_t, kMaxPoints> cell;
    std::array<float, kMaxPoints> weight;
};

/// The grid of points a Huang table's f and absorption parts are baked on, and how a read
/// between them weighs them (the file comment's interpolation).
class HuangFGrid {
  public:
    /// The grid of `set`'s cells (its sizes must be valid).
    explicit HuangFGrid(const HuangTableSet &set);
    HuangFGrid() = default;
    /// The weights of a read at ω_i (Huang's frame) for the view `q` was located for; none
    /// for an ω_i that is not a unit vector.
    HuangGridRead read(const HuangTableQuery &q, Vec3 wi) const;
    /// sin θ_i of the points of the θ_i cells.
    const std::vector<double> &sin_theta_points() const { return sin_points_; }
    std::size_t cell(int q, int r, int i, int j) const {
        return ((std::size_t(q) * std::size_t(theta_o_count_) + std::size_t(r)) * std::size_t(theta_i_count_) +
                std::size_t(i)) * std::size_t(phi_count_) + std::size_t(j);
    }
    std::size_t memory_bytes() const { return sin_points_.size() * sizeof(double) + phi_o_nodes_.size() * sizeof(float); }

  private:
    // Four neighbouring points of one axis, from index `first`, and their weights.
    struct Stencil {
        int first;
        std::array<float, 4> w;
    };
    Stencil theta_i_stencil(double sin_theta) const;  // rows −1 and theta_i_count are the poles
    Stencil phi_stencil(double phi) const;            // columns wrap around
    // Adds slice (q, r)'s bicubic weights in (sin θ_i, φ), times `scale`, to `out`.
    void add_slice(int q, int r, const Stencil &rows, const Stencil &columns, float scale, HuangGridRead &out) const;

    int theta_o_count_ = 0, theta_i_count_ = 0, phi_count_ = 0;
    std::vector<double> sin_points_;  // the θ_i cells' points
    std::vector<float> phi_o_nodes_;
};

class HuangFTable {
  public:
    /// The f part of `set` (HuangTableSet::f); refuses a set that is invalid or has none.
    static Expected<HuangFTable> create(const HuangTableSet &set);

    /// f·|cos θ_i| of TT, TRT and TRRT+ at ω_i (Huang's frame) for the view `q` was located
    /// for (by the HuangTable of the same set).
    Rgb f_cos(const HuangTableQuery &q, Vec3 wi) const { return f_cos(grid_.read(q, wi)); }
    /// The same from the grid's read (which an absorption part of the same set shares).
    Rgb f_cos(const HuangGridRead &read) const;
    /// The stored value of φ_o node q, θ_o node r, cell (i, j).
    Rgb value(int q, int r, int i, int j) const;
    /// sin θ_i of the points of the θ_i cells.
    const std::vector<double> &sin_theta_points() const { return grid_.sin_theta_points(); }
    const HuangFGrid &grid() const { return grid_; }
    std::size_t memory_bytes() const { return values_.size() * sizeof(float) + grid_.memory_bytes(); }

  private:
    HuangFTable() = default;
    HuangFGrid grid_;
    std::vector<float> values_;
};

/// Cubic Hermite weights of the four values at x[0] < x[1] ≤ x < x[2] < x[3], t = (x − x[1]) /
/// (x[2] − x[1]), with the slopes at x[1] and x[2] taken from their neighbours (Catmull-Rom
/// on uneven nodes). It passes through the values and reproduces quadratics.
std::array<float, 4> catmull_rom_weights(const double x[4], double t);

/// The sin θ_i of the points of `theta_i_count` equal θ_i cells over [−π/2, π/2]: the midpoint
/// of each cell's sin θ_i range (where the bake evaluates f).
std::vector<double> huang_sin_theta_points(int theta_i_count);

}  // namespace hairis
