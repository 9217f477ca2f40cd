// C API: fibers. A hairis_fiber keeps the FiberSpec it was made from, so that its model name
// and "name=value;..." parameters are exactly what fiber_spec.h gives the baker and what
// table metadata records (hairis_tables_match_fiber compares those strings).
#include <charconv>
#include <string>
#include <system_error>

#include "capi_internal.h"
#include "hairis/marschner.h"
#include "hairis/principled_hair.h"

namespace hairis::capi {

PrincipledHairNode to_node(const hairis_principled_hair &c, const char *name) {
    const std::string prefix = std::string(name) + ".";
    PrincipledHairNode node;
    switch (c.parametrization) {
        case HAIRIS_PARAM_ABSORPTION:
            node.parametrization = HairParametrization::AbsorptionCoefficient;
            break;
        case HAIRIS_PARAM_MELANIN: node.parametrization = HairParametrization::Melanin; break;
        case HAIRIS_PARAM_COLOR: node.parametrization = HairParametrization::Color; break;
        default:
            invalid(prefix + "parametrization must be 0 (HAIRIS_PARAM_ABSORPTION), 1 "
                             "(HAIRIS_PARAM_MELANIN) or 2 (HAIRIS_PARAM_COLOR) (got " +
                    std::to_string(c.parametrization) + ")");
    }
    // Every input must be finite, also those the parametrization does not read: a NaN
    // anywhere is a caller's bug worth reporting.
    const struct {
        const char *field;
        const float *values;
        size_t count;
    } inputs[] = {{"color", c.color, 3},
                  {"melanin", &c.melanin, 1},
                  {"melanin_redness", &c.melanin_redness, 1},
                  {"tint", c.tint, 3},
                  {"absorption_coefficient", c.absorption_coefficient, 3},
                  {"roughness", &c.roughness, 1},
                  {"radial_roughness", &c.radial_roughness, 1},
                  {"coat", &c.coat, 1},
                  {"ior", &c.ior, 1},
                  {"offset", &c.offset, 1},
                  {"random_color", &c.random_color, 1},
                  {"random_roughness", &c.random_roughness, 1},
                  {"random", &c.random, 1}};
    for (const auto &in : inputs)
        for (size_t k = 0; k < in.count; ++k)
            require_finite(in.values[k], in.count == 1 ? prefix + in.field
                                                        : indexed((prefix + in.field).c_str(), k));
    node.color = {c.color[0], c.color[1], c.color[2]};
    node.melanin = c.melanin;
    node.melanin_redness = c.melanin_redness;
    node.tint = {c.tint[0], c.tint[1], c.tint[2]};
    node.absorption_coefficient = {c.absorption_coefficient[0], c.absorption_coefficient[1],
                                   c.absorption_coefficient[2]};
    node.roughness = c.roughness;
    node.radial_roughness = c.radial_roughness;
    node.coat = c.coat;
    node.ior = c.ior;
    node.offset = c.offset;
    node.random_color = c.random_color;
    node.random_roughness = c.random_roughness;
    node.random = c.random;
    return node;
}

std::string spec_parameters(const FiberSpec &spec) {
    Expected<std::vector<std::pair<std::string, double>>> p = spec.parameters();
    if (!p) invalid(p.error().message);
    return canonical_parameters(p.value());
}

namespace {

// float → double through the float's shortest decimal form (1.55f → 1.55, not
// 1.5499999523...), so that a value typed as a decimal gives the same double here as in a
// hairis-bake parameter file, and the same canonical parameters in the table metadata.
double widen(float value) {
    char text[64];
    const std::to_chars_result w = std::to_chars(text, text + sizeof text, value);
    if (w.ec != std::errc()) return double(value);
    double result = 0;
    const std::from_chars_result r = std::from_chars(text, w.ptr, result);
    return r.ec == std::errc() ? result : double(value);
}

float narrow(double value) { return float(value); }

hairis_fiber *make_fiber(FiberSpec spec, const std::string &prefix) {
    Expected<std::unique_ptr<FiberModel>> model = spec.create_model();
    if (!model) {
        // The core calls Marschner's field caustic_limit; the C struct caustic_intensity_limit.
        std::string message = model.error().message;
        if (spec.kind == FiberKind::Marschner && message.rfind("caustic_limit", 0) == 0)
            message = "caustic_intensity_limit" + message.substr(13);
        invalid(prefix + message);
    }
    auto fiber = std::make_unique<hairis_fiber>();
    std::shared_ptr<const FiberModel> shared(std::move(model).value());
    fiber->chiang = std::dynamic_pointer_cast<const ChiangFiber>(shared);
    fiber->model_name = shared->name();
    fiber->model = std::move(shared);
    fiber->parameters = spec_parameters(spec);
    fiber->spec = std::move(spec);
    return fiber.release();
}

}  // namespace

}  // namespace hairis::capi

