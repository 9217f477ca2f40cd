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
#include "render/surface_material.h"
#include "render/texture.h"

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

std::string name_of(CyclesVersion v) { return v == CyclesVersion::V3_4 ? "3.4" : "4.5"; }

// The texture of a colour input's `<name>_texture` option (-1: none).
std::shared_ptr<const ImageTexture> texture_of(const hairis_scene &scene, int index, const char *name) {
    if (index < 0) return nullptr;
    if (size_t(index) >= scene.textures.size())
        invalid(std::string(name) + " must be the index of a texture added to the scene, in [0, " +
                std::to_string(scene.textures.size()) + "), or -1 for none (got " +
                std::to_string(index) + ")");
    return scene.textures[size_t(index)];
}

// A surface material already in the scene, for Mix and Add Shaders.
const SurfaceMaterial &surface_of(const hairis_scene &scene, int index, const char *name) {
    if (index < 0 || size_t(index) >= scene.materials.size())
        invalid(std::string(name) + " must be the index of a surface material added to the "
                "scene, in [0, " + std::to_string(scene.materials.size()) + ") (got " +
                std::to_string(index) + ")");
    const auto *surface = std::get_if<SurfaceMaterial>(&scene.materials[size_t(index)]);
    if (!surface)
        invalid(std::string(name) + " = " + std::to_string(index) +
                " is a hair material; Mix and Add Shaders combine surface materials");
    return *surface;
}

SurfaceMaterial make_surface(std::vector<SurfaceNode> nodes, const std::string &what) {
    Expected<SurfaceMaterial> m = SurfaceMaterial::create(std::move(nodes));
    if (!m) invalid(what + ": " + m.error().message);
    return std::move(m).value();
}

