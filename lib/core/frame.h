// The fiber frame and its angles, in Cycles 3.4's convention (bsdf_hair_principled.h).
//
//   X  the unit tangent along the curve (Cycles: normalize(dPdu)),
//   Y  normalize(cross(X, ω_o)), perpendicular to the fiber and to the view,
//   Z  cross(X, Y).
//
// A direction ω has local coordinates (ω·X, ω·Y, ω·Z) and
//   sin θ = ω·X,          θ ∈ [−π/2, π/2], measured from the normal plane of the fiber
//                         (θ = ±π/2 looks along the fiber),
//   φ = atan2(ω·Z, ω·Y),  φ ∈ (−π, π], the azimuth around the fiber.
// All directions point away from the shading point: ω_o (= ω_r, "r" in Marschner and the
// seed) towards the viewer, ω_i towards the light. The relative azimuth is φ = φ_i − φ_o,
// wrapped to [−π, π]. In Cycles' frame every ω_o has φ_o = −π/2; the far-field models only
// depend on φ_i − φ_o (Marschner's eccentricity also on the half angle (φ_i + φ_o)/2, which is
// why the frame's Y axis is kept explicit here).
//
// h ∈ [−1, 1] is the offset across the fiber's width where the ray hits it: h = sin γ_o,
// γ_o the angle between the ray's projection into the normal plane and the surface normal.
// −1 and 1 graze the two edges, 0 hits the centre. Cycles computes it for 3D curves as
// dot(cross(Ng, X), Z).
//
// The seed and its figures: the seed writes the transmission (TT) lobe at "φ_i + φ_r = ±π"
// (its "±2π" is a slip for ±π). It measures φ_r with the opposite orientation from φ_i; in
// our convention (both azimuths measured the same way around X) the same lobe is at
// φ_i − φ_r = ±π, i.e. light leaves on the far side of the fiber. So the seed's φ_r maps to
// −φ_r here; its rows φ_r ∈ {180°, 0°, −180°} are unchanged and its rows ±90° swap.
#pragma once

#include "core/math.h"

namespace hairis {

/// Longitudinal and azimuthal angles of a direction in the fiber frame (radians).
struct FiberAngles {
    float theta = 0;  ///< in [−π/2, π/2], from the normal plane
    float phi = 0;    ///< in (−π, π], around the fiber from Y towards Z
};

/// An orthonormal frame attached to a fiber: x is the tangent.
struct FiberFrame {
    Vec3 x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};

    /// Cycles 3.4's frame: x = tangent, y = cross(x, wo), z = cross(x, y). Requires wo not
    /// parallel to the tangent; falls back to any frame around the tangent then.
    static FiberFrame from_tangent_and_view(Vec3 tangent, Vec3 wo);

    /// World direction to local coordinates (ω·x, ω·y, ω·z).
    Vec3 to_local(Vec3 w) const { return {dot(w, x), dot(w, y), dot(w, z)}; }
    /// Local coordinates to a world direction.
    Vec3 to_world(Vec3 l) const { return x * l.x + y * l.y + z * l.z; }
};

/// Local direction to (θ, φ): sin θ = ω.x, φ = atan2(ω.z, ω.y).
FiberAngles angles_of(Vec3 local);

/// θ of the world direction `w` in `frame`: asin(ω·x), sin θ clamped to [−1, 1] (asin rather
/// than angles_of's atan2, which rounds differently).
inline float theta_of(const FiberFrame &frame, Vec3 w) { return safe_asin(frame.to_local(w).x); }

/// (θ, φ) to a unit local direction (sin θ, cos θ cos φ, cos θ sin φ).
Vec3 direction_of(float theta, float phi);
Vec3 direction_of(FiberAngles a);

/// Wraps an angle to [−π, π].
float wrap_angle(float a);
double wrap_angle(double a);

/// The relative azimuth φ_i − φ_o wrapped to [−π, π].
inline float relative_azimuth(float phi_i, float phi_o) { return wrap_angle(phi_i - phi_o); }

/// Marschner's half and difference angles: θ_h = (θ_i + θ_o)/2, θ_d = (θ_o − θ_i)/2.
/// sin θ of a sampled direction kept off the fiber axis (|sin θ| ≤ the largest float below 1):
/// on the axis φ is undefined, so a sample there would carry its φ in name only while pdf()
/// and f read another.
inline float off_axis(float sin_theta) {
    return sin_theta < -kOneMinusEpsilon ? -kOneMinusEpsilon
                                         : (sin_theta > kOneMinusEpsilon ? kOneMinusEpsilon : sin_theta);
}

inline float theta_half(float theta_i, float theta_o) { return 0.5f * (theta_i + theta_o); }
inline float theta_diff(float theta_i, float theta_o) { return 0.5f * (theta_o - theta_i); }

}  // namespace hairis
