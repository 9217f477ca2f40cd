// C API: building a render scene incrementally (materials, curves, meshes, lights, world,
// camera). Every input is checked when it is added, so an error names the call and argument
// that caused it; Scene::build (at render time) checks the whole again.
#include <algorithm>
#include <climits>
#include <limits>
#include <string>
#include <utility>

#include "capi_scene.h"
#include "render/camera.h"
#include "render/environment_image.h"
#include "render/environment_map.h"
#include "render/lights.h"

namespace hairis::capi {

namespace {

// Material indices are returned as int and stored as uint32.
constexpr size_t kMaxMaterials = size_t(1) << 20;
// Scene::build's limit on the points of one curve set.
constexpr size_t kMaxCurvePoints = size_t(1) << 31;

int add_material(hairis_scene &scene, SceneMaterial material) {
    if (scene.materials.size() >= kMaxMaterials)
        invalid("scene already has " + std::to_string(kMaxMaterials) +
                " materials (the most allowed)");
    scene.materials.push_back(std::move(material));
    return int(scene.materials.size() - 1);
}

Vec3 vec3(const float *v) { return {v[0], v[1], v[2]}; }

// Checks and adds a curve set (hairis_scene_add_curves and ..._with_normals); normals may be
// NULL (the curves have none).
int add_curves(hairis_scene *scene, int material, size_t curve_count, const uint32_t *first,
               size_t point_count, const float *positions, const float *radii, const float *normals) {
    require(scene, "scene");
    require(first, "first");
    require_array(positions, point_count, "positions");
    require_array(radii, point_count, "radii");
    if (material < 0 || size_t(material) >= scene->materials.size())
        invalid("material must be the index of a material added to the scene, in [0, " +
                std::to_string(scene->materials.size()) + ") (got " + std::to_string(material) + ")");
    if (point_count > kMaxCurvePoints)
        invalid("point_count must be at most 2^31 per call (got " + std::to_string(point_count) + ")");
    if (curve_count > point_count / 2)
        invalid("curve_count (" + std::to_string(curve_count) +
                ") needs at least 2 points per curve, but point_count is " + std::to_string(point_count));
    if (first[0] != 0) invalid("first[0] must be 0 (got " + std::to_string(first[0]) + ")");
    for (size_t c = 0; c < curve_count; ++c)
        if (!(first[c + 1] >= first[c] && first[c + 1] - first[c] >= 2))
            invalid("curve " + std::to_string(c) + ": first[" + std::to_string(c + 1) + "] = " +
                    std::to_string(first[c + 1]) + " must be at least first[" + std::to_string(c) +
                    "] + 2 = " + std::to_string(size_t(first[c]) + 2) + " (a curve has at least 2 points)");
    if (first[curve_count] != point_count)
        invalid("first[curve_count] must equal point_count (" + std::to_string(point_count) + "; got " +
                std::to_string(first[curve_count]) + ")");
    for (size_t i = 0; i < point_count; ++i) {
        for (size_t k = 0; k < 3; ++k) require_finite(positions[3 * i + k], indexed("positions", 3 * i + k));
        require_non_negative(radii[i], indexed("radii", i));
        if (normals)
            for (size_t k = 0; k < 3; ++k) require_finite(normals[3 * i + k], indexed("normals", 3 * i + k));
    }
    if (curve_count == 0) return HAIRIS_OK;  // nothing to add
    HairCurves curves;
    curves.material = std::uint32_t(material);
    curves.first.assign(first, first + curve_count + 1);
    curves.points.resize(point_count);
    for (size_t i = 0; i < point_count; ++i) curves.points[i] = vec3(positions + 3 * i);
    curves.radii.assign(radii, radii + point_count);
    if (normals) {
        curves.normals.resize(point_count);
        for (size_t i = 0; i < point_count; ++i) curves.normals[i] = vec3(normals + 3 * i);
    }
    const size_t bytes = curves.first.size() * sizeof(std::uint32_t) +
                         point_count * (sizeof(Vec3) + sizeof(float)) + curves.normals.size() * sizeof(Vec3);
    scene->desc.curves.push_back(std::move(curves));
    scene->curve_count += curve_count;
    scene->geometry_bytes += bytes;
    return HAIRIS_OK;
}

// The world of `o` around an environment image (already read): the Mapping and the matrix
// composed into world_to_texture, the sampling settings, colour (default 1 with an image)
// and strength; refusals name the option.
WorldLight environment_world(const OptionReader &reader, const WorldOptions &o,
                             EnvironmentImage image) {
    MappingNode node;
    node.type = MappingType(o.mapping);
    node.rotation = o.rotation;
    node.scale = o.scale;
    Expected<Mat4> mapping = mapping_node_transform(node);
    if (!mapping) invalid("world: " + mapping.error().message);
    EnvironmentDesc desc;
    desc.image = std::move(image);
    desc.world_to_texture = mapping.value() * Mat4::from_row_major(o.matrix);
    desc.strength = o.strength;
    desc.color = reader.has("color") ? o.color : Rgb(1.0f);
    if (o.sampling == 1) desc.map_width = o.map_resolution;  // manual: height = width / 2
    Expected<EnvironmentMap> map = EnvironmentMap::create(std::move(desc));
    if (!map) invalid("world: " + map.error().message);
    WorldLight world;
    world.environment = std::make_shared<const EnvironmentMap>(std::move(map).value());
    world.light_sampled = o.sampling != 2;
    return world;
}

// Reads world options; `pixels` says whether the image comes as an array (then `image` is
// refused).
OptionReader read_world_options(const char *options, WorldOptions &o, bool pixels) {
    Expected<OptionReader> parsed = OptionReader::parse(options ? options : "", "world");
    if (!parsed) invalid(parsed.error().message);
    OptionReader reader = std::move(parsed).value();
    describe(reader, o);
    ok_or_invalid(reader.finish());
    if (pixels && reader.has("image"))
        invalid("world: image must not be given with pixels (the pixels are the image)");
    // Environment settings other than their defaults mean nothing without an environment
    // (hairis_defaults("world") itself reads back).
    const WorldOptions d;
    const bool same_matrix = std::equal(o.matrix, o.matrix + 16, d.matrix);
    const std::pair<const char *, bool> changed[] = {
        {"color_space", o.color_space != d.color_space},
        {"matrix", !same_matrix},
        {"mapping", o.mapping != d.mapping},
        {"rotation", !(o.rotation.x == 0.0f && o.rotation.y == 0.0f && o.rotation.z == 0.0f)},
        {"scale", !(o.scale.x == 1.0f && o.scale.y == 1.0f && o.scale.z == 1.0f)},
        {"sampling", o.sampling != d.sampling},
        {"map_resolution", o.map_resolution != d.map_resolution}};
    if (!pixels && o.image.empty())
        for (const auto &[name, differs] : changed)
            if (differs)
                invalid(std::string("world: ") + name +
                        " needs an environment (image=<path> or hairis_scene_set_world_pixels)");
    if (o.map_resolution != d.map_resolution && o.sampling != 1)
        invalid("world: map_resolution needs sampling=manual (auto follows the image's "
                "resolution)");
    return reader;
}

}  // namespace

}  // namespace hairis::capi

