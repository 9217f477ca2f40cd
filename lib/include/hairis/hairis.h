/* hairis C API: fiber models, sampling tables, direction sampling and the hair renderer.
 *
 * A small, stable C interface over the C++ core, for renderers that embed hairis and for the
 * Blender add-on (through ctypes). Conventions:
 *  - Functions that can fail return an int status (HAIRIS_OK = 0, otherwise an error code) or a
 *    handle that is NULL on failure; hairis_last_error() then describes what is wrong and what
 *    is allowed. Nothing aborts the process on bad input. Every function (except
 *    hairis_last_error) sets the calling thread's last error, "" on success; getters and
 *    _defaults given NULL set it and return "" (or nothing). Invalid arguments (NULL, not
 *    finite, out of range, unknown enum values) give HAIRIS_ERROR_INVALID_ARGUMENT with a
 *    message naming the argument; a C++ exception never escapes (HAIRIS_ERROR_INTERNAL).
 *  - Directions are unit 3-vectors in the fiber frame (x along the tangent, Cycles 3.4's frame:
 *    see lib/include/hairis/frame.h), packed as 3 floats each. Batches are arrays of n items.
 *    Directions must be finite and of unit length within 1e-3, offsets h finite and in
 *    [-1, 1]. A batch is checked whole before anything is written: on error the outputs are
 *    untouched. n = 0 with NULL arrays is a no-op (HAIRIS_OK).
 *  - Handles are opaque and owned by the caller, released with the matching _destroy call.
 *  - Handles may be used from several threads for reading (eval, sample, pdf, render) at once.
 */
#ifndef HAIRIS_H
#define HAIRIS_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32)
#define HAIRIS_API __declspec(dllexport)
#else
#define HAIRIS_API __attribute__((visibility("default")))
#endif

#define HAIRIS_API_VERSION 1

/** Status codes. */
enum {
    HAIRIS_OK = 0,
    HAIRIS_ERROR_INVALID_ARGUMENT = 1, /**< a parameter is out of range, NULL or not finite */
    HAIRIS_ERROR_IO = 2,               /**< a file could not be read or written */
    HAIRIS_ERROR_INVALID_TABLE = 3,    /**< a table file or buffer was refused */
    HAIRIS_ERROR_CANCELLED = 4,        /**< the progress callback asked to stop */
    HAIRIS_ERROR_INTERNAL = 5          /**< an unexpected failure (a bug: please report) */
};

/** Sampling strategies. */
typedef enum hairis_strategy {
    HAIRIS_STRATEGY_UNIFORM = 0,  /**< uniform over the sphere */
    HAIRIS_STRATEGY_ANALYTIC = 1, /**< Chiang 2016 lobe sampling, as Cycles and pbrt do (exact pdf) */
    HAIRIS_STRATEGY_GAUSSIAN = 2, /**< the seed's Gaussian PDFs */
    HAIRIS_STRATEGY_TABLE = 3     /**< the baked inverse-CDF tables */
} hairis_strategy;

/** Parametrizations of the Principled Hair BSDF node. */
typedef enum hairis_parametrization {
    HAIRIS_PARAM_ABSORPTION = 0, /**< "Absorption Coefficient" */
    HAIRIS_PARAM_MELANIN = 1,    /**< "Melanin Concentration" */
    HAIRIS_PARAM_COLOR = 2       /**< "Direct Coloring" */
} hairis_parametrization;

/** The inputs of Blender's Principled Hair BSDF node (Cycles 3.4). Angles in radians. */
typedef struct hairis_principled_hair {
    int parametrization;          /**< a hairis_parametrization */
    float color[3];               /**< Direct Coloring */
    float melanin;                /**< Melanin Concentration */
    float melanin_redness;
    float tint[3];
    float absorption_coefficient[3];
    float roughness;
    float radial_roughness;
    float coat;
    float ior;
    float offset;                 /**< cuticle tilt, radians (Blender shows degrees) */
    float random_color;
    float random_roughness;
    float random;                 /**< the "Random" input's value (unlinked: 0) */
} hairis_principled_hair;

/** Marschner 2003 parameters. Angles in radians, absorption per unit radius. */
typedef struct hairis_marschner_params {
    float eta;
    float sigma_a[3];
    float alpha_r, alpha_tt, alpha_trt;
    float beta_r, beta_tt, beta_trt;
    float eccentricity;
    float glint_scale;
    float caustic_width;
    float caustic_fade;
    float caustic_intensity_limit;
} hairis_marschner_params;

