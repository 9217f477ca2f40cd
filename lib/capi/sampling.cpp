// C API: direction samplers (strategies.h) and their batch sample/pdf loops.
#include <string>

#include "capi_internal.h"

namespace hairis::capi {

namespace {

const char *strategy_c_name(int strategy) {
    switch (strategy) {
        case HAIRIS_STRATEGY_UNIFORM: return "UNIFORM";
        case HAIRIS_STRATEGY_ANALYTIC: return "ANALYTIC";
        case HAIRIS_STRATEGY_GAUSSIAN: return "GAUSSIAN";
        case HAIRIS_STRATEGY_TABLE: return "TABLE";
        default: return "?";
    }
}

// Checks wo (unit), h (NULL or in [-1, 1]) for item i.
void check_view(const float *wo, const float *h, size_t i) {
    require_unit_direction(wo, "wo", i);
    if (h && !(h[i] >= -1.0f && h[i] <= 1.0f))
        invalid(indexed("h", i) + " must be finite and in [-1, 1] (got " + describe(h[i]) + ")");
}

}  // namespace

}  // namespace hairis::capi

using namespace hairis;
using namespace hairis::capi;

extern "C" {

HAIRIS_API hairis_sampler *hairis_sampler_create(hairis_strategy strategy,
                                                 const hairis_fiber *fiber,
                                                 const hairis_tables *tables,
                                                 float multiple_weight, int n_h) {
    return guard_handle<hairis_sampler>("hairis_sampler_create", [&] {
        const int kind = enum_value(strategy);
        if (kind < HAIRIS_STRATEGY_UNIFORM || kind > HAIRIS_STRATEGY_TABLE)
            invalid("strategy must be HAIRIS_STRATEGY_UNIFORM (0), ANALYTIC (1), GAUSSIAN (2) or "
                    "TABLE (3) (got " + std::to_string(kind) + ")");
        if (!(multiple_weight >= 0.0f && multiple_weight <= 1.0f))
            invalid("multiple_weight must be finite and in [0, 1] (got " +
                    describe(multiple_weight) + ")");
        StrategyInputs inputs;
        inputs.multiple_weight = multiple_weight;
        inputs.n_h = n_h;
        if (kind == HAIRIS_STRATEGY_ANALYTIC) {
            if (!fiber)
                invalid("fiber must not be NULL for HAIRIS_STRATEGY_ANALYTIC (it samples the "
                        "fiber's own lobes)");
            if (!fiber->chiang)
                invalid("fiber must be a chiang2016 fiber for HAIRIS_STRATEGY_ANALYTIC (got " +
                        fiber->model_name + ")");
            inputs.chiang = fiber->chiang;
        }
        if (kind == HAIRIS_STRATEGY_TABLE) {
            if (!tables) invalid("tables must not be NULL for HAIRIS_STRATEGY_TABLE");
            inputs.tables = &tables->sampling;  // make_sampler copies the shared_ptrs
            // With a Chiang fiber the sampler follows the near field at h (near_field_table.h);
            // without one it samples the h-averaged direct table.
            if (fiber && fiber->chiang) inputs.chiang = fiber->chiang;
        }
        if (kind == HAIRIS_STRATEGY_GAUSSIAN || kind == HAIRIS_STRATEGY_TABLE) {
            const std::vector<int> &allowed = kind == HAIRIS_STRATEGY_TABLE
                                                  ? tables->set.n_h_values
                                                  : inputs.seed.n_h_values;
            bool found = false;
            std::string list;
            for (int v : allowed) {
                found = found || v == n_h;
                list += (list.empty() ? "" : ", ") + std::to_string(v);
            }
            if (!found)
                invalid("n_h must be one of " + list +
                        (kind == HAIRIS_STRATEGY_TABLE ? " (the tables' n_h values)"
                                                       : " (the seed's n_h values)") +
                        " for HAIRIS_STRATEGY_" + strategy_c_name(kind) + " (got " +
                        std::to_string(n_h) + ")");
        }
        Expected<std::shared_ptr<const DirectionSampler>> made =
            make_sampler(StrategyKind(kind), inputs);
        if (!made) invalid(made.error().message);
        auto sampler = std::make_unique<hairis_sampler>();
        sampler->sampler = std::move(made).value();
        return sampler.release();
    });
}

HAIRIS_API void hairis_sampler_destroy(hairis_sampler *sampler) {
    guard_void("hairis_sampler_destroy", [&] { delete sampler; });
}

HAIRIS_API int hairis_sample(const hairis_sampler *sampler, size_t n, const float *wo,
                             const float *h, const float *u, float *wi_out, float *pdf_out) {
    return guard_status("hairis_sample", [&] {
        require(sampler, "sampler");
        require_batch_size(n, 3, "n");
        require_array(wo, n, "wo");
        require_array(u, n, "u");
        require_array(wi_out, n, "wi_out");
        require_array(pdf_out, n, "pdf_out");
        for (size_t i = 0; i < n; ++i) {
            check_view(wo, h, i);
            for (size_t k = 0; k < 3; ++k) {
                const float v = u[3 * i + k];
                if (!(v >= 0.0f && v < 1.0f))
                    invalid(indexed("u", 3 * i + k) + " must be in [0, 1) (got " + describe(v) +
                            ")");
            }
        }
        const DirectionSampler &s = *sampler->sampler;
        for_each_item(n, [&](size_t i) {
            const Vec3 o{wo[3 * i], wo[3 * i + 1], wo[3 * i + 2]};
            const std::optional<DirectionSample> d =
                s.sample(o, h ? h[i] : 0.0f, u[3 * i], u[3 * i + 1], u[3 * i + 2]);
            const bool ok = d && d->pdf > 0.0f;
            const Vec3 w = ok ? d->wi : Vec3{};
            wi_out[3 * i] = w.x;
            wi_out[3 * i + 1] = w.y;
            wi_out[3 * i + 2] = w.z;
            pdf_out[i] = ok ? d->pdf : 0.0f;
        });
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_pdf(const hairis_sampler *sampler, size_t n, const float *wi,
                          const float *wo, const float *h, float *pdf_out) {
    return guard_status("hairis_pdf", [&] {
        require(sampler, "sampler");
        require_batch_size(n, 3, "n");
        require_array(wi, n, "wi");
        require_array(wo, n, "wo");
        require_array(pdf_out, n, "pdf_out");
        for (size_t i = 0; i < n; ++i) {
            require_unit_direction(wi, "wi", i);
            check_view(wo, h, i);
        }
        const DirectionSampler &s = *sampler->sampler;
        for_each_item(n, [&](size_t i) {
            const Vec3 a{wi[3 * i], wi[3 * i + 1], wi[3 * i + 2]};
            const Vec3 o{wo[3 * i], wo[3 * i + 1], wo[3 * i + 2]};
            pdf_out[i] = s.pdf(a, o, h ? h[i] : 0.0f);
        });
        return HAIRIS_OK;
    });
}

}  // extern "C"
