/* Tests of the hairis C API (lib/include/hairis/hairis.h), written in C11 against the shared
 * library, as a renderer embedding hairis would use it.
 *
 * Usage: capi_test [--layout]
 *   (no argument)  runs every check and prints "N passed, M failed"; exits 1 on a failure.
 *   --layout       prints "struct <name> <sizeof>" and "field <struct> <field> <offset>" lines
 *                  for every struct of the header (capi_ctypes_test.py compares its ctypes
 *                  mirrors against them) and exits.
 *
 * HAIRIS_EXPECTED_VERSION (a compile definition) is the project's version.
 */
#define _POSIX_C_SOURCE 200809L
#include "hairis/hairis.h"

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

/* ---- Layout dump (for the ctypes test) ---------------------------------------------------- */

#define PRINT_SIZE(type) printf("struct %s %zu\n", #type, sizeof(type))
#define PRINT_FIELD(type, field) printf("field %s %s %zu\n", #type, #field, offsetof(type, field))

static void print_layout(void)
{
    PRINT_SIZE(hairis_principled_hair);
    PRINT_FIELD(hairis_principled_hair, parametrization);
    PRINT_FIELD(hairis_principled_hair, color);
    PRINT_FIELD(hairis_principled_hair, melanin);
    PRINT_FIELD(hairis_principled_hair, melanin_redness);
    PRINT_FIELD(hairis_principled_hair, tint);
    PRINT_FIELD(hairis_principled_hair, absorption_coefficient);
    PRINT_FIELD(hairis_principled_hair, roughness);
    PRINT_FIELD(hairis_principled_hair, radial_roughness);
    PRINT_FIELD(hairis_principled_hair, coat);
    PRINT_FIELD(hairis_principled_hair, ior);
    PRINT_FIELD(hairis_principled_hair, offset);
    PRINT_FIELD(hairis_principled_hair, random_color);
    PRINT_FIELD(hairis_principled_hair, random_roughness);
    PRINT_FIELD(hairis_principled_hair, random);
    PRINT_SIZE(hairis_marschner_params);
    PRINT_FIELD(hairis_marschner_params, eta);
    PRINT_FIELD(hairis_marschner_params, sigma_a);
    PRINT_FIELD(hairis_marschner_params, alpha_r);
    PRINT_FIELD(hairis_marschner_params, alpha_tt);
    PRINT_FIELD(hairis_marschner_params, alpha_trt);
    PRINT_FIELD(hairis_marschner_params, beta_r);
    PRINT_FIELD(hairis_marschner_params, beta_tt);
    PRINT_FIELD(hairis_marschner_params, beta_trt);
    PRINT_FIELD(hairis_marschner_params, eccentricity);
    PRINT_FIELD(hairis_marschner_params, glint_scale);
    PRINT_FIELD(hairis_marschner_params, caustic_width);
    PRINT_FIELD(hairis_marschner_params, caustic_fade);
    PRINT_FIELD(hairis_marschner_params, caustic_intensity_limit);
    PRINT_SIZE(hairis_bake_options);
    PRINT_FIELD(hairis_bake_options, theta_r_count);
    PRINT_FIELD(hairis_bake_options, theta_i_count);
    PRINT_FIELD(hairis_bake_options, phi_count);
    PRINT_FIELD(hairis_bake_options, n_h_count);
    PRINT_FIELD(hairis_bake_options, n_h_values);
    PRINT_FIELD(hairis_bake_options, source);
    PRINT_FIELD(hairis_bake_options, threads);
    PRINT_SIZE(hairis_camera);
    PRINT_FIELD(hairis_camera, camera_to_world);
    PRINT_FIELD(hairis_camera, orthographic);
    PRINT_FIELD(hairis_camera, frame);
    PRINT_FIELD(hairis_camera, width);
    PRINT_FIELD(hairis_camera, height);
    PRINT_SIZE(hairis_render_settings);
    PRINT_FIELD(hairis_render_settings, samples);
    PRINT_FIELD(hairis_render_settings, max_bounces);
    PRINT_FIELD(hairis_render_settings, strategy);
    PRINT_FIELD(hairis_render_settings, multiple_weight);
    PRINT_FIELD(hairis_render_settings, n_h);
    PRINT_FIELD(hairis_render_settings, seed);
    PRINT_FIELD(hairis_render_settings, threads);
    PRINT_SIZE(hairis_render_stats);
    PRINT_FIELD(hairis_render_stats, seconds);
    PRINT_FIELD(hairis_render_stats, camera_rays);
    PRINT_FIELD(hairis_render_stats, dropped_samples);
    PRINT_FIELD(hairis_render_stats, peak_memory_bytes);
}

/* ---- Library ------------------------------------------------------------------------------ */

static int set_error_in_thread(void *arg)
{
    (void)arg;
    hairis_fiber *fiber = hairis_fiber_create_principled(NULL);
    return fiber == NULL && hairis_last_error()[0] != '\0' ? 0 : 1;
}

static void test_library(void)
{
    section("library");
    CHECK(hairis_api_version() == HAIRIS_API_VERSION, "api version %d", hairis_api_version());
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
    CHECK(hairis_fiber_create_principled(NULL) == NULL, "NULL node refused");
    CHECK(hairis_last_error()[0] != '\0', "an error is reported");
    hairis_api_version();
    CHECK_NO_ERROR();
}

/* ---- Defaults ----------------------------------------------------------------------------- */

