// The hairis_scene handle and the option sets of hairis_render.h, shared by scene.cpp
// (building it), render.cpp (rendering it) and defaults.cpp (hairis_defaults).
#pragma once

#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "capi_internal.h"
#include "fiber/hair_inputs.h"
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

/// "cycles=3.4|4.5": which Cycles a light follows (lights.h).
template <typename Fields>
void describe_version(Fields &f, CyclesVersion &v) {
    int index = int(v);
    f.choice("cycles", index, {"3.4", "4.5"});
    v = CyclesVersion(index);
}

/// "type=sun": direction towards the sun, W/m², angular diameter (radians).
template <typename Fields>
void describe(Fields &f, SunLight &o) {
    f.field("direction", o.to_sun);
    f.field("color", o.color, 0.0, kHugeOption);
    f.field("strength", o.strength, 0.0, kHugeOption);
    f.field("angle", o.angle, 0.0, std::nextafter(kPi, 0.0));
    describe_version(f, o.cycles);
}

/// "type=point": power in W, radius in metres.
template <typename Fields>
void describe(Fields &f, PointLight &o) {
    f.field("position", o.position);
    f.field("color", o.color, 0.0, kHugeOption);
    f.field("power", o.power, 0.0, kHugeOption);
    f.field("radius", o.radius, 0.0, kHugeOption);
    describe_version(f, o.cycles);
    f.field("soft_falloff", o.soft_falloff);
}

}  // namespace hairis

