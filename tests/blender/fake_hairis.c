/* A stand-in for libhairis used by the Blender add-on tests.
 *
 * It implements every function of lib/include/hairis/hairis.h and hairis_render.h (compiled
 * against them, so the compiler checks the signatures) with trivial physics: the render is
 * the world radiance (every camera ray misses), the sampler is uniform. It keeps the real
 * API's conventions: thread-local last error, option strings "name=value;..." whose names are
 * those of hairis_defaults (the same strings the real library lists; unknown and repeated
 * names are refused, naming them and listing the known ones), argument checks, progress
 * callbacks that cancel, table files that round-trip and match fibers by their parameter
 * string, and TABLE renders refused with HAIRIS_ERROR_INVALID_TABLE naming the material.
 *
 * Test hooks (environment variables):
 *   HAIRIS_FAKE_API_VERSION   value returned by hairis_api_version (default HAIRIS_API_VERSION)
 *   HAIRIS_FAKE_ROW_DELAY_MS  sleep per rendered row (to test cancelling; hairis_render_progressive
 *                             calls its update before every row, with samples_done 0 until the end)
 *   HAIRIS_FAKE_SUMMARY       hairis_render appends a summary of the scene to this file
 *   HAIRIS_FAKE_NOISE         relative noise of the rendered pixels (default 0: exact)
 */
#define _POSIX_C_SOURCE 200809L
#include "hairis/hairis.h"
#include "hairis/hairis_render.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static _Thread_local char last_error[2048];
static _Thread_local char defaults_text[1024];
static _Thread_local char render_stats[512];

static void clear_error(void) { last_error[0] = '\0'; }

static int fail(int code, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    vsnprintf(last_error, sizeof last_error, format, args);
    va_end(args);
    return code;
}

static void sleep_ms(int ms)
{
    if (ms <= 0) return;
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- Option strings ----------------------------------------------------------------------- */

/* Each kind's names with their defaults, as the real library's hairis_defaults lists them. */
static const char *const kinds[][2] = {
    {"chiang", "model=chiang;cycles=3.4;parametrization=color;"
               "color=0.0175129995,0.00576299988,0.00205900008;tint=1,1,1;"
               "absorption=0.245530993,0.519999981,1.36500001;melanin=0.800000012;"
               "melanin_redness=1;roughness=0.300000012;radial_roughness=0.300000012;coat=0;"
               "ior=1.54999995;offset=0.0349065848;random_color=0;random_roughness=0;random=0"},
    {"huang", "model=huang;parametrization=color;"
              "color=0.0175129995,0.00576299988,0.00205900008;tint=1,1,1;"
              "absorption=0.245530993,0.519999981,1.36500001;melanin=0.800000012;"
              "melanin_redness=1;roughness=0.300000012;ior=1.54999995;offset=0.0349065848;"
              "random_color=0;random_roughness=0;random=0;aspect_ratio=0.850000024;reflection=1;"
              "transmission=1;secondary_reflection=1"},
    {"marschner", "model=marschner;sigma_a=0.150000006,0.200000003,0.300000012;eta=1.55;"
                  "alpha_r_deg=-7.5;alpha_tt_deg=3.75;alpha_trt_deg=11.25;beta_r_deg=7.5;"
                  "beta_tt_deg=3.725;beta_trt_deg=15;eccentricity=0.9;glint_scale=0.4;"
                  "caustic_width_deg=1.5;caustic_fade=0.3;caustic_limit=0.5"},
    {"bake", "theta_r=31;theta_i=64;phi=64;n_h=1,2,4,8,16;source=exact;quadrature_points=2;"
             "threads=0;huang_theta_o=24;huang_phi_o=4;huang_theta_i=48;huang_phi=64"},
    {"sampler", "strategy=table;multiple_weight=0;n_h=2"},
    {"diffuse", "type=diffuse;color=0.800000012,0.800000012,0.800000012;emission=0,0,0;"
                "roughness=0;color_texture=-1;cycles=3.4"},
    {"principled", "type=principled;cycles=3.4;distribution=ggx;"
                   "base_color=0.800000012,0.800000012,0.800000012;base_color_texture=-1;"
                   "metallic=0;roughness=0.5;ior=1.45000005;specular=0.5;specular_tint=0;"
                   "specular_tint_color=1,1,1;subsurface=0;"
                   "subsurface_color=0.800000012,0.800000012,0.800000012;sheen=0;sheen_tint=0.5;"
                   "coat=0;coat_roughness=0.0299999993;coat_ior=1.5;coat_tint=1,1,1;"
                   "diffuse_roughness=0;emission=0,0,0"},
    {"glossy", "type=glossy;color=0.800000012,0.800000012,0.800000012;color_texture=-1;"
               "roughness=0.5;distribution=ggx;cycles=3.4"},
    {"emission", "type=emission;color=1,1,1;strength=1"},
    {"mix", "type=mix;factor=0.5;shader1=-1;shader2=-1"},
    {"add", "type=add;shader1=-1;shader2=-1"},
    {"texture", "image=;color_space=auto;interpolation=linear;extension=repeat;mapping=none;"
                "location=0,0,0;rotation=0,0,0;scale=1,1,1"},
    {"sun", "type=sun;direction=0,0,1;color=1,1,1;strength=1;angle=0;cycles=3.4"},
    {"point", "type=point;position=0,0,0;color=1,1,1;power=10;radius=0;cycles=3.4;soft_falloff=1"},
    {"spot", "type=spot;matrix=1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1;color=1,1,1;power=10;radius=0;"
             "spot_size=0.785398185;spot_blend=0.150000006;cycles=3.4;soft_falloff=1"},
    {"area", "type=area;matrix=1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1;shape=square;size=1;size_y=1;"
             "color=1,1,1;power=10;cycles=3.4"},
    {"world", "color=0,0,0;strength=1;image=;color_space=auto;"
              "matrix=1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1;mapping=point;rotation=0,0,0;scale=1,1,1;"
              "sampling=auto;map_resolution=1024"},
    {"camera", "matrix=1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1;orthographic=0;"
               "frame=0.5,0.5,-1,0.5,-0.5,-1,-0.5,-0.5,-1,-0.5,0.5,-1;width=64;height=64;"
               "clip_start=0;clip_end=3.40282347e+38"},
    {"render", "integrator=path;samples=64;max_bounces=12;max_diffuse_bounces=4;max_glossy_bounces=4;"
               "max_transmission_bounces=12;max_transparent_bounces=8;transparent_limit=plus_one;"
               "seed=0;threads=0;tile_size=16;rr_start_bounce=2;film_transparent=0;"
               "huang_sampling=strategy;dual_hair_volume=layer;dual_exact_bounces=3;"
               "dual_bounce_limit=bounces;time_limit=0;adaptive_threshold=0;"
               "adaptive_min_samples=0;region=0,0,0,0;passes=;filter_glossy=0;clamp_direct=0;"
               "clamp_indirect=0;pixel_filter=box;pixel_filter_width=1;exposure=1;strategy=table;"
               "multiple_weight=0;n_h=2;"
               "curve_backfaces=ignore;curve_shape=thick;bvh_quality=medium;curve_subdivisions=2"},
    {"curve_inputs", "color=material;melanin=material;melanin_redness=material;tint=material;"
                     "absorption=material;roughness=material;radial_roughness=material;"
                     "coat=material;ior=material;offset=material;random_color=material;"
                     "random_roughness=material;random=material;weight0=material;"
                     "weight1=material;weight2=material;weight3=material;weight4=material;"
                     "weight5=material;weight6=material;weight7=material"},
    {"curves", ""},
};
enum { KIND_COUNT = sizeof kinds / sizeof kinds[0] };

static const char *defaults_of(const char *kind)
{
    for (int k = 0; k < KIND_COUNT; ++k)
        if (strcmp(kinds[k][0], kind) == 0) return kinds[k][1];
    return NULL;
}

enum { MAX_ITEMS = 48, NAME_SIZE = 64, VALUE_SIZE = 512 };

typedef struct option_item {
    char name[NAME_SIZE];
    char value[VALUE_SIZE];
} option_item;

/* An option string's items: its own (given) over the kind's defaults (known). */
typedef struct options {
    const char *what;
    option_item known[MAX_ITEMS];
    int known_count;
    int given[MAX_ITEMS]; /* per known item: given in the string */
} options;

static void trim(char *s)
{
    size_t n = strlen(s), a = 0;
    while (a < n && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r' || s[a] == '\n')) ++a;
    while (n > a && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r' || s[n - 1] == '\n'))
        --n;
    memmove(s, s + a, n - a);
    s[n - a] = '\0';
}

/* Calls f(name, value) for each item of "name=value;..."; stops at an error (returned). */
typedef int (*item_fn)(options *o, const char *name, const char *value);

static int for_each_item(const char *text, options *o, item_fn f)
{
    const char *p = text ? text : "";
    while (1) {
        const char *end = strchr(p, ';');
        const size_t length = end ? (size_t)(end - p) : strlen(p);
        char item[NAME_SIZE + VALUE_SIZE + 2];
        if (length >= sizeof item)
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "%s: an item is too long for the fake",
                        o->what);
        memcpy(item, p, length);
        item[length] = '\0';
        trim(item);
        if (item[0] != '\0') {
            char *eq = strchr(item, '=');
            if (!eq) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "%s: \"%s\" is not name=value", o->what, item);
            *eq = '\0';
            char *name = item, *value = eq + 1;
            trim(name);
            trim(value);
            if (name[0] == '\0')
                return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "%s: \"=%s\" has no name before '='",
                            o->what, value);
            const int status = f(o, name, value);
            if (status != HAIRIS_OK) return status;
        }
        if (!end) return HAIRIS_OK;
        p = end + 1;
    }
}

