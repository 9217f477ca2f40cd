/* A stand-in for libhairis used by the Blender add-on tests.
 *
 * It implements every function of lib/include/hairis/hairis.h with trivial physics (the
 * render is the world radiance, the sampler is uniform), but with the real header's
 * conventions: thread-local last error, argument checks, progress callbacks that cancel,
 * table files that round-trip and match fibers by their parameter string. Compiled against the
 * real header, it also exports hairis_fake_sizeof/hairis_fake_offsetof so the tests can check
 * the ctypes mirrors of the structs field by field.
 *
 * Test hooks (environment variables):
 *   HAIRIS_FAKE_API_VERSION   value returned by hairis_api_version (default 1)
 *   HAIRIS_FAKE_ROW_DELAY_MS  sleep per rendered row (to test cancelling)
 *   HAIRIS_FAKE_SUMMARY       hairis_render appends a summary of the scene to this file
 *   HAIRIS_FAKE_NOISE         relative noise of the rendered pixels (default 0: exact)
 */
#define _POSIX_C_SOURCE 200809L
#include "hairis/hairis.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define FAKE_EXPORT HAIRIS_API

static _Thread_local char last_error[1024];

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

/* ---- Library ------------------------------------------------------------------------------ */

int hairis_api_version(void)
{
    const char *override = getenv("HAIRIS_FAKE_API_VERSION");
    return override ? atoi(override) : HAIRIS_API_VERSION;
}

const char *hairis_version_string(void) { return "0.0.0-fake"; }

const char *hairis_last_error(void) { return last_error; }

/* ---- Fibers ------------------------------------------------------------------------------- */

struct hairis_fiber {
    char model[32];
    char parameters[768];
};

void hairis_principled_hair_defaults(hairis_principled_hair *node)
{
    if (!node) return;
    memset(node, 0, sizeof *node);
    node->parametrization = HAIRIS_PARAM_COLOR;
    node->color[0] = 0.017513f;
    node->color[1] = 0.005763f;
    node->color[2] = 0.002059f;
    node->melanin = 0.8f;
    node->melanin_redness = 1.0f;
    node->tint[0] = node->tint[1] = node->tint[2] = 1.0f;
    node->absorption_coefficient[0] = 0.245531f;
    node->absorption_coefficient[1] = 0.52f;
    node->absorption_coefficient[2] = 1.365f;
    node->roughness = 0.3f;
    node->radial_roughness = 0.3f;
    node->coat = 0.0f;
    node->ior = 1.55f;
    node->offset = 0.034906585f;
}

void hairis_marschner_defaults(hairis_marschner_params *p)
{
    if (!p) return;
    memset(p, 0, sizeof *p);
    p->eta = 1.55f;
    p->sigma_a[0] = 0.2f;
    p->sigma_a[1] = 0.3f;
    p->sigma_a[2] = 0.5f;
    p->alpha_r = -0.1f;
    p->alpha_tt = 0.05f;
    p->alpha_trt = 0.15f;
    p->beta_r = 0.1f;
    p->beta_tt = 0.05f;
    p->beta_trt = 0.2f;
    p->eccentricity = 0.9f;
    p->glint_scale = 1.0f;
    p->caustic_width = 0.3f;
    p->caustic_fade = 0.3f;
    p->caustic_intensity_limit = 0.5f;
}

static int check_principled(const hairis_principled_hair *n)
{
    const float *values = &n->color[0];
    size_t count = (sizeof *n - offsetof(hairis_principled_hair, color)) / sizeof(float);
    for (size_t i = 0; i < count; ++i)
        if (!isfinite(values[i]))
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "node value %zu is not finite", i);
    if (n->parametrization < 0 || n->parametrization > 2)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                    "parametrization %d is not 0 (absorption), 1 (melanin) or 2 (color)",
                    n->parametrization);
    if (!(n->ior > 1.0f))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "IOR must be > 1, got %g", (double)n->ior);
    if (n->roughness < 0.0f || n->roughness > 1.0f)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "Roughness must be in [0, 1], got %g",
                    (double)n->roughness);
    return HAIRIS_OK;
}

