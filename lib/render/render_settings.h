// What a render is asked to do (RenderSettings and its enums) and what it reports
// (RenderStats), apart from the renderer so that the integrators can read them.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace hairis {

/// How hair vertices are shaded: path tracing (unbiased), or dual scattering
/// (render/dual_scattering_integrator.h), whose hair materials need HairMaterial::dual and
/// ::multiple.
enum class Integrator { Path = 0, DualScattering = 1 };

/// How Huang hair draws its BSDF samples.
enum class HuangSampling {
    /// The material's strategy (its sampler's exact density, MIS with it, f = Cycles' eval).
    Strategy = 0,
    /// Cycles 4.5/5.0's chained microfacet sampler with its own weight, and pdf 1 for MIS in
    /// both light and BSDF samples, as Cycles renders Huang. Its BSDF-sampled paths follow
    /// the sampler's weight, which is not Cycles' eval (docs/huang.md §8): what Cycles'
    /// images converge to, for comparing with them.
    Cycles = 1,
};

/// What the dual-scattering integrator takes the hair around a vertex to be.
enum class DualHairVolume {
    /// A layer over what is under it: the backscatter series (Ā_b) are cut at the strands a
    /// probe finds behind the vertex, and light meshes reflect onto the vertex through n ≥ 1
    /// strands is the global term (render/dual_scattering_integrator.h).
    Layer = 0,
    /// Zinke et al.'s semi-infinite hair volume: Ā_b unbounded, and the continuation ends at
    /// hair (mesh light reaches a hair vertex only where no strand is in the way).
    Unbounded = 1,
};

/// Which orders of scattering the dual-scattering vertex that closes a path adds.
enum class DualBounceLimit {
    /// Those the path tracer would reach: light that crossed n strands needs n more scattering
    /// events, and a backscatter series term through i strands behind 2i, within what Max
    /// Bounces and Max Transmission Bounces leave after the vertex (as Cycles ends its paths).
    Bounces = 0,
    /// Zinke et al.'s: every order, whatever the bounce limits.
    None = 1,
};

/// How Max Bounces: Transparent limits a path's transparent crossings, as each Cycles stores
/// the setting.
enum class TransparentLimit {
    /// Cycles up to 4.5 (kernel data transparent_max_bounce = setting + 1): setting + 1.
    PlusOne = 0,
    /// Cycles 5.0 (transparent_max_bounce = setting): the setting, and 1 for a setting of 0.
    Setting = 1,
};

/// The transparent surfaces a path may cross under `limit` with Max Bounces: Transparent
/// `setting` (>= 0); the surface after the last one ends the path.
inline int transparent_crossings(TransparentLimit limit, int setting) {
    return limit == TransparentLimit::Setting ? std::max(setting, 1) : setting + 1;
}

/// Cycles' Film > Pixel Filter: the shape a camera sample's position in its pixel is drawn from.
enum class PixelFilterType { Box = 0, Gaussian = 1, BlackmanHarris = 2 };

