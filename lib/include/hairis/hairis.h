/* hairis C API: fiber models, sampling tables and direction sampling.
 *
 * A small C interface over the C++ core, for renderers that embed hairis and for the Blender
 * add-on (through ctypes); the scene and renderer are in hairis_render.h. Conventions:
 *
 *  - Options. Every parameter set (a fiber, a bake, a sampler; in hairis_render.h a material,
 *    light, camera, world or render) is one string "name=value;name=value;...". Names may come
 *    in any order; an omitted name keeps its default (hairis_defaults lists every name with its
 *    default); an unknown name, a repeated one or a value out of range is refused with a
 *    message naming it and saying what is allowed. Numbers are decimal ("%.9g" round-trips a
 *    float), vectors are numbers separated by ',', booleans 0 or 1, choices are words.
 *    THE RULE FOR GROWING THE API: a new parameter is a new name with a default, so no
 *    function's signature changes and no struct exists whose layout could; a new kind of
 *    object is a new function. HAIRIS_API_VERSION changes only when an existing call changes
 *    meaning.
 *  - Errors. Functions that can fail return an int status (HAIRIS_OK = 0, else an error code)
 *    or a handle that is NULL on failure; hairis_last_error() then says what is wrong. Every
 *    function sets the calling thread's last error ("" on success). Nothing aborts the process
 *    on bad input; a C++ exception never escapes (HAIRIS_ERROR_INTERNAL).
 *  - Directions are unit 3-vectors in the fiber frame (x along the tangent, Cycles' frame: see
 *    lib/core/frame.h), packed as 3 floats each; batches are arrays of n items, checked whole
 *    before anything is written (directions finite and of unit length within 1e-3, offsets h
 *    finite and in [-1, 1]); n = 0 with NULL arrays is a no-op.
 *  - Handles are opaque, owned by the caller and released with the matching _destroy call
 *    (NULL is ignored). They may be used from several threads for reading (eval, sample, pdf,
 *    render) at once. Returned strings stay valid as long as the handle (or, for
 *    hairis_last_error and hairis_defaults, until the next hairis call on the thread).
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

#define HAIRIS_API_VERSION 2

/** Status codes. */
enum {
    HAIRIS_OK = 0,
    HAIRIS_ERROR_INVALID_ARGUMENT = 1, /**< a parameter is out of range, unknown, NULL or not finite */
    HAIRIS_ERROR_IO = 2,               /**< a file could not be read or written */
    HAIRIS_ERROR_INVALID_TABLE = 3,    /**< a table file or buffer was refused, or tables do not fit */
    HAIRIS_ERROR_CANCELLED = 4,        /**< the progress callback asked to stop */
    HAIRIS_ERROR_INTERNAL = 5          /**< an unexpected failure (a bug: please report) */
};

typedef struct hairis_fiber hairis_fiber;
typedef struct hairis_tables hairis_tables;
typedef struct hairis_sampler hairis_sampler;

/** Called with progress in [0, 1]; return non-zero to cancel the operation. */
typedef int (*hairis_progress_fn)(void *user, float progress);

/* ---- Library ---------------------------------------------------------------------------- */

/** HAIRIS_API_VERSION of the library, to check against the header a caller was built with. */
HAIRIS_API int hairis_api_version(void);
/** The library's version string, e.g. "0.2.0". */
HAIRIS_API const char *hairis_version_string(void);
/** The last error on the calling thread, or "" when the last call succeeded. Never NULL. */
HAIRIS_API const char *hairis_last_error(void);
/**
 * Every option name of `kind` with its default, as an option string; NULL (and the last error
 * listing the kinds) for an unknown kind. Kinds: "chiang", "huang" and "marschner"
 * (hairis_fiber_create), "bake", "sampler", and hairis_render.h's "diffuse", "principled",
 * "glossy", "emission", "mix", "add", "texture", "sun", "point", "spot", "area", "world",
 * "camera", "render", "curve_inputs", "curves".
 */
