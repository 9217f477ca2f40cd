// Writes the seed corpus of the capi_params target (fuzz/corpus/capi_params/) from the C
// structs themselves, so the blobs follow the header's layout: valid call sequences and
// their broken variants (NaN, inf, negative, out-of-range enums, degenerate curves, huge
// counts). Usage: write_capi_seeds DIR. The opcodes are capi_params.cpp's.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "hairis/hairis.h"

namespace {

enum Op : uint8_t {
    kPrincipled = 0, kMarschner, kEval, kBake, kSample, kHairMaterial, kDiffuse, kCurves, kMesh,
    kLight, kCamera, kRender
};

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
};

hairis_principled_hair node() {
    hairis_principled_hair n;
    hairis_principled_hair_defaults(&n);
    return n;
}

hairis_marschner_params marschner() {
    hairis_marschner_params m;
    hairis_marschner_defaults(&m);
    return m;
}

// From the seed's Gaussian PDFs: capi_params runs only those bakes to the end.
hairis_bake_options tiny_bake() {
    hairis_bake_options o;
    hairis_bake_options_defaults(&o);
    o.source = 1;
    o.theta_r_count = 2;
    o.theta_i_count = 4;
    o.phi_count = 8;
    o.n_h_count = 2;
    o.n_h_values[0] = 1;
    o.n_h_values[1] = 2;
    o.threads = 1;
    return o;
}

Blob &eval(Blob &b) {
    // fiber 0, 1 pair: wi = wo = (0, 1, 0), far field.
    return b.op(kEval).put(uint8_t(0)).count(1).floats({0, 1, 0}).floats({0, 1, 0}).floats({0}).put(uint8_t(0));
}

Blob &sample(Blob &b, int strategy, uint8_t tables) {
    b.op(kSample).put(strategy).put(uint8_t(0)).put(tables).put(0.25f).put(int(1)).put(uint8_t(0));
    return b.count(2).floats({0, 1, 0, 0.6f, 0.8f, 0}).floats({0.1f, 0.5f, 0.9f, 0.3f, 0.7f, 0.2f})
        .floats({0.0f, 0.5f}).put(uint8_t(1));
}

hairis_camera camera(int width, int height) {
    hairis_camera c{};
    const float m[16] = {1, 0, 0, 0, 0, 0, -1, -5, 0, 1, 0, 0, 0, 0, 0, 1};  // looks down +Y
    std::memcpy(c.camera_to_world, m, sizeof m);
    const float frame[12] = {0.5f, 0.5f, -1, 0.5f, -0.5f, -1, -0.5f, -0.5f, -1, -0.5f, 0.5f, -1};
    std::memcpy(c.frame, frame, sizeof frame);
    c.width = width;
    c.height = height;
    return c;
}

hairis_render_settings settings(int strategy, int samples, int bounces) {
    hairis_render_settings s;
    std::memset(&s, 0, sizeof s);  // its padding goes into the seed bytes too
    hairis_render_settings_defaults(&s);
    s.strategy = strategy;
    s.samples = samples;
    s.max_bounces = bounces;
    s.threads = 1;
    return s;
}

// A hair scene: material 0 diffuse, material 1 hair; `points` (x, y, z, radius) as curve(s)
// with `first`; a ground triangle; a sun; a 4×4 camera; a render.
Blob scene(const std::vector<uint8_t> &first, const std::vector<std::array<float, 4>> &points,
           int strategy = HAIRIS_STRATEGY_ANALYTIC) {
    Blob b;
    b.op(kDiffuse).floats({0.5f, 0.5f, 0.5f, 0, 0, 0});
    b.op(kHairMaterial).put(node()).put(uint8_t(0));
    b.op(kCurves).put(int8_t(1)).put(uint8_t(0)).count(uint16_t(first.size() - 1)).count(uint16_t(points.size()));
    for (uint8_t f : first) b.put(f);
    for (const auto &p : points) b.floats({p[0], p[1], p[2]});
    for (const auto &p : points) b.put(p[3]);
    b.op(kMesh).count(3).count(1).floats({-2, -2, -1, 2, -2, -1, 0, 2, -1});
    b.put(uint8_t(0)).put(uint8_t(1)).put(uint8_t(2)).put(int8_t(0));
    b.op(kLight).put(uint8_t(0)).floats({0.3f, -0.5f, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0})
        .floats({1, 1, 1}).floats({3.0f, 0.05f});
    b.op(kCamera).put(camera(4, 4));
    b.op(kRender).put(settings(strategy, 1, 3));
    return b;
}

}  // namespace

