// Baking a Huang table (sampling/huang_table.h) from a HuangFiber: per view node the cell
// averages of luminance(f·cos θ_i) over (θ_i, φ_i − φ_o) cells. The table only has to be a good
// density (its pdf is exact whatever its values), so f is evaluated cheaply: the expectation
// of Cycles' eval by a low-order rule, or Cycles' one-sample eval with fixed per-cell seeds
// (both deterministic; the second unbiased per cell). The resolution and evaluator defaults
// are the cheapest whose sampling variance a finer table no longer lowers.
#pragma once

#include <string>
#include <vector>

#include "core/expected.h"
#include "fiber/huang.h"
#include "sampling/huang_table.h"
#include "tables/bake.h"

namespace hairis {

/// How a Huang table is baked.
struct HuangBakeOptions {
    int theta_o_count = HuangResolution{}.theta_o;  ///< θ_o nodes at the centres of equal cells of [−π/2, π/2]
    /// φ_o nodes over [0, π/2], ends included (1: the node π/2). Circular fibers get one node.
    int phi_o_count = HuangResolution{}.phi_o;
    int theta_i_count = HuangResolution{}.theta_i;  ///< θ_i cells over [−π/2, π/2]
    int phi_count = HuangResolution{}.phi;          ///< cells of φ_i − φ_o over [−π, π]
    int points = 1;          ///< evaluation points per cell and axis (midpoints in sin θ_i and φ)
    /// "expectation" (HuangExpectation with the orders below) or "estimate" (Cycles' eval).
    std::string evaluator = "expectation";
    /// The expectation's rule (HuangQuadrature). TRT's internal reflection needs the finer
    /// rule: with few nodes its exit lobes sum to ripples that are right on average over the
    /// sphere but several percent off towards one light.
    int first_order = 3, second_order = 6;
    int estimates = 1;                      ///< Cycles evals per point ("estimate")
    int threads = 0;                        ///< 0: all cores
    /// Also bake the f part (huang_f_table.h): TT, TRT and TRRT+ of the expectation at the
    /// rule below, RGB, at each cell's midpoint.
    bool f = true;
    int f_first_order = 3, f_second_order = 6;  ///< the f part's rule (HuangQuadrature)
    /// TT's entry rule in both parts (HuangQuadrature::tt_order; 0: first_order): the brightest
    /// lobe needs a finer rule than TRT to be baked within a few percent at its peak.
    int f_tt_order = 8;
    /// Multiplies f_first_order, f_second_order and f_tt_order in the f part (the sampling
    /// part keeps its rule): TRT's two microfacets are the f part's largest error left.
    int f_refinement = 1;
    /// Also bake the absorption part (huang_absorption_table.h) at these absorption nodes
    /// (empty: none), with the f part's rule; it needs the f part.
    std::vector<float> absorption_nodes;

    /// Names the first option out of range.
    Status validate() const;
};

/// The φ_o nodes of a bake (see HuangBakeOptions::phi_o_count).
std::vector<float> huang_phi_o_nodes(int count);

/// Bakes the table of `fiber`. The same bytes for any thread count; progress as bake_tables'
/// (false cancels: Error "cancelled", ErrorKind::Cancelled).
Expected<HuangTableSet> bake_huang_table(const HuangFiber &fiber, const HuangBakeOptions &options = {},
                                         const ProgressFn &progress = {});

/// The dual-scattering averages of a Huang fiber (fiber/dual_scattering.h), as its tables'
/// multiple part and integrator=dual_scattering use them: f by the expectation rule (4, 3)
/// and a coarser quadrature than DualScatteringParams' default (16 θ nodes, 8 θ and 4 φ
/// panels), the coarsest whose averages the default quadrature no longer changes visibly, as
/// the default one costs too long per fiber. Runs on the calling thread's arena. Kept for the process by the
/// fiber's parameters (the last 16 fibers), so that a bake and the renders after it in one
/// process (the add-on's) compute them once.
Expected<std::shared_ptr<const DualScattering>> huang_dual_scattering(const HuangFiber &fiber);

/// The table set of a huang2022 fiber (table_set.h): its Huang table baked at options.huang's
/// resolution with options.threads, the default evaluator, and the fiber's parameters; with
/// options.huang_multiple, the multiple part at options.theta_r_count × n_h_values ×
/// theta_i_count from huang_dual_scattering. Refuses source "gaussian" (the seed's far-field
/// PDFs, which a Huang table set does not hold). Progress: the Huang table to 0.8, the averages
/// (not cancellable inside), then the multiple part.
Expected<TableSet> bake_huang_tables(const HuangFiber &fiber, const BakeOptions &options,
                                     const ProgressFn &progress = {});

}  // namespace hairis
