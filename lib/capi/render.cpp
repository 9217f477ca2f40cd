// C API: hairis_render — each hair material's sampler from the settings (the policy in
// sampling/strategy.h), the Scene (Embree BVH) and the path tracer (render/render.h).
#include <chrono>
#include <deque>
#include <mutex>
#include <functional>
#include <string>

#include "capi_scene.h"
#include "fiber/fiber_spec.h"
#include "tables/huang_bake.h"
#include "render/render.h"

namespace hairis::capi {

namespace {

thread_local std::string t_last_stats;

// Whether a Huang material's tables were baked for its own fiber and hold a baked f.
bool has_baked_f(const SceneHairMaterial &hair) {
    return hair.huang && hair.tables && hair.tables->huang && hair.tables->huang->f &&
           hair.tables->model == hair.huang->name() &&
           hair.tables->parameters == canonical_parameters(huang_parameters(hair.huang->params()));
}

// The shading of a Huang material: TABLE samples the material's Huang table (baked for its
// parameters), UNIFORM and GAUSSIAN need none. With Cycles' own sampling (huang_sampling=cycles)
// the renderer samples the fiber itself and the strategy is not used; a material whose tables
// hold a baked f still shades with it, since that f is the expectation of Cycles' eval.
HairShading huang_shading(const SceneHairMaterial &hair, const std::string &name, StrategyKind kind,
                          const SamplerOptions &o, bool cycles_sampling) {
    if (cycles_sampling) kind = has_baked_f(hair) ? StrategyKind::Table : StrategyKind::Uniform;
    if (kind == StrategyKind::Analytic)
        invalid(name + "strategy=analytic has no sampler with a known density for a huang2022 fiber (Cycles' "
                       "own Huang sampler has none); render with strategy=table or uniform");
    StrategyInputs inputs;
    if (kind == StrategyKind::Table) {
        if (!hair.tables)
            refuse(HAIRIS_ERROR_INVALID_TABLE, name + "strategy=table needs sampling tables, but the material was "
                                                      "added without tables; bake or load tables for it, or render "
                                                      "with another strategy");
        inputs.huang = hair.huang;
        inputs.tables = &*hair.tables;
    }
    inputs.multiple_weight = o.multiple_weight;
    inputs.n_h = o.n_h;
    // Cycles' sampler, not the eval, makes most of that image's noise: a strand of its own
    // inputs takes its one Cycles eval: the control variate's lower noise does not pay for its
    // extra time there.
    if (cycles_sampling) inputs.huang_strand_shading = StrandShading::OwnEval;
    // Every Huang material shades through the strands model, as Chiang's do.
    Expected<HuangStrands> strands = HuangStrands::create(hair.node, hair.huang);
    if (!strands) refuse(HAIRIS_ERROR_INTERNAL, name + strands.error().message);
    auto model = std::make_shared<const HuangStrands>(std::move(strands).value());
    if (kind == StrategyKind::Table) inputs.huang_strands = model;
    // TABLE shades with the table's baked f where the table has one.
    Expected<HairShading> shading = make_hair_shading(kind, inputs, model);
    if (!shading) refuse(code_of(shading.error().kind), name + shading.error().message);
    return std::move(shading).value();
}

// The shading of hair material `index` under the settings. TABLE refuses a material without
// tables, or with tables of other parameters, with HAIRIS_ERROR_INVALID_TABLE naming it.
HairShading hair_shading(const SceneHairMaterial &hair, size_t index, const SamplerOptions &o,
                         bool cycles_huang) {
    const std::string name = "material " + std::to_string(index) + " (hair): ";
    const StrategyKind kind = StrategyKind(o.strategy);
    if (hair.huang) return huang_shading(hair, name, kind, o, cycles_huang);
    // Every hair material shades through the strands model: curves without inputs get the
    // node's own fiber from it, the same as the fiber itself.
    Expected<ChiangStrands> strands = ChiangStrands::create(hair.node);
    if (!strands) refuse(HAIRIS_ERROR_INTERNAL, name + strands.error().message);
    auto model = std::make_shared<const ChiangStrands>(std::move(strands).value());
    StrategyInputs inputs;
    inputs.strands = model;
    inputs.multiple_weight = o.multiple_weight;
    inputs.n_h = o.n_h;
    if (kind == StrategyKind::Table) {
        if (!hair.tables)
            refuse(HAIRIS_ERROR_INVALID_TABLE, name + "strategy=table needs sampling tables, but the material was "
                                                      "added without tables; bake or load tables for it, or render "
                                                      "with another strategy");
        inputs.tables = &*hair.tables;
    }
    Expected<std::shared_ptr<const Sampler>> made = make_sampler(kind, inputs);
    if (!made) refuse(code_of(made.error().kind), name + made.error().message);
    Expected<HairShading> shading = HairShading::create(model, std::move(made).value());
    if (!shading) refuse(HAIRIS_ERROR_INTERNAL, name + shading.error().message);
    return std::move(shading).value();
}

// A Chiang fiber's dual-scattering averages (about a second of quadrature), kept for the
// process by model and parameters: the add-on builds a new scene for every render. At most
// kDualCacheSize fibers are kept; the oldest goes first. (Huang's: huang_dual_scattering.)
constexpr std::size_t kDualCacheSize = 64;
std::shared_ptr<const DualScattering> dual_scattering_of(const ChiangFiber &fiber, const std::string &name) {
    static std::mutex mutex;
    static std::deque<std::pair<std::string, std::shared_ptr<const DualScattering>>> cache;
    const std::string key = fiber.name() + ":" + canonical_parameters(chiang_parameters(fiber.params()));
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto &entry : cache)
        if (entry.first == key) return entry.second;
    Expected<DualScattering> made = DualScattering::create(fiber, DualScatteringParams{});
    if (!made) refuse(HAIRIS_ERROR_INTERNAL, name + "dual scattering: " + made.error().message);
    auto dual = std::make_shared<const DualScattering>(std::move(made).value());
    if (cache.size() == kDualCacheSize) cache.pop_front();
    cache.emplace_back(key, dual);
    return dual;
}

// The dual-scattering data of hair material `index` (integrator=dual_scattering): its fiber's
// averages and the multiple tables baked for the same parameters.
void add_dual_scattering(HairMaterial &material, const SceneHairMaterial &hair, size_t index) {
    const std::string name = "material " + std::to_string(index) + " (hair): ";
    if (!hair.tables)
        refuse(HAIRIS_ERROR_INVALID_TABLE, name + "integrator=dual_scattering samples multiple scattering from the "
                                                  "material's baked multiple-scattering tables, but it was added "
                                                  "without tables; bake or load tables for it, or render with "
                                                  "integrator=path");
    const std::string model = hair.huang ? hair.huang->name() : hair.fiber->name();
    const std::string parameters = canonical_parameters(hair.huang ? huang_parameters(hair.huang->params())
                                                                   : chiang_parameters(hair.fiber->params()));
    if (hair.tables->parameters != parameters || hair.tables->model != model)
        refuse(HAIRIS_ERROR_INVALID_TABLE, name + "the tables were baked for " + hair.tables->model + " \"" +
                                               hair.tables->parameters + "\", not for this fiber; bake tables for it");
    if (!hair.tables->multiple)
        refuse(HAIRIS_ERROR_INVALID_TABLE, name + "these " + model + " tables have no multiple-scattering part "
                                               "(baked with huang_multiple=0 or by hairis before dual scattering "
                                               "covered Huang); bake them again, or render with integrator=path");
    if (hair.huang) {
        Expected<std::shared_ptr<const DualScattering>> dual = huang_dual_scattering(*hair.huang);
        if (!dual) refuse(HAIRIS_ERROR_INTERNAL, name + "dual scattering: " + dual.error().message);
        material.dual = std::move(dual).value();
    } else {
        material.dual = dual_scattering_of(*hair.fiber, name);
    }
    material.multiple = hair.tables->multiple;
}

// A mixture's material: each closure's shading under the settings (its own sampler and
// tables), mixed with its weight.
HairMaterial hair_mixture(const hairis_scene &scene, const SceneHairMaterial &hair, size_t index,
                          const SamplerOptions &o) {
    const std::string name = "material " + std::to_string(index) + " (hair mixture): ";
    std::vector<HairShading> closures;
    for (size_t m : hair.closures)
        closures.push_back(hair_shading(std::get<SceneHairMaterial>(scene.materials[m]), m, o, false));
    HairMaterial material{closures.front()};
    Expected<HairMixture> mixture = HairMixture::create(std::move(closures), hair.weights);
    if (!mixture) invalid(name + mixture.error().message);
    material.mixture = std::make_shared<const HairMixture>(std::move(mixture).value());
    return material;
}

}  // namespace

}  // namespace hairis::capi

