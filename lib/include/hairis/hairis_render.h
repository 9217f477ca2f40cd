/* hairis render API: a scene of hair curves, meshes, materials, lights, world and camera, and
 * the hair path tracer behind the Blender add-on's "Hairis" engine (lib/render/render.h).
 * Conventions as hairis.h: options strings, status codes, hairis_last_error().
 *
 * Lights, materials, the world, the camera and the render settings are option strings
 * (hairis_defaults("sun"), "point", "spot", "area", "world", ... list every name with its
 * default); geometry and world pixels are arrays.
 * Matrices are 16 numbers, row-major, object-to-world, as Blender's matrix_world.
 */
#ifndef HAIRIS_RENDER_H
#define HAIRIS_RENDER_H

#include "hairis/hairis.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct hairis_scene hairis_scene;

HAIRIS_API hairis_scene *hairis_scene_create(void);
HAIRIS_API void hairis_scene_destroy(hairis_scene *scene);

/**
 * Adds a hair material of `fiber` (a chiang2016 or huang2022 fiber); `tables` (may be NULL)
 * are what the TABLE strategy samples and must have been baked for the fiber. Returns the material index, or -1.
 * The scene keeps what it needs (the handles may be destroyed). Whether the tables fit is
 * checked by hairis_render for the TABLE strategy: HAIRIS_ERROR_INVALID_TABLE naming the
 * material otherwise.
 */
HAIRIS_API int hairis_scene_add_hair_material(hairis_scene *scene, const hairis_fiber *fiber,
                                              const hairis_tables *tables);
/**
 * Adds a hair material that mixes `count` (1 to 8) hair materials of this scene, each added by
 * hairis_scene_add_hair_material with a chiang2016 fiber, as Cycles renders a Mix Shader or Add
 * Shader of Principled Hair BSDFs: f is the sum of weights[k] times material k's f, and a
 * sample draws one closure with probability weights[k] / (sum of weights) from its own sampler,
 * so the density is the same weighted sum of the closures' densities. A closure's weight is
 * Cycles' closure weight: the product of the mix factors on its way to the output (1 through
 * an Add Shader); finite and >= 0. hairis_scene_add_curves_with_inputs' weight0 .. weight7 vary
 * it per curve or point; its node inputs go to every closure that reads them. Returns the
 * material index, or -1. integrator=dual_scattering refuses a mixture.
 */
HAIRIS_API int hairis_scene_add_hair_mixture(hairis_scene *scene, size_t count, const int *materials,
                                             const float *weights);
/**
 * Adds a surface material (a mesh's shader nodes, as Cycles renders them) from options; returns
 * its index or -1. type = diffuse | principled | glossy | emission | mix | add
 * (hairis_defaults(type) lists each type's names and defaults):
 *  - "diffuse": Diffuse BSDF (color, roughness: Oren-Nayar above 0) plus an emission radiance;
 *  - "principled": Principled BSDF with cycles = 3.4 (Blender 3.x's inputs: specular,
 *    specular_tint, subsurface, subsurface_color, sheen, sheen_tint, coat = Clearcoat,
 *    coat_roughness) or 4.5 (Blender 4.x and 5.0's: specular = Specular IOR Level,
 *    specular_tint_color, subsurface = Subsurface Weight, coat = Coat Weight, coat_roughness,
 *    coat_ior, coat_tint, diffuse_roughness), both with base_color, metallic, roughness, ior,
 *    distribution = ggx | multi_ggx and emission (Emission Color x Strength); inputs of the other
 *    version must keep their defaults;
 *  - "glossy": Glossy BSDF (color, roughness, distribution);
 *  - "emission": Emission (color, strength);
 *  - "mix": Mix Shader of surface materials shader1 and shader2 by factor; "add": Add Shader.
 * Colour inputs base_color (principled) and color (diffuse, glossy) take an Image Texture by
 * index with base_color_texture / color_texture (-1: none), read at the mesh's UV map (see
 * hairis_scene_set_mesh_attribute). Every BSDF type takes cycles = 3.4 (default) | 4.5; the BSDF
 * nodes of one material (through mix and add) must follow the same version.
 */
