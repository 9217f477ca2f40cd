// Lights with Blender's parameters, converted to radiance exactly as Cycles 3.4 converts them,
// and the light set the path tracer samples (next-event estimation) and hits (MIS).
//
// Units and normalisations (the radiance L is what a ray that hits the light receives):
//
//  - Blender → Cycles (intern/cycles/blender/light.cpp, sync_light): every light's Cycles
//    "strength" is color × energy, energy being the Power (W) of point/spot/area lights and the
//    Strength (W/m²) of a sun. Sun: angle = the light's Angle. Point: size = Radius
//    (shadow_soft_size). Area: axisu, axisv = the object matrix's columns 0 and 1 (with the
//    object's scale), sizeu = Size, sizev = Size (Square, Disk) or Size Y (Rectangle,
//    Ellipse), round for Disk/Ellipse; position = column 3; dir = −column 2 (lights shine
//    along their local −Z).
//
//  - Cycles → radiance (intern/cycles/scene/light.cpp, device_update_points, and
//    intern/cycles/kernel/light/light.h, light_sample and light_sample_from_intersection):
//    * Point, radius r > 0: a disk of radius r centred on the light and facing the shading
//      point, with invarea = 1/(π r²), L = strength · invarea / (4π) — the 1/(4π) of an
//      isotropic source and the 1/(π r²) of the disk: intensity P/(4π) W/sr. Its points are
//      drawn uniformly on that disk (pdf = invarea per area, times t²/cos per solid angle).
//      Radius 0: a true point, intensity strength/(4π), no MIS (it cannot be hit).
//    * Area: axisu·sizeu, axisv·sizev span it; area = |u|·|v|, × π/4 when round;
//      L = strength · 0.25 / area, one-sided: it emits towards dir (= −Z) only. A Lambertian
//      emitter of this radiance radiates π/4 · Power in total: Blender's Watts for area
//      lights are not radiometric Watts, exactly as in Cycles. Spread is not supported (Blender's
//      default 180° = no spread attenuation). Rectangles are sampled by solid angle (Ureña
//      et al. 2013's spherical rectangles, as Cycles' rect_light_sample does), disks and
//      ellipses uniformly by area.
//    * Sun, angle a > 0: a disc of radius tan(a/2) at distance 1, invarea = 1/(π tan²(a/2));
//      a direction at angle θ from the sun centre with cos θ ≥ cos(a/2) has
//      L = strength · invarea / cos³θ and is drawn with pdf invarea / cos³θ, so the irradiance
//      on a surface facing the sun is exactly strength (W/m²). Angle 0: a delta light of
//      irradiance strength.
//    * World: constant radiance color × strength from every direction.
//    * Emissive triangles (a mesh material with emission): radiance = the emission colour,
//      on both sides (Cycles' emissive closure uses |cos|).
//
// Light selection: like Cycles 3.4's light distribution (scene/light.cpp,
// device_update_distribution): emissive triangles as a group get probability 1/2 when there
// are also lamps (sun, point, area), otherwise all of it; a triangle
// within the group is chosen in proportion to its area; lamps share the rest uniformly (not by
// power). Like Cycles 3.4, which disables the background light when the world shader is not
// spatially varying, hairis does not sample a constant world as a light: paths find it by BSDF
// sampling alone, at full weight.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "render/camera.h"
#include "core/expected.h"
#include "core/math.h"

