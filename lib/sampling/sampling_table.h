// Per-θ_r importance-sampling tables for ω_i (the seed's plan): tabulated densities of the
// incident direction given the view's longitudinal angle θ_r (= θ_o), inverted as CDFs.
//
// Conventions (frame.h): θ ∈ [−π/2, π/2] from the fiber's normal plane, sin θ = ω.x;
// φ = φ_i − φ_o ∈ [−π, π] is the relative azimuth. Every density here is per steradian of ω_i
// (dω = cos θ dθ dφ = d(sin θ) dφ), never per unit θ·φ.
//
// Cells. θ_i is cut into equal cells in θ (not in sin θ) over [−π/2, π/2], φ into equal cells
// over [−π, π]. A table value is a density per steradian, constant inside its cell; the cell's
// solid angle is (sin θ_1 − sin θ_0)·Δφ, so its probability is value × that solid angle /
// total, and inside the cell sin θ (not θ) is sampled uniformly, which makes the sampled
// density exactly constant per steradian there: pdf(ω) = value / total (up to the float
// rounding of the stored CDFs, about 2^-24 / cell mass relative; see piecewise.h: the CDF is
// the distribution, so sample() and pdf() agree bit for bit).
//
// Interpolation over θ_r: STOCHASTIC SELECTION between the two neighbouring nodes. For θ_r
// between nodes r and r + 1 at t = (θ_r − θ_r,r)/(θ_r,r+1 − θ_r,r), sample() draws from node
// r + 1 with probability t (decided by u2) and from node r otherwise, and pdf() returns
// (1 − t)·pdf_r + t·pdf_r+1: the density of that mixture by construction, so exact, O(1) (one
// guide table per slice) and with no per-query table. It is the same density as blending the
// two normalized slices bilinearly; sampling that blend deterministically (Mitsuba 3's
// Marginal2D style) would need the blended marginal AND a blended conditional over φ, which is
// not the blend of the two conditionals but a per-θ_i-row mass-weighted one — interpolating
// the marginal and conditional CDFs independently would sample a different density than the
// one pdf() reports. Doing it right needs a binary search over blended CDFs per query; its
// only gain, a map u → ω continuous in θ_r, does not matter to a path tracer. Outside the node
// range θ_r is clamped to the first or last node.
//
// Fallbacks: a slice (node, or node and n_h) whose values are all zero samples the uniform
// sphere, pdf 1/(4π), and is flagged by slice_is_fallback(). Cells of zero value are never
// sampled and have pdf 0. A θ_i row of zero mass is never sampled.
//
// Use from a renderer, with the fiber frame F of frame.h and ω_o:
//   FiberAngles o = angles_of(F.to_local(wo));
//   TableSample s = table.sample(o.theta, u0, u1, u2);
//   Vec3 wi = F.to_world(s.local_direction(o.phi));          // s.pdf is per steradian of ω_i
//   and for a given ω_i (no asin needed: sin θ_i is ω_i's x coordinate):
//   Vec3 l = F.to_local(wi);
//   float pdf = table.pdf_sin(o.theta, l.x, relative_azimuth(angles_of(l).phi, o.phi));
// With Cycles' frame φ_o = −π/2 always, and s.local_direction(0, −1) needs no trigonometry
// at all; sample() and pdf_sin() use none either (sin θ is sampled directly, the azimuth's
// cos and sin come from a table).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/expected.h"
#include "core/math.h"
#include "sampling/piecewise.h"
#include "sampling/table_limits.h"

namespace hairis {


/// A sampled incident direction ω_i, without trigonometry: sin θ_i is what the tables sample
/// (ω_i.x exactly), and the azimuth comes with its cosine and sine.
struct TableSample {
    float sin_theta_i = 0;  ///< sin θ_i = ω_i.x, in [−1, 1]
    float cos_theta_i = 1;  ///< cos θ_i = sqrt(1 − sin² θ_i) ≥ 0
    float phi = 0;          ///< relative azimuth φ = φ_i − φ_o in [−π, π]
    float cos_phi = 1;      ///< cos φ (to float precision)
    float sin_phi = 0;      ///< sin φ
    float pdf = 0;          ///< per steradian of ω_i; pdf_sin(θ_o, sin_theta_i, phi) is the same

    /// θ_i in [−π/2, π/2] (one asin).
    float theta_i() const { return std::asin(std::clamp(sin_theta_i, -1.0f, 1.0f)); }