hairis_fiber *hairis_fiber_create_principled(const hairis_principled_hair *n)
{
    if (!n) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "node is NULL");
        return NULL;
    }
    if (check_principled(n) != HAIRIS_OK) return NULL;
    hairis_fiber *f = calloc(1, sizeof *f);
    snprintf(f->model, sizeof f->model, "chiang2016");
    snprintf(f->parameters, sizeof f->parameters,
             "parametrization=%d;color=%.9g,%.9g,%.9g;melanin=%.9g;melanin_redness=%.9g;"
             "tint=%.9g,%.9g,%.9g;absorption=%.9g,%.9g,%.9g;roughness=%.9g;"
             "radial_roughness=%.9g;coat=%.9g;ior=%.9g;offset=%.9g;random_color=%.9g;"
             "random_roughness=%.9g;random=%.9g",
             n->parametrization, n->color[0], n->color[1], n->color[2], n->melanin,
             n->melanin_redness, n->tint[0], n->tint[1], n->tint[2],
             n->absorption_coefficient[0], n->absorption_coefficient[1],
             n->absorption_coefficient[2], n->roughness, n->radial_roughness, n->coat, n->ior,
             n->offset, n->random_color, n->random_roughness, n->random);
    clear_error();
    return f;
}

hairis_fiber *hairis_fiber_create_marschner(const hairis_marschner_params *p)
{
    if (!p) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "params is NULL");
        return NULL;
    }
    if (!(p->eta > 1.0f)) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "eta must be > 1, got %g", (double)p->eta);
        return NULL;
    }
    hairis_fiber *f = calloc(1, sizeof *f);
    snprintf(f->model, sizeof f->model, "marschner2003");
    snprintf(f->parameters, sizeof f->parameters, "eta=%.9g;sigma_a=%.9g,%.9g,%.9g", p->eta,
             p->sigma_a[0], p->sigma_a[1], p->sigma_a[2]);
    clear_error();
    return f;
}

void hairis_fiber_destroy(hairis_fiber *fiber) { free(fiber); }

const char *hairis_fiber_model(const hairis_fiber *fiber) { return fiber ? fiber->model : ""; }

const char *hairis_fiber_parameters(const hairis_fiber *fiber)
{
    return fiber ? fiber->parameters : "";
}

int hairis_fiber_eval(const hairis_fiber *fiber, size_t n, const float *wi, const float *wo,
                      const float *h, float *rgb_out)
{
    if (!fiber || (n && (!wi || !wo || !rgb_out)))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber, wi, wo and rgb_out must not be NULL");
    for (size_t i = 0; i < n; ++i) {
        float cos_theta = sqrtf(fmaxf(0.0f, 1.0f - wi[3 * i] * wi[3 * i]));
        float value = 0.1f * cos_theta * (h ? 1.0f - fabsf(h[i]) : 1.0f);
        (void)wo;
        rgb_out[3 * i] = rgb_out[3 * i + 1] = rgb_out[3 * i + 2] = value;
    }
    clear_error();
    return HAIRIS_OK;
}

/* ---- Tables ------------------------------------------------------------------------------- */

struct hairis_tables {
    char model[32];
    char parameters[768];
};

#define FAKE_MAGIC "HAIRISFAKE"

void hairis_bake_options_defaults(hairis_bake_options *o)
{
    if (!o) return;
    memset(o, 0, sizeof *o);
    o->theta_r_count = 16;
    o->theta_i_count = 16;
    o->phi_count = 32;
    o->n_h_count = 5;
    for (int i = 0; i < 5; ++i) o->n_h_values[i] = 1 << i;
}

