// Fuzz target: the C API's parameter intake. The bytes are read as a sequence of calls, each
// an opcode followed by the raw C structs and values it takes (fuzz_input.h), so NaN, inf,
// negative radii, unknown enums and huge counts all reach the API as a caller could pass them.
// The API must refuse what is wrong with an error, never crash; HAIRIS_ERROR_INTERNAL or
// "out of memory" also count as findings.
//
// Work is bounded so that each input runs in milliseconds: bakes and renders the API accepts
// with a large resolution are cancelled at their first progress call (the sizes have been
// checked by then), and at most kMaxCalls calls run per input.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "fuzz_input.h"
#include "hairis/hairis.h"

// c_calls.c: hairis_sampler_create with any int as its strategy, as a C caller may pass
// (in C++ an int outside the enum's range cannot be converted to the enum type).
extern "C" hairis_sampler *hairis_fuzz_sampler_create(int strategy, const hairis_fiber *fiber,
                                                      const hairis_tables *tables,
                                                      float multiple_weight, int n_h);

namespace {

using hairis::fuzz::check_last_error;
using hairis::fuzz::check_not_internal;
using hairis::fuzz::FuzzInput;

constexpr int kMaxCalls = 32;
// Largest bake (cells) and render (pixel samples × bounces) run to the end.
constexpr double kMaxBakeCells = 2 * 4 * 8;
constexpr double kMaxRenderWork = 64;
constexpr long long kMaxRenderPixels = 4096;
// Largest arrays the harness builds for one call.
constexpr size_t kMaxItems = 64;

int cancel_at_once(void *, float) { return 1; }

struct State {
    std::vector<hairis_fiber *> fibers;
    std::vector<hairis_tables *> tables;
    std::vector<hairis_sampler *> samplers;
    hairis_scene *scene = nullptr;
    long long camera_pixels = 0;  // of the last camera the scene accepted

    ~State() {
        for (hairis_sampler *s : samplers) hairis_sampler_destroy(s);
        for (hairis_tables *t : tables) hairis_tables_destroy(t);
        for (hairis_fiber *f : fibers) hairis_fiber_destroy(f);
        hairis_scene_destroy(scene);
    }