HAIRIS_API const char *hairis_defaults(const char *kind);

/* ---- Fibers ----------------------------------------------------------------------------- */

/**
 * A fiber from options; NULL on error.
 *  - "model=chiang" (the default): Blender's Principled Hair BSDF node with the Chiang model,
 *    mapped as Cycles does: parametrization (absorption | melanin | color), color, melanin,
 *    melanin_redness, tint, absorption, roughness, radial_roughness, coat, ior, offset
 *    (radians; offset_deg in degrees), random_color, random_roughness, random, and cycles (the
 *    Blender version whose Cycles evaluates it: 3.4 to 4.1 tilt θ_i, 4.2 and later θ_o).
 *  - "model=huang": the node with the Huang model (Blender 4.0+), as Cycles 4.5 and 5.0
 *    evaluate it: the same names without cycles, radial_roughness and coat (Huang inverts the
 *    colour with roughness), plus aspect_ratio (> 0; above 1 rendered as its inverse, as
 *    Cycles does) and the lobe multipliers reflection, transmission, secondary_reflection
 *    (negative ones count as 0; all three <= 0 is refused: Cycles then makes no closure).
 *  - "model=marschner": Marschner 2003 (eta, sigma_a, alpha_r_deg, ..., eccentricity, ...).
 */
HAIRIS_API hairis_fiber *hairis_fiber_create(const char *options);
HAIRIS_API void hairis_fiber_destroy(hairis_fiber *fiber);
/** "chiang2016", "huang2022" or "marschner2003". */
HAIRIS_API const char *hairis_fiber_model(const hairis_fiber *fiber);
/** The parameters that determine the fiber's scattering, "name=value;..." (what table metadata
 * records): for Chiang the mapped closure parameters, so nodes that scatter alike match. */
HAIRIS_API const char *hairis_fiber_parameters(const hairis_fiber *fiber);
/** f(ω_i, ω_o)·|cos θ_i| (RGB) for n direction pairs; `h` holds n offsets for the near field
 * (Chiang only), or is NULL for the far field (averaged over h). For a huang2022 fiber the
 * frame's y axis is the ellipse's major axis (x the tangent, z = x × y), and f is the
 * expectation of Cycles' stochastic eval. */
HAIRIS_API int hairis_fiber_eval(const hairis_fiber *fiber, size_t n, const float *wi,
                                 const float *wo, const float *h, float *rgb_out);

/* ---- Tables ----------------------------------------------------------------------------- */

/**
 * Bakes tables for a fiber; NULL on error or cancel (then the last error is exactly
 * "cancelled"). Options: theta_r, theta_i, phi (resolution), n_h (strand counts, increasing),
 * source (exact | gaussian), quadrature_points, threads (0: all cores); a huang2022 fiber's
 * tables are its Huang table alone, of huang_theta_o × huang_phi_o view nodes and
 * huang_theta_i × huang_phi cells (the options above but source = exact and threads do not
 * apply to it), with its baked f unless huang_f = 0 (huang_f_refinement, 1 to 4, multiplies
 * the orders of the f part's quadrature: finer and slower) and its multiple part unless
 * huang_multiple = 0. `progress` (may be NULL) is called on the calling thread; non-zero cancels
 * within one θ_r (Huang: θ_o) slice.
 */
HAIRIS_API hairis_tables *hairis_tables_bake(const hairis_fiber *fiber, const char *options,
                                             hairis_progress_fn progress, void *user);