static int add_known(options *o, const char *name, const char *value)
{
    if (o->known_count >= MAX_ITEMS) return fail(HAIRIS_ERROR_INTERNAL, "fake: too many names");
    snprintf(o->known[o->known_count].name, NAME_SIZE, "%s", name);
    snprintf(o->known[o->known_count].value, VALUE_SIZE, "%s", value);
    o->given[o->known_count] = 0;
    ++o->known_count;
    return HAIRIS_OK;
}

static int set_given(options *o, const char *name, const char *value)
{
    for (int i = 0; i < o->known_count; ++i) {
        if (strcmp(o->known[i].name, name) != 0) continue;
        if (o->given[i])
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "%s: %s is given twice", o->what, name);
        o->given[i] = 1;
        snprintf(o->known[i].value, VALUE_SIZE, "%s", value);
        return HAIRIS_OK;
    }
    char list[1024] = "";
    for (int i = 0; i < o->known_count; ++i) {
        const size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s %s", i ? "," : "", o->known[i].name);
    }
    return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "%s: unknown option \"%s\" (known:%s)", o->what, name,
                list);
}

/* Reads `text` as options of `kind` (plus `extra`, a name with its default, or NULL). */
static int read_options(const char *text, const char *kind, const char *what, const char *extra,
                        options *o)
{
    memset(o, 0, sizeof *o);
    o->what = what;
    int status = for_each_item(defaults_of(kind), o, add_known);
    if (status == HAIRIS_OK && extra) {
        char name[NAME_SIZE];
        snprintf(name, sizeof name, "%s", extra);
        char *eq = strchr(name, '=');
        *eq = '\0';
        status = add_known(o, name, eq + 1);
    }
    return status == HAIRIS_OK ? for_each_item(text, o, set_given) : status;
}

/* The value of the first item called `name` in "name=value;..." ("" when absent). */
static void find_value(const char *text, const char *name, char *out, size_t size)
{
    out[0] = '\0';
    const char *p = text ? text : "";
    while (*p) {
        const char *end = strchr(p, ';');
        const size_t length = end ? (size_t)(end - p) : strlen(p);
        char item[NAME_SIZE + VALUE_SIZE + 2];
        snprintf(item, sizeof item, "%.*s", (int)(length < sizeof item ? length : sizeof item - 1), p);
        char *eq = strchr(item, '=');
        if (eq) {
            *eq = '\0';
            trim(item);
            trim(eq + 1);
            if (strcmp(item, name) == 0) {
                snprintf(out, size, "%s", eq + 1);
                return;
            }
        }
        if (!end) return;
        p = end + 1;
    }
}

static const char *value_of(const options *o, const char *name)
{
    for (int i = 0; i < o->known_count; ++i)
        if (strcmp(o->known[i].name, name) == 0) return o->known[i].value;
    return "";
}

static int given(const options *o, const char *name)
{
    for (int i = 0; i < o->known_count; ++i)
        if (strcmp(o->known[i].name, name) == 0) return o->given[i];
    return 0;
}

/* `count` finite numbers separated by ','. */
static int numbers(const options *o, const char *name, double *out, int count)
{
    const char *p = value_of(o, name);
    for (int k = 0; k < count; ++k) {
        char *end = NULL;
        errno = 0;
        out[k] = strtod(p, &end);
        while (end && *end == ' ') ++end;
        const char want = k + 1 < count ? ',' : '\0';
        if (end == p || !end || *end != want || !isfinite(out[k]))
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "%s: %s must be %d finite number%s (got \"%s\")",
                        o->what, name, count, count > 1 ? "s separated by ','" : "",
                        value_of(o, name));
        p = end + (want ? 1 : 0);
    }
    return HAIRIS_OK;
}

static int number_in(const options *o, const char *name, double lo, double hi, double *out)
{
    if (numbers(o, name, out, 1) != HAIRIS_OK) return HAIRIS_ERROR_INVALID_ARGUMENT;
    if (*out < lo || *out > hi)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "%s: %s must be in [%g, %g] (got %s)", o->what,
                    name, lo, hi, value_of(o, name));
    return HAIRIS_OK;
}

static int integer_in(const options *o, const char *name, long long lo, long long hi, long long *out)
{
    const char *text = value_of(o, name);
    char *end = NULL;
    errno = 0;
    *out = strtoll(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE || *out < lo || *out > hi)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "%s: %s must be an integer in [%lld, %lld] (got \"%s\")",
                    o->what, name, lo, hi, text);
    return HAIRIS_OK;
}

/* One of `count` words; *out receives its index. */
static int word(const options *o, const char *name, const char *const *words, int count, int *out)
{
    const char *text = value_of(o, name);
    char allowed[256] = "";
    for (int k = 0; k < count; ++k) {
        if (strcmp(text, words[k]) == 0) {
            *out = k;
            return HAIRIS_OK;
        }
        const size_t used = strlen(allowed);
        snprintf(allowed + used, sizeof allowed - used, "%s%s", k ? ", " : "", words[k]);
    }
    return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "%s: %s must be one of %s (got \"%s\")", o->what, name,
                allowed, text);
}

/* ---- Library ------------------------------------------------------------------------------ */

int hairis_api_version(void)
{
    clear_error();
    const char *override = getenv("HAIRIS_FAKE_API_VERSION");
    return override ? atoi(override) : HAIRIS_API_VERSION;
}

const char *hairis_version_string(void)
{
    clear_error();
    return "0.0.0-fake";
}

const char *hairis_last_error(void) { return last_error; }

const char *hairis_defaults(const char *kind)
{
    if (!kind) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "kind must not be NULL");
        return NULL;
    }
    const char *d = defaults_of(kind);
    if (!d) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT,
             "kind must be one of chiang, huang, marschner, bake, sampler, render, diffuse, principled, "
             "glossy, emission, mix, add, texture, sun, point, spot, area, world, camera, curve_inputs, "
             "curves (got \"%s\")",
             kind);
        return NULL;
    }
    snprintf(defaults_text, sizeof defaults_text, "%s", d);
    clear_error();
    return defaults_text;
}

/* ---- Fibers ------------------------------------------------------------------------------- */

struct hairis_fiber {
    char model[32];
    char parameters[1024];
    int chiang, huang;
};

/* Every number of a value printed as a float ("%.9g"), words as they are: equal inputs give
 * equal parameter strings. */
static void canonical_value(const char *value, char *out, size_t size)
{
    out[0] = '\0';
    const char *p = value;
    while (1) {
        char *end = NULL;
        const double v = strtod(p, &end);
        if (end == p || (*end != ',' && *end != '\0')) {
            snprintf(out, size, "%s", value); /* not a list of numbers */
            return;
        }
        const size_t used = strlen(out);
        snprintf(out + used, size - used, "%s%.9g", used ? "," : "", (double)(float)v);
        if (*end == '\0') return;
        p = end + 1;
    }
}

hairis_fiber *hairis_fiber_create(const char *text)
{
    /* The model picks the names. */
    char model_name[64];
    find_value(text, "model", model_name, sizeof model_name);
    const int marschner = strcmp(model_name, "marschner") == 0;
    const int huang = strcmp(model_name, "huang") == 0;
    options o;
    if (read_options(text, marschner ? "marschner" : huang ? "huang" : "chiang", "fiber options",
                     marschner ? NULL : "offset_deg=2", &o) != HAIRIS_OK)
        return NULL;
    const char *models[3] = {"chiang", "marschner", "huang"};
    int model = 0;
    if (word(&o, "model", models, 3, &model) != HAIRIS_OK) return NULL;
    double v[3];
    if (huang) {
        const char *scalars[] = {"aspect_ratio", "reflection", "transmission", "secondary_reflection"};
        double lobes = 0.0;
        for (size_t k = 0; k < sizeof scalars / sizeof scalars[0]; ++k) {
            if (numbers(&o, scalars[k], v, 1) != HAIRIS_OK) return NULL;
            if (k > 0 && v[0] > 0.0) lobes += v[0];
            if (k == 0 && !(v[0] > 0.0)) {
                fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber options: aspect_ratio must be in (0, 1000] (got %g)", v[0]);
                return NULL;
            }
        }
        if (!(lobes > 0.0)) {
            fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                 "fiber options: reflection, transmission and secondary_reflection are all <= 0: Cycles "
                 "allocates no closure then");
            return NULL;
        }
    }
    if (!marschner) {
        const char *parametrizations[3] = {"absorption", "melanin", "color"};
        int p = 0;
        if (word(&o, "parametrization", parametrizations, 3, &p) != HAIRIS_OK) return NULL;
        const char *vectors[3] = {"color", "tint", "absorption"};
        for (int k = 0; k < 3; ++k)
            if (numbers(&o, vectors[k], v, 3) != HAIRIS_OK) return NULL;
        const char *scalars[] = {"cycles", "melanin", "melanin_redness", "roughness",
                                 "radial_roughness", "coat", "ior", "offset", "offset_deg",
                                 "random_color", "random_roughness", "random"};
        for (size_t k = 0; k < sizeof scalars / sizeof scalars[0]; ++k) {
            const int chiang_only = k == 0 || k == 4 || k == 5;
            if ((!huang || !chiang_only) && numbers(&o, scalars[k], v, 1) != HAIRIS_OK) return NULL;
        }
        numbers(&o, "ior", v, 1);
        if (!(v[0] > 1.0)) {
            fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber options: ior: IOR must be > 1, got %g", v[0]);
            return NULL;
        }
        if (number_in(&o, "roughness", 0.0, 1.0, v) != HAIRIS_OK) {
            fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber options: roughness: Roughness must be in [0, 1], got %s",
                 value_of(&o, "roughness"));
            return NULL;
        }
        if (given(&o, "offset") && given(&o, "offset_deg")) {
            fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber options: offset and offset_deg set the same angle: give one");
            return NULL;
        }
    } else {
        if (numbers(&o, "sigma_a", v, 3) != HAIRIS_OK) return NULL;
        for (int i = 0; i < o.known_count; ++i)
            if (strcmp(o.known[i].name, "model") != 0 && strcmp(o.known[i].name, "sigma_a") != 0 &&
                numbers(&o, o.known[i].name, v, 1) != HAIRIS_OK)
                return NULL;
        numbers(&o, "eta", v, 1);
        if (!(v[0] > 1.0)) {
            fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber options: eta must be > 1, got %g", v[0]);
            return NULL;
        }
    }
    hairis_fiber *f = calloc(1, sizeof *f);
    if (!f) {
        fail(HAIRIS_ERROR_INTERNAL, "hairis_fiber_create: out of memory");
        return NULL;
    }
    snprintf(f->model, sizeof f->model, "%s",
             marschner ? "marschner2003" : huang ? "huang2022" : "chiang2016");
    f->chiang = !marschner && !huang;
    f->huang = huang;
    /* The parameters: every name but model (offset_deg as offset), canonical numbers. */
    for (int i = 0; i < o.known_count; ++i) {
        const char *name = o.known[i].name;
        if (strcmp(name, "model") == 0 || strcmp(name, "offset_deg") == 0) continue;
        char value[VALUE_SIZE];
        if (strcmp(name, "offset") == 0 && given(&o, "offset_deg")) {
            numbers(&o, "offset_deg", v, 1);
            snprintf(value, sizeof value, "%.9g", (double)(float)(v[0] * 3.14159265358979 / 180.0));
        } else {
            canonical_value(o.known[i].value, value, sizeof value);
        }
        const size_t used = strlen(f->parameters);
        snprintf(f->parameters + used, sizeof f->parameters - used, "%s%s=%s", used ? ";" : "", name,
                 value);
    }
    clear_error();
    return f;
}

