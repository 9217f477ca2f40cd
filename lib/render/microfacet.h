// Microfacet reflection in a local frame whose z axis is the shading normal, in single
// precision for the path tracer: the GGX distribution with Smith's shadowing-masking in the two
// forms Cycles has used (separable G1·G1 in 3.4, height-correlated 1/(1 + Λ + Λ) from 4.0),
// Burley's GTR1 distribution (Cycles 3.4's clearcoat), and the samplers hairis draws
// reflections with:
//  - GGX: Heitz 2018's visible normals (stretch, concentric disk, warp, lift, unstretch); the
//    reflected direction wi = 2(wo·h)h − wo has density G1(wo) D(h) / (4 wo.z) on the sphere
//    (it may fall below the horizon; callers reject those draws, and their mass is missing);
//  - GTR1: its normals exactly, cos²θ_h = (1 − (α²)^u) / (1 − α²), φ = 2π u', density
//    D_GTR1(h) cos θ_h per unit solid angle of h, so wi has D_GTR1(h) h.z / (4 wo·h).
// α is Cycles' alpha (the node's roughness squared).
#pragma once

#include "core/math.h"

namespace hairis::microfacet {

/// GGX D(h) from α² and cos θ_h: α² / (π (1 − c² + α² c²)²), c² clamped to 1.
float ggx_d(float alpha2, float cos_h);
/// The same D for a local (not necessarily unit) h, with sin² θ_h from its x and y components:
/// accurate where 1 − cos² θ_h is below float resolution (very smooth lobes).
float ggx_d(float alpha2, Vec3 h);
/// Smith's Λ for GGX: (sqrt(1 + α² (1/c² − 1)) − 1) / 2, 0 for c² >= 1.
float ggx_lambda(float alpha2, float cos_theta);
/// G1 = 1 / (1 + Λ).
inline float ggx_g1(float alpha2, float cos_theta) { return 1.0f / (1.0f + ggx_lambda(alpha2, cos_theta)); }

/// Burley's GTR1 D(h): (α² − 1) / (π ln(α²) (1 + (α² − 1) c²)); 1/π at α >= 1.
float gtr1_d(float alpha, float cos_h);
/// The same D for a local (not necessarily unit) h, 1 − cos² θ_h from its x and y components.
float gtr1_d(float alpha, Vec3 h);

/// The normal h of a GGX visible-normal draw seen from wo (wo.z > 0) with u0, u1 in [0, 1).
Vec3 sample_ggx_visible(Vec3 wo, float alpha, float u0, float u1);
/// The density on the sphere of wi = reflect(wo, h), h from sample_ggx_visible:
/// G1(wo) D(h) / (4 wo.z) with h = normalize(wo + wi); 0 when wo.z <= 0 or h.z <= 0.
float ggx_reflection_pdf(Vec3 wo, Vec3 wi, float alpha);

/// The normal h of a GTR1 draw (density D_GTR1(h) h.z per solid angle of h).
Vec3 sample_gtr1(float alpha, float u0, float u1);
/// The density on the sphere of wi = reflect(wo, h), h from sample_gtr1:
/// D_GTR1(h) h.z / (4 wo·h) with h = normalize(wo + wi); 0 when h.z <= 0.
float gtr1_reflection_pdf(Vec3 wo, Vec3 wi, float alpha);

/// Mirror reflection of wo about unit h: 2(wo·h)h − wo.
inline Vec3 reflect(Vec3 wo, Vec3 h) { return h * (2.0f * dot(wo, h)) - wo; }

}  // namespace hairis::microfacet
