// The seed's Gaussian PDFs as samplers (fiber/seed_pdfs.h): its direct-scattering PDF f_ds and
// its multiple-scattering PDF f_ms of one n_h. The "gaussian" strategy mixes the two.
#pragma once

#include "core/expected.h"
#include "fiber/seed_pdfs.h"
#include "sampling/sampler.h"

namespace hairis {

class SeedDirectSampler final : public Sampler {
  public:
    static Expected<SeedDirectSampler> create(const SeedPdfParams &params);
    const SamplerPoint &at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const override;

  private:
    explicit SeedDirectSampler(const SeedPdfParams &params) : params_(params) {}
    SeedPdfParams params_;
};

class SeedMultipleSampler final : public Sampler {
  public:
    /// Refuses an n_h without a σ in params (Table 1: 1, 2, 4, 8, 16).
    static Expected<SeedMultipleSampler> create(const SeedPdfParams &params, int n_h);
    const SamplerPoint &at(const FiberHit &hit, const FiberPoint *fiber, ScratchBuffer &scratch) const override;

  private:
    explicit SeedMultipleSampler(double sigma) : sigma_(sigma) {}
    double sigma_;
};

}  // namespace hairis