using namespace hairis;
using namespace hairis::capi;

extern "C" {

HAIRIS_API hairis_scene *hairis_scene_create(void) {
    return guard_handle<hairis_scene>("hairis_scene_create", [] { return new hairis_scene(); });
}

HAIRIS_API void hairis_scene_destroy(hairis_scene *scene) {
    guard_void("hairis_scene_destroy", [&] { delete scene; });
}

HAIRIS_API int hairis_scene_add_hair_material(hairis_scene *scene, const hairis_fiber *fiber,
                                              const hairis_tables *tables) {
    return guard_value<int>("hairis_scene_add_hair_material", -1, [&] {
        require(scene, "scene");
        require(fiber, "fiber");
        if (!fiber->chiang && !fiber->huang)
            invalid("fiber must be a chiang2016 or huang2022 fiber (the renderer shades the Principled Hair BSDF), "
                    "got " + fiber->model_name);
        SceneHairMaterial hair;
        hair.fiber = fiber->chiang;
        hair.huang = fiber->huang;
        if (tables) hair.tables = tables->sampling;
        return add_material(*scene, std::move(hair));
    });
}

HAIRIS_API int hairis_scene_add_surface_material(hairis_scene *scene, const char *options) {
    return guard_value<int>("hairis_scene_add_surface_material", -1, [&] {
        require(scene, "scene");
        Expected<OptionReader> reader = OptionReader::parse(options ? options : "", "surface material");
        if (!reader) invalid(reader.error().message);
        int type = 0;
        reader.value().choice("type", type, {"diffuse"});
        DiffuseOptions diffuse;
        describe(reader.value(), diffuse);
        ok_or_invalid(reader.value().finish());
        return add_material(*scene, DiffuseMaterial{diffuse.color, diffuse.emission});
    });
}

HAIRIS_API int hairis_scene_add_curves(hairis_scene *scene, int material, size_t curve_count,
                                       const uint32_t *first, size_t point_count,
                                       const float *positions, const float *radii) {
    return guard_status("hairis_scene_add_curves", [&] {
        return add_curves(scene, material, curve_count, first, point_count, positions, radii, nullptr);
    });
}

HAIRIS_API int hairis_scene_add_curves_with_normals(hairis_scene *scene, int material, size_t curve_count,
                                                    const uint32_t *first, size_t point_count,
                                                    const float *positions, const float *radii,
                                                    const float *normals, const char *options) {
    return guard_status("hairis_scene_add_curves_with_normals", [&] {
        require(scene, "scene");
        require_array(normals, point_count, "normals");
        CurveOptions o;
        read_options(options, "curve options", o);
        return add_curves(scene, material, curve_count, first, point_count, positions, radii, normals);
    });
}

HAIRIS_API int hairis_scene_add_mesh(hairis_scene *scene, size_t vertex_count,
                                     const float *positions, size_t triangle_count,
                                     const uint32_t *indices, const int32_t *materials) {
    return guard_status("hairis_scene_add_mesh", [&] {
        require(scene, "scene");
        require_batch_size(vertex_count, 3, "vertex_count");
        require_batch_size(triangle_count, 3, "triangle_count");
        require_array(positions, vertex_count, "positions");
        require_array(indices, triangle_count, "indices");
        require_array(materials, triangle_count, "materials");
        if (vertex_count > UINT32_MAX)
            invalid("vertex_count must be at most 2^32 - 1 (got " + std::to_string(vertex_count) +
                    ")");
        for (size_t i = 0; i < 3 * vertex_count; ++i)
            require_finite(positions[i], indexed("positions", i));
        for (size_t t = 0; t < triangle_count; ++t) {
            for (size_t k = 0; k < 3; ++k)
                if (indices[3 * t + k] >= vertex_count)
                    invalid(indexed("indices", 3 * t + k) + " = " +
                            std::to_string(indices[3 * t + k]) +
                            " must be a vertex index in [0, vertex_count = " +
                            std::to_string(vertex_count) + ")");
            const int32_t m = materials[t];
            if (m < 0 || size_t(m) >= scene->materials.size())
                invalid(indexed("materials", t) + " must be the index of a material added to "
                        "the scene, in [0, " + std::to_string(scene->materials.size()) +
                        ") (got " + std::to_string(m) + ")");
            if (!std::holds_alternative<DiffuseMaterial>(scene->materials[size_t(m)]))
                invalid(indexed("materials", t) + " = " + std::to_string(m) +
                        " is a hair material; meshes need a surface material");
        }
        if (triangle_count == 0) return HAIRIS_OK;  // nothing to draw
        TriangleMesh mesh;
        mesh.positions.resize(vertex_count);
        for (size_t v = 0; v < vertex_count; ++v) mesh.positions[v] = vec3(positions + 3 * v);
        mesh.indices.assign(indices, indices + 3 * triangle_count);
        mesh.materials.assign(materials, materials + triangle_count);  // all >= 0, checked
        const size_t bytes = vertex_count * sizeof(Vec3) +
                             triangle_count * 4 * sizeof(std::uint32_t);
        scene->desc.meshes.push_back(std::move(mesh));
        scene->triangle_count += triangle_count;
        scene->geometry_bytes += bytes;
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_add_light(hairis_scene *scene, const char *options) {
    return guard_status("hairis_scene_add_light", [&] {
        require(scene, "scene");
        const std::string what =
            "light " + std::to_string(scene->desc.suns.size() + scene->desc.point_lights.size() +
                                      scene->desc.spot_lights.size() +
                                      scene->desc.area_lights.size());
        Expected<OptionReader> parsed = OptionReader::parse(options ? options : "", what);
        if (!parsed) invalid(parsed.error().message);
        OptionReader &reader = parsed.value();
        if (!reader.has("type")) invalid(what + ": type must be given (sun, point, spot or area)");
        int type = 0;
        reader.choice("type", type, {"sun", "point", "area", "spot"});
        if (type == 0) {
            SunLight sun;
            describe(reader, sun);
            ok_or_invalid(reader.finish());
            if (!(length(sun.to_sun) > 0.0f)) invalid(what + ": direction must not be the zero vector");
            sun.to_sun = safe_normalize(sun.to_sun);
            scene->desc.suns.push_back(sun);
        } else if (type == 1) {
            PointLight point;
            describe(reader, point);
            ok_or_invalid(reader.finish());
            if (point.cycles == CyclesVersion::V3_4 && !point.soft_falloff)
                invalid(what + ": soft_falloff=0 (a sphere) needs cycles=4.5; Cycles 3.4 has "
                               "only the disk");
            scene->desc.point_lights.push_back(point);
        } else if (type == 3) {
            SpotOptions o;
            describe(reader, o);
            ok_or_invalid(reader.finish());
            SpotLight spot;
            spot.light_to_world = Mat4::from_row_major(o.matrix);
            if (!(length(spot.light_to_world.column(2)) > 0.0f))
                invalid(what + ": matrix has a zero Z axis (column 2): the spot has no direction");
            if (o.cycles == CyclesVersion::V3_4 && !o.soft_falloff)
                invalid(what + ": soft_falloff=0 (a sphere) needs cycles=4.5; Cycles 3.4 has "
                               "only the disk");
            spot.color = o.color;
            spot.power = o.power;
            spot.radius = o.radius;
            spot.spot_size = o.spot_size;
            spot.spot_blend = o.spot_blend;
            spot.cycles = o.cycles;
            spot.soft_falloff = o.soft_falloff;
            // Refused now rather than at render time (e.g. a singular matrix for 4.5).
            LightsDesc check;
            check.spots = {spot};
            Expected<LightSet> checked = LightSet::build(check, {});
            if (!checked) invalid(what + ": " + checked.error().message);
            scene->desc.spot_lights.push_back(spot);
        } else {
            AreaOptions o;
            describe(reader, o);
            ok_or_invalid(reader.finish());
            AreaLight light;
            light.light_to_world = Mat4::from_row_major(o.matrix);
            if (!(length(light.light_to_world.column(2)) > 0.0f))
                invalid(what + ": matrix has a zero Z axis (column 2): the light has no emitting direction");
            light.shape = AreaShape(o.shape);
            light.size_x = o.size;
            light.size_y = o.size_y;
            light.color = o.color;
            light.power = o.power;
            light.cycles = o.cycles;
            scene->desc.area_lights.push_back(light);
        }
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_set_world(hairis_scene *scene, const char *options) {
    return guard_status("hairis_scene_set_world", [&] {
        require(scene, "scene");
        WorldOptions o;
        const OptionReader reader = read_world_options(options, o, false);
        if (o.image.empty()) {
            WorldLight world;
            world.color = o.color;
            world.strength = o.strength;
            scene->desc.world = world;
            return HAIRIS_OK;
        }
        Expected<EnvironmentImage> image =
            load_environment_image(o.image, ImageColorSpace(o.color_space));
        if (!image) invalid("world: image: " + image.error().message);
        scene->desc.world = environment_world(reader, o, std::move(image).value());
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_set_world_pixels(hairis_scene *scene, const char *options,
                                             const float *pixels, size_t width, size_t height,
                                             int channels) {
    return guard_status("hairis_scene_set_world_pixels", [&] {
        require(scene, "scene");
        WorldOptions o;
        const OptionReader reader = read_world_options(options, o, true);
        if (o.color_space == int(ImageColorSpace::Auto))
            invalid("world: color_space must be linear or srgb with pixels (an array does not "
                    "say what it holds)");
        if (width < 1 || height < 1 || width > size_t(kMaxEnvironmentImageAxis) ||
            height > size_t(kMaxEnvironmentImageAxis))
            invalid("width and height must be in [1, " +
                    std::to_string(kMaxEnvironmentImageAxis) + "] (got " +
                    std::to_string(width) + " x " + std::to_string(height) + ")");
        if (channels < 1 || channels > 4)
            invalid("channels must be in [1, 4] (got " + std::to_string(channels) + ")");
        const long long count = (long long)width * (long long)height * channels;
        require_array(pixels, size_t(count), "pixels");
        Expected<EnvironmentImage> image = EnvironmentImage::from_pixels(
            pixels, count, int(width), int(height), channels, ImageColorSpace(o.color_space));
        if (!image) invalid("world: pixels: " + image.error().message);
        scene->desc.world = environment_world(reader, o, std::move(image).value());
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_set_camera(hairis_scene *scene, const char *options) {
    return guard_status("hairis_scene_set_camera", [&] {
        require(scene, "scene");
        CameraOptions c;
        read_options(options, "camera", c);
        CameraDesc desc;
        desc.camera_to_world = Mat4::from_row_major(c.matrix);
        desc.projection = c.orthographic ? Projection::Orthographic : Projection::Perspective;
        for (size_t i = 0; i < 4; ++i) desc.frame[i] = vec3(c.frame + 3 * i);
        desc.width = c.width;
        desc.height = c.height;
        desc.clip_start = c.clip_start;
        desc.clip_end = c.clip_end >= std::numeric_limits<float>::max() ? INFINITY : c.clip_end;
        // Refused now rather than at render time; the messages start with "camera: ".
        Expected<Camera> checked = Camera::create(desc);
        if (!checked) invalid(checked.error().message);
        scene->desc.camera = desc;
        scene->has_camera = true;
        return HAIRIS_OK;
    });
}

}  // extern "C"