void hairis_fiber_destroy(hairis_fiber *fiber)
{
    free(fiber);
    clear_error();
}

/* A string of a handle, as the library's getters return it: "" and an error for a NULL handle. */
static const char *handle_string(const void *handle, const char *name, const char *s)
{
    if (!handle) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "%s must not be NULL", name);
        return "";
    }
    clear_error();
    return s;
}

const char *hairis_fiber_model(const hairis_fiber *fiber)
{
    return handle_string(fiber, "fiber", fiber ? fiber->model : "");
}

const char *hairis_fiber_parameters(const hairis_fiber *fiber)
{
    return handle_string(fiber, "fiber", fiber ? fiber->parameters : "");
}

/* The fake's f·|cos θ_i|: grey, 0.1 cos θ_i, fading with |h|. */
static void fake_f(size_t n, const float *wi, const float *h, float *rgb_out)
{
    for (size_t i = 0; i < n; ++i) {
        float cos_theta = sqrtf(fmaxf(0.0f, 1.0f - wi[3 * i] * wi[3 * i]));
        float value = 0.1f * cos_theta * (h ? 1.0f - fabsf(h[i]) : 1.0f);
        rgb_out[3 * i] = rgb_out[3 * i + 1] = rgb_out[3 * i + 2] = value;
    }
}

int hairis_fiber_eval(const hairis_fiber *fiber, size_t n, const float *wi, const float *wo,
                      const float *h, float *rgb_out)
{
    if (!fiber || (n && (!wi || !wo || !rgb_out)))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber, wi, wo and rgb_out must not be NULL");
    if (h && !fiber->chiang)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "h must be NULL for a %s fiber", fiber->model);
    /* (Huang's frame has the ellipse's major axis as y: the fake ignores it.) */
    fake_f(n, wi, h, rgb_out);
    clear_error();
    return HAIRIS_OK;
}

/* ---- Tables ------------------------------------------------------------------------------- */

struct hairis_tables {
    char model[32];
    char parameters[1024];
    char info[256];
};

#define FAKE_MAGIC "HAIRISFAKE"

hairis_tables *hairis_tables_bake(const hairis_fiber *fiber, const char *text,
                                  hairis_progress_fn progress, void *user)
{
    if (!fiber) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber must not be NULL");
        return NULL;
    }
    options o;
    if (read_options(text, "bake", "bake options", NULL, &o) != HAIRIS_OK) return NULL;
    long long theta_r, theta_i, phi, threads, points, huang_theta_o, huang_phi_o, huang_theta_i, huang_phi;
    if (integer_in(&o, "huang_theta_o", 1, 1024, &huang_theta_o) != HAIRIS_OK ||
        integer_in(&o, "huang_phi_o", 1, 256, &huang_phi_o) != HAIRIS_OK ||
        integer_in(&o, "huang_theta_i", 1, 4096, &huang_theta_i) != HAIRIS_OK ||
        integer_in(&o, "huang_phi", 1, 4096, &huang_phi) != HAIRIS_OK ||
        integer_in(&o, "theta_r", 1, 1024, &theta_r) != HAIRIS_OK ||
        integer_in(&o, "theta_i", 2, 4096, &theta_i) != HAIRIS_OK ||
        integer_in(&o, "phi", 1, 4096, &phi) != HAIRIS_OK ||
        integer_in(&o, "threads", 0, 1024, &threads) != HAIRIS_OK ||
        integer_in(&o, "quadrature_points", 1, 16, &points) != HAIRIS_OK)
        return NULL;
    const char *sources[2] = {"exact", "gaussian"};
    int source = 0;
    if (word(&o, "source", sources, 2, &source) != HAIRIS_OK) return NULL;
    if (fiber->huang && source != 0) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "source must be \"exact\" for a huang2022 fiber (got \"%s\")",
             sources[source]);
        return NULL;
    }
    /* n_h: 1 to 16 increasing integers. */
    int n_h_count = 0, previous = 0;
    const char *p = value_of(&o, "n_h");
    while (1) {
        char *end = NULL;
        const long value = strtol(p, &end, 10);
        if (end == p || (*end != ',' && *end != '\0') || value < 1 || value > 1024 || n_h_count == 16) {
            fail(HAIRIS_ERROR_INVALID_ARGUMENT, "bake options: n_h must be 1 to 16 integers in [1, 1024] (got \"%s\")",
                 value_of(&o, "n_h"));
            return NULL;
        }
        if (n_h_count > 0 && value <= previous) {
            fail(HAIRIS_ERROR_INVALID_ARGUMENT, "bake options: n_h must be increasing (got \"%s\")", value_of(&o, "n_h"));
            return NULL;
        }
        previous = (int)value;
        ++n_h_count;
        if (*end == '\0') break;
        p = end + 1;
    }
    for (int step = 0; step <= 20; ++step) {
        if (progress && progress(user, (float)step / 20.0f)) {
            fail(HAIRIS_ERROR_CANCELLED, "cancelled");
            return NULL;
        }
        sleep_ms(2);
    }
    hairis_tables *t = calloc(1, sizeof *t);
    if (!t) {
        fail(HAIRIS_ERROR_INTERNAL, "hairis_tables_bake: out of memory");
        return NULL;
    }
    memcpy(t->model, fiber->model, sizeof t->model);
    memcpy(t->parameters, fiber->parameters, sizeof t->parameters);
    if (fiber->huang)
        snprintf(t->info, sizeof t->info, "source=exact;huang_theta_o=%lld;huang_phi_o=%lld;huang_theta_i=%lld;"
                 "huang_phi=%lld", huang_theta_o, huang_phi_o, huang_theta_i, huang_phi);
    else
        snprintf(t->info, sizeof t->info, "source=%s;theta_r=%lld;theta_i=%lld;phi=%lld;n_h=%s",
                 sources[source], theta_r, theta_i, phi, value_of(&o, "n_h"));
    clear_error();
    return t;
}

int hairis_tables_write(const hairis_tables *t, const char *path)
{
    if (!t || !path) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "tables and path must not be NULL");
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "wb");
    if (!f) return fail(HAIRIS_ERROR_IO, "cannot write %s: %s", tmp, strerror(errno));
    fprintf(f, "%s\n%s\n%s\n%s\n", FAKE_MAGIC, t->model, t->parameters, t->info);
    fclose(f);
    if (rename(tmp, path) != 0) return fail(HAIRIS_ERROR_IO, "cannot rename to %s", path);
    clear_error();
    return HAIRIS_OK;
}

static hairis_tables *parse_tables(const char *text, size_t size, const char *what)
{
    char buffer[4096];
    if (size >= sizeof buffer) size = sizeof buffer - 1;
    memcpy(buffer, text, size);
    buffer[size] = '\0';
    char *model = strchr(buffer, '\n');
    char *parameters = model ? strchr(model + 1, '\n') : NULL;
    char *info = parameters ? strchr(parameters + 1, '\n') : NULL;
    char *end = info ? strchr(info + 1, '\n') : NULL;
    if (strncmp(buffer, FAKE_MAGIC "\n", strlen(FAKE_MAGIC) + 1) != 0 || !end) {
        fail(HAIRIS_ERROR_INVALID_TABLE, "%s is not a hairis table file", what);
        return NULL;
    }
    *parameters = *info = *end = '\0';
    hairis_tables *t = calloc(1, sizeof *t);
    if (!t) {
        fail(HAIRIS_ERROR_INTERNAL, "out of memory");
        return NULL;
    }
    snprintf(t->model, sizeof t->model, "%s", model + 1);
    snprintf(t->parameters, sizeof t->parameters, "%s", parameters + 1);
    snprintf(t->info, sizeof t->info, "%s", info + 1);
    clear_error();
    return t;
}

