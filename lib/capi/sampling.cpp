// C API: direction samplers (sampling/strategy.h chooses them) and their batch sample/pdf
// loops, each item prepared at its own hit.
#include <string>

#include "capi_internal.h"

namespace hairis::capi {

// The BSDF of one batch item (thread-local scratch: for_each_item may run in parallel).
HairBsdf bsdf_at(const hairis_sampler &sampler, const float *wo, const float *h, size_t i) {
    thread_local ScratchBuffer scratch;
    scratch.reset();
    return sampler.shading.at({vec3_at(wo, i), h ? h[i] : 0.0f}, scratch);
}

}  // namespace hairis::capi

using namespace hairis;
using namespace hairis::capi;

extern "C" {

HAIRIS_API hairis_sampler *hairis_sampler_create(const hairis_fiber *fiber, const hairis_tables *tables,
                                                 const char *options) {
    return guard_handle<hairis_sampler>("hairis_sampler_create", [&] {
        SamplerOptions o;
        read_options(options, "sampler options", o);
        const StrategyKind kind = StrategyKind(o.strategy);
        StrategyInputs inputs;
        inputs.multiple_weight = o.multiple_weight;
        inputs.n_h = o.n_h;
        if (kind == StrategyKind::Analytic) {
            if (!fiber) invalid("fiber must not be NULL for strategy=analytic (it samples the fiber's own lobes)");
            if (!fiber->chiang)
                invalid("fiber must be a chiang2016 fiber for strategy=analytic (got " + fiber->model_name + ")");
        }
        if (kind == StrategyKind::Table && !tables)
            refuse(HAIRIS_ERROR_INVALID_TABLE, "tables must not be NULL for strategy=table");
        if (kind == StrategyKind::Table && fiber && fiber->huang) {
            // A Huang fiber's table sampler reads its points: it needs the fiber.
            inputs.huang = fiber->huang;
            inputs.tables = &tables->sampling;
            Expected<HairShading> shading = make_hair_shading(kind, inputs, fiber->huang);
            if (!shading) refuse(code_of(shading.error().kind), "sampler options: " + shading.error().message);
            return new hairis_sampler{std::move(shading).value()};
        }
        if (kind == StrategyKind::Analytic || kind == StrategyKind::Table) inputs.chiang = fiber ? fiber->chiang : nullptr;
        if (tables) inputs.tables = &tables->sampling;  // make_sampler copies the shared_ptrs
        Expected<std::shared_ptr<const Sampler>> made = make_sampler(kind, inputs);
        if (!made) refuse(code_of(made.error().kind), "sampler options: " + made.error().message);
        // The sampler reads its fiber's points only when it was built for one.
        std::shared_ptr<const ShadingModel> model;
        if (made.value()->model()) model = inputs.chiang;
        Expected<HairShading> shading = HairShading::create(std::move(model), std::move(made).value());
        if (!shading) refuse(HAIRIS_ERROR_INTERNAL, shading.error().message);
        return new hairis_sampler{std::move(shading).value()};
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
            require_view(wo, h, i);
            for (size_t k = 0; k < 3; ++k) {
                const float v = u[3 * i + k];
                if (!(v >= 0.0f && v < 1.0f))
                    invalid(indexed("u", 3 * i + k) + " must be in [0, 1) (got " + describe(v) +
                            ")");
            }
        }
        for_each_item(n, [&](size_t i) {
            const std::optional<BsdfSample> d = bsdf_at(*sampler, wo, h, i).sample(u[3 * i], u[3 * i + 1], u[3 * i + 2]);
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
        require_pair_batch(n, wi, wo, pdf_out, "pdf_out");
        for (size_t i = 0; i < n; ++i) require_pair(wi, wo, h, i);
        for_each_item(n, [&](size_t i) {
            pdf_out[i] = bsdf_at(*sampler, wo, h, i).pdf(vec3_at(wi, i));
        });
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_sampler_eval(const hairis_sampler *sampler, size_t n, const float *wi,
                                   const float *wo, const float *h, float *rgb_out) {
    return guard_status("hairis_sampler_eval", [&] {
        require(sampler, "sampler");
        if (!sampler->shading.model())
            invalid("sampler: it was created without a fiber, so it has no f; create it with a fiber");
        require_pair_batch(n, wi, wo, rgb_out, "rgb_out");
        for (size_t i = 0; i < n; ++i) require_pair(wi, wo, h, i);
        for_each_item(n, [&](size_t i) {
            store_rgb(rgb_out, i, bsdf_at(*sampler, wo, h, i).f(vec3_at(wi, i)));
        });
        return HAIRIS_OK;
    });
}

}  // extern "C"