hairis_tables *hairis_tables_bake(const hairis_fiber *fiber, const hairis_bake_options *o,
                                  hairis_progress_fn progress, void *user)
{
    if (!fiber || !o) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "fiber and options must not be NULL");
        return NULL;
    }
    if (o->n_h_count < 1 || o->n_h_count > 16) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "n_h_count must be in [1, 16], got %d", o->n_h_count);
        return NULL;
    }
    for (int i = 1; i < o->n_h_count; ++i)
        if (o->n_h_values[i] <= o->n_h_values[i - 1]) {
            fail(HAIRIS_ERROR_INVALID_ARGUMENT, "n_h_values must increase");
            return NULL;
        }
    for (int step = 0; step <= 20; ++step) {
        if (progress && progress(user, (float)step / 20.0f)) {
            fail(HAIRIS_ERROR_CANCELLED, "bake cancelled");
            return NULL;
        }
        sleep_ms(2);
    }
    hairis_tables *t = calloc(1, sizeof *t);
    memcpy(t->model, fiber->model, sizeof t->model);
    memcpy(t->parameters, fiber->parameters, sizeof t->parameters);
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
    fprintf(f, "%s\n%s\n%s\n", FAKE_MAGIC, t->model, t->parameters);
    fclose(f);
    if (rename(tmp, path) != 0) return fail(HAIRIS_ERROR_IO, "cannot rename to %s", path);
    clear_error();
    return HAIRIS_OK;
}

static hairis_tables *parse_tables(const char *text, size_t size, const char *what)
{
    char buffer[2048];
    if (size >= sizeof buffer) size = sizeof buffer - 1;
    memcpy(buffer, text, size);
    buffer[size] = '\0';
    char *model = strchr(buffer, '\n');
    char *parameters = model ? strchr(model + 1, '\n') : NULL;
    char *end = parameters ? strchr(parameters + 1, '\n') : NULL;
    if (strncmp(buffer, FAKE_MAGIC "\n", strlen(FAKE_MAGIC) + 1) != 0 || !end) {
        fail(HAIRIS_ERROR_INVALID_TABLE, "%s is not a hairis table file", what);
        return NULL;
    }
    *parameters = '\0';
    *end = '\0';
    hairis_tables *t = calloc(1, sizeof *t);
    snprintf(t->model, sizeof t->model, "%s", model + 1);
    snprintf(t->parameters, sizeof t->parameters, "%s", parameters + 1);
    clear_error();
    return t;
}

hairis_tables *hairis_tables_load_file(const char *path)
{
    if (!path) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "path is NULL");
        return NULL;
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        fail(HAIRIS_ERROR_IO, "cannot read %s: %s", path, strerror(errno));
        return NULL;
    }
    char buffer[2048];
    size_t size = fread(buffer, 1, sizeof buffer, f);
    fclose(f);
    return parse_tables(buffer, size, path);
}

hairis_tables *hairis_tables_load_memory(const void *data, size_t size)
{
    if (!data) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "data is NULL");
        return NULL;
    }
    return parse_tables((const char *)data, size, "the buffer");
}

void hairis_tables_destroy(hairis_tables *tables) { free(tables); }

const char *hairis_tables_model(const hairis_tables *t) { return t ? t->model : ""; }

const char *hairis_tables_parameters(const hairis_tables *t) { return t ? t->parameters : ""; }

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

hairis_sampler *hairis_sampler_create(hairis_strategy strategy, const hairis_fiber *fiber,
                                      const hairis_tables *tables, float multiple_weight, int n_h)
{
    if ((int)strategy < 0 || (int)strategy > 3) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "unknown strategy %d", (int)strategy);
        return NULL;
    }
    if (strategy == HAIRIS_STRATEGY_ANALYTIC && !fiber) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "the ANALYTIC strategy needs a fiber");
        return NULL;
    }
    if (strategy == HAIRIS_STRATEGY_TABLE && !tables) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "the TABLE strategy needs tables");
        return NULL;
    }
    if (!(multiple_weight >= 0.0f && multiple_weight <= 1.0f)) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "multiple_weight must be in [0, 1], got %g",
             (double)multiple_weight);
        return NULL;
    }
    if (n_h < 1) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "n_h must be >= 1, got %d", n_h);
        return NULL;
    }
    hairis_sampler *s = calloc(1, sizeof *s);
    s->strategy = (int)strategy;
    clear_error();
    return s;
}

