#include "sampling/strategy.h"

#include <algorithm>

#include "fiber/fiber_spec.h"
#include "sampling/analytic_sampler.h"
#include "sampling/huang_table_sampler.h"
#include "sampling/mixture_sampler.h"
#include "sampling/seed_samplers.h"
#include "sampling/table_samplers.h"
#include "sampling/uniform_sampler.h"

namespace hairis {

namespace {

std::string join(const std::vector<int> &values) {
    std::string out;
    for (int v : values) out += (out.empty() ? "" : ", ") + std::to_string(v);
    return out;
}

template <typename T>
Expected<std::shared_ptr<const Sampler>> shared(Expected<T> made) {
    if (!made) return made.error();
    return std::shared_ptr<const Sampler>(std::make_shared<const T>(std::move(made).value()));
}

Expected<std::shared_ptr<const Sampler>> mixture(Expected<std::shared_ptr<const Sampler>> single,
                                                 Expected<std::shared_ptr<const Sampler>> multiple, float w) {
    if (!single) return single.error();
    if (!multiple) return multiple.error();
    return shared(MixtureSampler::create(std::move(single).value(), std::move(multiple).value(), w));
}

Error table_error(std::string message) { return Error{std::move(message), ErrorKind::InvalidTable}; }

// The Huang table TABLE samples for `in`, checked against the fiber.
Expected<std::shared_ptr<const HuangSamplingTable>> huang_table_of(const StrategyInputs &in) {
    if (Status s = check::in_range("huang_uniform_weight", in.huang_uniform_weight, 0.0, 1.0)) return *s;
    if (!(in.huang_uniform_weight < 1.0f))
        return Error{"huang_uniform_weight must be below 1 (got 1): the table would never be sampled"};
    if (in.multiple_weight > 0.0f)
        return Error{"multiple_weight must be 0 for a Huang fiber (got " + std::to_string(in.multiple_weight) +
                     "): the multiple-scattering table is not part of the single-fiber f a path tracer samples"};
    const std::string parameters = canonical_parameters(huang_parameters(in.huang->params()));
    std::shared_ptr<const HuangSamplingTable> table = in.huang_table;
    if (!table && in.tables) {
        if (!in.tables->huang)
            return table_error("the tables were baked for " + in.tables->model + " \"" + in.tables->parameters +
                               "\", not for " + in.huang->name() + " \"" + parameters + "\"; bake tables for this fiber");
        table = in.tables->huang;
    }
    if (!table || !table->table)
        return table_error("the table strategy for a Huang fiber needs a baked Huang table (none was given)");
    if (table->parameters != parameters)
        return table_error("the Huang table was baked for \"" + table->parameters + "\", not for " +
                           in.huang->name() + " \"" + parameters + "\"; bake a table for this fiber");
    return table;
}

// TABLE for a Huang fiber: its baked table, mixed with the uniform sphere; for the points of
// `tabulated` when given (the fiber shaded with the table's f).
Expected<std::shared_ptr<const Sampler>> huang_table_sampler(const StrategyInputs &in,
                                                             std::shared_ptr<const HuangTabulatedFiber> tabulated = nullptr) {
    Expected<std::shared_ptr<const HuangSamplingTable>> table = huang_table_of(in);
    if (!table) return table.error();
    auto uniform = std::shared_ptr<const Sampler>(std::make_shared<const UniformSampler>());
    if (tabulated) return mixture(shared(HuangTableSampler::create(std::move(tabulated))), uniform, in.huang_uniform_weight);
    return mixture(shared(HuangTableSampler::create(in.huang, table.value()->table)), uniform, in.huang_uniform_weight);
}

}  // namespace

const char *strategy_name(StrategyKind kind) {
    switch (kind) {
        case StrategyKind::Uniform: return "uniform";
        case StrategyKind::Analytic: return "analytic";
        case StrategyKind::Gaussian: return "gaussian";
        case StrategyKind::Table: return "table";
    }
    return "unknown";
}

Expected<SamplingTables> SamplingTables::from(const TableSet &t) {
    if (Status s = t.validate()) return Error{s->message, ErrorKind::InvalidTable};
    if (t.huang) {
        Expected<HuangSamplingTable> huang = HuangSamplingTable::from(*t.huang);
        if (!huang) return table_error("Huang table: " + huang.error().message);
        SamplingTables out;
        out.model = t.model;
        out.parameters = canonical_parameters(t.parameters);
        out.huang = std::make_shared<const HuangSamplingTable>(std::move(huang).value());
        if (t.has_multiple()) {
            Expected<MultipleTable> multiple = MultipleTable::create(t.theta_r_nodes, t.n_h_values, t.theta_i_count, t.multiple);
            if (!multiple) return table_error("multiple table: " + multiple.error().message);
            out.multiple = std::make_shared<const MultipleTable>(std::move(multiple).value());
        }
        return out;
    }
    Expected<DirectTable> direct = DirectTable::create(t.theta_r_nodes, t.theta_i_count, t.phi_count, t.direct);
    if (!direct) return table_error("direct table: " + direct.error().message);
    Expected<MultipleTable> multiple = MultipleTable::create(t.theta_r_nodes, t.n_h_values, t.theta_i_count, t.multiple);
    if (!multiple) return table_error("multiple table: " + multiple.error().message);
    return SamplingTables{std::make_shared<const DirectTable>(std::move(direct).value()),
                          std::make_shared<const MultipleTable>(std::move(multiple).value()), t.model,
                          canonical_parameters(t.parameters), t.near_field, nullptr};
}

Expected<std::shared_ptr<const Sampler>> make_sampler(StrategyKind kind, const StrategyInputs &input) {
    if (Status s = check::in_range("multiple_weight", input.multiple_weight, 0.0, 1.0)) return *s;
    if ((input.chiang || input.strands) && input.huang) return Error{"give either a Chiang or a Huang fiber, not both"};
    if (input.strands && input.chiang && input.chiang != input.strands->fiber())
        return Error{"strategy inputs: chiang must be null or the strands' own fiber"};
    StrategyInputs in = input;
    if (in.strands) in.chiang = in.strands->fiber();
    switch (kind) {
        case StrategyKind::Uniform:
            return std::shared_ptr<const Sampler>(std::make_shared<const UniformSampler>());
        case StrategyKind::Analytic:
            if (in.huang)
                return Error{"the analytic strategy has no exact sampler for a Huang fiber (Cycles' own Huang sampler "
                             "has no density); use table (with a baked Huang table), uniform or gaussian"};
            if (in.strands) return std::shared_ptr<const Sampler>(std::make_shared<const AnalyticSampler>(in.strands));
            if (!in.chiang) return Error{"the analytic strategy needs a Chiang (Principled Hair) fiber"};
            return std::shared_ptr<const Sampler>(std::make_shared<const AnalyticSampler>(in.chiang));
        case StrategyKind::Gaussian:
            return mixture(shared(SeedDirectSampler::create(in.seed)), shared(SeedMultipleSampler::create(in.seed, in.n_h)),
                           in.multiple_weight);
        case StrategyKind::Table: {
            if (in.huang) return huang_table_sampler(in);
            if (in.tables && in.tables->huang)
                return table_error("the tables are huang2022 tables (\"" + in.tables->parameters +
                                   "\"), which only a Huang fiber samples" +
                                   (in.chiang ? "; bake tables for this " + in.chiang->name() + " fiber" : std::string()));
            if (!in.tables || !in.tables->direct || !in.tables->multiple)
                return table_error("the table strategy needs baked tables (none were given)");
            const SamplingTables &t = *in.tables;
            if (in.chiang) {
                const std::string parameters = canonical_parameters(chiang_parameters(in.chiang->params()));
                if (t.model != in.chiang->name() || t.parameters != parameters)
                    return table_error("the tables were baked for " + t.model + " \"" + t.parameters + "\", not for " +
                                       in.chiang->name() + " \"" + parameters + "\"; bake tables for this fiber");
            }
            if (t.multiple->strand_index(in.n_h) < 0)
                return table_error("the tables hold n_h " + join(t.multiple->n_h_values()) + ", not n_h = " +
                                   std::to_string(in.n_h));
            Expected<std::shared_ptr<const Sampler>> single =
                std::shared_ptr<const Sampler>(std::make_shared<const FarTableSampler>(t.direct));
            if (in.chiang) {
                std::shared_ptr<const NearFieldTable> near_field = in.near_field;
                if (!near_field) {
                    // From the tables' data alone: nothing is tabulated from the fiber here.
                    if (!t.near_field)
                        return table_error("the tables have no near-field part (they were not baked for a Chiang "
                                           "fiber); bake tables for this fiber");
                    Expected<NearFieldTable> made = NearFieldTable::from_data(in.chiang, t.near_field);
                    if (!made) return table_error(made.error().message);
                    near_field = std::make_shared<const NearFieldTable>(std::move(made).value());
                }
                single = in.strands ? std::shared_ptr<const Sampler>(
                                          std::make_shared<const NearFieldTableSampler>(near_field, in.strands))
                                    : std::shared_ptr<const Sampler>(
                                          std::make_shared<const NearFieldTableSampler>(near_field));
            }
            return mixture(std::move(single), shared(MultipleTableSampler::create(t.multiple, in.n_h)),
                           in.multiple_weight);
        }
    }
    return Error{"strategy must be uniform, analytic, gaussian or table"};
}

Expected<HairShading> make_hair_shading(StrategyKind kind, const StrategyInputs &inputs,
                                        std::shared_ptr<const ShadingModel> model) {
    if (kind == StrategyKind::Table && inputs.huang) {
        Expected<std::shared_ptr<const HuangSamplingTable>> table = huang_table_of(inputs);
        if (!table) return table.error();
        if (table.value()->f) {
            Expected<HuangTabulatedFiber> tabulated = HuangTabulatedFiber::create(inputs.huang, table.value(), inputs.huang_strands,
                                                                                  inputs.huang_strand_shading);
            if (!tabulated) return tabulated.error();
            auto shared_model = std::make_shared<const HuangTabulatedFiber>(std::move(tabulated).value());
            Expected<std::shared_ptr<const Sampler>> sampler = huang_table_sampler(inputs, shared_model);
            if (!sampler) return sampler.error();
            return HairShading::create(std::move(shared_model), std::move(sampler).value());
        }
    }
    Expected<std::shared_ptr<const Sampler>> sampler = make_sampler(kind, inputs);
    if (!sampler) return sampler.error();
    return HairShading::create(std::move(model), std::move(sampler).value());
}

}  // namespace hairis
