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
//    * Spot (Blender's Spot; a point light with a cone): position = column 3, axis dir =
//      −column 2 normalised; radius = Radius (shadow_soft_size); spot_angle = Size (spot_size,
//      the full cone angle), spot_smooth = Blend (spot_blend). scene/light.cpp stores
//      cos_half = cos(spot_angle/2) and smooth = (1 − cos_half)·blend; the disk, invarea and
//      L = strength·invarea/(4π) are the point light's, times kernel/light/common.h's
//      spot_light_attenuation(dir, cos_half, smooth, N) with N the unit direction from the
//      light's sampled point to the shading point: c = dot(dir, N); 0 when c ≤ cos_half, else
//      c · smoothstep((c − cos_half)/smooth) when c − cos_half < smooth (and smooth ≠ 0), else
//      c. The factor c is Cycles 3.4's: a spot's intensity on its axis is P/(4π) and falls
//      with the cosine inside the cone.
//    * World: constant radiance color × strength from every direction, or an Environment
//      Texture (environment_map.h) that is light-sampled unless its Sampling is None.
//
//  - Cycles 4.x (cycles = CyclesVersion::V4_5, for Blender 4.1 to 5.0; kernel/light/point.h,
//    spot.h, area.h, distant.h and scene/light.cpp of v4.5.0 and v5.0.0):
//    * Area: L = strength/(π·area) (commit a21af93e6, "Fix wrong conversion from power to
//      radiance of area lights", in 4.0): 4/π times 3.4's radiance; a Lambertian emitter of
//      Power P now radiates P.
//    * Sun: a cone of half-angle a/2 of constant radiance strength/(π sin²(a/2)), sampled
//      uniformly (pdf 1/(2π(1 − cos(a/2)))); a surface facing it receives exactly strength.
//    * Point and spot with Soft Falloff (use_soft_falloff, Blender's default since 4.1): the
//      disk of 3.4, same radiance P/(4π²r²) (invarea = 1/(4πr²), eval_fac = invarea/π). Without
//      Soft Falloff: a sphere of radius r of that radiance, sampled uniformly in the cone it
//      subtends (from inside it: uniformly over the sphere of directions, where Cycles uses a
//      cosine hemisphere around the shading normal; a density, not a result, differs).
//    * Spot attenuation: smoothstep((z − cos_half)/smooth) clamped to [0, 1], without 3.4's
//      factor c, z being the local −Z component of normalize(M⁻¹·N) (the object's scale makes
//      the cone elliptical); from inside a sphere spot there is no attenuation, and every
//      direction sees it (Cycles' hit test skips rays leaving the centre there but its light
//      samples do not, which hairis does not copy: the estimate would be biased).
//    * Emissive triangles (a mesh material with emission): radiance = the emission colour,
//      on both sides (Cycles' emissive closure uses |cos|).
//
// Light selection: emissive triangles as a group get probability 1/2 when there are also
// lamps (sun, point, spot, area, environment world), otherwise all of it, as in Cycles 3.4's
// light distribution (scene/light.cpp, device_update_distribution); a triangle within the
// group is chosen in proportion to its area. Lamps share the rest by their importance at the
// shading point, an estimate of the unshadowed irradiance each brings there (importance_at),
// as Cycles 4.x's light tree (its default) does, with a tenth of it shared uniformly so that
// no lamp that reaches the point goes unchosen. One lamp, or more than 64, are chosen
// uniformly (3.4's distribution). Selection changes only the noise: every density is exact.
// The world is one lamp among them
// when it is an Environment Texture whose Sampling is not None (Cycles' background light):
// directions from its importance map (environment_map.h) with their exact density, and rays
// that escape weighted against it by the power heuristic. Like Cycles, which disables the
// background light when the world shader is not spatially varying, hairis does not sample a
// constant world as a light, nor a world whose Sampling is None: paths find them by BSDF
// sampling alone, at full weight.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.h"
#include "core/math.h"
#include "render/camera.h"
#include "render/environment_map.h"

namespace hairis {

/// Which Cycles a light follows (see the file comment): 3.4, or 4.5 (Blender 4.1 to 5.0).
enum class CyclesVersion { V3_4 = 0, V4_5 = 1 };

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
    CyclesVersion cycles = CyclesVersion::V3_4;
};