hairis_tables *hairis_tables_load_file(const char *path)
{
    if (!path) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "path must not be NULL");
        return NULL;
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        fail(HAIRIS_ERROR_IO, "cannot open \"%s\" for reading: %s", path, strerror(errno));
        return NULL;
    }
    char buffer[4096];
    size_t size = fread(buffer, 1, sizeof buffer, f);
    fclose(f);
    return parse_tables(buffer, size, path);
}

hairis_tables *hairis_tables_load_memory(const void *data, size_t size)
{
    if (!data) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "data must not be NULL");
        return NULL;
    }
    return parse_tables((const char *)data, size, "the buffer");
}

void hairis_tables_destroy(hairis_tables *tables)
{
    free(tables);
    clear_error();
}

const char *hairis_tables_model(const hairis_tables *t)
{
    return handle_string(t, "tables", t ? t->model : "");
}

const char *hairis_tables_parameters(const hairis_tables *t)
{
    return handle_string(t, "tables", t ? t->parameters : "");
}

const char *hairis_tables_info(const hairis_tables *t)
{
    return handle_string(t, "tables", t ? t->info : "");
}

int hairis_tables_match_fiber(const hairis_tables *t, const hairis_fiber *f)
{
    if (!t || !f) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "tables and fiber must not be NULL");
        return 0;
    }
    clear_error();
    return strcmp(t->model, f->model) == 0 && strcmp(t->parameters, f->parameters) == 0;
}

/* ---- Sampling ----------------------------------------------------------------------------- */

struct hairis_sampler {
    int strategy;
};

static const char *const strategies[4] = {"uniform", "analytic", "gaussian", "table"};

/* strategy, multiple_weight and n_h of sampler or render options. */
static int read_strategy(const options *o, int *strategy)
{
    double weight;
    long long n_h;
    if (word(o, "strategy", strategies, 4, strategy) != HAIRIS_OK ||
        number_in(o, "multiple_weight", 0.0, 1.0, &weight) != HAIRIS_OK ||
        integer_in(o, "n_h", 1, 1024, &n_h) != HAIRIS_OK)
        return HAIRIS_ERROR_INVALID_ARGUMENT;
    return HAIRIS_OK;
}

hairis_sampler *hairis_sampler_create(const hairis_fiber *fiber, const hairis_tables *tables,
                                      const char *text)
{
    options o;
    int strategy = 0;
    if (read_options(text, "sampler", "sampler options", NULL, &o) != HAIRIS_OK ||
        read_strategy(&o, &strategy) != HAIRIS_OK)
        return NULL;
    if (strategy == 1 && !(fiber && fiber->chiang)) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber must be a chiang2016 fiber for strategy=analytic");
        return NULL;
    }
    if (strategy == 3 && fiber && fiber->huang) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber: strategy=table for a huang2022 fiber samples its Huang "
             "table in the renderer; a sampler for it takes strategy=uniform or gaussian");
        return NULL;
    }
    if (strategy == 3 && !tables) {
        fail(HAIRIS_ERROR_INVALID_TABLE, "tables must not be NULL: the TABLE strategy needs tables");
        return NULL;
    }
    if (strategy == 3 && fiber && fiber->chiang && !hairis_tables_match_fiber(tables, fiber)) {
        fail(HAIRIS_ERROR_INVALID_TABLE, "sampler options: the tables were baked for other parameters");
        return NULL;
    }
    hairis_sampler *s = calloc(1, sizeof *s);
    if (!s) {
        fail(HAIRIS_ERROR_INTERNAL, "out of memory");
        return NULL;
    }
    s->strategy = strategy;
    clear_error();
    return s;
}

void hairis_sampler_destroy(hairis_sampler *sampler)
{
    free(sampler);
    clear_error();
}

int hairis_sample(const hairis_sampler *s, size_t n, const float *wo, const float *h,
                  const float *u, float *wi_out, float *pdf_out)
{
    (void)h;
    if (!s || (n && (!wo || !u || !wi_out || !pdf_out)))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "sampler, wo, u, wi_out, pdf_out: NULL");
    for (size_t i = 0; i < 3 * n; ++i)
        if (!(u[i] >= 0.0f && u[i] < 1.0f))
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "u[%zu] must be in [0, 1)", i);
    for (size_t i = 0; i < n; ++i) {
        float z = 1.0f - 2.0f * u[3 * i];
        float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
        float phi = 6.2831853f * u[3 * i + 1];
        wi_out[3 * i] = z;
        wi_out[3 * i + 1] = r * cosf(phi);
        wi_out[3 * i + 2] = r * sinf(phi);
        pdf_out[i] = 0.0795774715f;
    }
    clear_error();
    return HAIRIS_OK;
}

int hairis_pdf(const hairis_sampler *s, size_t n, const float *wi, const float *wo,
               const float *h, float *pdf_out)
{
    (void)wo;
    (void)h;
    if (!s || (n && (!wi || !pdf_out)))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "sampler, wi, pdf_out: NULL");
    for (size_t i = 0; i < n; ++i) pdf_out[i] = 0.0795774715f;
    clear_error();
    return HAIRIS_OK;
}

int hairis_sampler_eval(const hairis_sampler *s, size_t n, const float *wi, const float *wo,
                        const float *h, float *rgb_out)
{
    (void)wo;
    if (!s || (n && (!wi || !rgb_out)))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "sampler, wi, rgb_out: NULL");
    fake_f(n, wi, h, rgb_out);  /* the fake fiber's, at h */
    clear_error();
    return HAIRIS_OK;
}

/* ---- Scenes ------------------------------------------------------------------------------- */

#define MAX_MATERIALS 256

struct hairis_scene {
    int material_count;
    int material_is_hair[MAX_MATERIALS];
    int material_is_huang[MAX_MATERIALS];
    int material_has_tables[MAX_MATERIALS];
    int material_tables_match[MAX_MATERIALS];
    int material_closures[MAX_MATERIALS]; /* a hair mixture's closure count, else 0 */
    char material_parameters[MAX_MATERIALS][1024];
    size_t curve_sets, curve_count, curve_points, curve_sets_with_normals;
    size_t input_sets, input_values;  /* hairis_scene_add_curves_with_inputs */
    char inputs[512];                 /* the last call's inputs given per curve or point */
    double radius_sum, position_sum[3];
    size_t mesh_count, vertex_count, triangle_count;
    size_t last_mesh_triangles; /* of the last hairis_scene_add_mesh call (0: it added none) */
    int texture_count, uv_meshes, normal_meshes;
    int material_nodes[MAX_MATERIALS]; /* shader nodes of a surface material */
    int suns, points, areas;
    float world[3];
    int has_camera;
    int width, height, orthographic;
};

hairis_scene *hairis_scene_create(void)
{
    hairis_scene *s = calloc(1, sizeof(hairis_scene));
    if (!s) fail(HAIRIS_ERROR_INTERNAL, "out of memory");
    else clear_error();
    return s;
}

void hairis_scene_destroy(hairis_scene *scene)
{
    free(scene);
    clear_error();
}

int hairis_scene_add_hair_material(hairis_scene *s, const hairis_fiber *fiber,
                                   const hairis_tables *tables)
{
    if (!s || !fiber) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene and fiber must not be NULL");
        return -1;
    }
    if (!fiber->chiang && !fiber->huang) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber must be a chiang2016 or huang2022 fiber, got %s",
             fiber->model);
        return -1;
    }
    if (s->material_count >= MAX_MATERIALS) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "too many materials");
        return -1;
    }
    /* Whether the tables fit is hairis_render's question (TABLE only), as in the library. */
    int index = s->material_count++;
    s->material_is_hair[index] = 1;
    s->material_is_huang[index] = fiber->huang;
    s->material_has_tables[index] = tables != NULL;
    s->material_tables_match[index] = tables && hairis_tables_match_fiber(tables, fiber);
    memcpy(s->material_parameters[index], fiber->parameters, sizeof fiber->parameters);
    clear_error();
    return index;
}

int hairis_scene_add_hair_mixture(hairis_scene *s, size_t count, const int *materials,
                                  const float *weights)
{
    if (!s || !materials || !weights) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene, materials and weights must not be NULL");
        return -1;
    }
    if (count < 1 || count > 8) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "hair mixture: count must be in [1, 8] (got %zu)", count);
        return -1;
    }
    if (s->material_count >= MAX_MATERIALS) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "too many materials");
        return -1;
    }
    int has_tables = 1, match = 1;
    for (size_t k = 0; k < count; ++k) {
        const int m = materials[k];
        if (m < 0 || m >= s->material_count || !s->material_is_hair[m] || s->material_closures[m] ||
            s->material_is_huang[m]) {
            fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                 "hair mixture: closure %zu: material %d is not a chiang2016 hair material of one fiber",
                 k, m);
            return -1;
        }
        if (!isfinite(weights[k]) || weights[k] < 0.0f) {
            fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                 "hair mixture: closure %zu's weight is %g; weights must be finite and >= 0", k,
                 (double)weights[k]);
            return -1;
        }
        has_tables &= s->material_has_tables[m];
        match &= s->material_tables_match[m];
    }
    int index = s->material_count++;
    s->material_is_hair[index] = 1;
    s->material_closures[index] = (int)count;
    s->material_has_tables[index] = has_tables;
    s->material_tables_match[index] = match;
    snprintf(s->material_parameters[index], sizeof s->material_parameters[index],
             "mixture of %zu", count);
    clear_error();
    return index;
}