void hairis_sampler_destroy(hairis_sampler *sampler) { free(sampler); }

int hairis_sample(const hairis_sampler *s, size_t n, const float *wo, const float *h,
                  const float *u, float *wi_out, float *pdf_out)
{
    (void)h;
    if (!s || (n && (!wo || !u || !wi_out || !pdf_out)))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "sampler, wo, u, wi_out, pdf_out: NULL");
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

/* ---- Scenes ------------------------------------------------------------------------------- */

#define MAX_MATERIALS 256

struct hairis_scene {
    int material_count;
    int material_is_hair[MAX_MATERIALS];
    int material_has_tables[MAX_MATERIALS];
    char material_parameters[MAX_MATERIALS][768];
    size_t curve_sets, curve_count, curve_points;
    double radius_sum, position_sum[3];
    size_t mesh_count, vertex_count, triangle_count;
    int suns, points, areas;
    float world[3];
    int has_camera;
    hairis_camera camera;
};

hairis_scene *hairis_scene_create(void)
{
    clear_error();
    return calloc(1, sizeof(hairis_scene));
}

void hairis_scene_destroy(hairis_scene *scene) { free(scene); }

int hairis_scene_add_hair_material(hairis_scene *s, const hairis_principled_hair *node,
                                   const hairis_tables *tables)
{
    if (!s || !node) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene and node must not be NULL");
        return -1;
    }
    if (s->material_count >= MAX_MATERIALS) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "too many materials");
        return -1;
    }
    hairis_fiber *fiber = hairis_fiber_create_principled(node);
    if (!fiber) return -1;
    if (tables && !hairis_tables_match_fiber(tables, fiber)) {
        hairis_fiber_destroy(fiber);
        fail(HAIRIS_ERROR_INVALID_TABLE, "the tables were baked for other parameters");
        return -1;
    }
    int index = s->material_count++;
    s->material_is_hair[index] = 1;
    s->material_has_tables[index] = tables != NULL;
    memcpy(s->material_parameters[index], fiber->parameters, sizeof fiber->parameters);
    hairis_fiber_destroy(fiber);
    clear_error();
    return index;
}

int hairis_scene_add_diffuse_material(hairis_scene *s, const float albedo[3],
                                      const float emission[3])
{
    if (!s || !albedo || !emission) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "scene, albedo and emission must not be NULL");
        return -1;
    }
    if (s->material_count >= MAX_MATERIALS) {
        fail(HAIRIS_ERROR_INVALID_ARGUMENT, "too many materials");
        return -1;
    }
    clear_error();
    return s->material_count++;
}