/// A point light (Blender's Point): power in W, radius in metres.
struct PointLight {
    Vec3 position;
    Rgb color{1.0f};
    float power = 10.0f;
    float radius = 0.0f;
    CyclesVersion cycles = CyclesVersion::V3_4;
    /// Blender 4.1+'s Soft Falloff (default on): a disk facing the shading point; off, a
    /// sphere (only with cycles = V4_5; Cycles 3.4 has the disk alone).
    bool soft_falloff = true;
};

/// A spot light (Blender's Spot): the object's matrix (row-major, with its scale; the light
/// shines along its local −Z), power in W, radius in metres, Size = the full cone angle in
/// radians, Blend in [0, 1].
struct SpotLight {
    Mat4 light_to_world;
    Rgb color{1.0f};
    float power = 10.0f;
    float radius = 0.0f;
    /// Blender's spot_size, in [1°, 180°] (radians).
    float spot_size = float(kPi / 4.0);
    /// Blender's spot_blend, in [0, 1].
    float spot_blend = 0.15f;
    CyclesVersion cycles = CyclesVersion::V3_4;
    bool soft_falloff = true;  ///< as PointLight's
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
    CyclesVersion cycles = CyclesVersion::V3_4;
};

/// The world: a constant background of radiance color × strength, or an Environment Texture.
struct WorldLight {
    Rgb color{0.0f};
    float strength = 1.0f;
    /// When set, the world's radiance is environment->eval(direction) (its own colour and
    /// strength included) and color and strength above are not used.
    std::shared_ptr<const EnvironmentMap> environment{};
    /// Cycles' World > Settings > Sampling other than None: the environment is light-sampled.
    bool light_sampled = true;
};

/// Every light of a scene but its emissive triangles.
struct LightsDesc {
    std::vector<SunLight> suns;
    std::vector<PointLight> points;
    std::vector<SpotLight> spots;
    std::vector<AreaLight> areas;
    WorldLight world;
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
/// Radiance of an area light: color·P·0.25/area (3.4), color·P/(π·area) (4.5).
Rgb area_radiance(Rgb color, float power, float area,
                  CyclesVersion version = CyclesVersion::V3_4);
/// invarea of a sun of angular diameter `angle`: 1/(π tan²(angle/2)), or 1 for angle 0.
float sun_invarea(float angle);
/// Radiance of a sun at angle θ from its centre (cos θ ≥ cos(angle/2)): E·invarea/cos³θ (3.4).
Rgb sun_radiance(Rgb color, float strength, float angle, float cos_theta);
/// Radiance of a sun in Cycles 4.5: E/(π sin²(angle/2)) inside its cone (angle > 0).
Rgb sun_radiance_cycles45(Rgb color, float strength, float angle);
/// Cycles 3.4's spot_light_attenuation: c = dot(axis, n) for the unit axis and the unit
/// direction n from the light to the shading point; 0 for c ≤ cos_half, c·smoothstep((c −
/// cos_half)/smooth) for c − cos_half < smooth (smooth ≠ 0), else c.
float spot_attenuation(float c, float cos_half, float smooth);
/// Cycles 4.5's: smoothstep((z − cos_half)/smooth) clamped to [0, 1], z the local −Z
/// component; a hard edge (1 inside, 0 at or outside) for smooth = 0.
float spot_attenuation_cycles45(float z, float cos_half, float smooth);
/// smoothstep(f) = 3f² − 2f³ (Cycles' smoothstepf), not clamped.
inline float smoothstep(float f) { return f * f * (3.0f - 2.0f * f); }

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
    /// colour, an all-black environment) are left out silently; an area light of zero size is
    /// left out with a warning appended to `warnings`. Errors name the light (e.g. "point
    /// light 2: power must be finite and >= 0 (got nan)").
    static Expected<LightSet> build(const LightsDesc &lights,
                                    std::vector<EmissiveTriangle> emissive,
                                    std::vector<std::string> *warnings = nullptr);
    /// The same without spot lights.
    static Expected<LightSet> build(const std::vector<SunLight> &suns,
                                    const std::vector<PointLight> &points,
                                    const std::vector<AreaLight> &areas, const WorldLight &world,
                                    std::vector<EmissiveTriangle> emissive,
                                    std::vector<std::string> *warnings = nullptr);

    LightSet() = default;

