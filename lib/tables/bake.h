// Baking: from a fiber model (or the seed's Gaussian PDFs) to the per-θ_r tables of a
// TableSet, ready to write as EXR or to build samplers from.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "fiber/dual_scattering.h"
#include "fiber/fiber.h"
#include "fiber/seed_pdfs.h"
#include "sampling/huang_table.h"
#include "sampling/table_set.h"

namespace hairis {

/// The resolution of a Huang table (sampling/huang_table.h): θ_o nodes, φ_o nodes, θ_i cells
/// and cells of φ_i − φ_o (HuangBakeOptions takes its defaults from here).
struct HuangResolution {
    int theta_o = 24;
    int phi_o = 4;
    int theta_i = 48;
    int phi = 64;
};

/// What to bake and at which resolution.
struct BakeOptions {
    int theta_r_count = 31;    ///< θ_r nodes at the centres of equal cells of [−π/2, π/2]
    int theta_i_count = 64;    ///< θ_i cells over [−π/2, π/2]
    int phi_count = 64;        ///< φ cells over [−π, π]
    int quadrature_points = 2; ///< Gauss–Legendre nodes per axis inside each cell
    std::vector<int> n_h_values = {1, 2, 4, 8, 16};
    std::string source = "exact";  ///< "exact" (the model's distributions) or "gaussian"
    SeedPdfParams seed;            ///< the seed's PDFs, for source "gaussian"
    int threads = 0;               ///< 0: all cores
    /// What a huang2022 fiber bakes instead of the direct tables: its Huang table at this
    /// resolution (source must be "exact", phi and quadrature_points are unused).
    HuangResolution huang;
    /// A huang2022 fiber's multiple part (theta_r × n_h × theta_i, for dual scattering); 0
    /// bakes its Huang table alone (faster, as the multiple part is the bake's longest step).
    bool huang_multiple = true;
    /// A huang2022 fiber's f part (huang_f_table.h): the baked expectation renders shade with;
    /// 0 leaves renders with Cycles' noisy one-sample eval.
    bool huang_f = true;
    /// Multiplies the Gauss orders of the f part's rule (HuangBakeOptions): the finer rule
    /// leaves less of the f part's error towards single lights and takes longer to bake.
    int huang_f_refinement = 1;
    /// A huang2022 fiber's absorption part (huang_absorption_table.h), with the f part: renders
    /// then shade strands of other absorption (Random Color, Hair Info) without Cycles' eval.
    bool huang_absorption = false;

    /// Names the first option out of range.
    Status validate() const;
};

/// The option names of BakeOptions (core/options.h's field descriptions).
template <typename Fields>
void describe(Fields &f, BakeOptions &o) {
    f.field("theta_r", o.theta_r_count, 1, kMaxThetaRNodes);
    f.field("theta_i", o.theta_i_count, 2, kMaxTableAxisCells);
    f.field("phi", o.phi_count, 1, kMaxTableAxisCells);
    f.field("n_h", o.n_h_values, 16, 1, 1024);
    f.field("source", o.source);
    f.field("quadrature_points", o.quadrature_points, 1, 16);
    f.field("threads", o.threads, 0, 1024);
    f.field("huang_multiple", o.huang_multiple);
    f.field("huang_f", o.huang_f);
    f.field("huang_f_refinement", o.huang_f_refinement, 1, kMaxHuangFRefinement);
    f.field("huang_absorption", o.huang_absorption);
    f.field("huang_theta_o", o.huang.theta_o, 1, kMaxThetaRNodes);
    f.field("huang_phi_o", o.huang.phi_o, 1, kMaxPhiONodes);
    f.field("huang_theta_i", o.huang.theta_i, 1, kMaxTableAxisCells);
    f.field("huang_phi", o.huang.phi, 1, kMaxTableAxisCells);
}

/// The θ_r nodes of a bake: centres of `count` equal cells of [−π/2, π/2]. The ends ±π/2
/// (a view along the fiber) are singular for both models, so no node sits there; a θ_r past
/// the outer nodes uses the outer node's slice.
std::vector<float> theta_r_nodes(int count);

/// Called with progress in [0, 1]; return false to cancel.
using ProgressFn = std::function<bool(float)>;

/// The multiple tables of θ_r at `theta_r` for options.n_h_values over options.theta_i_count
/// cells (TableSet::multiple's [k][i] of one θ_r node), from `dual`, into `out`.
Status bake_multiple_slice(const DualScattering &dual, double theta_r, const BakeOptions &options, float *out);

/// Bakes direct and multiple tables for `model` whose parameters are `parameters` (recorded
/// in the metadata); for a huang2022 fiber its Huang table alone, at options.huang's resolution
/// (bake_huang_tables). Deterministic: the same inputs give the same numbers for any thread
/// count. Returns an error naming the problem, or "cancelled".
Expected<TableSet> bake_tables(const FiberModel &model,
                               const std::vector<std::pair<std::string, double>> &parameters,
                               const BakeOptions &options, const ProgressFn &progress = {});

}  // namespace hairis
