// A baked importance-sampling table for the Huang 2022 fiber (fiber/huang.h): per view
// (θ_o node, φ_o node) a 2D piecewise-constant density over (θ_i, φ) proportional to a
// tabulated luminance(f·cos θ_i), in Huang's frame (x = tangent, y = the ellipse's major axis,
// z = x × y; azimuths measured from y towards z).
//
// Folding. The ellipse is symmetric about both of its axes, so f is unchanged when ω_o and ω_i
// are mirrored together by y → −y (φ → π − φ) or z → −z (φ → −φ). A view is folded into the
// quadrant φ_o ∈ [0, π/2] by the mirror that takes its (y, z) to (|y|, |z|); ω_i is mirrored
// with it. The φ_o nodes lie in that quadrant. One node means a circular fiber, whose f
// depends on the azimuths only through φ_i − φ_o: that node serves every view, unfolded.
//
// Azimuth. Cells are over the relative azimuth φ = φ_i − φ_o of the folded directions, in
// [−π, π] (not over φ_i itself): the lobes of neighbouring φ_o nodes then nearly coincide, so
// their mixture is close to the density between them. Each node's slice is a DirectTable over
// the θ_o nodes (sampling_table.h: equal θ_i cells sampled uniformly in sin θ_i, equal φ cells).
//
// Longitudinal alignment. Huang's lobes (R, TT, TRT off the tilted cuticle, TRRT+'s d'Eon
// cone) sit near the specular cone θ_i = −θ_o and move with θ_o, one degree per degree. A node's
// slice is therefore read through a warp of θ_i: the piecewise-linear map of [−π/2, π/2] onto
// itself that fixes ±π/2 and takes the view's −θ_o to the node's −θ_node (ThetaWarp). Drawing
// from node r at a view θ_o means drawing ω' from the slice and mapping its θ' back; the density
// per steradian is the slice's at the warped direction times the warp's Jacobian
// dΩ'/dΩ = T'(θ_i)·cos θ'/cos θ_i. On a node the warp is the identity. (For smooth fibers the
// lobes are narrower than the node spacing, and mixing unaligned neighbouring slices would
// put most samples where neither lobe is.)
//
// Between nodes: exact stochastic mixing. For a view between φ_o nodes q and q + 1 at
// s = (φ_o − φ_q)/(φ_q+1 − φ_q), u2 < s picks node q + 1, and the rest of u2 (rescaled) picks
// the θ_o node the same way: the sampled density is the bilinear mixture of the four
// neighbouring slices (each through its warp), and pdf() returns exactly that mixture.
// Outside the node ranges the outer nodes are used (warped to the view's cone, whose anchor is
// clamped halfway from the outer θ_o node to the pole). O(1): guide tables per slice, no
// per-query tables; a pdf costs an asin, an atan2 and a sin per θ_o node.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "core/math.h"
#include "fiber/fiber_point.h"
#include "fiber/huang.h"
#include "sampling/sampling_table.h"

namespace hairis {

/// Refuses more φ_o nodes than this.
inline constexpr int kMaxPhiONodes = 256;

/// The warp of θ_i at a view onto a θ_o node's θ_i axis (see the file comment): piecewise
/// linear on [−π/2, anchor] and [anchor, π/2], anchor ↦ node_anchor, ±π/2 fixed.
struct ThetaWarp {
    double anchor = 0, node_anchor = 0;  ///< −θ_o and −θ_node
    double below = 1, above = 1;         ///< the slopes of the two pieces