namespace hairis::capi {

inline constexpr double kHuge = kHugeOption;

/// "type=spot": the light object's matrix (row-major, with its scale), Blender's spot_size
/// (full cone angle, radians) and spot_blend, power in W, radius (shadow_soft_size) in metres.
struct SpotOptions {
    float matrix[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    SpotLight light;  ///< all but its light_to_world, which the matrix gives
};
template <typename Fields>
void describe(Fields &f, SpotOptions &o) {
    float *matrix = o.matrix;
    f.field("matrix", matrix, 16, -kHuge, kHuge);
    f.field("color", o.light.color, 0.0, kHuge);
    f.field("power", o.light.power, 0.0, kHuge);
    f.field("radius", o.light.radius, 0.0, kHuge);
    f.field("spot_size", o.light.spot_size, kPi / 180.0, kPi);
    f.field("spot_blend", o.light.spot_blend, 0.0, 1.0);
    describe_version(f, o.light.cycles);
    f.field("soft_falloff", o.light.soft_falloff);
}

/// The world: a constant background (color × strength), or an Environment Texture read from
/// `image` (or handed over by hairis_scene_set_world_pixels) through a Mapping node, times
/// color and strength, light-sampled as Cycles' World > Settings > Sampling says.
struct WorldOptions {
    Rgb color{0.0f};  ///< the constant's colour; with an environment the multiplier (default 1)
    float strength = 1.0f;
    std::string image;  ///< a file OpenImageIO reads (EXR, HDR, ...); empty: no environment
    int color_space = 0;  ///< auto | linear | srgb (ImageColorSpace)
    float matrix[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  ///< world → texture, before the Mapping
    int mapping = 0;  ///< the Mapping node's type: point | texture | vector | normal
    Vec3 rotation{0, 0, 0};
    Vec3 scale{1, 1, 1};
    int sampling = 0;  ///< auto | manual | none
    int map_resolution = 1024;  ///< Manual: map_resolution × map_resolution/2
};
template <typename Fields>
void describe(Fields &f, WorldOptions &o) {
    float *matrix = o.matrix;
    f.field("color", o.color, 0.0, kHuge);
    f.field("strength", o.strength, 0.0, kHuge);
    f.field("image", o.image);
    f.choice("color_space", o.color_space, {"auto", "linear", "srgb"});
    f.field("matrix", matrix, 16, -kHuge, kHuge);
    f.choice("mapping", o.mapping, {"point", "texture", "vector", "normal"});
    f.field("rotation", o.rotation);
    f.field("scale", o.scale);
    f.choice("sampling", o.sampling, {"auto", "manual", "none"});
    f.field("map_resolution", o.map_resolution, 1, EnvironmentMap::kMaxMapWidth);
}

/// A hair material as the C API keeps it until a render: its fiber (Chiang or Huang) and,
/// optionally, tables (shared with the hairis_tables they came from). The sampler is made by
/// hairis_render from its settings.
struct SceneHairMaterial {
    std::shared_ptr<const ChiangFiber> fiber;
    PrincipledHairNode node;  ///< the fiber's node: what curve inputs vary
    std::shared_ptr<const HuangFiber> huang;
    std::optional<SamplingTables> tables;
    /// A mixture (hairis_scene_add_hair_mixture): the hair materials it mixes, by index, and
    /// their weights; the fields above are then its first closure's. Empty otherwise.
    std::vector<std::size_t> closures;
    std::vector<float> weights;
};

/// hairis_scene_add_curves_with_inputs' `inputs`: per node input (hair_inputs.h's names and
/// order), where its values come from: 0 material (the fiber's own value), 1 curve, 2 point.
/// weight0 .. weight7: the same for the weight of each closure of a hair mixture (their values
/// follow the node inputs', one float per curve or point, in closure order).
struct CurveInputOptions {
    int domain[kHairInputCount] = {};
    int weight_domain[kMaxHairClosures] = {};
};
template <typename Fields>
void describe(Fields &f, CurveInputOptions &o) {
    for (int i = 0; i < kHairInputCount; ++i)
        f.choice(hair_input_info(HairInput(i)).name, o.domain[i], {"material", "curve", "point"});
    static const char *const kWeightNames[kMaxHairClosures] = {"weight0", "weight1", "weight2", "weight3",
                                                               "weight4", "weight5", "weight6", "weight7"};
    for (int k = 0; k < kMaxHairClosures; ++k)
        f.choice(kWeightNames[k], o.weight_domain[k], {"material", "curve", "point"});
}

using SceneMaterial = std::variant<SceneHairMaterial, SurfaceMaterial>;

/// The options of hairis_scene_add_curves_with_normals: none yet (every name is refused, so a
/// name added later is never silently ignored by an older library).
struct CurveOptions {};
template <typename Fields>
void describe(Fields &, CurveOptions &) {}

/// The most textures a scene holds (indices are ints).
inline constexpr int kMaxTextures = 1 << 20;

/// "type=diffuse": Blender's Diffuse BSDF (Lambert at roughness 0, else Oren–Nayar as the
/// Cycles version has it) with an emission (radiance) added; color_texture: an index from
/// hairis_scene_add_texture that replaces color, -1 for none.
struct DiffuseOptions {
    Rgb color{0.8f};
    Rgb emission{0.0f};
    float roughness = 0.0f;
    int color_texture = -1;
    CyclesVersion cycles = CyclesVersion::V3_4;
};
template <typename Fields>
void describe(Fields &f, DiffuseOptions &o) {
    f.field("color", o.color, 0.0, 1.0);
    f.field("emission", o.emission, 0.0, kHuge);
    f.field("roughness", o.roughness, 0.0, 1.0);
    f.field("color_texture", o.color_texture, -1, kMaxTextures - 1);
    describe_version(f, o.cycles);
}

/// "distribution=ggx|multi_ggx" of the Glossy and Principled BSDFs.
template <typename Fields>
void describe_distribution(Fields &f, bool &multiscatter) {
    int index = multiscatter ? 1 : 0;
    f.choice("distribution", index, {"ggx", "multi_ggx"});
    multiscatter = index == 1;
}

/// "type=glossy": Blender's Glossy BSDF with GGX or Multiscatter GGX.
struct GlossyOptions {
    Rgb color{0.8f};
    int color_texture = -1;
    float roughness = 0.5f;
    bool multiscatter = false;
    CyclesVersion cycles = CyclesVersion::V3_4;
};
template <typename Fields>
void describe(Fields &f, GlossyOptions &o) {
    f.field("color", o.color, 0.0, kHuge);
    f.field("color_texture", o.color_texture, -1, kMaxTextures - 1);
    f.field("roughness", o.roughness, 0.0, 1.0);
    describe_distribution(f, o.multiscatter);
    describe_version(f, o.cycles);
}

/// "type=emission": radiance color × strength.
struct EmissionOptions {
    Rgb color{1.0f};
    float strength = 1.0f;
};
template <typename Fields>
void describe(Fields &f, EmissionOptions &o) {
    f.field("color", o.color, 0.0, kHuge);
    f.field("strength", o.strength, 0.0, kHuge);
}

/// "type=mix" ((1 − factor) shader1 + factor shader2) and "type=add" (shader1 + shader2):
/// shader1 and shader2 are surface materials already in the scene.
struct MixOptions {
    float factor = 0.5f;
    int shader1 = -1, shader2 = -1;
};
template <typename Fields>
void describe(Fields &f, MixOptions &o) {
    f.field("factor", o.factor, 0.0, 1.0);
    f.field("shader1", o.shader1, -1, 1 << 20);
    f.field("shader2", o.shader2, -1, 1 << 20);
}

struct AddOptions {
    int shader1 = -1, shader2 = -1;
};
template <typename Fields>
void describe(Fields &f, AddOptions &o) {
    f.field("shader1", o.shader1, -1, 1 << 20);
    f.field("shader2", o.shader2, -1, 1 << 20);
}

/// "type=principled": Blender's Principled BSDF in the inputs of the Cycles version given
/// (surface_material.h says what each becomes). specular is 3.4's Specular or 4.x's Specular
/// IOR Level; specular_tint is 3.4's (a float), specular_tint_color 4.x's; subsurface_color,
/// sheen and sheen_tint are 3.4's; coat is 3.4's Clearcoat or 4.x's Coat Weight, coat_ior,
/// coat_tint and diffuse_roughness are 4.x's. emission is Emission (Color) × Emission Strength.
struct PrincipledOptions {
    CyclesVersion cycles = CyclesVersion::V3_4;
    bool multiscatter = false;
    Rgb base_color{0.8f};
    int base_color_texture = -1;
    float metallic = 0.0f;
    float roughness = 0.5f;
    float ior = 1.45f;
    float specular = 0.5f;
    float specular_tint = 0.0f;
    Rgb specular_tint_color{1.0f};
    float subsurface = 0.0f;
    Rgb subsurface_color{0.8f};
    float sheen = 0.0f;
    float sheen_tint = 0.5f;
    float coat = 0.0f;
    float coat_roughness = 0.03f;
    float coat_ior = 1.5f;
    Rgb coat_tint{1.0f};
    float diffuse_roughness = 0.0f;
    Rgb emission{0.0f};
};
template <typename Fields>
void describe(Fields &f, PrincipledOptions &o) {
    describe_version(f, o.cycles);
    describe_distribution(f, o.multiscatter);
    f.field("base_color", o.base_color, 0.0, kHuge);
    f.field("base_color_texture", o.base_color_texture, -1, kMaxTextures - 1);
    f.field("metallic", o.metallic, 0.0, 1.0);
    f.field("roughness", o.roughness, 0.0, 1.0);
    f.field("ior", o.ior, 0.0, 1000.0);
    f.field("specular", o.specular, 0.0, kHuge);
    f.field("specular_tint", o.specular_tint, 0.0, 1.0);
    f.field("specular_tint_color", o.specular_tint_color, 0.0, kHuge);
    f.field("subsurface", o.subsurface, 0.0, 1.0);
    f.field("subsurface_color", o.subsurface_color, 0.0, kHuge);
    f.field("sheen", o.sheen, 0.0, kHuge);
    f.field("sheen_tint", o.sheen_tint, 0.0, 1.0);
    f.field("coat", o.coat, 0.0, kHuge);
    f.field("coat_roughness", o.coat_roughness, 0.0, 1.0);
    f.field("coat_ior", o.coat_ior, 1.0, 1000.0);
    f.field("coat_tint", o.coat_tint, 0.0, kHuge);
    f.field("diffuse_roughness", o.diffuse_roughness, 0.0, 1.0);
    f.field("emission", o.emission, 0.0, kHuge);
}

/// hairis_scene_add_texture: an Image Texture (texture.h) of a file or of pixels, with its
/// interpolation, extension and Mapping node (mapping=none: none).
struct TextureOptions {
    std::string image;
    int color_space = 0;  ///< auto | linear | srgb (ImageColorSpace)
    int interpolation = 0;  ///< linear | closest
    int extension = 0;  ///< repeat | extend | clip | mirror
    int mapping = 0;  ///< none | point | texture | vector
    Vec3 location{0, 0, 0};
    Vec3 rotation{0, 0, 0};
    Vec3 scale{1, 1, 1};
};
template <typename Fields>
void describe(Fields &f, TextureOptions &o) {
    f.field("image", o.image);
    f.choice("color_space", o.color_space, {"auto", "linear", "srgb"});
    f.choice("interpolation", o.interpolation, {"linear", "closest"});
    f.choice("extension", o.extension, {"repeat", "extend", "clip", "mirror"});
    f.choice("mapping", o.mapping, {"none", "point", "texture", "vector"});
    f.field("location", o.location);
    f.field("rotation", o.rotation);
    f.field("scale", o.scale);
}

/// hairis_scene_set_mesh_attribute: which corner attribute.
struct MeshAttributeOptions {
    int name = 0;  ///< normal | uv
};
template <typename Fields>
void describe(Fields &f, MeshAttributeOptions &o) {
    f.choice("name", o.name, {"normal", "uv"});
}

/// "type=area": the light object's matrix (row-major, with its scale), shape, sizes, power.
struct AreaOptions {
    float matrix[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    AreaLight light;  ///< all but its light_to_world, which the matrix gives
};
template <typename Fields>
void describe(Fields &f, AreaOptions &o) {
    float *matrix = o.matrix;
    int shape = int(o.light.shape);
    f.field("matrix", matrix, 16, -kHuge, kHuge);
    f.choice("shape", shape, {"square", "rectangle", "disk", "ellipse"});
    o.light.shape = AreaShape(shape);
    f.field("size", o.light.size_x, 0.0, kHuge);
    f.field("size_y", o.light.size_y, 0.0, kHuge);
    f.field("color", o.light.color, 0.0, kHuge);
    f.field("power", o.light.power, 0.0, kHuge);
    describe_version(f, o.light.cycles);
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

/// Everything hairis_render reads: the renderer's settings, the hair sampler's and how the
/// scene it builds traces curves (curve_backfaces=ignore|hit, scene.h's CurveBackfaces;
/// curve_shape=thick|ribbons|thick_linear, scene.h's CurveShape; bvh_quality=low|medium|high,
/// scene.h's BvhQuality; curve_subdivisions, SceneDesc's).
struct RenderOptions {
    RenderSettings render;
    SamplerOptions sampler;
    CurveBackfaces curve_backfaces = CurveBackfaces::Ignore;
    CurveShape curve_shape = CurveShape::Thick;
    BvhQuality bvh_quality = BvhQuality::Medium;
    int curve_subdivisions = 2;
};
template <typename Fields>
void describe(Fields &f, RenderOptions &o) {
    describe(f, o.render);
    describe(f, o.sampler);
    int backfaces = int(o.curve_backfaces);
    f.choice("curve_backfaces", backfaces, {"ignore", "hit"});
    o.curve_backfaces = CurveBackfaces(backfaces);
    int shape = int(o.curve_shape);
    f.choice("curve_shape", shape, {"thick", "ribbons", "thick_linear"});
    o.curve_shape = CurveShape(shape);
    int quality = int(o.bvh_quality);
    f.choice("bvh_quality", quality, {"low", "medium", "high"});
    o.bvh_quality = BvhQuality(quality);
    f.field("curve_subdivisions", o.curve_subdivisions, 0, 24);
}

}  // namespace hairis::capi

/// A scene under construction: materials, and a SceneDesc whose geometry, lights, world and
/// camera are filled in by the hairis_scene_* calls; its materials are made by hairis_render.
/// The last render's built scene is kept for the next render: whole with the same render
/// settings, its geometry (BVH) with others. A hairis_scene_* call that changes the geometry
/// must call forget_build(), one that changes materials, textures, lights or the world
/// forget_shading(); hairis_scene_set_camera counts camera_revision up.
struct hairis_scene {
    void forget_build() {
        std::lock_guard<std::mutex> lock(build_mutex);
        built.reset();
        built_key.clear();
    }
    void forget_shading() {
        std::lock_guard<std::mutex> lock(build_mutex);
        built_key.clear();
    }
    std::mutex build_mutex;                ///< guards the five fields below
    std::shared_ptr<hairis::Scene> built;  ///< the last render's scene (BVH, lights, materials)
    std::string built_key;                 ///< the render settings its shading was made for ("": stale)
    std::string built_geometry_key;        ///< the render settings its BVH was built for
    unsigned camera_revision = 0;          ///< hairis_scene_set_camera calls so far
    unsigned built_camera = 0;             ///< the camera_revision `built` has
    std::vector<hairis::capi::SceneMaterial> materials;
    std::vector<std::shared_ptr<const hairis::ImageTexture>> textures;
    hairis::SceneDesc desc;
    /// The mesh the last hairis_scene_add_mesh call added (-1: it added none).
    long long last_mesh = -1;
    bool has_camera = false;
    size_t curve_count = 0;      // curves added (before the build skips degenerate ones)
    size_t triangle_count = 0;   // triangles added
    size_t geometry_bytes = 0;   // the buffers held by desc
};