// A seed that changes one field of a valid struct.
template <typename T>
struct EditCase {
    const char *name;
    void (*edit)(T &);
};

int main(int argc, char **argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
        return 2;
    }
    std::vector<std::pair<std::string, Blob>> seeds;
    auto add = [&](const std::string &name, Blob b) { seeds.emplace_back(name, std::move(b)); };

    {  // A Principled fiber: evaluate, bake tiny tables, sample them.
        Blob b;
        b.op(kPrincipled).put(node());
        eval(b);
        b.op(kBake).put(uint8_t(0)).put(tiny_bake());
        sample(b, HAIRIS_STRATEGY_TABLE, 0);
        sample(b, HAIRIS_STRATEGY_ANALYTIC, 0);
        sample(b, HAIRIS_STRATEGY_GAUSSIAN, 0);
        add("principled_bake_sample", b);
    }
    {
        Blob b;
        b.op(kMarschner).put(marschner());
        eval(b);
        b.op(kBake).put(uint8_t(0)).put(tiny_bake());
        sample(b, HAIRIS_STRATEGY_UNIFORM, 0);
        add("marschner_bake_sample", b);
    }
    // Bad Principled inputs, one field at a time.
    const EditCase<hairis_principled_hair> node_cases[] = {
        {"principled_nan_roughness", [](hairis_principled_hair &n) { n.roughness = kNaN; }},
        {"principled_inf_melanin", [](hairis_principled_hair &n) { n.melanin = kInf; }},
        {"principled_negative_melanin", [](hairis_principled_hair &n) { n.melanin = -1; }},
        {"principled_roughness_above_1", [](hairis_principled_hair &n) { n.roughness = 2; }},
        {"principled_negative_roughness", [](hairis_principled_hair &n) { n.roughness = -0.5f; }},
        {"principled_ior_1", [](hairis_principled_hair &n) { n.ior = 1; }},
        {"principled_ior_below_1", [](hairis_principled_hair &n) { n.ior = 0.5f; }},
        {"principled_parametrization_7", [](hairis_principled_hair &n) { n.parametrization = 7; }},
        {"principled_negative_absorption", [](hairis_principled_hair &n) {
             n.parametrization = HAIRIS_PARAM_ABSORPTION;
             n.absorption_coefficient[1] = -3;
         }},
        {"principled_color_above_1", [](hairis_principled_hair &n) {
             n.parametrization = HAIRIS_PARAM_COLOR;
             n.color[0] = 4;
         }},
        {"principled_coat_nan", [](hairis_principled_hair &n) { n.coat = kNaN; }},
    };
    // Each a fiber from the edited struct, then an evaluation with it.
    auto add_fiber_cases = [&](const auto &cases, const auto &base, Op op) {
        for (const auto &c : cases) {
            auto value = base;
            c.edit(value);
            Blob b;
            b.op(op).put(value);
            eval(b);
            add(c.name, b);
        }
    };
    add_fiber_cases(node_cases, node(), kPrincipled);
    const EditCase<hairis_marschner_params> marschner_cases[] = {
        {"marschner_eta_below_1", [](hairis_marschner_params &m) { m.eta = 0.9f; }},
        {"marschner_nan_beta", [](hairis_marschner_params &m) { m.beta_tt = kNaN; }},
        {"marschner_negative_beta", [](hairis_marschner_params &m) { m.beta_r = -0.1f; }},
        {"marschner_negative_sigma", [](hairis_marschner_params &m) { m.sigma_a[2] = -1; }},
        {"marschner_inf_eccentricity", [](hairis_marschner_params &m) { m.eccentricity = kInf; }},
        {"marschner_zero_eccentricity", [](hairis_marschner_params &m) { m.eccentricity = 0; }},
    };
    add_fiber_cases(marschner_cases, marschner(), kMarschner);
    // Bake options: huge (refused before allocating), large but valid (cancelled), broken.
    const EditCase<hairis_bake_options> bake_cases[] = {
        {"bake_huge_resolution", [](hairis_bake_options &o) {
             o.theta_r_count = 1024;
             o.theta_i_count = 4096;
             o.phi_count = 4096;
         }},
        {"bake_int_max", [](hairis_bake_options &o) {
             o.theta_r_count = o.theta_i_count = o.phi_count = std::numeric_limits<int>::max();
         }},
        {"bake_default_resolution", [](hairis_bake_options &o) { hairis_bake_options_defaults(&o); }},
        {"bake_zero_resolution", [](hairis_bake_options &o) { o.theta_i_count = 0; }},
        {"bake_negative_resolution", [](hairis_bake_options &o) { o.phi_count = -8; }},
        {"bake_n_h_count_17", [](hairis_bake_options &o) { o.n_h_count = 17; }},
        {"bake_n_h_decreasing", [](hairis_bake_options &o) { o.n_h_values[0] = 4; }},
        {"bake_source_2", [](hairis_bake_options &o) { o.source = 2; }},
        {"bake_gaussian_n_h_3", [](hairis_bake_options &o) { o.n_h_values[1] = 3; }},
        {"bake_exact_cancelled", [](hairis_bake_options &o) { o.source = 0; }},
        {"bake_negative_threads", [](hairis_bake_options &o) { o.threads = -1; }},
    };
    for (const auto &c : bake_cases) {
        hairis_bake_options o = tiny_bake();
        c.edit(o);
        Blob b;
        b.op(kPrincipled).put(node());
        b.op(kBake).put(uint8_t(0)).put(o);
        sample(b, HAIRIS_STRATEGY_TABLE, 0);
        add(c.name, b);
    }
    // Scenes: a valid one, then broken curves.
    const std::vector<std::array<float, 4>> strand = {
        {0, 0, -1, 0.02f}, {0, 0, -0.3f, 0.02f}, {0.1f, 0, 0.3f, 0.01f}, {0.2f, 0, 1, 0.005f}};
    add("scene_render_analytic", scene({0, 4}, strand));
    add("scene_render_uniform", scene({0, 4}, strand, HAIRIS_STRATEGY_UNIFORM));
    add("scene_render_table_without_tables", scene({0, 4}, strand, HAIRIS_STRATEGY_TABLE));
    auto with = [&](std::vector<std::array<float, 4>> pts, size_t i, int k, float v) {
        pts[i][size_t(k)] = v;
        return pts;
    };
    add("curves_nan_position", scene({0, 4}, with(strand, 2, 1, kNaN)));
    add("curves_inf_position", scene({0, 4}, with(strand, 0, 2, -kInf)));
    add("curves_negative_radius", scene({0, 4}, with(strand, 1, 3, -0.01f)));
    add("curves_nan_radius", scene({0, 4}, with(strand, 3, 3, kNaN)));
    add("curves_zero_radius", scene({0, 4}, {{0, 0, 0, 0}, {0, 0, 1, 0}}));
    add("curves_zero_length", scene({0, 2}, {{0, 0, 0, 0.01f}, {0, 0, 0, 0.01f}}));
    add("curves_single_point", scene({0, 1}, {{0, 0, 0, 0.01f}}));
    add("curves_first_not_zero", scene({1, 4}, strand));
    add("curves_first_decreasing", scene({0, 3, 2}, strand));
    add("curves_first_past_end", scene({0, 9}, strand));
    add("curves_two_strands", scene({0, 2, 4}, strand));
    {
        Blob b;
        b.op(kDiffuse).floats({0.5f, 0.5f, 0.5f, 0, 0, 0});
        b.op(kCurves).put(int8_t(0)).put(uint8_t(3)).put(uint64_t(1) << 40).put(uint64_t(1) << 41);
        b.op(kCurves).put(int8_t(0)).put(uint8_t(3)).put(~uint64_t(0)).put(~uint64_t(0));
        b.op(kCurves).put(int8_t(0)).put(uint8_t(1)).put(uint64_t(0)).put(uint64_t(1) << 62);
        add("curves_huge_counts", b);
    }
    {  // An empty scene with a camera; then a camera of the largest size, cancelled.
        Blob b;
        b.op(kCamera).put(camera(4, 4));
        b.op(kRender).put(settings(HAIRIS_STRATEGY_UNIFORM, 1, 1));
        b.op(kCamera).put(camera(65536, 65536));
        b.op(kCamera).put(camera(65537, 1));
        b.op(kCamera).put(camera(0, -1));
        add("scene_empty_and_camera_sizes", b);
    }
    {
        Blob b = scene({0, 4}, strand);
        b.op(kRender).put(settings(9, 1, 1));
        b.op(kRender).put(settings(HAIRIS_STRATEGY_ANALYTIC, 0, 1));
        b.op(kRender).put(settings(HAIRIS_STRATEGY_ANALYTIC, 1, -1));
        b.op(kRender).put(settings(HAIRIS_STRATEGY_ANALYTIC, 1 << 24, 1024));
        hairis_render_settings nan_weight = settings(HAIRIS_STRATEGY_GAUSSIAN, 1, 1);
        nan_weight.multiple_weight = kNaN;
        b.op(kRender).put(nan_weight);
        add("render_bad_settings", b);
    }
    {  // Lights with NaN, negative power, unknown area shapes, a zero sun direction.
        Blob b;
        b.op(kLight).put(uint8_t(0)).floats({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0})
            .floats({1, 1, 1}).floats({1, 0});
        b.op(kLight).put(uint8_t(1)).floats({kNaN, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0})
            .floats({1, 1, 1}).floats({-1, 0});
        b.op(kLight).put(uint8_t(2)).floats({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 2, 0, 0, 0, 1})
            .floats({1, 1, 1}).floats({1, 1}).put(int(7)).put(10.0f);
        b.op(kLight).put(uint8_t(3)).floats({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0})
            .floats({-1, kInf, 1}).floats({1, 0});
        add("lights_bad", b);
    }
    {  // A mesh with an index past the end and a hair material on a triangle.
        Blob b;
        b.op(kHairMaterial).put(node()).put(uint8_t(0));
        b.op(kMesh).count(3).count(1).floats({0, 0, 0, 1, 0, 0, 0, 1, 0});
        b.put(uint8_t(0)).put(uint8_t(1)).put(uint8_t(2)).put(int8_t(0));
        b.op(kDiffuse).floats({0.5f, 0.5f, 0.5f, 0, 0, 0});
        b.op(kMesh).count(3).count(1).floats({0, 0, 0, 1, 0, 0, 0, 1, 0});
        b.put(uint8_t(0)).put(uint8_t(1)).put(uint8_t(200)).put(int8_t(1));
        b.op(kDiffuse).floats({1.5f, kNaN, 0.5f, 0, 0, -1});
        add("mesh_bad", b);
    }

    for (const auto &[name, blob] : seeds) {
        const std::string path = std::string(argv[1]) + "/" + name;
        std::FILE *f = std::fopen(path.c_str(), "wb");
        if (!f || std::fwrite(blob.bytes.data(), 1, blob.bytes.size(), f) != blob.bytes.size() ||
            std::fclose(f) != 0) {
            std::fprintf(stderr, "cannot write %s\n", path.c_str());
            return 1;
        }
    }
    std::printf("wrote %zu seeds to %s\n", seeds.size(), argv[1]);
    return 0;
}