typedef struct hairis_fiber hairis_fiber;
typedef struct hairis_tables hairis_tables;
typedef struct hairis_sampler hairis_sampler;
typedef struct hairis_scene hairis_scene;

/** Called with progress in [0, 1]; return non-zero to cancel the operation. */
typedef int (*hairis_progress_fn)(void *user, float progress);

/* ---- Library ---------------------------------------------------------------------------- */

/** HAIRIS_API_VERSION of the library, to check against the header a caller was built with. */
HAIRIS_API int hairis_api_version(void);
/** The library's version string, e.g. "0.1.0". */
HAIRIS_API const char *hairis_version_string(void);
/** The last error on the calling thread, or "" when the last call succeeded. Never NULL; valid
 * until the next hairis call on this thread. */
HAIRIS_API const char *hairis_last_error(void);

/* ---- Fibers ----------------------------------------------------------------------------- */

/** Fills `node` with the Principled Hair BSDF node's defaults in Blender 3.4. */
HAIRIS_API void hairis_principled_hair_defaults(hairis_principled_hair *node);
/** Fills `params` with the seed's Marschner defaults (blonde absorption). */
HAIRIS_API void hairis_marschner_defaults(hairis_marschner_params *params);
/** A Chiang 2016 fiber from a Principled Hair node, mapped as Cycles 3.4 does; NULL on error. */
HAIRIS_API hairis_fiber *hairis_fiber_create_principled(const hairis_principled_hair *node);
/** A Marschner 2003 fiber; NULL on error. */
HAIRIS_API hairis_fiber *hairis_fiber_create_marschner(const hairis_marschner_params *params);
/** Releases a fiber (NULL is ignored). */
HAIRIS_API void hairis_fiber_destroy(hairis_fiber *fiber);
/** "chiang2016" or "marschner2003". */
HAIRIS_API const char *hairis_fiber_model(const hairis_fiber *fiber);
/** The fiber's parameters as "name=value;..." (what table metadata records). For Chiang
 * fibers these are the mapped closure parameters, so nodes that scatter alike give the same
 * string. Marschner's float fields are widened through their shortest decimal form
 * (1.55f -> 1.55), so values typed as decimals match a hairis-bake parameter file; angles in
 * radians cannot reproduce a preset defined in degrees to the 9 digits the metadata keeps. */
HAIRIS_API const char *hairis_fiber_parameters(const hairis_fiber *fiber);
/**
 * Evaluates f(ω_i, ω_o)·|cos θ_i| (RGB) for n direction pairs. `h` holds n offsets for the
 * near field (Chiang only), or is NULL for the far field (averaged over h).
 */
HAIRIS_API int hairis_fiber_eval(const hairis_fiber *fiber, size_t n, const float *wi,
                                 const float *wo, const float *h, float *rgb_out);

/* ---- Tables ----------------------------------------------------------------------------- */

/** Resolution and content of a bake. */
typedef struct hairis_bake_options {
    int theta_r_count;      /**< θ_r nodes over [−π/2, π/2] */
    int theta_i_count;      /**< θ_i cells */
    int phi_count;          /**< φ cells */
    int n_h_count;          /**< entries used in n_h_values */
    int n_h_values[16];     /**< strands for the multiple tables, increasing */
    int source;             /**< 0: exact distributions, 1: the seed's Gaussian PDFs */
    int threads;            /**< 0: all cores */
} hairis_bake_options;

/** Fills `options` with the default table resolution. */
HAIRIS_API void hairis_bake_options_defaults(hairis_bake_options *options);
/** Bakes tables for a fiber; NULL on error or cancel (hairis_last_error says which: after a
 * cancel it is exactly "cancelled"). `progress` (may be NULL) is called on the calling
 * thread; its returning non-zero cancels within one theta_r slice. */
HAIRIS_API hairis_tables *hairis_tables_bake(const hairis_fiber *fiber,
                                             const hairis_bake_options *options,
                                             hairis_progress_fn progress, void *user);