/// How to render.
struct RenderSettings {
    /// An Integrator: "path" or "dual_scattering".
    int integrator = int(Integrator::Path);
    /// Samples per pixel, in [1, 2^24].
    int samples = 64;
    /// Cycles' Max Bounces (Total), in [0, 1024]; Blender's default is 12.
    int max_bounces = 12;
    /// Cycles' Max Bounces: Diffuse, in [0, 1024] (Blender's default 4): counts bounces drawn
    /// from a surface's diffuse lobes (Lambert, Oren–Nayar, Principled diffuse and sheen).
    int max_diffuse_bounces = 4;
    /// Cycles' Max Bounces: Glossy, in [0, 1024] (Blender's default 4): counts bounces drawn
    /// from a surface's microfacet (glossy) lobes.
    int max_glossy_bounces = 4;
    /// Cycles' Max Bounces: Transmission, in [0, 1024] (Blender's default 12): counts hair
    /// bounces. Cycles counts a hair bounce drawn from the R lobe as a glossy bounce (limit
    /// Max Bounces: Glossy, default 4) and the other lobes as transmission; a DirectionSampler
    /// does not say which lobe it drew from, so hairis counts every hair bounce here and has
    /// no glossy limit (paths with more than 4 R-lobe bounces are vanishingly rare).
    int max_transmission_bounces = 12;
    /// Same seed, same image.
    std::uint64_t seed = 0;
    /// Cycles' Max Bounces: Transparent, in [0, 1024] (Blender's default 8): a path crosses at
    /// most transparent_crossings(transparent_limit, this) transparent surfaces; the surface
    /// after the last one ends it (emission only).
    int max_transparent_bounces = 8;
    /// A TransparentLimit: "plus_one" (Cycles up to 4.5) or "setting" (Cycles 5.0).
    int transparent_limit = int(TransparentLimit::PlusOne);
    /// Threads to use, in [0, 1024]; 0 = oneTBB's default concurrency (all cores).
    int threads = 0;
    /// Tile edge in pixels, in [1, 4096].
    int tile_size = 16;
    /// Russian roulette applies at vertices of depth >= this, in [1, 1024]. Cycles with
    /// "Min Light Bounces" 0 (the default) stores min_bounce 1 and plays roulette from depth 2.
    int rr_start_bounce = 2;
    /// Blender's Film > Transparent: camera rays that miss everything add neither the world
    /// nor alpha (suns seen directly still add their disc, as in Cycles). Alpha is otherwise 1.
    bool film_transparent = false;
    /// A HuangSampling: how Huang hair samples directions (integrator=dual_scattering uses
    /// the strategy's sampler at the vertex that closes the path, whose MIS needs a density,
    /// which Cycles' sampler lacks; its exact bounces follow this setting). With Cycles' own
    /// sampling, light samples are shaded with the material's model: the baked f where its
    /// tables hold one (huang_tabulated_fiber.h), else Cycles' eval.
    int huang_sampling = int(HuangSampling::Strategy);
    /// A DualHairVolume for integrator=dual_scattering: "layer" or "unbounded".
    int dual_hair_volume = int(DualHairVolume::Layer);
    /// integrator=dual_scattering: the path's first scattering vertices (depth < this, the
    /// camera's hit is depth 0) are path-traced as integrator=path traces them, and the first
    /// hair vertex at a depth >= this is shaded by dual scattering, which closes the path there
    /// (its light from other strands is the dual estimate's). In [0, 1024]; 0 is Zinke et al.'s
    /// dual scattering at the first hair hit. Each exact bounce leaves less of the light to the
    /// approximation: less bias, more noise.
    int dual_exact_bounces = 3;
    /// A DualBounceLimit for integrator=dual_scattering: "bounces" or "none".
    int dual_bounce_limit = int(DualBounceLimit::Bounces);
    /// Seconds after which a progressive render stops at the end of its round; 0: none.
    double time_limit = 0;
    /// Cycles' Noise Threshold of adaptive sampling, in [0, 1]; 0: off (render/render.h).
    float adaptive_threshold = 0;
    /// Samples no pixel stops before, in [0, 2^24]; 0: Cycles' automatic count.
    int adaptive_min_samples = 0;
    /// The pixels rendered, x0,y0,x1,y1 half-open with row 0 the bottom one; 0,0,0,0: all.
    std::vector<int> region{0, 0, 0, 0};
    /// The passes render_progressive writes beside rgba, names separated by ',' (render.h).
    std::string passes;
    /// Cycles' Light Paths > Caustics > Filter Glossy, in [0, 10]; 0: off (render/filter_glossy.h).
    /// Blender's default is 1; the library's is off, so an unset option renders unbiased.
    float filter_glossy = 0;
    /// Cycles' Light Paths > Clamping: Direct and Indirect, in [0, 3.4e38]; 0: off. A sample's
    /// contribution whose |R| + |G| + |B| exceeds 3× the limit is scaled down to it, as Cycles'
    /// film_clamp_light does (Blender's defaults: 0 and 10).
    float clamp_direct = 0;
    float clamp_indirect = 0;
    /// A PixelFilterType: "box", "gaussian" or "blackman_harris" (Blender's default).
    int pixel_filter = int(PixelFilterType::Box);
    /// Cycles' Film > Pixel Filter width in pixels, in [0.001, 10] (Blender's default 1.5).
    float pixel_filter_width = 1.0f;
    /// Cycles' Film > Exposure, in [0, 10] (Blender's default 1): the image's light is scaled by
    /// it when read out (after adaptive sampling's decisions, as in Cycles); alpha and the data
    /// passes are not.
    float exposure = 1.0f;
};

