// Tables for the near field of a Chiang fiber: the part of f that the 2D far-field tables
// cannot follow.
//
// A renderer (like Cycles) shades the near field f(ω_i, ω_o, h), whose azimuthal lobes move
// with the offset h: R sits at Φ = −2γ_o, and over h ∈ [−1, 1] it sweeps all of [−π, π].
// Tables averaged over h spread every lobe over that whole sweep, and sample a fixed h far
// worse than Chiang's own analytic sampler. A 4D table over
// (θ_o, h, θ_i, φ) would be large. It is not needed, because the model factors per lobe:
//
//   f_p·|cos θ_i| = A_p(θ_o, h) · M_p(θ_i | θ_o) · N_p(φ − Φ_p(h)).
//
// Only M_p depends on θ_i, and it does not depend on h. So this table holds, per θ_o node and
// lobe, M_p(θ_i | θ_o)·cos θ_i exactly as Cycles evaluates it (with the cuticle tilt on θ_i,
// which the analytic sampler can only approximate) as a 1D inverse-CDF over θ_i cells, plus
// each lobe's integral I_p(θ_o). Inside a cell the density is linear in sin θ_i between M_p's
// values at the cell's edges, with the cell's mass from the exact integral (piecewise-constant
// cells would cost ~10⁻³ relative variance at 1°). At a shading point the sampler picks the
// lobe with probability ∝ luminance(A_p)·I_p, θ_i from the lobe's table and φ from the trimmed
// logistic around Φ_p(h) (N_p is sampled exactly, in closed form). θ_o between nodes picks the
// lower or upper node stochastically, so the density is the exact blend of the two nodes'.
//
// The density is then proportional to luminance(f·cos) up to the cells' resolution and the
// blend between nodes, far below the analytic sampler's variance (whose M_p is tilted on θ_o
// instead of θ_i). The blend dominates, so the defaults spend memory on nodes rather than
// cells.
//
// Smooth fibers (roughness below ~0.1) have lobes narrower than the cells and the node
// spacing, which a table in (θ_o, θ_i) cannot follow; the fiber's own cone sampler
// (ChiangFiber::sample_lobe_sin_theta, d'Eon's, with the tilt on θ_o) follows them at any
// width but misplaces a wide lobe by its tilt. So at each node each lobe takes whichever of
// the two has the smaller χ² divergence from Cycles' M_p (∫ M²/q − 1, the lobe's relative
// variance), measured at build time over the adjacent node intervals; the row is kept where
// its divergence is already below 10⁻³ (every lobe of a fiber rougher than ~0.15), since the
// cone costs an M_p evaluation at every pdf. The lobe is still chosen with the table's
// weights, and its density enters the same mixture. At roughness 0.02–0.1 this takes the
// variance from above the analytic sampler's (rows alone) to a fraction of it.
//
// A material whose inputs vary per strand (chiang_strands.h) keeps the tables of its node's
// own values; at a strand's hit the lobe weights take the strand's A_p, φ the strand's N_p,
// and a lobe whose M_p is not the table's draws θ_i from the strand's own cone, never from
// rows baked for another roughness.
#pragma once

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "fiber/chiang.h"
#include "fiber/chiang_strands.h"
#include "core/expected.h"
#include "sampling/piecewise.h"
#include "sampling/sampling_table.h"
#include "sampling/sampler.h"

namespace hairis {

/// Where a lobe of the near-field table draws θ_i from (NearFieldTableOptions::lobe_sampling).
enum class LobeSampling { Auto, Table, Cone };

/// Resolution and lobe sources of a NearFieldTable (the resolution spends memory on θ_o nodes,
/// whose blend dominates the variance).
struct NearFieldTableOptions {
    int theta_o_nodes = 121;  ///< nodes over [−π/2, π/2], ends included (1.5° apart)
    int theta_i_cells = 90;   ///< equal θ_i cells over [−π/2, π/2] (2° wide)
    /// How lobe p (R, TT, TRT, residual) draws θ_i: from its table row, from the fiber's own
    /// cone sampler, or (Auto) from whichever of the two is closer to Cycles' M_p, measured
    /// when the table is built.
    std::array<LobeSampling, 4> lobe_sampling = {LobeSampling::Auto, LobeSampling::Auto,
                                                 LobeSampling::Auto, LobeSampling::Auto};
};

/// What a near-field table holds, as plain data (what a table file stores): per θ_o node r
/// (equally spaced over [−π/2, π/2], ends included) and lobe p, row r·4 + p.
struct NearFieldData {
    int theta_o_nodes = 0;
    int theta_i_cells = 0;
    std::vector<float> mass;          ///< [row·cells + k]: ∫ over θ_i cell k of M_p cos θ_i (any scale per row)
    std::vector<float> edge;          ///< [row·(cells + 1) + k]: M_p at the cells' edges (the shape inside a cell)
    std::vector<float> integral;      ///< [row]: ∫ M_p cos θ_i dθ_i over the sphere (the lobe's weight factor)
    std::vector<unsigned char> cone;  ///< [row]: 1 when the lobe draws θ_i from the fiber's cone

