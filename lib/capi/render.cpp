// C API: render settings and hairis_render — make each hair material's direction sampler
// from the settings, build the Scene (Embree BVH) and run the path tracer (render.h).
#include <algorithm>
#include <chrono>
#include <functional>
#include <string>

#include "capi_scene.h"
#include "hairis/render.h"
#include "hairis/strategies.h"

namespace hairis::capi {

namespace {

constexpr int kMaxSamples = 1 << 24;

void check_settings(const hairis_render_settings &s) {
    ok_or_invalid(check::count_in_range("settings.samples", s.samples, 1, kMaxSamples));
    ok_or_invalid(check::count_in_range("settings.max_bounces", s.max_bounces, 0, 1024));
    if (s.strategy < HAIRIS_STRATEGY_UNIFORM || s.strategy > HAIRIS_STRATEGY_TABLE)
        invalid("settings.strategy must be HAIRIS_STRATEGY_UNIFORM (0), ANALYTIC (1), GAUSSIAN "
                "(2) or TABLE (3) (got " + std::to_string(s.strategy) + ")");
    if (!(s.multiple_weight >= 0.0f && s.multiple_weight <= 1.0f))
        invalid("settings.multiple_weight must be finite and in [0, 1] (got " +
                describe(s.multiple_weight) + ")");
    ok_or_invalid(check::count_in_range("settings.n_h", s.n_h, 1, 1024));
    ok_or_invalid(check::count_in_range("settings.threads", s.threads, 0, 1024));
}

std::string join(const std::vector<int> &values) {
    std::string out;
    for (int v : values) out += (out.empty() ? "" : ", ") + std::to_string(v);
    return out;
}

// The direction sampler of hair material `index` for the render settings. TABLE refuses a
// material without tables, or whose tables were baked for other parameters, with
// HAIRIS_ERROR_INVALID_TABLE naming the material: never a silently wrong render.
std::shared_ptr<const DirectionSampler> hair_sampler(const SceneHairMaterial &hair, size_t index,
                                                     const hairis_render_settings &s) {
    const std::string name = "material " + std::to_string(index);
    StrategyInputs inputs;
    inputs.multiple_weight = s.multiple_weight;
    inputs.n_h = s.n_h;
    switch (s.strategy) {
        case HAIRIS_STRATEGY_UNIFORM: break;
        case HAIRIS_STRATEGY_ANALYTIC:
            // The renderer recognises this sampler and takes f·cos from the fiber's own sample.
            return std::make_shared<const AnalyticSampler>(hair.fiber);
        case HAIRIS_STRATEGY_GAUSSIAN: {
            const std::vector<int> &allowed = inputs.seed.n_h_values;
            if (std::find(allowed.begin(), allowed.end(), s.n_h) == allowed.end())
                invalid("settings.n_h must be one of " + join(allowed) +
                        " for HAIRIS_STRATEGY_GAUSSIAN (the seed's n_h values; got " +
                        std::to_string(s.n_h) + ")");
            break;
        }
        case HAIRIS_STRATEGY_TABLE:
            if (!hair.has_tables)
                refuse(HAIRIS_ERROR_INVALID_TABLE,
                       name + " (hair): HAIRIS_STRATEGY_TABLE needs sampling tables, but the "
                              "material was added without tables; bake or load tables for it, "
                              "or render with another strategy");
            if (hair.tables_model != hair.model || hair.tables_parameters != hair.parameters)
                refuse(HAIRIS_ERROR_INVALID_TABLE,
                       name + " (hair): its tables were baked for " + hair.tables_model + " \"" +
                           hair.tables_parameters + "\", not for the material's " + hair.model +
                           " \"" + hair.parameters + "\"; bake tables for the material");
            if (std::find(hair.tables_n_h.begin(), hair.tables_n_h.end(), s.n_h) ==
                hair.tables_n_h.end())
                refuse(HAIRIS_ERROR_INVALID_TABLE,
                       name + " (hair): its tables hold n_h " + join(hair.tables_n_h) +
                           ", not settings.n_h = " + std::to_string(s.n_h));
            inputs.tables = &hair.tables;
            inputs.chiang = hair.fiber;  // the near field gets its own table (near_field_table.h)
            break;
        default: break;  // refused by check_settings
    }
    Expected<std::shared_ptr<const DirectionSampler>> made =
        make_sampler(StrategyKind(s.strategy), inputs);
    if (!made) invalid(name + " (hair): " + made.error().message);
    return std::move(made).value();
}

}  // namespace

}  // namespace hairis::capi

