#include "hairis/strategies.h"

#include "hairis/frame.h"

namespace hairis {

const char *strategy_name(StrategyKind kind) {
    switch (kind) {
        case StrategyKind::Uniform: return "uniform";
        case StrategyKind::Analytic: return "analytic";
        case StrategyKind::Gaussian: return "gaussian";
        case StrategyKind::Table: return "table";
    }
    return "unknown";
}

std::optional<DirectionSample> UniformSampler::sample(Vec3, float, float u0, float u1, float) const {
    const float x = 1.0f - 2.0f * u0;
    const float r = std::sqrt(std::max(0.0f, 1.0f - x * x));
    const float phi = float(kTwoPi) * u1;
    return DirectionSample{{x, r * std::cos(phi), r * std::sin(phi)}, float(kInvFourPi)};
}

float UniformSampler::pdf(Vec3, Vec3, float) const { return float(kInvFourPi); }

std::optional<DirectionSample> AnalyticSampler::sample(Vec3 wo, float h, float u0, float u1, float u2) const {
    std::optional<ChiangSample> s = fiber_->sample(wo, h, u0, u1, u2);
    if (!s || !(s->pdf > 0.0f)) return std::nullopt;
    return DirectionSample{s->wi, s->pdf};
}

float AnalyticSampler::pdf(Vec3 wi, Vec3 wo, float h) const { return fiber_->pdf(wi, wo, h); }

Expected<SamplingTables> SamplingTables::from(const TableSet &t) {
    if (Status s = t.validate()) return *s;
    Expected<DirectTable> direct = DirectTable::create(t.theta_r_nodes, t.theta_i_count, t.phi_count, t.direct);
    if (!direct) return Error{"direct table: " + direct.error().message};
    Expected<MultipleTable> multiple = MultipleTable::create(t.theta_r_nodes, t.n_h_values, t.theta_i_count, t.multiple);
    if (!multiple) return Error{"multiple table: " + multiple.error().message};
    return SamplingTables{std::make_shared<const DirectTable>(std::move(direct).value()),
                          std::make_shared<const MultipleTable>(std::move(multiple).value())};
}

Expected<TableSampler> TableSampler::create(const SamplingTables &tables, float multiple_weight, int n_h) {
    Expected<MixtureSampler> m = MixtureSampler::create(tables.direct, tables.multiple, n_h, multiple_weight);
    if (!m) return m.error();
    return TableSampler(std::move(m).value());
}

std::optional<DirectionSample> TableSampler::sample(Vec3 wo, float, float u0, float u1, float u2) const {
    const FiberAngles o = angles_of(wo);
    const TableSample s = mixture_.sample(o.theta, u0, u1, u2);
    if (!(s.pdf > 0.0f)) return std::nullopt;
    return DirectionSample{s.local_direction(o.phi), s.pdf};
}

float TableSampler::pdf(Vec3 wi, Vec3 wo, float) const {
    const FiberAngles o = angles_of(wo);
    const float phi_i = std::atan2(wi.z, wi.y);
    return mixture_.pdf_sin(o.theta, wi.x, relative_azimuth(phi_i, o.phi));
}

Expected<std::shared_ptr<const DirectionSampler>> make_sampler(StrategyKind kind, const StrategyInputs &in) {
    switch (kind) {
        case StrategyKind::Uniform:
            return std::shared_ptr<const DirectionSampler>(std::make_shared<UniformSampler>());
        case StrategyKind::Analytic:
            if (!in.chiang) return Error{"the analytic strategy needs a Chiang (Principled Hair) fiber"};
            return std::shared_ptr<const DirectionSampler>(std::make_shared<AnalyticSampler>(in.chiang));
        case StrategyKind::Gaussian: {
            Expected<GaussianSampler> g = GaussianSampler::create(in.seed, in.multiple_weight, in.n_h);
            if (!g) return g.error();
            return std::shared_ptr<const DirectionSampler>(std::make_shared<GaussianSampler>(std::move(g).value()));
        }
        case StrategyKind::Table: {
            if (!in.tables || !in.tables->direct || !in.tables->multiple)
                return Error{"the table strategy needs baked tables (none were given)"};
            Expected<TableSampler> t = TableSampler::create(*in.tables, in.multiple_weight, in.n_h);
            if (!t) return t.error();
            return std::shared_ptr<const DirectionSampler>(std::make_shared<TableSampler>(std::move(t).value()));
        }
    }
    return Error{"strategy must be uniform, analytic, gaussian or table"};
}

}  // namespace hairis