    /// ω_i in the fiber frame for a view with azimuth φ_o given as cos φ_o, sin φ_o (Cycles'
    /// frame: φ_o = −π/2, i.e. (0, −1)): (sin θ_i, cos θ_i cos(φ_o + φ), cos θ_i sin(φ_o + φ)).
    Vec3 local_direction(float cos_phi_o, float sin_phi_o) const {
        const float c = cos_phi_o * cos_phi - sin_phi_o * sin_phi;
        const float s = sin_phi_o * cos_phi + cos_phi_o * sin_phi;
        return {sin_theta_i, cos_theta_i * c, cos_theta_i * s};
    }
    /// The same from φ_o itself (one cos and one sin).
    Vec3 local_direction(float phi_o) const {
        return local_direction(std::cos(phi_o), std::sin(phi_o));
    }
};

/// Where θ_r falls among the nodes: node `lower` with weight 1 − t, node lower + 1 with t.
struct NodeBlend {
    int lower = 0;
    float t = 0;
};

/// Sorted θ_r nodes in [−π/2, π/2] and the lookup of θ_r among them (O(1) when uniform).
class ThetaRNodes {
  public:
    /// Refuses counts outside [1, kMaxThetaRNodes], nodes outside [−π/2, π/2] (float) and
    /// nodes that are not strictly increasing.
    static Expected<ThetaRNodes> create(const std::vector<float> &nodes);

    /// The neighbouring nodes of θ_r and the upper one's weight t ∈ [0, 1]; θ_r is clamped to
    /// the node range (NaN to the first node). t is exactly 0 on a node.
    NodeBlend locate(float theta_r) const {
        const int n = count();
        if (n == 1 || !(theta_r > nodes_.front())) return {0, 0.0f};  // also NaN
        if (!(theta_r < nodes_.back())) return {n - 2, 1.0f};
        int k = uniform_ ? int((theta_r - nodes_.front()) * inv_spacing_) : search(theta_r);
        k = k < 0 ? 0 : (k > n - 2 ? n - 2 : k);
        while (k > 0 && theta_r < nodes_[size_t(k)]) --k;  // at most a step of rounding
        while (k < n - 2 && theta_r >= nodes_[size_t(k) + 1]) ++k;
        const float t = (theta_r - nodes_[size_t(k)]) * inv_interval_[size_t(k)];
        return {k, t < 1.0f ? t : 1.0f};
    }

    int count() const { return int(nodes_.size()); }
    const std::vector<float> &values() const { return nodes_; }

  private:
    int search(float theta_r) const;

    std::vector<float> nodes_;
    std::vector<float> inv_interval_;  // 1 / (node k+1 − node k)
    bool uniform_ = false;
    float inv_spacing_ = 0;
};

/// Equal θ cells over [−π/2, π/2], sampled uniformly in sin θ inside each cell; the cell of a
/// direction is decided by sin θ = ω.x (boundaries sin θ_k rounded to float), so neither
/// sampling nor lookup needs trigonometry.
class LongitudinalCells {
  public:
    static Expected<LongitudinalCells> create(int count);

    struct Point {
        float sin_theta, cos_theta;
    };

    int count() const { return count_; }
    /// sin of the cell boundary θ_k = −π/2 + kπ/count (sin_edge(0) = −1, sin_edge(count) = 1).
    float sin_edge(int k) const { return sin_edges_[size_t(k)]; }
    /// sin θ_{k+1} − sin θ_k: the solid angle of cell k per radian of φ.
    float sin_width(int k) const { return sin_edges_[size_t(k) + 1] - sin_edges_[size_t(k)]; }
    /// True for sin θ in [−1, 1]; false for NaN.
    static bool contains_sin(float s) { return s >= -1.0f && s <= 1.0f; }
    /// The cell k with sin_edge(k) ≤ s < sin_edge(k + 1) (s = 1 in the last cell), for
    /// s ∈ [−1, 1]: a guide table over s and a step or two.
    int cell_of_sin(float s) const {
        const int g = int((s + 1.0f) * guide_scale_);
        int k = int(guide_[size_t(g < guide_max_ ? g : guide_max_)]);
        while (k > 0 && s < sin_edges_[size_t(k)]) --k;  // only after rounding in (s + 1)
        // Usually zero or one step forward: the first without a branch (sin_edges_[count] = 1,
        // so s = 1 stays in the last cell).
        k += int(s >= sin_edges_[size_t(k) + 1]) & int(k < count_ - 1);
        while (k < count_ - 1 && s >= sin_edges_[size_t(k) + 1]) ++k;
        return k;
    }
    /// The point of cell k at fraction t ∈ [0, 1) of its sin θ range, kept inside the cell so
    /// that cell_of_sin() returns k for it, and off the fiber axis (|sin θ| < 1): there φ is
    /// undefined, so a sample would carry its φ in name only while pdf() and f read another
    /// (rounding put ~10⁻⁴ of a polar cell's samples exactly on the axis).
    Point point_in_cell(int k, float t) const {
        const float lo = k == 0 ? -kOneMinusEpsilon : sin_edge(k);
        float s = sin_edge(k) + t * sin_width(k);
        s = s < lo ? lo : (s > last_sin_[size_t(k)] ? last_sin_[size_t(k)] : s);
        return {s, std::sqrt((1.0f - s) * (1.0f + s))};
    }