namespace hairis {

/// A sun light (Blender's Sun): parallel light from a small disc.
struct SunLight {
    /// Unit direction from the scene towards the sun: the light object's +Z axis (the light
    /// shines along −Z). Normalised on validation; must not be zero.
    Vec3 to_sun{0, 0, 1};
    Rgb color{1.0f};
    /// Strength in W/m²: the irradiance on a surface facing the sun.
    float strength = 1.0f;
    /// Angular diameter of the sun's disc in radians, in [0, π).
    float angle = 0.0f;
};

/// A point light (Blender's Point): power in W, radius in metres.
struct PointLight {
    Vec3 position;
    Rgb color{1.0f};
    float power = 10.0f;
    float radius = 0.0f;
};

/// Blender's area light shapes.
enum class AreaShape { Square = 0, Rectangle = 1, Disk = 2, Ellipse = 3 };

/// An area light (Blender's Area): the object's matrix (row-major, with its scale), shape,
/// Size (size_x) and Size Y (size_y; only for Rectangle and Ellipse), power in W.
struct AreaLight {
    Mat4 light_to_world;
    AreaShape shape = AreaShape::Square;
    float size_x = 1.0f;
    float size_y = 1.0f;
    Rgb color{1.0f};
    float power = 10.0f;
};

/// The world: a constant background of radiance color × strength.
struct WorldLight {
    Rgb color{0.0f};
    float strength = 1.0f;
};

/// An emissive triangle handed to the light set by the scene (world space).
struct EmissiveTriangle {
    Vec3 p0, p1, p2;
    Rgb radiance;
    std::uint32_t geometry = 0;  ///< the scene's geometry id of its mesh
    std::uint32_t primitive = 0; ///< its index in that mesh
};

/// Cycles 3.4's conversions of Blender's light values (see the file comment).
namespace cycles_light {

/// Cycles' "strength" of a light: color × Blender's power (W) or sun strength (W/m²).
inline Rgb strength(Rgb color, float energy) { return color * energy; }
/// invarea of a point light: 1/(π r²), or 1 for r = 0 (Cycles' convention).
float point_invarea(float radius);
/// Radiance of a point light's disk (r > 0): strength·invarea/(4π) = color·P/(4π²r²).
Rgb point_radiance(Rgb color, float power, float radius);
/// Radiant intensity of a point light (W/sr): color·P/(4π), whatever its radius.
Rgb point_intensity(Rgb color, float power);
/// Area of an area light: |axis_u|·size_u · |axis_v|·size_v, × π/4 for Disk and Ellipse.
float area_light_area(const AreaLight &light);
/// Radiance of an area light: color·P·0.25/area.
Rgb area_radiance(Rgb color, float power, float area);
/// invarea of a sun of angular diameter `angle`: 1/(π tan²(angle/2)), or 1 for angle 0.
float sun_invarea(float angle);
/// Radiance of a sun at angle θ from its centre (cos θ ≥ cos(angle/2)): E·invarea/cos³θ.
Rgb sun_radiance(Rgb color, float strength, float angle, float cos_theta);

}  // namespace cycles_light

/// The power heuristic (β = 2) weight a²/(a² + b²) of a strategy with density a against one
/// with b, written as 1/(1 + (b/a)²) so that large densities cannot overflow. 0 when a is 0.
inline float power_heuristic(float a, float b) {
    if (!(a > 0.0f)) return 0.0f;
    const float r = b / a;
    return 1.0f / (1.0f + r * r);
}

/// A light sample for next-event estimation.
struct LightSample {
    Vec3 wi;                 ///< unit direction from the shading point towards the light
    float distance = 0;      ///< to the sampled point; infinity for a sun
    /// The light's contribution before the BSDF: the estimate is f·value/pdf. For area-like
    /// lights value is the radiance L; for delta lights (point radius 0, sun angle 0) it is
    /// the irradiance at normal incidence (I/d² or E), and pdf the selection probability.
    Rgb value;
    float pdf = 0;           ///< solid-angle density including the selection probability
    bool delta = false;      ///< true for point lights of radius 0 and suns of angle 0: no MIS
    /// Emissive triangle samples: the primitive to ignore on the shadow ray (the light itself).
    std::uint32_t skip_geometry = std::numeric_limits<std::uint32_t>::max();
    std::uint32_t skip_primitive = std::numeric_limits<std::uint32_t>::max();
};

/// The lights of a scene in Cycles' form, sampled and intersected by the path tracer.
/// Immutable and thread-safe after build().
class LightSet {
  public:
    /// Validates the lights and converts them. Lights that cannot contribute (zero power or
    /// colour) are left out silently; an area light of zero size is left out with a warning
    /// appended to `warnings`. Errors name the light (e.g. "point light 2: power must be
    /// finite and >= 0 (got nan)").
    static Expected<LightSet> build(const std::vector<SunLight> &suns,
                                    const std::vector<PointLight> &points,
                                    const std::vector<AreaLight> &areas, const WorldLight &world,
                                    std::vector<EmissiveTriangle> emissive,
                                    std::vector<std::string> *warnings = nullptr);

    LightSet() = default;

    /// Number of lamps (suns, points and areas; the world is not one).
    int lamp_count() const { return int(lamps_.size()); }
    /// Number of emissive triangles.
    int emissive_triangle_count() const { return int(triangles_.size()); }
    /// True when there is nothing to sample.
    bool empty() const { return lamps_.empty() && triangles_.empty(); }
    /// The world's radiance (black without a world).
    Rgb world_radiance() const { return world_; }
    /// The probability of choosing lamp i, and of choosing the emissive-triangle group.
    float lamp_selection_probability() const { return lamp_pick_; }
    float triangle_group_probability() const { return triangle_pick_; }