    int rows() const { return 4 * theta_o_nodes; }
    /// Counts in range ([2, kMaxThetaRNodes] nodes, [4, kMaxTableAxisCells] cells), sizes
    /// consistent, values finite and >= 0, cone flags 0 or 1; names the first problem.
    Status validate() const;
};

/// Per-θ_o, per-lobe inverse CDFs of Cycles' M_p·cos θ_i, and the near-field sampler on them.
class NearFieldTable {
  public:
    /// Tabulates the fiber's M_p (what the baker stores); refuses node counts outside
    /// [2, kMaxThetaRNodes] and cell counts outside [4, kMaxTableAxisCells].
    static Expected<NearFieldTable> create(std::shared_ptr<const ChiangFiber> fiber,
                                           const NearFieldTableOptions &options = {});
    /// The table of `data` (baked for `fiber`'s parameters) for `fiber`: nothing is computed
    /// from the fiber but the CDFs of the stored masses, so tables built and loaded sample
    /// alike, bit for bit.
    static Expected<NearFieldTable> from_data(std::shared_ptr<const ChiangFiber> fiber,
                                              std::shared_ptr<const NearFieldData> data);
    /// What the table holds.
    const NearFieldData &data() const { return *data_; }
    const std::shared_ptr<const NearFieldData> &shared_data() const { return data_; }

    /// What sample() and pdf() need at one hit, computed once from the fiber's point there:
    /// the θ_o nodes, their lobe weights, and the lobes whose M_p is not the table's.
    struct Prepared {
        const ChiangPoint *fiber = nullptr;
        NodeBlend blend;
        float weight[2][4] = {};  // lobe probabilities at the lower and upper node
        unsigned own_cones = 0;   // bit p: lobe p draws θ_i from the hit's own cone
    };
    /// `fiber` is the fiber at the hit, and must outlive the result: this table's fiber, or a
    /// strand's own (chiang_strands.h) whose parameters differ from the table's. The lobe
    /// weights luminance(A_p)·I_p take the hit's A_p, φ is drawn from the hit's N_p around its
    /// Φ_p(h), and a lobe whose M_p differs from the table's (another roughness, coat or
    /// offset) draws θ_i from the hit's own cone when `own_cones` is set, else from the
    /// table's rows and cones as they are; the density is the exact one in every case.
    Prepared prepare(const ChiangPoint &fiber, bool own_cones = true) const;

    /// Draws ω_i: u2 picks the θ_o node and the lobe, u1 θ_i, u0 φ. nullopt when the density
    /// there is not positive (never for a valid fiber).
    std::optional<DirectionSample> sample(const Prepared &q, float u0, float u1, float u2) const;
    /// The density of sample() per steradian of ω_i.
    float density(const Prepared &q, Vec3 wi) const;
    /// The same at (ω_o, h), preparing the fiber's point first (for tests).
    std::optional<DirectionSample> sample(Vec3 wo, float h, float u0, float u1, float u2) const;
    float pdf(Vec3 wi, Vec3 wo, float h) const;

    const ChiangFiber &fiber() const { return *fiber_; }
    int theta_o_nodes() const { return nodes_.count(); }
    int theta_i_cells() const { return cells_.count(); }
    /// ∫ M_p(θ_i | θ_o node r)·cos θ_i dθ_i: 1 without a tilt, not exactly 1 with one.
    double lobe_integral(int r, int p) const { return data_->integral[size_t(r) * 4 + size_t(p)]; }
    /// True when lobe p at θ_o node r draws θ_i from the fiber's cone sampler (see lobe_sampling).
    bool uses_cone(int r, int p) const { return data_->cone[size_t(r) * 4 + size_t(p)] != 0; }
    /// Bytes the tables hold (CDFs, guides, integrals).
    size_t memory_bytes() const;

  private:
    NearFieldTable() = default;
    struct Divergences {
        double table = 0, cone = 0;
    };
    Divergences divergences(int r, int p, float t_node) const;
    Status set_grid(int nodes, int cells);  // nodes_ equally spaced, ends included; cells_
    Status set_cdfs();                      // cdfs_ of data_->mass

    std::shared_ptr<const ChiangFiber> fiber_;
    std::shared_ptr<const NearFieldData> data_;
    ThetaRNodes nodes_;
    LongitudinalCells cells_;
    DiscreteCdfs cdfs_;  // row r·4 + p: data_->mass
    const float *edge(int row) const { return data_->edge.data() + size_t(row) * size_t(cells_.count() + 1); }
};

/// The near-field table as a sampler: for the table's fiber, or for a material whose inputs
/// vary per strand (then each hit's point is the strand's own, see NearFieldTable::prepare).
class NearFieldTableSampler final : public Sampler {
  public:
    explicit NearFieldTableSampler(std::shared_ptr<const NearFieldTable> table) : table_(std::move(table)) {}
    /// `strands`' own fiber must have the table's parameters (strategy.h checks it).
    NearFieldTableSampler(std::shared_ptr<const NearFieldTable> table, std::shared_ptr<const ChiangStrands> strands)
        : table_(std::move(table)), strands_(std::move(strands)) {}
    const ShadingModel *model() const override {
        return strands_ ? static_cast<const ShadingModel *>(strands_.get()) : &table_->fiber();
    }
    const SamplerPoint &at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const override;
    const NearFieldTable &table() const { return *table_; }

  private:
    std::shared_ptr<const NearFieldTable> table_;
    std::shared_ptr<const ChiangStrands> strands_;
};

}  // namespace hairis