int hairis_scene_add_curves(hairis_scene *s, int material, size_t curve_count,
                            const uint32_t *first, size_t point_count, const float *positions,
                            const float *radii)
{
    if (!s || !first || (point_count && (!positions || !radii)))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "NULL argument to hairis_scene_add_curves");
    if (material < 0 || material >= s->material_count)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "material %d does not exist", material);
    if (first[0] != 0 || first[curve_count] != point_count)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                    "first[0] must be 0 and first[curve_count] = point_count (%zu), got %u, %u",
                    point_count, first[0], first[curve_count]);
    for (size_t c = 0; c < curve_count; ++c)
        if (first[c + 1] < first[c] + 2)
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "curve %zu has fewer than 2 points", c);
    for (size_t i = 0; i < point_count; ++i) {
        if (!isfinite(positions[3 * i]) || !isfinite(positions[3 * i + 1]) ||
            !isfinite(positions[3 * i + 2]) || !(radii[i] >= 0.0f))
            return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "point %zu is not finite", i);
        s->radius_sum += radii[i];
        for (int k = 0; k < 3; ++k) s->position_sum[k] += positions[3 * i + k];
    }
    s->curve_sets++;
    s->curve_count += curve_count;
    s->curve_points += point_count;
    clear_error();
    return HAIRIS_OK;
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
    }
    s->mesh_count++;
    s->vertex_count += vertex_count;
    s->triangle_count += triangle_count;
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_add_sun(hairis_scene *s, const float direction[3], const float color[3],
                         float strength, float angle)
{
    if (!s || !direction || !color) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "NULL argument");
    float length = sqrtf(direction[0] * direction[0] + direction[1] * direction[1] +
                         direction[2] * direction[2]);
    if (fabsf(length - 1.0f) > 1e-3f)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "sun direction must be a unit vector");
    if (!(strength >= 0.0f) || !(angle >= 0.0f))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "sun strength and angle must be >= 0");
    s->suns++;
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_add_point_light(hairis_scene *s, const float position[3], const float color[3],
                                 float power, float radius)
{
    if (!s || !position || !color) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "NULL argument");
    if (!(power >= 0.0f) || !(radius >= 0.0f))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "point power and radius must be >= 0");
    s->points++;
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_add_area_light(hairis_scene *s, const float light_to_world[16], int shape,
                                float size_x, float size_y, const float color[3], float power)
{
    if (!s || !light_to_world || !color) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "NULL");
    if (shape < HAIRIS_AREA_SQUARE || shape > HAIRIS_AREA_ELLIPSE)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "unknown area shape %d", shape);
    if (!(size_x >= 0.0f) || !(size_y >= 0.0f) || !(power >= 0.0f))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "area sizes and power must be >= 0");
    s->areas++;
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_set_world(hairis_scene *s, const float color[3], float strength)
{
    if (!s || !color) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "NULL argument");
    for (int k = 0; k < 3; ++k) s->world[k] = color[k] * strength;
    clear_error();
    return HAIRIS_OK;
}

int hairis_scene_set_camera(hairis_scene *s, const hairis_camera *camera)
{
    if (!s || !camera) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "NULL argument");
    if (camera->width < 1 || camera->height < 1)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "camera resolution %dx%d is empty",
                    camera->width, camera->height);
    s->camera = *camera;
    s->has_camera = 1;
    clear_error();
    return HAIRIS_OK;
}

void hairis_render_settings_defaults(hairis_render_settings *settings)
{
    if (!settings) return;
    memset(settings, 0, sizeof *settings);
    settings->samples = 64;
    settings->max_bounces = 12;
    settings->strategy = HAIRIS_STRATEGY_TABLE;
    settings->multiple_weight = 0.25f;
    settings->n_h = 2;
}

static void write_summary(const hairis_scene *s, const hairis_render_settings *r)
{
    const char *path = getenv("HAIRIS_FAKE_SUMMARY");
    if (!path || !*path) return;
    FILE *f = fopen(path, "a");
    if (!f) return;
    fprintf(f, "samples=%d max_bounces=%d strategy=%d multiple_weight=%.6g n_h=%d seed=%llu "
               "threads=%d\n",
            r->samples, r->max_bounces, r->strategy, (double)r->multiple_weight, r->n_h,
            (unsigned long long)r->seed, r->threads);
    fprintf(f, "materials=%d curve_sets=%zu curves=%zu points=%zu radius_sum=%.9g "
               "position_sum=%.9g,%.9g,%.9g\n",
            s->material_count, s->curve_sets, s->curve_count, s->curve_points, s->radius_sum,
            s->position_sum[0], s->position_sum[1], s->position_sum[2]);
    fprintf(f, "meshes=%zu vertices=%zu triangles=%zu suns=%d points=%d areas=%d "
               "world=%.6g,%.6g,%.6g\n",
            s->mesh_count, s->vertex_count, s->triangle_count, s->suns, s->points, s->areas,
            (double)s->world[0], (double)s->world[1], (double)s->world[2]);
    fprintf(f, "camera=%dx%d orthographic=%d\n", s->camera.width, s->camera.height,
            s->camera.orthographic);
    for (int i = 0; i < s->material_count; ++i)
        if (s->material_is_hair[i])
            fprintf(f, "hair %d tables=%d %s\n", i, s->material_has_tables[i],
                    s->material_parameters[i]);
    fclose(f);
}