  private:
    int count_ = 0;
    std::vector<float> sin_edges_;  // count + 1, strictly increasing
    std::vector<float> last_sin_;   // the largest float of each cell
    std::vector<std::uint16_t> guide_;
    float guide_scale_ = 0;
    int guide_max_ = 0;
};

/// cos and sin of an azimuth φ ∈ [−π, π] without calling trigonometric functions: a table of
/// 256 angles rotated by the small remainder, whose cos and sin come from short Taylor series
/// (error far below float precision for remainders under 2π/256).
class AzimuthTrig {
  public:
    AzimuthTrig();
    void operator()(float phi, float &cos_phi, float &sin_phi) const {
        constexpr int kLast = kSteps - 1;
        const int k0 = int((phi + float(kPi)) * float(kSteps / kTwoPi));
        const int k = k0 < 0 ? 0 : (k0 > kLast ? kLast : k0);
        const float d = phi - angle_[size_t(k)], d2 = d * d;
        const float sd = d * (1.0f - d2 * (1.0f / 6.0f - d2 * (1.0f / 120.0f)));
        const float cd = 1.0f - d2 * (0.5f - d2 * (1.0f / 24.0f - d2 * (1.0f / 720.0f)));
        cos_phi = cos_[size_t(k)] * cd - sin_[size_t(k)] * sd;
        sin_phi = sin_[size_t(k)] * cd + cos_[size_t(k)] * sd;
    }

  private:
    static constexpr int kSteps = 256;
    std::vector<float> angle_, cos_, sin_;
};

/// Direct scattering: for each θ_r node a density f(θ_i, φ) per steradian on an
/// theta_i_count × phi_count grid of cells.
class DirectTable {
  public:
    /// values[(r·theta_i_count + i)·phi_count + j]: node r, θ_i cell i (from −π/2), φ cell j
    /// (from −π); finite and non-negative, any overall scale (each slice is normalized).
    static Expected<DirectTable> create(const std::vector<float> &theta_r_nodes, int theta_i_count,
                                        int phi_count, const std::vector<float> &values);

    /// ω_i for a view at θ_o: u0 picks θ_i, u1 the azimuth φ, u2 the θ_r node. All in [0, 1).
    TableSample sample(float theta_o, float u0, float u1, float u2) const;
    /// The same with θ_o already located among the nodes (locate()).
    TableSample sample(NodeBlend at, float u0, float u1, float u2) const;
    /// Where θ_o falls among the nodes.
    NodeBlend locate(float theta_o) const { return nodes_.locate(theta_o); }

    /// Density per steradian of ω_i at sin θ_i (= ω_i.x) and φ = φ_i − φ_o, for a view at θ_o:
    /// the exact counterpart of sample(), bit for bit, with no trigonometry. φ outside [−π, π]
    /// is wrapped; sin θ_i outside [−1, 1] or NaN gives 0.
    float pdf_sin(float theta_o, float sin_theta_i, float phi) const;
    float pdf_sin(NodeBlend at, float sin_theta_i, float phi) const;

    /// The same from the angle θ_i: pdf_sin(θ_o, sin θ_i, φ), 0 for |θ_i| > π/2 or NaN. Within
    /// a float ulp of a cell boundary the rounding of sin may pick the neighbouring cell.
    float pdf(float theta_o, float theta_i, float phi) const {
        return std::fabs(theta_i) <= float(kHalfPi) ? pdf_sin(theta_o, std::sin(theta_i), phi)
                                                    : 0.0f;
    }

