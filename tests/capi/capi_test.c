/* Tests of the hairis C API (lib/include/hairis/hairis.h, hairis_render.h), written in C11
 * against the shared library, as a renderer embedding hairis would use it.
 *
 * Usage: capi_test   runs every check and prints "N passed, M failed"; exits 1 on a failure.
 *
 * HAIRIS_EXPECTED_VERSION (a compile definition) is the project's version.
 */
#define _POSIX_C_SOURCE 200809L
#include "hairis/hairis.h"
#include "hairis/hairis_render.h"

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <threads.h>
#include <unistd.h>

#ifndef HAIRIS_EXPECTED_VERSION
#error "HAIRIS_EXPECTED_VERSION must be defined (the project's version)"
#endif

/* ---- A tiny test harness ------------------------------------------------------------------ */

static int g_passed = 0, g_failed = 0;
static const char *g_section = "";

static void check_at(int ok, const char *file, int line, const char *format, ...)
{
    if (ok) {
        ++g_passed;
        return;
    }
    ++g_failed;
    fprintf(stderr, "FAIL [%s] %s:%d: ", g_section, file, line);
    va_list args;
    va_start(args, format);
    vfprintf(stderr, format, args);
    va_end(args);
    fprintf(stderr, " (hairis_last_error: \"%s\")\n", hairis_last_error());
}

#define CHECK(cond, ...) check_at((cond) ? 1 : 0, __FILE__, __LINE__, __VA_ARGS__)

/* The last error is "" (the last call succeeded). */
#define CHECK_NO_ERROR()                                                                          \
    CHECK(hairis_last_error() != NULL && hairis_last_error()[0] == '\0',                          \
          "expected no error after a successful call")

/* The last error mentions `word`. */
static int error_mentions(const char *word)
{
    const char *message = hairis_last_error();
    return message != NULL && message[0] != '\0' && strstr(message, word) != NULL;
}

#define CHECK_ERROR_MENTIONS(word) CHECK(error_mentions(word), "error should mention \"%s\"", word)

static void section(const char *name)
{
    g_section = name;
    printf("-- %s\n", name);
    fflush(stdout);
}

/* Deterministic uniform numbers in [0, 1) (splitmix64). */
static uint64_t g_rng = 0x1234567887654321ull;
static float uniform(void)
{
    uint64_t z = (g_rng += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (float)(z >> 40) / 16777216.0f;
}

/* A uniformly random unit vector, kept away from the fiber axis (|x| <= 0.98). */
static void random_direction(float *w)
{
    float x, r, phi;
    do {
        x = 1.0f - 2.0f * uniform();
    } while (fabsf(x) > 0.98f);
    r = sqrtf(fmaxf(0.0f, 1.0f - x * x));
    phi = 6.2831853f * uniform();
    w[0] = x;
    w[1] = r * cosf(phi);
    w[2] = r * sinf(phi);
}

static void direction_from_angles(float theta, float phi, float *w)
{
    w[0] = sinf(theta);
    w[1] = cosf(theta) * cosf(phi);
    w[2] = cosf(theta) * sinf(phi);
}

static int all_finite_non_negative(const float *v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(v[i]) || v[i] < 0.0f) return 0;
    return 1;
}

/* ---- Option strings, read here independently of the library ------------------------------- */

enum { TEXT = 4096 };

/* Copies a string the library returned (it lives until the next call on this thread). */
static const char *keep(char *into, const char *text)
{
    snprintf(into, TEXT, "%s", text ? text : "(null)");
    return into;
}

/* Item `index` of "name=value;..." as name and value; 0 past the last item. */
static int option_item(const char *options, int index, char *name, char *value, size_t size)
{
    const char *p = options;
    for (int i = 0; i < index; ++i) {
        p = strchr(p, ';');
        if (!p) return 0;
        ++p;
    }
    if (*p == '\0') return 0;
    const char *end = strchr(p, ';'), *eq = strchr(p, '=');
    if (!end) end = p + strlen(p);
    if (!eq || eq > end) return 0;
    snprintf(name, size, "%.*s", (int)(eq - p), p);
    snprintf(value, size, "%.*s", (int)(end - eq - 1), eq + 1);
    return 1;
}

/* The value of `name` in "name=value;..."; 0 when absent. */
static int option_value(const char *options, const char *name, char *value, size_t size)
{
    char n[256], v[TEXT];
    for (int i = 0; option_item(options, i, n, v, sizeof v); ++i)
        if (strcmp(n, name) == 0) {
            snprintf(value, size, "%s", v);
            return 1;
        }
    return 0;
}

/* `options` with the value of `name` (which must be there) replaced; into has TEXT bytes. */
static const char *with_option(char *into, const char *options, const char *name,
                               const char *value)
{
    char n[256], v[TEXT], out[TEXT] = "";
    int found = 0;
    for (int i = 0; option_item(options, i, n, v, sizeof v); ++i) {
        const int same = strcmp(n, name) == 0;
        found |= same;
        size_t used = strlen(out);
        const int n_out =
            snprintf(out + used, sizeof out - used, "%s%s=%s", i ? ";" : "", n, same ? value : v);
        CHECK(n_out > 0 && (size_t)n_out < sizeof out - used, "with_option: too long");
    }
    CHECK(found, "with_option: \"%s\" has no %s", options, name);
    snprintf(into, TEXT, "%s", out);
    return into;
}

/* The message lists `name` among the known names "(known: a, b, c)". */
static int lists_known_name(const char *message, const char *name)
{
    const char *p = strstr(message, "(known:");
    if (!p) return 0;
    p += strlen("(known:");
    const size_t n = strlen(name);
    while (*p && *p != ')') {
        while (*p == ' ') ++p;
        const char *end = p;
        while (*end && *end != ',' && *end != ')') ++end;
        if ((size_t)(end - p) == n && strncmp(p, name, n) == 0) return 1;
        p = *end == ',' ? end + 1 : end;
    }
    return 0;
}

/* ---- Shared fixtures ---------------------------------------------------------------------- */

#define TINY_BAKE "theta_r=4;theta_i=8;phi=8;n_h=1,2;threads=2"

typedef struct progress_state {
    int calls;
    int cancel_at; /* cancel on this call (1-based); 0 = never */
    float last;
    int decreasing;
} progress_state;

static int on_progress(void *user, float progress)
{
    progress_state *s = (progress_state *)user;
    ++s->calls;
    if (progress < s->last) s->decreasing = 1;
    s->last = progress;
    return s->cancel_at > 0 && s->calls >= s->cancel_at;
}

static int cancel_at_once(void *user, float progress)
{
    (void)user;
    (void)progress;
    return 1;
}

static hairis_tables *g_tables = NULL; /* baked for the default Chiang fiber, n_h {1, 2} */

/* ---- Library ------------------------------------------------------------------------------ */

static int set_error_in_thread(void *arg)
{
    (void)arg;
    hairis_fiber *fiber = hairis_fiber_create("roughness=2");
    return fiber == NULL && hairis_last_error()[0] != '\0' ? 0 : 1;
}

static void test_library(void)
{
    section("library");
    CHECK(hairis_api_version() == 2 && HAIRIS_API_VERSION == 2, "api version %d",
          hairis_api_version());
    CHECK_NO_ERROR();
    const char *version = hairis_version_string();
    CHECK(version != NULL && strcmp(version, HAIRIS_EXPECTED_VERSION) == 0,
          "version string \"%s\", the project is %s", version ? version : "(null)",
          HAIRIS_EXPECTED_VERSION);
    CHECK(hairis_last_error() != NULL, "hairis_last_error never returns NULL");

    /* The last error is per thread: an error on another thread leaves this one's alone. */
    hairis_api_version();
    thrd_t thread;
    int result = -1;
    CHECK(thrd_create(&thread, set_error_in_thread, NULL) == thrd_success, "thrd_create");
    thrd_join(thread, &result);
    CHECK(result == 0, "the other thread saw its own error");
    CHECK_NO_ERROR();

    /* An error is cleared by the next successful call. */
    CHECK(hairis_fiber_create("ior=0.5") == NULL, "IOR 0.5 refused");
    CHECK(hairis_last_error()[0] != '\0', "an error is reported");
    hairis_api_version();
    CHECK_NO_ERROR();
}

/* ---- Defaults ----------------------------------------------------------------------------- */

/* hairis_defaults(kind) holds name=expected. */
static void expect_default(const char *kind, const char *name, const char *expected)
{
    char value[TEXT];
    const char *defaults = hairis_defaults(kind);
    CHECK(defaults != NULL && option_value(defaults, name, value, sizeof value) &&
              strcmp(value, expected) == 0,
          "hairis_defaults(\"%s\"): %s should be %s in \"%s\"", kind, name, expected,
          defaults ? defaults : "(null)");
}

static const char *const g_kinds[] = {"chiang",  "huang",      "marschner", "bake",   "sampler",
                                      "diffuse",  "principled", "glossy",    "emission", "sun",
                                      "point",    "area",       "world",     "camera", "render",
                                      "curve_inputs"};
enum { KIND_COUNT = sizeof g_kinds / sizeof g_kinds[0] };

static void test_defaults(void)
{
    section("defaults");
    /* Blender's Principled Hair node (Direct Coloring), in radians. */
    expect_default("chiang", "model", "chiang");
    expect_default("chiang", "parametrization", "color");
    expect_default("chiang", "ior", "1.54999995");
    expect_default("chiang", "roughness", "0.300000012");
    expect_default("chiang", "radial_roughness", "0.300000012");
    expect_default("chiang", "offset", "0.0349065848"); /* 2 degrees */
    expect_default("chiang", "color", "0.0175129995,0.00576299988,0.00205900008");
    expect_default("chiang", "coat", "0");
    expect_default("chiang", "random", "0");
    expect_default("chiang", "cycles", "3.4");
    /* The node with the Huang model: Chiang's shared inputs, Aspect Ratio and the lobes. */
    expect_default("huang", "model", "huang");
    expect_default("huang", "aspect_ratio", "0.850000024");
    expect_default("huang", "reflection", "1");
    expect_default("huang", "transmission", "1");
    expect_default("huang", "secondary_reflection", "1");
    expect_default("huang", "roughness", "0.300000012");
    expect_default("huang", "offset", "0.0349065848");
    {
        const char *huang = hairis_defaults("huang");
        CHECK(huang && !strstr(huang, "radial_roughness") && !strstr(huang, "coat=") &&
                  !strstr(huang, "cycles="),
              "Huang lists no Chiang-only input: \"%s\"", huang ? huang : "(null)");
    }
    CHECK(hairis_defaults("curves") != NULL && strcmp(hairis_defaults("curves"), "") == 0,
          "curves options: none yet");
    /* The seed's Marschner parameters (blonde). */
    expect_default("marschner", "model", "marschner");
    expect_default("marschner", "eta", "1.55");
    expect_default("marschner", "sigma_a", "0.150000006,0.200000003,0.300000012");
    expect_default("marschner", "alpha_r_deg", "-7.5");
    expect_default("marschner", "eccentricity", "0.9");
    expect_default("bake", "theta_r", "31");
    expect_default("bake", "theta_i", "64");
    expect_default("bake", "phi", "64");
    expect_default("bake", "n_h", "1,2,4,8,16");
    expect_default("bake", "source", "exact");
    expect_default("bake", "threads", "0");
    expect_default("sampler", "strategy", "table");
    expect_default("sampler", "multiple_weight", "0");
    expect_default("sampler", "n_h", "2");
    expect_default("render", "integrator", "path");
    expect_default("render", "dual_exact_bounces", "3");
    expect_default("render", "dual_bounce_limit", "bounces");
    expect_default("render", "samples", "64");
    expect_default("render", "max_bounces", "12");
    expect_default("render", "max_diffuse_bounces", "4");
    expect_default("render", "max_transmission_bounces", "12");
    expect_default("render", "max_transparent_bounces", "8");
    expect_default("render", "transparent_limit", "plus_one");
    expect_default("render", "tile_size", "16");
    expect_default("render", "film_transparent", "0");
    expect_default("render", "curve_backfaces", "ignore");
    expect_default("render", "curve_shape", "thick");
    expect_default("render", "bvh_quality", "medium");
    expect_default("render", "filter_glossy", "0");
    expect_default("render", "clamp_indirect", "0");
    expect_default("render", "pixel_filter", "box");
    expect_default("render", "pixel_filter_width", "1");
    expect_default("render", "curve_subdivisions", "2");
    expect_default("render", "exposure", "1");
    expect_default("render", "strategy", "table");
    expect_default("render", "seed", "0");
    expect_default("render", "threads", "0");
    expect_default("camera", "width", "64");
    expect_default("camera", "clip_start", "0");
    expect_default("sun", "type", "sun");
    expect_default("area", "shape", "square");
    expect_default("diffuse", "type", "diffuse");
    CHECK_NO_ERROR();

    /* Every kind the header names has defaults; the others are refused, listing the kinds. */
    for (int k = 0; k < KIND_COUNT; ++k) {
        const char *d = hairis_defaults(g_kinds[k]);
        CHECK(d != NULL && strchr(d, '=') != NULL, "defaults of %s: \"%s\"", g_kinds[k],
              d ? d : "(null)");
    }
    CHECK(hairis_defaults("velvet") == NULL, "unknown kind");
    for (int k = 0; k < KIND_COUNT; ++k) CHECK_ERROR_MENTIONS(g_kinds[k]);
    CHECK_ERROR_MENTIONS("texture");
    CHECK_ERROR_MENTIONS("mix");
    CHECK(hairis_defaults(NULL) == NULL, "NULL kind");
    CHECK_ERROR_MENTIONS("kind");
}

/* ---- Option strings: the grammar and the refusals every call shares ----------------------- */

static hairis_fiber *g_option_fiber;   /* default Chiang fiber */
static hairis_scene *g_option_scene;   /* a scene for the scene calls */
static float g_option_rgba[16 * 16 * 4];

/* Each tries one call of a kind with `options` and returns whether it was accepted. */
static int try_fiber(const char *kind, const char *options)
{
    char text[TEXT];
    snprintf(text, sizeof text, "model=%s;%s", kind, options);
    hairis_fiber *f = hairis_fiber_create(text);
    if (f) hairis_fiber_destroy(f); /* (destroy would clear a refusal's message) */
    return f != NULL;
}

static int try_options(const char *kind, const char *options)
{
    char text[TEXT];
    if (strcmp(kind, "chiang") == 0 || strcmp(kind, "huang") == 0 || strcmp(kind, "marschner") == 0)
        return try_fiber(kind, options);
    if (strcmp(kind, "bake") == 0) {
        /* Accepted options reach the first progress call, which cancels. */
        hairis_tables *t = hairis_tables_bake(g_option_fiber, options, cancel_at_once, NULL);
        if (t) hairis_tables_destroy(t);
        return t != NULL || strcmp(hairis_last_error(), "cancelled") == 0;
    }
    if (strcmp(kind, "sampler") == 0) {
        hairis_sampler *s = hairis_sampler_create(g_option_fiber, g_tables, options);
        if (s) hairis_sampler_destroy(s);
        return s != NULL;
    }
    if (strcmp(kind, "render") == 0) {
        const int status =
            hairis_render(g_option_scene, options, g_option_rgba, cancel_at_once, NULL);
        return status == HAIRIS_OK || status == HAIRIS_ERROR_CANCELLED;
    }
    if (strcmp(kind, "diffuse") == 0 || strcmp(kind, "principled") == 0 ||
        strcmp(kind, "glossy") == 0 || strcmp(kind, "emission") == 0) {
        snprintf(text, sizeof text, "type=%s;%s", kind, options);
        return hairis_scene_add_surface_material(g_option_scene, text) >= 0;
    }
    if (strcmp(kind, "sun") == 0 || strcmp(kind, "point") == 0 || strcmp(kind, "area") == 0) {
        snprintf(text, sizeof text, "type=%s;%s", kind, options);
        return hairis_scene_add_light(g_option_scene, text) == HAIRIS_OK;
    }
    if (strcmp(kind, "world") == 0)
        return hairis_scene_set_world(g_option_scene, options) == HAIRIS_OK;
    if (strcmp(kind, "camera") == 0) {
        /* The scene's camera stays 16 x 16 (g_option_rgba's size). */
        snprintf(text, sizeof text, "width=16;height=16;%s", options);
        return hairis_scene_set_camera(g_option_scene, text) == HAIRIS_OK;
    }
    if (strcmp(kind, "curve_inputs") == 0) {
        /* Curves of material 0 with the given inputs; "material" (the default) takes no value. */
        const float p[6] = {-1, 0.5f, 0, 1, 0.5f, 0}, r[2] = {0.05f, 0.05f};
        const uint32_t first[2] = {0, 2};
        return hairis_scene_add_curves_with_inputs(g_option_scene, 0, 1, first, 2, p, r, options, 0,
                                                   NULL) == HAIRIS_OK;
    }
    CHECK(0, "no call for kind %s", kind);
    return 0;
}

