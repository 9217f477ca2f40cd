// C API: building a render scene incrementally (materials, curves, meshes, lights, world,
// camera). Every input is checked when it is added, so an error names the call and argument
// that caused it; Scene::build (at render time) checks the whole again.
#include <climits>
#include <string>

#include "capi_scene.h"
#include "hairis/camera.h"
#include "hairis/lights.h"

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
Rgb rgb(const float *v) { return {v[0], v[1], v[2]}; }

void require_finite3(const float *v, const char *name) {
    require(v, name);
    for (size_t k = 0; k < 3; ++k) require_finite(v[k], indexed(name, k));
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

HAIRIS_API int hairis_scene_add_hair_material(hairis_scene *scene,
                                              const hairis_principled_hair *node,
                                              const hairis_tables *tables) {
    return guard_value<int>("hairis_scene_add_hair_material", -1, [&] {
        require(scene, "scene");
        require(node, "node");
        FiberSpec spec;
        spec.kind = FiberKind::Chiang;
        spec.node = to_node(*node, "node");
        Expected<std::unique_ptr<FiberModel>> model = spec.create_model();
        if (!model) invalid("node." + model.error().message);
        SceneHairMaterial hair;
        hair.fiber = std::dynamic_pointer_cast<const ChiangFiber>(
            std::shared_ptr<const FiberModel>(std::move(model).value()));
        if (!hair.fiber) refuse(HAIRIS_ERROR_INTERNAL, "a Principled Hair node gave no Chiang fiber");
        hair.model = hair.fiber->name();
        hair.parameters = spec_parameters(spec);
        if (tables) {
            hair.has_tables = true;
            hair.tables = tables->sampling;
            hair.tables_model = tables->set.model;
            hair.tables_parameters = tables->parameters;
            hair.tables_n_h = tables->set.n_h_values;
        }
        return add_material(*scene, std::move(hair));
    });
}

HAIRIS_API int hairis_scene_add_diffuse_material(hairis_scene *scene, const float albedo[3],
                                                 const float emission[3]) {
    return guard_value<int>("hairis_scene_add_diffuse_material", -1, [&] {
        require(scene, "scene");
        require(albedo, "albedo");
        require(emission, "emission");
        for (size_t k = 0; k < 3; ++k)
            if (!(albedo[k] >= 0.0f && albedo[k] <= 1.0f))
                invalid(indexed("albedo", k) + " must be finite and in [0, 1] (got " +
                        describe(albedo[k]) + ")");
        require_colour(emission, "emission");
        return add_material(*scene, DiffuseMaterial{rgb(albedo), rgb(emission)});
    });
}

HAIRIS_API int hairis_scene_add_curves(hairis_scene *scene, int material, size_t curve_count,
                                       const uint32_t *first, size_t point_count,
                                       const float *positions, const float *radii) {
    return guard_status("hairis_scene_add_curves", [&] {
        require(scene, "scene");
        require(first, "first");
        require_array(positions, point_count, "positions");
        require_array(radii, point_count, "radii");
        if (material < 0 || size_t(material) >= scene->materials.size())
            invalid("material must be the index of a material added to the scene, in [0, " +
                    std::to_string(scene->materials.size()) + ") (got " +
                    std::to_string(material) + ")");
        if (point_count > kMaxCurvePoints)
            invalid("point_count must be at most 2^31 per call (got " +
                    std::to_string(point_count) + ")");
        if (curve_count > point_count / 2)
            invalid("curve_count (" + std::to_string(curve_count) +
                    ") needs at least 2 points per curve, but point_count is " +
                    std::to_string(point_count));
        if (first[0] != 0) invalid("first[0] must be 0 (got " + std::to_string(first[0]) + ")");
        for (size_t c = 0; c < curve_count; ++c)
            if (!(first[c + 1] >= first[c] && first[c + 1] - first[c] >= 2))
                invalid("curve " + std::to_string(c) + ": first[" + std::to_string(c + 1) + "] = " +
                        std::to_string(first[c + 1]) + " must be at least first[" +
                        std::to_string(c) + "] + 2 = " + std::to_string(size_t(first[c]) + 2) +
                        " (a curve has at least 2 points)");
        if (first[curve_count] != point_count)
            invalid("first[curve_count] must equal point_count (" + std::to_string(point_count) +
                    "; got " + std::to_string(first[curve_count]) + ")");
        for (size_t i = 0; i < point_count; ++i) {
            for (size_t k = 0; k < 3; ++k)
                require_finite(positions[3 * i + k], indexed("positions", 3 * i + k));
            require_non_negative(radii[i], indexed("radii", i));
        }
        if (curve_count == 0) return HAIRIS_OK;  // nothing to add
        HairCurves curves;
        curves.material = std::uint32_t(material);
        curves.first.assign(first, first + curve_count + 1);
        curves.points.resize(point_count);
        for (size_t i = 0; i < point_count; ++i) curves.points[i] = vec3(positions + 3 * i);
        curves.radii.assign(radii, radii + point_count);
        const size_t bytes = curves.first.size() * sizeof(std::uint32_t) +
                             point_count * (sizeof(Vec3) + sizeof(float));
        scene->desc.curves.push_back(std::move(curves));
        scene->curve_count += curve_count;
        scene->geometry_bytes += bytes;
        return HAIRIS_OK;
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
                        " is a hair material; meshes need a diffuse material");
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

HAIRIS_API int hairis_scene_add_sun(hairis_scene *scene, const float direction[3],
                                    const float color[3], float strength, float angle) {
    return guard_status("hairis_scene_add_sun", [&] {
        require(scene, "scene");
        require_finite3(direction, "direction");
        require_colour(color, "color");
        require_non_negative(strength, "strength");
        if (!(angle >= 0.0f && angle < float(kPi)))
            invalid("angle must be finite and in [0, pi) radians (got " + describe(angle) + ")");
        const Vec3 d = vec3(direction);
        if (!(length(d) > 0.0f)) invalid("direction must not be the zero vector");
        SunLight sun;
        sun.to_sun = safe_normalize(d);
        sun.color = rgb(color);
        sun.strength = strength;
        sun.angle = angle;
        scene->desc.suns.push_back(sun);
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_add_point_light(hairis_scene *scene, const float position[3],
                                            const float color[3], float power, float radius) {
    return guard_status("hairis_scene_add_point_light", [&] {
        require(scene, "scene");
        require_finite3(position, "position");
        require_colour(color, "color");
        require_non_negative(power, "power");
        require_non_negative(radius, "radius");
        PointLight light;
        light.position = vec3(position);
        light.color = rgb(color);
        light.power = power;
        light.radius = radius;
        scene->desc.point_lights.push_back(light);
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_add_area_light(hairis_scene *scene, const float light_to_world[16],
                                           int shape, float size_x, float size_y,
                                           const float color[3], float power) {
    return guard_status("hairis_scene_add_area_light", [&] {
        require(scene, "scene");
        require(light_to_world, "light_to_world");
        for (size_t k = 0; k < 16; ++k)
            require_finite(light_to_world[k], indexed("light_to_world", k));
        if (shape < HAIRIS_AREA_SQUARE || shape > HAIRIS_AREA_ELLIPSE)
            invalid("shape must be HAIRIS_AREA_SQUARE (0), RECTANGLE (1), DISK (2) or ELLIPSE (3) "
                    "(got " + std::to_string(shape) + ")");
        require_non_negative(size_x, "size_x");
        require_non_negative(size_y, "size_y");
        require_colour(color, "color");
        require_non_negative(power, "power");
        AreaLight light;
        light.light_to_world = Mat4::from_row_major(light_to_world);
        if (!(length(light.light_to_world.column(2)) > 0.0f))
            invalid("light_to_world has a zero Z axis (column 2): the light has no emitting "
                    "direction");
        light.shape = AreaShape(shape);
        light.size_x = size_x;
        light.size_y = size_y;
        light.color = rgb(color);
        light.power = power;
        scene->desc.area_lights.push_back(light);
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_set_world(hairis_scene *scene, const float color[3],
                                      float strength) {
    return guard_status("hairis_scene_set_world", [&] {
        require(scene, "scene");
        require_colour(color, "color");
        require_non_negative(strength, "strength");
        scene->desc.world = WorldLight{rgb(color), strength};
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_set_camera(hairis_scene *scene, const hairis_camera *camera) {
    return guard_status("hairis_scene_set_camera", [&] {
        require(scene, "scene");
        require(camera, "camera");
        const hairis_camera &c = *camera;
        if (c.orthographic != 0 && c.orthographic != 1)
            invalid("camera.orthographic must be 0 (perspective) or 1 (orthographic) (got " +
                    std::to_string(c.orthographic) + ")");
        for (size_t k = 0; k < 16; ++k)
            require_finite(c.camera_to_world[k], indexed("camera.camera_to_world", k));
        for (size_t k = 0; k < 12; ++k) require_finite(c.frame[k], indexed("camera.frame", k));
        CameraDesc desc;
        desc.camera_to_world = Mat4::from_row_major(c.camera_to_world);
        desc.projection = c.orthographic ? Projection::Orthographic : Projection::Perspective;
        for (size_t i = 0; i < 4; ++i) desc.frame[i] = vec3(c.frame + 3 * i);
        desc.width = c.width;
        desc.height = c.height;
        // Refused now rather than at render time; the messages start with "camera: ".
        Expected<Camera> checked = Camera::create(desc);
        if (!checked) invalid(checked.error().message);
        scene->desc.camera = desc;
        scene->has_camera = true;
        return HAIRIS_OK;
    });
}

}  // extern "C"
