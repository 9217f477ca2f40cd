// Cycles' biased conveniences that a scene set up for Cycles carries by default, as its
// integrator applies them (kernel/integrator/surface_shader.h and kernel/film/light_passes.h at
// v3.4.0, v4.5.0 and v5.0.0, the same in all three):
//
//  - Filter Glossy (Light Paths > Caustics, Blender's default 1): a path remembers the least
//    density any of its BSDF samples was drawn with (min_ray_pdf; transparent crossings do
//    not count; a Huang closure reports 1). At a later vertex where min_ray_pdf / Filter
//    Glossy < 1, every glossy closure is widened before it is shaded: roughness parameters
//    raised to sqrt(1 − min_ray_pdf / Filter Glossy) / 2 (bsdf_blur: microfacet α, Chiang's
//    mapped v, s and coat variance, Huang's roughness). It trades caustic noise for a softer,
//    brighter look of light hair seen through other hair.
//  - Clamping (Light Paths > Clamping, Blender's defaults Direct 0 and Indirect 10): each
//    contribution a sample adds (throughput × light × MIS weight) is scaled down where
//    |R| + |G| + |B| exceeds 3× the limit; Direct is the limit for light reaching the camera
//    directly or after one bounce (next-event estimation at the first vertex, the emission its
//    BSDF sample meets), Indirect for the rest.
#pragma once

#include <cmath>

#include "core/math.h"

namespace hairis {

/// The roughness Filter Glossy `filter_glossy` (0: off) widens the closures at a vertex to, for
/// a path whose least BSDF density so far is `min_ray_pdf` (+inf before its first bounce);
/// 0 when nothing is widened.
inline float glossy_blur_roughness(float filter_glossy, float min_ray_pdf) {
    if (!(filter_glossy > 0.0f)) return 0.0f;
    const float blur_pdf = min_ray_pdf / filter_glossy;
    return blur_pdf < 1.0f ? 0.5f * std::sqrt(1.0f - std::max(blur_pdf, 0.0f)) : 0.0f;
}

/// A contribution clamped as Cycles' film_clamp_light does with a limit of `setting` (0: off).
inline Rgb clamp_contribution(Rgb c, float setting) {
    if (!(setting > 0.0f)) return c;
    const float limit = 3.0f * setting;
    const float sum = std::fabs(c.r) + std::fabs(c.g) + std::fabs(c.b);
    return sum > limit ? c * (limit / sum) : c;
}

}  // namespace hairis
