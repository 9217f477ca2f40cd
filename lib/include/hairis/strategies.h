// The four direction-sampling strategies behind one interface (strategy.h): uniform,
// analytic (Chiang's lobe sampling), gaussian (the seed's PDFs) and table (baked inverse CDFs).
#pragma once

#include <memory>

#include "hairis/chiang.h"
#include "hairis/expected.h"
#include "hairis/near_field_table.h"
#include "hairis/sampling_table.h"
#include "hairis/seed_pdfs.h"
#include "hairis/strategy.h"
#include "hairis/table_file.h"

namespace hairis {

/// Uniform over the sphere: pdf 1/(4π).
class UniformSampler final : public DirectionSampler {
  public:
    StrategyKind kind() const override { return StrategyKind::Uniform; }
    std::optional<DirectionSample> sample(Vec3 wo, float h, float u0, float u1, float u2) const override;
    float pdf(Vec3 wi, Vec3 wo, float h) const override;
};

/// Chiang 2016 lobe sampling (as Cycles and pbrt sample, with the exact pdf of chiang.h).
class AnalyticSampler final : public DirectionSampler {
  public:
    explicit AnalyticSampler(std::shared_ptr<const ChiangFiber> fiber) : fiber_(std::move(fiber)) {}
    StrategyKind kind() const override { return StrategyKind::Analytic; }
    std::optional<DirectionSample> sample(Vec3 wo, float h, float u0, float u1, float u2) const override;
    float pdf(Vec3 wi, Vec3 wo, float h) const override;
    /// The fiber sampled: a renderer can take f·cos from ChiangFiber::sample instead of
    /// evaluating it again.
    const ChiangFiber &fiber() const { return *fiber_; }

  private:
    std::shared_ptr<const ChiangFiber> fiber_;
};

/// The baked tables of one fiber, ready to sample.
struct SamplingTables {
    std::shared_ptr<const DirectTable> direct;
    std::shared_ptr<const MultipleTable> multiple;

    /// Builds the samplers from a validated table set.
    static Expected<SamplingTables> from(const TableSet &tables);
};

/// The table strategy: a one-sample mixture (1 − w)·pdf_single + w·pdf_multiple of a
/// single-scattering part and the multiple table for one n_h. The single-scattering part is
/// the near-field table (near_field_table.h) when one is given — what a renderer shading
/// Chiang's near field wants — and otherwise the far-field direct table, which ignores h.
class TableSampler final : public DirectionSampler {
  public:
    static Expected<TableSampler> create(const SamplingTables &tables, float multiple_weight, int n_h,
                                         std::shared_ptr<const NearFieldTable> near_field = nullptr);
    StrategyKind kind() const override { return StrategyKind::Table; }
    std::optional<DirectionSample> sample(Vec3 wo, float h, float u0, float u1, float u2) const override;
    float pdf(Vec3 wi, Vec3 wo, float h) const override;
    /// The near-field table, or null when the far-field direct table is used.
    const NearFieldTable *near_field() const { return near_.get(); }

  private:
    TableSampler(MixtureSampler mixture, std::shared_ptr<const NearFieldTable> near_field)
        : mixture_(std::move(mixture)), near_(std::move(near_field)) {}
    MixtureSampler mixture_;
    std::shared_ptr<const NearFieldTable> near_;
    int strand_ = 0;
};

/// What a strategy needs: the fiber for ANALYTIC (Chiang only), tables for TABLE, the seed's
/// parameters for GAUSSIAN, and the mixture weight and n_h for TABLE and GAUSSIAN.
struct StrategyInputs {
    /// For ANALYTIC; with TABLE, a Chiang fiber also gets the near-field table (built from
    /// it unless near_field is given).
    std::shared_ptr<const ChiangFiber> chiang;
    const SamplingTables *tables = nullptr;
    SeedPdfParams seed;
    /// 0: in a path tracer the multiple-scattering part only adds variance
    /// (bench/results/mixture_weight.md).
    float multiple_weight = 0.0f;
    int n_h = 2;
    /// A near-field table to share between samplers (TABLE with a Chiang fiber).
    std::shared_ptr<const NearFieldTable> near_field;
};

/// Builds a strategy; the error names what is missing or out of range.
Expected<std::shared_ptr<const DirectionSampler>> make_sampler(StrategyKind kind, const StrategyInputs &inputs);

}  // namespace hairis
