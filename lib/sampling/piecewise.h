// Piecewise-constant densities on equal-width cells, sampled by inverting their CDF.
//
// The CDF is the distribution. Each distribution stores its CDF as floats c_0 = 0 ≤ c_1 ≤ … ≤
// c_n = 1; cell k carries the probability mass c_{k+1} − c_k (computed from the stored floats,
// the same way everywhere), so sample(), pdf() and invert() describe one density exactly —
// they do not each round their own copy of value / integral. The price is that a cell's mass
// may differ from value_k·width / integral by the float rounding of the CDF (relative error
// about 2^-24 / c_k), and a cell with a positive value always keeps at least one float ulp of
// CDF: a positive cell is never silently dropped.
//
// Boundaries: cell k is the half-open interval [edge_k, edge_{k+1}) of floats; the upper end hi
// belongs to the last cell. edge_k is the smallest float that the index computation
// floor((x − lo)·n / (hi − lo)) puts into cell k, so the boundary convention and the index
// arithmetic cannot disagree, and samples are clamped into their cell's floats.
//
// Sampling is O(1) expected: a guide table (the cutpoint method of Chen & Asau 1974) with a
// power-of-two number G ≥ n of entries maps u to the first cell that can contain it, and a
// short forward walk over the CDF finishes. u·G is exact in float for G = 2^m, so the guide
// never starts past the right cell. The expected walk is at most (n + G)/G ≤ 2 cells.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "core/math.h"

namespace hairis {

/// `count` equal-width cells over [lo, hi] and the exact float boundaries between them.
class UniformCells {
  public:
    /// Refuses more than this many cells.
    static constexpr int kMaxCells = 1 << 22;

    /// Refuses non-finite or empty intervals, counts outside [1, kMaxCells], and intervals
    /// too narrow for every cell to contain a float.
    static Expected<UniformCells> create(float lo, float hi, int count);

    int count() const { return count_; }
    float lo() const { return lo_; }
    float hi() const { return hi_; }
    /// (hi − lo) / count.
    float width() const { return width_; }
    /// count / (hi − lo): a density per unit x is a cell's mass times this.
    float inv_width() const { return inv_width_; }

    /// True for x in [lo, hi]; false for NaN.
    bool contains(float x) const { return x >= lo_ && x <= hi_; }

    /// The cell of x ∈ [lo, hi]: k with edge(k) ≤ x < edge(k + 1), hi in the last cell.
    int cell_of(float x) const {
        const int k = int((x - lo_) * inv_width_);
        return k < 0 ? 0 : (k >= count_ ? count_ - 1 : k);
    }

    /// The smallest float in cell k (k ∈ [0, count]); edge(count) = hi.
    float edge(int k) const { return edges_[size_t(k)]; }

    /// edge(k) + t·(edge(k + 1) − edge(k)) for t ∈ [0, 1), clamped into the floats of cell k so
    /// that cell_of() returns k for it.
    float point_in_cell(int k, float t) const {
        return clamp_to_cell(k, edge(k) + t * (edge(k + 1) - edge(k)));
    }

    /// The inverse of point_in_cell: (x − edge(k)) / (edge(k + 1) − edge(k)) in [0, 1].
    float fraction_in_cell(int k, float x) const;

    /// x moved into the floats of cell k: [edge(k), edge(k + 1)) or [edge(k), hi] for the last.
    float clamp_to_cell(int k, float x) const {
        if (!(x >= edges_[size_t(k)])) return edges_[size_t(k)];
        if (x >= edges_[size_t(k) + 1]) return last_in_cell_[size_t(k)];
        return x;
    }

  private:
    float lo_ = 0, hi_ = 1, width_ = 1, inv_width_ = 1;
    int count_ = 1;
    std::vector<float> edges_;         // count + 1
    std::vector<float> last_in_cell_;  // the largest float of each cell
};

/// A discrete choice of cell k by u ∈ [c_k, c_{k+1}), and where u fell inside that range:
/// fraction = (u − c_k) / (c_{k+1} − c_k) ∈ [0, 1), a fresh uniform number for the cell.
struct CellChoice {
    int index = 0;
    float fraction = 0;
};

/// `count` discrete distributions over `size` cells each, stored contiguously (one row per
/// distribution): inverse CDFs with guide tables. The building block of everything here.
/// A row whose weights are all zero becomes uniform and is flagged by is_fallback().
class DiscreteCdfs {
  public:
    static constexpr int kMaxSize = UniformCells::kMaxCells;

    /// An empty set (count() == 0), to be assigned from create().
    DiscreteCdfs() = default;

    /// Bytes a set of `count` rows of `size` cells will allocate, for limits checked before
    /// anything is allocated.
    static long long bytes_needed(long long count, long long size);