bool same(Rgb a, Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

// Options the chosen Cycles version has no input for must keep their defaults (so that
// hairis_defaults("principled") reads back).
void refuse_other_version(const PrincipledOptions &o) {
    const PrincipledOptions d;
    const bool v34 = o.cycles == CyclesVersion::V3_4;
    const std::pair<const char *, bool> changed[] = {
        {"specular_tint_color", v34 && !same(o.specular_tint_color, d.specular_tint_color)},
        {"coat_ior", v34 && o.coat_ior != d.coat_ior},
        {"coat_tint", v34 && !same(o.coat_tint, d.coat_tint)},
        {"diffuse_roughness", v34 && o.diffuse_roughness != d.diffuse_roughness},
        {"specular_tint", !v34 && o.specular_tint != d.specular_tint},
        {"subsurface_color", !v34 && !same(o.subsurface_color, d.subsurface_color)},
        {"sheen", !v34 && o.sheen != d.sheen},
        {"sheen_tint", !v34 && o.sheen_tint != d.sheen_tint}};
    for (const auto &[name, differs] : changed)
        if (differs)
            invalid(std::string("surface material (principled): ") + name + " is not an input hairis "
                    "renders for the Principled BSDF of cycles=" + name_of(o.cycles) +
                    " (leave it at its default)");
}

SurfaceMaterial principled_material(const hairis_scene &scene, const PrincipledOptions &o) {
    const char *what = "surface material (principled)";
    refuse_other_version(o);
    PrincipledBsdfNode p;
    p.cycles = o.cycles;
    p.multiscatter = o.multiscatter;
    p.base_color.value = o.base_color;
    p.base_color.texture = texture_of(scene, o.base_color_texture, "base_color_texture");
    p.metallic = o.metallic;
    p.roughness = o.roughness;
    p.ior = o.ior;
    p.specular = o.specular;
    p.specular_tint = o.specular_tint;
    p.specular_tint_color = o.specular_tint_color;
    p.subsurface = o.subsurface;
    p.subsurface_color = o.subsurface_color;
    p.sheen = o.sheen;
    p.sheen_tint = o.sheen_tint;
    p.coat = o.coat;
    p.coat_roughness = o.coat_roughness;
    p.coat_ior = o.coat_ior;
    p.coat_tint = o.coat_tint;
    p.diffuse_roughness = o.diffuse_roughness;
    p.emission = o.emission;
    return make_surface({p}, what);
}

// Reads the options of one surface material type and makes it.
SurfaceMaterial surface_material(const hairis_scene &scene, const char *options) {
    Expected<OptionReader> parsed = OptionReader::parse(options ? options : "", "surface material");
    if (!parsed) invalid(parsed.error().message);
    OptionReader &reader = parsed.value();
    int type = 0;
    reader.choice("type", type, {"diffuse", "principled", "glossy", "emission", "mix", "add"});
    switch (type) {
        case 0: {
            DiffuseOptions o;
            describe(reader, o);
            ok_or_invalid(reader.finish());
            DiffuseBsdfNode d;
            d.cycles = o.cycles;
            d.color.value = o.color;
            d.color.texture = texture_of(scene, o.color_texture, "color_texture");
            d.roughness = o.roughness;
            if (o.emission.max_component() > 0.0f)
                return make_surface({d, EmissionNode{o.emission, 1.0f}, AddShaderNode{0, 1}}, "surface material (diffuse)");
            return make_surface({d}, "surface material (diffuse)");
        }
        case 1: {
            PrincipledOptions o;
            describe(reader, o);
            ok_or_invalid(reader.finish());
            return principled_material(scene, o);
        }
        case 2: {
            GlossyOptions o;
            describe(reader, o);
            ok_or_invalid(reader.finish());
            GlossyBsdfNode g;
            g.cycles = o.cycles;
            g.multiscatter = o.multiscatter;
            g.color.value = o.color;
            g.color.texture = texture_of(scene, o.color_texture, "color_texture");
            g.roughness = o.roughness;
            return make_surface({g}, "surface material (glossy)");
        }
        case 3: {
            EmissionOptions o;
            describe(reader, o);
            ok_or_invalid(reader.finish());
            return make_surface({EmissionNode{o.color, o.strength}}, "surface material (emission)");
        }
        case 4: {
            MixOptions o;
            describe(reader, o);
            ok_or_invalid(reader.finish());
            const SurfaceMaterial &first = surface_of(scene, o.shader1, "shader1");
            const SurfaceMaterial &second = surface_of(scene, o.shader2, "shader2");
            Expected<SurfaceMaterial> m = SurfaceMaterial::combine(first, second, o.factor);
            if (!m) invalid("surface material (mix): " + m.error().message);
            return std::move(m).value();
        }
        default: {
            AddOptions o;
            describe(reader, o);
            ok_or_invalid(reader.finish());
            const SurfaceMaterial &first = surface_of(scene, o.shader1, "shader1");
            const SurfaceMaterial &second = surface_of(scene, o.shader2, "shader2");
            Expected<SurfaceMaterial> m = SurfaceMaterial::combine(first, second, std::nullopt);
            if (!m) invalid("surface material (add): " + m.error().message);
            return std::move(m).value();
        }
    }
}

// The texture of options `o` around an image already read or copied.
int add_texture(hairis_scene &scene, const TextureOptions &o, EnvironmentImage image) {
    if (scene.textures.size() >= size_t(kMaxTextures))
        invalid("scene already has " + std::to_string(kMaxTextures) + " textures (the most allowed)");
    ImageTextureDesc desc;
    desc.image = std::make_shared<const EnvironmentImage>(std::move(image));
    desc.interpolation = TextureInterpolation(o.interpolation);
    desc.extension = TextureExtension(o.extension);
    desc.use_mapping = o.mapping != 0;
    if (desc.use_mapping) {
        desc.mapping.type = MappingType(o.mapping - 1);
        desc.mapping.location = o.location;
        desc.mapping.rotation = o.rotation;
        desc.mapping.scale = o.scale;
    }
    Expected<ImageTexture> texture = ImageTexture::create(std::move(desc));
    if (!texture) invalid("texture: " + texture.error().message);
    scene.geometry_bytes += texture.value().image().rgb().size() * sizeof(float);
    scene.textures.push_back(std::make_shared<const ImageTexture>(std::move(texture).value()));
    return int(scene.textures.size() - 1);
}

// Reads texture options; mapping inputs other than their defaults need a mapping.
TextureOptions read_texture_options(const char *options, bool pixels) {
    Expected<OptionReader> parsed = OptionReader::parse(options ? options : "", "texture");
    if (!parsed) invalid(parsed.error().message);
    OptionReader &reader = parsed.value();
    TextureOptions o;
    describe(reader, o);
    ok_or_invalid(reader.finish());
    if (pixels && reader.has("image"))
        invalid("texture: image must not be given with pixels (the pixels are the image)");
    if (!pixels && o.image.empty())
        invalid("texture: image=<path> must be given (or use hairis_scene_add_texture_pixels)");
    const TextureOptions d;
    const auto same3 = [](Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; };
    const std::pair<const char *, bool> changed[] = {{"location", !same3(o.location, d.location)},
                                                     {"rotation", !same3(o.rotation, d.rotation)},
                                                     {"scale", !same3(o.scale, d.scale)}};
    if (o.mapping == 0)
        for (const auto &[name, differs] : changed)
            if (differs)
                invalid(std::string("texture: ") + name + " needs a mapping (mapping=point, texture or vector)");
    return o;
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

// Reads a spot's or an area's options: a light placed by its object's matrix, refused when the
// matrix's Z axis is zero since the light shines along it.
template <typename Options>
auto read_placed_light(OptionReader &reader, Options &o, const std::string &what,
                       const char *consequence) {
    describe(reader, o);
    ok_or_invalid(reader.finish());
    auto light = o.light;
    light.light_to_world = Mat4::from_row_major(o.matrix);
    if (!(length(light.light_to_world.column(2)) > 0.0f))
        invalid(what + ": matrix has a zero Z axis (column 2): " + consequence);
    return light;
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
                "resolution, at least 4096 x 2048)");
    return reader;
}

const char *parametrization_name(HairParametrization p) {
    switch (p) {
        case HairParametrization::AbsorptionCoefficient: return "absorption";
        case HairParametrization::Melanin: return "melanin";
        case HairParametrization::Color: return "color";
    }
    return "unknown";
}

// The curves of hairis_scene_add_curves, checked (the arguments named); empty when
// curve_count is 0.
HairCurves checked_curves(const hairis_scene *scene, int material, size_t curve_count, const uint32_t *first,
                          size_t point_count, const float *positions, const float *radii) {
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
            if (!std::isfinite(positions[3 * i + k]))
                require_finite(positions[3 * i + k], indexed("positions", 3 * i + k));
        if (!(radii[i] >= 0.0f && std::isfinite(radii[i]))) require_non_negative(radii[i], indexed("radii", i));
    }
    HairCurves curves;
    if (curve_count == 0) return curves;  // nothing to add
    curves.material = std::uint32_t(material);
    curves.first.assign(first, first + curve_count + 1);
    curves.points.resize(point_count);
    for (size_t i = 0; i < point_count; ++i) curves.points[i] = vec3(positions + 3 * i);
    curves.radii.assign(radii, radii + point_count);
    return curves;
}