HAIRIS_API int hairis_scene_add_surface_material(hairis_scene *scene, const char *options);
/**
 * Adds an Image Texture for surface materials from options; returns its index or -1.
 * image=<path> (a file OpenImageIO reads; the path may not hold ';' nor start or end with a
 * space: use hairis_scene_add_texture_pixels then), color_space = auto (float files linear,
 * 8-bit files sRGB) | linear | srgb (decoded after interpolation, as Cycles does),
 * interpolation = linear | closest, extension = repeat | extend | clip | mirror, and the Mapping
 * node between the UV map and the texture: mapping = none | point | texture | vector with
 * location, rotation (XYZ Euler, radians) and scale (which need a mapping). Alpha is ignored.
 */
HAIRIS_API int hairis_scene_add_texture(hairis_scene *scene, const char *options);
/**
 * The same with the image as `pixels`: width x height pixels of `channels` (1 to 4) floats,
 * the BOTTOM row first (Blender's Image.pixels), finite and >= 0; options without image,
 * color_space linear or srgb. The pixels are copied.
 */
HAIRIS_API int hairis_scene_add_texture_pixels(hairis_scene *scene, const char *options,
                                               const float *pixels, size_t width, size_t height,
                                               int channels);
/**
 * Adds hair curves drawn as round Catmull-Rom curves (Cycles' "3D Curves"): curve c has points
 * first[c] .. first[c+1]-1 (first has curve_count+1 entries), positions xyz in world space,
 * one radius per point. `material` must already be in the scene. The curves have no normals:
 * elliptical Huang fibers on them take Cycles' fallback frame around the tangent, as
 * Blender's particle hair does in Cycles.
 */
HAIRIS_API int hairis_scene_add_curves(hairis_scene *scene, int material, size_t curve_count,
                                       const uint32_t *first, size_t point_count,
                                       const float *positions, const float *radii);
/**
 * Adds hair curves as hairis_scene_add_curves does, with some of their hair material's node
 * inputs given per curve or per point in place of the fiber's own values (Hair Info, Cycles'
 * per-strand random number or attributes feeding the Principled Hair BSDF in Blender).
 * `inputs` says where each input comes from, "name=material|curve|point;..."; every name
 * defaults to material (hairis_defaults("curve_inputs") lists them in order): color,
 * melanin, melanin_redness, tint, absorption, roughness, radial_roughness, coat, ior,
 * offset (radians), random_color, random_roughness, random — the node inputs of
 * hairis_fiber_create, in the same units and ranges (colour and tint > 0, absorption >= 0,
 * ior > 1, offset in [-pi/2, pi/2], the others in [0, 1]), and only those the material's
 * parametrization reads (a huang2022 material reads neither radial_roughness nor coat). `values` holds value_count floats: for each input given per curve
 * or per point, in that order, its components (3 for color, tint and absorption, else 1) for
 * each curve (curve_count items) or each point (point_count items) in turn, then weight0 ..
 * weight7 (a hair mixture's closure weights, finite and >= 0) given per curve or point, one
 * float each. A renderer
 * evaluates the fiber at a hit with the hit's values: a curve's own, or a point value
 * interpolated linearly in the segment's curve parameter between its two points, as Cycles
 * interpolates curve attributes, then mapped as Cycles maps the node (Random Color and
 * Random Roughness from the hit's random, melanin, colours). The TABLE strategy samples the
 * tables baked for the fiber's own values and stays exact for every strand; a huang2022
 * strand is shaded with its own f (the baked f corrected by the strand's Cycles eval where
 * only its absorption differs, else its Cycles eval).
 */
