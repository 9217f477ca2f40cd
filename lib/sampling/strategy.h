// The strategy policy: which sampler draws ω_i for a hair material under each setting. This
// is the one place that decides; the renderer, the C API and the studies all ask here.
#pragma once

#include <memory>
#include <string>

#include "core/expected.h"
#include "fiber/chiang.h"
#include "fiber/chiang_strands.h"
#include "fiber/huang.h"
#include "fiber/huang_strands.h"
#include "fiber/seed_pdfs.h"
#include "sampling/hair_bsdf.h"
#include "sampling/huang_table.h"
#include "sampling/huang_tabulated_fiber.h"
#include "sampling/near_field_table.h"
#include "sampling/sampler.h"
#include "sampling/sampling_table.h"
#include "sampling/table_set.h"

namespace hairis {

/// The strategies hairis offers (the add-on's `strategy` setting, the C API's `strategy`).
enum class StrategyKind { Uniform = 0, Analytic = 1, Gaussian = 2, Table = 3 };

/// "uniform", "analytic", "gaussian" or "table".
const char *strategy_name(StrategyKind kind);

/// The baked tables of one fiber, ready to sample, and what they were baked for.
struct SamplingTables {
    std::shared_ptr<const DirectTable> direct;
    std::shared_ptr<const MultipleTable> multiple;
    std::string model;       ///< TableSet::model
    std::string parameters;  ///< canonical_parameters(TableSet::parameters)
    /// The near-field part (Chiang), or null.
    std::shared_ptr<const NearFieldData> near_field;
    /// The Huang table (huang2022 tables, which have no direct table and a multiple table only
    /// when baked for dual scattering), or null.
    std::shared_ptr<const HuangSamplingTable> huang;

    /// Builds the samplers' tables from a table set (validated here).
    static Expected<SamplingTables> from(const TableSet &tables);
};

/// A strategy and its settings, as the add-on and the C API give them.
struct SamplerOptions {
    int strategy = int(StrategyKind::Table);  ///< a StrategyKind
    /// Weight of the multiple-scattering part (TABLE, GAUSSIAN). 0: in a path tracer the
    /// multiple-scattering part only adds variance.
    float multiple_weight = 0.0f;
    int n_h = 2;
};

/// The option names of SamplerOptions (core/options.h's field descriptions).
template <typename Fields>
void describe(Fields &f, SamplerOptions &o) {
    f.choice("strategy", o.strategy, {"uniform", "analytic", "gaussian", "table"});
    f.field("multiple_weight", o.multiple_weight, 0.0, 1.0);
    f.field("n_h", o.n_h, 1, 1024);
}

/// The weight of the uniform sphere in TABLE's mixture for a Huang fiber: it keeps the density
/// positive wherever f is, also in cells the bake saw as zero.
inline constexpr float kHuangUniformWeight = 0.01f;

/// What a strategy may need.
struct StrategyInputs {
    /// The material's fiber: ANALYTIC samples it; TABLE samples its near field from it.
    std::shared_ptr<const ChiangFiber> chiang;
    /// A material whose inputs vary per strand (takes the place of `chiang`, which must then
    /// be null or its own fiber): ANALYTIC samples each strand's own fiber; TABLE samples the
    /// tables baked for the node's own values, following each strand as
    /// NearFieldTable::prepare says. The sampler's model() is then `strands`.
    std::shared_ptr<const ChiangStrands> strands;
    /// Baked tables (TABLE): they must have been baked for `chiang`'s parameters.
    const SamplingTables *tables = nullptr;
    /// The seed's PDFs (GAUSSIAN).
    SeedPdfParams seed;
    /// Weight of the multiple-scattering part (TABLE, GAUSSIAN), in [0, 1].
    float multiple_weight = SamplerOptions{}.multiple_weight;
    /// The multiple-scattering distribution's n_h (TABLE: one the tables hold; GAUSSIAN: 1, 2,
    /// 4, 8 or 16).
    int n_h = SamplerOptions{}.n_h;
    /// A near-field table to use instead of the tables' near-field part (studies of other
    /// resolutions; TABLE with a fiber).
    std::shared_ptr<const NearFieldTable> near_field;
    /// A Huang fiber instead of `chiang`: TABLE samples `huang_table`, UNIFORM and GAUSSIAN
    /// work as for any fiber, ANALYTIC is refused.
    std::shared_ptr<const HuangFiber> huang;
    /// The Huang table (TABLE with `huang`): it must have been baked for `huang`'s parameters.
    /// Null: the Huang part of `tables`, if they have one.
    std::shared_ptr<const HuangSamplingTable> huang_table;
    /// A Huang material whose inputs vary per strand (its fiber must be `huang`): TABLE's
    /// baked f then serves the strands as huang_tabulated_fiber.h says.
    std::shared_ptr<const HuangStrands> huang_strands;
    /// How the baked f serves strands whose inputs differ (huang_tabulated_fiber.h).
    StrandShading huang_strand_shading = StrandShading::ControlVariate;
    /// TABLE with `huang`: the uniform sphere's weight in the mixture, in [0, 1).
    float huang_uniform_weight = kHuangUniformWeight;
};

/// The sampler of `kind`:
///   UNIFORM   the sphere;
///   ANALYTIC  Chiang's lobe sampling (needs the fiber);
///   GAUSSIAN  (1 − w)·seed direct + w·seed multiple(n_h);
///   TABLE     (1 − w)·single + w·multiple table(n_h), single = the tables' near-field part
///             for the fiber when a fiber is given, else the tables' far-field direct table;
///             with a Huang fiber (1 − u)·Huang table + u·uniform, u = huang_uniform_weight,
///             and w must be 0 (a path tracer samples the single-fiber f, which the
///             multiple-scattering table does not describe).
/// ANALYTIC with a Huang fiber is refused: Huang has no sampler with a known density.
/// Errors name what is missing or out of range; tables baked for another fiber, or without
/// n_h, are refused with ErrorKind::InvalidTable.
Expected<std::shared_ptr<const Sampler>> make_sampler(StrategyKind kind, const StrategyInputs &inputs);

/// What a hair material shades with under `kind`: make_sampler's sampler and the fiber model
/// whose f weights its samples. TABLE for a Huang fiber whose table holds the baked f shades
/// with that f (HuangTabulatedFiber: Cycles' expectation without its noise); every other case
/// shades with `model` (the material's fiber, or null for samplers that read none).
Expected<HairShading> make_hair_shading(StrategyKind kind, const StrategyInputs &inputs,
                                        std::shared_ptr<const ShadingModel> model);

}  // namespace hairis