/** Writes tables to an EXR file atomically (temporary file, then rename). */
HAIRIS_API int hairis_tables_write(const hairis_tables *tables, const char *path);
/** Loads and validates tables from an EXR file; NULL on error. */
HAIRIS_API hairis_tables *hairis_tables_load_file(const char *path);
/** Loads and validates tables from EXR bytes in memory (e.g. a packed image); NULL on error. */
HAIRIS_API hairis_tables *hairis_tables_load_memory(const void *data, size_t size);
/** Releases tables (NULL is ignored). */
HAIRIS_API void hairis_tables_destroy(hairis_tables *tables);
/** The model the tables were baked for. */
HAIRIS_API const char *hairis_tables_model(const hairis_tables *tables);
/** The fiber parameters the tables were baked for, "name=value;...". */
HAIRIS_API const char *hairis_tables_parameters(const hairis_tables *tables);
/** 1 when the tables were baked for exactly this fiber's parameters (same model, same
 * parameter string), else 0 (also for NULL arguments, with the last error set). */
HAIRIS_API int hairis_tables_match_fiber(const hairis_tables *tables, const hairis_fiber *fiber);

/* ---- Sampling --------------------------------------------------------------------------- */

/**
 * A direction sampler. `fiber` is needed for ANALYTIC (Chiang only), `tables` for TABLE.
 * TABLE with a chiang2016 `fiber` (optional) samples its single scattering from the fiber's
 * near-field table, following the offset h (what a renderer shading Cycles' near field wants);
 * without one, from the tables' h-averaged 2D distribution. Either way the pdf is exact.
 * `multiple_weight` ∈ [0, 1] is the one-sample mixture weight of the multiple-scattering
 * distribution (TABLE and GAUSSIAN), `n_h` selects which multiple distribution: one of the
 * tables' n_h values (TABLE), one of 1, 2, 4, 8, 16 (GAUSSIAN), ignored otherwise. The sampler
 * keeps what it samples from: it stays valid after `fiber` and `tables` are destroyed.
 */
HAIRIS_API hairis_sampler *hairis_sampler_create(hairis_strategy strategy,
                                                 const hairis_fiber *fiber,
                                                 const hairis_tables *tables,
                                                 float multiple_weight, int n_h);
/** Releases a sampler (NULL is ignored). */
HAIRIS_API void hairis_sampler_destroy(hairis_sampler *sampler);
/**
 * Draws n incident directions. u holds 3 uniform numbers in [0, 1) per item, h one offset per
 * item (may be NULL: h = 0). Writes wi_out (3n) and pdf_out (n, per steradian; 0 where no
 * direction was produced).
 */
HAIRIS_API int hairis_sample(const hairis_sampler *sampler, size_t n, const float *wo,
                             const float *h, const float *u, float *wi_out, float *pdf_out);
/** The solid-angle density with which hairis_sample produces each wi (h may be NULL: h = 0). */
HAIRIS_API int hairis_pdf(const hairis_sampler *sampler, size_t n, const float *wi,
                          const float *wo, const float *h, float *pdf_out);


/* ---- Scenes and rendering ---------------------------------------------------------------- */

/** Light shapes of area lights (Blender's names). */
typedef enum hairis_area_shape {
    HAIRIS_AREA_SQUARE = 0,
    HAIRIS_AREA_RECTANGLE = 1,
    HAIRIS_AREA_DISK = 2,
    HAIRIS_AREA_ELLIPSE = 3
} hairis_area_shape;

/** A camera as Blender describes it. Matrices are 4×4, row-major, camera-to-world. */
typedef struct hairis_camera {
    float camera_to_world[16]; /**< Blender camera: looks down −Z, +Y up */
    int orthographic;          /**< 0 perspective, 1 orthographic */
    /** Image-plane frame from Camera.view_frame(scene=...): 4 corners (x, y, z) in camera
     * space, in Blender's order (top right, bottom right, bottom left, top left). It already
     * holds lens, sensor fit and shift. */
    float frame[12];
    int width, height;         /**< output resolution in pixels */
} hairis_camera;

/** Render settings (the add-on's scene.hairis). */
typedef struct hairis_render_settings {
    int samples;            /**< samples per pixel, ≥ 1 */
    int max_bounces;        /**< as Cycles' Max Bounces (Total), ≥ 0 */
    int strategy;           /**< a hairis_strategy for hair BSDF sampling */
    float multiple_weight;  /**< mixture weight of the multiple-scattering table/PDF */
    int n_h;                /**< the multiple-scattering table used */
    uint64_t seed;          /**< same seed, same image, whatever the thread count */
    int threads;            /**< 0: all cores */
} hairis_render_settings;