    /// Chooses a light with u_select and samples a point or direction on it from (u0, u1), as
    /// seen from the shading point p. nullopt when the chosen light cannot reach p (e.g. p is
    /// behind an area light).
    std::optional<LightSample> sample(Vec3 p, float u_select, float u0, float u1) const;

    /// Radiance and light-sampling density (solid angle, with selection) of every lamp a ray
    /// crosses (point-light disks and area lights, which are transparent to rays as in Cycles)
    /// between tmin and tmax, combined with the BSDF density bsdf_pdf by the power heuristic:
    /// returns Σ L·w. With use_mis false (camera rays, or after a delta BSDF) w = 1.
    Rgb lamps_along_ray(Vec3 origin, Vec3 dir, float tmin, float tmax, float bsdf_pdf,
                        bool use_mis) const;
    /// Radiance reaching a ray that escapes the scene in direction dir: suns whose disc
    /// contains dir and the world, each weighted by MIS against bsdf_pdf (when use_mis).
    /// include_world false leaves the world out (transparent film for camera rays).
    Rgb escaped(Vec3 dir, float bsdf_pdf, bool use_mis, bool include_world = true) const;
    /// The light-sampling density (solid angle, with selection) of an emissive triangle point
    /// seen at distance t with |cos| abs_cos between the ray and the triangle's normal.
    float emissive_triangle_pdf(float t, float abs_cos) const;

    /// The bytes this light set holds.
    std::size_t memory_bytes() const;

  private:
    enum class LampType : std::uint8_t { Point, Area, Sun };
    struct Lamp {
        LampType type = LampType::Point;
        Rgb value;          // point: radiance (r > 0) or intensity (r = 0); area: radiance;
                            // sun: strength (irradiance); world: radiance
        Vec3 position;      // point and area centre
        Vec3 axis_u, axis_v;// area: full extents
        Vec3 direction;     // area: emitting normal; sun: towards the sun
        float radius = 0;   // point radius; sun: tan(angle/2)
        float invarea = 1;  // 1/area of the disk, rectangle or ellipse
        float cos_half = 1; // sun: cos(angle/2)
        bool round = false; // area: disk or ellipse
        bool solid_angle = false;  // area: rectangle with orthogonal axes, sampled by solid angle
    };

    std::optional<LightSample> sample_lamp(const Lamp &lamp, Vec3 p, float u0, float u1) const;
    std::optional<LightSample> sample_triangle(Vec3 p, float u_select, float u0, float u1) const;

    std::vector<Lamp> lamps_;
    std::vector<EmissiveTriangle> triangles_;
    std::vector<float> triangle_cdf_;  // size n + 1, normalised
    float triangle_area_ = 0;
    float lamp_pick_ = 0;      // probability of each lamp
    float triangle_pick_ = 0;  // probability of the triangle group
    Rgb world_;
};

/// A rectangle as seen from a point, for sampling it uniformly by solid angle (Ureña, Fajardo
/// and King 2013, "An Area-Preserving Parametrization for Spherical Rectangles").
class SphericalRectangle {
  public:
    /// The rectangle corner + s·ex + t·ey, s, t ∈ [0, 1] (ex ⟂ ey), seen from p.
    SphericalRectangle(Vec3 p, Vec3 corner, Vec3 ex, Vec3 ey);
    /// Its solid angle (steradians); 0 when p lies in its plane or it is degenerate.
    float solid_angle() const { return solid_angle_; }
    /// The point on the rectangle for (u, v) ∈ [0, 1)²; uniform in solid angle.
    Vec3 sample(float u, float v) const;

  private:
    Vec3 o_, x_, y_, z_;
    float x0_ = 0, y0_ = 0, z0_ = 0, x1_ = 0, y1_ = 0;
    float b0_ = 0, b1_ = 0, k_ = 0, solid_angle_ = 0;
};

/// Uniform point in the unit disk from (u0, u1) by Shirley and Chiu's concentric map (the
/// map Cycles' to_unit_disk uses too).
void concentric_disk(float u0, float u1, float &x, float &y);
/// Two unit vectors completing n (unit) to an orthonormal basis.
void orthonormal_basis(Vec3 n, Vec3 &a, Vec3 &b);

}  // namespace hairis