using namespace hairis;
using namespace hairis::capi;

namespace {

// What a built scene's BVH depends on among the render settings: the curves' backfaces, shape
// and subdivisions, and the BVH's build quality.
std::string geometry_key(const RenderOptions &o) {
    return "curve_backfaces=" + std::to_string(int(o.curve_backfaces)) + ";curve_shape=" +
           std::to_string(int(o.curve_shape)) + ";bvh_quality=" + std::to_string(int(o.bvh_quality)) +
           ";curve_subdivisions=" + std::to_string(o.curve_subdivisions);
}

// What its shading depends on besides: the sampler (the materials), the integrator and Huang
// sampling.
std::string build_key(const RenderOptions &o) {
    return write_options(o.sampler) + ";integrator=" + std::to_string(o.render.integrator) +
           ";huang_sampling=" + std::to_string(o.render.huang_sampling) + ";" + geometry_key(o);
}

// The scene's materials as this render's settings make them.
std::vector<Material> render_materials(hairis_scene &scene, const RenderOptions &o) {
    const bool dual = o.render.integrator == int(Integrator::DualScattering);
    if (dual)
        for (size_t m = 0; m < scene.materials.size(); ++m)
            if (const auto *hair = std::get_if<SceneHairMaterial>(&scene.materials[m]); hair && !hair->closures.empty())
                invalid("material " + std::to_string(m) + " (hair mixture): integrator=dual_scattering shades "
                        "one Principled Hair BSDF per material, and this material mixes " +
                        std::to_string(hair->closures.size()) + " (a Mix or Add Shader of hair closures); "
                        "render with integrator=path");
    std::vector<Material> materials;
    materials.reserve(scene.materials.size());
    for (size_t m = 0; m < scene.materials.size(); ++m) {
        if (const auto *hair = std::get_if<SceneHairMaterial>(&scene.materials[m])) {
            if (!hair->closures.empty()) {
                materials.push_back(hair_mixture(scene, *hair, m, o.sampler));
                continue;
            }
            // Dual scattering samples Huang with its tables: its MIS needs the sampler's
            // density, which Cycles' own Huang sampler does not have.
            HairMaterial material{hair_shading(*hair, m, o.sampler,
                                               o.render.huang_sampling == int(HuangSampling::Cycles) && !dual)};
            if (dual) add_dual_scattering(material, *hair, m);
            materials.push_back(std::move(material));
        } else
            materials.push_back(std::get<SurfaceMaterial>(scene.materials[m]));
    }
    return materials;
}

// A built scene for a render: whether it is the last render's whole (only the camera set
// again) or with its BVH kept (new materials, lights and world), and the seconds spent making it.
struct BuiltScene {
    std::shared_ptr<Scene> scene;
    bool reused = false, geometry_reused = false;
    double seconds = 0;
};

// The scene built with this render's materials. The last render's build is reused whole when
// the render settings and everything but the camera are the same (the camera is set again
// when no other render is using it), and its BVH when only the shading changed.
BuiltScene built_scene(hairis_scene &scene, const RenderOptions &o) {
    const auto start = std::chrono::steady_clock::now();
    const std::string key = build_key(o);
    unsigned camera = 0;
    std::shared_ptr<Scene> kept;  // the last build, taken out of the handle while it is shaded anew
    {
        std::lock_guard<std::mutex> lock(scene.build_mutex);
        camera = scene.camera_revision;
        if (scene.built && scene.built_key == key) {
            if (scene.built_camera == camera) return {scene.built, true, true, 0.0};
            if (scene.built.use_count() == 1) {
                ok_or_invalid(scene.built->set_camera(scene.desc.camera), "camera: ");
                scene.built_camera = camera;
                return {scene.built, true, true, 0.0};
            }
        }
        if (scene.built && scene.built.use_count() == 1 && scene.built_geometry_key == geometry_key(o))
            kept = std::move(scene.built);
        // Free the old build before making the new one (a render using it keeps it alive).
        scene.built.reset();
        scene.built_key.clear();
    }
    SceneDesc shading;
    shading.materials = render_materials(scene, o);
    shading.suns = scene.desc.suns;
    shading.point_lights = scene.desc.point_lights;
    shading.spot_lights = scene.desc.spot_lights;
    shading.area_lights = scene.desc.area_lights;
    shading.world = scene.desc.world;
    std::shared_ptr<Scene> built;
    const bool geometry_reused = kept != nullptr;
    if (kept) {
        ok_or_invalid(kept->set_shading(std::move(shading)), "scene: ");
        ok_or_invalid(kept->set_camera(scene.desc.camera), "camera: ");
        built = std::move(kept);
    } else {
        // The scene description with this render's materials. The handle keeps its own copy
        // of the geometry so that it can be rendered again with other settings.
        SceneDesc desc = scene.desc;
        desc.materials = std::move(shading.materials);
        desc.curve_backfaces = o.curve_backfaces;
        desc.curve_shape = o.curve_shape;
        desc.bvh_quality = o.bvh_quality;
        desc.curve_subdivisions = o.curve_subdivisions;
        Expected<Scene> made = Scene::build(std::move(desc));
        if (!made) invalid("scene: " + made.error().message);
        built = std::make_shared<Scene>(std::move(made).value());
    }
    std::lock_guard<std::mutex> lock(scene.build_mutex);
    scene.built = built;
    scene.built_key = key;
    scene.built_geometry_key = geometry_key(o);
    scene.built_camera = camera;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return {built, false, geometry_reused, seconds};
}

// hairis_render and hairis_render_progressive: the scene built with this render's materials,
// rendered by render/render.h, the statistics kept for hairis_last_render_stats.
int render_scene(const char *function, hairis_scene *scene, const char *settings, float *rgba, float *passes,
                 const UpdateFn &update, const RoundSchedule &schedule) {
    return guard_status(function, [&] {
        const auto start = std::chrono::steady_clock::now();
        require(scene, "scene");
        require(rgba, "rgba");
        RenderOptions o;
        read_options(settings, "render settings", o);
        if (!scene->has_camera) invalid("scene has no camera: call hairis_scene_set_camera before " + std::string(function));

        const BuiltScene built = built_scene(*scene, o);

        RenderStats stats;
        const Status status = render_progressive(*built.scene, o.render, rgba, passes, update, &stats, schedule);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        t_last_stats = format_options({{"seconds", format_number(seconds)},
                                       {"build_seconds", format_number(built.seconds)},
                                       {"scene_reused", built.reused ? "1" : "0"},
                                       {"geometry_reused", built.geometry_reused ? "1" : "0"},
                                       {"camera_rays", std::to_string(stats.camera_rays)},
                                       {"rays", std::to_string(stats.rays)},
                                       {"shadow_rays", std::to_string(stats.shadow_rays)},
                                       {"dropped_samples", std::to_string(stats.dropped_samples)},
                                       {"peak_memory_bytes", std::to_string(stats.peak_memory_bytes + scene->geometry_bytes)},
                                       {"threads", std::to_string(stats.threads)},
                                       {"cancelled", stats.cancelled ? "1" : "0"},
                                       {"samples", std::to_string(stats.samples)},
                                       {"converged_pixels", std::to_string(stats.converged_pixels)}});
        if (stats.cancelled)
            refuse(HAIRIS_ERROR_CANCELLED, status ? status->message : std::string("cancelled by the callback"));
        if (status) {
            const bool failure = status->message.rfind("render failed", 0) == 0 || status->message.rfind("render: ", 0) == 0;
            refuse(failure ? HAIRIS_ERROR_INTERNAL : HAIRIS_ERROR_INVALID_ARGUMENT, status->message);
        }
        return HAIRIS_OK;
    });
}

}  // namespace

extern "C" {

HAIRIS_API int hairis_render(hairis_scene *scene, const char *settings, float *rgba, hairis_progress_fn progress,
                             void *user) {
    // Whether the render stopped early is what RenderStats::cancelled says: a non-zero return
    // at the last call changes nothing.
    UpdateFn report;
    if (progress) report = [&](float fraction, int, bool) { return progress(user, fraction) == 0; };
    // render()'s schedule: progress every 50 ms, no call after a cancel.
    RoundSchedule schedule;
    schedule.heartbeat_seconds = 0.05;
    schedule.final_update_when_cancelled = false;
    return render_scene("hairis_render", scene, settings, rgba, nullptr, report, schedule);
}

HAIRIS_API int hairis_render_progressive(hairis_scene *scene, const char *settings, float *rgba, float *passes,
                                         hairis_update_fn update, void *user) {
    UpdateFn report;
    if (update)
        report = [&](float fraction, int samples_done, bool final) {
            return update(user, fraction, samples_done, final ? 1 : 0) == 0;
        };
    return render_scene("hairis_render_progressive", scene, settings, rgba, passes, report, RoundSchedule{});
}

HAIRIS_API const char *hairis_last_render_stats(void) { return t_last_stats.c_str(); }

}  // extern "C"