static void test_option_strings(void)
{
    section("option strings");
    g_option_fiber = hairis_fiber_create("");
    g_option_scene = hairis_scene_create();
    const int hair = hairis_scene_add_hair_material(g_option_scene, g_option_fiber, g_tables);
    const float p[6] = {-1, 0, 0, 1, 0, 0}, r[2] = {0.05f, 0.05f};
    const uint32_t first[2] = {0, 2};
    CHECK(hairis_scene_add_curves(g_option_scene, hair, 1, first, 2, p, r) == HAIRIS_OK &&
              hairis_scene_set_camera(g_option_scene,
                                      "matrix=1,0,0,0,0,1,0,0,0,0,1,3,0,0,0,1;width=16;height=16") ==
                  HAIRIS_OK,
          "a scene to render");

    char text[TEXT];
    for (int k = 0; k < KIND_COUNT; ++k) {
        const char *kind = g_kinds[k];
        /* What the kind's call accepts without a name of its own. */
        CHECK(try_options(kind, ""), "%s: no options are its defaults", kind);
        if (strcmp(kind, "bake") != 0 && strcmp(kind, "render") != 0) CHECK_NO_ERROR();

        /* An unknown name: refused, naming it and listing every name of the kind. */
        CHECK(!try_options(kind, "bogus_name=1"), "%s: an unknown name is refused", kind);
        char message[TEXT];
        keep(message, hairis_last_error());
        CHECK(strstr(message, "\"bogus_name\"") != NULL, "%s: the message names it: %s", kind,
              message);
        char defaults[TEXT], name[256], value[TEXT];
        keep(defaults, hairis_defaults(kind));
        for (int i = 0; option_item(defaults, i, name, value, sizeof value); ++i)
            CHECK(lists_known_name(message, name), "%s: the message lists %s: %s", kind, name,
                  message);

        /* A name given twice, an item without '=', an item without a name. */
        option_item(defaults, 1, name, value, sizeof value);
        CHECK(snprintf(text, sizeof text, "%s=%s;%s=%s", name, value, name, value) < TEXT, "fits");
        CHECK(!try_options(kind, text), "%s: %s given twice is refused", kind, name);
        CHECK_ERROR_MENTIONS("given twice");
        CHECK_ERROR_MENTIONS(name);
        snprintf(text, sizeof text, "%s", name);
        CHECK(!try_options(kind, text), "%s: \"%s\" without a value is refused", kind, name);
        CHECK_ERROR_MENTIONS("name=value");
        CHECK(!try_options(kind, "=3"), "%s: an item without a name is refused", kind);
        CHECK_ERROR_MENTIONS("no name");

        /* Spaces around names and values and empty items are allowed. */
        CHECK(snprintf(text, sizeof text, " ;; %s = %s ; ", name, value) < TEXT, "fits");
        CHECK(try_options(kind, text), "%s: \"%s\" is accepted", kind, text);
    }

    /* A Marschner name is unknown to Chiang and the other way round; preset is not an option. */
    CHECK(!try_fiber("chiang", "eta=1.5"), "eta for Chiang");
    CHECK_ERROR_MENTIONS("\"eta\"");
    CHECK_ERROR_MENTIONS("model=chiang");
    CHECK(!try_fiber("marschner", "roughness=0.3"), "roughness for Marschner");
    CHECK_ERROR_MENTIONS("\"roughness\"");
    CHECK_ERROR_MENTIONS("model=marschner");
    CHECK(!try_fiber("huang", "radial_roughness=0.3"), "radial_roughness for Huang");
    CHECK_ERROR_MENTIONS("\"radial_roughness\"");
    CHECK_ERROR_MENTIONS("model=huang");
    CHECK_ERROR_MENTIONS("aspect_ratio");
    CHECK(!try_fiber("huang", "cycles=4.5"), "cycles for Huang (it is Cycles 4.5/5.0's)");
    CHECK(!try_fiber("chiang", "aspect_ratio=0.5"), "aspect_ratio for Chiang");
    CHECK_ERROR_MENTIONS("model=chiang");
    CHECK(!try_fiber("chiang", "preset=blonde"), "preset");
    CHECK_ERROR_MENTIONS("\"preset\"");
    CHECK(!try_fiber("chiang", "offset=0.1;offset_deg=3"), "offset and offset_deg");
    CHECK_ERROR_MENTIONS("offset_deg");

    /* Unknown choice words: refused naming the option and listing the words it takes. */
    struct {
        const char *kind, *options, *name, *allowed;
    } words[] = {
        {"chiang", "parametrization=7", "parametrization", "melanin"},
        {"chiang", "parametrization=Color", "parametrization", "absorption"},
        {"sampler", "strategy=9", "strategy", "analytic"},
        {"sampler", "strategy=TABLE", "strategy", "gaussian"},
        {"render", "strategy=tables", "strategy", "uniform"},
        {"render", "integrator=dual", "integrator", "dual_scattering"},
        {"bake", "source=2", "source", "gaussian"},
        {"area", "shape=hexagon", "shape", "ellipse"},
        {"render", "film_transparent=2", "film_transparent", "true"},
        {"render", "curve_backfaces=cull", "curve_backfaces", "hit"},
        {"render", "curve_shape=RIBBONS", "curve_shape", "thick_linear"},
        {"render", "bvh_quality=fast", "bvh_quality", "high"},
        {"render", "pixel_filter=mitchell", "pixel_filter", "blackman_harris"},
        {"render", "pixel_filter_width=0", "pixel_filter_width", "0.001"},
        {"render", "filter_glossy=-1", "filter_glossy", "10"},
        {"camera", "orthographic=yes", "orthographic", "false"},
    };
    for (size_t i = 0; i < sizeof words / sizeof words[0]; ++i) {
        CHECK(!try_options(words[i].kind, words[i].options), "%s: %s refused", words[i].kind,
              words[i].options);
        CHECK_ERROR_MENTIONS(words[i].name);
        CHECK_ERROR_MENTIONS(words[i].allowed);
    }
    CHECK(hairis_fiber_create("model=hair") == NULL, "an unknown model");
    CHECK_ERROR_MENTIONS("marschner");
    CHECK(hairis_scene_add_light(g_option_scene, "type=tube") != HAIRIS_OK, "a tube light");
    CHECK_ERROR_MENTIONS("spot");
    CHECK(hairis_scene_add_light(g_option_scene, "strength=2") != HAIRIS_OK, "a light without type");
    CHECK_ERROR_MENTIONS("type");
    CHECK(hairis_scene_add_surface_material(g_option_scene, "type=velvet") < 0, "velvet");
    CHECK_ERROR_MENTIONS("diffuse");
    CHECK_ERROR_MENTIONS("principled");

    /* NaN, infinity and numbers that are not numbers, refused by name. */
    struct {
        const char *kind, *options, *name;
    } numbers[] = {
        {"chiang", "roughness=nan", "roughness"},
        {"chiang", "coat=NaN", "coat"},
        {"chiang", "offset=inf", "offset"},
        {"chiang", "tint=nan,1,1", "tint"},       /* not read by Direct Coloring, still refused */
        {"chiang", "melanin=-inf", "melanin"},
        {"chiang", "color=0.5,0.5", "color"},     /* two components */
        {"marschner", "eta=nan", "eta"},
        {"marschner", "beta_trt_deg=inf", "beta_trt_deg"},
        {"bake", "theta_i=8.5", "theta_i"},
        {"bake", "threads=two", "threads"},
        {"sampler", "multiple_weight=nan", "multiple_weight"},
        {"render", "samples=1e3", "samples"},
        {"render", "seed=-1", "seed"},
        {"sun", "direction=nan,0,1", "direction"},
        {"point", "power=inf", "power"},
        {"world", "strength=-inf", "strength"},
        {"camera", "frame=0,0,nan,1,1,1,1,1,1,1,1,1", "frame"},
        {"diffuse", "emission=1,1,inf", "emission"},
        {"principled", "metallic=nan", "metallic"},
        {"principled", "base_color=1,inf,1", "base_color"},
        {"glossy", "roughness=-inf", "roughness"},
        {"emission", "strength=nan", "strength"},
    };
    for (size_t i = 0; i < sizeof numbers / sizeof numbers[0]; ++i) {
        CHECK(!try_options(numbers[i].kind, numbers[i].options), "%s: %s refused",
              numbers[i].kind, numbers[i].options);
        CHECK_ERROR_MENTIONS(numbers[i].name);
    }

    /* NULL options read as "": the defaults. */
    hairis_fiber *from_null = hairis_fiber_create(NULL);
    CHECK(from_null && strcmp(keep(text, hairis_fiber_parameters(from_null)),
                              hairis_fiber_parameters(g_option_fiber)) == 0,
          "hairis_fiber_create(NULL) is the default fiber");
    hairis_fiber_destroy(from_null);
    CHECK(hairis_scene_set_world(g_option_scene, NULL) == HAIRIS_OK, "world from NULL");
    CHECK(hairis_scene_add_surface_material(g_option_scene, NULL) >= 0, "diffuse from NULL");
    CHECK(hairis_scene_add_light(g_option_scene, NULL) != HAIRIS_OK, "a light needs its type");
    CHECK_ERROR_MENTIONS("type");

    hairis_scene_destroy(g_option_scene);
    hairis_fiber_destroy(g_option_fiber);
}

/* ---- Fibers ------------------------------------------------------------------------------- */

/* Creating a fiber from `options` fails and the error mentions `word`. */
static void expect_fiber_refused(const char *options, const char *word)
{
    hairis_fiber *fiber = hairis_fiber_create(options);
    CHECK(fiber == NULL, "\"%s\" refused", options);
    CHECK_ERROR_MENTIONS(word);
    hairis_fiber_destroy(fiber);
}

static void test_fiber_creation(void)
{
    section("fiber creation");
    const char *parametrizations[3] = {"absorption", "melanin", "color"};
    char text[TEXT], first[TEXT] = "";
    for (int p = 0; p < 3; ++p) {
        snprintf(text, sizeof text, "parametrization=%s", parametrizations[p]);
        hairis_fiber *fiber = hairis_fiber_create(text);
        CHECK(fiber != NULL, "%s accepted", text);
        CHECK_NO_ERROR();
        CHECK(strcmp(hairis_fiber_model(fiber), "chiang2016") == 0, "model \"%s\"",
              hairis_fiber_model(fiber));
        CHECK(strstr(hairis_fiber_parameters(fiber), "sigma_a.r=") != NULL &&
                  strstr(hairis_fiber_parameters(fiber), "offset=") != NULL,
              "parameters \"%s\"", hairis_fiber_parameters(fiber));
        CHECK_NO_ERROR();
        /* Each parametrization maps the node's defaults to its own absorption. */
        if (p == 0) keep(first, hairis_fiber_parameters(fiber));
        else CHECK(strcmp(first, hairis_fiber_parameters(fiber)) != 0, "%s: another sigma_a", text);
        hairis_fiber_destroy(fiber);
        CHECK_NO_ERROR();
    }

    /* Two nodes that map to the same closure parameters give the same parameter string. */
    {
        hairis_fiber *a = hairis_fiber_create("");
        hairis_fiber *b = hairis_fiber_create("melanin=0.1"); /* not read by Direct Coloring */
        CHECK(a && b && strcmp(keep(text, hairis_fiber_parameters(a)),
                               hairis_fiber_parameters(b)) == 0,
              "unread inputs do not change the parameters");
        /* offset_deg is offset in degrees. */
        hairis_fiber *c = hairis_fiber_create("offset_deg=2");
        CHECK(a && c && strcmp(keep(text, hairis_fiber_parameters(a)),
                               hairis_fiber_parameters(c)) == 0,
              "offset_deg=2 is the default offset of 2 degrees");
        /* Cycles 4.2's tilt changes f, and the parameters say so. */
        hairis_fiber *d = hairis_fiber_create("cycles=4.2");
        CHECK(d && strstr(hairis_fiber_parameters(d), "cycles=4.2") != NULL &&
                  strstr(hairis_fiber_parameters(a), "cycles") == NULL,
              "cycles=4.2 is recorded: \"%s\"", d ? hairis_fiber_parameters(d) : "");
        hairis_fiber_destroy(a);
        hairis_fiber_destroy(b);
        hairis_fiber_destroy(c);
        hairis_fiber_destroy(d);
    }

    hairis_fiber *marschner = hairis_fiber_create("model=marschner");
    CHECK(marschner != NULL, "Marschner defaults accepted");
    CHECK(strcmp(hairis_fiber_model(marschner), "marschner2003") == 0, "model \"%s\"",
          hairis_fiber_model(marschner));
    CHECK(strstr(hairis_fiber_parameters(marschner), "eta=1.55;") != NULL,
          "eta printed as typed: \"%s\"", hairis_fiber_parameters(marschner));
    CHECK(strstr(hairis_fiber_parameters(marschner), "sigma_a.r=0.150000006;") != NULL,
          "blonde sigma_a: \"%s\"", hairis_fiber_parameters(marschner));
    hairis_fiber_destroy(marschner);

    /* Every kind of bad value: unknown word, non-finite, out of range. */
    expect_fiber_refused("parametrization=7", "parametrization");
    expect_fiber_refused("parametrization=-1", "parametrization");
    expect_fiber_refused("roughness=2", "roughness");
    expect_fiber_refused("radial_roughness=-0.5", "radial_roughness");
    expect_fiber_refused("ior=0.9", "ior");
    expect_fiber_refused("ior=1", "ior");
    expect_fiber_refused("coat=nan", "coat");
    expect_fiber_refused("offset=inf", "offset");
    expect_fiber_refused("offset=2", "offset"); /* more than pi/2 */
    expect_fiber_refused("color=0.5,0,0.5", "color");
    expect_fiber_refused("tint=1,1,nan", "tint"); /* not read by Direct Coloring, never finite */
    expect_fiber_refused("parametrization=melanin;melanin=1.5", "melanin");
    expect_fiber_refused("parametrization=absorption;absorption=-1,0,0", "absorption");
    expect_fiber_refused("random=-0.5", "random");
    expect_fiber_refused("cycles=2.8", "cycles");

    expect_fiber_refused("model=marschner;eta=nan", "eta");
    expect_fiber_refused("model=marschner;eta=0.8", "eta");
    expect_fiber_refused("model=marschner;eccentricity=0.5", "eccentricity");
    expect_fiber_refused("model=marschner;caustic_limit=2", "caustic_limit");
    expect_fiber_refused("model=marschner;sigma_a=0.1,-0.1,0.1", "sigma_a");
    expect_fiber_refused("model=marschner;beta_trt_deg=inf", "beta_trt_deg");
    expect_fiber_refused("model=marschner;beta_r_deg=-1", "beta_r");

    /* Getters on NULL. */
    CHECK(strcmp(hairis_fiber_model(NULL), "") == 0, "model of NULL is \"\"");
    CHECK_ERROR_MENTIONS("fiber");
    CHECK(strcmp(hairis_fiber_parameters(NULL), "") == 0, "parameters of NULL is \"\"");
    CHECK_ERROR_MENTIONS("fiber");
    hairis_fiber_destroy(NULL);
    CHECK_NO_ERROR();
}

static void test_fiber_eval(void)
{
    section("fiber eval");
    hairis_fiber *chiang = hairis_fiber_create("");
    hairis_fiber *marschner = hairis_fiber_create("model=marschner");
    CHECK(chiang && marschner, "fibers");

    enum { N = 64 };
    float wi[3 * N], wo[3 * N], h[N], rgb[3 * N];
    for (int i = 0; i < N; ++i) {
        random_direction(wi + 3 * i);
        random_direction(wo + 3 * i);
        h[i] = 2.0f * uniform() - 1.0f;
    }
    CHECK(hairis_fiber_eval(chiang, N, wi, wo, NULL, rgb) == HAIRIS_OK, "far field");
    CHECK_NO_ERROR();
    CHECK(all_finite_non_negative(rgb, 3 * N), "far field finite, >= 0");
    CHECK(hairis_fiber_eval(chiang, N, wi, wo, h, rgb) == HAIRIS_OK, "near field");
    CHECK(all_finite_non_negative(rgb, 3 * N), "near field finite, >= 0");
    CHECK(hairis_fiber_eval(marschner, N, wi, wo, NULL, rgb) == HAIRIS_OK, "Marschner far");
    CHECK(all_finite_non_negative(rgb, 3 * N), "Marschner finite, >= 0");

    /* The far field is the near field averaged over h = sin(gamma): (1/2) ∫ f(h) dh. */
    {
        float a[3], b[3];
        direction_from_angles(-0.3f, 2.6f, a); /* near the TT lobe */
        direction_from_angles(0.25f, -1.5707963f, b);
        float far[3];
        CHECK(hairis_fiber_eval(chiang, 1, a, b, NULL, far) == HAIRIS_OK, "far one");
        enum { K = 4001 };
        static float many_a[3 * K], many_b[3 * K], many_h[K], many_f[3 * K];
        static double weights[K];
        for (int k = 0; k < K; ++k) {
            const double gamma = -1.5707963267948966 + 3.141592653589793 * k / (K - 1);
            memcpy(many_a + 3 * k, a, sizeof a);
            memcpy(many_b + 3 * k, b, sizeof b);
            many_h[k] = (float)sin(gamma);
            weights[k] = cos(gamma) * (k == 0 || k == K - 1 ? 0.5 : 1.0) * 3.141592653589793 /
                         (K - 1) * 0.5;
        }
        CHECK(hairis_fiber_eval(chiang, K, many_a, many_b, many_h, many_f) == HAIRIS_OK,
              "near batch (parallel)");
        double sum[3] = {0, 0, 0};
        for (int k = 0; k < K; ++k)
            for (int c = 0; c < 3; ++c) sum[c] += weights[k] * many_f[3 * k + c];
        for (int c = 0; c < 3; ++c)
            CHECK(fabs(sum[c] - far[c]) <= 0.01 * fabs(far[c]) + 1e-6,
                  "channel %d: average of the near field %g, far field %g", c, sum[c], far[c]);
        CHECK(far[0] > 1e-4f, "a direction pair with a visible value (%g)", far[0]);
    }

    /* Which argument is ω_i: Marschner's f is reciprocal (M_R,TT,TRT depend on θ_h and |θ_d|,
     * N_p on φ and |θ_d|, the eccentric η* on φ_h, all unchanged by swapping ω_i and ω_o), so
     * eval(ω_i, ω_o) / |cos θ_i| = eval(ω_o, ω_i) / |cos θ_o| where the cosines differ; with
     * ω_i and ω_o swapped at the ABI the cosine factor is the wrong one and the sides differ by
     * (cos θ_o / cos θ_i)². */
    {
        const float pairs[][4] = {/* θ_i, φ_i, θ_o, φ_o */
                                  {-0.9f, 2.9f, 0.2f, -1.5707963f},
                                  {0.1f, -2.8f, -0.4f, 1.0f},
                                  {-0.35f, 0.4f, 0.95f, -0.6f},
                                  {0.9f, 3.0f, -1.2f, -0.3f}};
        enum { P = sizeof pairs / sizeof pairs[0] };
        float forward_i[3 * P], forward_o[3 * P], forward[3 * P], backward[3 * P];
        for (int k = 0; k < P; ++k) {
            direction_from_angles(pairs[k][0], pairs[k][1], forward_i + 3 * k);
            direction_from_angles(pairs[k][2], pairs[k][3], forward_o + 3 * k);
        }
        CHECK(hairis_fiber_eval(marschner, P, forward_i, forward_o, NULL, forward) == HAIRIS_OK,
              "Marschner forward");
        CHECK(hairis_fiber_eval(marschner, P, forward_o, forward_i, NULL, backward) == HAIRIS_OK,
              "Marschner backward");
        for (int k = 0; k < P; ++k) {
            const double cos_i = cos(pairs[k][0]), cos_o = cos(pairs[k][2]);
            for (int c = 0; c < 3; ++c) {
                const double f_forward = forward[3 * k + c] / cos_i;
                const double f_backward = backward[3 * k + c] / cos_o;
                CHECK(f_forward > 1e-4, "pair %d channel %d: a visible value (%g)", k, c,
                      f_forward);
                CHECK(fabs(f_forward - f_backward) <= 1e-4 * f_forward,
                      "pair %d channel %d: eval/cos θ_i %g, swapped eval/cos θ_o %g (ω_i and ω_o "
                      "taken the other way round?)", k, c, f_forward, f_backward);
            }
        }
    }

    /* Refusals: the batch is checked whole before anything is written. */
    CHECK(hairis_fiber_eval(marschner, N, wi, wo, h, rgb) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "no near field for Marschner");
    CHECK_ERROR_MENTIONS("h must be NULL");
    CHECK_ERROR_MENTIONS("marschner2003");
    CHECK(hairis_fiber_eval(NULL, N, wi, wo, NULL, rgb) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "NULL fiber");
    CHECK_ERROR_MENTIONS("fiber");
    CHECK(hairis_fiber_eval(chiang, N, NULL, wo, NULL, rgb) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "NULL wi");
    CHECK_ERROR_MENTIONS("wi");
    CHECK(hairis_fiber_eval(chiang, N, wi, wo, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "NULL rgb_out");
    CHECK_ERROR_MENTIONS("rgb_out");
    CHECK(hairis_fiber_eval(chiang, 0, NULL, NULL, NULL, NULL) == HAIRIS_OK,
          "n = 0 with NULL arrays is a no-op");
    CHECK_NO_ERROR();
    float saved = wi[3 * 5];
    wi[3 * 5] = NAN;
    for (int i = 0; i < 3 * N; ++i) rgb[i] = -7.0f;
    CHECK(hairis_fiber_eval(chiang, N, wi, wo, NULL, rgb) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "NaN wi");
    CHECK_ERROR_MENTIONS("wi item 5");
    int untouched = 1;
    for (int i = 0; i < 3 * N; ++i) untouched &= rgb[i] == -7.0f;
    CHECK(untouched, "nothing written on error (items before the bad one included)");
    wi[3 * 5] = saved;
    wo[3 * 2] *= 2.0f; /* not unit length */
    CHECK(hairis_fiber_eval(chiang, N, wi, wo, NULL, rgb) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "non-unit wo");
    CHECK_ERROR_MENTIONS("unit");
    CHECK(rgb[0] == -7.0f, "nothing written on error");
    wo[3 * 2] *= 0.5f;
    h[3] = 1.5f;
    CHECK(hairis_fiber_eval(chiang, N, wi, wo, h, rgb) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "h out of range");
    CHECK_ERROR_MENTIONS("h[3]");
    h[3] = NAN;
    CHECK(hairis_fiber_eval(chiang, N, wi, wo, h, rgb) == HAIRIS_ERROR_INVALID_ARGUMENT, "NaN h");
    CHECK_ERROR_MENTIONS("h[3]");
    CHECK(rgb[0] == -7.0f, "nothing written on error");

    hairis_fiber_destroy(chiang);
    hairis_fiber_destroy(marschner);
}

/* ---- Tables ------------------------------------------------------------------------------- */

/* Reads a whole file; *size receives its length. NULL on failure. */
static unsigned char *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long length = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *data = malloc(length > 0 ? (size_t)length : 1);
    *size = data ? fread(data, 1, (size_t)length, f) : 0;
    fclose(f);
    return data;
}

static void expect_bake_refused(const hairis_fiber *fiber, const char *options, const char *word)
{
    hairis_tables *t = hairis_tables_bake(fiber, options, NULL, NULL);
    CHECK(t == NULL, "bake with \"%s\" refused", options ? options : "(NULL)");
    CHECK_ERROR_MENTIONS(word);
    CHECK(strcmp(hairis_last_error(), "cancelled") != 0, "refused, not cancelled");
    hairis_tables_destroy(t);
}