    /// The warp from a view at θ_o to the node θ_node (both clamped into (−π/2, π/2)).
    static ThetaWarp between(double theta_o, double theta_node);
    double to_node(double theta_i) const {
        return theta_i < anchor ? -kHalfPi + (theta_i + kHalfPi) * below : kHalfPi - (kHalfPi - theta_i) * above;
    }
    double from_node(double theta) const {
        return theta < node_anchor ? -kHalfPi + (theta + kHalfPi) / below : kHalfPi - (kHalfPi - theta) / above;
    }
    /// dΩ_node/dΩ at θ_i: the slope × cos(to_node(θ_i)) / cos θ_i (the slope squared at ±π/2).
    double jacobian(double theta_i) const;
};

/// Where a view falls in a HuangTable (HuangTable::locate).
struct HuangTableQuery {
    /// The fold: ω ↦ (ω.x, sign_y·ω.y, sign_z·ω.z) takes ω_o to φ_o ∈ [0, π/2] (its own
    /// inverse); the identity for a one-node table.
    float sign_y = 1, sign_z = 1;
    /// cos and sin of the folded view's azimuth φ_o (1, 0 for a view along the tangent).
    float cos_phi_o = 1, sin_phi_o = 0;
    NodeBlend theta;  ///< among the θ_o nodes
    NodeBlend phi;    ///< among the φ_o nodes
    ThetaWarp warp[2];  ///< onto the lower and the upper θ_o node
};

/// The tables of one Huang fiber.
class HuangTable {
  public:
    /// values[((q·theta_o_count + r)·theta_i_count + i)·phi_count + j]: φ_o node q, θ_o node r,
    /// θ_i cell i (equal cells from −π/2), φ cell j (equal cells of φ_i − φ_o from −π); each
    /// proportional to the density per steradian there (any scale per slice), finite and
    /// non-negative. theta_o_nodes strictly increasing in [−π/2, π/2]; phi_o_nodes strictly
    /// increasing in [0, π/2]. Sizes are checked before anything is allocated; errors name the
    /// argument, the entry and the allowed range.
    static Expected<HuangTable> create(const std::vector<float> &theta_o_nodes, const std::vector<float> &phi_o_nodes,
                                       int theta_i_count, int phi_count, const std::vector<float> &values);
    /// What create() refuses, without building anything.
    static Status check(const std::vector<float> &theta_o_nodes, const std::vector<float> &phi_o_nodes,
                        int theta_i_count, int phi_count, const std::vector<float> &values);

    /// Where ω_o (Huang's frame, unit) falls: its fold, neighbouring nodes and warps. One asin
    /// and one atan2.
    HuangTableQuery locate(Vec3 wo) const;

    /// ω_i in Huang's frame from three uniform numbers in [0, 1): u0 picks θ_i, u1 φ, u2 the
    /// nodes. nullopt where the density is not positive (never for a table with positive mass).
    std::optional<DirectionSample> sample(const HuangTableQuery &q, float u0, float u1, float u2) const;
    /// The density per steradian with which sample() produces ω_i (Huang's frame).
    float pdf(const HuangTableQuery &q, Vec3 wi) const;

    const std::vector<float> &theta_o_nodes() const { return theta_o_nodes_; }
    const std::vector<float> &phi_o_nodes() const { return phi_o_nodes_; }
    int theta_i_count() const { return slices_.front().theta_i_count(); }
    int phi_count() const { return slices_.front().phi_count(); }
    /// The slices of φ_o node q, one per θ_o node.
    const DirectTable &slices(int q) const { return slices_[std::size_t(q)]; }
    /// The value given to create() for φ_o node q, θ_o node r, cell (i, j).
    float value(int q, int r, int i, int j) const { return slices(q).value(r, i, j); }
    /// Bytes the table holds (values, CDFs, guides, row factors).
    std::size_t memory_bytes() const;
    /// The same for a table of these dimensions, before building it.
    static long long bytes_needed(long long theta_o_count, long long phi_o_count, long long theta_i_count,
                                  long long phi_count);

  private:
    HuangTable() = default;
    float slice_pdf(const HuangTableQuery &q, NodeBlend theta_node, float sin_theta_i, float phi) const;

    // The anchor −θ_o of a warp is clamped to ±theta_limit_, halfway from the outer nodes to
    // the poles, so that the slopes stay bounded for views along the fiber.
    double theta_limit_ = kHalfPi;

