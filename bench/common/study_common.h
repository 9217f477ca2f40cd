// Shared setup of the benchmarks and studies: the Cycles-default fiber, its default tables
// and every strategy built from them.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "tables/bake.h"
#include "fiber/fiber_spec.h"
#include "sampling/hair_bsdf.h"
#include "sampling/strategy.h"

namespace hairis::bench {

struct StudySetup {
    FiberSpec spec;
    std::shared_ptr<const ChiangFiber> fiber;
    TableSet tables;
    SamplingTables sampling;
};

inline StudySetup make_setup(const std::string &preset = "cycles-default", BakeOptions options = {}) {
    StudySetup s;
    s.spec = FiberSpec::preset(preset).value();
    s.fiber = std::make_shared<const ChiangFiber>(ChiangFiber::create(to_chiang_params(s.spec.node).value()).value());
    s.tables = bake_tables(*s.fiber, s.spec.parameters().value(), options).value();
    s.sampling = SamplingTables::from(s.tables).value();
    return s;
}

/// A strategy bound to its fiber, used as the renderer uses it: prepared at (ω_o, h), then
/// sampled or evaluated (one scratch buffer per thread).
class Strategy {
  public:
    Strategy(std::shared_ptr<const Sampler> sampler, std::shared_ptr<const ChiangFiber> fiber)
        : shading_(HairShading::create(std::move(fiber), sampler).value()) {}
    HairBsdf at(Vec3 wo, float h, ScratchBuffer &scratch) const { return shading_.at({wo, h}, scratch); }
    std::optional<BsdfSample> sample(Vec3 wo, float h, float u0, float u1, float u2) const {
        return at(wo, h, scratch()).sample(u0, u1, u2);
    }
    float pdf(Vec3 wi, Vec3 wo, float h) const { return at(wo, h, scratch()).pdf(wi); }

  private:
    static ScratchBuffer &scratch() {
        thread_local ScratchBuffer buffer;
        buffer.reset();
        return buffer;
    }
    HairShading shading_;
};

/// The strategies compared, with the label used in tables: the mixture weight w of the
/// multiple-scattering part is 0 for the "direct" variants.
struct NamedSampler {
    std::string name;
    std::shared_ptr<const Strategy> sampler;
};

inline std::vector<NamedSampler> all_samplers(const StudySetup &s, float mixture_weight = 0.25f, int n_h = 2) {
    // The near-field table is built once and shared by both table variants that use it.
    const auto near_field = std::make_shared<const NearFieldTable>(NearFieldTable::create(s.fiber).value());
    auto make = [&](StrategyKind kind, float w, bool near) {
        StrategyInputs in;
        in.chiang = kind == StrategyKind::Table && !near ? nullptr : s.fiber;
        in.tables = &s.sampling;
        in.multiple_weight = w;
        in.n_h = n_h;
        if (near) in.near_field = near_field;
        return std::make_shared<const Strategy>(make_sampler(kind, in).value(), s.fiber);
    };
    const std::string w = "w=" + std::to_string(mixture_weight).substr(0, 4);
    return {{"uniform", make(StrategyKind::Uniform, 0.0f, false)},
            {"analytic", make(StrategyKind::Analytic, 0.0f, false)},
            {"gaussian (w=0)", make(StrategyKind::Gaussian, 0.0f, false)},
            {"gaussian (" + w + ")", make(StrategyKind::Gaussian, mixture_weight, false)},
            {"table, far-field 2D (w=0)", make(StrategyKind::Table, 0.0f, false)},
            {"table, far-field 2D (" + w + ")", make(StrategyKind::Table, mixture_weight, false)},
            {"table, near-field (w=0)", make(StrategyKind::Table, 0.0f, true)},
            {"table, near-field (" + w + ")", make(StrategyKind::Table, mixture_weight, true)}};
}

}  // namespace hairis::bench