static void test_tables(const char *temp_dir)
{
    section("tables");
    hairis_fiber *fiber = hairis_fiber_create("");
    char text[TEXT];

    progress_state progress = {0, 0, -1.0f, 0};
    hairis_tables *baked = hairis_tables_bake(fiber, TINY_BAKE, on_progress, &progress);
    CHECK(baked != NULL, "tiny bake");
    CHECK_NO_ERROR();
    CHECK(progress.calls >= 2 && progress.last == 1.0f && !progress.decreasing,
          "progress: %d calls, last %g", progress.calls, progress.last);
    CHECK(strcmp(hairis_tables_model(baked), "chiang2016") == 0, "model \"%s\"",
          hairis_tables_model(baked));
    CHECK(strcmp(keep(text, hairis_tables_parameters(baked)), hairis_fiber_parameters(fiber)) == 0,
          "tables parameters \"%s\" = fiber's \"%s\"", text, hairis_fiber_parameters(fiber));
    CHECK(hairis_tables_match_fiber(baked, fiber) == 1, "matches its fiber");
    CHECK_NO_ERROR();
    /* What the tables hold, as the bake asked for. */
    CHECK(strcmp(hairis_tables_info(baked), "source=exact;theta_r=4;theta_i=8;phi=8;n_h=1,2") == 0,
          "info \"%s\"", hairis_tables_info(baked));
    CHECK_NO_ERROR();

    /* A bake without a progress callback; the Gaussian source. */
    hairis_tables *gaussian = hairis_tables_bake(fiber, TINY_BAKE ";source=gaussian", NULL, NULL);
    CHECK(gaussian != NULL, "gaussian-source bake");
    CHECK(gaussian && hairis_tables_match_fiber(gaussian, fiber) == 1,
          "the source does not change the fiber match");
    CHECK(gaussian && strcmp(hairis_tables_info(gaussian),
                             "source=gaussian;theta_r=4;theta_i=8;phi=8;n_h=1,2") == 0,
          "gaussian info \"%s\"", gaussian ? hairis_tables_info(gaussian) : "");
    hairis_tables_destroy(gaussian);

    /* Marschner tables. */
    {
        hairis_fiber *marschner = hairis_fiber_create("model=marschner");
        hairis_tables *mt = hairis_tables_bake(
            marschner, "theta_r=2;theta_i=8;phi=8;n_h=1,2;threads=2", NULL, NULL);
        CHECK(mt != NULL, "Marschner bake");
        CHECK(mt && strcmp(hairis_tables_model(mt), "marschner2003") == 0, "Marschner model");
        CHECK(mt && hairis_tables_match_fiber(mt, marschner) == 1, "Marschner tables match");
        CHECK(mt && hairis_tables_match_fiber(mt, fiber) == 0, "not the Chiang fiber's");
        CHECK_NO_ERROR();
        hairis_tables_destroy(mt);
        hairis_fiber_destroy(marschner);
    }

    /* A cancelled bake. */
    progress_state cancel = {0, 2, -1.0f, 0};
    hairis_tables *cancelled = hairis_tables_bake(fiber, TINY_BAKE, on_progress, &cancel);
    CHECK(cancelled == NULL, "cancelled bake returns NULL");
    CHECK(strcmp(hairis_last_error(), "cancelled") == 0, "the message is \"cancelled\"");
    CHECK(cancel.calls == 2, "no progress call after cancelling (%d calls)", cancel.calls);
    hairis_tables_destroy(cancelled);
    /* NULL options are the defaults (31 x 64 x 64, exact): accepted, so cancelled at once. */
    cancel = (progress_state){0, 1, -1.0f, 0};
    CHECK(hairis_tables_bake(fiber, NULL, on_progress, &cancel) == NULL &&
              strcmp(hairis_last_error(), "cancelled") == 0 && cancel.calls == 1,
          "NULL options: the default bake, cancelled at the first progress call");

    /* Bad options. */
    expect_bake_refused(NULL, TINY_BAKE, "fiber");
    expect_bake_refused(fiber, "theta_r=0", "theta_r");
    expect_bake_refused(fiber, "theta_r=-4", "theta_r");
    expect_bake_refused(fiber, "theta_i=100000", "theta_i");
    expect_bake_refused(fiber, "phi=0", "phi");
    expect_bake_refused(fiber, "n_h=1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17", "n_h");
    expect_bake_refused(fiber, "n_h=", "n_h");
    expect_bake_refused(fiber, "n_h=1,1", "increasing");
    expect_bake_refused(fiber, "n_h=4,2", "increasing");
    expect_bake_refused(fiber, "source=2", "source");
    expect_bake_refused(fiber, "source=gaussian;n_h=1,3", "n_h");
    expect_bake_refused(fiber, "threads=-1", "threads");
    expect_bake_refused(fiber, "quadrature_points=0", "quadrature_points");
    /* Every axis in range, the product too large: refused before allocating. */
    expect_bake_refused(fiber, "theta_r=1024;theta_i=4096;phi=4096", "cells");

    /* Write, load from the file and from memory. */
    char path[1024], missing_dir_path[1024], missing_path[1024];
    snprintf(path, sizeof path, "%s/hairis_capi_test_%ld.exr", temp_dir, (long)getpid());
    snprintf(missing_dir_path, sizeof missing_dir_path, "%s/no_such_dir_%ld/t.exr", temp_dir,
             (long)getpid());
    snprintf(missing_path, sizeof missing_path, "%s/no_such_file_%ld.exr", temp_dir,
             (long)getpid());
    CHECK(hairis_tables_write(baked, path) == HAIRIS_OK, "write %s", path);
    CHECK_NO_ERROR();
    CHECK(hairis_tables_write(baked, missing_dir_path) == HAIRIS_ERROR_IO,
          "write into a missing folder is an I/O error");
    CHECK_ERROR_MENTIONS("no_such_dir");
    CHECK(hairis_tables_write(NULL, path) == HAIRIS_ERROR_INVALID_ARGUMENT, "NULL tables");
    CHECK_ERROR_MENTIONS("tables");
    CHECK(hairis_tables_write(baked, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT, "NULL path");
    CHECK_ERROR_MENTIONS("path");

    hairis_tables *from_file = hairis_tables_load_file(path);
    CHECK(from_file != NULL, "load from file");
    CHECK_NO_ERROR();
    CHECK(from_file && strcmp(keep(text, hairis_tables_parameters(from_file)),
                              hairis_tables_parameters(baked)) == 0,
          "parameters survive the file");
    CHECK(from_file && strcmp(keep(text, hairis_tables_info(from_file)),
                              hairis_tables_info(baked)) == 0,
          "info survives the file: \"%s\"", text);
    CHECK(from_file && hairis_tables_match_fiber(from_file, fiber) == 1,
          "loaded tables match the fiber");

    size_t size = 0;
    unsigned char *bytes = read_all(path, &size);
    CHECK(bytes != NULL && size > 100, "read %zu bytes", size);
    hairis_tables *from_memory = bytes ? hairis_tables_load_memory(bytes, size) : NULL;
    CHECK(from_memory != NULL, "load from memory");
    CHECK_NO_ERROR();
    CHECK(from_memory && strcmp(hairis_tables_model(from_memory), "chiang2016") == 0,
          "model from memory");
    CHECK(from_memory && hairis_tables_match_fiber(from_memory, fiber) == 1,
          "memory tables match the fiber");

    /* The same bytes again (decoded once, then reused): an independent handle, alive after the
     * first is destroyed, that samples alike. */
    if (bytes && from_memory) {
        hairis_tables *again = hairis_tables_load_memory(bytes, size);
        CHECK(again != NULL && again != from_memory, "the same bytes load again as a new handle");
        hairis_tables *first = hairis_tables_load_memory(bytes, size);
        hairis_tables_destroy(first);
        CHECK(again && strcmp(hairis_tables_info(again), hairis_tables_info(from_memory)) == 0 &&
                  hairis_tables_match_fiber(again, fiber) == 1,
              "with the same content after another handle of it was destroyed");
        hairis_sampler *a = again ? hairis_sampler_create(fiber, again, NULL) : NULL;
        hairis_sampler *b = hairis_sampler_create(fiber, from_memory, NULL);
        enum { M = 64 };
        float wo[3 * M], u[3 * M], wa[3 * M], wb[3 * M], pa[M], pb[M];
        for (int i = 0; i < M; ++i) {
            random_direction(wo + 3 * i);
            for (int k = 0; k < 3; ++k) u[3 * i + k] = uniform();
        }
        CHECK(a && b && hairis_sample(a, M, wo, NULL, u, wa, pa) == HAIRIS_OK &&
                  hairis_sample(b, M, wo, NULL, u, wb, pb) == HAIRIS_OK && memcmp(wa, wb, sizeof wa) == 0 &&
                  memcmp(pa, pb, sizeof pa) == 0,
              "and samples exactly as the first load");
        hairis_sampler_destroy(a);
        hairis_sampler_destroy(b);
        hairis_tables_destroy(again);
    }

    /* Corrupt and empty buffers, missing files (after the same file's valid bytes were loaded:
     * a changed byte is decoded, not taken from what was loaded before). */
    if (bytes) {
        unsigned char *corrupt = malloc(size);
        memcpy(corrupt, bytes, size);
        corrupt[size - 16] ^= 0x5a; /* inside the pixel data */
        hairis_tables *t = hairis_tables_load_memory(corrupt, size);
        CHECK(t == NULL, "a corrupted buffer is refused");
        CHECK_ERROR_MENTIONS("hairis table");
        hairis_tables_destroy(t);
        t = hairis_tables_load_memory(bytes, size / 2);
        CHECK(t == NULL, "a truncated buffer is refused");
        CHECK(hairis_last_error()[0] != '\0', "with a message");
        hairis_tables_destroy(t);
        memset(corrupt, 'x', size);
        t = hairis_tables_load_memory(corrupt, size);
        CHECK(t == NULL, "garbage is refused");
        CHECK_ERROR_MENTIONS("EXR");
        hairis_tables_destroy(t);
        free(corrupt);
    }
    CHECK(hairis_tables_load_memory(bytes, 0) == NULL, "size 0 refused");
    CHECK_ERROR_MENTIONS("size");
    CHECK(hairis_tables_load_memory(NULL, 10) == NULL, "NULL data refused");
    CHECK_ERROR_MENTIONS("data");
    CHECK(hairis_tables_load_file(missing_path) == NULL, "missing file refused");
    CHECK_ERROR_MENTIONS("no_such_file");
    CHECK(hairis_tables_load_file(NULL) == NULL, "NULL path refused");
    CHECK_ERROR_MENTIONS("path");
    free(bytes);

    /* Matching: another roughness, another model. */
    {
        hairis_fiber *rougher = hairis_fiber_create("roughness=0.4");
        CHECK(hairis_tables_match_fiber(baked, rougher) == 0, "another roughness: no match");
        CHECK_NO_ERROR();
        hairis_fiber *marschner = hairis_fiber_create("model=marschner");
        CHECK(hairis_tables_match_fiber(baked, marschner) == 0, "another model: no match");
        CHECK(hairis_tables_match_fiber(NULL, fiber) == 0, "NULL tables");
        CHECK_ERROR_MENTIONS("tables");
        CHECK(hairis_tables_match_fiber(baked, NULL) == 0, "NULL fiber");
        CHECK_ERROR_MENTIONS("fiber");
        CHECK(strcmp(hairis_tables_model(NULL), "") == 0, "model of NULL");
        CHECK(strcmp(hairis_tables_parameters(NULL), "") == 0, "parameters of NULL");
        CHECK(strcmp(hairis_tables_info(NULL), "") == 0, "info of NULL");
        CHECK_ERROR_MENTIONS("tables");
        hairis_fiber_destroy(rougher);
        hairis_fiber_destroy(marschner);
    }

    hairis_tables_destroy(from_file);
    hairis_tables_destroy(baked);
    hairis_tables_destroy(NULL);
    CHECK_NO_ERROR();
    g_tables = from_memory; /* used by the sampling and render tests */
    remove(path);
    hairis_fiber_destroy(fiber);
}

/* ---- Sampling ----------------------------------------------------------------------------- */

/* ∫ pdf(ω_i) dω_i over the sphere at one ω_o and h, by the midpoint rule in (θ, φ) with
 * dω = cos θ dθ dφ: 1 for a normalised density. */
static double pdf_integral(hairis_sampler *sampler, const float *wo, float h)
{
    enum { NT = 512, NPHI = 512, N = NT * NPHI };
    static float wi[3 * N], wos[3 * N], hs[N], pdf[N];
    static double weight[N];
    const double pi = 3.141592653589793;
    for (int a = 0; a < NT; ++a)
        for (int b = 0; b < NPHI; ++b) {
            const int i = a * NPHI + b;
            const double theta = -0.5 * pi + pi * (a + 0.5) / NT;
            const double phi = -pi + 2.0 * pi * (b + 0.5) / NPHI;
            wi[3 * i] = (float)sin(theta);
            wi[3 * i + 1] = (float)(cos(theta) * cos(phi));
            wi[3 * i + 2] = (float)(cos(theta) * sin(phi));
            weight[i] = cos(theta) * (pi / NT) * (2.0 * pi / NPHI);
            memcpy(wos + 3 * i, wo, 3 * sizeof(float));
            hs[i] = h;
        }
    if (hairis_pdf(sampler, N, wi, wos, hs, pdf) != HAIRIS_OK) return -1.0;
    double sum = 0;
    for (int i = 0; i < N; ++i) sum += weight[i] * pdf[i];
    return sum;
}

static void check_sample_pdf_consistency(hairis_sampler *sampler, const char *name, int normalised)
{
    enum { N = 4096 };
    static float wo[3 * N], h[N], u[3 * N], wi[3 * N], pdf[N], pdf_again[N];
    for (int i = 0; i < N; ++i) {
        random_direction(wo + 3 * i);
        h[i] = 2.0f * uniform() - 1.0f;
        for (int k = 0; k < 3; ++k) u[3 * i + k] = uniform();
    }
    CHECK(hairis_sample(sampler, N, wo, h, u, wi, pdf) == HAIRIS_OK, "%s: sample", name);
    CHECK_NO_ERROR();
    CHECK(hairis_pdf(sampler, N, wi, wo, h, pdf_again) == HAIRIS_OK, "%s: pdf", name);
    int produced = 0, consistent = 0, unit = 0;
    double worst = 0;
    for (int i = 0; i < N; ++i) {
        if (pdf[i] == 0.0f) {
            if (wi[3 * i] != 0.0f || wi[3 * i + 1] != 0.0f || wi[3 * i + 2] != 0.0f)
                CHECK(0, "%s: item %d: no sample but wi is not (0, 0, 0)", name, i);
            continue;
        }
        ++produced;
        const float len = sqrtf(wi[3 * i] * wi[3 * i] + wi[3 * i + 1] * wi[3 * i + 1] +
                                wi[3 * i + 2] * wi[3 * i + 2]);
        unit += fabsf(len - 1.0f) < 1e-4f;
        const double rel = fabs((double)pdf_again[i] - pdf[i]) / pdf[i];
        if (rel > worst) worst = rel;
        consistent += rel <= 1e-5;
    }
    CHECK(produced > N * 9 / 10, "%s: %d of %d items produced a direction", name, produced, N);
    CHECK(unit == produced, "%s: %d of %d directions have unit length", name, unit, produced);
    CHECK(consistent == produced,
          "%s: pdf(sample) equals the sample's pdf to 1e-5 for %d of %d (worst %g)", name,
          consistent, produced, worst);
    printf("   %s: %d/%d sampled, worst relative pdf difference %.3g\n", name, produced, N,
           worst);

    /* The density integrates to 1 over the sphere (at a few views and offsets). */
    if (normalised) {
        const float views[3][2] = {{0.3f, 0.0f}, {-0.9f, 0.7f}, {1.2f, -0.4f}};
        for (int v = 0; v < 3; ++v) {
            float w[3];
            direction_from_angles(views[v][0], 1.0f, w);
            const double integral = pdf_integral(sampler, w, views[v][1]);
            CHECK(fabs(integral - 1.0) < 0.005, "%s: ∫ pdf dω = %.5f at θ_o = %g, h = %g", name,
                  integral, views[v][0], views[v][1]);
            printf("   %s: ∫ pdf dω = %.5f at θ_o = %g, h = %g\n", name, integral, views[v][0],
                   views[v][1]);
        }
    }

    /* h = NULL means h = 0. */
    float h0[8] = {0}, pdf_null[8], pdf_zero[8];
    CHECK(hairis_pdf(sampler, 8, wi, wo, NULL, pdf_null) == HAIRIS_OK &&
              hairis_pdf(sampler, 8, wi, wo, h0, pdf_zero) == HAIRIS_OK &&
              memcmp(pdf_null, pdf_zero, sizeof pdf_null) == 0,
          "%s: h = NULL is h = 0", name);
}

typedef struct thread_job {
    const hairis_sampler *sampler;
    const float *wo, *u;
    float wi[3 * 256], pdf[256];
    int status;
} thread_job;

static int sample_in_thread(void *arg)
{
    thread_job *job = (thread_job *)arg;
    job->status = hairis_sample(job->sampler, 256, job->wo, NULL, job->u, job->wi, job->pdf);
    return 0;
}

static void test_sampling(void)
{
    section("sampling");
    hairis_fiber *chiang = hairis_fiber_create("");
    hairis_fiber *marschner = hairis_fiber_create("model=marschner");

    hairis_sampler *uniform_s = hairis_sampler_create(NULL, NULL, "strategy=uniform");
    CHECK(uniform_s != NULL, "UNIFORM without fiber or tables");
    CHECK_NO_ERROR();
    hairis_sampler *analytic = hairis_sampler_create(chiang, NULL, "strategy=analytic");
    CHECK(analytic != NULL, "ANALYTIC with a Chiang fiber");
    hairis_sampler *gaussian =
        hairis_sampler_create(NULL, NULL, "strategy=gaussian;multiple_weight=0.25;n_h=2");
    CHECK(gaussian != NULL, "GAUSSIAN");
    hairis_sampler *table =
        hairis_sampler_create(NULL, g_tables, "strategy=table;multiple_weight=0.25;n_h=2");
    CHECK(table != NULL, "TABLE");
    /* With a Chiang fiber, TABLE follows the near field at h (near_field_table.h). */
    hairis_sampler *table_near =
        hairis_sampler_create(chiang, g_tables, "strategy=table;multiple_weight=0.25;n_h=2");
    CHECK(table_near != NULL, "TABLE with a Chiang fiber");
    /* The defaults: TABLE, weight 0, n_h 2 (which the tables hold). */
    char text[TEXT];
    hairis_sampler *by_default = hairis_sampler_create(chiang, g_tables, NULL);
    CHECK(by_default != NULL, "NULL options: the default TABLE sampler");
    /* A Chiang sampler's f is the fiber's near field at h (NULL: h = 0). */
    {
        enum { M = 32 };
        float wi[3 * M], wo[3 * M], h[M], zero[M], f[3 * M], g[3 * M];
        for (int i = 0; i < M; ++i) {
            random_direction(wi + 3 * i);
            random_direction(wo + 3 * i);
            h[i] = 2.0f * uniform() - 1.0f;
            zero[i] = 0.0f;
        }
        CHECK(hairis_sampler_eval(by_default, M, wi, wo, h, f) == HAIRIS_OK &&
                  hairis_fiber_eval(chiang, M, wi, wo, h, g) == HAIRIS_OK && memcmp(f, g, sizeof f) == 0,
              "a Chiang sampler's f is the fiber's at h");
        CHECK(hairis_sampler_eval(by_default, M, wi, wo, NULL, f) == HAIRIS_OK &&
                  hairis_fiber_eval(chiang, M, wi, wo, zero, g) == HAIRIS_OK && memcmp(f, g, sizeof f) == 0,
              "and at h = 0 without h");
    }

    /* A TABLE sampler stays valid after its tables handle is destroyed. */
    hairis_sampler *orphan = NULL;
    {
        hairis_fiber *fiber = hairis_fiber_create("");
        hairis_tables *t = hairis_tables_bake(fiber, TINY_BAKE, NULL, NULL);
        orphan = hairis_sampler_create(NULL, t, "multiple_weight=1;n_h=1");
        CHECK(orphan != NULL, "TABLE sampler from short-lived tables");
        hairis_tables_destroy(t);
        hairis_fiber_destroy(fiber);
    }

    /* Roughness 0, which Blender's slider allows: lobes narrower than a table cell, and TT's
       mass at grazing below the smallest double (the near-field table refused it once). */
    hairis_sampler *smooth = NULL;
    {
        hairis_fiber *fiber = hairis_fiber_create("roughness=0");
        /* The seed's Gaussians: fast, and enough for a sampler. */
        hairis_tables *t = hairis_tables_bake(fiber, TINY_BAKE ";source=gaussian", NULL, NULL);
        smooth = hairis_sampler_create(fiber, t, "multiple_weight=0;n_h=1");
        CHECK(smooth != NULL, "TABLE with a fiber of roughness 0: %s", hairis_last_error());
        hairis_tables_destroy(t);
        hairis_fiber_destroy(fiber);
    }

    if (uniform_s) check_sample_pdf_consistency(uniform_s, "uniform", 1);
    if (smooth) check_sample_pdf_consistency(smooth, "table with a fiber of roughness 0", 0);
    if (analytic) check_sample_pdf_consistency(analytic, "analytic", 1);
    if (gaussian) check_sample_pdf_consistency(gaussian, "gaussian", 1);
    if (table) check_sample_pdf_consistency(table, "table", 1);
    if (table_near) check_sample_pdf_consistency(table_near, "table with a fiber (near field)", 1);
    if (orphan) check_sample_pdf_consistency(orphan, "table (tables destroyed)", 1);
    if (by_default) check_sample_pdf_consistency(by_default, "table by default", 1);

    /* The defaults round-trip: hairis_defaults("sampler") samples as no options do. */
    {
        hairis_sampler *from_defaults =
            hairis_sampler_create(chiang, g_tables, keep(text, hairis_defaults("sampler")));
        CHECK(from_defaults != NULL, "the sampler defaults are accepted");
        enum { M = 512 };
        static float wo[3 * M], u[3 * M], h[M], wi_a[3 * M], pdf_a[M], wi_b[3 * M], pdf_b[M];
        for (int i = 0; i < M; ++i) {
            random_direction(wo + 3 * i);
            h[i] = 2.0f * uniform() - 1.0f;
            for (int k = 0; k < 3; ++k) u[3 * i + k] = uniform();
        }
        CHECK(from_defaults && by_default &&
                  hairis_sample(from_defaults, M, wo, h, u, wi_a, pdf_a) == HAIRIS_OK &&
                  hairis_sample(by_default, M, wo, h, u, wi_b, pdf_b) == HAIRIS_OK &&
                  memcmp(wi_a, wi_b, sizeof wi_a) == 0 && memcmp(pdf_a, pdf_b, sizeof pdf_a) == 0,
              "hairis_defaults(\"sampler\") and NULL options sample alike");
        /* ... and the options are read: another weight samples otherwise. */
        hairis_sampler *weighted =
            hairis_sampler_create(chiang, g_tables, "multiple_weight=0.5");
        CHECK(weighted && hairis_sample(weighted, M, wo, h, u, wi_b, pdf_b) == HAIRIS_OK &&
                  memcmp(pdf_a, pdf_b, sizeof pdf_a) != 0,
              "multiple_weight=0.5 samples another density");
        hairis_sampler_destroy(weighted);
        hairis_sampler_destroy(from_defaults);
    }

    /* The uniform density. */
    {
        float wo[3] = {0, 1, 0}, wi[3] = {0, 0, 1}, pdf = 0;
        CHECK(hairis_pdf(uniform_s, 1, wi, wo, NULL, &pdf) == HAIRIS_OK &&
                  fabsf(pdf - 0.0795774715f) < 1e-7f,
              "uniform pdf 1/(4 pi), got %g", pdf);
    }

    /* Several threads sampling with one sampler get the single-threaded result. */
    if (analytic) {
        static float wo[3 * 256], u[3 * 256], wi_ref[3 * 256], pdf_ref[256];
        for (int i = 0; i < 256; ++i) {
            random_direction(wo + 3 * i);
            for (int k = 0; k < 3; ++k) u[3 * i + k] = uniform();
        }
        hairis_sample(analytic, 256, wo, NULL, u, wi_ref, pdf_ref);
        static thread_job jobs[4];
        thrd_t threads[4];
        for (int t = 0; t < 4; ++t) {
            jobs[t].sampler = analytic;
            jobs[t].wo = wo;
            jobs[t].u = u;
            thrd_create(&threads[t], sample_in_thread, &jobs[t]);
        }
        int same = 1;
        for (int t = 0; t < 4; ++t) {
            thrd_join(threads[t], NULL);
            same = same && jobs[t].status == HAIRIS_OK &&
                   memcmp(jobs[t].wi, wi_ref, sizeof wi_ref) == 0 &&
                   memcmp(jobs[t].pdf, pdf_ref, sizeof pdf_ref) == 0;
        }
        CHECK(same, "concurrent sampling gives the single-threaded result");
    }

    /* Refusals. */
    CHECK(hairis_sampler_create(NULL, NULL, "strategy=analytic") == NULL,
          "ANALYTIC without fiber");
    CHECK_ERROR_MENTIONS("fiber");
    CHECK(hairis_sampler_create(marschner, NULL, "strategy=analytic") == NULL,
          "ANALYTIC with a Marschner fiber");
    CHECK_ERROR_MENTIONS("chiang2016");
    CHECK(hairis_sampler_create(chiang, NULL, "strategy=table") == NULL,
          "TABLE without tables");
    CHECK_ERROR_MENTIONS("tables");
    CHECK(hairis_sampler_create(chiang, NULL, NULL) == NULL, "TABLE (the default) without tables");
    CHECK_ERROR_MENTIONS("tables");
    CHECK(hairis_sampler_create(NULL, g_tables, "n_h=8") == NULL,
          "TABLE with an n_h the tables lack");
    CHECK_ERROR_MENTIONS("n_h");
    /* Tables baked for other parameters than the fiber's. */
    {
        hairis_fiber *rougher = hairis_fiber_create("roughness=0.45");
        hairis_sampler *s = hairis_sampler_create(rougher, g_tables, "strategy=table");
        CHECK(s == NULL, "TABLE with tables of another fiber");
        CHECK_ERROR_MENTIONS("baked for");
        hairis_sampler_destroy(s);
        /* (A handle call has no status: test_render checks the code, INVALID_TABLE.) */
        hairis_fiber_destroy(rougher);
    }
    CHECK(hairis_sampler_create(NULL, NULL, "strategy=gaussian;n_h=3") == NULL,
          "GAUSSIAN with n_h 3");
    CHECK_ERROR_MENTIONS("n_h");
    CHECK(hairis_sampler_create(NULL, NULL, "strategy=gaussian;multiple_weight=1.5") == NULL,
          "weight 1.5");
    CHECK_ERROR_MENTIONS("multiple_weight");
    CHECK(hairis_sampler_create(NULL, NULL, "strategy=uniform;multiple_weight=nan") == NULL,
          "weight NaN");
    CHECK_ERROR_MENTIONS("multiple_weight");
    CHECK(hairis_sampler_create(NULL, NULL, "strategy=9") == NULL, "strategy 9");
    CHECK_ERROR_MENTIONS("strategy");
    CHECK(hairis_sampler_create(NULL, NULL, "strategy=-1") == NULL, "strategy -1");
    CHECK_ERROR_MENTIONS("strategy");
    CHECK(hairis_sampler_create(NULL, NULL, "strategy=uniform;weight=0.5") == NULL,
          "an unknown name");
    CHECK_ERROR_MENTIONS("\"weight\"");

    float wo[6] = {0, 1, 0, 0, 0, 1}, u[6] = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
    float wi[6] = {-7, -7, -7, -7, -7, -7}, pdf[2] = {-7, -7};
    CHECK(hairis_sample(NULL, 2, wo, NULL, u, wi, pdf) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "NULL sampler");
    CHECK_ERROR_MENTIONS("sampler");
    CHECK(hairis_sample(uniform_s, 2, wo, NULL, NULL, wi, pdf) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "NULL u");
    CHECK_ERROR_MENTIONS("u must not be NULL");
    CHECK(hairis_sample(uniform_s, 0, NULL, NULL, NULL, NULL, NULL) == HAIRIS_OK,
          "n = 0 with NULL arrays");
    CHECK(hairis_pdf(uniform_s, 0, NULL, NULL, NULL, NULL) == HAIRIS_OK,
          "pdf: n = 0 with NULL arrays");
    u[4] = 1.0f;
    CHECK(hairis_sample(uniform_s, 2, wo, NULL, u, wi, pdf) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "u = 1 is outside [0, 1)");
    CHECK_ERROR_MENTIONS("u[4]");
    CHECK(wi[0] == -7 && pdf[0] == -7, "nothing written before the bad item was found");
    u[4] = NAN;
    CHECK(hairis_sample(uniform_s, 2, wo, NULL, u, wi, pdf) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "u NaN");
    CHECK_ERROR_MENTIONS("u[4]");
    u[4] = 0.5f;
    wo[4] = NAN;
    CHECK(hairis_sample(uniform_s, 2, wo, NULL, u, wi, pdf) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "NaN wo");
    CHECK_ERROR_MENTIONS("wo item 1");
    CHECK(wi[0] == -7 && pdf[0] == -7, "nothing written before the bad item was found");
    CHECK(hairis_pdf(uniform_s, 2, wo, wo, NULL, pdf) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "pdf: NaN wi");
    CHECK_ERROR_MENTIONS("wi item 1");
    CHECK(pdf[0] == -7, "pdf: nothing written");
    wo[4] = 0.0f;
    float bad_h[2] = {0.0f, -2.0f};
    CHECK(hairis_pdf(uniform_s, 2, wo, wo, bad_h, pdf) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "pdf: h out of range");
    CHECK_ERROR_MENTIONS("h[1]");
    CHECK(pdf[0] == -7, "pdf: nothing written");

    hairis_sampler_destroy(uniform_s);
    hairis_sampler_destroy(analytic);
    hairis_sampler_destroy(gaussian);
    hairis_sampler_destroy(table);
    hairis_sampler_destroy(table_near);
    hairis_sampler_destroy(by_default);
    hairis_sampler_destroy(orphan);
    hairis_sampler_destroy(smooth);
    hairis_sampler_destroy(NULL);
    CHECK_NO_ERROR();
    hairis_fiber_destroy(chiang);
    hairis_fiber_destroy(marschner);
}

/* ---- Scenes and rendering ----------------------------------------------------------------- */

enum { W = 16, H = 16 };

/* Camera at z = 3 looking down -Z; view_frame order: top right, bottom right, bottom left,
 * top left. */
#define CAMERA                                                                                     \
    "matrix=1,0,0,0,0,1,0,0,0,0,1,3,0,0,0,1;"                                                      \
    "frame=0.4,0.4,-1,0.4,-0.4,-1,-0.4,-0.4,-1,-0.4,0.4,-1;width=16;height=16"
#define SKY "color=0.1,0.12,0.15;strength=1"

/* Five strands along x in the plane z = 0, 4 points each. */
static int add_strands(hairis_scene *scene, int material)
{
    enum { C = 5, P = 4 };
    uint32_t first[C + 1];
    float positions[3 * C * P], radii[C * P];
    for (int c = 0; c <= C; ++c) first[c] = (uint32_t)(c * P);
    for (int c = 0; c < C; ++c)
        for (int p = 0; p < P; ++p) {
            const int i = c * P + p;
            positions[3 * i] = -1.5f + 1.0f * (float)p;
            positions[3 * i + 1] = -0.8f + 0.4f * (float)c;
            positions[3 * i + 2] = 0.05f * (float)(p % 2);
            radii[i] = 0.05f;
        }
    return hairis_scene_add_curves(scene, material, C, first, C * P, positions, radii);
}

/* A triangle at z = -0.5; the camera's top corners see past it. */
static int add_floor(hairis_scene *scene, int material)
{
    const float positions[9] = {-3, -3, -0.5f, 3, -3, -0.5f, 0, 3, -0.5f};
    const uint32_t indices[3] = {0, 1, 2};
    const int32_t materials[1] = {material};
    return hairis_scene_add_mesh(scene, 3, positions, 1, indices, materials);
}

/* A scene: hair (material 0: `fiber_options`, tables as given), a floor of `surface`
 * (material 1), `light`, `world` and `camera` (NULL: none). */
static hairis_scene *make_scene_of(const char *fiber_options, const hairis_tables *tables,
                                   const char *surface, const char *light, const char *world,
                                   const char *camera)
{
    hairis_scene *scene = hairis_scene_create();
    CHECK(scene != NULL, "scene_create");
    CHECK_NO_ERROR();
    hairis_fiber *fiber = hairis_fiber_create(fiber_options);
    CHECK(fiber != NULL, "fiber \"%s\"", fiber_options);
    const int hair = hairis_scene_add_hair_material(scene, fiber, tables);
    hairis_fiber_destroy(fiber); /* the scene keeps what it needs */
    CHECK(hair == 0, "hair material index %d", hair);
    const int diffuse = hairis_scene_add_surface_material(scene, surface);
    CHECK(diffuse == 1, "surface material index %d", diffuse);
    CHECK(add_strands(scene, hair) == HAIRIS_OK, "curves");
    CHECK(add_floor(scene, diffuse) == HAIRIS_OK, "mesh");
    if (light) CHECK(hairis_scene_add_light(scene, light) == HAIRIS_OK, "light \"%s\"", light);
    CHECK(hairis_scene_set_world(scene, world) == HAIRIS_OK, "world \"%s\"", world);
    if (camera) CHECK(hairis_scene_set_camera(scene, camera) == HAIRIS_OK, "camera \"%s\"", camera);
    CHECK_NO_ERROR();
    return scene;
}

/* The test scene: a sun and a sky over hair and a grey floor. */
static hairis_scene *make_scene(const char *fiber_options, const hairis_tables *tables)
{
    return make_scene_of(fiber_options, tables, "type=diffuse;color=0.5,0.5,0.5;emission=0,0,0",
                         "type=sun;direction=0.3,0.2,1;color=1,1,1;strength=3;angle=0.05", SKY,
                         CAMERA);
}

/* Tiny settings with `strategy` and `extra` ("" or ";name=value..."). */
static const char *tiny_settings(char *into, const char *strategy, const char *extra)
{
    snprintf(into, TEXT, "samples=4;max_bounces=3;strategy=%s%s", strategy, extra);
    return into;
}

static int pixels_ok(const float *rgba)
{
    for (int i = 0; i < W * H; ++i) {
        if (!all_finite_non_negative(rgba + 4 * i, 4)) return 0;
        if (rgba[4 * i + 3] != 1.0f) return 0;
    }
    return 1;
}

static double pixel_sum(const float *rgba, int pixels)
{
    double sum = 0;
    for (int i = 0; i < pixels; ++i) sum += rgba[4 * i] + rgba[4 * i + 1] + rgba[4 * i + 2];
    return sum;
}

/* An unsigned integer from hairis_last_render_stats(); -1 when absent. */
static double stat_of(const char *name)
{
    char value[TEXT];
    if (!option_value(hairis_last_render_stats(), name, value, sizeof value)) return -1.0;
    return strtod(value, NULL);
}

typedef struct render_job {
    hairis_scene *scene;
    char settings[TEXT];
    float rgba[W * H * 4];
    int status;
    char stats_before[TEXT];
} render_job;

static int render_in_thread(void *arg)
{
    render_job *job = (render_job *)arg;
    keep(job->stats_before, hairis_last_render_stats());
    job->status = hairis_render(job->scene, job->settings, job->rgba, NULL, NULL);
    return 0;
}

static void test_render(void)
{
    section("render");
    static float rgba[W * H * 4], again[W * H * 4];
    char s[TEXT];

    hairis_scene *scene = make_scene("", g_tables);
    const char *strategies[4] = {"uniform", "analytic", "gaussian", "table"};
    for (int k = 0; k < 4; ++k) {
        for (int i = 0; i < W * H * 4; ++i) rgba[i] = -1.0f;
        progress_state progress = {0, 0, -1.0f, 0};
        const int status =
            hairis_render(scene, tiny_settings(s, strategies[k], ";seed=7;threads=2"), rgba,
                          on_progress, &progress);
        CHECK(status == HAIRIS_OK, "render with strategy %s", strategies[k]);
        CHECK_NO_ERROR();
        CHECK(pixels_ok(rgba), "%s: pixels finite, >= 0, alpha 1", strategies[k]);
        CHECK(pixel_sum(rgba, W * H) > 0.0, "%s: the image is not black", strategies[k]);
        CHECK(progress.calls >= 1 && progress.last == 1.0f && !progress.decreasing,
              "progress ends at 1 (%d calls)", progress.calls);
        /* What the render did. */
        const char *stats = hairis_last_render_stats();
        CHECK(stat_of("camera_rays") == W * H * 4, "camera rays: \"%s\"", stats);
        CHECK(stat_of("rays") >= W * H * 4, "rays: \"%s\"", stats);
        CHECK(stat_of("shadow_rays") > 0, "shadow rays: \"%s\"", stats);
        CHECK(stat_of("seconds") > 0 && stat_of("seconds") < 600, "seconds: \"%s\"", stats);
        CHECK(stat_of("build_seconds") > 0 && stat_of("build_seconds") < stat_of("seconds"),
              "build seconds, a part of the whole: \"%s\"", stats);
        CHECK(stat_of("peak_memory_bytes") > 0 && stat_of("peak_memory_bytes") < 1e12,
              "peak memory: \"%s\"", stats);
        CHECK(stat_of("dropped_samples") == 0, "dropped: \"%s\"", stats);
        CHECK(stat_of("threads") == 2, "threads: \"%s\"", stats);
        CHECK(stat_of("cancelled") == 0, "cancelled: \"%s\"", stats);
    }

    /* A render with the last render's build settings keeps its build: only the camera is set
     * again. Its image is a fresh scene's with that camera, bit for bit; a change to the scene
     * or to the sampler builds anew. */
    {
        static float fresh[W * H * 4];
        const char *moved = "matrix=1,0,0,0.1,0,1,0,0,0,0,1,2.5,0,0,0,1;"
                            "frame=0.3,0.3,-1,0.3,-0.3,-1,-0.3,-0.3,-1,-0.3,0.3,-1;width=16;height=16";
        const char *settings = tiny_settings(s, "table", ";seed=3;threads=2");
        CHECK(hairis_render(scene, settings, rgba, NULL, NULL) == HAIRIS_OK, "first render");
        CHECK(hairis_scene_set_camera(scene, moved) == HAIRIS_OK, "move the camera");
        CHECK(hairis_render(scene, settings, rgba, NULL, NULL) == HAIRIS_OK, "render after the move");
        CHECK(stat_of("scene_reused") == 1 && stat_of("build_seconds") == 0,
              "the same settings reuse the build: \"%s\"", hairis_last_render_stats());
        hairis_scene *other = make_scene_of("", g_tables, "type=diffuse;color=0.5,0.5,0.5;emission=0,0,0",
                                            "type=sun;direction=0.3,0.2,1;color=1,1,1;strength=3;angle=0.05",
                                            SKY, moved);
        CHECK(hairis_render(other, settings, fresh, NULL, NULL) == HAIRIS_OK, "fresh scene");
        CHECK(memcmp(rgba, fresh, sizeof fresh) == 0, "the reused build renders as a fresh one");
        CHECK(hairis_scene_add_light(scene, "type=point;position=0,0,1;power=40") == HAIRIS_OK, "a light");
        CHECK(hairis_render(scene, settings, again, NULL, NULL) == HAIRIS_OK, "render after the light");
        CHECK(stat_of("scene_reused") == 0 && stat_of("geometry_reused") == 1,
              "a new light shades anew on the same BVH: \"%s\"", hairis_last_render_stats());
        CHECK(memcmp(rgba, again, sizeof again) != 0, "and the light shows");
        CHECK(hairis_render(scene, tiny_settings(s, "uniform", ";seed=3;threads=2"), again, NULL, NULL) ==
                  HAIRIS_OK, "other strategy");
        CHECK(stat_of("scene_reused") == 0 && stat_of("geometry_reused") == 1,
              "another strategy shades anew on the same BVH");
        {
            /* Another BVH quality builds another BVH over the same curves: the image is the
             * same, bit for bit, at every quality. */
            static float other_bvh[W * H * 4];
            const char *qualities[] = {"low", "high"};
            for (size_t q = 0; q < 2; ++q) {
                char with[64];
                snprintf(with, sizeof with, ";seed=3;threads=2;bvh_quality=%s", qualities[q]);
                CHECK(hairis_render(scene, tiny_settings(s, "uniform", with), other_bvh, NULL, NULL) ==
                          HAIRIS_OK, "bvh_quality=%s", qualities[q]);
                CHECK(stat_of("geometry_reused") == 0, "bvh_quality=%s builds a new BVH", qualities[q]);
                CHECK(memcmp(again, other_bvh, sizeof again) == 0,
                      "bvh_quality=%s renders the same image", qualities[q]);
            }
        }
        CHECK(hairis_render(scene, tiny_settings(s, "uniform", ";seed=3;threads=2;curve_shape=ribbons"), again,
                            NULL, NULL) == HAIRIS_OK, "other curve shape");
        CHECK(stat_of("geometry_reused") == 0, "another curve shape builds a new BVH");
        CHECK(add_strands(scene, 0) == HAIRIS_OK, "more curves");
        CHECK(hairis_render(scene, tiny_settings(s, "uniform", ";seed=3;threads=2;curve_shape=ribbons"), again,
                            NULL, NULL) == HAIRIS_OK, "render after more curves");
        CHECK(stat_of("geometry_reused") == 0, "new curves build a new BVH");
        hairis_scene_destroy(other);
        hairis_scene_destroy(scene);
        scene = make_scene("", g_tables);
    }

    /* hairis_scene_reset_shading keeps the geometry and its BVH: new materials, lights and world
     * render as a fresh scene made with them, bit for bit; materials that do not fit the
     * geometry are refused, naming what does not fit. */
    {
        static float fresh[W * H * 4];
        const char *settings = tiny_settings(s, "table", ";seed=5;threads=2");
        const char *red = "type=diffuse;color=0.8,0.2,0.1;emission=0,0,0";
        const char *lamp = "type=point;position=0,0,1;power=40";
        CHECK(hairis_render(scene, settings, rgba, NULL, NULL) == HAIRIS_OK, "render before the edit");
        CHECK(hairis_scene_reset_shading(scene) == HAIRIS_OK, "reset_shading");
        CHECK_NO_ERROR();
        hairis_fiber *fiber = hairis_fiber_create("");
        CHECK(hairis_scene_add_hair_material(scene, fiber, g_tables) == 0, "hair material again at 0");
        CHECK(hairis_scene_add_surface_material(scene, red) == 1, "another surface at 1");
        CHECK(hairis_scene_add_light(scene, lamp) == HAIRIS_OK, "another light");
        CHECK(hairis_scene_set_world(scene, SKY) == HAIRIS_OK, "world");
        CHECK(hairis_render(scene, settings, again, NULL, NULL) == HAIRIS_OK, "render after the edit");
        CHECK(stat_of("geometry_reused") == 1 && stat_of("scene_reused") == 0,
              "the edit keeps the BVH: \"%s\"", hairis_last_render_stats());
        hairis_scene *other = make_scene_of("", g_tables, red, lamp, SKY, CAMERA);
        CHECK(hairis_render(other, settings, fresh, NULL, NULL) == HAIRIS_OK, "fresh scene of the edit");
        CHECK(stat_of("geometry_reused") == 0, "a fresh scene builds its BVH");
        CHECK(memcmp(again, fresh, sizeof fresh) == 0, "the edit renders as a fresh scene");
        CHECK(memcmp(again, rgba, sizeof rgba) != 0, "and the edit shows");
        hairis_scene_destroy(other);
        CHECK(hairis_scene_reset_shading(scene) == HAIRIS_OK, "reset_shading again");
        CHECK(hairis_scene_add_hair_material(scene, fiber, g_tables) == 0, "hair at 0");
        CHECK(hairis_scene_add_hair_material(scene, fiber, g_tables) == 1, "hair at 1, where the floor's was");
        CHECK(hairis_render(scene, settings, again, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT &&
                  strstr(hairis_last_error(), "mesh 0: material 1 is a hair material") != NULL,
              "a floor on a hair material is refused: \"%s\"", hairis_last_error());
        CHECK(hairis_scene_reset_shading(NULL) == HAIRIS_ERROR_INVALID_ARGUMENT &&
                  strstr(hairis_last_error(), "scene") != NULL, "reset_shading(NULL)");
        hairis_fiber_destroy(fiber);
        hairis_scene_destroy(scene);
        scene = make_scene("", g_tables);
    }

    /* Dual scattering: with either sampler for the direct term, an image of its own (not the
     * path tracer's), the same for any thread count. */
    {
        static float path[W * H * 4];
        CHECK(hairis_render(scene, tiny_settings(s, "table", ";seed=7;threads=2"), path, NULL,
                            NULL) == HAIRIS_OK,
              "path reference");
        const char *direct[2] = {"table", "analytic"};
        for (int k = 0; k < 2; ++k) {
            CHECK(hairis_render(scene, tiny_settings(s, direct[k], ";integrator=dual_scattering;dual_exact_bounces=0;seed=7;threads=2"),
                                rgba, NULL, NULL) == HAIRIS_OK,
                  "dual scattering with strategy %s", direct[k]);
            CHECK_NO_ERROR();
            CHECK(pixels_ok(rgba), "dual %s: pixels finite, >= 0, alpha 1", direct[k]);
            CHECK(pixel_sum(rgba, W * H) > 0.0, "dual %s: the image is not black", direct[k]);
            CHECK(stat_of("shadow_rays") > 0, "dual %s: shadow rays: \"%s\"", direct[k],
                  hairis_last_render_stats());
        }
        CHECK(memcmp(rgba, path, sizeof rgba) != 0, "dual scattering is not the path tracer");
        CHECK(hairis_render(scene, tiny_settings(s, "analytic", ";integrator=dual_scattering;dual_exact_bounces=0;seed=7;threads=1"),
                            again, NULL, NULL) == HAIRIS_OK,
              "dual scattering, 1 thread");
        CHECK(memcmp(rgba, again, sizeof rgba) == 0, "dual: bit-identical with 1 and 2 threads");
        CHECK(hairis_render(scene, tiny_settings(s, "table", ";integrator=path;seed=7;threads=2"),
                            again, NULL, NULL) == HAIRIS_OK,
              "integrator=path");
        CHECK(memcmp(path, again, sizeof again) == 0, "integrator=path is the default");
        CHECK(hairis_render(scene, tiny_settings(s, "table", ";integrator=dual_scattering;dual_exact_bounces=1024;seed=7;threads=2"),
                            again, NULL, NULL) == HAIRIS_OK,
              "dual scattering with every bounce exact");
        CHECK(memcmp(path, again, sizeof again) == 0,
              "dual scattering with every bounce exact is the path tracer, bit for bit");
    }

    /* Same seed, same image, whatever the thread count or tile size; another seed differs. */
    {
        CHECK(hairis_render(scene, tiny_settings(s, "table", ";seed=7;threads=2"), rgba, NULL,
                            NULL) == HAIRIS_OK,
              "2 threads");
        const double peak_16 = stat_of("peak_memory_bytes");
        CHECK(hairis_render(scene, tiny_settings(s, "table", ";seed=7;threads=2;tile_size=1"),
                            again, NULL, NULL) == HAIRIS_OK,
              "tiles of 1 pixel");
        CHECK(memcmp(rgba, again, sizeof rgba) == 0, "bit-identical with tiles of 16 and 1");
        /* The tile size reaches the renderer: it keeps a record per tile (render.h). */
        CHECK(stat_of("peak_memory_bytes") > peak_16, "tiles of 1 need more tile records (%g > %g)",
              stat_of("peak_memory_bytes"), peak_16);
        CHECK(hairis_render(scene, tiny_settings(s, "table", ";seed=7;threads=1;tile_size=5"),
                            again, NULL, NULL) == HAIRIS_OK,
              "1 thread, tiles of 5");
        CHECK(stat_of("threads") == 1, "1 thread: \"%s\"", hairis_last_render_stats());
        CHECK(memcmp(rgba, again, sizeof rgba) == 0, "bit-identical with 1 and 2 threads");
        CHECK(hairis_render(scene, tiny_settings(s, "table", ";seed=8;threads=2"), again, NULL,
                            NULL) == HAIRIS_OK,
              "seed 8");
        CHECK(memcmp(rgba, again, sizeof rgba) != 0, "another seed, another image");
    }

    /* Two renders of one scene at once, from two threads, each as if alone; the stats are
     * per thread ("" on a thread that has not rendered). */
    {
        static render_job jobs[2];
        thrd_t threads[2];
        for (int t = 0; t < 2; ++t) {
            jobs[t].scene = scene;
            tiny_settings(jobs[t].settings, "table", ";seed=7;threads=1");
            thrd_create(&threads[t], render_in_thread, &jobs[t]);
        }
        CHECK(hairis_render(scene, tiny_settings(s, "table", ";seed=7;threads=2"), again, NULL,
                            NULL) == HAIRIS_OK,
              "reference");
        for (int t = 0; t < 2; ++t) {
            thrd_join(threads[t], NULL);
            CHECK(jobs[t].status == HAIRIS_OK && memcmp(jobs[t].rgba, again, sizeof again) == 0,
                  "concurrent render %d equals the reference", t);
            CHECK(jobs[t].stats_before[0] == '\0', "no stats before a thread's first render: \"%s\"",
                  jobs[t].stats_before);
        }
        CHECK(stat_of("threads") == 2, "this thread's stats are its own render's: \"%s\"",
              hairis_last_render_stats());
    }

    /* Cancelling from the progress callback. */
    {
        progress_state cancel = {0, 1, -1.0f, 0};
        /* Far more samples than can finish before the first callback. */
        const int status = hairis_render(
            scene, "samples=65536;max_bounces=3;strategy=analytic;threads=2", rgba, on_progress,
            &cancel);
        CHECK(status == HAIRIS_ERROR_CANCELLED, "cancelled render returns CANCELLED (%d)", status);
        CHECK_ERROR_MENTIONS("cancelled");
        CHECK(cancel.calls == 1, "no progress call after cancelling (%d)", cancel.calls);
        CHECK(stat_of("cancelled") == 1, "the stats say so: \"%s\"", hairis_last_render_stats());
        CHECK(stat_of("camera_rays") < (double)W * H * 65536, "stopped early (%g camera rays)",
              stat_of("camera_rays"));
        CHECK(all_finite_non_negative(rgba, W * H * 4), "the partial image is finite");
    }

    /* Bad settings and arguments. */
    {
        CHECK(hairis_render(scene, "samples=0;strategy=analytic", rgba, NULL, NULL) ==
                  HAIRIS_ERROR_INVALID_ARGUMENT,
              "samples 0");
        CHECK_ERROR_MENTIONS("samples");
        CHECK(hairis_render(scene, "strategy=eleven", rgba, NULL, NULL) ==
                  HAIRIS_ERROR_INVALID_ARGUMENT,
              "an unknown strategy");
        CHECK_ERROR_MENTIONS("strategy");
        CHECK_ERROR_MENTIONS("analytic");
        CHECK(hairis_render(scene, "multiple_weight=nan", rgba, NULL, NULL) ==
                  HAIRIS_ERROR_INVALID_ARGUMENT,
              "weight NaN");
        CHECK_ERROR_MENTIONS("multiple_weight");
        CHECK(hairis_render(scene, tiny_settings(s, "table", ";n_h=4"), rgba, NULL, NULL) ==
                  HAIRIS_ERROR_INVALID_TABLE,
              "TABLE with an n_h the tables lack");
        CHECK_ERROR_MENTIONS("material 0");
        CHECK_ERROR_MENTIONS("n_h");
        CHECK(hairis_render(scene, tiny_settings(s, "gaussian", ";n_h=3"), rgba, NULL, NULL) ==
                  HAIRIS_ERROR_INVALID_ARGUMENT,
              "GAUSSIAN with n_h 3");
        CHECK_ERROR_MENTIONS("n_h");
        const char *bad[][2] = {{"max_bounces=-1", "max_bounces"},
                                {"max_bounces=1025", "max_bounces"},
                                {"max_diffuse_bounces=-1", "max_diffuse_bounces"},
                                {"max_transmission_bounces=2000", "max_transmission_bounces"},
                                {"tile_size=0", "tile_size"},
                                {"tile_size=4097", "tile_size"},
                                {"threads=-1", "threads"},
                                {"rr_start_bounce=0", "rr_start_bounce"},
                                {"dual_exact_bounces=-1", "dual_exact_bounces"},
                                {"dual_exact_bounces=1025", "dual_exact_bounces"},
                                {"dual_bounce_limit=max_bounces", "dual_bounce_limit"},
                                {"samples=16777217", "samples"},
                                {"film_transparent=maybe", "film_transparent"},
                                {"curve_backfaces=yes", "curve_backfaces"}};
        for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
            for (int k = 0; k < W * H * 4; ++k) rgba[k] = -7.0f;
            CHECK(hairis_render(scene, bad[i][0], rgba, NULL, NULL) ==
                      HAIRIS_ERROR_INVALID_ARGUMENT,
                  "%s refused", bad[i][0]);
            CHECK_ERROR_MENTIONS(bad[i][1]);
            CHECK(rgba[0] == -7.0f && rgba[W * H * 4 - 1] == -7.0f, "%s: nothing written",
                  bad[i][0]);
        }
        CHECK(hairis_render(NULL, "strategy=analytic", rgba, NULL, NULL) ==
                  HAIRIS_ERROR_INVALID_ARGUMENT,
              "NULL scene");
        CHECK_ERROR_MENTIONS("scene");
        CHECK(hairis_render(scene, "strategy=analytic", NULL, NULL, NULL) ==
                  HAIRIS_ERROR_INVALID_ARGUMENT,
              "NULL rgba");
        CHECK_ERROR_MENTIONS("rgba");
    }

    /* NULL settings, "" and hairis_defaults("render") are one render (64 samples, TABLE). */
    {
        static float by_default[W * H * 4];
        char defaults[TEXT];
        keep(defaults, hairis_defaults("render"));
        CHECK(hairis_render(scene, NULL, rgba, NULL, NULL) == HAIRIS_OK, "NULL settings");
        CHECK(stat_of("camera_rays") == W * H * 64, "64 samples by default: \"%s\"",
              hairis_last_render_stats());
        CHECK(hairis_render(scene, "", again, NULL, NULL) == HAIRIS_OK, "\"\" settings");
        CHECK(memcmp(rgba, again, sizeof rgba) == 0, "NULL and \"\" render alike");
        CHECK(hairis_render(scene, defaults, by_default, NULL, NULL) == HAIRIS_OK,
              "the defaults are accepted");
        CHECK(memcmp(rgba, by_default, sizeof rgba) == 0,
              "hairis_defaults(\"render\") renders as no settings do");
        char changed[TEXT];
        CHECK(hairis_render(scene, with_option(changed, defaults, "seed", "1"), again, NULL,
                            NULL) == HAIRIS_OK &&
                  memcmp(rgba, again, sizeof rgba) != 0,
              "and the defaults string is read: seed=1 changes the image");
    }
    hairis_scene_destroy(scene);

    /* TABLE with a material that has no tables. */
    {
        hairis_scene *no_tables = make_scene("", NULL);
        CHECK(hairis_render(no_tables, tiny_settings(s, "table", ""), rgba, NULL, NULL) ==
                  HAIRIS_ERROR_INVALID_TABLE,
              "TABLE without tables is refused");
        CHECK_ERROR_MENTIONS("material 0");
        CHECK_ERROR_MENTIONS("without tables");
        CHECK(hairis_render(no_tables, tiny_settings(s, "analytic", ""), rgba, NULL, NULL) ==
                  HAIRIS_OK,
              "ANALYTIC needs no tables");
        CHECK(hairis_render(no_tables, tiny_settings(s, "analytic", ";integrator=dual_scattering"), rgba,
                            NULL, NULL) == HAIRIS_ERROR_INVALID_TABLE,
              "dual scattering without tables is refused, whatever the strategy");
        CHECK_ERROR_MENTIONS("material 0");
        CHECK_ERROR_MENTIONS("integrator=dual_scattering");
        CHECK_ERROR_MENTIONS("without tables");
        hairis_scene_destroy(no_tables);
    }

    /* TABLE with tables baked for other parameters. */
    {
        hairis_scene *mismatch = make_scene("roughness=0.5", g_tables);
        CHECK(hairis_render(mismatch, tiny_settings(s, "table", ""), rgba, NULL, NULL) ==
                  HAIRIS_ERROR_INVALID_TABLE,
              "TABLE with mismatched tables is refused");
        CHECK_ERROR_MENTIONS("material 0");
        CHECK_ERROR_MENTIONS("baked for");
        CHECK(hairis_render(mismatch, tiny_settings(s, "uniform", ""), rgba, NULL, NULL) ==
                  HAIRIS_OK,
              "UNIFORM ignores the tables");
        CHECK(hairis_render(mismatch, tiny_settings(s, "uniform", ";integrator=dual_scattering"), rgba,
                            NULL, NULL) == HAIRIS_ERROR_INVALID_TABLE,
              "dual scattering with mismatched tables is refused");
        CHECK_ERROR_MENTIONS("material 0");
        CHECK_ERROR_MENTIONS("baked for");
        hairis_scene_destroy(mismatch);
    }

    /* A scene without camera, an empty scene. */
    {
        hairis_scene *empty = hairis_scene_create();
        CHECK(hairis_render(empty, tiny_settings(s, "analytic", ""), rgba, NULL, NULL) ==
                  HAIRIS_ERROR_INVALID_ARGUMENT,
              "no camera");
        CHECK_ERROR_MENTIONS("camera");
        CHECK(hairis_scene_set_camera(empty, CAMERA) == HAIRIS_OK, "camera");
        CHECK(hairis_scene_set_world(empty, "color=1,1,1") == HAIRIS_OK, "world");
        /* No geometry is legal, as in Cycles: every ray misses and every pixel is the world. */
        CHECK(hairis_render(empty, tiny_settings(s, "analytic", ""), rgba, NULL, NULL) == HAIRIS_OK,
              "empty scene: %s", hairis_last_error());
        int world_pixels = 0;
        for (int i = 0; i < W * H; ++i)
            world_pixels += fabsf(rgba[4 * i] - 1.0f) < 1e-6f && fabsf(rgba[4 * i + 1] - 1.0f) < 1e-6f &&
                            fabsf(rgba[4 * i + 2] - 1.0f) < 1e-6f && rgba[4 * i + 3] == 1.0f;
        CHECK(world_pixels == W * H, "empty scene: %d of %d pixels are the world", world_pixels, W * H);
        hairis_scene_destroy(empty);
    }

    /* Point and area lights, an emissive triangle, an orthographic camera. */
    {
        hairis_scene *lit = make_scene_of("", NULL, "color=0.7,0.6,0.5", NULL, "", NULL);
        const int lamp = hairis_scene_add_surface_material(lit, "color=0,0,0;emission=2,2,2");
        CHECK(lamp == 2, "material index %d", lamp);
        const float lamp_positions[9] = {-1, -1, 2, 1, -1, 2, 0, 1, 2};
        const uint32_t lamp_indices[3] = {0, 2, 1};
        const int32_t lamp_materials[1] = {lamp};
        CHECK(hairis_scene_add_mesh(lit, 3, lamp_positions, 1, lamp_indices, lamp_materials) ==
                  HAIRIS_OK,
              "emissive triangle");
        CHECK(hairis_scene_add_light(lit, "type=point;position=1,1,2;color=1,0.9,0.8;power=50;"
                                          "radius=0.1") == HAIRIS_OK,
              "point light");
        CHECK(hairis_scene_add_light(lit, "type=point;position=1,1,2;color=1,0.9,0.8;power=20") ==
                  HAIRIS_OK,
              "point light of radius 0");
        const char *shapes[4] = {"square", "rectangle", "disk", "ellipse"};
        for (int k = 0; k < 4; ++k) {
            char light[TEXT];
            snprintf(light, sizeof light,
                     "type=area;matrix=1,0,0,-1,0,1,0,0,0,0,1,2.5,0,0,0,1;shape=%s;size=0.5;"
                     "size_y=0.3;color=1,0.9,0.8;power=30",
                     shapes[k]);
            CHECK(hairis_scene_add_light(lit, light) == HAIRIS_OK, "area light %s", shapes[k]);
        }
        CHECK(hairis_scene_set_camera(lit, "matrix=1,0,0,0,0,1,0,0,0,0,1,3,0,0,0,1;orthographic=1;"
                                           "frame=1.2,1.2,-1,1.2,-1.2,-1,-1.2,-1.2,-1,-1.2,1.2,-1;"
                                           "width=16;height=16") == HAIRIS_OK,
              "orthographic camera");
        CHECK(hairis_render(lit, tiny_settings(s, "analytic", ""), rgba, NULL, NULL) == HAIRIS_OK,
              "lit render");
        CHECK(pixels_ok(rgba) && pixel_sum(rgba, W * H) > 0.0,
              "lit pixels finite, >= 0, not black");
        hairis_scene_destroy(lit);
    }
}

/* ---- Render settings and camera options the first C API lacked ---------------------------- */

/* ---- Huang fibers and oriented curves ------------------------------------------------------ */

/* Curves along x with a normal per point (or none), added to `scene` as material `material`. */
static int add_oriented_strands(hairis_scene *scene, int material, const float *normal,
                                const char *options)
{
    enum { C = 5, P = 4 };
    uint32_t first[C + 1];
    float positions[3 * C * P], radii[C * P], normals[3 * C * P];
    for (int c = 0; c <= C; ++c) first[c] = (uint32_t)(c * P);
    for (int c = 0; c < C; ++c)
        for (int p = 0; p < P; ++p) {
            const int i = c * P + p;
            positions[3 * i] = -1.5f + 1.0f * (float)p;
            positions[3 * i + 1] = -0.8f + 0.4f * (float)c;
            positions[3 * i + 2] = 0.0f;
            radii[i] = 0.12f;
            for (int k = 0; k < 3; ++k) normals[3 * i + k] = normal ? normal[k] : 0.0f;
        }
    return hairis_scene_add_curves_with_normals(scene, material, C, first, C * P, positions, radii,
                                                normals, options);
}

static void test_huang(void)
{
    section("huang");
    hairis_fiber *huang = hairis_fiber_create("model=huang;aspect_ratio=0.5;transmission=0.5");
    CHECK(huang != NULL, "a Huang fiber: %s", hairis_last_error());
    CHECK(huang && strcmp(hairis_fiber_model(huang), "huang2022") == 0, "model \"%s\"",
          huang ? hairis_fiber_model(huang) : "");
    CHECK(huang && strstr(hairis_fiber_parameters(huang), "aspect_ratio=0.5;") != NULL &&
              strstr(hairis_fiber_parameters(huang), "transmission=0.5;") != NULL,
          "its parameters: \"%s\"", huang ? hairis_fiber_parameters(huang) : "");
    /* Aspect ratios above 1 are rendered as their inverse: the same scattering. */
    hairis_fiber *inverted = hairis_fiber_create("model=huang;aspect_ratio=2;transmission=0.5");
    CHECK(inverted != NULL, "aspect_ratio=2 accepted");

    /* Refusals name the input and Cycles' rule. */
    expect_fiber_refused("model=huang;aspect_ratio=0", "aspect_ratio");
    expect_fiber_refused("model=huang;aspect_ratio=-1", "aspect_ratio");
    expect_fiber_refused("model=huang;reflection=0;transmission=0;secondary_reflection=-1", "no closure");
    expect_fiber_refused("model=huang;reflection=nan", "reflection");
    expect_fiber_refused("model=huang;ior=0.8", "ior");

    /* The far field: finite, non-negative, and the same for aspect 2 as for 1/2. */
    enum { N = 64 };
    float wi[3 * N], wo[3 * N], f[3 * N], g[3 * N];
    for (int i = 0; i < N; ++i) {
        random_direction(wi + 3 * i);
        random_direction(wo + 3 * i);
    }
    CHECK(hairis_fiber_eval(huang, N, wi, wo, NULL, f) == HAIRIS_OK, "eval: %s", hairis_last_error());
    CHECK(all_finite_non_negative(f, 3 * N), "Huang's f is finite and >= 0");
    CHECK(hairis_fiber_eval(inverted, N, wi, wo, NULL, g) == HAIRIS_OK && memcmp(f, g, sizeof f) == 0,
          "aspect 2 evaluates as 1/2");
    double sum = 0;
    for (int i = 0; i < 3 * N; ++i) sum += f[i];
    CHECK(sum > 0.0, "and not all zero");
    const float h[N] = {0};
    CHECK(hairis_fiber_eval(huang, N, wi, wo, h, f) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "no near field by h for Huang");
    CHECK_ERROR_MENTIONS("huang2022");
    /* Its tables are its Huang table: baked, described, matched, written and loaded. */
    const char *small = "huang_theta_o=8;huang_phi_o=3;huang_theta_i=16;huang_phi=24;threads=2";
    hairis_tables *huang_tables = hairis_tables_bake(huang, small, NULL, NULL);
    CHECK(huang_tables != NULL, "Huang tables bake: %s", hairis_last_error());
    CHECK(huang_tables && strcmp(hairis_tables_model(huang_tables), "huang2022") == 0, "model huang2022");
    CHECK(huang_tables && strcmp(hairis_tables_info(huang_tables),
                                 "source=exact;huang_theta_o=8;huang_phi_o=3;huang_theta_i=16;huang_phi=24;"
                                 "huang_f=1;huang_f_refinement=1;huang_absorption=0;theta_r=31;theta_i=64;"
                                 "n_h=1,2,4,8,16") == 0,
          "info \"%s\" (with the multiple part)", huang_tables ? hairis_tables_info(huang_tables) : "");
    char table_only_options[TEXT];
    snprintf(table_only_options, TEXT, "%s;huang_multiple=0", small);
    hairis_tables *table_only = hairis_tables_bake(huang, table_only_options, NULL, NULL);
    CHECK(table_only && strcmp(hairis_tables_info(table_only),
                               "source=exact;huang_theta_o=8;huang_phi_o=3;huang_theta_i=16;huang_phi=24;huang_f=1;"
                               "huang_f_refinement=1;huang_absorption=0") == 0,
          "huang_multiple=0: the Huang table alone, \"%s\"", table_only ? hairis_tables_info(table_only) : "");
    /* A refined f part says so, also after a round trip through a file; 5 is out of range. */
    char refined_options[TEXT];
    snprintf(refined_options, TEXT, "%s;huang_multiple=0;huang_f_refinement=2", small);
    hairis_tables *refined = hairis_tables_bake(huang, refined_options, NULL, NULL);
    CHECK(refined && strstr(hairis_tables_info(refined), "huang_f_refinement=2") != NULL,
          "huang_f_refinement=2: \"%s\"", refined ? hairis_tables_info(refined) : hairis_last_error());
    const char *temp_dir = getenv("TMPDIR");
    char refined_path[TEXT];
    snprintf(refined_path, TEXT, "%s/hairis_capi_refined_%ld.exr", temp_dir && *temp_dir ? temp_dir : "/tmp",
             (long)getpid());
    CHECK(refined && hairis_tables_write(refined, refined_path) == HAIRIS_OK, "write refined: %s", hairis_last_error());
    hairis_tables *refined_loaded = hairis_tables_load_file(refined_path);
    CHECK(refined_loaded && strstr(hairis_tables_info(refined_loaded), "huang_f_refinement=2") != NULL,
          "the refinement survives the file: \"%s\"",
          refined_loaded ? hairis_tables_info(refined_loaded) : hairis_last_error());
    hairis_tables_destroy(refined_loaded);
    hairis_tables_destroy(refined);
    remove(refined_path);
    expect_bake_refused(huang, "huang_f_refinement=5", "huang_f_refinement");
    char no_f_options[TEXT];
    snprintf(no_f_options, TEXT, "%s;huang_multiple=0;huang_f=0", small);
    hairis_tables *no_f = hairis_tables_bake(huang, no_f_options, NULL, NULL);
    CHECK(no_f && strstr(hairis_tables_info(no_f), "huang_f=0") != NULL, "huang_f=0: no baked f, \"%s\"",
          no_f ? hairis_tables_info(no_f) : "");
    hairis_tables_destroy(no_f);
    CHECK(hairis_tables_match_fiber(huang_tables, huang) == 1, "they match their fiber");
    hairis_fiber *rounder = hairis_fiber_create("model=huang;aspect_ratio=0.6;transmission=0.5");
    hairis_fiber *dimmer = hairis_fiber_create("model=huang;aspect_ratio=0.5;transmission=0.4");
    CHECK(hairis_tables_match_fiber(huang_tables, rounder) == 0 && hairis_tables_match_fiber(huang_tables, dimmer) == 0,
          "not another aspect ratio or lobe multiplier");
    CHECK(hairis_tables_bake(huang, "huang_phi=0", NULL, NULL) == NULL, "huang_phi=0 refused");
    CHECK_ERROR_MENTIONS("huang_phi");
    CHECK(hairis_tables_bake(huang, "source=gaussian", NULL, NULL) == NULL, "gaussian refused for Huang");
    CHECK_ERROR_MENTIONS("huang2022");
    CHECK(hairis_tables_bake(huang, small, cancel_at_once, NULL) == NULL &&
              strcmp(hairis_last_error(), "cancelled") == 0,
          "a Huang bake cancels");
    /* The sampler API samples a Huang fiber from its table, the density it reports. */
    hairis_sampler *huang_sampler = hairis_sampler_create(huang, huang_tables, "strategy=table");
    CHECK(huang_sampler != NULL, "the sampler API samples a Huang fiber from its table");
    CHECK_NO_ERROR();
    if (huang_sampler) check_sample_pdf_consistency(huang_sampler, "huang table", 1);
    hairis_sampler_destroy(huang_sampler);
    CHECK(hairis_sampler_create(huang, NULL, "strategy=table") == NULL, "a Huang table sampler needs tables");
    CHECK_ERROR_MENTIONS("tables");
    /* Its f is the tables' baked f: deterministic and close to the fiber's expectation. */
    huang_sampler = hairis_sampler_create(huang, huang_tables, "strategy=table");
    {
        float baked[3 * N], again[3 * N];
        CHECK(hairis_fiber_eval(huang, N, wi, wo, NULL, f) == HAIRIS_OK, "eval: %s", hairis_last_error());
        CHECK(hairis_sampler_eval(huang_sampler, N, wi, wo, NULL, baked) == HAIRIS_OK, "sampler eval: %s",
              hairis_last_error());
        CHECK(hairis_sampler_eval(huang_sampler, N, wi, wo, NULL, again) == HAIRIS_OK &&
                  memcmp(baked, again, sizeof baked) == 0,
              "the baked f is deterministic");
        double l1 = 0, total = 0, baked_total = 0;
        for (int i = 0; i < 3 * N; ++i) {
            l1 += fabs((double)baked[i] - f[i]);
            total += f[i];
            baked_total += baked[i];
        }
        printf("   huang baked f against the expectation: L1 %.3f, sums %.4f vs %.4f\n", l1 / total, baked_total,
               total);
        CHECK(l1 < 0.35 * total && fabs(baked_total / total - 1.0) < 0.1,
              "the baked f is near the expectation (L1 %.3f, sums %.4f vs %.4f)", l1 / total, baked_total, total);
    }
    hairis_sampler_destroy(huang_sampler);
    /* R alone is analytic in the baked f: equal to the fiber's eval pair by pair, so a
     * swapped wi and wo (R is not symmetric in them for an elliptic fiber) shows. */
    {
        hairis_fiber *r_only = hairis_fiber_create("model=huang;transmission=0;secondary_reflection=0");
        hairis_tables *r_tables = hairis_tables_bake(r_only, small, NULL, NULL);
        hairis_sampler *r_sampler = hairis_sampler_create(r_only, r_tables, "strategy=table");
        float baked[3 * N], swapped[3 * N];
        CHECK(r_sampler != NULL, "an R-only Huang sampler: %s", hairis_last_error());
        CHECK(hairis_fiber_eval(r_only, N, wi, wo, NULL, f) == HAIRIS_OK, "R-only eval");
        CHECK(hairis_sampler_eval(r_sampler, N, wi, wo, NULL, baked) == HAIRIS_OK, "R-only sampler eval");
        CHECK(hairis_sampler_eval(r_sampler, N, wo, wi, NULL, swapped) == HAIRIS_OK, "R-only sampler eval, swapped");
        int same = 0, swapped_same = 0;
        for (int i = 0; i < 3 * N; ++i) {
            same += fabsf(baked[i] - f[i]) <= 1e-5f * (f[i] + 1e-6f) + 1e-7f;
            swapped_same += fabsf(swapped[i] - f[i]) <= 1e-5f * (f[i] + 1e-6f) + 1e-7f;
        }
        CHECK(same == 3 * N, "R-only: the baked f equals the fiber's R for %d of %d values", same, 3 * N);
        CHECK(swapped_same < 3 * N, "R-only: a swapped wi and wo differs (%d of %d equal)", swapped_same, 3 * N);
        hairis_sampler_destroy(r_sampler);
        hairis_tables_destroy(r_tables);
        hairis_fiber_destroy(r_only);
    }
    {
        hairis_sampler *uniform = hairis_sampler_create(NULL, NULL, "strategy=uniform");
        CHECK(hairis_sampler_eval(uniform, N, wi, wo, NULL, f) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "a sampler without a fiber has no f");
        CHECK_ERROR_MENTIONS("without a fiber");
        hairis_sampler_destroy(uniform);
    }

    /* A scene of Huang hair: renders with uniform (and gaussian), refuses analytic and table
     * naming the material. */
    static float rgba[W * H * 4];
    char s[TEXT];
    hairis_scene *scene = hairis_scene_create();
    const int hair = hairis_scene_add_hair_material(scene, huang, NULL);
    CHECK(hair == 0, "Huang hair material: %s", hairis_last_error());
    const float up[3] = {0, 0, 1};
    CHECK(add_oriented_strands(scene, hair, up, "") == HAIRIS_OK, "curves with normals: %s",
          hairis_last_error());
    CHECK(add_oriented_strands(scene, hair, NULL, NULL) == HAIRIS_OK, "zero normals, NULL options");
    CHECK(hairis_scene_add_light(scene, "type=sun;direction=0.3,0.2,1;strength=3") == HAIRIS_OK, "sun");
    CHECK(hairis_scene_set_world(scene, SKY) == HAIRIS_OK && hairis_scene_set_camera(scene, CAMERA) == HAIRIS_OK,
          "world and camera");
    CHECK(hairis_render(scene, tiny_settings(s, "uniform", ";max_transparent_bounces=3"), rgba, NULL, NULL) ==
              HAIRIS_OK,
          "uniform renders Huang: %s", hairis_last_error());
    CHECK(pixels_ok(rgba) && pixel_sum(rgba, W * H) > 0.0, "a finite, non-black image");
    CHECK(hairis_render(scene, tiny_settings(s, "gaussian", ""), rgba, NULL, NULL) == HAIRIS_OK,
          "gaussian renders Huang");
    CHECK(hairis_render(scene, tiny_settings(s, "analytic", ""), rgba, NULL, NULL) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "analytic refused for Huang");
    CHECK_ERROR_MENTIONS("material 0");
    CHECK_ERROR_MENTIONS("uniform");
    CHECK(hairis_render(scene, tiny_settings(s, "table", ""), rgba, NULL, NULL) == HAIRIS_ERROR_INVALID_TABLE,
          "table refused for Huang without tables");
    CHECK_ERROR_MENTIONS("material 0");
    CHECK_ERROR_MENTIONS("without tables");
    CHECK(hairis_render(scene, tiny_settings(s, "table", ";huang_sampling=cycles"), rgba, NULL, NULL) == HAIRIS_OK,
          "Cycles' own Huang sampling needs no tables");

    /* With its Huang table, TABLE renders Huang hair, converging to what UNIFORM converges to:
     * the image means over independent seeds agree within 4 standard errors. */
    hairis_scene *tabled = hairis_scene_create();
    CHECK(hairis_scene_add_hair_material(tabled, huang, huang_tables) == 0, "Huang material with tables");
    CHECK(add_oriented_strands(tabled, 0, up, "") == HAIRIS_OK, "its curves");
    CHECK(hairis_scene_add_light(tabled, "type=sun;direction=0.3,0.2,1;strength=3") == HAIRIS_OK &&
              hairis_scene_set_world(tabled, SKY) == HAIRIS_OK && hairis_scene_set_camera(tabled, CAMERA) == HAIRIS_OK,
          "sun, world and camera");
    enum { SEEDS = 8 };
    double mean[2] = {0, 0}, square[2] = {0, 0};
    const char *const compared[2] = {"table", "uniform"};
    for (int k = 0; k < 2; ++k)
        for (int seed = 1; seed <= SEEDS; ++seed) {
            snprintf(s, TEXT, "samples=16;max_bounces=3;max_transparent_bounces=3;threads=2;seed=%d;strategy=%s", seed,
                     compared[k]);
            CHECK(hairis_render(tabled, s, rgba, NULL, NULL) == HAIRIS_OK, "%s renders Huang with its table: %s",
                  compared[k], hairis_last_error());
            CHECK(pixels_ok(rgba), "%s: a finite image", compared[k]);
            const double m = pixel_sum(rgba, W * H) / (3.0 * W * H);
            mean[k] += m / SEEDS;
            square[k] += m * m / SEEDS;
        }
    double error2 = 0;
    for (int k = 0; k < 2; ++k) error2 += (square[k] - mean[k] * mean[k]) / (SEEDS - 1);
    printf("   Huang TABLE vs UNIFORM image means over %d seeds: %g vs %g (standard error of the difference %g)\n",
           SEEDS, mean[0], mean[1], sqrt(error2));
    CHECK(mean[0] > 0.0 && fabs(mean[0] - mean[1]) <= 4.0 * sqrt(error2),
          "TABLE and UNIFORM agree in the mean: %g and %g (standard error of the difference %g)", mean[0], mean[1],
          sqrt(error2));
    /* Dual scattering renders Huang hair with the tables' multiple part, sampling the vertex
     * that closes the path with the Huang table whatever huang_sampling says (its MIS needs the
     * sampler's density); tables
     * without the multiple part are refused naming the material and what to do. */
    static float dual[W * H * 4], path[W * H * 4];
    CHECK(hairis_render(tabled, tiny_settings(s, "table", ";integrator=dual_scattering;dual_exact_bounces=0;seed=3"), dual, NULL, NULL) ==
              HAIRIS_OK,
          "dual scattering renders Huang: %s", hairis_last_error());
    CHECK(pixels_ok(dual) && pixel_sum(dual, W * H) > 0.0, "dual Huang: a finite, non-black image");
    CHECK(hairis_render(tabled, tiny_settings(s, "table", ";integrator=dual_scattering;dual_exact_bounces=0;seed=3;huang_sampling=cycles"),
                        rgba, NULL, NULL) == HAIRIS_OK,
          "dual scattering with huang_sampling=cycles: %s", hairis_last_error());
    CHECK(memcmp(rgba, dual, sizeof rgba) == 0, "dual scattering samples Huang with its table either way");
    CHECK(hairis_render(tabled, tiny_settings(s, "table", ";seed=3"), path, NULL, NULL) == HAIRIS_OK,
          "path tracing the same scene");
    CHECK(memcmp(path, dual, sizeof path) != 0, "dual scattering is not the path tracer for Huang");
    /* Its exact bounces are path-traced as huang_sampling says: with every bounce exact, the
     * path tracer's image bit for bit under either sampler. */
    static float exact[W * H * 4];
    const char *samplings[2] = {"strategy", "cycles"};
    for (int k = 0; k < 2; ++k) {
        char extra[128];
        snprintf(extra, sizeof extra, ";seed=3;huang_sampling=%s", samplings[k]);
        CHECK(hairis_render(tabled, tiny_settings(s, "table", extra), path, NULL, NULL) == HAIRIS_OK,
              "path tracing Huang with huang_sampling=%s", samplings[k]);
        snprintf(extra, sizeof extra, ";integrator=dual_scattering;dual_exact_bounces=1024;seed=3;huang_sampling=%s",
                 samplings[k]);
        CHECK(hairis_render(tabled, tiny_settings(s, "table", extra), exact, NULL, NULL) == HAIRIS_OK,
              "dual scattering with every bounce exact, huang_sampling=%s", samplings[k]);
        CHECK(memcmp(path, exact, sizeof path) == 0,
              "dual scattering with every bounce exact is the path tracer for Huang, huang_sampling=%s", samplings[k]);
    }
    CHECK(hairis_render(tabled, tiny_settings(s, "analytic", ";integrator=dual_scattering;huang_sampling=cycles"),
                        rgba, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "dual scattering with analytic is refused for Huang, whatever huang_sampling says");
    CHECK_ERROR_MENTIONS("strategy=analytic");
    hairis_scene_destroy(tabled);
    hairis_scene *old = hairis_scene_create();
    CHECK(hairis_scene_add_hair_material(old, huang, table_only) == 0, "Huang material with the table alone");
    CHECK(add_oriented_strands(old, 0, up, "") == HAIRIS_OK && hairis_scene_set_camera(old, CAMERA) == HAIRIS_OK &&
              hairis_scene_set_world(old, SKY) == HAIRIS_OK,
          "its curves, camera and world");
    CHECK(hairis_render(old, tiny_settings(s, "table", ""), rgba, NULL, NULL) == HAIRIS_OK,
          "the table alone path-traces: %s", hairis_last_error());
    CHECK(hairis_render(old, tiny_settings(s, "table", ";integrator=dual_scattering"), rgba, NULL, NULL) ==
              HAIRIS_ERROR_INVALID_TABLE,
          "dual scattering without the multiple part is refused");
    CHECK_ERROR_MENTIONS("material 0");
    CHECK_ERROR_MENTIONS("no multiple-scattering part");
    CHECK_ERROR_MENTIONS("bake them again");
    hairis_scene_destroy(old);
    hairis_tables_destroy(table_only);

    /* Tables of other parameters, or of another model, are refused naming the material. */
    hairis_fiber *chiang = hairis_fiber_create("");
    hairis_tables *chiang_tables = hairis_tables_bake(chiang, "theta_r=2;theta_i=4;phi=4;n_h=2", NULL, NULL);
    CHECK(chiang_tables != NULL, "Chiang tables: %s", hairis_last_error());
    struct {
        const hairis_fiber *fiber;
        const hairis_tables *tables;
        const char *what;
    } stale[3] = {{rounder, huang_tables, "aspect_ratio=0.6"}, {dimmer, huang_tables, "transmission=0.4"},
                  {huang, chiang_tables, "chiang2016"}};
    for (int k = 0; k < 3; ++k) {
        hairis_scene *other = hairis_scene_create();
        hairis_scene_add_hair_material(other, stale[k].fiber, stale[k].tables);
        add_oriented_strands(other, 0, up, "");
        hairis_scene_set_camera(other, CAMERA);
        CHECK(hairis_render(other, tiny_settings(s, "table", ""), rgba, NULL, NULL) == HAIRIS_ERROR_INVALID_TABLE,
              "stale tables refused (%s)", stale[k].what);
        CHECK_ERROR_MENTIONS("material 0");
        CHECK_ERROR_MENTIONS(stale[k].what);
        hairis_scene_destroy(other);
    }
    hairis_tables_destroy(chiang_tables);
    hairis_fiber_destroy(chiang);
    CHECK(hairis_render(scene, tiny_settings(s, "uniform", ";max_transparent_bounces=-1"), rgba, NULL, NULL) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "max_transparent_bounces -1 refused");
    CHECK_ERROR_MENTIONS("max_transparent_bounces");

    /* Curves with normals: the normals are checked like positions; options are refused by name. */
    CHECK(add_oriented_strands(scene, hair, up, "twist=1") == HAIRIS_ERROR_INVALID_ARGUMENT,
          "unknown curve option");
    CHECK_ERROR_MENTIONS("\"twist\"");
    const float bad[3] = {0, NAN, 1};
    CHECK(add_oriented_strands(scene, hair, bad, "") == HAIRIS_ERROR_INVALID_ARGUMENT, "NaN normal");
    CHECK_ERROR_MENTIONS("normals[1]");
    const uint32_t first[2] = {0, 2};
    const float p[6] = {0, 0, 0, 1, 0, 0}, r[2] = {0.1f, 0.1f};
    CHECK(hairis_scene_add_curves_with_normals(scene, hair, 1, first, 2, p, r, NULL, "") ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "NULL normals");
    CHECK_ERROR_MENTIONS("normals");
    CHECK(hairis_scene_add_curves_with_normals(scene, 5, 1, first, 2, p, r, p, "") ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "an unknown material");
    CHECK_ERROR_MENTIONS("material");
    CHECK(hairis_scene_add_curves_with_normals(NULL, 0, 1, first, 2, p, r, p, "") ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "NULL scene");
    hairis_scene_destroy(scene);
    hairis_tables_destroy(huang_tables);
    hairis_fiber_destroy(huang);
    hairis_fiber_destroy(inverted);
    hairis_fiber_destroy(rounder);
    hairis_fiber_destroy(dimmer);
}

static void test_render_options(void)
{
    section("render options");
    static float full[W * H * 4], image[W * H * 4], direct[W * H * 4];
    char s[TEXT];
    const char *base = "samples=4;max_bounces=3;strategy=analytic;seed=5;threads=2";
    hairis_scene *scene = make_scene("", NULL);

    /* Bounce limits per kind count like max_bounces: with both at 0 every path ends after its
     * first continuation, which is what max_bounces=0 (direct light only) does. */
    CHECK(hairis_render(scene, base, full, NULL, NULL) == HAIRIS_OK, "all bounces");
    snprintf(s, sizeof s, "%s", "samples=4;max_bounces=0;strategy=analytic;seed=5;threads=2");
    CHECK(hairis_render(scene, s, direct, NULL, NULL) == HAIRIS_OK, "max_bounces=0");
    CHECK(memcmp(full, direct, sizeof full) != 0 && pixel_sum(direct, W * H) < pixel_sum(full, W * H),
          "direct light alone is less light (%g < %g)", pixel_sum(direct, W * H),
          pixel_sum(full, W * H));
    snprintf(s, sizeof s, "%s;max_diffuse_bounces=0;max_transmission_bounces=0", base);
    CHECK(hairis_render(scene, s, image, NULL, NULL) == HAIRIS_OK, "both limits 0");
    CHECK(memcmp(image, direct, sizeof image) == 0,
          "max_diffuse_bounces=0 and max_transmission_bounces=0 render as max_bounces=0");
    const char *limits[2] = {"max_diffuse_bounces", "max_transmission_bounces"};
    for (int k = 0; k < 2; ++k) {
        snprintf(s, sizeof s, "%s;%s=0", base, limits[k]);
        CHECK(hairis_render(scene, s, image, NULL, NULL) == HAIRIS_OK, "%s=0", limits[k]);
        const double sum = pixel_sum(image, W * H);
        CHECK(memcmp(image, full, sizeof image) != 0 && memcmp(image, direct, sizeof image) != 0 &&
                  sum < pixel_sum(full, W * H) && sum > pixel_sum(direct, W * H),
              "%s=0 cuts some bounces: %g between %g and %g", limits[k], sum,
              pixel_sum(direct, W * H), pixel_sum(full, W * H));
    }

    /* film_transparent: camera rays that miss add neither the world nor alpha. The camera's
     * top corners look past the floor. */
    {
        const int corner = (H - 1) * W + (W - 1); /* top right (bottom row first) */
        CHECK(pixels_ok(full), "opaque film: alpha 1 everywhere");
        CHECK(fabsf(full[4 * corner] - 0.1f) < 1e-6f && fabsf(full[4 * corner + 2] - 0.15f) < 1e-6f,
              "the corner sees the sky (%g, %g, %g)", full[4 * corner], full[4 * corner + 1],
              full[4 * corner + 2]);
        snprintf(s, sizeof s, "%s;film_transparent=1", base);
        CHECK(hairis_render(scene, s, image, NULL, NULL) == HAIRIS_OK, "film_transparent=1");
        CHECK(image[4 * corner] == 0 && image[4 * corner + 1] == 0 && image[4 * corner + 2] == 0 &&
                  image[4 * corner + 3] == 0,
              "a ray that misses: rgba 0 (%g, %g, %g, %g)", image[4 * corner],
              image[4 * corner + 1], image[4 * corner + 2], image[4 * corner + 3]);
        const int centre = (H / 2) * W + W / 2;
        CHECK(image[4 * centre + 3] == 1.0f, "a ray that hits: alpha 1 (%g)", image[4 * centre + 3]);
        int transparent = 0;
        for (int i = 0; i < W * H; ++i) transparent += image[4 * i + 3] == 0.0f;
        CHECK(transparent > 0 && transparent < W * H / 4, "%d transparent pixels", transparent);
        snprintf(s, sizeof s, "%s;film_transparent=true", base);
        CHECK(hairis_render(scene, s, direct, NULL, NULL) == HAIRIS_OK &&
                  memcmp(image, direct, sizeof image) == 0,
              "film_transparent=true is 1");
    }
    hairis_scene_destroy(scene);

    /* The camera's clip range: geometry outside it is not seen (the hair is ~3 away, the floor
     * 3.5). Every pixel is then the sky. */
    {
        const char *clips[3] = {"clip_end=1", "clip_start=10", "clip_start=2;clip_end=2.5"};
        for (int k = 0; k < 3; ++k) {
            char camera[TEXT];
            snprintf(camera, sizeof camera, CAMERA ";%s", clips[k]);
            hairis_scene *clipped = make_scene_of("", NULL, "", "type=sun;direction=0.3,0.2,1",
                                                  SKY, camera);
            CHECK(hairis_render(clipped, base, image, NULL, NULL) == HAIRIS_OK, "%s", clips[k]);
            int sky = 0;
            for (int i = 0; i < W * H; ++i)
                sky += fabsf(image[4 * i] - 0.1f) < 1e-6f && fabsf(image[4 * i + 1] - 0.12f) < 1e-6f &&
                       fabsf(image[4 * i + 2] - 0.15f) < 1e-6f && image[4 * i + 3] == 1.0f;
            CHECK(sky == W * H, "%s: %d of %d pixels are the sky", clips[k], sky, W * H);
            hairis_scene_destroy(clipped);
        }
        /* A range that holds the geometry sees it. */
        char camera[TEXT];
        snprintf(camera, sizeof camera, CAMERA ";clip_start=2;clip_end=4");
        hairis_scene *clipped =
            make_scene_of("", NULL, "", "type=sun;direction=0.3,0.2,1", SKY, camera);
        CHECK(hairis_render(clipped, base, image, NULL, NULL) == HAIRIS_OK, "clip 2 to 4");
        int sky = 0;
        for (int i = 0; i < W * H; ++i) sky += fabsf(image[4 * i] - 0.1f) < 1e-6f;
        CHECK(sky < W * H / 2, "clip 2 to 4 sees the hair and the floor (%d sky pixels)", sky);
        CHECK(hairis_scene_set_camera(clipped, CAMERA ";clip_start=2;clip_end=1") ==
                  HAIRIS_ERROR_INVALID_ARGUMENT,
              "clip_end before clip_start");
        CHECK_ERROR_MENTIONS("clip_end");
        CHECK(hairis_scene_set_camera(clipped, CAMERA ";clip_start=-1") ==
                  HAIRIS_ERROR_INVALID_ARGUMENT,
              "negative clip_start");
        CHECK_ERROR_MENTIONS("clip_start");
        hairis_scene_destroy(clipped);
    }
}

/* ---- Defaults round-trip: each kind's defaults, passed back, are what omitting them gives -- */

enum { CW = 64, CH = 64 };

/* Renders a scene of the round-trip test (hair with ANALYTIC, a floor) into rgba. */
static int render_round_trip(const char *surface, const char *light, const char *world,
                             const char *camera, float *rgba)
{
    hairis_scene *scene = make_scene_of("", NULL, surface, light, world, camera);
    const int status =
        hairis_render(scene, "samples=2;max_bounces=2;strategy=analytic;seed=3;threads=2", rgba,
                      NULL, NULL);
    hairis_scene_destroy(scene);
    return status;
}

static void test_defaults_round_trip(void)
{
    section("defaults round-trip");
    char d[TEXT], a_text[TEXT], text[TEXT];

    /* Fibers: the defaults of a model are what its model name alone gives. */
    hairis_fiber *a = hairis_fiber_create(keep(d, hairis_defaults("chiang")));
    hairis_fiber *b = hairis_fiber_create("");
    CHECK(a && b && strcmp(keep(a_text, hairis_fiber_parameters(a)), hairis_fiber_parameters(b)) == 0,
          "hairis_fiber_create(hairis_defaults(\"chiang\")) is hairis_fiber_create(\"\")");
    hairis_fiber *c = hairis_fiber_create(with_option(text, d, "roughness", "0.4"));
    CHECK(c && strcmp(a_text, hairis_fiber_parameters(c)) != 0, "and roughness in it is read");
    hairis_fiber_destroy(a);
    hairis_fiber_destroy(b);
    hairis_fiber_destroy(c);
    a = hairis_fiber_create(keep(d, hairis_defaults("huang")));
    b = hairis_fiber_create("model=huang");
    CHECK(a && b && strcmp(keep(a_text, hairis_fiber_parameters(a)), hairis_fiber_parameters(b)) == 0,
          "Huang's defaults are model=huang's");
    c = hairis_fiber_create(with_option(text, d, "aspect_ratio", "0.5"));
    CHECK(c && strcmp(a_text, hairis_fiber_parameters(c)) != 0, "and aspect_ratio in it is read");
    hairis_fiber_destroy(a);
    hairis_fiber_destroy(b);
    hairis_fiber_destroy(c);
    a = hairis_fiber_create(keep(d, hairis_defaults("marschner")));
    b = hairis_fiber_create("model=marschner");
    CHECK(a && b && strcmp(keep(a_text, hairis_fiber_parameters(a)), hairis_fiber_parameters(b)) == 0,
          "Marschner's defaults are model=marschner's: \"%s\" vs \"%s\"", a_text,
          b ? hairis_fiber_parameters(b) : "");
    c = hairis_fiber_create(with_option(text, d, "eta", "1.6"));
    CHECK(c && strcmp(a_text, hairis_fiber_parameters(c)) != 0, "and eta in it is read");
    hairis_fiber_destroy(a);
    hairis_fiber_destroy(b);
    hairis_fiber_destroy(c);

    /* Bakes: the defaults are accepted (cancelled at once: the default bake takes minutes);
     * at a small resolution they bake what they say. */
    hairis_fiber *fiber = hairis_fiber_create("");
    keep(d, hairis_defaults("bake"));
    CHECK(hairis_tables_bake(fiber, d, cancel_at_once, NULL) == NULL &&
              strcmp(hairis_last_error(), "cancelled") == 0,
          "the bake defaults are accepted");
    with_option(text, d, "theta_r", "2");
    with_option(text, keep(a_text, text), "theta_i", "4");
    with_option(text, keep(a_text, text), "phi", "8");
    with_option(text, keep(a_text, text), "source", "gaussian");
    hairis_tables *t = hairis_tables_bake(fiber, text, NULL, NULL);
    CHECK(t && strcmp(hairis_tables_info(t), "source=gaussian;theta_r=2;theta_i=4;phi=8;n_h=1,2,4,8,16") == 0,
          "\"%s\" bakes \"%s\"", text, t ? hairis_tables_info(t) : hairis_last_error());
    hairis_tables_destroy(t);
    hairis_fiber_destroy(fiber);

    /* Scene options: each kind's defaults render as the kind with no options; one value
     * changed in them renders otherwise (so the comparison can fail). */
    static float with_defaults[CW * CH * 4], without[CW * CH * 4], changed[CW * CH * 4];
    const char *sun = "type=sun;direction=0.3,0.2,1;strength=2";
    struct {
        const char *kind, *bare, *name, *value;
    } cases[] = {
        {"diffuse", "type=diffuse", "color", "0.3,0.3,0.3"},
        {"principled", "type=principled", "roughness", "0.2"},
        {"glossy", "type=glossy", "color", "0.3,0.6,0.9"},
        {"emission", "type=emission", "strength", "3"},
        {"sun", "type=sun", "strength", "2"},
        {"point", "type=point", "power", "30"},
        {"area", "type=area", "power", "30"},
        {"world", "", "color", "0.2,0.2,0.2"},
        {"camera", "", "orthographic", "1"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        const char *kind = cases[k].kind;
        keep(d, hairis_defaults(kind));
        with_option(text, d, cases[k].name, cases[k].value);
        const int is_surface = strcmp(kind, "diffuse") == 0 || strcmp(kind, "principled") == 0 ||
                               strcmp(kind, "glossy") == 0 || strcmp(kind, "emission") == 0;
        const int is_world = strcmp(kind, "world") == 0, is_camera = strcmp(kind, "camera") == 0;
        const int is_light = !is_surface && !is_world && !is_camera;
        const char *camera = is_camera ? NULL : CAMERA;
        const int pixels = is_camera ? CW * CH : W * H;
        const char *options[3] = {d, cases[k].bare, text};
        float *images[3] = {with_defaults, without, changed};
        for (int v = 0; v < 3; ++v) {
            char camera_text[TEXT];
            if (is_camera) snprintf(camera_text, sizeof camera_text, "%s", options[v]);
            const int status = render_round_trip(
                is_surface ? options[v] : "color=0.5,0.5,0.5", is_light ? options[v] : sun,
                is_world ? options[v] : SKY, is_camera ? camera_text : camera, images[v]);
            CHECK(status == HAIRIS_OK, "%s: render with \"%s\"", kind, options[v]);
        }
        CHECK(memcmp(with_defaults, without, sizeof(float) * 4 * (size_t)pixels) == 0,
              "%s: hairis_defaults renders as \"%s\"", kind, cases[k].bare);
        CHECK(memcmp(with_defaults, changed, sizeof(float) * 4 * (size_t)pixels) != 0,
              "%s: %s=%s in the defaults renders otherwise", kind, cases[k].name, cases[k].value);
    }
}

/* ---- Curve inputs -------------------------------------------------------------------------- */

/* add_strands' curves through hairis_scene_add_curves_with_inputs. */
static int add_strands_with(hairis_scene *scene, int material, const char *inputs, size_t count,
                            const float *values)
{
    enum { C = 5, P = 4 };
    uint32_t first[C + 1];
    float positions[3 * C * P], radii[C * P];
    for (int c = 0; c <= C; ++c) first[c] = (uint32_t)(c * P);
    for (int c = 0; c < C; ++c)
        for (int p = 0; p < P; ++p) {
            const int i = c * P + p;
            positions[3 * i] = -1.5f + 1.0f * (float)p;
            positions[3 * i + 1] = -0.8f + 0.4f * (float)c;
            positions[3 * i + 2] = 0.05f * (float)(p % 2);
            radii[i] = 0.05f;
        }
    return hairis_scene_add_curves_with_inputs(scene, material, C, first, C * P, positions, radii,
                                               inputs, count, values);
}

/* A sun and a sky over the strands of `fiber_options`, through add_strands_with. */
static hairis_scene *curve_input_scene(const char *fiber_options, const char *inputs, size_t count,
                                       const float *values)
{
    hairis_scene *scene = hairis_scene_create();
    hairis_fiber *fiber = hairis_fiber_create(fiber_options);
    CHECK(fiber != NULL, "fiber \"%s\"", fiber_options);
    CHECK(hairis_scene_add_hair_material(scene, fiber, NULL) == 0, "hair material");
    hairis_fiber_destroy(fiber);
    CHECK(add_strands_with(scene, 0, inputs, count, values) == HAIRIS_OK, "curves with \"%s\": %s",
          inputs, hairis_last_error());
    CHECK(hairis_scene_add_light(scene, "type=sun;direction=0.3,0.2,1;strength=3") == HAIRIS_OK, "sun");
    CHECK(hairis_scene_set_world(scene, SKY) == HAIRIS_OK, "world");
    CHECK(hairis_scene_set_camera(scene, CAMERA) == HAIRIS_OK, "camera");
    return scene;
}

static void test_curve_inputs(void)
{
    section("curve inputs");
    expect_default("curve_inputs", "melanin", "material");
    expect_default("curve_inputs", "absorption", "material");
    expect_default("curve_inputs", "random", "material");

    /* Melanin 0.8 per curve, or per point, on a melanin-0.3 material is a melanin-0.8
     * material: the strand's own fiber, bit for bit (analytic strategy). */
    static float expected[W * H * 4], per_curve[W * H * 4], per_point[W * H * 4], plain[W * H * 4];
    float curve_values[5], point_values[20];
    for (int i = 0; i < 5; ++i) curve_values[i] = 0.8f;
    for (int i = 0; i < 20; ++i) point_values[i] = 0.8f;
    const char *settings = "samples=4;max_bounces=3;strategy=analytic;seed=5";
    hairis_scene *scenes[4] = {
        curve_input_scene("parametrization=melanin;melanin=0.8", "", 0, NULL),
        curve_input_scene("parametrization=melanin;melanin=0.3", "melanin=curve", 5, curve_values),
        curve_input_scene("parametrization=melanin;melanin=0.3", "melanin=point", 20, point_values),
        curve_input_scene("parametrization=melanin;melanin=0.3", "", 0, NULL)};
    float *images[4] = {expected, per_curve, per_point, plain};
    for (int k = 0; k < 4; ++k)
        CHECK(hairis_render(scenes[k], settings, images[k], NULL, NULL) == HAIRIS_OK, "render %d: %s",
              k, hairis_last_error());
    const size_t bytes = sizeof(float) * W * H * 4;
    CHECK(memcmp(expected, per_curve, bytes) == 0, "melanin=curve 0.8 renders as melanin 0.8");
    CHECK(memcmp(expected, per_point, bytes) == 0, "melanin=point 0.8 renders as melanin 0.8");
    CHECK(memcmp(expected, plain, bytes) != 0, "and the inputs change the image");
    for (int k = 0; k < 4; ++k) hairis_scene_destroy(scenes[k]);

    /* The same for a huang2022 material (uniform strategy: the strand's own Cycles eval, whose
     * draws are seeded by the hit alone). Huang reads no radial roughness. */
    const char *huang_settings = "samples=2;max_bounces=2;strategy=uniform;seed=5";
    hairis_scene *huang_scenes[3] = {
        curve_input_scene("model=huang;parametrization=melanin;melanin=0.8", "", 0, NULL),
        curve_input_scene("model=huang;parametrization=melanin;melanin=0.3", "melanin=curve", 5, curve_values),
        curve_input_scene("model=huang;parametrization=melanin;melanin=0.3", "", 0, NULL)};
    float *huang_images[3] = {expected, per_curve, plain};
    for (int k = 0; k < 3; ++k)
        CHECK(hairis_render(huang_scenes[k], huang_settings, huang_images[k], NULL, NULL) == HAIRIS_OK,
              "huang render %d: %s", k, hairis_last_error());
    CHECK(memcmp(expected, per_curve, bytes) == 0, "huang2022 melanin=curve 0.8 renders as melanin 0.8");
    CHECK(memcmp(expected, plain, bytes) != 0, "and the inputs change the huang2022 image");
    CHECK(add_strands_with(huang_scenes[2], 0, "radial_roughness=curve", 5, curve_values) ==
              HAIRIS_ERROR_INVALID_ARGUMENT, "radial roughness on Huang");
    CHECK_ERROR_MENTIONS("huang2022");
    for (int k = 0; k < 3; ++k) hairis_scene_destroy(huang_scenes[k]);

    /* Refusals name the input, the item and the range. */
    hairis_scene *scene = curve_input_scene("parametrization=melanin", "", 0, NULL);
    point_values[7] = 1.25f;
    CHECK(add_strands_with(scene, 0, "melanin=point", 20, point_values) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "melanin 1.25");
    CHECK_ERROR_MENTIONS("point 7");
    CHECK_ERROR_MENTIONS("melanin must be in [0, 1]");
    CHECK(add_strands_with(scene, 0, "melanin=point", 19, point_values) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "19 values for 20 points");
    CHECK_ERROR_MENTIONS("value_count must be 20");
    CHECK(add_strands_with(scene, 0, "absorption=curve", 15, point_values) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "absorption under melanin");
    CHECK_ERROR_MENTIONS("parametrization (melanin)");
    CHECK(add_strands_with(scene, 0, "melanin=everywhere", 5, curve_values) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "an unknown domain");
    CHECK_ERROR_MENTIONS("melanin");
    CHECK(add_strands_with(scene, 0, "melanin=curve", 5, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT, "NULL values");
    CHECK_ERROR_MENTIONS("values");
    CHECK(add_strands_with(NULL, 0, "", 0, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT, "NULL scene");
    CHECK_ERROR_MENTIONS("scene");
    hairis_scene_destroy(scene);
}

/* ---- Scene refusals ----------------------------------------------------------------------- */

static void test_scene_refusals(void)
{
    section("scene refusals");
    hairis_scene *scene = hairis_scene_create();
    hairis_fiber *chiang = hairis_fiber_create("");
    hairis_fiber *marschner = hairis_fiber_create("model=marschner");

    CHECK(hairis_scene_add_hair_material(scene, marschner, NULL) == -1, "Marschner hair");
    CHECK_ERROR_MENTIONS("chiang2016");
    CHECK(hairis_scene_add_hair_material(NULL, chiang, NULL) == -1, "NULL scene");
    CHECK_ERROR_MENTIONS("scene");
    CHECK(hairis_scene_add_hair_material(scene, NULL, NULL) == -1, "NULL fiber");
    CHECK_ERROR_MENTIONS("fiber");
    CHECK(hairis_scene_add_surface_material(scene, "color=0.5,1.5,0.5") == -1, "colour > 1");
    CHECK_ERROR_MENTIONS("color");
    CHECK(hairis_scene_add_surface_material(scene, "emission=0,-1,0") == -1, "negative emission");
    CHECK_ERROR_MENTIONS("emission");
    CHECK(hairis_scene_add_surface_material(NULL, "") == -1, "NULL scene");
    CHECK_ERROR_MENTIONS("scene");

    const int hair = hairis_scene_add_hair_material(scene, chiang, NULL);
    const int diffuse = hairis_scene_add_surface_material(scene, "color=1,1,1");
    CHECK(hair == 0 && diffuse == 1, "indices %d %d", hair, diffuse);

    uint32_t first[3] = {0, 2, 4};
    float positions[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    float radii[4] = {0.1f, 0.1f, 0.1f, 0.1f};
    CHECK(hairis_scene_add_curves(scene, 5, 2, first, 4, positions, radii) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "curves: material out of range");
    CHECK_ERROR_MENTIONS("material");
    first[0] = 1;
    CHECK(hairis_scene_add_curves(scene, hair, 2, first, 4, positions, radii) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "curves: first[0] = 1");
    CHECK_ERROR_MENTIONS("first[0]");
    first[0] = 0;
    first[1] = 1;
    CHECK(hairis_scene_add_curves(scene, hair, 2, first, 4, positions, radii) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "curves: a curve of one point");
    CHECK_ERROR_MENTIONS("at least 2 points");
    first[1] = 2;
    first[2] = 3;
    CHECK(hairis_scene_add_curves(scene, hair, 1, first, 4, positions, radii) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "curves: first[curve_count] != point_count");
    CHECK_ERROR_MENTIONS("point_count");
    first[2] = 4;
    positions[4] = NAN;
    CHECK(hairis_scene_add_curves(scene, hair, 2, first, 4, positions, radii) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "curves: NaN position");
    CHECK_ERROR_MENTIONS("positions[4]");
    positions[4] = 0;
    radii[3] = -0.1f;
    CHECK(hairis_scene_add_curves(scene, hair, 2, first, 4, positions, radii) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "curves: negative radius");
    CHECK_ERROR_MENTIONS("radii[3]");
    radii[3] = 0.1f;
    CHECK(hairis_scene_add_curves(scene, hair, 2, NULL, 4, positions, radii) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "curves: NULL first");
    CHECK_ERROR_MENTIONS("first");
    CHECK(hairis_scene_add_curves(scene, hair, 2, first, 4, positions, NULL) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "curves: NULL radii");
    CHECK_ERROR_MENTIONS("radii");
    CHECK(hairis_scene_add_curves(scene, hair, (size_t)1 << 40, first, (size_t)1 << 41, NULL,
                                  NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "curves: huge counts with NULL arrays, refused before reading them");
    CHECK(hairis_scene_add_curves(scene, hair, 2, first, 4, positions, radii) == HAIRIS_OK,
          "curves: valid");
    CHECK_NO_ERROR();

    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    uint32_t indices[3] = {0, 1, 3};
    int32_t materials[1] = {diffuse};
    CHECK(hairis_scene_add_mesh(scene, 3, tri, 1, indices, materials) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "mesh: index out of range");
    CHECK_ERROR_MENTIONS("indices[2]");
    indices[2] = 2;
    materials[0] = hair;
    CHECK(hairis_scene_add_mesh(scene, 3, tri, 1, indices, materials) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "mesh: hair material");
    CHECK_ERROR_MENTIONS("hair material");
    materials[0] = -1;
    CHECK(hairis_scene_add_mesh(scene, 3, tri, 1, indices, materials) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "mesh: material -1");
    CHECK_ERROR_MENTIONS("materials[0]");
    materials[0] = diffuse;
    CHECK(hairis_scene_add_mesh(scene, 3, NULL, 1, indices, materials) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "mesh: NULL positions");
    CHECK_ERROR_MENTIONS("positions");
    CHECK(hairis_scene_add_mesh(NULL, 3, tri, 1, indices, materials) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "mesh: NULL scene");
    CHECK_ERROR_MENTIONS("scene");
    CHECK(hairis_scene_add_mesh(scene, 3, tri, 1, indices, materials) == HAIRIS_OK,
          "mesh: valid");

    /* Lights, world and camera: every bad value named. */
    const char *bad[][2] = {
        {"type=sun;direction=0,0,0", "direction"},
        {"type=sun;direction=nan,0,1", "direction"},
        {"type=sun;strength=-1", "strength"},
        {"type=sun;angle=4", "angle"},
        {"type=sun;color=1,-1,1", "color"},
        {"type=sun;radius=1", "\"radius\""},
        {"type=point;radius=-1", "radius"},
        {"type=point;position=nan,0,0", "position"},
        {"type=point;power=inf", "power"},
        {"type=area;shape=7", "shape"},
        {"type=area;matrix=1,0,0,0,0,1,0,0,0,0,0,0,0,0,0,1", "Z axis"},
        {"type=area;size=-1", "size"},
        {"type=area;matrix=1,0,0", "matrix"},
        {"type=area;size_x=1", "\"size_x\""},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        CHECK(hairis_scene_add_light(scene, bad[i][0]) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "light \"%s\" refused", bad[i][0]);
        CHECK_ERROR_MENTIONS(bad[i][1]);
    }
    CHECK(hairis_scene_add_light(NULL, "type=sun") == HAIRIS_ERROR_INVALID_ARGUMENT, "NULL scene");
    CHECK_ERROR_MENTIONS("scene");
    CHECK(hairis_scene_set_world(scene, "strength=-2") == HAIRIS_ERROR_INVALID_ARGUMENT,
          "world: negative strength");
    CHECK_ERROR_MENTIONS("strength");
    CHECK(hairis_scene_set_world(scene, "color=1,1") == HAIRIS_ERROR_INVALID_ARGUMENT,
          "world: two components");
    CHECK_ERROR_MENTIONS("color");
    CHECK(hairis_scene_set_world(NULL, "") == HAIRIS_ERROR_INVALID_ARGUMENT, "world: NULL scene");
    CHECK_ERROR_MENTIONS("scene");
    CHECK(hairis_scene_set_world(scene, "image=/nonexistent/sky.exr") != HAIRIS_OK,
          "world: a missing image");
    CHECK_ERROR_MENTIONS("sky.exr");
    CHECK(hairis_scene_set_world(scene, "sampling=manual") == HAIRIS_ERROR_INVALID_ARGUMENT,
          "world: environment options without an environment");
    CHECK_ERROR_MENTIONS("sampling");

    /* World pixels: a valid 4 x 2 RGB image, then each bad argument named. */
    float sky[4 * 2 * 3];
    for (int i = 0; i < 24; ++i) sky[i] = 0.1f * (float)(i % 5);
    CHECK(hairis_scene_set_world_pixels(scene, "color_space=linear", sky, 4, 2, 3) == HAIRIS_OK,
          "world pixels (%s)", hairis_last_error());
    CHECK(hairis_scene_set_world_pixels(scene, "color_space=linear", NULL, 4, 2, 3) ==
              HAIRIS_ERROR_INVALID_ARGUMENT, "world pixels: NULL");
    CHECK_ERROR_MENTIONS("pixels");
    CHECK(hairis_scene_set_world_pixels(scene, "color_space=linear", sky, 4, 2, 5) ==
              HAIRIS_ERROR_INVALID_ARGUMENT, "world pixels: 5 channels");
    CHECK_ERROR_MENTIONS("channels");
    CHECK(hairis_scene_set_world_pixels(scene, "color_space=linear", sky, 0, 2, 3) ==
              HAIRIS_ERROR_INVALID_ARGUMENT, "world pixels: zero width");
    CHECK_ERROR_MENTIONS("width");
    sky[7] = -1.0f;
    CHECK(hairis_scene_set_world_pixels(scene, "color_space=linear", sky, 4, 2, 3) ==
              HAIRIS_ERROR_INVALID_ARGUMENT, "world pixels: a negative value");
    CHECK_ERROR_MENTIONS("pixel");
    sky[7] = 0.0f;
    CHECK(hairis_scene_set_world_pixels(scene, "image=a.exr", sky, 4, 2, 3) ==
              HAIRIS_ERROR_INVALID_ARGUMENT, "world pixels: with an image path");
    CHECK_ERROR_MENTIONS("image");

    const char *spots[][2] = {
        {"type=spot;spot_size=0", "spot_size"},
        {"type=spot;spot_blend=1.5", "spot_blend"},
        {"type=spot;radius=-1", "radius"},
        {"type=spot;cycles=4.0", "cycles"},
        {"type=point;soft_falloff=0", "soft_falloff"},
    };
    for (size_t i = 0; i < sizeof spots / sizeof spots[0]; ++i) {
        CHECK(hairis_scene_add_light(scene, spots[i][0]) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "light \"%s\" refused", spots[i][0]);
        CHECK_ERROR_MENTIONS(spots[i][1]);
    }
    CHECK(hairis_scene_add_light(scene, "type=spot;cycles=4.5;soft_falloff=0;spot_size=0.5") ==
              HAIRIS_OK, "a 4.5 sphere spot (%s)", hairis_last_error());

    const char *bad_cameras[][2] = {
        {"width=0", "width"},
        {"height=65537", "height"},
        {"orthographic=2", "orthographic"},
        {"frame=nan,0.4,-1,0.4,-0.4,-1,-0.4,-0.4,-1,-0.4,0.4,-1", "frame"},
        /* Corners in the wrong order (top left first). */
        {"frame=-0.4,0.4,-1,0.4,0.4,-1,0.4,-0.4,-1,-0.4,-0.4,-1", "frame"},
        {"matrix=nan,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1", "matrix"},
        {"matrix=0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,1", "camera_to_world"},
        {"lens=50", "\"lens\""},
    };
    for (size_t i = 0; i < sizeof bad_cameras / sizeof bad_cameras[0]; ++i) {
        CHECK(hairis_scene_set_camera(scene, bad_cameras[i][0]) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "camera \"%s\" refused", bad_cameras[i][0]);
        CHECK_ERROR_MENTIONS(bad_cameras[i][1]);
    }
    CHECK(hairis_scene_set_camera(NULL, "") == HAIRIS_ERROR_INVALID_ARGUMENT, "camera: NULL scene");
    CHECK_ERROR_MENTIONS("scene");
    /* A refused camera leaves the scene without one. */
    static float rgba[W * H * 4];
    CHECK(hairis_render(scene, "strategy=analytic", rgba, NULL, NULL) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "render after refused cameras");
    CHECK_ERROR_MENTIONS("no camera");
    hairis_scene_destroy(scene);
    hairis_scene_destroy(NULL);
    CHECK_NO_ERROR();
    hairis_fiber_destroy(chiang);
    hairis_fiber_destroy(marschner);
}

/* ---- Surface materials, textures and mesh attributes -------------------------------------- */

static void test_surfaces(void)
{
    section("surfaces");
    hairis_scene *scene = hairis_scene_create();

    /* Textures from pixels (bottom row first) and their refusals. */
    const float pixels[6] = {0.2f, 0.4f, 0.6f, 0.9f, 0.8f, 0.1f};
    const int texture = hairis_scene_add_texture_pixels(
        scene, "color_space=linear;interpolation=closest;extension=extend", pixels, 2, 1, 3);
    CHECK(texture == 0, "texture index %d", texture);
    CHECK_NO_ERROR();
    CHECK(hairis_scene_add_texture_pixels(scene, "", pixels, 2, 1, 3) == -1, "auto colour space");
    CHECK_ERROR_MENTIONS("color_space");
    const float bad[3] = {0.0f, NAN, 0.0f};
    CHECK(hairis_scene_add_texture_pixels(scene, "color_space=linear", bad, 1, 1, 3) == -1, "NaN texel");
    CHECK_ERROR_MENTIONS("pixel");
    CHECK(hairis_scene_add_texture_pixels(scene, "color_space=linear", pixels, 2, 1, 5) == -1, "5 channels");
    CHECK_ERROR_MENTIONS("channels");
    CHECK(hairis_scene_add_texture_pixels(scene, "color_space=linear;rotation=0,0,1", pixels, 2, 1, 3) == -1,
          "a rotation without a mapping");
    CHECK_ERROR_MENTIONS("mapping");
    CHECK(hairis_scene_add_texture_pixels(scene, "color_space=linear;mapping=normal", pixels, 2, 1, 3) == -1,
          "a Normal mapping");
    CHECK_ERROR_MENTIONS("mapping");
    CHECK(hairis_scene_add_texture(scene, "") == -1, "a texture without image");
    CHECK_ERROR_MENTIONS("image");
    CHECK(hairis_scene_add_texture(scene, "image=/nonexistent/skin.png") == -1, "a missing file");
    CHECK_ERROR_MENTIONS("skin.png");

    /* Materials: textures by index, version-specific inputs, Mix and Add of surfaces. */
    const int textured = hairis_scene_add_surface_material(scene, "type=diffuse;color_texture=0");
    CHECK(textured == 0, "textured diffuse %d", textured);
    CHECK(hairis_scene_add_surface_material(scene, "type=principled;base_color_texture=3") == -1,
          "a texture index out of range");
    CHECK_ERROR_MENTIONS("base_color_texture");
    CHECK(hairis_scene_add_surface_material(scene, "type=principled;cycles=4.5;sheen=0.5") == -1,
          "4.x sheen");
    CHECK_ERROR_MENTIONS("sheen");
    CHECK_ERROR_MENTIONS("4.5");
    CHECK(hairis_scene_add_surface_material(scene, "type=principled;coat_tint=1,0,0") == -1,
          "coat tint for 3.4");
    CHECK_ERROR_MENTIONS("coat_tint");
    CHECK(hairis_scene_add_surface_material(scene, "type=principled;metallic=1.5") == -1, "metallic > 1");
    CHECK_ERROR_MENTIONS("metallic");
    const int glow = hairis_scene_add_surface_material(scene, "type=emission;color=1,0,0;strength=2");
    const int mix = hairis_scene_add_surface_material(scene, "type=mix;factor=0.25;shader1=0;shader2=1");
    CHECK(glow == 1 && mix == 2, "emission %d, mix %d", glow, mix);
    CHECK(hairis_scene_add_surface_material(scene, "type=mix;shader1=0") == -1, "a mix of one");
    CHECK_ERROR_MENTIONS("shader2");
    CHECK(hairis_scene_add_surface_material(scene, "type=add;shader1=0;shader2=9") == -1, "out of range");
    CHECK_ERROR_MENTIONS("shader2");
    CHECK(hairis_scene_add_surface_material(scene, "type=add;factor=0.5;shader1=0;shader2=1") == -1,
          "an Add Shader has no factor");
    CHECK_ERROR_MENTIONS("factor");
    const int later = hairis_scene_add_surface_material(scene, "type=glossy;cycles=4.5");
    CHECK(later == 3, "glossy %d", later);
    CHECK(hairis_scene_add_surface_material(scene, "type=add;shader1=0;shader2=3") == -1,
          "3.4 and 4.5 nodes in one material");
    CHECK_ERROR_MENTIONS("same Cycles");
    hairis_fiber *fiber = hairis_fiber_create("");
    const int hair = hairis_scene_add_hair_material(scene, fiber, NULL);
    hairis_fiber_destroy(fiber);
    CHECK(hairis_scene_add_surface_material(scene, "type=mix;shader1=0;shader2=4") == -1 && hair == 4,
          "a mix with hair");
    CHECK_ERROR_MENTIONS("hair");

    /* Mesh attributes attach to the last mesh added. */
    const float uv[12] = {0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1};
    CHECK(hairis_scene_set_mesh_attribute(scene, "name=uv", uv, 12) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "no mesh yet");
    CHECK_ERROR_MENTIONS("no triangles");
    const float quad[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    const uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
    const int32_t materials[2] = {textured, textured};
    CHECK(hairis_scene_add_mesh(scene, 4, quad, 2, indices, materials) == HAIRIS_OK, "quad");
    CHECK(hairis_scene_set_mesh_attribute(scene, "name=uv", uv, 10) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "10 floats for 6 corners");
    CHECK_ERROR_MENTIONS("12");
    float normals[18] = {0};
    CHECK(hairis_scene_set_mesh_attribute(scene, "name=normal", normals, 18) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "zero normals");
    CHECK_ERROR_MENTIONS("zero normal");
    CHECK(hairis_scene_set_mesh_attribute(scene, "name=tangent", uv, 12) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "an attribute hairis does not know");
    CHECK_ERROR_MENTIONS("uv");
    CHECK(hairis_scene_set_mesh_attribute(scene, "name=uv", uv, 12) == HAIRIS_OK, "uv");
    for (int k = 0; k < 6; ++k) normals[3 * k + 2] = 1.0f;
    CHECK(hairis_scene_set_mesh_attribute(scene, "name=normal", normals, 18) == HAIRIS_OK, "normals");

    /* A sun from straight above, orthographic view from above: the left half of the image sees
     * texel 0, the right half texel 1, each exactly colour x strength / pi. */
    CHECK(hairis_scene_add_light(scene, "type=sun;direction=0,0,1;strength=3") == HAIRIS_OK, "sun");
    CHECK(hairis_scene_set_world(scene, "color=0,0,0") == HAIRIS_OK, "world");
    CHECK(hairis_scene_set_camera(scene, "matrix=1,0,0,0,0,1,0,0,0,0,1,3,0,0,0,1;orthographic=1;"
                                         "frame=0.8,0.4,-1,0.8,-0.4,-1,-0.8,-0.4,-1,-0.8,0.4,-1;"
                                         "width=4;height=2") == HAIRIS_OK,
          "camera");
    float rgba[4 * 2 * 4];
    CHECK(hairis_render(scene, "samples=2;max_bounces=0;strategy=analytic", rgba, NULL, NULL) == HAIRIS_OK,
          "render");
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x)
            for (int c = 0; c < 3; ++c) {
                const float expected = pixels[(x < 2 ? 0 : 3) + c] * 3.0f / 3.14159265f;
                CHECK(fabsf(rgba[(y * 4 + x) * 4 + c] - expected) < 1e-5f, "pixel %d,%d channel %d: %g, not %g",
                      x, y, c, rgba[(y * 4 + x) * 4 + c], expected);
            }
    hairis_scene_destroy(scene);
}

int main(void)
{
    const char *temp_dir = getenv("TMPDIR");
    if (!temp_dir || !*temp_dir) temp_dir = "/tmp";

    test_library();
    test_defaults();
    test_fiber_creation();
    test_fiber_eval();
    test_tables(temp_dir);
    if (g_tables) {
        test_option_strings();
        test_sampling();
        test_render();
    } else {
        CHECK(0, "no tables: the option, sampling and render tests cannot run");
    }
    test_huang();
    test_render_options();
    test_defaults_round_trip();
    test_scene_refusals();
    test_curve_inputs();
    test_surfaces();
    hairis_tables_destroy(g_tables);

    printf("%d passed, %d failed\n", g_passed, g_failed);
    return g_failed == 0 ? 0 : 1;
}