/* A colour input's texture index: -1 or a texture of the scene. */
static int texture_index(const hairis_scene *s, const options *o, const char *name)
{
    long long t;
    if (integer_in(o, name, -1, (1 << 20) - 1, &t) != HAIRIS_OK) return HAIRIS_ERROR_INVALID_ARGUMENT;
    if (t >= s->texture_count)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                    "%s must be the index of a texture added to the scene, in [0, %d), or -1 for none "
                    "(got %lld)",
                    name, s->texture_count, t);
    return HAIRIS_OK;
}

/* A surface material that Mix and Add Shaders combine. */
static int shader_index(const hairis_scene *s, const options *o, const char *name, long long *out)
{
    if (integer_in(o, name, -1, 1 << 20, out) != HAIRIS_OK) return HAIRIS_ERROR_INVALID_ARGUMENT;
    if (*out < 0 || *out >= s->material_count)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                    "%s must be the index of a surface material added to the scene, in [0, %d) (got %lld)",
                    name, s->material_count, *out);
    if (s->material_is_hair[*out])
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                    "%s = %lld is a hair material; Mix and Add Shaders combine surface materials", name,
                    *out);
    return HAIRIS_OK;
}

int hairis_scene_add_surface_material(hairis_scene *s, const char *text)
{
    options o;
    double v[3];
    const char *types[6] = {"diffuse", "principled", "glossy", "emission", "mix", "add"};
    const char *versions[2] = {"3.4", "4.5"};
    const char *distributions[2] = {"ggx", "multi_ggx"};
    int kind = -1, choice = 0;
    if (!s) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene must not be NULL");
        return -1;
    }
    char type[32];
    find_value(text, "type", type, sizeof type);
    if (!type[0]) snprintf(type, sizeof type, "diffuse");
    for (int k = 0; k < 6; ++k)
        if (strcmp(type, types[k]) == 0) kind = k;
    if (kind < 0) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT,
             "surface material: type must be one of diffuse, principled, glossy, emission, mix, add "
             "(got \"%s\")",
             type);
        return -1;
    }
    if (read_options(text, types[kind], "surface material", NULL, &o) != HAIRIS_OK) return -1;
    int nodes = 1;
    if (kind == 0) {
        if (number_in(&o, "roughness", 0, 1, v) != HAIRIS_OK || numbers(&o, "color", v, 3) != HAIRIS_OK ||
            numbers(&o, "emission", v, 3) != HAIRIS_OK || texture_index(s, &o, "color_texture") != HAIRIS_OK ||
            word(&o, "cycles", versions, 2, &choice) != HAIRIS_OK)
            return -1;
        if (v[0] > 0 || v[1] > 0 || v[2] > 0) nodes = 3;
    } else if (kind == 1) {
        if (word(&o, "cycles", versions, 2, &choice) != HAIRIS_OK ||
            word(&o, "distribution", distributions, 2, &choice) != HAIRIS_OK ||
            numbers(&o, "base_color", v, 3) != HAIRIS_OK ||
            texture_index(s, &o, "base_color_texture") != HAIRIS_OK ||
            number_in(&o, "metallic", 0, 1, v) != HAIRIS_OK ||
            number_in(&o, "roughness", 0, 1, v) != HAIRIS_OK ||
            number_in(&o, "ior", 0, 1000, v) != HAIRIS_OK || numbers(&o, "emission", v, 3) != HAIRIS_OK)
            return -1;
    } else if (kind == 2) {
        if (word(&o, "cycles", versions, 2, &choice) != HAIRIS_OK ||
            word(&o, "distribution", distributions, 2, &choice) != HAIRIS_OK ||
            numbers(&o, "color", v, 3) != HAIRIS_OK || texture_index(s, &o, "color_texture") != HAIRIS_OK ||
            number_in(&o, "roughness", 0, 1, v) != HAIRIS_OK)
            return -1;
    } else if (kind == 3) {
        if (numbers(&o, "color", v, 3) != HAIRIS_OK || number_in(&o, "strength", 0, 3.4e38, v) != HAIRIS_OK)
            return -1;
    } else {
        long long a, b;
        if ((kind == 4 && number_in(&o, "factor", 0, 1, v) != HAIRIS_OK) ||
            shader_index(s, &o, "shader1", &a) != HAIRIS_OK || shader_index(s, &o, "shader2", &b) != HAIRIS_OK)
            return -1;
        nodes = s->material_nodes[a] + s->material_nodes[b] + 1;
    }
    if (s->material_count >= MAX_MATERIALS) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "too many materials");
        return -1;
    }
    s->material_nodes[s->material_count] = nodes;
    clear_error();
    return s->material_count++;
}

/* Texture options; `pixels` says whether the image comes as an array. */
static int read_texture(const char *text, int pixels, options *o)
{
    const char *spaces[3] = {"auto", "linear", "srgb"};
    const char *interpolations[2] = {"linear", "closest"};
    const char *extensions[4] = {"repeat", "extend", "clip", "mirror"};
    const char *mappings[4] = {"none", "point", "texture", "vector"};
    int space = 0, choice = 0;
    double v[3];
    if (read_options(text, "texture", "texture", NULL, o) != HAIRIS_OK ||
        word(o, "color_space", spaces, 3, &space) != HAIRIS_OK ||
        word(o, "interpolation", interpolations, 2, &choice) != HAIRIS_OK ||
        word(o, "extension", extensions, 4, &choice) != HAIRIS_OK ||
        word(o, "mapping", mappings, 4, &choice) != HAIRIS_OK || numbers(o, "location", v, 3) != HAIRIS_OK ||
        numbers(o, "rotation", v, 3) != HAIRIS_OK || numbers(o, "scale", v, 3) != HAIRIS_OK)
        return HAIRIS_ERROR_INVALID_ARGUMENT;
    if (pixels && given(o, "image"))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "texture: image must not be given with pixels");
    if (!pixels && !value_of(o, "image")[0])
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "texture: image=<path> must be given");
    if (pixels && space == 0)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "texture: color_space must be linear or srgb with pixels");
    return HAIRIS_OK;
}

int hairis_scene_add_texture(hairis_scene *s, const char *text)
{
    options o;
    if (!s) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene must not be NULL");
        return -1;
    }
    if (read_texture(text, 0, &o) != HAIRIS_OK) return -1;
    FILE *f = fopen(value_of(&o, "image"), "rb");
    if (!f) {
        fail(HAIRIS_ERROR_IO, "texture: image: cannot open %s", value_of(&o, "image"));
        return -1;
    }
    fclose(f);
    clear_error();
    return s->texture_count++;
}

int hairis_scene_add_texture_pixels(hairis_scene *s, const char *text, const float *pixels,
                                    size_t width, size_t height, int channels)
{
    options o;
    if (!s) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene must not be NULL");
        return -1;
    }
    if (!pixels || width == 0 || height == 0) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "texture: pixels must not be NULL or empty");
        return -1;
    }
    if (channels < 1 || channels > 4) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "channels must be in [1, 4] (got %d)", channels);
        return -1;
    }
    if (read_texture(text, 1, &o) != HAIRIS_OK) return -1;
    for (size_t i = 0; i < width * height * (size_t)channels; ++i)
        if (!isfinite(pixels[i]) || pixels[i] < 0.0f) {
            fail(HAIRIS_ERROR_INVALID_ARGUMENT, "texture: pixels: value %zu must be finite and >= 0", i);
            return -1;
        }
    clear_error();
    return s->texture_count++;
}

int hairis_scene_set_mesh_attribute(hairis_scene *s, const char *text, const float *values,
                                    size_t count)
{
    if (!s) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene must not be NULL");
    static const char *const names[2] = {"normal", "uv"};
    char name[32];
    find_value(text, "name", name, sizeof name);
    int which = -1;
    for (int k = 0; k < 2; ++k)
        if (strcmp(name, names[k]) == 0) which = k;
    if (which < 0)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "mesh attribute: name must be one of normal, uv (got \"%s\")",
                    name);
    if (s->last_mesh_triangles == 0)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                    "mesh attribute: the last hairis_scene_add_mesh call added no triangles");
    const size_t want = s->last_mesh_triangles * 3 * (which == 0 ? 3 : 2);
    if (count != want)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "mesh attribute %s: count must be %zu, got %zu",
                    names[which], want, count);
    if (!values) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "values must not be NULL");
    for (size_t i = 0; i < count; ++i)
        if (!isfinite(values[i]))
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "values[%zu] must be finite", i);
    if (which == 0) s->normal_meshes++;
    else s->uv_meshes++;
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_add_curves(hairis_scene *s, int material, size_t curve_count,
                            const uint32_t *first, size_t point_count, const float *positions,
                            const float *radii)
{
    if (!s || !first || (point_count && (!positions || !radii)))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "NULL argument to hairis_scene_add_curves");
    if (material < 0 || material >= s->material_count)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "material %d does not exist", material);
    if (curve_count > point_count / 2)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "curve_count needs 2 points per curve");
    if (first[0] != 0 || first[curve_count] != point_count)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                    "first[0] must be 0 and first[curve_count] = point_count (%zu), got %u, %u",
                    point_count, first[0], first[curve_count]);
    for (size_t c = 0; c < curve_count; ++c)
        if (first[c + 1] < first[c] + 2)
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "curve %zu has fewer than 2 points", c);
    for (size_t i = 0; i < point_count; ++i)
        if (!isfinite(positions[3 * i]) || !isfinite(positions[3 * i + 1]) ||
            !isfinite(positions[3 * i + 2]) || !(radii[i] >= 0.0f))
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "point %zu is not finite", i);
    for (size_t i = 0; i < point_count; ++i) {
        s->radius_sum += radii[i];
        for (int k = 0; k < 3; ++k) s->position_sum[k] += positions[3 * i + k];
    }
    s->curve_sets++;
    s->curve_count += curve_count;
    s->curve_points += point_count;
    clear_error();
    return HAIRIS_OK;
}