HAIRIS_API int hairis_scene_add_curves_with_inputs(hairis_scene *scene, int material, size_t curve_count,
                                                   const uint32_t *first, size_t point_count,
                                                   const float *positions, const float *radii,
                                                   const char *inputs, size_t value_count,
                                                   const float *values);
/**
 * Adds hair curves as hairis_scene_add_curves does, with the curves' normal attribute:
 * `normals` holds 3 finite floats per point (Blender's Curves.normals), interpolated linearly
 * along each segment. A Huang fiber with an aspect ratio other than 1 puts its major axis
 * along the normal made perpendicular to the tangent; where that is zero (a zero normal, or
 * one along the tangent) it takes the fallback frame. The normals are used as given, as
 * Cycles does (it does not rotate them with the object). `options`: none yet ("" or NULL;
 * hairis_defaults("curves")).
 */
HAIRIS_API int hairis_scene_add_curves_with_normals(hairis_scene *scene, int material,
                                                    size_t curve_count, const uint32_t *first,
                                                    size_t point_count, const float *positions,
                                                    const float *radii, const float *normals,
                                                    const char *options);
/** Adds a triangle mesh in world space; `materials` holds one material index per triangle. */
HAIRIS_API int hairis_scene_add_mesh(hairis_scene *scene, size_t vertex_count,
                                     const float *positions, size_t triangle_count,
                                     const uint32_t *indices, const int32_t *materials);
/**
 * Per-corner data of the mesh the last hairis_scene_add_mesh call added (refused when that call
 * added no triangles), in the order of its indices, from options name = normal (3 floats per
 * corner: world-space shading normals, finite and not zero, interpolated across each triangle
 * and normalized as Cycles does; without them the face normal shades) | uv (2 floats per corner:
 * the UV map Image Textures read; without it UV is (0, 0)). `count` is the number of floats
 * (9 or 6 per triangle). Setting a name again replaces it.
 */
HAIRIS_API int hairis_scene_set_mesh_attribute(hairis_scene *scene, const char *options,
                                               const float *values, size_t count);
/**
 * Adds a light from options, in Blender's units and names: "type=sun" (direction towards the
 * sun, color, strength W/m², angle), "type=point" (position, color, power W, radius),
 * "type=spot" (matrix: the light object's, shining along its -Z; color, power W, radius =
 * shadow_soft_size, spot_size = the full cone angle in radians [1°, 180°], spot_blend [0, 1]),
 * "type=area" (matrix, shape square | rectangle | disk | ellipse, size, size_y, color, power).
 * Every light takes cycles=3.4 (default) | 4.5: the Cycles whose conversion it follows (4.5
 * for Blender 4.1 to 5.0: area lights 4/pi brighter, suns a cone of constant radiance, spots
 * without 3.4's cosine and shaped in the light's scaled frame); points and spots also take
 * soft_falloff=1 (default; Blender 4.1+'s Soft Falloff) | 0 (a sphere; needs cycles=4.5).
 */
HAIRIS_API int hairis_scene_add_light(hairis_scene *scene, const char *options);
/**
 * The world from options. Without an image: a constant background of radiance color ×
 * strength (color default 0,0,0), never light-sampled. With image=<path> (a file OpenImageIO
 * reads, e.g. EXR or Radiance HDR; the path may not hold ';' nor start or end with a space:
 * use hairis_scene_set_world_pixels then): Cycles' Background fed by an Environment Texture
 * (equirectangular, linear interpolation), radiance = color × strength × texture, color then
 * defaulting to 1,1,1. color_space = auto (float files linear, 8-bit files sRGB) | linear |
 * srgb. The lookup direction is Mapping(matrix · d): matrix (16 numbers, row-major, default
 * identity) maps world directions first (e.g. a Texture Coordinate Object output: the
 * object's inverse matrix, without translation), then the Mapping node: mapping = point |
 * texture | vector | normal, rotation (XYZ Euler, radians), scale (its Location must be 0 and
 * is not taken). sampling = auto (default: light-sampled with an importance map at the
 * image's resolution but at least 4096 x 2048 and at most 8192 x 4096, as Cycles' Auto) | manual (map_resolution x map_resolution/2,
 * map_resolution in [1, 8192], default 1024) | none (not light-sampled: found by BSDF rays
 * alone), as World > Settings > Sampling. Environment options other than their defaults are
 * refused without an environment. The image is read and its importance map built here.
 */