// Whether `hair`, or another closure of its mixture, reads `input`.
// Whether the material's model reads `input` (Huang has no Radial Roughness and no Coat).
bool material_reads(const SceneHairMaterial &hair, HairInput input) {
    if (hair.huang && (input == HairInput::RadialRoughness || input == HairInput::Coat)) return false;
    return reads(hair.node.parametrization, input);
}

bool mixture_reads(const hairis_scene &scene, const SceneHairMaterial &hair, HairInput input) {
    if (material_reads(hair, input)) return true;
    for (size_t m : hair.closures)
        if (material_reads(std::get<SceneHairMaterial>(scene.materials[m]), input)) return true;
    return false;
}

void add(hairis_scene &scene, HairCurves curves) {
    size_t bytes = curves.first.size() * sizeof(std::uint32_t) +
                   curves.points.size() * (sizeof(Vec3) + sizeof(float));
    for (const CurveInput &in : curves.inputs) bytes += in.values.size() * sizeof(float);
    bytes += curves.normals.size() * sizeof(Vec3);
    scene.curve_count += curves.first.size() - 1;
    scene.desc.curves.push_back(std::move(curves));
    scene.geometry_bytes += bytes;
}

// The pixel arguments of an image given as an array (a texture's or the world's): an explicit
// colour space, a size within the image limits, 1 to 4 channels; returns the float count.
long long checked_pixels(const std::string &what, int color_space, const float *pixels, size_t width,
                         size_t height, int channels) {
    if (color_space == int(ImageColorSpace::Auto))
        invalid(what + ": color_space must be linear or srgb with pixels (an array does not say what it holds)");
    if (width < 1 || height < 1 || width > size_t(kMaxEnvironmentImageAxis) ||
        height > size_t(kMaxEnvironmentImageAxis))
        invalid("width and height must be in [1, " + std::to_string(kMaxEnvironmentImageAxis) + "] (got " +
                std::to_string(width) + " x " + std::to_string(height) + ")");
    if (channels < 1 || channels > 4) invalid("channels must be in [1, 4] (got " + std::to_string(channels) + ")");
    const long long count = (long long)width * (long long)height * channels;
    require_array(pixels, size_t(count), "pixels");
    return count;
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
        if (scene) scene->forget_shading();  // the BVH stays
        require(scene, "scene");
        require(fiber, "fiber");
        if (!fiber->chiang && !fiber->huang)
            invalid("fiber must be a chiang2016 or huang2022 fiber (the renderer shades the Principled Hair BSDF), "
                    "got " + fiber->model_name);
        SceneHairMaterial hair;
        hair.fiber = fiber->chiang;
        hair.node = fiber->spec.node;
        hair.huang = fiber->huang;
        if (tables) hair.tables = tables->sampling;
        return add_material(*scene, std::move(hair));
    });
}