static void test_defaults(void)
{
    section("defaults");
    hairis_principled_hair node;
    memset(&node, 0xff, sizeof node);
    hairis_principled_hair_defaults(&node);
    CHECK_NO_ERROR();
    CHECK(node.parametrization == HAIRIS_PARAM_COLOR, "Direct Coloring by default");
    CHECK(fabsf(node.ior - 1.55f) < 1e-6f, "ior %g", node.ior);
    CHECK(fabsf(node.roughness - 0.3f) < 1e-6f && fabsf(node.radial_roughness - 0.3f) < 1e-6f,
          "roughness %g %g", node.roughness, node.radial_roughness);
    CHECK(fabsf(node.offset - 0.034906585f) < 1e-6f, "offset 2 degrees in radians, got %g",
          node.offset);
    CHECK(fabsf(node.color[0] - 0.017513f) < 1e-6f, "colour %g", node.color[0]);
    CHECK(node.coat == 0.0f && node.random == 0.0f && node.random_roughness == 0.0f,
          "coat and randoms 0");

    hairis_marschner_params m;
    memset(&m, 0xff, sizeof m);
    hairis_marschner_defaults(&m);
    CHECK_NO_ERROR();
    CHECK(fabsf(m.eta - 1.55f) < 1e-6f, "eta %g", m.eta);
    CHECK(fabsf(m.sigma_a[0] - 0.15f) < 1e-6f && fabsf(m.sigma_a[1] - 0.2f) < 1e-6f &&
              fabsf(m.sigma_a[2] - 0.3f) < 1e-6f,
          "blonde sigma_a (%g, %g, %g)", m.sigma_a[0], m.sigma_a[1], m.sigma_a[2]);
    CHECK(fabsf(m.alpha_r + 0.1308997f) < 1e-6f, "alpha_r -7.5 degrees, got %g", m.alpha_r);
    CHECK(fabsf(m.eccentricity - 0.9f) < 1e-6f, "eccentricity %g", m.eccentricity);

    hairis_bake_options o;
    memset(&o, 0xff, sizeof o);
    hairis_bake_options_defaults(&o);
    CHECK_NO_ERROR();
    CHECK(o.theta_r_count == 31 && o.theta_i_count == 64 && o.phi_count == 64,
          "resolution %d %d %d", o.theta_r_count, o.theta_i_count, o.phi_count);
    CHECK(o.n_h_count == 5 && o.n_h_values[0] == 1 && o.n_h_values[4] == 16 &&
              o.n_h_values[5] == 0 && o.n_h_values[15] == 0,
          "n_h values");
    CHECK(o.source == 0 && o.threads == 0, "source %d threads %d", o.source, o.threads);

    hairis_render_settings r;
    memset(&r, 0xff, sizeof r);
    hairis_render_settings_defaults(&r);
    CHECK_NO_ERROR();
    CHECK(r.samples == 64 && r.max_bounces == 12 && r.strategy == HAIRIS_STRATEGY_TABLE,
          "samples %d bounces %d strategy %d", r.samples, r.max_bounces, r.strategy);
    CHECK(r.multiple_weight == 0.0f && r.n_h == 2 && r.seed == 0 &&
              r.threads == 0,
          "weight %g n_h %d", r.multiple_weight, r.n_h);

    /* NULL is refused without a crash. */
    hairis_principled_hair_defaults(NULL);
    CHECK_ERROR_MENTIONS("node");
    hairis_marschner_defaults(NULL);
    CHECK_ERROR_MENTIONS("params");
    hairis_bake_options_defaults(NULL);
    CHECK_ERROR_MENTIONS("options");
    hairis_render_settings_defaults(NULL);
    CHECK_ERROR_MENTIONS("settings");
}

/* ---- Fibers ------------------------------------------------------------------------------- */

static hairis_fiber *default_chiang(void)
{
    hairis_principled_hair node;
    hairis_principled_hair_defaults(&node);
    return hairis_fiber_create_principled(&node);
}

/* Creating a fiber from `node` fails and the error mentions `word`. */
static void expect_principled_refused(const hairis_principled_hair *node, const char *word)
{
    hairis_fiber *fiber = hairis_fiber_create_principled(node);
    CHECK(fiber == NULL, "node with a bad %s refused", word);
    CHECK_ERROR_MENTIONS(word);
    hairis_fiber_destroy(fiber);
}

static void expect_marschner_refused(const hairis_marschner_params *params, const char *word)
{
    hairis_fiber *fiber = hairis_fiber_create_marschner(params);
    CHECK(fiber == NULL, "params with a bad %s refused", word);
    CHECK_ERROR_MENTIONS(word);
    hairis_fiber_destroy(fiber);
}