using namespace hairis;
using namespace hairis::capi;

extern "C" {

HAIRIS_API void hairis_render_settings_defaults(hairis_render_settings *settings) {
    guard_void("hairis_render_settings_defaults", [&] {
        require(settings, "settings");
        // The add-on's scene.hairis defaults; bounces, seed and threads as RenderSettings.
        const RenderSettings d;
        hairis_render_settings c{};
        c.samples = 64;
        c.max_bounces = d.max_bounces;
        c.strategy = HAIRIS_STRATEGY_TABLE;
        c.multiple_weight = StrategyInputs{}.multiple_weight;
        c.n_h = StrategyInputs{}.n_h;
        c.seed = d.seed;
        c.threads = d.threads;
        *settings = c;
    });
}

HAIRIS_API int hairis_render(hairis_scene *scene, const hairis_render_settings *settings,
                             float *rgba, hairis_progress_fn progress, void *user,
                             hairis_render_stats *stats) {
    return guard_status("hairis_render", [&] {
        const auto start = std::chrono::steady_clock::now();
        require(scene, "scene");
        require(settings, "settings");
        require(rgba, "rgba");
        const hairis_render_settings s = *settings;
        check_settings(s);
        if (!scene->has_camera)
            invalid("scene has no camera: call hairis_scene_set_camera before hairis_render");
        if (scene->curve_count == 0 && scene->triangle_count == 0)
            invalid("scene is empty: add curves (hairis_scene_add_curves) or a mesh "
                    "(hairis_scene_add_mesh) before hairis_render");

        // The scene description with this render's materials. The handle keeps its own copy
        // of the geometry so that it can be rendered again with other settings.
        SceneDesc desc = scene->desc;
        desc.materials.reserve(scene->materials.size());
        for (size_t m = 0; m < scene->materials.size(); ++m) {
            if (const auto *hair = std::get_if<SceneHairMaterial>(&scene->materials[m]))
                desc.materials.push_back(HairMaterial{hair->fiber, hair_sampler(*hair, m, s)});
            else
                desc.materials.push_back(std::get<DiffuseMaterial>(scene->materials[m]));
        }
        Expected<Scene> built = Scene::build(std::move(desc));
        if (!built) invalid("scene: " + built.error().message);

        RenderSettings rs;
        rs.samples = s.samples;
        rs.max_bounces = s.max_bounces;
        rs.seed = s.seed;
        rs.threads = s.threads;

        // Called on this thread only (render.h). Whether the render stopped early is what
        // RenderStats::cancelled says: a non-zero return after the last pass changes nothing.
        std::function<bool(float)> report;
        if (progress) report = [&](float fraction) { return progress(user, fraction) == 0; };
        RenderStats rstats;
        const Status status = render(built.value(), rs, rgba, report, &rstats);
        if (stats) {
            hairis_render_stats out{};
            out.seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            out.camera_rays = rstats.camera_rays;
            out.dropped_samples = rstats.dropped_samples;
            out.peak_memory_bytes = rstats.peak_memory_bytes + scene->geometry_bytes;
            *stats = out;
        }
        if (rstats.cancelled)
            refuse(HAIRIS_ERROR_CANCELLED,
                   status ? status->message : std::string("cancelled by the progress callback"));
        if (status) {
            const bool failure = status->message.rfind("render failed", 0) == 0 ||
                                 status->message.rfind("render: ", 0) == 0;
            refuse(failure ? HAIRIS_ERROR_INTERNAL : HAIRIS_ERROR_INVALID_ARGUMENT,
                   status->message);
        }
        return HAIRIS_OK;
    });
}

}  // extern "C"
