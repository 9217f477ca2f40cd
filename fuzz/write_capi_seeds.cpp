// Writes the seed corpus of the capi_params target (fuzz/corpus/capi_params/) in the input
// format of fuzz_input.h: valid call sequences and their broken variants (NaN, inf, negative
// values, unknown words and names, degenerate curves, huge counts), and the regression_*
// inputs, each re-creating the situation of an input that once failed. Most option strings
// are written as raw text, so a seed reads as what it passes; a few are structured, to start
// the fuzzer from known names. Deterministic: the same bytes on every run.
// Usage: write_capi_seeds DIR.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "fuzz_input.h"
#include "hairis/hairis.h"
#include "seed_writer.h"

namespace {

using namespace hairis::fuzz;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

struct Blob {
    std::vector<uint8_t> bytes;
    template <typename T>
    Blob &put(const T &v) {
        const auto *p = reinterpret_cast<const uint8_t *>(&v);
        bytes.insert(bytes.end(), p, p + sizeof v);
        return *this;
    }
    Blob &op(Op o) { return put(uint8_t(o)); }
    Blob &count(uint16_t n) { return put(n); }
    Blob &floats(std::initializer_list<float> v) {
        for (float x : v) put(x);
        return *this;
    }
    /// An option string as raw text.
    Blob &text(const std::string &t) {
        put(kRawOptions).put(uint16_t(t.size()));
        bytes.insert(bytes.end(), t.begin(), t.end());
        return *this;
    }
    Blob &null_options() { return put(kNullOptions); }
    /// A structured option string of `kind`: every known name with its default value.
    Blob &all_defaults(size_t kind) {
        const auto &known = known_names(kind);
        const size_t n = std::min<size_t>(known.size(), 15);
        put(uint8_t(n));
        for (size_t i = 0; i < n; ++i) put(uint8_t(i)).put(uint8_t(kDefault));
        return *this;
    }
    /// A structured item list: (name index into known_names(kind), value kind, payload bytes).
    Blob &items(std::initializer_list<std::vector<uint8_t>> list) {
        put(uint8_t(list.size()));
        for (const auto &item : list) bytes.insert(bytes.end(), item.begin(), item.end());
        return *this;
    }
};

size_t kind_of(const std::string &kind) {
    for (size_t k = 0; k < option_kinds().size(); ++k)
        if (option_kinds()[k] == kind) return k;
    return 0;
}

uint8_t name_index(const std::string &kind, const std::string &name) {
    const auto &known = known_names(kind_of(kind));
    for (size_t i = 0; i < known.size(); ++i)
        if (known[i].first == name) return uint8_t(i);
    std::fprintf(stderr, "write_capi_seeds: %s has no option %s\n", kind.c_str(), name.c_str());
    std::exit(1);
}

uint8_t number_index(const std::string &number) {
    for (size_t i = 0; i < numbers().size(); ++i)
        if (numbers()[i] == number) return uint8_t(i);
    std::fprintf(stderr, "write_capi_seeds: no number %s\n", number.c_str());
    std::exit(1);
}

/// "text" with name=value (replaced where present, else added at the end).
std::string with(const std::string &text, const std::string &name, const std::string &value) {
    std::vector<std::pair<std::string, std::string>> items;
    split_options(text, items);
    std::string out;
    bool found = false;
    for (auto &[n, v] : items) {
        if (n == name) {
            v = value;
            found = true;
        }
        out += (out.empty() ? "" : ";") + n + "=" + v;
    }
    if (!found) out += (out.empty() ? "" : ";") + name + "=" + value;
    return out;
}

// From the seed's Gaussian PDFs: capi_params runs only those bakes to the end.
const std::string kTinyBake = "theta_r=2;theta_i=4;phi=8;n_h=1,2;source=gaussian;threads=1";

Blob &chiang(Blob &b, const std::string &options) { return b.op(kFiber).put(uint8_t(0)).text(options); }
Blob &marschner(Blob &b, const std::string &options) {
    return b.op(kFiber).put(uint8_t(1)).text("model=marschner" + (options.empty() ? "" : ";" + options));
}

Blob &eval(Blob &b) {
    // fiber 0, 1 pair: wi = wo = (0, 1, 0), far field.
    return b.op(kEval).put(uint8_t(0)).count(1).floats({0, 1, 0}).floats({0, 1, 0}).floats({0}).put(uint8_t(0));
}

Blob &bake(Blob &b, const std::string &options) { return b.op(kBake).put(uint8_t(0)).text(options); }

// A sampler of fiber 0 and tables `tables` (0: the first, 1 with no tables: NULL), then two
// samples from sampler `sampler`.
Blob &sample(Blob &b, const std::string &options, uint8_t tables, uint8_t sampler) {
    b.op(kSample).put(uint8_t(0)).put(tables).text(options).put(sampler);
    return b.count(2).floats({0, 1, 0, 0.6f, 0.8f, 0}).floats({0.1f, 0.5f, 0.9f, 0.3f, 0.7f, 0.2f})
        .floats({0.0f, 0.5f}).put(uint8_t(1));
}

std::string camera(int width, int height, const std::string &extra = "") {
    // Looks down +Y from y = -5.
    return "matrix=1,0,0,0,0,0,-1,-5,0,1,0,0,0,0,0,1;frame=0.5,0.5,-1,0.5,-0.5,-1,-0.5,-0.5,-1,-0.5,0.5,-1;width=" +
           std::to_string(width) + ";height=" + std::to_string(height) + extra;
}

Blob &curves(Blob &b, int8_t material, const std::vector<uint8_t> &first,
             const std::vector<std::array<float, 4>> &points) {
    b.op(kCurves).put(material).put(uint8_t(0)).count(uint16_t(first.size() - 1)).count(uint16_t(points.size()));
    for (uint8_t f : first) b.put(f);
    for (const auto &p : points) b.floats({p[0], p[1], p[2]});
    for (const auto &p : points) b.put(p[3]);
    return b;
}

Blob &ground(Blob &b, int8_t material) {
    b.op(kMesh).count(3).count(1).floats({-2, -2, -1, 2, -2, -1, 0, 2, -1});
    return b.put(uint8_t(0)).put(uint8_t(1)).put(uint8_t(2)).put(material);
}

// A hair scene: material 0 diffuse, material 1 hair (a default Chiang fiber); `points`
// (x, y, z, radius) as curve(s) with `first`; a ground triangle; a sun; a 4×4 camera; a
// render of 16 pixel samples × 4 (small enough to run to the end).
Blob scene(const std::vector<uint8_t> &first, const std::vector<std::array<float, 4>> &points,
           const std::string &strategy = "analytic") {
    Blob b;
    b.op(kSurface).text("type=diffuse;color=0.5,0.5,0.5;emission=0,0,0");
    chiang(b, "");
    b.op(kHairMaterial).put(uint8_t(0)).put(uint8_t(0));
    curves(b, 1, first, points);
    ground(b, 0);
    b.op(kLight).put(uint8_t(0)).text("type=sun;direction=0.3,-0.5,1;color=1,1,1;strength=3;angle=0.05");
    b.op(kCamera).text(camera(4, 4));
    b.op(kRender).text("samples=1;max_bounces=3;strategy=" + strategy + ";threads=1");
    return b;
}

const std::vector<std::array<float, 4>> kStrand = {
    {0, 0, -1, 0.02f}, {0, 0, -0.3f, 0.02f}, {0.1f, 0, 0.3f, 0.01f}, {0.2f, 0, 1, 0.005f}};

}  // namespace