/* The curve inputs' names in hairis_defaults("curve_inputs") order, with their components. */
static const char *const curve_input_names[] = {
    "color", "melanin", "melanin_redness", "tint", "absorption", "roughness", "radial_roughness",
    "coat", "ior", "offset", "random_color", "random_roughness", "random",
    "weight0", "weight1", "weight2", "weight3", "weight4", "weight5", "weight6", "weight7"};
static const int curve_input_components[] = {3, 1, 1, 3, 3, 1, 1, 1, 1, 1, 1, 1, 1,
                                             1, 1, 1, 1, 1, 1, 1, 1};
enum { CURVE_INPUT_COUNT = sizeof curve_input_names / sizeof curve_input_names[0] };

int hairis_scene_add_curves_with_inputs(hairis_scene *s, int material, size_t curve_count,
                                        const uint32_t *first, size_t point_count,
                                        const float *positions, const float *radii,
                                        const char *inputs, size_t value_count,
                                        const float *values)
{
    options o;
    const char *domains[3] = {"material", "curve", "point"};
    int domain[CURVE_INPUT_COUNT];
    if (!s) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene must not be NULL");
    if (read_options(inputs, "curve_inputs", "curve inputs", NULL, &o) != HAIRIS_OK)
        return HAIRIS_ERROR_INVALID_ARGUMENT;
    size_t needed = 0;
    char list[512] = "";
    for (int i = 0; i < CURVE_INPUT_COUNT; ++i) {
        if (word(&o, curve_input_names[i], domains, 3, &domain[i]) != HAIRIS_OK)
            return HAIRIS_ERROR_INVALID_ARGUMENT;
        if (domain[i] == 0) continue;
        if (material >= 0 && material < s->material_count && !s->material_is_hair[material])
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                        "curve inputs: %s needs a hair material; material %d is a surface material",
                        curve_input_names[i], material);
        needed += (size_t)curve_input_components[i] * (domain[i] == 2 ? point_count : curve_count);
        const size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s%s=%s", used ? ";" : "", curve_input_names[i],
                 domains[domain[i]]);
    }
    if (value_count != needed)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                    "value_count must be %zu (the inputs' components for each of %zu curves or %zu "
                    "points, in hairis_defaults(\"curve_inputs\")'s order), got %zu",
                    needed, curve_count, point_count, value_count);
    if (value_count && !values)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "values must not be NULL when n > 0 (n = %zu)",
                    value_count);
    for (size_t i = 0; i < value_count; ++i)
        if (!isfinite(values[i]))
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "values[%zu] must be finite", i);
    const int status = hairis_scene_add_curves(s, material, curve_count, first, point_count,
                                               positions, radii);
    if (status != HAIRIS_OK) return status;
    s->input_sets++;
    s->input_values += value_count;
    snprintf(s->inputs, sizeof s->inputs, "%s", list);
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_add_curves_with_normals(hairis_scene *s, int material, size_t curve_count,
                                         const uint32_t *first, size_t point_count,
                                         const float *positions, const float *radii,
                                         const float *normals, const char *text)
{
    options o;
    if (!s || (point_count && !normals))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene and normals must not be NULL");
    if (read_options(text, "curves", "curve options", NULL, &o) != HAIRIS_OK)
        return HAIRIS_ERROR_INVALID_ARGUMENT;
    for (size_t i = 0; i < 3 * point_count; ++i)
        if (!isfinite(normals[i]))
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "normals[%zu] must be finite", i);
    const int status =
        hairis_scene_add_curves(s, material, curve_count, first, point_count, positions, radii);
    if (status == HAIRIS_OK) s->curve_sets_with_normals++;
    return status;
}

int hairis_scene_add_mesh(hairis_scene *s, size_t vertex_count, const float *positions,
                          size_t triangle_count, const uint32_t *indices,
                          const int32_t *materials)
{
    if (!s || (vertex_count && !positions) || (triangle_count && (!indices || !materials)))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "NULL argument to hairis_scene_add_mesh");
    for (size_t t = 0; t < triangle_count; ++t) {
        for (int k = 0; k < 3; ++k)
            if (indices[3 * t + k] >= vertex_count)
                return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "triangle %zu indexes vertex %u of %zu",
                            t, indices[3 * t + k], vertex_count);
        if (materials[t] < 0 || materials[t] >= s->material_count)
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "triangle %zu: material %d does not exist",
                        t, materials[t]);
        if (s->material_is_hair[materials[t]])
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "materials[%zu] = %d is a hair material", t,
                        materials[t]);
    }
    s->last_mesh_triangles = triangle_count;
    if (triangle_count == 0) {
        clear_error();
        return HAIRIS_OK;
    }
    s->mesh_count++;
    s->vertex_count += vertex_count;
    s->triangle_count += triangle_count;
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_add_light(hairis_scene *s, const char *text)
{
    if (!s) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene must not be NULL");
    /* The type picks the names. */
    char type[32];
    find_value(text, "type", type, sizeof type);
    const char *types[4] = {"sun", "point", "area", "spot"};
    int kind = -1;
    for (int k = 0; k < 4; ++k)
        if (strcmp(type, types[k]) == 0) kind = k;
    if (kind < 0)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                    "light: type must be given: sun, point, spot or area (got \"%s\")", type);
    options o;
    double v[16];
    if (read_options(text, types[kind], "light", NULL, &o) != HAIRIS_OK ||
        numbers(&o, "color", v, 3) != HAIRIS_OK)
        return HAIRIS_ERROR_INVALID_ARGUMENT;
    if (kind == 0) {
        if (numbers(&o, "direction", v, 3) != HAIRIS_OK) return HAIRIS_ERROR_INVALID_ARGUMENT;
        if (v[0] == 0 && v[1] == 0 && v[2] == 0)
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "light: direction must not be the zero vector");
        if (number_in(&o, "strength", 0, 3.4e38, v) != HAIRIS_OK ||
            number_in(&o, "angle", 0, 3.14159, v) != HAIRIS_OK)
            return HAIRIS_ERROR_INVALID_ARGUMENT;
        s->suns++;
    } else if (kind == 1) {
        if (numbers(&o, "position", v, 3) != HAIRIS_OK ||
            number_in(&o, "power", 0, 3.4e38, v) != HAIRIS_OK ||
            number_in(&o, "radius", 0, 3.4e38, v) != HAIRIS_OK)
            return HAIRIS_ERROR_INVALID_ARGUMENT;
        s->points++;
    } else if (kind == 3) {
        if (numbers(&o, "matrix", v, 16) != HAIRIS_OK ||
            number_in(&o, "power", 0, 3.4e38, v) != HAIRIS_OK ||
            number_in(&o, "radius", 0, 3.4e38, v) != HAIRIS_OK ||
            number_in(&o, "spot_size", 0.0174532925, 3.14159266, v) != HAIRIS_OK ||
            number_in(&o, "spot_blend", 0, 1, v) != HAIRIS_OK)
            return HAIRIS_ERROR_INVALID_ARGUMENT;
        s->points++;
    } else {
        const char *shapes[4] = {"square", "rectangle", "disk", "ellipse"};
        int shape = 0;
        if (numbers(&o, "matrix", v, 16) != HAIRIS_OK ||
            word(&o, "shape", shapes, 4, &shape) != HAIRIS_OK ||
            number_in(&o, "size", 0, 3.4e38, v) != HAIRIS_OK ||
            number_in(&o, "size_y", 0, 3.4e38, v) != HAIRIS_OK ||
            number_in(&o, "power", 0, 3.4e38, v) != HAIRIS_OK)
            return HAIRIS_ERROR_INVALID_ARGUMENT;
        s->areas++;
    }
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_set_world(hairis_scene *s, const char *text)
{
    if (!s) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene must not be NULL");
    options o;
    double color[3], strength;
    if (read_options(text, "world", "world", NULL, &o) != HAIRIS_OK ||
        numbers(&o, "color", color, 3) != HAIRIS_OK ||
        number_in(&o, "strength", 0, 3.4e38, &strength) != HAIRIS_OK)
        return HAIRIS_ERROR_INVALID_ARGUMENT;
    for (int k = 0; k < 3; ++k) s->world[k] = (float)(color[k] * strength);
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_set_world_pixels(hairis_scene *s, const char *text, const float *pixels,
                                  size_t width, size_t height, int channels)
{
    if (!s) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene must not be NULL");
    if (!pixels || width == 0 || height == 0)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "world: pixels must not be NULL or empty");
    if (channels < 1 || channels > 4)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "world: channels must be 1 to 4, not %d", channels);
    options o;
    double color[3] = {1, 1, 1}, strength;
    if (read_options(text, "world", "world", NULL, &o) != HAIRIS_OK ||
        number_in(&o, "strength", 0, 3.4e38, &strength) != HAIRIS_OK)
        return HAIRIS_ERROR_INVALID_ARGUMENT;
    /* The fake renders the environment as its mean times the multiplier. */
    double mean = 0;
    for (size_t i = 0; i < width * height; ++i) mean += pixels[i * (size_t)channels];
    mean /= (double)(width * height);
    for (int k = 0; k < 3; ++k) s->world[k] = (float)(color[k] * strength * mean);
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_reset_shading(hairis_scene *s)
{
    if (!s) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene must not be NULL");
    s->material_count = 0;
    s->texture_count = 0;
    s->suns = s->points = s->areas = 0;
    for (int k = 0; k < 3; ++k) s->world[k] = 0.0f;
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_set_camera(hairis_scene *s, const char *text)
{
    if (!s) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene must not be NULL");
    options o;
    double v[16];
    long long width, height;
    const char *flags[4] = {"0", "1", "false", "true"};
    int orthographic = 0;
    if (read_options(text, "camera", "camera", NULL, &o) != HAIRIS_OK ||
        numbers(&o, "matrix", v, 16) != HAIRIS_OK || numbers(&o, "frame", v, 12) != HAIRIS_OK ||
        word(&o, "orthographic", flags, 4, &orthographic) != HAIRIS_OK ||
        integer_in(&o, "width", 1, 65536, &width) != HAIRIS_OK ||
        integer_in(&o, "height", 1, 65536, &height) != HAIRIS_OK ||
        numbers(&o, "clip_start", v, 1) != HAIRIS_OK || numbers(&o, "clip_end", v + 1, 1) != HAIRIS_OK)
        return HAIRIS_ERROR_INVALID_ARGUMENT;
    if (!(v[1] > v[0])) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "camera: clip_end must be greater than clip_start");
    s->width = (int)width;
    s->height = (int)height;
    s->orthographic = orthographic % 2;
    s->has_camera = 1;
    clear_error();
    return HAIRIS_OK;
}