    const std::vector<float> &theta_r_nodes() const { return nodes_.values(); }
    int node_count() const { return nodes_.count(); }
    int theta_i_count() const { return theta_.count(); }
    int phi_count() const { return phi_.count(); }
    const LongitudinalCells &theta_i_cells() const { return theta_; }
    const UniformCells &phi_cells() const { return phi_; }
    /// The values given to create(), unchanged (an all-zero slice stays zero here).
    const std::vector<float> &values() const { return values_; }
    float value(int r, int i, int j) const {
        return values_[(size_t(r) * size_t(theta_.count()) + size_t(i)) * size_t(phi_.count()) +
                       size_t(j)];
    }
    /// True when node r's values were all zero and it samples the uniform sphere instead.
    bool slice_is_fallback(int r) const { return slice_fallback_[size_t(r)] != 0; }

  private:
    DirectTable() = default;
    float node_cell_pdf(int r, int i, int j) const {
        const size_t row = size_t(r) * size_t(theta_.count()) + size_t(i);
        return row_factor_[row] * conditional_.pmf(int(row), j);
    }
    float cell_pdf(NodeBlend b, int i, int j) const;

    ThetaRNodes nodes_;
    LongitudinalCells theta_;
    UniformCells phi_;
    AzimuthTrig trig_;
    DiscreteCdfs marginal_;          // per node: over θ_i cells
    DiscreteCdfs conditional_;       // per node and θ_i cell: over φ cells
    std::vector<float> row_factor_;  // marginal mass / (Δ sin θ) × count / 2π, per node and row
    std::vector<float> values_;
    std::vector<unsigned char> slice_fallback_;
};

/// Multiple scattering: for each θ_r node and each strand count n_h a density over θ_i per
/// steradian, uniform in φ over [−π, π].
class MultipleTable {
  public:
    /// values[(r·n_h_count + k)·theta_i_count + i]: node r, strand count n_h_values[k], θ_i
    /// cell i. n_h_values: positive, strictly increasing (e.g. 1, 2, 4, 8, 16).
    static Expected<MultipleTable> create(const std::vector<float> &theta_r_nodes,
                                          const std::vector<int> &n_h_values, int theta_i_count,
                                          const std::vector<float> &values);

    /// The index of n_h in n_h_values(), or −1.
    int strand_index(int n_h) const;

    /// ω_i for a view at θ_o through n_h_values()[strand]: u0 picks θ_i, u1 φ (uniform),
    /// u2 the θ_r node. An invalid strand index returns a sample with pdf 0.
    TableSample sample(int strand, float theta_o, float u0, float u1, float u2) const;
    TableSample sample(int strand, NodeBlend at, float u0, float u1, float u2) const;
    /// Where θ_o falls among the nodes.
    NodeBlend locate(float theta_o) const { return nodes_.locate(theta_o); }

    /// Density per steradian of ω_i at sin θ_i (= ω_i.x), any φ (the density does not depend
    /// on it): the exact counterpart of sample(), with no trigonometry.
    float pdf_sin(int strand, float theta_o, float sin_theta_i) const;
    float pdf_sin(int strand, NodeBlend at, float sin_theta_i) const;

    /// The same from the angle θ_i (see DirectTable::pdf); φ is accepted for symmetry only.
    float pdf(int strand, float theta_o, float theta_i, float /*phi*/ = 0.0f) const {
        return std::fabs(theta_i) <= float(kHalfPi) ? pdf_sin(strand, theta_o, std::sin(theta_i))
                                                    : 0.0f;
    }

    const std::vector<float> &theta_r_nodes() const { return nodes_.values(); }
    const std::vector<int> &n_h_values() const { return n_h_; }
    int node_count() const { return nodes_.count(); }
    int theta_i_count() const { return theta_.count(); }
    const LongitudinalCells &theta_i_cells() const { return theta_; }
    const std::vector<float> &values() const { return values_; }
    float value(int r, int k, int i) const {
        return values_[(size_t(r) * n_h_.size() + size_t(k)) * size_t(theta_.count()) + size_t(i)];
    }
    /// True when the values of node r and strand index k were all zero (uniform sphere).
    bool slice_is_fallback(int r, int k) const {
        return slice_fallback_[size_t(r) * n_h_.size() + size_t(k)] != 0;
    }

  private:
    MultipleTable() = default;
    float cell_pdf(int strand, NodeBlend b, int i) const;

    ThetaRNodes nodes_;
    LongitudinalCells theta_;
    AzimuthTrig trig_;
    std::vector<int> n_h_;
    DiscreteCdfs cdfs_;           // per node and strand count: over θ_i cells
    std::vector<float> density_;  // per node, strand count and θ_i cell: mass / (Δ sin θ · 2π)
    std::vector<float> values_;
    std::vector<unsigned char> slice_fallback_;  // per node and strand count
};

}  // namespace hairis