    std::vector<float> theta_o_nodes_, phi_o_nodes_;
    ThetaRNodes phi_nodes_;  // the φ_o nodes' lookup
    std::vector<DirectTable> slices_;
};

/// The parameters a Huang table records: the fiber's, in HuangParams' order and names.
std::vector<std::pair<std::string, double>> huang_parameters(const HuangParams &params);

/// The largest f refinement (HuangBakeOptions::f_refinement): the rule's finest order stays
/// within GaussLegendre's nodes.
inline constexpr int kMaxHuangFRefinement = 4;

/// The most absorption nodes a Huang table's absorption part may have.
inline constexpr int kMaxHuangAbsorptionNodes = 32;
/// The largest absorption node: beyond it a strand's TT, TRT and TRRT+ are far below its R.
inline constexpr float kMaxHuangAbsorption = 1000.0f;

/// What a set's and a bake's absorption nodes must be: 2 to kMaxHuangAbsorptionNodes, strictly
/// increasing in (0, kMaxHuangAbsorption]; errors name them as `name`.
Status check_huang_absorption_nodes(const std::vector<float> &nodes, const std::string &name);

/// A baked Huang table as plain data: what a table file holds.
struct HuangTableSet {
    std::string model = "huang2022";
    std::vector<std::pair<std::string, double>> parameters;  ///< huang_parameters of the fiber
    std::vector<float> theta_o_nodes, phi_o_nodes;
    int theta_i_count = 0, phi_count = 0;
    std::vector<float> values;  ///< HuangTable::create's layout
    /// The baked expectation of f·|cos θ_i| of TT, TRT and TRRT+, RGB per cell in values'
    /// order (huang_f_table.h), or empty: renders then use Cycles' one-sample eval.
    std::vector<float> f;
    /// The factor of the f part's quadrature orders it was baked with (HuangBakeOptions), in
    /// [1, kMaxHuangFRefinement].
    int f_refinement = 1;
    /// The absorption part (huang_absorption_table.h), or both empty: for strands whose
    /// absorption differs from the fiber's. absorption_nodes: K absorption coefficients,
    /// strictly increasing in (0, kMaxHuangAbsorption]. absorption: K values per cell in
    /// values' order, absorption[K·n + k] = one channel of the f part at cell n of the fiber
    /// whose absorption in that channel is absorption_nodes[k]. Only with the f part.
    std::vector<float> absorption_nodes;
    std::vector<float> absorption;

    int theta_o_count() const { return int(theta_o_nodes.size()); }
    int phi_o_count() const { return int(phi_o_nodes.size()); }
    /// The model, plain parameter names with finite values, what HuangTable::check checks,
    /// an f part that is empty or 3 finite non-negative values per cell, f_refinement in
    /// range, and an absorption part that is empty or has 2 to kMaxHuangAbsorptionNodes nodes
    /// in range and their finite non-negative values, beside an f part.
    Status validate() const;
    bool has_f() const { return !f.empty(); }
    bool has_absorption() const { return !absorption_nodes.empty(); }
    int absorption_count() const { return int(absorption_nodes.size()); }
};

/// A Huang table ready to sample, and the fiber parameters it was baked for.
class HuangFTable;
class HuangAbsorptionTable;

struct HuangSamplingTable {
    std::shared_ptr<const HuangTable> table;
    /// The baked f (huang_f_table.h), or null when the set has none.
    std::shared_ptr<const HuangFTable> f;
    /// The absorption part (huang_absorption_table.h), or null when the set has none.
    std::shared_ptr<const HuangAbsorptionTable> absorption;
    std::string parameters;  ///< canonical_parameters(HuangTableSet::parameters)

    /// Builds the table (ErrorKind::InvalidTable when the set is not a valid Huang table).
    static Expected<HuangSamplingTable> from(const HuangTableSet &set);
};

}  // namespace hairis