/* ---- Rendering ---------------------------------------------------------------------------- */

typedef struct render_settings {
    long long samples, max_bounces, max_diffuse_bounces, max_glossy_bounces,
        max_transmission_bounces, max_transparent_bounces, threads, tile_size, rr_start_bounce, n_h,
        dual_exact_bounces, curve_subdivisions;
    unsigned long long seed;
    int integrator, strategy, film_transparent, curve_backfaces, curve_shape, bvh_quality, huang_sampling,
        transparent_limit, dual_hair_volume, dual_bounce_limit;
    double multiple_weight, time_limit, adaptive_threshold;
    double filter_glossy, clamp_direct, clamp_indirect, pixel_filter_width, exposure;
    int pixel_filter;
    long long adaptive_min_samples;
    double region[4];
    /* The passes asked for (0 depth, 1 normal, 2 denoising_albedo, 3 denoising_normal). */
    int pass_count, pass_kind[16];
} render_settings;

static const char *const pass_names[4] = {"depth", "normal", "denoising_albedo", "denoising_normal"};

/* "name,name,..." of pass_names into r->pass_kind. */
static int read_passes(const char *text, render_settings *r)
{
    r->pass_count = 0;
    while (*text) {
        const char *end = strchr(text, ',');
        size_t n = end ? (size_t)(end - text) : strlen(text);
        int kind = -1;
        for (int k = 0; k < 4; ++k)
            if (strlen(pass_names[k]) == n && strncmp(text, pass_names[k], n) == 0) kind = k;
        if (kind < 0 || r->pass_count == 16)
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                        "render settings: passes must be names among depth, normal, "
                        "denoising_albedo, denoising_normal separated by ',' (got \"%.*s\")",
                        (int)n, text);
        r->pass_kind[r->pass_count++] = kind;
        text += n + (end ? 1 : 0);
    }
    return HAIRIS_OK;
}

static int read_render_settings(const char *text, render_settings *r)
{
    static const char *const huang_samplings[2] = {"strategy", "cycles"};
    static const char *const volumes[2] = {"layer", "unbounded"};
    static const char *const bounce_limits[2] = {"bounces", "none"};
    options o;
    const char *flags[4] = {"0", "1", "false", "true"};
    const char *backfaces[2] = {"ignore", "hit"};
    const char *shapes[3] = {"thick", "ribbons", "thick_linear"};
    const char *qualities[3] = {"low", "medium", "high"};
    const char *integrators[2] = {"path", "dual_scattering"};
    const char *transparent_limits[2] = {"plus_one", "setting"};
    const char *pixel_filters[3] = {"box", "gaussian", "blackman_harris"};
    if (read_options(text, "render", "render settings", NULL, &o) != HAIRIS_OK ||
        word(&o, "integrator", integrators, 2, &r->integrator) != HAIRIS_OK ||
        integer_in(&o, "samples", 1, 1 << 24, &r->samples) != HAIRIS_OK ||
        integer_in(&o, "max_bounces", 0, 1024, &r->max_bounces) != HAIRIS_OK ||
        integer_in(&o, "max_diffuse_bounces", 0, 1024, &r->max_diffuse_bounces) != HAIRIS_OK ||
        integer_in(&o, "max_glossy_bounces", 0, 1024, &r->max_glossy_bounces) != HAIRIS_OK ||
        integer_in(&o, "max_transmission_bounces", 0, 1024, &r->max_transmission_bounces) != HAIRIS_OK ||
        integer_in(&o, "max_transparent_bounces", 0, 1024, &r->max_transparent_bounces) != HAIRIS_OK ||
        word(&o, "transparent_limit", transparent_limits, 2, &r->transparent_limit) != HAIRIS_OK ||
        integer_in(&o, "threads", 0, 1024, &r->threads) != HAIRIS_OK ||
        integer_in(&o, "tile_size", 1, 4096, &r->tile_size) != HAIRIS_OK ||
        integer_in(&o, "rr_start_bounce", 1, 1024, &r->rr_start_bounce) != HAIRIS_OK ||
        word(&o, "film_transparent", flags, 4, &r->film_transparent) != HAIRIS_OK ||
        word(&o, "curve_backfaces", backfaces, 2, &r->curve_backfaces) != HAIRIS_OK ||
        word(&o, "curve_shape", shapes, 3, &r->curve_shape) != HAIRIS_OK ||
        word(&o, "bvh_quality", qualities, 3, &r->bvh_quality) != HAIRIS_OK ||
        integer_in(&o, "curve_subdivisions", 0, 24, &r->curve_subdivisions) != HAIRIS_OK ||
        word(&o, "huang_sampling", huang_samplings, 2, &r->huang_sampling) != HAIRIS_OK ||
        word(&o, "dual_hair_volume", volumes, 2, &r->dual_hair_volume) != HAIRIS_OK ||
        integer_in(&o, "dual_exact_bounces", 0, 1024, &r->dual_exact_bounces) != HAIRIS_OK ||
        word(&o, "dual_bounce_limit", bounce_limits, 2, &r->dual_bounce_limit) != HAIRIS_OK ||
        number_in(&o, "time_limit", 0.0, 3.4e38, &r->time_limit) != HAIRIS_OK ||
        number_in(&o, "adaptive_threshold", 0.0, 1.0, &r->adaptive_threshold) != HAIRIS_OK ||
        integer_in(&o, "adaptive_min_samples", 0, 1 << 24, &r->adaptive_min_samples) != HAIRIS_OK ||
        numbers(&o, "region", r->region, 4) != HAIRIS_OK ||
        number_in(&o, "filter_glossy", 0.0, 10.0, &r->filter_glossy) != HAIRIS_OK ||
        number_in(&o, "clamp_direct", 0.0, 3.4e38, &r->clamp_direct) != HAIRIS_OK ||
        number_in(&o, "clamp_indirect", 0.0, 3.4e38, &r->clamp_indirect) != HAIRIS_OK ||
        word(&o, "pixel_filter", pixel_filters, 3, &r->pixel_filter) != HAIRIS_OK ||
        number_in(&o, "pixel_filter_width", 0.001, 10.0, &r->pixel_filter_width) != HAIRIS_OK ||
        number_in(&o, "exposure", 0.0, 10.0, &r->exposure) != HAIRIS_OK ||
        read_passes(value_of(&o, "passes"), r) != HAIRIS_OK ||
        read_strategy(&o, &r->strategy) != HAIRIS_OK)
        return HAIRIS_ERROR_INVALID_ARGUMENT;
    r->film_transparent %= 2;
    long long n_h;
    integer_in(&o, "n_h", 1, 1024, &n_h);
    r->n_h = n_h;
    numbers(&o, "multiple_weight", &r->multiple_weight, 1);
    char *end = NULL;
    const char *seed = value_of(&o, "seed");
    errno = 0;
    r->seed = strtoull(seed, &end, 10);
    if (end == seed || *end != '\0' || errno == ERANGE || seed[0] == '-')
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "render settings: seed must be an integer in [0, 2^64 - 1] (got \"%s\")",
                    seed);
    return HAIRIS_OK;
}

static const char *const pixel_filters_of[3] = {"box", "gaussian", "blackman_harris"};