    /// Allocates `count` rows of `size` cells; fill(row, weights) must write `size`
    /// non-negative finite weights (any scale) into `weights` for each row in turn.
    template <typename Fill>
    static Expected<DiscreteCdfs> create(int count, int size, Fill &&fill) {
        if (Status s = first_error(check::count_in_range("distribution count", count, 1, 1 << 30),
                                   check::count_in_range("cell count", size, 1, kMaxSize)))
            return *s;
        DiscreteCdfs d(count, size);
        std::vector<double> weights(size_t(size), 0.0);
        for (int row = 0; row < count; ++row) {
            std::fill(weights.begin(), weights.end(), 0.0);
            fill(row, weights.data());
            if (Status s = d.set_row(row, weights.data())) return *s;
        }
        return d;
    }

    int count() const { return count_; }
    int size() const { return size_; }

    /// The cell of row `row` that u falls into, and u's fraction within it. u is clamped to
    /// [0, 1) (NaN to 0). Cells of zero mass are never returned.
    CellChoice sample(int row, float u) const {
        if (!(u > 0.0f)) u = 0.0f;
        if (u > kOneMinusEpsilon) u = kOneMinusEpsilon;
        const float *c = cdf(row);
        const size_t j = size_t(row) * size_t(guide_size_) + size_t(u * float(guide_size_));
        int k = narrow_ ? int(guide16_[j]) : int(guide32_[j]);  // u·2^m is exact
        // The walk: usually zero or one step, so the first is taken without a branch.
        // c[size] = 1 > u ends it.
        k += int(u >= c[k + 1]);
        while (u >= c[k + 1]) ++k;
        const float t = (u - c[k]) / (c[k + 1] - c[k]);
        return {k, t < kOneMinusEpsilon ? t : kOneMinusEpsilon};
    }

    /// The inverse of sample(): c_k + fraction·(c_{k+1} − c_k), clamped to [c_k, c_{k+1}].
    float invert(int row, int k, float fraction) const {
        const float *c = cdf(row);
        const float u = c[k] + fraction * (c[k + 1] - c[k]);
        return u < c[k] ? c[k] : (u > c[k + 1] ? c[k + 1] : u);
    }

    /// Probability mass of cell k of row `row`: c_{k+1} − c_k.
    float pmf(int row, int k) const {
        const float *c = cdf(row);
        return c[k + 1] - c[k];
    }

    /// The size + 1 CDF values of a row, c_0 = 0 … c_size = 1.
    const float *cdf(int row) const { return cdf_.data() + size_t(row) * size_t(size_ + 1); }

    /// True when the row's weights were all zero and it fell back to uniform.
    bool is_fallback(int row) const { return fallback_[size_t(row)] != 0; }

  private:
    DiscreteCdfs(int count, int size);
    Status set_row(int row, const double *weights);

    int count_ = 0, size_ = 0, guide_size_ = 1;
    bool narrow_ = true;                  // 16-bit guide entries (size ≤ 65536)
    std::vector<float> cdf_;              // count × (size + 1)
    std::vector<std::uint16_t> guide16_;  // count × guide_size when narrow_
    std::vector<std::uint32_t> guide32_;  // count × guide_size otherwise
    std::vector<unsigned char> fallback_;
};

/// A sample of a 1D piecewise-constant density.
struct PiecewiseSample1D {
    float x = 0;    ///< in [lo, hi]
    float pdf = 0;  ///< density per unit x at x; pdf(x) returns the same value
    int cell = 0;   ///< the cell x lies in
};

/// A piecewise-constant density over [lo, hi] from n non-negative cell values, in the
/// manner of pbrt-v4's PiecewiseConstant1D, with O(1) expected sampling (guide table).
///
/// Zero total mass (all values zero) falls back to the uniform density 1 / (hi − lo) and sets
/// is_uniform_fallback(), so a caller can tell "nothing to sample" from a real density.
class PiecewiseConstant1D {
  public:
    /// Refuses NaN, infinite or negative values, n outside [1, UniformCells::kMaxCells],
    /// and non-finite or empty intervals.
    static Expected<PiecewiseConstant1D> create(const std::vector<float> &values, float lo,
                                                float hi);
    static Expected<PiecewiseConstant1D> create(const float *values, int count, float lo, float hi);

    /// Maps u ∈ [0, 1) to x with density pdf(x). Cells of zero value are never sampled.
    PiecewiseSample1D sample(float u) const {
        const CellChoice c = cdfs_.sample(0, u);
        return {cells_.point_in_cell(c.index, c.fraction), cell_pdf(c.index), c.index};
    }

    /// Density per unit x; 0 outside [lo, hi] and for NaN.
    float pdf(float x) const { return cells_.contains(x) ? cell_pdf(cells_.cell_of(x)) : 0.0f; }