using namespace hairis;
using namespace hairis::capi;

extern "C" {

HAIRIS_API void hairis_principled_hair_defaults(hairis_principled_hair *node) {
    guard_void("hairis_principled_hair_defaults", [&] {
        require(node, "node");
        const PrincipledHairNode d = PrincipledHairNode::cycles_default();
        hairis_principled_hair c{};
        switch (d.parametrization) {
            case HairParametrization::AbsorptionCoefficient:
                c.parametrization = HAIRIS_PARAM_ABSORPTION;
                break;
            case HairParametrization::Melanin: c.parametrization = HAIRIS_PARAM_MELANIN; break;
            case HairParametrization::Color: c.parametrization = HAIRIS_PARAM_COLOR; break;
        }
        for (int k = 0; k < 3; ++k) {
            c.color[k] = d.color[k];
            c.tint[k] = d.tint[k];
            c.absorption_coefficient[k] = d.absorption_coefficient[k];
        }
        c.melanin = d.melanin;
        c.melanin_redness = d.melanin_redness;
        c.roughness = d.roughness;
        c.radial_roughness = d.radial_roughness;
        c.coat = d.coat;
        c.ior = d.ior;
        c.offset = d.offset;
        c.random_color = d.random_color;
        c.random_roughness = d.random_roughness;
        c.random = d.random;
        *node = c;
    });
}

HAIRIS_API void hairis_marschner_defaults(hairis_marschner_params *params) {
    guard_void("hairis_marschner_defaults", [&] {
        require(params, "params");
        const MarschnerParams d = MarschnerParams::blonde();
        hairis_marschner_params c{};
        c.eta = narrow(d.eta);
        for (int k = 0; k < 3; ++k) c.sigma_a[k] = d.sigma_a[k];
        c.alpha_r = narrow(d.alpha_r);
        c.alpha_tt = narrow(d.alpha_tt);
        c.alpha_trt = narrow(d.alpha_trt);
        c.beta_r = narrow(d.beta_r);
        c.beta_tt = narrow(d.beta_tt);
        c.beta_trt = narrow(d.beta_trt);
        c.eccentricity = narrow(d.eccentricity);
        c.glint_scale = narrow(d.glint_scale);
        c.caustic_width = narrow(d.caustic_width);
        c.caustic_fade = narrow(d.caustic_fade);
        c.caustic_intensity_limit = narrow(d.caustic_limit);
        *params = c;
    });
}

HAIRIS_API hairis_fiber *hairis_fiber_create_principled(const hairis_principled_hair *node) {
    return guard_handle<hairis_fiber>("hairis_fiber_create_principled", [&] {
        require(node, "node");
        FiberSpec spec;
        spec.kind = FiberKind::Chiang;
        spec.node = to_node(*node, "node");
        return make_fiber(std::move(spec), "node.");
    });
}

HAIRIS_API hairis_fiber *hairis_fiber_create_marschner(const hairis_marschner_params *params) {
    return guard_handle<hairis_fiber>("hairis_fiber_create_marschner", [&] {
        require(params, "params");
        const hairis_marschner_params &c = *params;
        const struct {
            const char *field;
            const float *values;
            size_t count;
        } inputs[] = {{"eta", &c.eta, 1},
                      {"sigma_a", c.sigma_a, 3},
                      {"alpha_r", &c.alpha_r, 1},
                      {"alpha_tt", &c.alpha_tt, 1},
                      {"alpha_trt", &c.alpha_trt, 1},
                      {"beta_r", &c.beta_r, 1},
                      {"beta_tt", &c.beta_tt, 1},
                      {"beta_trt", &c.beta_trt, 1},
                      {"eccentricity", &c.eccentricity, 1},
                      {"glint_scale", &c.glint_scale, 1},
                      {"caustic_width", &c.caustic_width, 1},
                      {"caustic_fade", &c.caustic_fade, 1},
                      {"caustic_intensity_limit", &c.caustic_intensity_limit, 1}};
        for (const auto &in : inputs)
            for (size_t k = 0; k < in.count; ++k)
                require_finite(in.values[k],
                               in.count == 1 ? std::string("params.") + in.field
                                             : indexed((std::string("params.") + in.field).c_str(), k));
        FiberSpec spec;
        spec.kind = FiberKind::Marschner;
        MarschnerParams &m = spec.marschner;
        m.eta = widen(c.eta);
        m.sigma_a = {c.sigma_a[0], c.sigma_a[1], c.sigma_a[2]};
        m.alpha_r = widen(c.alpha_r);
        m.alpha_tt = widen(c.alpha_tt);
        m.alpha_trt = widen(c.alpha_trt);
        m.beta_r = widen(c.beta_r);
        m.beta_tt = widen(c.beta_tt);
        m.beta_trt = widen(c.beta_trt);
        m.eccentricity = widen(c.eccentricity);
        m.glint_scale = widen(c.glint_scale);
        m.caustic_width = widen(c.caustic_width);
        m.caustic_fade = widen(c.caustic_fade);
        m.caustic_limit = widen(c.caustic_intensity_limit);
        return make_fiber(std::move(spec), "params.");
    });
}

HAIRIS_API void hairis_fiber_destroy(hairis_fiber *fiber) {
    guard_void("hairis_fiber_destroy", [&] { delete fiber; });
}

HAIRIS_API const char *hairis_fiber_model(const hairis_fiber *fiber) {
    return guard_value<const char *>("hairis_fiber_model", "", [&] {
        require(fiber, "fiber");
        return fiber->model_name.c_str();
    });
}

HAIRIS_API const char *hairis_fiber_parameters(const hairis_fiber *fiber) {
    return guard_value<const char *>("hairis_fiber_parameters", "", [&] {
        require(fiber, "fiber");
        return fiber->parameters.c_str();
    });
}

HAIRIS_API int hairis_fiber_eval(const hairis_fiber *fiber, size_t n, const float *wi,
                                 const float *wo, const float *h, float *rgb_out) {
    return guard_status("hairis_fiber_eval", [&] {
        require(fiber, "fiber");
        require_batch_size(n, 3, "n");
        require_array(wi, n, "wi");
        require_array(wo, n, "wo");
        require_array(rgb_out, n, "rgb_out");
        if (h && !fiber->chiang)
            invalid("h must be NULL for a " + fiber->model_name +
                    " fiber: the near field (an offset per item) is only available for "
                    "chiang2016 fibers; pass h = NULL for the far field");
        // Everything is checked before anything is written.
        for (size_t i = 0; i < n; ++i) {
            require_unit_direction(wi, "wi", i);
            require_unit_direction(wo, "wo", i);
            if (h && !(h[i] >= -1.0f && h[i] <= 1.0f))
                invalid(indexed("h", i) + " must be finite and in [-1, 1] (got " +
                        describe(h[i]) + ")");
        }
        const FiberModel &model = *fiber->model;
        const ChiangFiber *chiang = fiber->chiang.get();
        for_each_item(n, [&](size_t i) {
            const Vec3 a{wi[3 * i], wi[3 * i + 1], wi[3 * i + 2]};
            const Vec3 b{wo[3 * i], wo[3 * i + 1], wo[3 * i + 2]};
            const Rgb f = h ? chiang->f_cos_near(a, b, h[i]) : model.f_cos(a, b);
            rgb_out[3 * i] = f.r;
            rgb_out[3 * i + 1] = f.g;
            rgb_out[3 * i + 2] = f.b;
        });
        return HAIRIS_OK;
    });
}

}  // extern "C"