int hairis_render(hairis_scene *s, const hairis_render_settings *r, float *rgba,
                  hairis_progress_fn progress, void *user, hairis_render_stats *stats)
{
    if (!s || !r || !rgba) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "NULL argument");
    if (!s->has_camera) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "the scene has no camera");
    if (r->samples < 1)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "samples must be >= 1, got %d", r->samples);
    if (r->max_bounces < 0)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "max_bounces must be >= 0");
    if (r->strategy < 0 || r->strategy > 3)
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "unknown strategy %d", r->strategy);
    if (!(r->multiple_weight >= 0.0f && r->multiple_weight <= 1.0f))
        return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "multiple_weight must be in [0, 1]");
    if (r->n_h < 1) return fail(HAIRIS_ERROR_INVALID_ARGUMENT, "n_h must be >= 1");
    if (r->strategy == HAIRIS_STRATEGY_TABLE)
        for (int i = 0; i < s->material_count; ++i)
            if (s->material_is_hair[i] && !s->material_has_tables[i])
                return fail(HAIRIS_ERROR_INVALID_ARGUMENT,
                            "hair material %d has no tables (TABLE strategy)", i);
    write_summary(s, r);
    double start = now_seconds();
    const char *delay_text = getenv("HAIRIS_FAKE_ROW_DELAY_MS");
    int delay = delay_text ? atoi(delay_text) : 0;
    /* HAIRIS_FAKE_NOISE: pixels = world·(1 + uniform noise / sqrt(samples)), seeded, so the
     * statistical tests can be dry-run on the fake. */
    const char *noise_text = getenv("HAIRIS_FAKE_NOISE");
    float noise = noise_text ? (float)atof(noise_text) : 0.0f;
    int width = s->camera.width, height = s->camera.height;
    for (int y = 0; y < height; ++y) {
        if (progress && progress(user, (float)y / (float)height))
            return fail(HAIRIS_ERROR_CANCELLED, "render cancelled at row %d of %d", y, height);
        for (int x = 0; x < width; ++x) {
            float *p = rgba + 4 * ((size_t)y * (size_t)width + (size_t)x);
            float factor = 1.0f;
            if (noise > 0.0f) {
                uint64_t h = r->seed * 0x9E3779B97F4A7C15ull + (uint64_t)y * 0xBF58476D1CE4E5B9ull +
                             (uint64_t)x * 0x94D049BB133111EBull + 1u;
                h ^= h >> 31;
                h *= 0xD6E8FEB86659FD93ull;
                h ^= h >> 32;
                float u = (float)(h >> 40) / 16777216.0f;
                factor += noise * (u - 0.5f) * 3.4641016f / sqrtf((float)r->samples);
            }
            p[0] = s->world[0] * factor;
            p[1] = s->world[1] * factor;
            p[2] = s->world[2] * factor;
            p[3] = 1.0f;
        }
        sleep_ms(delay);
    }
    if (progress) progress(user, 1.0f);
    if (stats) {
        stats->seconds = now_seconds() - start;
        stats->camera_rays = (uint64_t)width * (uint64_t)height * (uint64_t)r->samples;
        stats->dropped_samples = 0;
        stats->peak_memory_bytes = sizeof *s;
    }
    clear_error();
    return HAIRIS_OK;
}

/* ---- Layout introspection for the tests --------------------------------------------------- */

