// Fuzz target: the C API's parameter intake. The bytes are read as a sequence of calls
// (fuzz_input.h defines the format): option strings built from the names each kind knows,
// garbage names and values (valid numbers, extremes, NaN/inf, words, vectors, raw bytes) or
// raw text, and raw arrays for the geometry, so NaN, inf, negative radii, unknown words and
// names and huge counts all reach the API as a caller could pass them. The API must refuse
// what is wrong with an error, never crash; HAIRIS_ERROR_INTERNAL or "out of memory" also
// count as findings.
//
// Work is bounded so that each input runs in milliseconds: bakes and renders the API accepts
// are run to the end only when tiny (Gaussian-source bakes of <= kMaxBakeCells cells, renders
// of <= kMaxRenderWork pixel samples x bounces, read from the options as the library reads
// them); the others are cancelled at their first progress call (the sizes have been checked
// by then). At most kMaxCalls calls run per input.
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fuzz_input.h"
#include "hairis/hairis.h"
#include "hairis/hairis_render.h"

namespace {

using namespace hairis::fuzz;

constexpr int kMaxCalls = 32;
// Largest bake (cells) and render (pixel samples × bounces) run to the end.
constexpr double kMaxBakeCells = 2 * 4 * 8;
constexpr double kMaxRenderWork = 64;
constexpr long long kMaxRenderPixels = 4096;
// Largest arrays the harness builds for one call.
constexpr size_t kMaxItems = 64;

int cancel_at_once(void *, float) { return 1; }

// ---- Option strings --------------------------------------------------------------------------

size_t kind_index(const char *kind) {
    const std::vector<std::string> &kinds = option_kinds();
    for (size_t k = 0; k < kinds.size(); ++k)
        if (kinds[k] == kind) return k;
    std::fprintf(stderr, "capi_params: no kind %s\n", kind);
    std::abort();
}

std::string number_text(FuzzInput &in) { return numbers()[in.take<uint8_t>() % numbers().size()]; }

std::string float_text(float v) {
    char text[48];
    std::snprintf(text, sizeof text, "%.9g", double(v));
    return text;
}

std::string value_text(FuzzInput &in, const std::string &default_value) {
    switch (Value(in.take<uint8_t>() % 8)) {
        case kNumber: return number_text(in);
        case kFloatBytes: return float_text(in.take<float>());
        case kIntBytes: return std::to_string(in.take<int32_t>());
        case kWord: return words()[in.take<uint8_t>() % words().size()];
        case kVector: {
            const size_t n = in.take<uint8_t>() % 17;
            std::string v;
            for (size_t k = 0; k < n; ++k) {
                const uint8_t b = in.take<uint8_t>();
                v += (k ? "," : "") + (b >= 128 ? float_text(in.take<float>()) : numbers()[b % numbers().size()]);
            }
            return v;
        }
        case kLiteral: return in.text(in.take<uint8_t>() % 32);
        case kDefault: return default_value;
        case kEmpty: break;
    }
    return "";
}

/// An option string of `kind` (nullopt: NULL); see fuzz_input.h. Structured strings of
/// Marschner fibers and lights get model / type first unless an item names it.
std::optional<std::string> options(FuzzInput &in, const char *kind) {
    const uint8_t mode = in.take<uint8_t>();
    std::string text;
    if (mode == kNullOptions) return std::nullopt;
    if (mode >= kRawOptions) {
        text = in.text(in.take<uint16_t>() % (kMaxRawText + 1));
    } else {
        const auto &known = known_names(kind_index(kind));
        std::string prefix_name = std::string(kind) == "marschner" ? "model" : "";
        const std::string k = kind;
        if (k == "sun" || k == "point" || k == "area") prefix_name = "type";
        bool prefix = !prefix_name.empty();
        const size_t items = mode % 16;
        std::string body;
        for (size_t i = 0; i < items; ++i) {
            const uint8_t n = in.take<uint8_t>();
            std::string name, default_value = "1";
            if (n < kGarbageNamesFrom) {
                name = known[n % known.size()].first;
                default_value = known[n % known.size()].second;
            } else {
                const uint8_t g = uint8_t((n - kGarbageNamesFrom) % garbage_names().size());
                name = g == kLiteralName ? in.text(in.take<uint8_t>() % 16) : garbage_names()[g];
            }
            if (name == prefix_name) prefix = false;
            body += (i ? ";" : "") + name + "=" + value_text(in, default_value);
        }
        text = prefix ? prefix_name + "=" + (k == "marschner" ? "marschner" : k) + (body.empty() ? "" : ";") + body
                      : body;
    }
    text.resize(std::strlen(text.c_str()));  // the C string the library sees
    return text;
}

const char *c_str(const std::optional<std::string> &text) { return text ? text->c_str() : nullptr; }

/// The value of `name` in `text` as the library reads it: nullopt when absent (or the string
/// does not split; the library refuses it then), the first one when repeated (refused too).
std::optional<std::string> lookup(const std::optional<std::string> &text, const char *name) {
    std::vector<std::pair<std::string, std::string>> items;
    if (!text || !split_options(*text, items)) return std::nullopt;
    for (const auto &item : items)
        if (item.first == name) return item.second;
    return std::nullopt;
}

/// An integer option as the library reads it (strtoll over the whole text), or `absent`
/// when it is not given; nullopt when it does not read as an integer.
std::optional<long long> integer(const std::optional<std::string> &text, const char *name, long long absent) {
    const std::optional<std::string> v = lookup(text, name);
    if (!v) return absent;
    if (v->empty()) return std::nullopt;
    char *end = nullptr;
    errno = 0;
    const long long n = std::strtoll(v->c_str(), &end, 10);
    if (end != v->c_str() + v->size() || errno == ERANGE) return std::nullopt;
    return n;
}

/// `text` with `name` set to `value` (every item of that name replaced by one at the end);
/// unchanged when it does not split.
std::optional<std::string> with_option(const std::optional<std::string> &text, const char *name, const char *value) {
    std::vector<std::pair<std::string, std::string>> items;
    if (text && !split_options(*text, items)) return text;
    std::string out;
    for (const auto &item : items)
        if (item.first != name) out += item.first + "=" + item.second + ";";
    return out + name + "=" + value;
}

// ---- Calls -----------------------------------------------------------------------------------

struct State {
    std::vector<hairis_fiber *> fibers;
    std::vector<hairis_tables *> tables;
    std::vector<hairis_sampler *> samplers;
    hairis_scene *scene = nullptr;
    long long camera_pixels = 0;  // of the last camera the scene accepted; -1: unknown

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

std::string shown(const std::optional<std::string> &text) { return text ? "\"" + *text + "\"" : "NULL"; }

template <typename T>
void keep(std::vector<T *> &into, T *handle, const char *call, const std::string &detail) {
    if (handle) {
        into.push_back(handle);
        trace(call, true, detail);
    } else {
        check_last_error(call, detail);
    }
}

std::vector<float> floats(FuzzInput &in, size_t n) {
    std::vector<float> v(n);
    for (float &x : v) x = in.take<float>();
    return v;
}

void fiber_create(State &st, FuzzInput &in) {
    const char *kind = in.take<uint8_t>() % 2 ? "marschner" : "chiang";
    const std::optional<std::string> o = options(in, kind);
    keep(st.fibers, hairis_fiber_create(c_str(o)), "hairis_fiber_create", shown(o));
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
    const std::optional<std::string> o = options(in, "bake");
    // Only small bakes from the seed's Gaussian PDFs run to the end: the exact source's
    // dual-scattering set-up takes seconds (half a minute under ASan) whatever the size.
    // The others are checked and cancelled at their first progress call. The sizes are
    // multiplied in double: the options may hold any integer.
    const std::optional<long long> r = integer(o, "theta_r", 31), i = integer(o, "theta_i", 64),
                                   p = integer(o, "phi", 64);
    const bool run = lookup(o, "source") == std::optional<std::string>("gaussian") && r && i && p &&
                     *r > 0 && *i > 0 && *p > 0 && double(*r) * double(*i) * double(*p) <= kMaxBakeCells;
    keep(st.tables, hairis_tables_bake(fiber, c_str(o), run ? nullptr : cancel_at_once, nullptr),
         "hairis_tables_bake", shown(o));
}

void sample(State &st, FuzzInput &in) {
    hairis_fiber *fiber = State::pick(st.fibers, in.take<uint8_t>());
    hairis_tables *tables = State::pick(st.tables, in.take<uint8_t>());
    const std::optional<std::string> o = options(in, "sampler");
    keep(st.samplers, hairis_sampler_create(fiber, tables, c_str(o)), "hairis_sampler_create", shown(o));
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
        if (!(pdf[k] >= 0.0f) || !std::isfinite(pdf[k]) || !(pdf2[k] >= 0.0f) || !std::isfinite(pdf2[k])) {
            std::fprintf(stderr, "hairis_sample accepted its input but gave pdf %g (again %g)\n", pdf[k], pdf2[k]);
            std::abort();
        }
}

void hair_material(State &st, FuzzInput &in) {
    hairis_fiber *fiber = State::pick(st.fibers, in.take<uint8_t>());
    hairis_tables *tables = State::pick(st.tables, in.take<uint8_t>());
    if (hairis_scene_add_hair_material(st.scene, fiber, tables) < 0)
        check_last_error("hairis_scene_add_hair_material");
    else
        trace("hairis_scene_add_hair_material", true);
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
    if (shape & 4) {
        // With curve inputs: an option string of them and values of any count.
        const std::optional<std::string> o = options(in, "curve_inputs");
        const size_t value_count = in.count(kMaxItems);
        const std::vector<float> values = floats(in, value_count);
        check_not_internal(hairis_scene_add_curves_with_inputs(
                               st.scene, material, curve_count, first.data(), point_count, positions.data(),
                               radii.data(), c_str(o), value_count, value_count ? values.data() : nullptr),
                           "hairis_scene_add_curves_with_inputs");
        return;
    }
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

void render(State &st, FuzzInput &in) {
    std::optional<std::string> o = options(in, "render");
    // The caller owns the image (width × height × 4 floats): the harness only renders images
    // it can afford and whose size it knows; set_camera tested the API's own limits.
    if (st.camera_pixels < 0 || st.camera_pixels > kMaxRenderPixels) return;
    const std::optional<long long> samples = integer(o, "samples", 64), bounces = integer(o, "max_bounces", 12);
    const bool small = st.camera_pixels > 0 && samples && bounces && *samples > 0 && *bounces >= 0 &&
                       double(st.camera_pixels) * double(*samples) * (double(*bounces) + 1) <= kMaxRenderWork;
    if (small) o = with_option(o, "threads", "1");
    std::vector<float> rgba(size_t(st.camera_pixels > 0 ? st.camera_pixels : 1) * 4);
    const int status = hairis_render(st.scene, c_str(o), rgba.data(), small ? nullptr : cancel_at_once, nullptr);
    check_not_internal(status, "hairis_render", shown(o));
    if (status == HAIRIS_OK) {
        for (float v : rgba)
            if (!std::isfinite(v)) {
                std::fprintf(stderr, "hairis_render succeeded with a non-finite pixel\n");
                std::abort();
            }
        if (!lookup(std::string(hairis_last_render_stats()), "camera_rays")) {
            std::fprintf(stderr, "hairis_render succeeded without stats: \"%s\"\n", hairis_last_render_stats());
            std::abort();
        }
    }
}

void set_camera(State &st, FuzzInput &in) {
    const std::optional<std::string> o = options(in, "camera");
    const int status = hairis_scene_set_camera(st.scene, c_str(o));
    check_not_internal(status, "hairis_scene_set_camera", shown(o));
    if (status != HAIRIS_OK) return;
    const std::optional<long long> w = integer(o, "width", 64), h = integer(o, "height", 64);
    // The library accepted the sizes; if the harness cannot read them, it renders no more.
    st.camera_pixels = w && h && *w > 0 && *h > 0 ? *w * *h : -1;
}

/// Getters and hairis_defaults: any handle (or NULL) gives a string, never a crash.
void query(State &st, FuzzInput &in) {
    const uint8_t which = in.take<uint8_t>();
    const char *s = "";
    switch (which % 8) {
        case 0: s = hairis_fiber_model(State::pick(st.fibers, in.take<uint8_t>())); break;
        case 1: s = hairis_fiber_parameters(State::pick(st.fibers, in.take<uint8_t>())); break;
        case 2: s = hairis_tables_model(State::pick(st.tables, in.take<uint8_t>())); break;
        case 3: s = hairis_tables_parameters(State::pick(st.tables, in.take<uint8_t>())); break;
        case 4: s = hairis_tables_info(State::pick(st.tables, in.take<uint8_t>())); break;
        case 5: {
            hairis_tables *t = State::pick(st.tables, in.take<uint8_t>());
            const int match = hairis_tables_match_fiber(t, State::pick(st.fibers, in.take<uint8_t>()));
            if (match != 0 && match != 1) {
                std::fprintf(stderr, "hairis_tables_match_fiber returned %d\n", match);
                std::abort();
            }
            break;
        }
        case 6: {
            const std::string kind = in.take<uint8_t>() & 1 ? in.text(in.take<uint8_t>() % 16)
                                                            : option_kinds()[in.take<uint8_t>() % option_kinds().size()];
            s = hairis_defaults(kind.c_str());
            if (!s) {
                check_last_error("hairis_defaults", kind);
                s = "";
            }
            break;
        }
        default: s = hairis_last_render_stats(); break;
    }
    if (!s) {
        std::fprintf(stderr, "a getter returned NULL\n");
        std::abort();
    }
    trace("query", true, s);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    FuzzInput in(data, size);
    State st;
    st.scene = hairis_scene_create();
    for (int call = 0; call < kMaxCalls && !in.empty(); ++call) {
        switch (Op(in.take<uint8_t>() % kOpCount)) {
            case kFiber: fiber_create(st, in); break;
            case kEval: fiber_eval(st, in); break;
            case kBake: bake(st, in); break;
            case kSample: sample(st, in); break;
            case kHairMaterial: hair_material(st, in); break;
            case kSurface: {
                const std::optional<std::string> o = options(in, "diffuse");
                if (hairis_scene_add_surface_material(st.scene, c_str(o)) < 0)
                    check_last_error("hairis_scene_add_surface_material", shown(o));
                else
                    trace("hairis_scene_add_surface_material", true, shown(o));
                break;
            }
            case kCurves: add_curves(st, in); break;
            case kMesh: add_mesh(st, in); break;
            case kLight: {
                const char *kinds[3] = {"sun", "point", "area"};
                const std::optional<std::string> o = options(in, kinds[in.take<uint8_t>() % 3]);
                check_not_internal(hairis_scene_add_light(st.scene, c_str(o)), "hairis_scene_add_light", shown(o));
                break;
            }
            case kWorld: {
                const std::optional<std::string> o = options(in, "world");
                check_not_internal(hairis_scene_set_world(st.scene, c_str(o)), "hairis_scene_set_world", shown(o));
                break;
            }
            case kCamera: set_camera(st, in); break;
            case kRender: render(st, in); break;
            case kQuery: query(st, in); break;
            case kOpCount: break;
        }
    }
    return 0;
}