/// The option names of RenderSettings (core/options.h's field descriptions).
template <typename Fields>
void describe(Fields &f, RenderSettings &s) {
    f.choice("integrator", s.integrator, {"path", "dual_scattering"});
    f.field("samples", s.samples, 1, 1 << 24);
    f.field("max_bounces", s.max_bounces, 0, 1024);
    f.field("max_diffuse_bounces", s.max_diffuse_bounces, 0, 1024);
    f.field("max_glossy_bounces", s.max_glossy_bounces, 0, 1024);
    f.field("max_transmission_bounces", s.max_transmission_bounces, 0, 1024);
    f.field("max_transparent_bounces", s.max_transparent_bounces, 0, 1024);
    f.choice("transparent_limit", s.transparent_limit, {"plus_one", "setting"});
    f.field("seed", s.seed);
    f.field("threads", s.threads, 0, 1024);
    f.field("tile_size", s.tile_size, 1, 4096);
    f.field("rr_start_bounce", s.rr_start_bounce, 1, 1024);
    f.field("film_transparent", s.film_transparent);
    f.choice("huang_sampling", s.huang_sampling, {"strategy", "cycles"});
    f.choice("dual_hair_volume", s.dual_hair_volume, {"layer", "unbounded"});
    f.field("dual_exact_bounces", s.dual_exact_bounces, 0, 1024);
    f.choice("dual_bounce_limit", s.dual_bounce_limit, {"bounces", "none"});
    f.field("time_limit", s.time_limit, 0.0, 3.4e38);
    f.field("adaptive_threshold", s.adaptive_threshold, 0.0, 1.0);
    f.field("adaptive_min_samples", s.adaptive_min_samples, 0, 1 << 24);
    f.field("region", s.region, 4, 0, 65536);
    f.field("passes", s.passes);
    f.field("filter_glossy", s.filter_glossy, 0.0, 10.0);
    f.field("clamp_direct", s.clamp_direct, 0.0, 3.4e38);
    f.field("clamp_indirect", s.clamp_indirect, 0.0, 3.4e38);
    f.choice("pixel_filter", s.pixel_filter, {"box", "gaussian", "blackman_harris"});
    f.field("pixel_filter_width", s.pixel_filter_width, 0.001, 10.0);
    f.field("exposure", s.exposure, 0.0, 10.0);
}

/// What a render did.
struct RenderStats {
    double seconds = 0;
    std::uint64_t camera_rays = 0;        ///< camera samples traced (= pixel samples done)
    std::uint64_t rays = 0;               ///< closest-hit rays (camera and continuation)
    std::uint64_t shadow_rays = 0;
    std::uint64_t dropped_samples = 0;    ///< NaN/inf contributions or throughputs dropped
    double samples_per_second = 0;        ///< camera_rays / seconds
    bool cancelled = false;               ///< the progress callback returned false
    float progress = 0;                   ///< fraction of the work done when render() returned
    std::uint64_t peak_memory_bytes = 0;  ///< scene estimate + render buffers
    int threads = 0;                      ///< threads actually allowed
    int samples = 0;                      ///< the most samples a pixel got
    std::uint64_t converged_pixels = 0;   ///< pixels adaptive sampling stopped early
};

}  // namespace hairis