HAIRIS_API int hairis_scene_set_world(hairis_scene *scene, const char *options);
/**
 * The world as hairis_scene_set_world with an environment whose image is `pixels`: width ×
 * height pixels of `channels` (1 grey, 2 grey + alpha, 3 RGB, 4 RGBA; alpha is ignored)
 * floats, the BOTTOM row first (Blender's Image.pixels). Options as hairis_scene_set_world's,
 * without image; color_space must be linear or srgb (srgb: the stored values are sRGB-encoded
 * and decoded after interpolation, as Cycles does). Every value must be finite and >= 0. The
 * pixels are copied.
 */
HAIRIS_API int hairis_scene_set_world_pixels(hairis_scene *scene, const char *options,
                                             const float *pixels, size_t width, size_t height,
                                             int channels);
/**
 * The camera from options: matrix (camera-to-world; Blender's camera looks down -Z, +Y up),
 * orthographic (0 | 1), frame (Camera.view_frame's 4 corners in camera space, 12 numbers: top
 * right, bottom right, bottom left, top left), width and height in pixels.
 */
/**
 * Removes the scene's materials, textures, lights and world, keeping its curves, meshes, mesh
 * attributes and camera, so that an edit of materials or lights is sent without the geometry:
 * add the materials again in their first order (curves and meshes keep the material indices
 * they were added with), then textures, lights and world. The next render keeps the BVH built
 * for the geometry (see hairis_render) and checks the new materials against it as it checks a
 * new scene: a mesh on a hair material, a material index out of range or curve inputs the new
 * material does not read are refused (HAIRIS_ERROR_INVALID_ARGUMENT, naming them).
 */