int main(int argc, char **argv) {
    const char *folder = hairis::fuzz::seed_folder(argc, argv);
    if (!folder) return 2;
    hairis::fuzz::Seeds seeds;
    auto add = [&](const std::string &name, Blob b) { seeds.emplace_back(name, std::move(b.bytes)); };

    {  // A Chiang fiber (the Principled Hair node): evaluate, bake tiny tables, sample them.
        Blob b;
        chiang(b, "");
        eval(b);
        bake(b, kTinyBake);
        sample(b, "strategy=table;multiple_weight=0.25;n_h=1", 0, 0);
        sample(b, "strategy=analytic", 0, 1);
        sample(b, "strategy=gaussian;multiple_weight=0.25;n_h=1", 0, 2);
        add("principled_bake_sample", b);
    }
    {
        Blob b;
        marschner(b, "");
        eval(b);
        bake(b, kTinyBake);
        sample(b, "strategy=uniform", 0, 0);
        add("marschner_bake_sample", b);
    }
    // Bad Principled Hair inputs, one at a time, each followed by an evaluation.
    const std::pair<const char *, const char *> node_cases[] = {
        {"principled_nan_roughness", "roughness=nan"},
        {"principled_inf_melanin", "melanin=inf"},
        {"principled_negative_melanin", "melanin=-1"},  // not read by Direct Coloring: accepted
        {"principled_roughness_above_1", "roughness=2"},
        {"principled_negative_roughness", "roughness=-0.5"},
        {"principled_ior_1", "ior=1"},
        {"principled_ior_below_1", "ior=0.5"},
        {"principled_parametrization_7", "parametrization=7"},
        {"principled_negative_absorption", "parametrization=absorption;absorption=0.245530993,-3,1.36500001"},
        {"principled_color_above_1", "parametrization=color;color=4,0.00576299988,0.00205900008"},
        {"principled_coat_nan", "coat=nan"},
    };
    for (const auto &[name, options] : node_cases) {
        Blob b;
        chiang(b, options);
        eval(b);
        add(name, b);
    }
    const std::pair<const char *, const char *> marschner_cases[] = {
        {"marschner_eta_below_1", "eta=0.9"},
        {"marschner_nan_beta", "beta_tt_deg=nan"},
        {"marschner_negative_beta", "beta_r_deg=-5.72957795"},
        {"marschner_negative_sigma", "sigma_a=0.15,0.2,-1"},
        {"marschner_inf_eccentricity", "eccentricity=inf"},
        {"marschner_zero_eccentricity", "eccentricity=0"},
    };
    for (const auto &[name, options] : marschner_cases) {
        Blob b;
        marschner(b, options);
        eval(b);
        add(name, b);
    }
    // Bake options: huge (refused before allocating), large but valid (cancelled), broken;
    // each followed by a TABLE sampler of what was baked.
    const std::pair<const char *, std::string> bake_cases[] = {
        {"bake_huge_resolution", with(with(with(kTinyBake, "theta_r", "1024"), "theta_i", "4096"), "phi", "4096")},
        {"bake_int_max", with(with(with(kTinyBake, "theta_r", "2147483647"), "theta_i", "2147483647"), "phi", "2147483647")},
        {"bake_default_resolution", hairis_defaults("bake")},
        {"bake_zero_resolution", with(kTinyBake, "theta_i", "0")},
        {"bake_negative_resolution", with(kTinyBake, "phi", "-8")},
        {"bake_n_h_count_17", with(kTinyBake, "n_h", "1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17")},
        {"bake_n_h_decreasing", with(kTinyBake, "n_h", "4,2")},
        {"bake_source_2", with(kTinyBake, "source", "2")},
        {"bake_gaussian_n_h_3", with(kTinyBake, "n_h", "1,3")},
        {"bake_exact_cancelled", with(kTinyBake, "source", "exact")},
        {"bake_negative_threads", with(kTinyBake, "threads", "-1")},
    };
    for (const auto &[name, options] : bake_cases) {
        Blob b;
        chiang(b, "");
        bake(b, options);
        if (std::string(name) == "bake_default_resolution") b.op(kBake).put(uint8_t(0)).null_options();
        sample(b, "strategy=table;multiple_weight=0.25;n_h=1", 0, 0);
        add(name, b);
    }
    // Scenes: a valid one, then broken curves.
    add("scene_render_analytic", scene({0, 4}, kStrand));
    add("scene_render_uniform", scene({0, 4}, kStrand, "uniform"));
    add("scene_render_table_without_tables", scene({0, 4}, kStrand, "table"));
    auto edited = [](std::vector<std::array<float, 4>> pts, size_t i, int k, float v) {
        pts[i][size_t(k)] = v;
        return pts;
    };
    add("curves_nan_position", scene({0, 4}, edited(kStrand, 2, 1, kNaN)));
    add("curves_inf_position", scene({0, 4}, edited(kStrand, 0, 2, -kInf)));
    add("curves_negative_radius", scene({0, 4}, edited(kStrand, 1, 3, -0.01f)));
    add("curves_nan_radius", scene({0, 4}, edited(kStrand, 3, 3, kNaN)));
    add("curves_zero_radius", scene({0, 4}, {{0, 0, 0, 0}, {0, 0, 1, 0}}));
    add("curves_zero_length", scene({0, 2}, {{0, 0, 0, 0.01f}, {0, 0, 0, 0.01f}}));
    add("curves_single_point", scene({0, 1}, {{0, 0, 0, 0.01f}}));
    add("curves_first_not_zero", scene({1, 4}, kStrand));
    add("curves_first_decreasing", scene({0, 3, 2}, kStrand));
    add("curves_first_past_end", scene({0, 9}, kStrand));
    add("curves_two_strands", scene({0, 2, 4}, kStrand));
    {
        Blob b;
        b.op(kSurface).text("color=0.5,0.5,0.5");
        b.op(kCurves).put(int8_t(0)).put(uint8_t(3)).put(uint64_t(1) << 40).put(uint64_t(1) << 41);
        b.op(kCurves).put(int8_t(0)).put(uint8_t(3)).put(~uint64_t(0)).put(~uint64_t(0));
        b.op(kCurves).put(int8_t(0)).put(uint8_t(1)).put(uint64_t(0)).put(uint64_t(1) << 62);
        add("curves_huge_counts", b);
    }
    {  // An empty scene with a camera; then cameras of the largest size and past it.
        Blob b;
        b.op(kCamera).text(camera(4, 4));
        b.op(kRender).text("samples=1;max_bounces=1;strategy=uniform");
        b.op(kCamera).text(camera(65536, 65536));
        b.op(kRender).text("samples=1;max_bounces=1;strategy=uniform");
        b.op(kCamera).text(camera(65537, 1));
        b.op(kCamera).text(camera(0, -1));
        add("scene_empty_and_camera_sizes", b);
    }
    {
        Blob b = scene({0, 4}, kStrand);
        b.op(kRender).text("samples=1;max_bounces=1;strategy=9");
        b.op(kRender).text("samples=0;max_bounces=1;strategy=analytic");
        b.op(kRender).text("samples=1;max_bounces=-1;strategy=analytic");
        b.op(kRender).text("samples=16777216;max_bounces=1024;strategy=analytic");
        b.op(kRender).text("samples=1;max_bounces=1;strategy=gaussian;multiple_weight=nan");
        add("render_bad_settings", b);
    }
    {  // Lights with NaN, negative power, an unknown area shape, a zero sun direction.
        Blob b;
        b.op(kLight).put(uint8_t(0)).text("type=sun;direction=0,0,0;color=1,1,1;strength=1;angle=0");
        b.op(kLight).put(uint8_t(1)).text("type=point;position=nan,0,0;color=1,1,1;power=-1;radius=0");
        b.op(kLight).put(uint8_t(2)).text("type=area;matrix=1,0,0,0,0,1,0,0,0,0,1,2,0,0,0,1;shape=7;size=1;size_y=1;color=1,1,1;power=10");
        b.op(kWorld).text("color=-1,inf,1;strength=1");
        add("lights_bad", b);
    }
    {  // A mesh with a hair material on a triangle, one with an index past the end.
        Blob b;
        chiang(b, "");
        b.op(kHairMaterial).put(uint8_t(0)).put(uint8_t(0));
        b.op(kMesh).count(3).count(1).floats({0, 0, 0, 1, 0, 0, 0, 1, 0});
        b.put(uint8_t(0)).put(uint8_t(1)).put(uint8_t(2)).put(int8_t(0));
        b.op(kSurface).text("color=0.5,0.5,0.5");
        b.op(kMesh).count(3).count(1).floats({0, 0, 0, 1, 0, 0, 0, 1, 0});
        b.put(uint8_t(0)).put(uint8_t(1)).put(uint8_t(200)).put(int8_t(1));
        b.op(kSurface).text("color=1.5,nan,0.5;emission=0,0,-1");
        add("mesh_bad", b);
    }

    // The option grammar: unknown and repeated names, items without '=' or a name, NULL.
    {
        Blob b;
        chiang(b, "bogus=1");
        chiang(b, "roughness=0.2;roughness=0.3");
        chiang(b, "roughness");
        chiang(b, "=0.3");
        chiang(b, " ;; roughness = 0.2 ; ");
        chiang(b, "eta=1.5");
        chiang(b, "offset=0.1;offset_deg=3");
        b.op(kFiber).put(uint8_t(0)).null_options();
        marschner(b, "roughness=0.3");
        b.op(kSample).put(uint8_t(0)).put(uint8_t(0)).text("strategy=uniform;weight=1").put(uint8_t(0)).count(0);  // no items: no h byte
        b.op(kWorld).null_options();
        b.op(kLight).put(uint8_t(0)).null_options();
        b.op(kSurface).text("type=glossy");
        b.op(kCamera).text("lens=50");
        add("options_grammar", b);
    }
    // Every kind's names with their defaults, structured (what the fuzzer starts from).
    {
        Blob b;
        b.op(kFiber).put(uint8_t(0)).all_defaults(kind_of("chiang"));
        b.op(kFiber).put(uint8_t(1)).all_defaults(kind_of("marschner"));
        b.op(kBake).put(uint8_t(0)).all_defaults(kind_of("bake"));
        b.op(kSample).put(uint8_t(0)).put(uint8_t(0)).all_defaults(kind_of("sampler")).put(uint8_t(0)).count(0);  // no items: no h byte
        b.op(kSurface).all_defaults(kind_of("diffuse"));
        b.op(kLight).put(uint8_t(0)).all_defaults(kind_of("sun"));
        b.op(kLight).put(uint8_t(1)).all_defaults(kind_of("point"));
        b.op(kLight).put(uint8_t(2)).all_defaults(kind_of("area"));
        b.op(kWorld).all_defaults(kind_of("world"));
        b.op(kHairMaterial).put(uint8_t(0)).put(uint8_t(0));
        curves(b, 1, {0, 4}, kStrand);
        b.op(kCamera).all_defaults(kind_of("camera"));
        b.op(kRender).all_defaults(kind_of("render"));
        // A tiny camera and render from structured items: width and height 4 (kNumbers),
        // samples 1, max_bounces 3, strategy analytic (kWords).
        const uint8_t number = kNumber, word = kWord;
        b.op(kCamera).items({{name_index("camera", "width"), number, number_index("4")},
                             {name_index("camera", "height"), number, number_index("4")}});
        b.op(kRender).items({{name_index("render", "samples"), number, number_index("1")},
                             {name_index("render", "max_bounces"), number, number_index("3")},
                             {name_index("render", "strategy"), word, 6}});
        add("defaults_every_kind", b);
    }
    // Render settings and camera options beyond the first C API's structs.
    {
        Blob b = scene({0, 4}, kStrand);
        b.op(kRender).text("samples=1;max_bounces=3;strategy=analytic;film_transparent=1");
        b.op(kRender).text("samples=1;max_bounces=3;strategy=analytic;tile_size=1");
        b.op(kRender).text("samples=1;max_bounces=3;strategy=analytic;max_diffuse_bounces=0;max_transmission_bounces=0");
        b.op(kRender).text("samples=1;max_bounces=3;strategy=analytic;tile_size=0");
        b.op(kCamera).text(camera(4, 4, ";clip_start=2;clip_end=8"));
        b.op(kRender).text("samples=1;max_bounces=3;strategy=analytic;rr_start_bounce=1;seed=18446744073709551615");
        b.op(kCamera).text(camera(4, 4, ";clip_start=3;clip_end=1"));
        add("render_new_settings", b);
    }
    // Cycles' Filter Glossy, Clamping and Pixel Filter, in range and out of it.
    {
        Blob b = scene({0, 4}, kStrand);
        b.op(kRender).text("samples=1;max_bounces=3;strategy=analytic;filter_glossy=1;clamp_indirect=10;"
                           "pixel_filter=blackman_harris;pixel_filter_width=1.5");
        b.op(kRender).text("samples=1;max_bounces=3;strategy=analytic;filter_glossy=10;clamp_direct=0.001;"
                           "pixel_filter=gaussian;pixel_filter_width=0.001");
        b.op(kRender).text("samples=1;max_bounces=3;strategy=analytic;pixel_filter=box;pixel_filter_width=10");
        b.op(kRender).text("samples=1;strategy=analytic;pixel_filter_width=0;filter_glossy=11;clamp_indirect=-1");
        add("render_cycles_biased_settings", b);
    }
    {  // Every getter, on handles and on NULL; hairis_defaults of every kind and of garbage.
        Blob b;
        chiang(b, "");
        bake(b, kTinyBake);
        for (uint8_t which = 0; which < 5; ++which) b.op(kQuery).put(which).put(uint8_t(0)).op(kQuery).put(which).put(uint8_t(1));
        b.op(kQuery).put(uint8_t(5)).put(uint8_t(0)).put(uint8_t(0));
        for (uint8_t kind = 0; kind < 12; ++kind) b.op(kQuery).put(uint8_t(6)).put(uint8_t(0)).put(kind);
        b.op(kQuery).put(uint8_t(6)).put(uint8_t(1)).put(uint8_t(5)).put('h').put('a').put('i').put('r').put('\0');
        b.op(kQuery).put(uint8_t(7));
        add("queries", b);
    }

    // ---- Regressions: each re-creates, in this format, an input that once failed. ----------

    // Embree aborted the process (ray.valid()) for a camera at ~1e35 over a curve reaching
    // 238 away: an ANALYTIC render, then refused renders and a garbage fiber.
    {
        Blob b;
        b.op(kSurface).text("type=diffuse;color=0.5,0.5,0.5;emission=0,0,0");
        chiang(b, "");
        b.op(kHairMaterial).put(uint8_t(0)).put(uint8_t(0));
        curves(b, 1, {0, 4}, {{0, 0, -1, 0.02f}, {0, 0, -238.404694f, 0.02f}, {0.1f, 0, 0.3f, 0.01f}, {0.2f, 0, 1, 0.005f}});
        ground(b, 0);
        b.op(kWorld).text("color=1,1,1;strength=3");
        b.op(kCamera).text("matrix=1,0,0,0,0,0,-1,-5,0,1,0,-6.64613998e+35,0,0,0,1;"
                           "frame=0.5,0.5,-1,0.5,-0.5,-1,-0.5,-0.5,-1,-0.5,0.5,-1;width=4;height=4");
        b.op(kRender).text("samples=1;max_bounces=3;strategy=analytic;multiple_weight=0.25;n_h=2;threads=1");
        b.op(kRender).text("samples=1;max_bounces=1;strategy=9");
        b.op(kRender).text("samples=0;max_bounces=1;strategy=analytic");
        b.op(kRender).text("samples=1;max_bounces=-1;strategy=analytic");
        chiang(b, "parametrization=7077888;color=7.255007e-39,0,9.18354962e-41;ior=0");
        add("regression_embree_ray_valid_assert", b);
    }
    // The harness multiplied resolutions of INT_MAX in int (undefined behaviour) to decide
    // whether a bake was small: bakes of INT_MAX and of negative sizes, then a TABLE sampler
    // without tables.
    {
        Blob b;
        chiang(b, "");
        bake(b, "theta_r=2147483647;theta_i=2147483647;phi=2147483647;n_h=1,2;source=exact;threads=1");
        bake(b, "theta_r=2147483647;theta_i=2147483647;phi=2147483647;n_h=1,2;source=gaussian;threads=1");
        bake(b, "theta_r=-2147483648;theta_i=-2147483648;phi=2;source=gaussian");
        bake(b, "theta_r=99999999999999999999;theta_i=4;phi=8;source=gaussian");
        sample(b, "strategy=table;multiple_weight=0.25;n_h=1", 0, 0);
        add("regression_harness_cells_overflow", b);
    }
    // A strategy outside the enum (1002231692) reached hairis_sampler_create; now an unknown
    // strategy word, with a NaN coat before and a garbage weight and n_h with it.
    {
        Blob b;
        chiang(b, "coat=nan");
        b.op(kEval).put(uint8_t(0)).count(0).put(uint8_t(0));
        b.op(kSample).put(uint8_t(0)).put(uint8_t(0)).text("strategy=1002231692;multiple_weight=-107599920;n_h=16204");
        b.put(uint8_t(0)).count(3)
            .floats({5.83155401e-39f, 5.83155401e-39f, 2.48581212e+35f, -4.54144756e-05f, 2.05106151e+11f,
                     -3.96390109e-23f, -3.94151543e-23f, 5.74890122e-39f, 1.51115727e+23f})
            .floats({7.14417524e-07f, 5.60733784e-39f, 0, 0, 9.40395481e-38f, 3.58732407e-43f, 0, 5.83155401e-39f, 0})
            .floats({0, 0, 0}).put(uint8_t(0));
        b.op(kSample).put(uint8_t(0)).put(uint8_t(0)).text("strategy=TABLE").put(uint8_t(0)).count(0);  // no items: no h byte
        b.op(kSample).put(uint8_t(0)).put(uint8_t(0)).text("strategy=").put(uint8_t(0)).count(0);  // no items: no h byte
        chiang(b, "parametrization=4161536");
        add("regression_strategy_outside_enum", b);
    }
    // TABLE with a fiber of roughness ~0 (Cycles clamps to 0.001): the near-field table
    // refused the fiber. The old input's tiny roughness, then roughness 0 exactly; each baked
    // (Gaussian source), sampled with TABLE and ANALYTIC.
    {
        Blob b;
        uint8_t index = 0;  // of the fiber and tables of each roughness
        for (const char *roughness : {"2.35103186e-38", "0"}) {
            chiang(b, std::string("roughness=") + roughness + ";radial_roughness=0.159765467;offset=0.0349065736");
            b.op(kEval).put(index).count(1).floats({0, 1, 0}).floats({0, 1, 0}).floats({0}).put(uint8_t(0));
            b.op(kBake).put(index).text(kTinyBake);
            const uint8_t sampler = uint8_t(2 * index);
            b.op(kSample).put(index).put(index).text("strategy=table;multiple_weight=0.25;n_h=1").put(sampler);
            b.count(2).floats({0, 1, 0, 0.6f, 0.8f, 0}).floats({0.1f, 0.5f, 0.9f, 0.3f, 0.7f, 0.2f})
                .floats({0.0f, 0.5f}).put(uint8_t(1));
            b.op(kSample).put(index).put(index).text("strategy=analytic;n_h=1").put(uint8_t(sampler + 1));
            b.count(2).floats({2.720076e+23f, -1.58821287e-23f, 2.73024443e-06f, 107375096.0f, 8.68805048e-44f, 0})
                .floats({9.69818601e-38f, 0, -0.0f, 4.45612912e-43f, 3.59091139e-40f, 0}).floats({0, 0}).put(uint8_t(0));
            ++index;
        }
        b.op(kLight).put(uint8_t(1)).text("type=point;position=107375096,8.82818033e-44,-107374592;color=0,0,0;power=0;radius=0");
        add("regression_table_sampler_roughness_tiny", b);
    }

    return hairis::fuzz::write_seeds(folder, seeds);
}