static void write_summary(const hairis_scene *s, const render_settings *r)
{
    const char *path = getenv("HAIRIS_FAKE_SUMMARY");
    if (!path || !*path) return;
    FILE *f = fopen(path, "a");
    if (!f) return;
    fprintf(f, "samples=%lld max_bounces=%lld strategy=%d multiple_weight=%.6g n_h=%lld seed=%llu "
               "threads=%lld max_diffuse_bounces=%lld max_glossy_bounces=%lld max_transmission_bounces=%lld "
               "max_transparent_bounces=%lld tile_size=%lld film_transparent=%d curve_backfaces=%s "
               "integrator=%d huang_sampling=%d transparent_limit=%s dual_hair_volume=%s "
               "dual_exact_bounces=%lld dual_bounce_limit=%s curve_shape=%s bvh_quality=%s "
               "filter_glossy=%.6g clamp_direct=%.6g clamp_indirect=%.6g pixel_filter=%s "
               "pixel_filter_width=%.6g curve_subdivisions=%lld exposure=%.6g\n",
            r->samples, r->max_bounces, r->strategy, r->multiple_weight, r->n_h, r->seed,
            r->threads, r->max_diffuse_bounces, r->max_glossy_bounces, r->max_transmission_bounces,
            r->max_transparent_bounces, r->tile_size, r->film_transparent,
            r->curve_backfaces ? "hit" : "ignore", r->integrator, r->huang_sampling,
            r->transparent_limit ? "setting" : "plus_one", r->dual_hair_volume ? "unbounded" : "layer",
            r->dual_exact_bounces, r->dual_bounce_limit ? "none" : "bounces",
            r->curve_shape == 2 ? "thick_linear" : r->curve_shape ? "ribbons" : "thick",
            r->bvh_quality == 2 ? "high" : r->bvh_quality ? "medium" : "low", r->filter_glossy,
            r->clamp_direct, r->clamp_indirect, pixel_filters_of[r->pixel_filter], r->pixel_filter_width,
            r->curve_subdivisions, r->exposure);
    fprintf(f, "materials=%d curve_sets=%zu curves=%zu points=%zu radius_sum=%.9g "
               "position_sum=%.9g,%.9g,%.9g curve_sets_with_normals=%zu\n",
            s->material_count, s->curve_sets, s->curve_count, s->curve_points, s->radius_sum,
            s->position_sum[0], s->position_sum[1], s->position_sum[2], s->curve_sets_with_normals);
    fprintf(f, "meshes=%zu vertices=%zu triangles=%zu suns=%d points=%d areas=%d "
               "world=%.6g,%.6g,%.6g\n",
            s->mesh_count, s->vertex_count, s->triangle_count, s->suns, s->points, s->areas,
            (double)s->world[0], (double)s->world[1], (double)s->world[2]);
    fprintf(f, "camera=%dx%d orthographic=%d\n", s->width, s->height, s->orthographic);
    fprintf(f, "curve_input_sets=%zu curve_input_values=%zu curve_inputs=%s\n", s->input_sets,
            s->input_values, s->inputs);
    fprintf(f, "textures=%d uv_meshes=%d normal_meshes=%d\n", s->texture_count, s->uv_meshes,
            s->normal_meshes);
    for (int i = 0; i < s->material_count; ++i)
        if (s->material_is_hair[i])
            fprintf(f, "hair %d tables=%d huang=%d %s\n", i, s->material_has_tables[i],
                    s->material_is_huang[i], s->material_parameters[i]);
    fclose(f);
}

static void set_stats(double seconds, unsigned long long camera_rays, long long threads,
                      int cancelled, unsigned long long samples)
{
    snprintf(render_stats, sizeof render_stats,
             "seconds=%.17g;camera_rays=%llu;rays=%llu;shadow_rays=0;dropped_samples=0;"
             "peak_memory_bytes=%zu;threads=%lld;cancelled=%d;samples=%llu;converged_pixels=0",
             seconds, camera_rays, camera_rays, sizeof(hairis_scene), threads > 0 ? threads : 1,
             cancelled, samples);
}

/* hairis_render (update NULL) and hairis_render_progressive (progress NULL). */
static int render_common(hairis_scene *s, const char *settings, float *rgba, float *passes,
                         hairis_progress_fn progress, hairis_update_fn update, void *user)
{
    if (!s || !rgba) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene and rgba must not be NULL");
    render_settings r;
    if (read_render_settings(settings, &r) != HAIRIS_OK) return HAIRIS_ERROR_INVALID_ARGUMENT;
    if (!s->has_camera)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                    "scene has no camera: call hairis_scene_set_camera before hairis_render");
    /* Dual scattering samples Huang with the strategy's sampler whatever huang_sampling says. */
    for (int i = 0; i < s->material_count; ++i)
        if (s->material_is_huang[i] && (!r.huang_sampling || r.integrator == 1) && r.strategy == 1)
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                        "material %d (hair): strategy=analytic has no sampler with a known density "
                        "for a huang2022 fiber; render with strategy=table or uniform",
                        i);
    /* integrator=dual_scattering samples multiple scattering from every hair material's tables. */
    if (r.integrator == 1)
        for (int i = 0; i < s->material_count; ++i) {
            if (s->material_is_hair[i] && !s->material_has_tables[i])
                return fail(HAIRIS_ERROR_INVALID_TABLE,
                            "material %d (hair): integrator=dual_scattering samples multiple "
                            "scattering from the material's baked multiple-scattering tables, but "
                            "it was added without tables",
                            i);
            if (s->material_is_hair[i] && !s->material_tables_match[i])
                return fail(HAIRIS_ERROR_INVALID_TABLE,
                            "material %d (hair): the tables were baked for other parameters", i);
        }
    if (r.strategy == 3)
        for (int i = 0; i < s->material_count; ++i) {
            if (s->material_is_huang[i] && r.huang_sampling) continue; /* Cycles' own Huang sampler */
            if (s->material_is_hair[i] && !s->material_has_tables[i])
                return fail(HAIRIS_ERROR_INVALID_TABLE,
                            "material %d (hair): strategy=table needs sampling tables, but the "
                            "material was added without tables",
                            i);
            if (s->material_is_hair[i] && !s->material_tables_match[i])
                return fail(HAIRIS_ERROR_INVALID_TABLE,
                            "material %d (hair): the tables were baked for other parameters", i);
        }
    /* The region: whole numbers, inside the image; 0,0,0,0 is the whole image. */
    int x0 = 0, y0 = 0, x1 = s->width, y1 = s->height;
    if (r.region[0] != 0 || r.region[1] != 0 || r.region[2] != 0 || r.region[3] != 0) {
        for (int k = 0; k < 4; ++k)
            if (r.region[k] != floor(r.region[k]))
                return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "render settings: region must be 4 integers");
        x0 = (int)r.region[0], y0 = (int)r.region[1], x1 = (int)r.region[2], y1 = (int)r.region[3];
        if (x0 < 0 || y0 < 0 || x1 > s->width || y1 > s->height || x0 >= x1 || y0 >= y1)
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                        "render settings: region must be x0,y0,x1,y1 with 0 <= x0 < x1 <= %d and "
                        "0 <= y0 < y1 <= %d",
                        s->width, s->height);
    }
    if (r.pass_count > 0 && !passes)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "passes must not be NULL when settings ask for passes");
    write_summary(s, &r);
    double start = now_seconds();
    const char *delay_text = getenv("HAIRIS_FAKE_ROW_DELAY_MS");
    int delay = delay_text ? atoi(delay_text) : 0;
    /* HAIRIS_FAKE_NOISE: pixels = world·(1 + uniform noise / sqrt(samples)), seeded, so the
     * statistical tests can be dry-run on the fake. */
    const char *noise_text = getenv("HAIRIS_FAKE_NOISE");
    float noise = noise_text ? (float)atof(noise_text) : 0.0f;
    int width = s->width, height = s->height;
    memset(rgba, 0, sizeof(float) * 4 * (size_t)width * (size_t)height);
    /* Every camera ray misses: depth 1e10 (Cycles' "nothing"), the other passes 0. */
    float *pass = passes;
    for (int k = 0; k < r.pass_count; ++k) {
        const size_t n = (size_t)width * (size_t)height * (r.pass_kind[k] == 0 ? 1 : 3);
        for (size_t i = 0; i < n; ++i) pass[i] = 0.0f;
        if (r.pass_kind[k] == 0)
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) pass[(size_t)y * (size_t)width + (size_t)x] = 1e10f;
        pass += n;
    }
    for (int y = y0; y < y1; ++y) {
        const float fraction = (float)(y - y0) / (float)(y1 - y0);
        if ((progress && progress(user, fraction)) ||
            (update && update(user, fraction, 0, 0))) {
            set_stats(now_seconds() - start, (unsigned long long)(y - y0) *
                                                 (unsigned long long)(x1 - x0) *
                                                 (unsigned long long)r.samples,
                      r.threads, 1, 0);
            return fail(HAIRIS_ERROR_CANCELLED, "render cancelled at row %d of %d", y, height);
        }
        for (int x = x0; x < x1; ++x) {
            float *p = rgba + 4 * ((size_t)y * (size_t)width + (size_t)x);
            float factor = 1.0f;
            if (noise > 0.0f) {
                uint64_t h = r.seed * 0x9E3779B97F4A7C15ull + (uint64_t)y * 0xBF58476D1CE4E5B9ull +
                             (uint64_t)x * 0x94D049BB133111EBull + 1u;
                h ^= h >> 31;
                h *= 0xD6E8FEB86659FD93ull;
                h ^= h >> 32;
                float u = (float)(h >> 40) / 16777216.0f;
                factor += noise * (u - 0.5f) * 3.4641016f / sqrtf((float)r.samples);
            }
            /* Every camera ray misses: a transparent film shows nothing. */
            const float shown = r.film_transparent ? 0.0f : factor;
            p[0] = s->world[0] * shown;
            p[1] = s->world[1] * shown;
            p[2] = s->world[2] * shown;
            p[3] = r.film_transparent ? 0.0f : 1.0f;
        }
        sleep_ms(delay);
    }
    if (progress) progress(user, 1.0f);
    if (update) update(user, 1.0f, (int)r.samples, 1);
    set_stats(now_seconds() - start,
              (unsigned long long)(x1 - x0) * (unsigned long long)(y1 - y0) *
                  (unsigned long long)r.samples,
              r.threads, 0, (unsigned long long)r.samples);
    clear_error();
    return HAIRIS_OK;
}

int hairis_render(hairis_scene *s, const char *settings, float *rgba, hairis_progress_fn progress,
                  void *user)
{
    return render_common(s, settings, rgba, NULL, progress, NULL, user);
}

int hairis_render_progressive(hairis_scene *s, const char *settings, float *rgba, float *passes,
                              hairis_update_fn update, void *user)
{
    return render_common(s, settings, rgba, passes, NULL, update, user);
}

const char *hairis_last_render_stats(void) { return render_stats; }