/** Writes tables to an EXR file atomically (a temporary file, then a rename). */
HAIRIS_API int hairis_tables_write(const hairis_tables *tables, const char *path);
/** Loads and validates tables from an EXR file; NULL on error. */
HAIRIS_API hairis_tables *hairis_tables_load_file(const char *path);
/** Loads and validates tables from EXR bytes in memory (e.g. a packed image); NULL on error. */
HAIRIS_API hairis_tables *hairis_tables_load_memory(const void *data, size_t size);
HAIRIS_API void hairis_tables_destroy(hairis_tables *tables);
/** The model the tables were baked for. */
HAIRIS_API const char *hairis_tables_model(const hairis_tables *tables);
/** The fiber parameters the tables were baked for, "name=value;...". */
HAIRIS_API const char *hairis_tables_parameters(const hairis_tables *tables);
/** What the tables hold, as options: source, theta_r, theta_i, phi, n_h; for huang2022 tables
 * source, huang_theta_o, huang_phi_o, huang_theta_i, huang_phi, huang_f (1 when they hold the
 * baked f that renders shade with), huang_f_refinement (with the f part), huang_absorption (1 when
 * they hold the absorption part, the f part at several absorptions for strands of other
 * absorption), huang_absorption_nodes (its number of absorption nodes, with it) and, when they
 * hold the multiple part that integrator=dual_scattering needs, theta_r, theta_i, n_h. */
HAIRIS_API const char *hairis_tables_info(const hairis_tables *tables);
/** 1 when the tables were baked for exactly this fiber's parameters, else 0 (also for NULL
 * arguments, with the last error set). */
HAIRIS_API int hairis_tables_match_fiber(const hairis_tables *tables, const hairis_fiber *fiber);

/* ---- Sampling --------------------------------------------------------------------------- */

/**
 * A direction sampler; NULL on error. Options: strategy (uniform | analytic | gaussian |
 * table; default table), multiple_weight in [0, 1] (the one-sample mixture weight of the
 * multiple-scattering distribution, TABLE and GAUSSIAN), n_h (which multiple distribution:
 * one the tables hold for TABLE, 1, 2, 4, 8 or 16 for GAUSSIAN). `fiber` is needed for
 * ANALYTIC; `tables` for TABLE, where a Chiang `fiber` (optional) makes the single-scattering
 * part follow its near field at h, and the tables must then have been baked for it
 * (HAIRIS_ERROR_INVALID_TABLE otherwise). For a huang2022 `fiber` TABLE samples the tables'
 * Huang table (baked for that fiber), with the frame of hairis_fiber_eval. The sampler keeps
 * what it samples from.
 */
HAIRIS_API hairis_sampler *hairis_sampler_create(const hairis_fiber *fiber, const hairis_tables *tables,
                                                 const char *options);
HAIRIS_API void hairis_sampler_destroy(hairis_sampler *sampler);
/** Draws n incident directions. u holds 3 uniform numbers in [0, 1) per item, h one offset
 * per item (may be NULL: h = 0). Writes wi_out (3n) and pdf_out (n, per steradian; 0 where no
 * direction was produced). */
HAIRIS_API int hairis_sample(const hairis_sampler *sampler, size_t n, const float *wo,
                             const float *h, const float *u, float *wi_out, float *pdf_out);
/** The solid-angle density with which hairis_sample produces each wi (h may be NULL: h = 0). */
HAIRIS_API int hairis_pdf(const hairis_sampler *sampler, size_t n, const float *wi,
                          const float *wo, const float *h, float *pdf_out);
/** f(ω_i, ω_o)·|cos θ_i| (RGB) with which a renderer weights this sampler's directions: the
 * fiber's f at offset h (h may be NULL: h = 0, as hairis_sample). For a huang2022 fiber under
 * TABLE with tables that hold the baked f it is that f: Cycles' R exactly and the other lobes
 * interpolated from their baked expectation, deterministic, in the far field. Refuses a
 * sampler created without a fiber. */
HAIRIS_API int hairis_sampler_eval(const hairis_sampler *sampler, size_t n, const float *wi,
                                   const float *wo, const float *h, float *rgb_out);

#ifdef __cplusplus
}
#endif

#endif /* HAIRIS_H */
