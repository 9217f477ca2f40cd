// C API: hairis_defaults — every option set's names with their defaults, written from the same
// descriptions that read them.
#include <string>

#include "capi_scene.h"
#include "tables/bake.h"

using namespace hairis;
using namespace hairis::capi;

namespace {

thread_local std::string t_defaults;

std::string defaults_of(const std::string &kind) {
    if (kind == "chiang") return default_fiber_spec(FiberKind::Chiang).options();
    if (kind == "huang") return default_fiber_spec(FiberKind::Huang).options();
    if (kind == "marschner") return default_fiber_spec(FiberKind::Marschner).options();
    if (kind == "bake") return write_options(BakeOptions{});
    if (kind == "sampler") return write_options(SamplerOptions{});
    if (kind == "render") return write_options(RenderOptions{});
    if (kind == "diffuse") return "type=diffuse;" + write_options(DiffuseOptions{});
    if (kind == "principled") return "type=principled;" + write_options(PrincipledOptions{});
    if (kind == "glossy") return "type=glossy;" + write_options(GlossyOptions{});
    if (kind == "emission") return "type=emission;" + write_options(EmissionOptions{});
    if (kind == "mix") return "type=mix;" + write_options(MixOptions{});
    if (kind == "add") return "type=add;" + write_options(AddOptions{});
    if (kind == "texture") return write_options(TextureOptions{});
    if (kind == "sun") return "type=sun;" + write_options(SunLight{});
    if (kind == "point") return "type=point;" + write_options(PointLight{});
    if (kind == "spot") return "type=spot;" + write_options(SpotOptions{});
    if (kind == "area") return "type=area;" + write_options(AreaOptions{});
    if (kind == "world") return write_options(WorldOptions{});
    if (kind == "camera") return write_options(CameraOptions{});
    if (kind == "curve_inputs") return write_options(CurveInputOptions{});
    if (kind == "curves") return write_options(CurveOptions{});
    invalid("kind must be one of chiang, huang, marschner, bake, sampler, render, diffuse, "
            "principled, glossy, emission, mix, add, texture, sun, point, spot, area, world, "
            "camera, curve_inputs, curves (got \"" + kind + "\")");
}

}  // namespace

extern "C" {

HAIRIS_API const char *hairis_defaults(const char *kind) {
    return guard_value<const char *>("hairis_defaults", nullptr, [&] {
        require(kind, "kind");
        t_defaults = defaults_of(kind);
        return t_defaults.c_str();
    });
}

}  // extern "C"