HAIRIS_API int hairis_scene_reset_shading(hairis_scene *scene);
HAIRIS_API int hairis_scene_set_camera(hairis_scene *scene, const char *options);
/**
 * Renders into rgba (width·height·4 floats, bottom row first, as Blender's render result
 * wants). Settings (options): integrator (path | dual_scattering), samples, max_bounces, max_diffuse_bounces, max_glossy_bounces,
 * max_transmission_bounces, strategy, multiple_weight, n_h, seed, threads, tile_size,
 * film_transparent, curve_backfaces = ignore (default) | hit: whether a ray that meets a
 * curve from inside its tube (it started inside another, overlapping strand) passes, as in
 * Cycles built with Embree 3 (Blender 3.4), or hits it, as in Cycles with Embree 4 (Blender's
 * builds from 3.6: 4.5, 5.0), curve_shape = thick (default) | ribbons | thick_linear: Cycles'
 * Curves > Shape (3D Curves, Rounded Ribbons, 5.0's Linear 3D Curves), bvh_quality = low | medium
 * (default) | high: the work Embree spends on the BVH, as Cycles asks for it in the viewport, in
 * a final render and with Use Spatial Splits (the image is the same), curve_subdivisions (in
 * [0, 24], default 2): Cycles' Curves > Subdivisions, Embree's tessellation rate
 * clamp(2^s, 1, 16) + 1 as Cycles sets it (ribbons are intersected as that many pieces per
 * segment), transparent_limit = plus_one (default) | setting: a path crosses
 * at most max_transparent_bounces + 1 transparent surfaces, as Cycles up to 4.5 (it stores the
 * setting + 1), or max(max_transparent_bounces, 1), as Cycles 5.0. filter_glossy (in [0, 10],
 * default 0 = off), clamp_direct and clamp_indirect (>= 0, default 0 = off): Cycles' Filter Glossy
 * and Clamping, applied as Cycles applies them (Blender's defaults are 1, 0 and 10); pixel_filter
 * = box (default) | gaussian | blackman_harris and pixel_filter_width (pixels, in [0.001, 10],
 * default 1): Cycles' Film > Pixel Filter, whose importance table places each camera sample
 * (Blender's default: blackman_harris, 1.5; Cycles renders a box at 1 px whatever its width);
 * exposure (in [0, 10], default 1): Cycles' Film > Exposure, scaling the image's colour (not its
 * alpha or data passes) when it is read out.
 * progress may be NULL; non-zero from it cancels
 * (HAIRIS_ERROR_CANCELLED, promptly; rgba then holds the samples finished so far); it is only
 * called on the calling thread. integrator=dual_scattering shades hair by dual scattering
 * (lib/render/dual_scattering_integrator.h) and needs every hair material's tables
 * (HAIRIS_ERROR_INVALID_TABLE naming the material otherwise); its dual_hair_volume = layer
 * (default: the hair is a layer over what is under it, whose light reaches hair through the
 * strands) | unbounded (Zinke et al.'s semi-infinite hair volume), and dual_exact_bounces (in
 * [0, 1024], default 3) the path's first scattering vertices that are path-traced before the
 * first hair vertex at that depth or deeper closes the path by dual scattering (0: at the
 * first hair hit, the paper's), and dual_bounce_limit = bounces (default: that vertex adds only
 * the orders of scattering the path tracer would reach within max_bounces and
 * max_transmission_bounces, as Cycles ends its paths) | none (every order, the paper's).
 * huang_sampling = strategy (default: Huang hair samples with the material's strategy and its
 * exact density) | cycles (Cycles' own chained Huang sampler with pdf 1 for MIS, as Cycles
 * renders Huang; its light samples are shaded with the material's baked f where its tables
 * hold one for its parameters, else with Cycles' eval). A scene without camera is
 * refused; one without geometry renders the world (every ray misses). A scene can be rendered
 * again with other settings, also from several threads at once. The scene keeps the last
 * render's build (BVH, lights, materials) while nothing but its camera changes: a render whose
 * sampler, integrator, huang_sampling, curve_backfaces, curve_shape, curve_subdivisions and bvh_quality are the last render's
 * reuses it with the current camera (build_seconds 0, scene_reused 1), so a new view costs no
 * new BVH. While its curves and meshes stay and no other render uses it, its BVH is kept for a
 * render with other materials, textures, lights or world (hairis_scene_reset_shading) or other
 * settings with the same curve_backfaces, curve_shape, curve_subdivisions and bvh_quality (geometry_reused 1); adding curves,
 * meshes or mesh attributes frees it. hairis_scene_destroy frees it too.
 */
HAIRIS_API int hairis_render(hairis_scene *scene, const char *settings, float *rgba,
                             hairis_progress_fn progress, void *user);
/**
 * Called by hairis_render_progressive on the calling thread: progress in [0, 1], samples_done
 * the samples every pixel still being refined has (it grows exactly when rgba changed), final
 * 1 on the last call. Return non-zero to stop the render, keeping what it has.
 */