static void test_fiber_creation(void)
{
    section("fiber creation");
    hairis_principled_hair node;
    hairis_principled_hair_defaults(&node);
    for (int p = HAIRIS_PARAM_ABSORPTION; p <= HAIRIS_PARAM_COLOR; ++p) {
        node.parametrization = p;
        hairis_fiber *fiber = hairis_fiber_create_principled(&node);
        CHECK(fiber != NULL, "parametrization %d accepted", p);
        CHECK_NO_ERROR();
        CHECK(strcmp(hairis_fiber_model(fiber), "chiang2016") == 0, "model \"%s\"",
              hairis_fiber_model(fiber));
        CHECK(strstr(hairis_fiber_parameters(fiber), "sigma_a.r=") != NULL &&
                  strstr(hairis_fiber_parameters(fiber), "offset=") != NULL,
              "parameters \"%s\"", hairis_fiber_parameters(fiber));
        CHECK_NO_ERROR();
        hairis_fiber_destroy(fiber);
        CHECK_NO_ERROR();
    }

    /* Two nodes that map to the same closure parameters give the same parameter string. */
    {
        hairis_fiber *a = default_chiang();
        hairis_principled_hair other;
        hairis_principled_hair_defaults(&other);
        other.melanin = 0.1f; /* not read by Direct Coloring */
        hairis_fiber *b = hairis_fiber_create_principled(&other);
        CHECK(a && b && strcmp(hairis_fiber_parameters(a), hairis_fiber_parameters(b)) == 0,
              "unread inputs do not change the parameters");
        hairis_fiber_destroy(a);
        hairis_fiber_destroy(b);
    }

    hairis_marschner_params m;
    hairis_marschner_defaults(&m);
    hairis_fiber *marschner = hairis_fiber_create_marschner(&m);
    CHECK(marschner != NULL, "Marschner defaults accepted");
    CHECK(strcmp(hairis_fiber_model(marschner), "marschner2003") == 0, "model \"%s\"",
          hairis_fiber_model(marschner));
    CHECK(strstr(hairis_fiber_parameters(marschner), "eta=1.55;") != NULL,
          "eta printed as typed: \"%s\"", hairis_fiber_parameters(marschner));
    CHECK(strstr(hairis_fiber_parameters(marschner), "sigma_a.r=0.150000006;") != NULL,
          "blonde sigma_a: \"%s\"", hairis_fiber_parameters(marschner));
    hairis_fiber_destroy(marschner);

    /* Every kind of bad input: NULL, enum out of range, non-finite, out of range. */
    expect_principled_refused(NULL, "node");
    hairis_principled_hair bad;
    hairis_principled_hair_defaults(&bad);
    bad.parametrization = 7;
    expect_principled_refused(&bad, "parametrization");
    bad.parametrization = -1;
    expect_principled_refused(&bad, "parametrization");
    hairis_principled_hair_defaults(&bad);
    bad.roughness = 2.0f;
    expect_principled_refused(&bad, "roughness");
    hairis_principled_hair_defaults(&bad);
    bad.radial_roughness = -0.5f;
    expect_principled_refused(&bad, "radial_roughness");
    hairis_principled_hair_defaults(&bad);
    bad.ior = 0.9f;
    expect_principled_refused(&bad, "ior");
    hairis_principled_hair_defaults(&bad);
    bad.coat = NAN;
    expect_principled_refused(&bad, "coat");
    hairis_principled_hair_defaults(&bad);
    bad.offset = INFINITY;
    expect_principled_refused(&bad, "offset");
    hairis_principled_hair_defaults(&bad);
    bad.offset = 2.0f; /* more than pi/2 */
    expect_principled_refused(&bad, "offset");
    hairis_principled_hair_defaults(&bad);
    bad.color[1] = 0.0f;
    expect_principled_refused(&bad, "color");
    hairis_principled_hair_defaults(&bad);
    bad.tint[2] = NAN; /* not read by Direct Coloring, but never finite */
    expect_principled_refused(&bad, "tint");
    hairis_principled_hair_defaults(&bad);
    bad.parametrization = HAIRIS_PARAM_MELANIN;
    bad.melanin = 1.5f;
    expect_principled_refused(&bad, "melanin");
    hairis_principled_hair_defaults(&bad);
    bad.parametrization = HAIRIS_PARAM_ABSORPTION;
    bad.absorption_coefficient[0] = -1.0f;
    expect_principled_refused(&bad, "absorption_coefficient");

    expect_marschner_refused(NULL, "params");
    hairis_marschner_params badm;
    hairis_marschner_defaults(&badm);
    badm.eta = NAN;
    expect_marschner_refused(&badm, "eta");
    hairis_marschner_defaults(&badm);
    badm.eta = 0.8f;
    expect_marschner_refused(&badm, "eta");
    hairis_marschner_defaults(&badm);
    badm.eccentricity = 0.5f;
    expect_marschner_refused(&badm, "eccentricity");
    hairis_marschner_defaults(&badm);
    badm.caustic_intensity_limit = 2.0f;
    expect_marschner_refused(&badm, "caustic_intensity_limit");
    hairis_marschner_defaults(&badm);
    badm.sigma_a[1] = -0.1f;
    expect_marschner_refused(&badm, "sigma_a");
    hairis_marschner_defaults(&badm);
    badm.beta_trt = INFINITY;
    expect_marschner_refused(&badm, "beta_trt");

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
    hairis_fiber *chiang = default_chiang();
    hairis_marschner_params m;
    hairis_marschner_defaults(&m);
    hairis_fiber *marschner = hairis_fiber_create_marschner(&m);
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
        direction_from_angles(-0.3f, 2.6f, a);  /* near the TT lobe */
        direction_from_angles(0.25f, -1.5707963f, b);
        float far[3];
        CHECK(hairis_fiber_eval(chiang, 1, a, b, NULL, far) == HAIRIS_OK, "far one");
        enum { K = 4001 };
        static float many_a[3 * K], many_b[3 * K], many_h[K], many_f[3 * K];
        double weights[K];
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

    /* Refusals. */
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
    CHECK(rgb[0] == -7.0f, "nothing written on error");
    wi[3 * 5] = saved;
    wo[3 * 2] *= 2.0f; /* not unit length */
    CHECK(hairis_fiber_eval(chiang, N, wi, wo, NULL, rgb) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "non-unit wo");
    CHECK_ERROR_MENTIONS("unit");
    wo[3 * 2] *= 0.5f;
    h[3] = 1.5f;
    CHECK(hairis_fiber_eval(chiang, N, wi, wo, h, rgb) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "h out of range");
    CHECK_ERROR_MENTIONS("h[3]");
    h[3] = NAN;
    CHECK(hairis_fiber_eval(chiang, N, wi, wo, h, rgb) == HAIRIS_ERROR_INVALID_ARGUMENT, "NaN h");
    CHECK_ERROR_MENTIONS("h[3]");

    hairis_fiber_destroy(chiang);
    hairis_fiber_destroy(marschner);
}

/* ---- Tables ------------------------------------------------------------------------------- */

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

static void tiny_options(hairis_bake_options *o)
{
    hairis_bake_options_defaults(o);
    o->theta_r_count = 4;
    o->theta_i_count = 8;
    o->phi_count = 8;
    o->n_h_count = 2;
    o->n_h_values[0] = 1;
    o->n_h_values[1] = 2;
    o->threads = 2;
}

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

static hairis_tables *g_tables = NULL; /* baked for the default node, n_h {1, 2} */

static void expect_bake_refused(const hairis_fiber *fiber, const hairis_bake_options *o,
                                const char *word)
{
    hairis_tables *t = hairis_tables_bake(fiber, o, NULL, NULL);
    CHECK(t == NULL, "bake with a bad %s refused", word);
    CHECK_ERROR_MENTIONS(word);
    hairis_tables_destroy(t);
}