    /// The CDF at x: the u that sample() maps to x (clamped to 0 below lo and 1 above hi).
    float invert(float x) const;

    /// Density inside cell k: its mass times count / (hi − lo).
    float cell_pdf(int k) const { return cdfs_.pmf(0, k) * cells_.inv_width(); }
    /// Probability mass of cell k.
    float cell_mass(int k) const { return cdfs_.pmf(0, k); }
    /// The stored CDF at the lower edge of cell k (k ∈ [0, n]); cdf_at(n) = 1.
    float cdf_at(int k) const { return cdfs_.cdf(0)[k]; }

    int cell_count() const { return cells_.count(); }
    float lo() const { return cells_.lo(); }
    float hi() const { return cells_.hi(); }
    const UniformCells &cells() const { return cells_; }
    /// The values given to create(), unchanged.
    const std::vector<float> &values() const { return values_; }
    /// ∫ of the given values over [lo, hi] (sum of value × width, in double).
    double integral() const { return integral_; }
    /// True when all values were zero and the density is uniform instead.
    bool is_uniform_fallback() const { return cdfs_.is_fallback(0); }

  private:
    PiecewiseConstant1D(UniformCells cells, DiscreteCdfs cdfs, std::vector<float> values,
                        double integral)
        : cells_(std::move(cells)),
          cdfs_(std::move(cdfs)),
          values_(std::move(values)),
          integral_(integral) {}

    UniformCells cells_;
    DiscreteCdfs cdfs_;
    std::vector<float> values_;
    double integral_ = 0;
};

/// A sample of a 2D piecewise-constant density.
struct PiecewiseSample2D {
    float x = 0, y = 0;  ///< x ∈ [x_lo, x_hi] (rows), y ∈ [y_lo, y_hi] (columns)
    float pdf = 0;       ///< density per unit x·y; pdf(x, y) returns the same value
    int row = 0, col = 0;
};

/// Two uniform numbers, e.g. the result of invert().
struct Point2 {
    float u0 = 0, u1 = 0;
};

/// A piecewise-constant density over [x_lo, x_hi] × [y_lo, y_hi] from a rows × cols grid
/// (row-major: values[row·cols + col]; rows along x, e.g. θ_i, columns along y, e.g. φ).
/// Sampled as a marginal over rows and a conditional over the columns of the chosen row.
/// The density is per unit x·y (parameter space, not solid angle).
///
/// A row of zero mass gets marginal probability 0 and is never sampled (its conditional is
/// uniform, and flagged by row_is_empty()); an all-zero grid falls back to uniform and sets
/// is_uniform_fallback() (every row is then flagged empty, and sampled uniformly).
class PiecewiseConstant2D {
  public:
    static Expected<PiecewiseConstant2D> create(const std::vector<float> &values, int rows,
                                                int cols, float x_lo, float x_hi, float y_lo,
                                                float y_hi);

    /// u0 picks the row (x) through the marginal, u1 the column (y) within that row.
    PiecewiseSample2D sample(float u0, float u1) const {
        const CellChoice r = marginal_.sample(0, u0);
        const CellChoice c = conditional_.sample(r.index, u1);
        return {xs_.point_in_cell(r.index, r.fraction), ys_.point_in_cell(c.index, c.fraction),
                cell_pdf(r.index, c.index), r.index, c.index};
    }

    /// Density per unit x·y; 0 outside the domain and for NaN.
    float pdf(float x, float y) const {
        if (!xs_.contains(x) || !ys_.contains(y)) return 0.0f;
        return cell_pdf(xs_.cell_of(x), ys_.cell_of(y));
    }

    /// The (u0, u1) that sample() maps to (x, y) (clamped into the domain).
    Point2 invert(float x, float y) const;

    /// Density inside cell (row, col).
    float cell_pdf(int row, int col) const {
        return (marginal_.pmf(0, row) * conditional_.pmf(row, col)) * inv_cell_area_;
    }

    int rows() const { return xs_.count(); }
    int cols() const { return ys_.count(); }
    const UniformCells &x_cells() const { return xs_; }
    const UniformCells &y_cells() const { return ys_; }
    const std::vector<float> &values() const { return values_; }
    /// True when the whole grid was zero and the density is uniform instead.
    bool is_uniform_fallback() const { return marginal_.is_fallback(0); }
    /// True when row `row` has zero mass (never sampled, pdf 0 there).
    bool row_is_empty(int row) const { return conditional_.is_fallback(row); }

  private:
    PiecewiseConstant2D(UniformCells xs, UniformCells ys, DiscreteCdfs marginal,
                        DiscreteCdfs conditional, std::vector<float> values);

    UniformCells xs_, ys_;
    DiscreteCdfs marginal_, conditional_;
    std::vector<float> values_;
    float inv_cell_area_ = 1;
};

}  // namespace hairis