    /// Number of lamps: suns, points, spots, areas and a light-sampled environment world.
    int lamp_count() const { return int(lamps_.size()); }
    /// Number of emissive triangles.
    int emissive_triangle_count() const { return int(triangles_.size()); }
    /// True when there is nothing to sample.
    bool empty() const { return lamps_.empty() && triangles_.empty(); }
    /// The constant world's radiance (black without a world or with an environment).
    Rgb world_radiance() const { return world_; }
    /// The world's radiance in direction dir (unit): the environment's, or the constant.
    Rgb world_radiance(Vec3 dir) const { return environment_ ? environment_->eval(dir) : world_; }
    /// True when the world is an environment sampled as a lamp.
    bool world_light_sampled() const { return environment_sampled_; }
    /// The light-sampling density (solid angle, with selection) of the world in direction
    /// dir, seen from p: 0 unless world_light_sampled().
    float world_pdf(Vec3 p, Vec3 dir) const;
    /// The probability of choosing lamp i at p (0 for i past the lamps), and of choosing the
    /// emissive-triangle group.
    float lamp_selection_probability(Vec3 p, std::size_t i) const;
    float triangle_group_probability() const { return triangle_pick_; }

    /// Chooses a light with u_select and samples a point or direction on it from (u0, u1), as
    /// seen from the shading point p. nullopt when the chosen light cannot reach p (e.g. p is
    /// behind an area light).
    std::optional<LightSample> sample(Vec3 p, float u_select, float u0, float u1) const;

    /// Radiance and light-sampling density (solid angle, with selection) of every lamp a ray
    /// crosses (point-light disks and area lights, which are transparent to rays as in Cycles)
    /// between tmin and tmax, combined with the BSDF density bsdf_pdf by the power heuristic:
    /// returns Σ L·w. With use_mis false (camera rays, or after a delta BSDF) w = 1.
    /// `from`: the shading point the ray left, where its light sample was drawn (the lamps'
    /// selection probabilities are taken there); the origin when not given.
    Rgb lamps_along_ray(Vec3 origin, Vec3 dir, float tmin, float tmax, float bsdf_pdf,
                        bool use_mis, std::optional<Vec3> from = std::nullopt) const;
    /// Radiance reaching a ray that escapes the scene in direction dir: suns whose disc
    /// contains dir and the world, each weighted by MIS against bsdf_pdf (when use_mis; a
    /// world that is not light-sampled takes weight 1).
    /// include_world false leaves the world out (transparent film for camera rays).
    /// `from`: the shading point the ray left (the lamps' selection probabilities are taken
    /// there).
    Rgb escaped(Vec3 from, Vec3 dir, float bsdf_pdf, bool use_mis, bool include_world = true) const;
    /// The density with which sample() draws the unit direction wi from p (solid angle, with
    /// the selection probabilities): the sum over every lamp and emissive triangle that wi
    /// reaches, as if nothing blocked it; delta lights have none. Directions that sample()
    /// refuses (a spot's attenuation is 0 there) have none either.
    float pdf(Vec3 p, Vec3 wi) const;
    /// The light-sampling density (solid angle, with selection) of an emissive triangle point
    /// seen at distance t with |cos| abs_cos between the ray and the triangle's normal.
    float emissive_triangle_pdf(float t, float abs_cos) const;

    /// The bytes this light set holds.
    std::size_t memory_bytes() const;

  private:
    enum class LampType : std::uint8_t { Point, Spot, Area, Sun, Environment };
    struct Lamp {
        LampType type = LampType::Point;
        CyclesVersion cycles = CyclesVersion::V3_4;
        Rgb value;          // point, spot: radiance (r > 0) or intensity (r = 0); area:
                            // radiance; sun: strength (irradiance) in 3.4, radiance in 4.5
        Vec3 position;      // point, spot and area centre
        Vec3 axis_u, axis_v;// area: full extents
        Vec3 direction;     // area: emitting normal; sun: towards the sun; spot: its axis
        float radius = 0;   // point and spot radius; sun: tan(angle/2) (3.4), angle/2 (4.5)
        float invarea = 1;  // 1/area of the disk, rectangle or ellipse
        float cos_half = 1; // sun: cos(angle/2); spot: cos(spot_size/2)
        float one_minus_cos_half = 0;  // sun (4.5): 1 − cos(angle/2), computed stably
        float smooth = 0;   // spot: (1 − cos_half)·blend
        float importance = 0;  // luminance: sun E, point and spot I, area L·A, environment πL̄
        float world_to_light[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // spot (4.5): M⁻¹
        bool sphere = false;// point, spot (4.5 without soft falloff): a sphere of radius r
        bool round = false; // area: disk or ellipse
        bool solid_angle = false;  // area: rectangle with orthogonal axes, sampled by solid angle
    };

