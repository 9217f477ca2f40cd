// The hairis_scene handle, shared by scene.cpp (building it) and render.cpp (rendering it).
#pragma once

#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "capi_internal.h"
#include "hairis/principled_hair.h"
#include "hairis/scene.h"

namespace hairis::capi {

/// A hair material as the C API keeps it until a render: the node's fiber and, optionally,
/// tables (shared with the hairis_tables they came from, so that handle may be destroyed).
/// The direction sampler is made by hairis_render from its settings.
struct SceneHairMaterial {
    std::shared_ptr<const ChiangFiber> fiber;
    std::string model;       // "chiang2016"
    std::string parameters;  // canonical parameters of the node (FiberSpec)
    bool has_tables = false;
    SamplingTables tables;
    std::string tables_model;
    std::string tables_parameters;
    std::vector<int> tables_n_h;
};

using SceneMaterial = std::variant<SceneHairMaterial, DiffuseMaterial>;

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