typedef int (*hairis_update_fn)(void *user, float progress, int samples_done, int final);
/**
 * Renders as hairis_render, refining the whole image: the samples are rendered in rounds over
 * every pixel (1, 1, 2, 4, ... samples per pixel, each round short enough for a prompt
 * update), and after each round rgba (and passes) hold, for every pixel, the average of the
 * samples it has so far. Each pixel sums its samples in sample order, so the finished image
 * is bit for bit hairis_render's with the same settings, for any thread count and tile size.
 * `update` (may be NULL) is called on the calling thread after every round and at least every
 * half second in between (rgba unchanged then), and once at the end with final = 1; between
 * calls the caller must not read rgba or passes. Non-zero from it stops the render promptly
 * (each tile in flight finishes its current sample) and returns HAIRIS_ERROR_CANCELLED, rgba
 * and passes holding each pixel's average of the samples it got. Settings are hairis_render's
 * and these (which hairis_render takes too, all but passes):
 *  - time_limit (seconds, >= 0; default 0 = none): as Cycles' Time Limit, the render stops
 *    after the round in which the limit is passed (HAIRIS_OK, the image of the samples done);
 *  - adaptive_threshold (in [0, 1]; default 0 = off): Cycles' Noise Threshold. From the sample
 *    after adaptive_min_samples on, every 16 samples, a pixel whose error estimate is below
 *    the threshold stops: the estimate is Cycles' |average - average of every other
 *    sample| summed over R, G, B, divided by sqrt(R + G + B) below 1 and by R + G + B
 *    above, against 5 × the threshold; a converged pixel whose neighbour along a row or
 *    column has not converged is sampled on, as Cycles' filter does. Decisions depend only
 *    on the pixels' samples, so the image is the same for a given seed whatever the threads;
 *  - adaptive_min_samples (in [0, 2^24]; default 0 = automatic as Cycles: max(4,
 *    ceil(16 / threshold^0.3))): no pixel stops before it has more samples than this;
 *  - region = "x0,y0,x1,y1" (pixels, half-open, rows counted as in rgba: bottom row 0;
 *    default "0,0,0,0" = the whole image): only these pixels are rendered, the others are 0
 *    in rgba and passes; a region's pixels equal the full render's bit for bit;
 *  - passes = a comma list of depth, normal, denoising_albedo and denoising_normal (default
 *    "": none), as Cycles writes them at the first surface that is not transparent (Huang
 *    hair the ray passes is not it): depth (1 channel) the distance from the camera along its
 *    view axis of sample 0's surface, 1e10 where it found none, not averaged (Cycles' Z
 *    pass); normal (3) the shading normal in world space turned towards the viewer, 0 where
 *    the ray found nothing, averaged over the pixel's samples as rgba. The denoising passes
 *    (3 each, averaged likewise) are Cycles' Denoising Albedo and Denoising Normal, written
 *    at the first vertex whose closures are not mostly specular (microfacet roughness² up to
 *    0.075²; every hair closure counts as diffuse): the sum of its closures' albedos (Cycles'
 *    bsdf_albedo; for Principled Hair the Chiang or Huang reflectance estimate) times the
 *    specular albedos passed on the way, plus the light the path meets before it (the world
 *    where the camera sees it; 0 for a transparent film), and the closure-weighted average
 *    normal there (Chiang: perpendicular to the strand and the view; Huang: the strand
 *    tangent) in camera space (x right, y up, z along the view), 0 where there is none.
 * `passes` (may be NULL when passes is empty) holds width·height·K floats, K the sum of the
 * channels of the passes in the order given: all pixels of the first pass (each pixel's
 * channels together, bottom row first), then of the next. hairis_last_render_stats adds
 * samples (the most any pixel got) and converged_pixels (pixels adaptive sampling stopped).
 */
HAIRIS_API int hairis_render_progressive(hairis_scene *scene, const char *settings, float *rgba,
                                         float *passes, hairis_update_fn update, void *user);
/** What the calling thread's last hairis_render or hairis_render_progressive did, as options:
 * seconds (the whole call), build_seconds (making the scene within it, 0 when scene_reused
 * is 1: the last render's build with a new camera), geometry_reused (1 when the BVH was the
 * last render's), camera_rays, rays, shadow_rays, dropped_samples, peak_memory_bytes, threads,
 * cancelled, samples, converged_pixels; "" before any render. */
HAIRIS_API const char *hairis_last_render_stats(void);

#ifdef __cplusplus
}
#endif

#endif /* HAIRIS_RENDER_H */
