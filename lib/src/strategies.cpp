#include "hairis/strategies.h"

#include <algorithm>

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
    const float x = off_axis(1.0f - 2.0f * u0);
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

Expected<TableSampler> TableSampler::create(const SamplingTables &tables, float multiple_weight, int n_h,
                                            std::shared_ptr<const NearFieldTable> near_field) {
    Expected<MixtureSampler> m = MixtureSampler::create(tables.direct, tables.multiple, n_h, multiple_weight);
    if (!m) return m.error();
    TableSampler sampler(std::move(m).value(), std::move(near_field));
    sampler.strand_ = tables.multiple->strand_index(n_h);
    return sampler;
}

std::optional<DirectionSample> TableSampler::sample(Vec3 wo, float h, float u0, float u1, float u2) const {
    if (!near_) {
        const FiberAngles o = angles_of(wo);
        const TableSample s = mixture_.sample(o.theta, u0, u1, u2);
        if (!(s.pdf > 0.0f)) return std::nullopt;
        return DirectionSample{s.local_direction(o.phi), s.pdf};
    }
    // u2 first chooses the part, then is reused inside it. The near field's per-point work
    // is shared between its sample and its density.
    const float w = mixture_.multiple_weight();
    const NearFieldTable::Prepared q = near_->prepare(wo, h);
    const float theta_o = q.theta_o;
    if (u2 < w) {
        const TableSample s = mixture_.multiple().sample(strand_, theta_o, u0, u1, u2 / w);
        if (!(s.pdf > 0.0f)) return std::nullopt;
        const Vec3 wi = s.local_direction(std::atan2(wo.z, wo.y));
        const float density = (1.0f - w) * near_->density(q, wi) + w * s.pdf;
        if (!(density > 0.0f) || !std::isfinite(density)) return std::nullopt;
        return DirectionSample{wi, density};
    }
    const float rest = std::min((u2 - w) / (1.0f - w), kOneMinusEpsilon);
    const std::optional<NearFieldSample> s = near_->sample(q, u0, u1, rest);
    if (!s) return std::nullopt;
    const float multiple = w > 0.0f ? mixture_.multiple().pdf_sin(strand_, theta_o, s->wi.x) : 0.0f;
    const float density = (1.0f - w) * s->pdf + w * multiple;
    if (!(density > 0.0f) || !std::isfinite(density)) return std::nullopt;
    return DirectionSample{s->wi, density};
}

float TableSampler::pdf(Vec3 wi, Vec3 wo, float h) const {
    if (!near_) {
        const FiberAngles o = angles_of(wo);
        const float phi_i = std::atan2(wi.z, wi.y);
        return mixture_.pdf_sin(o.theta, wi.x, relative_azimuth(phi_i, o.phi));
    }
    const float w = mixture_.multiple_weight();
    const NearFieldTable::Prepared q = near_->prepare(wo, h);
    const float single = w < 1.0f ? near_->density(q, wi) : 0.0f;
    const float multiple = w > 0.0f ? mixture_.multiple().pdf_sin(strand_, q.theta_o, wi.x) : 0.0f;
    return (1.0f - w) * single + w * multiple;
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
            std::shared_ptr<const NearFieldTable> near_field = in.near_field;
            if (!near_field && in.chiang) {
                Expected<NearFieldTable> made = NearFieldTable::create(in.chiang);
                if (!made) return Error{"near-field table: " + made.error().message};
                near_field = std::make_shared<const NearFieldTable>(std::move(made).value());
            }
            Expected<TableSampler> t = TableSampler::create(*in.tables, in.multiple_weight, in.n_h, near_field);
            if (!t) return t.error();
            return std::shared_ptr<const DirectionSampler>(std::make_shared<TableSampler>(std::move(t).value()));
        }
    }
    return Error{"strategy must be uniform, analytic, gaussian or table"};
}

}  // namespace hairis