static void test_tables(const char *temp_dir)
{
    section("tables");
    hairis_fiber *fiber = default_chiang();
    hairis_bake_options o;
    tiny_options(&o);

    progress_state progress = {0, 0, -1.0f, 0};
    hairis_tables *baked = hairis_tables_bake(fiber, &o, on_progress, &progress);
    CHECK(baked != NULL, "tiny bake");
    CHECK_NO_ERROR();
    CHECK(progress.calls >= 2 && progress.last == 1.0f && !progress.decreasing,
          "progress: %d calls, last %g", progress.calls, progress.last);
    CHECK(strcmp(hairis_tables_model(baked), "chiang2016") == 0, "model \"%s\"",
          hairis_tables_model(baked));
    CHECK(strcmp(hairis_tables_parameters(baked), hairis_fiber_parameters(fiber)) == 0,
          "tables parameters \"%s\" = fiber's \"%s\"", hairis_tables_parameters(baked),
          hairis_fiber_parameters(fiber));
    CHECK(hairis_tables_match_fiber(baked, fiber) == 1, "matches its fiber");
    CHECK_NO_ERROR();

    /* A bake without a progress callback; the Gaussian source. */
    o.source = 1;
    hairis_tables *gaussian = hairis_tables_bake(fiber, &o, NULL, NULL);
    CHECK(gaussian != NULL, "gaussian-source bake");
    CHECK(gaussian && hairis_tables_match_fiber(gaussian, fiber) == 1,
          "the source does not change the fiber match");
    hairis_tables_destroy(gaussian);
    o.source = 0;

    /* Marschner tables. */
    {
        hairis_marschner_params m;
        hairis_marschner_defaults(&m);
        hairis_fiber *marschner = hairis_fiber_create_marschner(&m);
        hairis_bake_options mo;
        tiny_options(&mo);
        mo.theta_r_count = 2;
        hairis_tables *mt = hairis_tables_bake(marschner, &mo, NULL, NULL);
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
    hairis_tables *cancelled = hairis_tables_bake(fiber, &o, on_progress, &cancel);
    CHECK(cancelled == NULL, "cancelled bake returns NULL");
    CHECK(strcmp(hairis_last_error(), "cancelled") == 0, "the message is \"cancelled\"");
    CHECK(cancel.calls == 2, "no progress call after cancelling (%d calls)", cancel.calls);
    hairis_tables_destroy(cancelled);

    /* Bad options. */
    expect_bake_refused(NULL, &o, "fiber");
    expect_bake_refused(fiber, NULL, "options");
    hairis_bake_options bad = o;
    bad.theta_r_count = 0;
    expect_bake_refused(fiber, &bad, "theta_r_count");
    bad = o;
    bad.theta_i_count = 100000;
    expect_bake_refused(fiber, &bad, "theta_i_count");
    bad = o;
    bad.n_h_count = 17;
    expect_bake_refused(fiber, &bad, "n_h_count");
    bad = o;
    bad.n_h_count = 0;
    expect_bake_refused(fiber, &bad, "n_h_count");
    bad = o;
    bad.n_h_values[1] = 1;
    expect_bake_refused(fiber, &bad, "increasing");
    bad = o;
    bad.source = 2;
    expect_bake_refused(fiber, &bad, "source");
    bad = o;
    bad.threads = -1;
    expect_bake_refused(fiber, &bad, "threads");

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
    CHECK(from_file && strcmp(hairis_tables_parameters(from_file),
                              hairis_tables_parameters(baked)) == 0,
          "parameters survive the file");
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

    /* Corrupt and empty buffers, missing files. */
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
        hairis_principled_hair node;
        hairis_principled_hair_defaults(&node);
        node.roughness = 0.4f;
        hairis_fiber *rougher = hairis_fiber_create_principled(&node);
        CHECK(hairis_tables_match_fiber(baked, rougher) == 0, "another roughness: no match");
        CHECK_NO_ERROR();
        hairis_marschner_params m;
        hairis_marschner_defaults(&m);
        hairis_fiber *marschner = hairis_fiber_create_marschner(&m);
        CHECK(hairis_tables_match_fiber(baked, marschner) == 0, "another model: no match");
        CHECK(hairis_tables_match_fiber(NULL, fiber) == 0, "NULL tables");
        CHECK_ERROR_MENTIONS("tables");
        CHECK(hairis_tables_match_fiber(baked, NULL) == 0, "NULL fiber");
        CHECK_ERROR_MENTIONS("fiber");
        CHECK(strcmp(hairis_tables_model(NULL), "") == 0, "model of NULL");
        CHECK(strcmp(hairis_tables_parameters(NULL), "") == 0, "parameters of NULL");
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

static void check_sample_pdf_consistency(hairis_sampler *sampler, const char *name)
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
    hairis_fiber *chiang = default_chiang();
    hairis_marschner_params m;
    hairis_marschner_defaults(&m);
    hairis_fiber *marschner = hairis_fiber_create_marschner(&m);

    hairis_sampler *uniform_s = hairis_sampler_create(HAIRIS_STRATEGY_UNIFORM, NULL, NULL, 0, 1);
    CHECK(uniform_s != NULL, "UNIFORM without fiber or tables");
    CHECK_NO_ERROR();
    hairis_sampler *analytic = hairis_sampler_create(HAIRIS_STRATEGY_ANALYTIC, chiang, NULL,
                                                     0.25f, 2);
    CHECK(analytic != NULL, "ANALYTIC with a Chiang fiber");
    hairis_sampler *gaussian = hairis_sampler_create(HAIRIS_STRATEGY_GAUSSIAN, NULL, NULL,
                                                     0.25f, 2);
    CHECK(gaussian != NULL, "GAUSSIAN");
    hairis_sampler *table = hairis_sampler_create(HAIRIS_STRATEGY_TABLE, NULL, g_tables, 0.25f,
                                                  2);
    CHECK(table != NULL, "TABLE");
    /* With a Chiang fiber, TABLE follows the near field at h (near_field_table.h). */
    hairis_sampler *table_near = hairis_sampler_create(HAIRIS_STRATEGY_TABLE, chiang, g_tables,
                                                       0.25f, 2);
    CHECK(table_near != NULL, "TABLE with a Chiang fiber");

    /* A TABLE sampler stays valid after its tables handle is destroyed. */
    hairis_sampler *orphan = NULL;
    {
        hairis_fiber *fiber = default_chiang();
        hairis_bake_options o;
        tiny_options(&o);
        hairis_tables *t = hairis_tables_bake(fiber, &o, NULL, NULL);
        orphan = hairis_sampler_create(HAIRIS_STRATEGY_TABLE, NULL, t, 1.0f, 1);
        CHECK(orphan != NULL, "TABLE sampler from short-lived tables");
        hairis_tables_destroy(t);
        hairis_fiber_destroy(fiber);
    }

    /* Roughness 0, which Blender's slider allows: lobes narrower than a table cell, and TT's
       mass at grazing below the smallest double (the near-field table refused it once). */
    hairis_sampler *smooth = NULL;
    {
        hairis_principled_hair node;
        hairis_principled_hair_defaults(&node);
        node.roughness = 0.0f;
        hairis_fiber *fiber = hairis_fiber_create_principled(&node);
        hairis_bake_options o;
        tiny_options(&o);
        o.source = 1; /* the seed's Gaussians: fast, and enough for a sampler */
        hairis_tables *t = hairis_tables_bake(fiber, &o, NULL, NULL);
        smooth = hairis_sampler_create(HAIRIS_STRATEGY_TABLE, fiber, t, 0.0f, 1);
        CHECK(smooth != NULL, "TABLE with a fiber of roughness 0: %s", hairis_last_error());
        hairis_tables_destroy(t);
        hairis_fiber_destroy(fiber);
    }

    if (uniform_s) check_sample_pdf_consistency(uniform_s, "uniform");
    if (smooth) check_sample_pdf_consistency(smooth, "table with a fiber of roughness 0");
    if (analytic) check_sample_pdf_consistency(analytic, "analytic");
    if (gaussian) check_sample_pdf_consistency(gaussian, "gaussian");
    if (table) check_sample_pdf_consistency(table, "table");
    if (table_near) check_sample_pdf_consistency(table_near, "table with a fiber (near field)");
    if (orphan) check_sample_pdf_consistency(orphan, "table (tables destroyed)");

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
    CHECK(hairis_sampler_create(HAIRIS_STRATEGY_ANALYTIC, NULL, NULL, 0.25f, 2) == NULL,
          "ANALYTIC without fiber");
    CHECK_ERROR_MENTIONS("fiber");
    CHECK(hairis_sampler_create(HAIRIS_STRATEGY_ANALYTIC, marschner, NULL, 0.25f, 2) == NULL,
          "ANALYTIC with a Marschner fiber");
    CHECK_ERROR_MENTIONS("chiang2016");
    CHECK(hairis_sampler_create(HAIRIS_STRATEGY_TABLE, chiang, NULL, 0.25f, 2) == NULL,
          "TABLE without tables");
    CHECK_ERROR_MENTIONS("tables");
    CHECK(hairis_sampler_create(HAIRIS_STRATEGY_TABLE, NULL, g_tables, 0.25f, 8) == NULL,
          "TABLE with an n_h the tables lack");
    CHECK_ERROR_MENTIONS("n_h");
    CHECK(hairis_sampler_create(HAIRIS_STRATEGY_GAUSSIAN, NULL, NULL, 0.25f, 3) == NULL,
          "GAUSSIAN with n_h 3");
    CHECK_ERROR_MENTIONS("n_h");
    CHECK(hairis_sampler_create(HAIRIS_STRATEGY_GAUSSIAN, NULL, NULL, 1.5f, 2) == NULL,
          "weight 1.5");
    CHECK_ERROR_MENTIONS("multiple_weight");
    CHECK(hairis_sampler_create(HAIRIS_STRATEGY_UNIFORM, NULL, NULL, NAN, 2) == NULL,
          "weight NaN");
    CHECK_ERROR_MENTIONS("multiple_weight");
    CHECK(hairis_sampler_create((hairis_strategy)9, NULL, NULL, 0.25f, 2) == NULL,
          "strategy 9");
    CHECK_ERROR_MENTIONS("strategy");
    CHECK(hairis_sampler_create((hairis_strategy)-1, NULL, NULL, 0.25f, 2) == NULL,
          "strategy -1");
    CHECK_ERROR_MENTIONS("strategy");

    float wo[6] = {0, 1, 0, 0, 0, 1}, u[6] = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
    float wi[6], pdf[2];
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
    u[4] = 0.5f;
    wo[1] = NAN;
    CHECK(hairis_sample(uniform_s, 2, wo, NULL, u, wi, pdf) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "NaN wo");
    CHECK_ERROR_MENTIONS("wo item 0");
    CHECK(hairis_pdf(uniform_s, 2, wo, wo, NULL, pdf) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "pdf: NaN wi");
    CHECK_ERROR_MENTIONS("wi item 0");
    wo[1] = 1.0f;
    float bad_h[2] = {0.0f, -2.0f};
    CHECK(hairis_pdf(uniform_s, 2, wo, wo, bad_h, pdf) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "pdf: h out of range");
    CHECK_ERROR_MENTIONS("h[1]");

    hairis_sampler_destroy(uniform_s);
    hairis_sampler_destroy(analytic);
    hairis_sampler_destroy(gaussian);
    hairis_sampler_destroy(table);
    hairis_sampler_destroy(table_near);
    hairis_sampler_destroy(orphan);
    hairis_sampler_destroy(smooth);
    hairis_sampler_destroy(NULL);
    CHECK_NO_ERROR();
    hairis_fiber_destroy(chiang);
    hairis_fiber_destroy(marschner);
}

/* ---- Scenes and rendering ----------------------------------------------------------------- */

enum { W = 16, H = 16 };

static void test_camera(hairis_camera *camera)
{
    static const float to_world[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 3, 0, 0, 0, 1};
    /* view_frame order: top right, bottom right, bottom left, top left. */
    static const float frame[12] = {0.4f,  0.4f,  -1, 0.4f,  -0.4f, -1,
                                    -0.4f, -0.4f, -1, -0.4f, 0.4f,  -1};
    memset(camera, 0, sizeof *camera);
    memcpy(camera->camera_to_world, to_world, sizeof to_world);
    memcpy(camera->frame, frame, sizeof frame);
    camera->orthographic = 0;
    camera->width = W;
    camera->height = H;
}

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

static int add_floor(hairis_scene *scene, int material)
{
    const float positions[9] = {-3, -3, -0.5f, 3, -3, -0.5f, 0, 3, -0.5f};
    const uint32_t indices[3] = {0, 1, 2};
    const int32_t materials[1] = {material};
    return hairis_scene_add_mesh(scene, 3, positions, 1, indices, materials);
}

/* The test scene: hair (material 0, tables as given), a diffuse floor (material 1), a sun
 * and a world. */
static hairis_scene *make_scene(const hairis_principled_hair *node, const hairis_tables *tables)
{
    hairis_scene *scene = hairis_scene_create();
    CHECK(scene != NULL, "scene_create");
    CHECK_NO_ERROR();
    const int hair = hairis_scene_add_hair_material(scene, node, tables);
    CHECK(hair == 0, "hair material index %d", hair);
    const float albedo[3] = {0.5f, 0.5f, 0.5f}, black[3] = {0, 0, 0};
    const int diffuse = hairis_scene_add_diffuse_material(scene, albedo, black);
    CHECK(diffuse == 1, "diffuse material index %d", diffuse);
    CHECK(add_strands(scene, hair) == HAIRIS_OK, "curves");
    CHECK(add_floor(scene, diffuse) == HAIRIS_OK, "mesh");
    const float to_sun[3] = {0.3f, 0.2f, 1.0f}, white[3] = {1, 1, 1};
    CHECK(hairis_scene_add_sun(scene, to_sun, white, 3.0f, 0.05f) == HAIRIS_OK, "sun");
    const float sky[3] = {0.1f, 0.12f, 0.15f};
    CHECK(hairis_scene_set_world(scene, sky, 1.0f) == HAIRIS_OK, "world");
    hairis_camera camera;
    test_camera(&camera);
    CHECK(hairis_scene_set_camera(scene, &camera) == HAIRIS_OK, "camera");
    CHECK_NO_ERROR();
    return scene;
}

static void tiny_settings(hairis_render_settings *s, int strategy)
{
    hairis_render_settings_defaults(s);
    s->samples = 4;
    s->max_bounces = 3;
    s->strategy = strategy;
    s->seed = 7;
    s->threads = 2;
}

static int pixels_ok(const float *rgba)
{
    for (int i = 0; i < W * H; ++i) {
        if (!all_finite_non_negative(rgba + 4 * i, 4)) return 0;
        if (rgba[4 * i + 3] != 1.0f) return 0;
    }
    return 1;
}

static double pixel_sum(const float *rgba)
{
    double sum = 0;
    for (int i = 0; i < W * H; ++i) sum += rgba[4 * i] + rgba[4 * i + 1] + rgba[4 * i + 2];
    return sum;
}

typedef struct render_job {
    hairis_scene *scene;
    hairis_render_settings settings;
    float rgba[W * H * 4];
    int status;
} render_job;

static int render_in_thread(void *arg)
{
    render_job *job = (render_job *)arg;
    job->status = hairis_render(job->scene, &job->settings, job->rgba, NULL, NULL, NULL);
    return 0;
}

static void test_render(void)
{
    section("render");
    static float rgba[W * H * 4], again[W * H * 4];
    hairis_principled_hair node;
    hairis_principled_hair_defaults(&node);

    hairis_scene *scene = make_scene(&node, g_tables);
    const int strategies[4] = {HAIRIS_STRATEGY_UNIFORM, HAIRIS_STRATEGY_ANALYTIC,
                               HAIRIS_STRATEGY_GAUSSIAN, HAIRIS_STRATEGY_TABLE};
    for (int k = 0; k < 4; ++k) {
        hairis_render_settings s;
        tiny_settings(&s, strategies[k]);
        hairis_render_stats stats;
        memset(&stats, 0xff, sizeof stats);
        for (int i = 0; i < W * H * 4; ++i) rgba[i] = -1.0f;
        progress_state progress = {0, 0, -1.0f, 0};
        const int status = hairis_render(scene, &s, rgba, on_progress, &progress, &stats);
        CHECK(status == HAIRIS_OK, "render with strategy %d", strategies[k]);
        CHECK_NO_ERROR();
        CHECK(pixels_ok(rgba), "strategy %d: pixels finite, >= 0, alpha 1", strategies[k]);
        CHECK(pixel_sum(rgba) > 0.0, "strategy %d: the image is not black", strategies[k]);
        CHECK(stats.camera_rays == (uint64_t)W * H * 4, "camera rays %llu",
              (unsigned long long)stats.camera_rays);
        CHECK(stats.seconds > 0 && stats.seconds < 600, "seconds %g", stats.seconds);
        CHECK(stats.peak_memory_bytes > 0 && stats.peak_memory_bytes < (1ull << 40),
              "peak memory %llu", (unsigned long long)stats.peak_memory_bytes);
        CHECK(stats.dropped_samples == 0, "dropped %llu",
              (unsigned long long)stats.dropped_samples);
        CHECK(progress.calls >= 1 && progress.last == 1.0f, "progress ends at 1 (%d calls)",
              progress.calls);
    }

    /* Same seed, same image, whatever the thread count; stats may be NULL. */
    {
        hairis_render_settings s;
        tiny_settings(&s, HAIRIS_STRATEGY_TABLE);
        s.threads = 1;
        CHECK(hairis_render(scene, &s, again, NULL, NULL, NULL) == HAIRIS_OK, "1 thread");
        CHECK(memcmp(rgba, again, sizeof rgba) == 0, "bit-identical with 1 and 2 threads");
        s.seed = 8;
        CHECK(hairis_render(scene, &s, again, NULL, NULL, NULL) == HAIRIS_OK, "seed 8");
        CHECK(memcmp(rgba, again, sizeof rgba) != 0, "another seed, another image");
    }

    /* Two renders of one scene at once, from two threads, each as if alone. */
    {
        static render_job jobs[2];
        thrd_t threads[2];
        for (int t = 0; t < 2; ++t) {
            jobs[t].scene = scene;
            tiny_settings(&jobs[t].settings, HAIRIS_STRATEGY_TABLE);
            jobs[t].settings.threads = 1;
            thrd_create(&threads[t], render_in_thread, &jobs[t]);
        }
        hairis_render_settings s;
        tiny_settings(&s, HAIRIS_STRATEGY_TABLE);
        CHECK(hairis_render(scene, &s, again, NULL, NULL, NULL) == HAIRIS_OK, "reference");
        for (int t = 0; t < 2; ++t) {
            thrd_join(threads[t], NULL);
            CHECK(jobs[t].status == HAIRIS_OK && memcmp(jobs[t].rgba, again, sizeof again) == 0,
                  "concurrent render %d equals the reference", t);
        }
    }

    /* Cancelling from the progress callback. */
    {
        hairis_render_settings s;
        tiny_settings(&s, HAIRIS_STRATEGY_ANALYTIC);
        s.samples = 1 << 16; /* far more than can finish before the first callback */
        hairis_render_stats stats;
        progress_state cancel = {0, 1, -1.0f, 0};
        const int status = hairis_render(scene, &s, rgba, on_progress, &cancel, &stats);
        CHECK(status == HAIRIS_ERROR_CANCELLED, "cancelled render returns CANCELLED (%d)",
              status);
        CHECK_ERROR_MENTIONS("cancelled");
        CHECK(stats.camera_rays < (uint64_t)W * H * s.samples, "stopped early (%llu rays)",
              (unsigned long long)stats.camera_rays);
        CHECK(all_finite_non_negative(rgba, W * H * 4), "the partial image is finite");
    }

    /* Bad settings and arguments. */
    {
        hairis_render_settings s;
        tiny_settings(&s, HAIRIS_STRATEGY_ANALYTIC);
        s.samples = 0;
        CHECK(hairis_render(scene, &s, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "samples 0");
        CHECK_ERROR_MENTIONS("samples");
        tiny_settings(&s, 11);
        CHECK(hairis_render(scene, &s, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "strategy 11");
        CHECK_ERROR_MENTIONS("strategy");
        tiny_settings(&s, HAIRIS_STRATEGY_TABLE);
        s.multiple_weight = NAN;
        CHECK(hairis_render(scene, &s, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "weight NaN");
        CHECK_ERROR_MENTIONS("multiple_weight");
        tiny_settings(&s, HAIRIS_STRATEGY_TABLE);
        s.n_h = 4; /* not baked */
        CHECK(hairis_render(scene, &s, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_TABLE,
              "TABLE with an n_h the tables lack");
        CHECK_ERROR_MENTIONS("material 0");
        tiny_settings(&s, HAIRIS_STRATEGY_GAUSSIAN);
        s.n_h = 3;
        CHECK(hairis_render(scene, &s, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "GAUSSIAN with n_h 3");
        CHECK_ERROR_MENTIONS("n_h");
        tiny_settings(&s, HAIRIS_STRATEGY_ANALYTIC);
        s.max_bounces = -1;
        CHECK(hairis_render(scene, &s, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "max_bounces -1");
        CHECK_ERROR_MENTIONS("max_bounces");
        tiny_settings(&s, HAIRIS_STRATEGY_ANALYTIC);
        CHECK(hairis_render(NULL, &s, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "NULL scene");
        CHECK_ERROR_MENTIONS("scene");
        CHECK(hairis_render(scene, NULL, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "NULL settings");
        CHECK_ERROR_MENTIONS("settings");
        CHECK(hairis_render(scene, &s, NULL, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "NULL rgba");
        CHECK_ERROR_MENTIONS("rgba");
    }
    hairis_scene_destroy(scene);

    /* TABLE with a material that has no tables. */
    {
        hairis_scene *no_tables = make_scene(&node, NULL);
        hairis_render_settings s;
        tiny_settings(&s, HAIRIS_STRATEGY_TABLE);
        CHECK(hairis_render(no_tables, &s, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_TABLE,
              "TABLE without tables is refused");
        CHECK_ERROR_MENTIONS("material 0");
        CHECK_ERROR_MENTIONS("without tables");
        tiny_settings(&s, HAIRIS_STRATEGY_ANALYTIC);
        CHECK(hairis_render(no_tables, &s, rgba, NULL, NULL, NULL) == HAIRIS_OK,
              "ANALYTIC needs no tables");
        hairis_scene_destroy(no_tables);
    }

    /* TABLE with tables baked for other parameters. */
    {
        hairis_principled_hair other = node;
        other.roughness = 0.5f;
        hairis_scene *mismatch = make_scene(&other, g_tables);
        hairis_render_settings s;
        tiny_settings(&s, HAIRIS_STRATEGY_TABLE);
        CHECK(hairis_render(mismatch, &s, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_TABLE,
              "TABLE with mismatched tables is refused");
        CHECK_ERROR_MENTIONS("material 0");
        CHECK_ERROR_MENTIONS("baked for");
        tiny_settings(&s, HAIRIS_STRATEGY_UNIFORM);
        CHECK(hairis_render(mismatch, &s, rgba, NULL, NULL, NULL) == HAIRIS_OK,
              "UNIFORM ignores the tables");
        hairis_scene_destroy(mismatch);
    }

    /* An empty scene, a scene without camera. */
    {
        hairis_scene *empty = hairis_scene_create();
        hairis_camera camera;
        test_camera(&camera);
        hairis_render_settings s;
        tiny_settings(&s, HAIRIS_STRATEGY_ANALYTIC);
        CHECK(hairis_render(empty, &s, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "no camera");
        CHECK_ERROR_MENTIONS("camera");
        CHECK(hairis_scene_set_camera(empty, &camera) == HAIRIS_OK, "camera");
        const float white[3] = {1, 1, 1};
        CHECK(hairis_scene_set_world(empty, white, 1.0f) == HAIRIS_OK, "world");
        CHECK(hairis_render(empty, &s, rgba, NULL, NULL, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
              "empty scene");
        CHECK_ERROR_MENTIONS("empty");
        hairis_scene_destroy(empty);
    }

    /* Point and area lights, an emissive triangle, an orthographic camera. */
    {
        hairis_scene *lit = hairis_scene_create();
        const int hair = hairis_scene_add_hair_material(lit, &node, NULL);
        const float albedo[3] = {0.7f, 0.6f, 0.5f}, black[3] = {0, 0, 0}, glow[3] = {2, 2, 2};
        const int floor = hairis_scene_add_diffuse_material(lit, albedo, black);
        const int lamp = hairis_scene_add_diffuse_material(lit, black, glow);
        CHECK(hair == 0 && floor == 1 && lamp == 2, "material indices");
        CHECK(add_strands(lit, hair) == HAIRIS_OK, "curves");
        CHECK(add_floor(lit, floor) == HAIRIS_OK, "floor");
        const float lamp_positions[9] = {-1, -1, 2, 1, -1, 2, 0, 1, 2};
        const uint32_t lamp_indices[3] = {0, 2, 1};
        const int32_t lamp_materials[1] = {lamp};
        CHECK(hairis_scene_add_mesh(lit, 3, lamp_positions, 1, lamp_indices, lamp_materials) ==
                  HAIRIS_OK,
              "emissive triangle");
        const float position[3] = {1, 1, 2}, warm[3] = {1, 0.9f, 0.8f};
        CHECK(hairis_scene_add_point_light(lit, position, warm, 50.0f, 0.1f) == HAIRIS_OK,
              "point light");
        CHECK(hairis_scene_add_point_light(lit, position, warm, 20.0f, 0.0f) == HAIRIS_OK,
              "point light of radius 0");
        const float area_to_world[16] = {1, 0, 0, -1, 0, 1, 0, 0, 0, 0, 1, 2.5f, 0, 0, 0, 1};
        for (int shape = HAIRIS_AREA_SQUARE; shape <= HAIRIS_AREA_ELLIPSE; ++shape)
            CHECK(hairis_scene_add_area_light(lit, area_to_world, shape, 0.5f, 0.3f, warm,
                                              30.0f) == HAIRIS_OK,
                  "area light shape %d", shape);
        hairis_camera camera;
        test_camera(&camera);
        camera.orthographic = 1;
        const float ortho_frame[12] = {1.2f,  1.2f,  -1, 1.2f,  -1.2f, -1,
                                       -1.2f, -1.2f, -1, -1.2f, 1.2f,  -1};
        memcpy(camera.frame, ortho_frame, sizeof ortho_frame);
        CHECK(hairis_scene_set_camera(lit, &camera) == HAIRIS_OK, "orthographic camera");
        hairis_render_settings s;
        tiny_settings(&s, HAIRIS_STRATEGY_ANALYTIC);
        CHECK(hairis_render(lit, &s, rgba, NULL, NULL, NULL) == HAIRIS_OK, "lit render");
        CHECK(pixels_ok(rgba) && pixel_sum(rgba) > 0.0, "lit pixels finite, >= 0, not black");
        hairis_scene_destroy(lit);
    }
}

static void test_scene_refusals(void)
{
    section("scene refusals");
    hairis_scene *scene = hairis_scene_create();
    hairis_principled_hair node;
    hairis_principled_hair_defaults(&node);
    const float white[3] = {1, 1, 1}, black[3] = {0, 0, 0};

    node.roughness = -1.0f;
    CHECK(hairis_scene_add_hair_material(scene, &node, NULL) == -1, "bad node");
    CHECK_ERROR_MENTIONS("node.roughness");
    hairis_principled_hair_defaults(&node);
    CHECK(hairis_scene_add_hair_material(NULL, &node, NULL) == -1, "NULL scene");
    CHECK_ERROR_MENTIONS("scene");
    CHECK(hairis_scene_add_hair_material(scene, NULL, NULL) == -1, "NULL node");
    CHECK_ERROR_MENTIONS("node");
    const float too_bright[3] = {0.5f, 1.5f, 0.5f};
    CHECK(hairis_scene_add_diffuse_material(scene, too_bright, black) == -1, "albedo > 1");
    CHECK_ERROR_MENTIONS("albedo[1]");
    const float negative[3] = {0, -1, 0};
    CHECK(hairis_scene_add_diffuse_material(scene, white, negative) == -1, "negative emission");
    CHECK_ERROR_MENTIONS("emission[1]");

    const int hair = hairis_scene_add_hair_material(scene, &node, NULL);
    const int diffuse = hairis_scene_add_diffuse_material(scene, white, black);
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
    CHECK(hairis_scene_add_mesh(scene, 3, tri, 1, indices, materials) == HAIRIS_OK,
          "mesh: valid");

    const float zero[3] = {0, 0, 0}, up[3] = {0, 0, 1}, nan3[3] = {NAN, 0, 1};
    CHECK(hairis_scene_add_sun(scene, zero, white, 1, 0) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "sun: zero direction");
    CHECK_ERROR_MENTIONS("direction");
    CHECK(hairis_scene_add_sun(scene, nan3, white, 1, 0) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "sun: NaN direction");
    CHECK_ERROR_MENTIONS("direction[0]");
    CHECK(hairis_scene_add_sun(scene, up, white, -1, 0) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "sun: negative strength");
    CHECK_ERROR_MENTIONS("strength");
    CHECK(hairis_scene_add_sun(scene, up, white, 1, 4.0f) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "sun: angle >= pi");
    CHECK_ERROR_MENTIONS("angle");
    CHECK(hairis_scene_add_sun(scene, up, negative, 1, 0) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "sun: negative colour");
    CHECK_ERROR_MENTIONS("color[1]");
    CHECK(hairis_scene_add_point_light(scene, up, white, 10, -1) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "point: negative radius");
    CHECK_ERROR_MENTIONS("radius");
    CHECK(hairis_scene_add_point_light(scene, nan3, white, 10, 0) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "point: NaN position");
    CHECK_ERROR_MENTIONS("position");
    CHECK(hairis_scene_add_point_light(scene, up, white, INFINITY, 0) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "point: infinite power");
    CHECK_ERROR_MENTIONS("power");
    const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const float flat[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1};
    CHECK(hairis_scene_add_area_light(scene, identity, 7, 1, 1, white, 10) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "area: shape 7");
    CHECK_ERROR_MENTIONS("shape");
    CHECK(hairis_scene_add_area_light(scene, flat, HAIRIS_AREA_DISK, 1, 1, white, 10) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "area: zero Z axis");
    CHECK_ERROR_MENTIONS("light_to_world");
    CHECK(hairis_scene_add_area_light(scene, identity, HAIRIS_AREA_DISK, -1, 1, white, 10) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "area: negative size");
    CHECK_ERROR_MENTIONS("size_x");
    CHECK(hairis_scene_add_area_light(scene, NULL, HAIRIS_AREA_DISK, 1, 1, white, 10) ==
              HAIRIS_ERROR_INVALID_ARGUMENT,
          "area: NULL matrix");
    CHECK_ERROR_MENTIONS("light_to_world");
    CHECK(hairis_scene_set_world(scene, white, -2) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "world: negative strength");
    CHECK_ERROR_MENTIONS("strength");
    CHECK(hairis_scene_set_world(scene, NULL, 1) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "world: NULL colour");
    CHECK_ERROR_MENTIONS("color");

    hairis_camera camera;
    test_camera(&camera);
    camera.width = 0;
    CHECK(hairis_scene_set_camera(scene, &camera) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "camera: width 0");
    CHECK_ERROR_MENTIONS("width");
    test_camera(&camera);
    camera.orthographic = 2;
    CHECK(hairis_scene_set_camera(scene, &camera) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "camera: orthographic 2");
    CHECK_ERROR_MENTIONS("orthographic");
    test_camera(&camera);
    camera.frame[0] = NAN;
    CHECK(hairis_scene_set_camera(scene, &camera) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "camera: NaN frame");
    CHECK_ERROR_MENTIONS("frame");
    test_camera(&camera);
    /* Corners in the wrong order (top left first). */
    const float wrong[12] = {-0.4f, 0.4f, -1, 0.4f, 0.4f,  -1,
                             0.4f,  -0.4f, -1, -0.4f, -0.4f, -1};
    memcpy(camera.frame, wrong, sizeof wrong);
    CHECK(hairis_scene_set_camera(scene, &camera) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "camera: corners out of order");
    CHECK_ERROR_MENTIONS("frame");
    CHECK(hairis_scene_set_camera(scene, NULL) == HAIRIS_ERROR_INVALID_ARGUMENT,
          "camera: NULL");
    CHECK_ERROR_MENTIONS("camera");
    hairis_scene_destroy(scene);
    hairis_scene_destroy(NULL);
    CHECK_NO_ERROR();
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--layout") == 0) {
        print_layout();
        return 0;
    }
    const char *temp_dir = getenv("TMPDIR");
    if (!temp_dir || !*temp_dir) temp_dir = "/tmp";

    test_library();
    test_defaults();
    test_fiber_creation();
    test_fiber_eval();
    test_tables(temp_dir);
    if (g_tables) {
        test_sampling();
        test_render();
    } else {
        CHECK(0, "no tables: the sampling and render tests cannot run");
    }
    test_scene_refusals();
    hairis_tables_destroy(g_tables);

    printf("%d passed, %d failed\n", g_passed, g_failed);
    return g_failed == 0 ? 0 : 1;
}