/** What a render did. */
typedef struct hairis_render_stats {
    double seconds;
    uint64_t camera_rays;
    uint64_t dropped_samples;  /**< NaN or infinite contributions discarded */
    uint64_t peak_memory_bytes;
} hairis_render_stats;

/** An empty scene. */
HAIRIS_API hairis_scene *hairis_scene_create(void);
/** Releases a scene (NULL is ignored). */
HAIRIS_API void hairis_scene_destroy(hairis_scene *scene);
/**
 * Adds a hair material from a Principled Hair node; `tables` (may be NULL) are used by the
 * TABLE strategy and must match the node's parameters. Returns the material index, or −1.
 * The scene keeps the tables' data (the tables handle may be destroyed). The match is checked
 * by hairis_render, for the TABLE strategy only: a hair material without tables, with tables
 * baked for other parameters, or without settings.n_h fails with HAIRIS_ERROR_INVALID_TABLE
 * naming the material index.
 */
HAIRIS_API int hairis_scene_add_hair_material(hairis_scene *scene,
                                              const hairis_principled_hair *node,
                                              const hairis_tables *tables);
/** Adds a diffuse (Lambert) material with an emission; returns its index, or −1. */
HAIRIS_API int hairis_scene_add_diffuse_material(hairis_scene *scene, const float albedo[3],
                                                 const float emission[3]);
/**
 * Adds hair curves drawn as round Catmull-Rom curves (Cycles' "3D Curves"): curve c has points
 * first[c] .. first[c+1]−1 (first has curve_count+1 entries), positions xyz in world space,
 * one radius per point. `material` must already be in the scene (hair or diffuse).
 */
HAIRIS_API int hairis_scene_add_curves(hairis_scene *scene, int material, size_t curve_count,
                                       const uint32_t *first, size_t point_count,
                                       const float *positions, const float *radii);
/** Adds a triangle mesh in world space; `materials` holds one material index per triangle
 * (diffuse materials already in the scene). */
HAIRIS_API int hairis_scene_add_mesh(hairis_scene *scene, size_t vertex_count,
                                     const float *positions, size_t triangle_count,
                                     const uint32_t *indices, const int32_t *materials);
/** A sun: `direction` points from the scene towards the sun; strength in W/m², angle in radians. */
HAIRIS_API int hairis_scene_add_sun(hairis_scene *scene, const float direction[3],
                                    const float color[3], float strength, float angle);
/** A point light of power `power` W (Blender's), radius in metres. */
HAIRIS_API int hairis_scene_add_point_light(hairis_scene *scene, const float position[3],
                                            const float color[3], float power, float radius);
/** An area light with Blender's object matrix (row-major 4×4), shape and sizes, power in W. */
HAIRIS_API int hairis_scene_add_area_light(hairis_scene *scene, const float light_to_world[16],
                                           int shape, float size_x, float size_y,
                                           const float color[3], float power);
/** The world: a constant background radiance colour·strength. */
HAIRIS_API int hairis_scene_set_world(hairis_scene *scene, const float color[3], float strength);
/** The camera. */
HAIRIS_API int hairis_scene_set_camera(hairis_scene *scene, const hairis_camera *camera);
/** Fills `settings` with defaults: the add-on's (64 samples, 12 bounces, TABLE, weight 0,
 * n_h 2, seed 0, all threads). */
HAIRIS_API void hairis_render_settings_defaults(hairis_render_settings *settings);
/**
 * Renders into rgba (width·height·4 floats, bottom row first, as Blender's render result
 * wants). progress may be NULL; returning non-zero from it cancels (HAIRIS_ERROR_CANCELLED,
 * promptly; rgba then holds the average of the samples finished so far, and stats are filled).
 * progress is only called on the calling thread. stats may be NULL; stats->seconds covers the
 * whole call. A scene without camera or without geometry is refused. Each call builds the
 * scene anew (the scene keeps its own copy of the geometry), so a scene can be rendered again
 * with other settings, also from several threads at once. The camera does not clip.
 */
HAIRIS_API int hairis_render(hairis_scene *scene, const hairis_render_settings *settings,
                             float *rgba, hairis_progress_fn progress, void *user,
                             hairis_render_stats *stats);

#ifdef __cplusplus
}
#endif

#endif /* HAIRIS_H */