#define SIZE_OF(type)                                                                             \
    if (strcmp(name, #type) == 0) return (long)sizeof(type)
#define OFFSET_OF(type, member)                                                                   \
    if (strcmp(name, #type) == 0 && strcmp(field, #member) == 0)                                  \
        return (long)offsetof(type, member)

FAKE_EXPORT long hairis_fake_sizeof(const char *name)
{
    SIZE_OF(hairis_principled_hair);
    SIZE_OF(hairis_marschner_params);
    SIZE_OF(hairis_bake_options);
    SIZE_OF(hairis_camera);
    SIZE_OF(hairis_render_settings);
    SIZE_OF(hairis_render_stats);
    return -1;
}

FAKE_EXPORT long hairis_fake_offsetof(const char *name, const char *field)
{
    OFFSET_OF(hairis_principled_hair, parametrization);
    OFFSET_OF(hairis_principled_hair, color);
    OFFSET_OF(hairis_principled_hair, melanin);
    OFFSET_OF(hairis_principled_hair, melanin_redness);
    OFFSET_OF(hairis_principled_hair, tint);
    OFFSET_OF(hairis_principled_hair, absorption_coefficient);
    OFFSET_OF(hairis_principled_hair, roughness);
    OFFSET_OF(hairis_principled_hair, radial_roughness);
    OFFSET_OF(hairis_principled_hair, coat);
    OFFSET_OF(hairis_principled_hair, ior);
    OFFSET_OF(hairis_principled_hair, offset);
    OFFSET_OF(hairis_principled_hair, random_color);
    OFFSET_OF(hairis_principled_hair, random_roughness);
    OFFSET_OF(hairis_principled_hair, random);
    OFFSET_OF(hairis_marschner_params, eta);
    OFFSET_OF(hairis_marschner_params, sigma_a);
    OFFSET_OF(hairis_marschner_params, alpha_r);
    OFFSET_OF(hairis_marschner_params, alpha_tt);
    OFFSET_OF(hairis_marschner_params, alpha_trt);
    OFFSET_OF(hairis_marschner_params, beta_r);
    OFFSET_OF(hairis_marschner_params, beta_tt);
    OFFSET_OF(hairis_marschner_params, beta_trt);
    OFFSET_OF(hairis_marschner_params, eccentricity);
    OFFSET_OF(hairis_marschner_params, glint_scale);
    OFFSET_OF(hairis_marschner_params, caustic_width);
    OFFSET_OF(hairis_marschner_params, caustic_fade);
    OFFSET_OF(hairis_marschner_params, caustic_intensity_limit);
    OFFSET_OF(hairis_bake_options, theta_r_count);
    OFFSET_OF(hairis_bake_options, theta_i_count);
    OFFSET_OF(hairis_bake_options, phi_count);
    OFFSET_OF(hairis_bake_options, n_h_count);
    OFFSET_OF(hairis_bake_options, n_h_values);
    OFFSET_OF(hairis_bake_options, source);
    OFFSET_OF(hairis_bake_options, threads);
    OFFSET_OF(hairis_camera, camera_to_world);
    OFFSET_OF(hairis_camera, orthographic);
    OFFSET_OF(hairis_camera, frame);
    OFFSET_OF(hairis_camera, width);
    OFFSET_OF(hairis_camera, height);
    OFFSET_OF(hairis_render_settings, samples);
    OFFSET_OF(hairis_render_settings, max_bounces);
    OFFSET_OF(hairis_render_settings, strategy);
    OFFSET_OF(hairis_render_settings, multiple_weight);
    OFFSET_OF(hairis_render_settings, n_h);
    OFFSET_OF(hairis_render_settings, seed);
    OFFSET_OF(hairis_render_settings, threads);
    OFFSET_OF(hairis_render_stats, seconds);
    OFFSET_OF(hairis_render_stats, camera_rays);
    OFFSET_OF(hairis_render_stats, dropped_samples);
    OFFSET_OF(hairis_render_stats, peak_memory_bytes);
    return -1;
}
