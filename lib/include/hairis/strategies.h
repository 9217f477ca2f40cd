// The four direction-sampling strategies behind one interface (strategy.h): uniform,
// analytic (Chiang's lobe sampling), gaussian (the seed's PDFs) and table (baked inverse CDFs).
#pragma once

#include <memory>

#include "hairis/chiang.h"
#include "hairis/expected.h"
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

/// The table strategy: a one-sample mixture of the direct table and the multiple table for
/// one n_h, (1 − w)·pdf_direct + w·pdf_multiple. Ignores h (the tables are far field).
class TableSampler final : public DirectionSampler {
  public:
    static Expected<TableSampler> create(const SamplingTables &tables, float multiple_weight, int n_h);
    StrategyKind kind() const override { return StrategyKind::Table; }
    std::optional<DirectionSample> sample(Vec3 wo, float h, float u0, float u1, float u2) const override;
    float pdf(Vec3 wi, Vec3 wo, float h) const override;

  private:
    explicit TableSampler(MixtureSampler mixture) : mixture_(std::move(mixture)) {}
    MixtureSampler mixture_;
};

/// What a strategy needs: the fiber for ANALYTIC (Chiang only), tables for TABLE, the seed's
/// parameters for GAUSSIAN, and the mixture weight and n_h for TABLE and GAUSSIAN.
struct StrategyInputs {
    std::shared_ptr<const ChiangFiber> chiang;
    const SamplingTables *tables = nullptr;
    SeedPdfParams seed;
    float multiple_weight = 0.25f;
    int n_h = 2;
};

/// Builds a strategy; the error names what is missing or out of range.
Expected<std::shared_ptr<const DirectionSampler>> make_sampler(StrategyKind kind, const StrategyInputs &inputs);

}  // namespace hairis
