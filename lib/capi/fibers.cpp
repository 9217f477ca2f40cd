// C API: fibers. A hairis_fiber keeps the FiberSpec it was made from, so that its model name
// and "name=value;..." parameters are exactly what fiber_spec.h gives the baker and what
// table metadata records (hairis_tables_match_fiber compares those strings).
#include <algorithm>
#include <string>
#include <vector>

#include "capi_internal.h"
#include "fiber/marschner.h"
#include "fiber/principled_hair.h"

namespace hairis::capi {

std::string spec_parameters(const FiberSpec &spec) {
    Expected<std::vector<std::pair<std::string, double>>> p = spec.parameters();
    if (!p) invalid(p.error().message);
    return canonical_parameters(p.value());
}

FiberSpec default_fiber_spec(FiberKind kind) {
    FiberSpec spec;
    spec.kind = kind;
    if (kind == FiberKind::Marschner) spec.marschner = MarschnerParams::blonde();
    return spec;
}

namespace {

// The names hairis_fiber_create reads for a model: those default_fiber_spec(kind).options()
// lists (hairis_defaults), and offset_deg for Chiang and Huang.
std::vector<std::string> fiber_option_names(FiberKind kind) {
    std::vector<std::string> names;
    Expected<OptionItems> items = parse_options(default_fiber_spec(kind).options(), "defaults");
    if (!items) invalid(items.error().message);
    for (const auto &item : items.value()) names.push_back(item.first);
    if (kind != FiberKind::Marschner) names.push_back("offset_deg");
    return names;
}

}  // namespace

/// The spec of `options`: "model" first (it picks the names and the defaults), then every
/// other name through FiberSpec::set, which names what it refuses. A name the model does not
/// read (a Marschner name for Chiang, "preset") is refused, listing the model's names.
FiberSpec fiber_spec_of(const char *options) {
    Expected<OptionItems> items = parse_options(options ? options : "", "fiber options");
    if (!items) invalid(items.error().message);
    FiberSpec spec;
    for (const auto &[key, value] : items.value())
        if (key == "model") ok_or_invalid(spec.set(key, value), "fiber options: ");
    spec = default_fiber_spec(spec.kind);
    const char *model = spec.kind == FiberKind::Marschner ? "marschner"
                        : spec.kind == FiberKind::Huang   ? "huang"
                                                          : "chiang";
    const std::vector<std::string> known = fiber_option_names(spec.kind);
    bool offset = false, offset_deg = false;
    for (const auto &[key, value] : items.value()) {
        if (std::find(known.begin(), known.end(), key) == known.end()) {
            std::string list;
            for (const std::string &name : known) list += (list.empty() ? "" : ", ") + name;
            invalid("fiber options: unknown option \"" + key + "\" for model=" + model + " (known: " + list + ")");
        }
        offset = offset || key == "offset";
        offset_deg = offset_deg || key == "offset_deg";
        if (offset && offset_deg)
            invalid("fiber options: offset (radians) and offset_deg (degrees) set the same angle: give one");
        if (Status s = spec.set(key, value)) invalid("fiber options: " + s->message);
    }
    return spec;
}

}  // namespace hairis::capi

using namespace hairis;
using namespace hairis::capi;

extern "C" {

HAIRIS_API hairis_fiber *hairis_fiber_create(const char *options) {
    return guard_handle<hairis_fiber>("hairis_fiber_create", [&] {
        FiberSpec spec = fiber_spec_of(options);
        Expected<std::unique_ptr<FiberModel>> model = spec.create_model();
        if (!model) invalid("fiber options: " + model.error().message);
        auto fiber = std::make_unique<hairis_fiber>();
        std::shared_ptr<const FiberModel> shared(std::move(model).value());
        fiber->chiang = std::dynamic_pointer_cast<const ChiangFiber>(shared);
        fiber->huang = std::dynamic_pointer_cast<const HuangFiber>(shared);
        fiber->model_name = shared->name();
        fiber->model = std::move(shared);
        fiber->parameters = spec_parameters(spec);
        fiber->spec = std::move(spec);
        return fiber.release();
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
        require_pair_batch(n, wi, wo, rgb_out, "rgb_out");
        if (h && !fiber->chiang)
            invalid("h must be NULL for a " + fiber->model_name +
                    " fiber: the near field (an offset per item) is only available for "
                    "chiang2016 fibers; pass h = NULL for the far field");
        // Everything is checked before anything is written.
        for (size_t i = 0; i < n; ++i) require_pair(wi, wo, h, i);
        const FiberModel &model = *fiber->model;
        const ChiangFiber *chiang = fiber->chiang.get();
        for_each_item(n, [&](size_t i) {
            const Vec3 a = vec3_at(wi, i), b = vec3_at(wo, i);
            store_rgb(rgb_out, i, h ? chiang->f_cos_near(a, b, h[i]) : model.f_cos(a, b));
        });
        return HAIRIS_OK;
    });
}

}  // extern "C"