HAIRIS_API int hairis_scene_add_hair_mixture(hairis_scene *scene, size_t count, const int *materials,
                                             const float *weights) {
    return guard_value<int>("hairis_scene_add_hair_mixture", -1, [&] {
        if (scene) scene->forget_shading();  // the BVH stays
        require(scene, "scene");
        if (count < 1 || count > size_t(kMaxHairClosures))
            invalid("hair mixture: count must be in [1, " + std::to_string(kMaxHairClosures) + "] (got " +
                    std::to_string(count) + ")");
        require_array(materials, count, "materials");
        require_array(weights, count, "weights");
        SceneHairMaterial mixture;
        for (size_t k = 0; k < count; ++k) {
            const int m = materials[k];
            const std::string which = "hair mixture: closure " + std::to_string(k) + ": material " + std::to_string(m);
            if (m < 0 || size_t(m) >= scene->materials.size())
                invalid(which + " is not in the scene, in [0, " + std::to_string(scene->materials.size()) + ")");
            const auto *hair = std::get_if<SceneHairMaterial>(&scene->materials[size_t(m)]);
            if (!hair || !hair->closures.empty())
                invalid(which + " is not a hair material of one fiber (hairis_scene_add_hair_material); a "
                                "mixture mixes those");
            if (hair->huang)
                invalid(which + " is huang2022; a mixture mixes chiang2016 materials in this version");
            if (!std::isfinite(weights[k]) || weights[k] < 0.0f)
                invalid("hair mixture: closure " + std::to_string(k) + "'s weight is " + format_number(weights[k]) +
                        "; weights must be finite and >= 0");
            if (k == 0) mixture = *hair;
            mixture.closures.push_back(size_t(m));
            mixture.weights.push_back(weights[k]);
        }
        return add_material(*scene, std::move(mixture));
    });
}

HAIRIS_API int hairis_scene_add_surface_material(hairis_scene *scene, const char *options) {
    return guard_value<int>("hairis_scene_add_surface_material", -1, [&] {
        if (scene) scene->forget_shading();  // the BVH stays
        require(scene, "scene");
        return add_material(*scene, surface_material(*scene, options));
    });
}

HAIRIS_API int hairis_scene_add_texture(hairis_scene *scene, const char *options) {
    return guard_value<int>("hairis_scene_add_texture", -1, [&] {
        if (scene) scene->forget_shading();  // the BVH stays
        require(scene, "scene");
        const TextureOptions o = read_texture_options(options, false);
        Expected<EnvironmentImage> image = load_environment_image(o.image, ImageColorSpace(o.color_space));
        if (!image) refuse(code_of(image.error().kind), "texture: image: " + image.error().message);
        return add_texture(*scene, o, std::move(image).value());
    });
}