    template <typename T>
    static T *pick(std::vector<T *> &from, uint8_t which) {
        // One past the end picks NULL, which every call must refuse.
        return which % (from.size() + 1) < from.size() ? from[which % (from.size() + 1)] : nullptr;
    }
};

template <typename T>
void keep(std::vector<T *> &into, T *handle, const char *call) {
    if (handle) {
        into.push_back(handle);
        hairis::fuzz::trace(call, true);
    } else {
        check_last_error(call);
    }
}

std::vector<float> floats(FuzzInput &in, size_t n) {
    std::vector<float> v(n);
    for (float &x : v) x = in.take<float>();
    return v;
}

void fiber_eval(State &st, FuzzInput &in) {
    hairis_fiber *fiber = State::pick(st.fibers, in.take<uint8_t>());
    const size_t n = in.count(4);
    const std::vector<float> wi = floats(in, 3 * n), wo = floats(in, 3 * n), h = floats(in, n);
    std::vector<float> rgb(3 * n);
    const bool near = in.take<uint8_t>() & 1;
    check_not_internal(hairis_fiber_eval(fiber, n, n ? wi.data() : nullptr, n ? wo.data() : nullptr,
                                         near && n ? h.data() : nullptr, n ? rgb.data() : nullptr),
                       "hairis_fiber_eval");
}

void bake(State &st, FuzzInput &in) {
    hairis_fiber *fiber = State::pick(st.fibers, in.take<uint8_t>());
    const hairis_bake_options options = in.take<hairis_bake_options>();
    const double cells = double(options.theta_r_count) * options.theta_i_count * options.phi_count;
    // Only small bakes from the seed's Gaussian PDFs run to the end: the exact source's
    // dual-scattering set-up takes seconds (half a minute under ASan) whatever the size.
    // The others are checked and cancelled at their first progress call.
    const bool run = options.source == 1 && options.theta_r_count > 0 && options.theta_i_count > 0 &&
                     options.phi_count > 0 && cells <= kMaxBakeCells;
    keep(st.tables, hairis_tables_bake(fiber, &options, run ? nullptr : cancel_at_once, nullptr),
         "hairis_tables_bake");
}

void sample(State &st, FuzzInput &in) {
    const int strategy = in.take<int>();
    hairis_fiber *fiber = State::pick(st.fibers, in.take<uint8_t>());
    hairis_tables *tables = State::pick(st.tables, in.take<uint8_t>());
    const float weight = in.take<float>();
    const int n_h = in.take<int>();
    keep(st.samplers, hairis_fuzz_sampler_create(strategy, fiber, tables, weight, n_h),
         "hairis_sampler_create");
    hairis_sampler *sampler = State::pick(st.samplers, in.take<uint8_t>());
    const size_t n = in.count(4);
    const std::vector<float> wo = floats(in, 3 * n), u = floats(in, 3 * n), h = floats(in, n);
    std::vector<float> wi(3 * n), pdf(n), pdf2(n);
    const float *wo_p = n ? wo.data() : nullptr;
    const float *h_p = n && (in.take<uint8_t>() & 1) ? h.data() : nullptr;
    const int status = hairis_sample(sampler, n, wo_p, h_p, n ? u.data() : nullptr,
                                     n ? wi.data() : nullptr, n ? pdf.data() : nullptr);
    check_not_internal(status, "hairis_sample");
    if (status != HAIRIS_OK) return;
    check_not_internal(hairis_pdf(sampler, n, n ? wi.data() : nullptr, wo_p, h_p,
                                  n ? pdf2.data() : nullptr),
                       "hairis_pdf");
    for (size_t k = 0; k < n; ++k)
        if (!(pdf[k] >= 0.0f) || !std::isfinite(pdf[k])) {
            std::fprintf(stderr, "hairis_sample accepted its input but gave pdf %g\n", pdf[k]);
            std::abort();
        }
}

void add_curves(State &st, FuzzInput &in) {
    const int material = in.take<int8_t>();
    const uint8_t shape = in.take<uint8_t>();
    // Counts as given (huge ones included) when the arrays are NULL; else arrays of that size.
    if (shape & 1) {
        const size_t curve_count = in.take<uint64_t>(), point_count = in.take<uint64_t>();
        std::vector<uint32_t> first(2, 0);
        check_not_internal(hairis_scene_add_curves(st.scene, material, curve_count,
                                                   (shape & 2) ? first.data() : nullptr,
                                                   point_count, nullptr, nullptr),
                           "hairis_scene_add_curves");
        return;
    }
    const size_t curve_count = in.count(8), point_count = in.count(kMaxItems);
    std::vector<uint32_t> first(curve_count + 1);
    for (uint32_t &f : first) f = in.take<uint8_t>();
    const std::vector<float> positions = floats(in, 3 * point_count), radii = floats(in, point_count);
    check_not_internal(hairis_scene_add_curves(st.scene, material, curve_count, first.data(),
                                               point_count, positions.data(), radii.data()),
                       "hairis_scene_add_curves");
}

void add_mesh(State &st, FuzzInput &in) {
    const size_t vertex_count = in.count(kMaxItems), triangle_count = in.count(kMaxItems / 3);
    const std::vector<float> positions = floats(in, 3 * vertex_count);
    std::vector<uint32_t> indices(3 * triangle_count);
    for (uint32_t &i : indices) i = in.take<uint8_t>();
    std::vector<int32_t> materials(triangle_count);
    for (int32_t &m : materials) m = in.take<int8_t>();
    check_not_internal(hairis_scene_add_mesh(st.scene, vertex_count, positions.data(),
                                             triangle_count, indices.data(), materials.data()),
                       "hairis_scene_add_mesh");
}

void add_light(State &st, FuzzInput &in) {
    const uint8_t kind = in.take<uint8_t>() % 4;
    const std::vector<float> a = floats(in, 16), color = floats(in, 3);
    const float x = in.take<float>(), y = in.take<float>();
    int status = HAIRIS_OK;
    switch (kind) {
        case 0: status = hairis_scene_add_sun(st.scene, a.data(), color.data(), x, y); break;
        case 1: status = hairis_scene_add_point_light(st.scene, a.data(), color.data(), x, y); break;
        case 2: {
            // Read in order: the order of evaluating call arguments is unspecified.
            const int shape = in.take<int>();
            const float power = in.take<float>();
            status = hairis_scene_add_area_light(st.scene, a.data(), shape, x, y, color.data(), power);
            break;
        }
        default: status = hairis_scene_set_world(st.scene, color.data(), x); break;
    }
    check_not_internal(status, "hairis_scene light");
}

void render(State &st, FuzzInput &in) {
    hairis_render_settings settings = in.take<hairis_render_settings>();
    // The caller owns the image (width × height × 4 floats): the harness only renders images
    // it can afford; the API's own limits on the camera are what set_camera tested.
    if (st.camera_pixels > kMaxRenderPixels) return;
    const double work = double(st.camera_pixels) * settings.samples * (double(settings.max_bounces) + 1);
    const bool small = st.camera_pixels > 0 && settings.samples > 0 && settings.max_bounces >= 0 &&
                       work <= kMaxRenderWork;
    if (small) settings.threads = 1;
    std::vector<float> rgba(size_t(st.camera_pixels > 0 ? st.camera_pixels : 1) * 4);
    hairis_render_stats stats;
    const int status = hairis_render(st.scene, &settings, rgba.data(),
                                     small ? nullptr : cancel_at_once, nullptr, &stats);
    check_not_internal(status, "hairis_render");
    if (status == HAIRIS_OK)
        for (float v : rgba)
            if (!std::isfinite(v)) {
                std::fprintf(stderr, "hairis_render succeeded with a non-finite pixel\n");
                std::abort();
            }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    FuzzInput in(data, size);
    State st;
    st.scene = hairis_scene_create();
    for (int call = 0; call < kMaxCalls && !in.empty(); ++call) {
        switch (in.take<uint8_t>() % 12) {
            case 0: {
                const hairis_principled_hair node = in.take<hairis_principled_hair>();
                keep(st.fibers, hairis_fiber_create_principled(&node), "hairis_fiber_create_principled");
                break;
            }
            case 1: {
                const hairis_marschner_params params = in.take<hairis_marschner_params>();
                keep(st.fibers, hairis_fiber_create_marschner(&params), "hairis_fiber_create_marschner");
                break;
            }
            case 2: fiber_eval(st, in); break;
            case 3: bake(st, in); break;
            case 4: sample(st, in); break;
            case 5: {
                const hairis_principled_hair node = in.take<hairis_principled_hair>();
                hairis_tables *tables = State::pick(st.tables, in.take<uint8_t>());
                if (hairis_scene_add_hair_material(st.scene, &node, tables) < 0)
                    check_last_error("hairis_scene_add_hair_material");
                break;
            }
            case 6: {
                const std::vector<float> albedo = floats(in, 3), emission = floats(in, 3);
                if (hairis_scene_add_diffuse_material(st.scene, albedo.data(), emission.data()) < 0)
                    check_last_error("hairis_scene_add_diffuse_material");
                break;
            }
            case 7: add_curves(st, in); break;
            case 8: add_mesh(st, in); break;
            case 9: add_light(st, in); break;
            case 10: {
                const hairis_camera camera = in.take<hairis_camera>();
                const int status = hairis_scene_set_camera(st.scene, &camera);
                check_not_internal(status, "hairis_scene_set_camera");
                if (status == HAIRIS_OK) st.camera_pixels = (long long)camera.width * camera.height;
                break;
            }
            default: render(st, in); break;
        }
    }
    return 0;
}
