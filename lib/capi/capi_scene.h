// The hairis_scene handle and the option sets of hairis_render.h, shared by scene.cpp
// (building it), render.cpp (rendering it) and defaults.cpp (hairis_defaults).
#pragma once

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "capi_internal.h"
#include "fiber/principled_hair.h"
#include "hairis/hairis_render.h"
#include "render/render.h"
#include "render/scene.h"

namespace hairis {

/// The bound of float options without a limit: the largest float as "%.9g" writes it. As a
/// double it lies just above FLT_MAX, yet reads back as FLT_MAX, so a written default at the
/// limit (the camera's clip_end) reads back.
inline constexpr double kHugeOption = 3.40282347e+38;
static_assert(float(kHugeOption) == std::numeric_limits<float>::max());

// Option names of the core's lights (found by describe()'s argument-dependent lookup).
/// "type=sun": direction towards the sun, W/m², angular diameter (radians).
template <typename Fields>
void describe(Fields &f, SunLight &o) {
    f.field("direction", o.to_sun);
    f.field("color", o.color, 0.0, kHugeOption);
    f.field("strength", o.strength, 0.0, kHugeOption);
    f.field("angle", o.angle, 0.0, std::nextafter(kPi, 0.0));
}

/// "type=point": power in W, radius in metres.
template <typename Fields>
void describe(Fields &f, PointLight &o) {
    f.field("position", o.position);
    f.field("color", o.color, 0.0, kHugeOption);
    f.field("power", o.power, 0.0, kHugeOption);
    f.field("radius", o.radius, 0.0, kHugeOption);
}

/// The world: a constant background of radiance color × strength.
template <typename Fields>
void describe(Fields &f, WorldLight &o) {
    f.field("color", o.color, 0.0, kHugeOption);
    f.field("strength", o.strength, 0.0, kHugeOption);
}

}  // namespace hairis

namespace hairis::capi {

inline constexpr double kHuge = kHugeOption;

/// A hair material as the C API keeps it until a render: its fiber and, optionally, tables
/// (shared with the hairis_tables they came from). The sampler is made by hairis_render from
/// its settings.
struct SceneHairMaterial {
    std::shared_ptr<const ChiangFiber> fiber;
    std::optional<SamplingTables> tables;
};

using SceneMaterial = std::variant<SceneHairMaterial, DiffuseMaterial>;

/// "type=diffuse": a Lambertian surface with an emission (radiance).
struct DiffuseOptions {
    Rgb color{0.8f};
    Rgb emission{0.0f};
};
template <typename Fields>
void describe(Fields &f, DiffuseOptions &o) {
    f.field("color", o.color, 0.0, 1.0);
    f.field("emission", o.emission, 0.0, kHuge);
}

/// "type=area": the light object's matrix (row-major, with its scale), shape, sizes, power.
struct AreaOptions {
    float matrix[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    int shape = 0;
    float size = 1.0f, size_y = 1.0f;
    Rgb color{1.0f};
    float power = 10.0f;
};
template <typename Fields>
void describe(Fields &f, AreaOptions &o) {
    float *matrix = o.matrix;
    f.field("matrix", matrix, 16, -kHuge, kHuge);
    f.choice("shape", o.shape, {"square", "rectangle", "disk", "ellipse"});
    f.field("size", o.size, 0.0, kHuge);
    f.field("size_y", o.size_y, 0.0, kHuge);
    f.field("color", o.color, 0.0, kHuge);
    f.field("power", o.power, 0.0, kHuge);
}

/// The camera as Blender describes it (Camera.view_frame, matrix_world, resolution, clip).
struct CameraOptions {
    float matrix[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    bool orthographic = false;
    float frame[12] = {0.5f, 0.5f, -1, 0.5f, -0.5f, -1, -0.5f, -0.5f, -1, -0.5f, 0.5f, -1};
    int width = 64, height = 64;
    float clip_start = 0.0f;
    float clip_end = std::numeric_limits<float>::max();  ///< the largest float: no far clip
};
template <typename Fields>
void describe(Fields &f, CameraOptions &o) {
    float *matrix = o.matrix, *frame = o.frame;
    f.field("matrix", matrix, 16, -kHuge, kHuge);
    f.field("orthographic", o.orthographic);
    f.field("frame", frame, 12, -kHuge, kHuge);
    f.field("width", o.width, 1, 65536);
    f.field("height", o.height, 1, 65536);
    f.field("clip_start", o.clip_start, 0.0, kHuge);
    f.field("clip_end", o.clip_end, 0.0, kHuge);
}

/// Everything hairis_render reads: the renderer's settings and the hair sampler's.
struct RenderOptions {
    RenderSettings render;
    SamplerOptions sampler;
};
template <typename Fields>
void describe(Fields &f, RenderOptions &o) {
    describe(f, o.render);
    describe(f, o.sampler);
}

}  // namespace hairis::capi

/// A scene under construction: materials, and a SceneDesc whose geometry, lights, world and
/// camera are filled in by the hairis_scene_* calls; its materials are made by hairis_render.
struct hairis_scene {
    std::vector<hairis::capi::SceneMaterial> materials;
    hairis::SceneDesc desc;
    bool has_camera = false;
    size_t curve_count = 0;      // curves added (before the build skips degenerate ones)
    size_t triangle_count = 0;   // triangles added
    size_t geometry_bytes = 0;   // the buffers held by desc
};