HAIRIS_API int hairis_scene_add_texture_pixels(hairis_scene *scene, const char *options,
                                               const float *pixels, size_t width, size_t height,
                                               int channels) {
    return guard_value<int>("hairis_scene_add_texture_pixels", -1, [&] {
        if (scene) scene->forget_shading();  // the BVH stays
        require(scene, "scene");
        const TextureOptions o = read_texture_options(options, true);
        const long long count = checked_pixels("texture", int(o.color_space), pixels, width, height, channels);
        Expected<EnvironmentImage> image = EnvironmentImage::from_pixels(
            pixels, count, int(width), int(height), channels, ImageColorSpace(o.color_space));
        if (!image) invalid("texture: pixels: " + image.error().message);
        return add_texture(*scene, o, std::move(image).value());
    });
}

HAIRIS_API int hairis_scene_set_mesh_attribute(hairis_scene *scene, const char *options,
                                               const float *values, size_t count) {
    return guard_status("hairis_scene_set_mesh_attribute", [&] {
        if (scene) scene->forget_build();  // new geometry needs a new BVH
        require(scene, "scene");
        MeshAttributeOptions o;
        read_options(options, "mesh attribute", o);
        if (scene->last_mesh < 0)
            invalid("mesh attribute: the last hairis_scene_add_mesh call added no triangles, so "
                    "there is no mesh to attach corner data to");
        TriangleMesh &mesh = scene->desc.meshes[size_t(scene->last_mesh)];
        const size_t corners = mesh.indices.size();
        const size_t per_corner = o.name == 0 ? 3 : 2;
        if (count != corners * per_corner)
            invalid(std::string("mesh attribute ") + (o.name == 0 ? "normal" : "uv") + ": count must be " +
                    std::to_string(per_corner) + " floats per triangle corner of the last mesh (" +
                    std::to_string(corners) + " corners: " + std::to_string(corners * per_corner) +
                    "), got " + std::to_string(count));
        require_array(values, count, "values");
        for (size_t i = 0; i < count; ++i)
            if (!std::isfinite(values[i])) require_finite(values[i], indexed("values", i));
        if (o.name == 0) {
            std::vector<Vec3> normals(corners);
            for (size_t k = 0; k < corners; ++k) {
                normals[k] = vec3(values + 3 * k);
                if (!(length(normals[k]) > 0.0f))
                    invalid("mesh attribute normal: corner " + std::to_string(k) + " has a zero normal");
            }
            scene->geometry_bytes += (normals.size() - mesh.normals.size()) * sizeof(Vec3);
            mesh.normals = std::move(normals);
        } else {
            scene->geometry_bytes += (count - mesh.uvs.size()) * sizeof(float);
            mesh.uvs.assign(values, values + count);
        }
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_add_curves(hairis_scene *scene, int material, size_t curve_count,
                                       const uint32_t *first, size_t point_count,
                                       const float *positions, const float *radii) {
    return guard_status("hairis_scene_add_curves", [&] {
        if (scene) scene->forget_build();  // new geometry needs a new BVH
        HairCurves curves = checked_curves(scene, material, curve_count, first, point_count, positions, radii);
        if (curve_count > 0) add(*scene, std::move(curves));
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_add_curves_with_inputs(hairis_scene *scene, int material, size_t curve_count,
                                                   const uint32_t *first, size_t point_count,
                                                   const float *positions, const float *radii,
                                                   const char *inputs, size_t value_count,
                                                   const float *values) {
    return guard_status("hairis_scene_add_curves_with_inputs", [&] {
        if (scene) scene->forget_build();  // new geometry needs a new BVH
        HairCurves curves = checked_curves(scene, material, curve_count, first, point_count, positions, radii);
        CurveInputOptions o;
        read_options(inputs, "curve inputs", o);
        const auto *hair = std::get_if<SceneHairMaterial>(&scene->materials[size_t(material)]);
        size_t needed = 0;
        for (int i = 0; i < kHairInputCount; ++i) {
            if (o.domain[i] == 0) continue;
            const HairInputInfo &info = hair_input_info(HairInput(i));
            if (!hair)
                invalid(std::string("curve inputs: ") + info.name + " needs a hair material; material " +
                        std::to_string(material) + " is a surface material");
            if (!mixture_reads(*scene, *hair, HairInput(i)))
                invalid(std::string("curve inputs: ") + info.name + " is not read by material " +
                        std::to_string(material) + "'s model and parametrization (" +
                        (hair->huang ? "huang2022, " : "") + parametrization_name(hair->node.parametrization) + ")" +
                        (hair->closures.empty() ? "" : " nor by another of its closures"));
            needed += size_t(info.components) * (o.domain[i] == 2 ? point_count : curve_count);
        }
        for (int k = 0; k < kMaxHairClosures; ++k) {
            if (o.weight_domain[k] == 0) continue;
            const size_t closures = hair ? hair->closures.size() : 0;
            if (size_t(k) >= closures)
                invalid("curve inputs: weight" + std::to_string(k) + " needs a hair mixture of more than " +
                        std::to_string(k) + " closures; material " + std::to_string(material) + " mixes " +
                        std::to_string(closures) + " (hairis_scene_add_hair_mixture)");
            needed += o.weight_domain[k] == 2 ? point_count : curve_count;
        }
        if (value_count != needed)
            invalid("value_count must be " + std::to_string(needed) + " (the inputs' components for each of " +
                    std::to_string(curve_count) + " curves or " + std::to_string(point_count) +
                    " points, in hairis_defaults(\"curve_inputs\")'s order), got " + std::to_string(value_count));
        require_array(values, value_count, "values");
        size_t at = 0;
        for (int i = 0; i < kHairInputCount; ++i) {
            if (o.domain[i] == 0) continue;
            const HairInput input = HairInput(i);
            const size_t k = size_t(hair_input_info(input).components);
            const bool per_point = o.domain[i] == 2;
            const size_t n = per_point ? point_count : curve_count;
            for (size_t j = 0; j < n; ++j) {
                const std::string where =
                    std::string("values: ") + (per_point ? "point " : "curve ") + std::to_string(j) + ": ";
                ok_or_invalid(check_hair_input(input, values + at + j * k, where));
            }
            curves.inputs.push_back({input, per_point, std::vector<float>(values + at, values + at + n * k)});
            at += n * k;
        }
        for (int k = 0; k < kMaxHairClosures; ++k) {
            if (o.weight_domain[k] == 0) continue;
            const bool per_point = o.weight_domain[k] == 2;
            const size_t n = per_point ? point_count : curve_count;
            for (size_t j = 0; j < n; ++j)
                if (!std::isfinite(values[at + j]) || values[at + j] < 0.0f)
                    invalid("values: weight" + std::to_string(k) + ", " + (per_point ? "point " : "curve ") +
                            std::to_string(j) + ": " + format_number(values[at + j]) +
                            " (a closure weight must be finite and >= 0)");
            CurveInput weight{HairInput::Melanin, per_point, std::vector<float>(values + at, values + at + n), k};
            curves.inputs.push_back(std::move(weight));
            at += n;
        }
        if (curve_count > 0) add(*scene, std::move(curves));
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_add_curves_with_normals(hairis_scene *scene, int material, size_t curve_count,
                                                    const uint32_t *first, size_t point_count,
                                                    const float *positions, const float *radii,
                                                    const float *normals, const char *options) {
    return guard_status("hairis_scene_add_curves_with_normals", [&] {
        if (scene) scene->forget_build();  // new geometry needs a new BVH
        HairCurves curves = checked_curves(scene, material, curve_count, first, point_count, positions, radii);
        require_array(normals, point_count, "normals");
        CurveOptions o;
        read_options(options, "curve options", o);
        for (size_t i = 0; i < point_count; ++i)
            for (size_t k = 0; k < 3; ++k)
                if (!std::isfinite(normals[3 * i + k])) require_finite(normals[3 * i + k], indexed("normals", 3 * i + k));
        if (curve_count == 0) return HAIRIS_OK;
        curves.normals.resize(point_count);
        for (size_t i = 0; i < point_count; ++i) curves.normals[i] = vec3(normals + 3 * i);
        add(*scene, std::move(curves));
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_add_mesh(hairis_scene *scene, size_t vertex_count,
                                     const float *positions, size_t triangle_count,
                                     const uint32_t *indices, const int32_t *materials) {
    return guard_status("hairis_scene_add_mesh", [&] {
        if (scene) scene->forget_build();  // new geometry needs a new BVH
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
            if (!std::isfinite(positions[i])) require_finite(positions[i], indexed("positions", i));
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
            if (!std::holds_alternative<SurfaceMaterial>(scene->materials[size_t(m)]))
                invalid(indexed("materials", t) + " = " + std::to_string(m) +
                        " is a hair material; meshes need a surface material");
        }
        scene->last_mesh = -1;
        if (triangle_count == 0) return HAIRIS_OK;  // nothing to draw
        TriangleMesh mesh;
        mesh.positions.resize(vertex_count);
        for (size_t v = 0; v < vertex_count; ++v) mesh.positions[v] = vec3(positions + 3 * v);
        mesh.indices.assign(indices, indices + 3 * triangle_count);
        mesh.materials.assign(materials, materials + triangle_count);  // all >= 0, checked
        const size_t bytes = vertex_count * sizeof(Vec3) +
                             triangle_count * 4 * sizeof(std::uint32_t);
        scene->desc.meshes.push_back(std::move(mesh));
        scene->last_mesh = (long long)scene->desc.meshes.size() - 1;
        scene->triangle_count += triangle_count;
        scene->geometry_bytes += bytes;
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_add_light(hairis_scene *scene, const char *options) {
    return guard_status("hairis_scene_add_light", [&] {
        if (scene) scene->forget_shading();  // the BVH stays
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
            const SpotLight spot = read_placed_light(reader, o, what, "the spot has no direction");
            if (spot.cycles == CyclesVersion::V3_4 && !spot.soft_falloff)
                invalid(what + ": soft_falloff=0 (a sphere) needs cycles=4.5; Cycles 3.4 has "
                               "only the disk");
            // Refused now rather than at render time (e.g. a singular matrix for 4.5).
            LightsDesc check;
            check.spots = {spot};
            Expected<LightSet> checked = LightSet::build(check, {});
            if (!checked) invalid(what + ": " + checked.error().message);
            scene->desc.spot_lights.push_back(spot);
        } else {
            AreaOptions o;
            scene->desc.area_lights.push_back(
                read_placed_light(reader, o, what, "the light has no emitting direction"));
        }
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_set_world(hairis_scene *scene, const char *options) {
    return guard_status("hairis_scene_set_world", [&] {
        if (scene) scene->forget_shading();  // the BVH stays
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
        if (scene) scene->forget_shading();  // the BVH stays
        require(scene, "scene");
        WorldOptions o;
        const OptionReader reader = read_world_options(options, o, true);
        const long long count = checked_pixels("world", int(o.color_space), pixels, width, height, channels);
        Expected<EnvironmentImage> image = EnvironmentImage::from_pixels(
            pixels, count, int(width), int(height), channels, ImageColorSpace(o.color_space));
        if (!image) invalid("world: pixels: " + image.error().message);
        scene->desc.world = environment_world(reader, o, std::move(image).value());
        return HAIRIS_OK;
    });
}

HAIRIS_API int hairis_scene_reset_shading(hairis_scene *scene) {
    return guard_status("hairis_scene_reset_shading", [&] {
        if (scene) scene->forget_shading();  // the BVH stays
        require(scene, "scene");
        const SceneDesc fresh;
        scene->materials.clear();
        scene->textures.clear();
        scene->desc.suns.clear();
        scene->desc.point_lights.clear();
        scene->desc.spot_lights.clear();
        scene->desc.area_lights.clear();
        scene->desc.world = fresh.world;
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
        std::lock_guard<std::mutex> lock(scene->build_mutex);
        ++scene->camera_revision;
        return HAIRIS_OK;
    });
}

}  // extern "C"