    // The steps of build(), in its order.
    template <typename Light>
    static void set_point_emission(Lamp &lamp, const Light &p);
    template <typename Light, typename... Extra>
    Status add_lamps(const std::vector<Light> &lights, const char *kind, Extra... extra);
    static Status lamp_of(const SunLight &s, const std::string &name, std::optional<Lamp> &out);
    static Status lamp_of(const PointLight &p, const std::string &name, std::optional<Lamp> &out);
    static Status lamp_of(const SpotLight &p, const std::string &name, std::optional<Lamp> &out);
    static Status lamp_of(const AreaLight &a, const std::string &name, std::optional<Lamp> &out,
                          std::vector<std::string> *warnings);
    Status set_world(const WorldLight &world);
    void set_triangles(const std::vector<EmissiveTriangle> &emissive);

    // The spot's attenuation for light leaving it in unit direction n (towards the receiver).
    static float spot_factor(const Lamp &lamp, Vec3 n);
    // The cosine spot_factor compares with the cone: of n and the axis (3.4), of the light's
    // own frame (4.5).
    static float spot_axis_cosine(const Lamp &lamp, Vec3 n);
    // 1 where light from some point of the spot's disk can leave inside its cone towards p
    // (d = p − centre, d2 = |d|²), else 0.
    static float spot_reach(const Lamp &lamp, Vec3 d, float d2);
    // Point and spot: the sphere's light-sampling density (without selection) seen from a
    // point at squared distance d2 from its centre.
    static float sphere_pdf(float d2, float r2);
    // Point and spot radiance towards a receiver at p along unit direction wi that reaches the
    // light (before selection); 0 where a spot's cone does not reach.
    Rgb point_like_value(const Lamp &lamp, Vec3 p, Vec3 wi) const;
    // Calls visit(radiance, light-sampling density with selection) for every lamp the ray
    // crosses in (tmin, tmax), and for every sun whose disc an escaping ray meets.
    template <typename Visit>
    void visit_lamps_along_ray(Vec3 origin, Vec3 dir, float tmin, float tmax, Vec3 from, Visit &&visit) const;
    template <typename Visit>
    void visit_escaped(Vec3 origin, Vec3 dir, Visit &&visit) const;
    // `pick`: the lamp's selection probability at p.
    std::optional<LightSample> sample_lamp(const Lamp &lamp, Vec3 p, float u0, float u1, float pick) const;
    std::optional<LightSample> sample_point_like(const Lamp &lamp, Vec3 p, float u0, float u1,
                                                 float pick) const;
    // Selection by importance: a lamp's estimate of the irradiance it brings to p, unshadowed
    // (sun: E; point: I/max(d², r²); spot: the same where its cone can reach p, else 0; area: L·A·max(cos, 0)/d², or L where p is within
    // √area of it; environment: πL̄ = ∫L dω/4), their sum over the lamps, and a lamp's share of
    // the lamps' probability from its importance: kUniformShare uniform, the rest by importance.
    static float importance_at(const Lamp &lamp, Vec3 p);
    float importance_total(Vec3 p) const;
    float share_of(float importance, float total) const;
    // The lamp's selection probability at p (with importance_total(p) as `total`).
    float lamp_pick(const Lamp &lamp, Vec3 p, float total) const;
    class LampPicks;
    static constexpr float kUniformShare = 0.1f;
    static constexpr std::size_t kMaxImportanceLamps = 64;  // more: uniform (O(n) per query)
    std::optional<LightSample> sample_triangle(Vec3 p, float u_select, float u0, float u1) const;

    std::vector<Lamp> lamps_;
    std::vector<EmissiveTriangle> triangles_;
    std::vector<float> triangle_cdf_;  // size n + 1, normalised
    float triangle_area_ = 0;
    float lamp_pick_ = 0;      // probability of each lamp when selection is uniform
    bool by_importance_ = false;  // 2..kMaxImportanceLamps lamps: chosen by importance at p
    float triangle_pick_ = 0;  // probability of the triangle group
    Rgb world_;
    std::shared_ptr<const EnvironmentMap> environment_;
    bool environment_sampled_ = false;  // environment_ is one of lamps_
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
