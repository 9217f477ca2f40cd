// A render scene: hair curves, triangle meshes, materials, lights, world and camera, given as
// plain data, validated, and built into an Embree 3 BVH.
//
// Hair curves are Embree curves of the type Cycles gives its Curves > Shape
// (intern/cycles/bvh/embree.cpp, add_curves and set_curve_vertex_buffer; SceneDesc::curve_shape):
// ROUND Catmull-Rom for "3D Curves" (Thick), FLAT Catmull-Rom — a strip facing the ray — for
// "Rounded Ribbons", ROUND linear for 5.0's "Linear 3D Curves". Per curve of n points,
// Embree gets n + 2 control points — the first and the last point duplicated — and n − 1
// segments, so a Catmull-Rom curve passes through every point from the first to the last;
// linear curves read the same buffer one control point on, so that segment k joins points k
// and k + 1, as Cycles' linear layout without the duplicates does. The radius is per point
// (Embree's 4th vertex component). Hits on the inside of a round tube (ray direction ·
// Embree's Ng > 0: a ray that starts inside another strand's tube) follow
// SceneDesc::curve_backfaces on Catmull-Rom tubes and are culled on linear curves (Cycles 5.0
// renders its linear curves so, Embree 4 or not); ribbons have no inside (Embree's Ng of a flat
// curve is its tangent, and Cycles culls nothing on them), and a ray never hits the curve it
// starts on — any segment of
// it — as Cycles' self-intersection test does (kernel/device/cpu/bvh.h,
// kernel_embree_is_self_intersection maps a hair segment to its curve before comparing), so
// no origin offset is needed. The
// Embree tessellation rate is Cycles' default: Curves > Subdivisions 2 (addon properties.py),
// SceneParams::curve_subdivisions() = 2² = 4, rtcSetGeometryTessellationRate(4 + 1).
//
// Curve shading data, as Cycles' curve_shader_setup (kernel/geom/curve_intersect.h): for thick
// curves the hit P, P_curve = the centre line at the hit's u (Catmull-Rom, or the segment's
// straight line for linear curves), Ng = normalize(P − P_curve), tangent = normalize(dP/du);
// the renderer then builds the fiber frame from the tangent and ω_o and
// h = dot(cross(Ng, X), Z) (bsdf_principled_hair_setup). For ribbons Ng = ω_o, the tangent
// is the Catmull-Rom one, N the rounded normal from Embree's v across the strip, and the
// hair closures take h = −v. Per-point attributes are
// interpolated linearly between the segment's two points at the hit's u, as Cycles'
// curve_attribute does: the curve normal (Huang's major axis, kernel/svm/closure.h) and the
// radius Cycles divides the pixel footprint by (pixel_coverage).
//
// Validation (errors name the object and what is allowed):
//  - refused: NaN/inf positions or radii, negative radii, a curve with fewer than 2 points,
//    inconsistent curve offsets, curve inputs of the wrong size, out of their range
//    (check_hair_input), repeated, not read by the material's parametrization or on a
//    material whose model does not vary per strand, mesh indices out of range, material
//    indices out of range, a hair material on a mesh, a hair material without fiber or
//    sampler, corner normals or UVs that are not one per triangle corner or not finite,
//    and invalid lights or camera. A scene with no geometry (left) is legal: every ray misses.
//
// Mesh shading data, as Cycles' triangle shader setup: Ng the face normal, N the corner normals
// interpolated with the hit's barycentrics and normalized (Blender's corner normals: the
// vertex normal on smooth faces, the face normal on flat ones, split or custom normals where
// the mesh has them; the face normal when a mesh gives none), and the UV map interpolated the
// same way ((0, 0) without one, as Cycles' missing attribute).
//  - skipped with a counted warning: curves of zero length (all points equal) or zero radius
//    everywhere — they would never be hit — and degenerate (zero-area) triangles.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "render/camera.h"
#include "core/expected.h"
#include "render/lights.h"
#include "core/math.h"
#include "fiber/hair_inputs.h"
#include "render/surface_material.h"
#include "fiber/dual_scattering.h"
#include "sampling/hair_bsdf.h"
#include "sampling/hair_mixture.h"
#include "sampling/sampling_table.h"

namespace hairis {

/// A hair material: the Cycles-exact fiber and the strategy that draws ω_i for it.
struct HairMaterial {
    explicit HairMaterial(HairShading shading_) : shading(std::move(shading_)) {}
    HairShading shading;
    /// Set for a Mix or Add Shader of hair closures (hair_mixture.h): the material then shades
    /// with all of them; `shading` is its first closure. Curve inputs go to every closure
    /// that reads them; CurveInput::closure_weight varies a closure's weight per strand.
    std::shared_ptr<const HairMixture> mixture;
    /// What integrator=dual_scattering shades with (render/dual_scattering_integrator.h): the
    /// fiber's dual-scattering averages and its baked multiple-scattering tables. Null for the
    /// path tracer.
    std::shared_ptr<const DualScattering> dual;
    std::shared_ptr<const MultipleTable> multiple;
};

/// A Lambertian surface with optional emission (radiance, on both sides as in Cycles). A pure
/// emitter is albedo 0; the emission of mesh triangles is sampled as a light.
struct DiffuseMaterial {
    Rgb albedo{0.8f};
    Rgb emission{0.0f};
};

/// A material of Blender shader nodes (surface_material.h).
using Material = std::variant<HairMaterial, DiffuseMaterial, SurfaceMaterial>;

/// The radiance a mesh material emits (0 for hair).
Rgb material_emission(const Material &material);

/// A node input of a hair material given per curve or per point of a curve set: `values`
/// holds the input's components (3 for colours) for each curve or each point in turn. At a
/// hit a per-curve value is the curve's; a per-point value is interpolated linearly in the
/// segment's curve parameter u between its two points, as Cycles interpolates curve-key
/// attributes (kernel/geom/curve.h).
struct CurveInput {
    HairInput input = HairInput::Melanin;
    bool per_point = false;
    std::vector<float> values;
    /// >= 0: not a node input but the weight of this closure of the material's mixture (one
    /// component, finite and >= 0); `input` is then ignored.
    int closure_weight = -1;
};

/// Hair curves sharing one material. Curve c has points first[c] .. first[c + 1] − 1; first
/// has curve count + 1 entries, starts at 0 and ends at points.size(). One radius per point.
/// `inputs` (at most one per HairInput) vary the material's node inputs per curve or point;
/// the material must then be one whose model reads them (ChiangStrands).
struct HairCurves {
    std::vector<Vec3> points;
    std::vector<float> radii;
    std::vector<std::uint32_t> first;
    std::uint32_t material = 0;
    std::vector<CurveInput> inputs;
    /// The curve normal attribute, one per point, finite; or empty (particle hair: Cycles
    /// then has zero normals). Used as given: Cycles does not transform curve normals by the
    /// object's matrix.
    std::vector<Vec3> normals;
};

/// A triangle mesh in world space. indices holds 3 vertex indices per triangle; materials
/// holds one material index per triangle, or a single index for the whole mesh. normals
/// (unit, world space) and uvs are per triangle corner, in the order of indices: 3 normals
/// and 3 UV pairs per triangle, or empty (the face normal; UV (0, 0)).
struct TriangleMesh {
    std::vector<Vec3> positions;
    std::vector<std::uint32_t> indices;
    std::vector<std::uint32_t> materials{0};
    std::vector<Vec3> normals;
    std::vector<float> uvs;
};

/// What a ray that meets a round curve from inside its tube does. Such rays start inside
/// another strand (strands that overlap). Cycles built with Embree 3 (Blender 3.4) culls
/// these back faces in its curve filter; with Embree 4 (Blender's own builds from 3.6, so
/// 4.5 and 5.0) the filter only skips the ray's own curve and the back face is a hit, shaded
/// with the outward normal like any other.
enum class CurveBackfaces : int { Ignore = 0, Hit = 1 };

/// The shape hair curves are traced as: Cycles' Curves > Shape (scene.cycles_curves.shape), one
/// for the whole scene. Thick is "3D Curves" (round Catmull-Rom tubes), Ribbons "Rounded
/// Ribbons" (flat Catmull-Rom strips that face the ray, shaded as if round), ThickLinear
/// Cycles 5.0's "Linear 3D Curves" (round cones from point to point).
enum class CurveShape : int { Thick = 0, Ribbons = 1, ThickLinear = 2 };

/// How much work Embree spends on the BVH, as Cycles asks for it: Low (with Embree's dynamic-scene
/// flag) for the viewport, Medium for a final render, High with Use Spatial Splits. The image does
/// not depend on it.
enum class BvhQuality : int { Low = 0, Medium = 1, High = 2 };

/// Everything a scene is made of, as plain data.
struct SceneDesc {
    std::vector<Material> materials;
    std::vector<HairCurves> curves;
    std::vector<TriangleMesh> meshes;
    std::vector<SunLight> suns;
    std::vector<PointLight> point_lights;
    std::vector<SpotLight> spot_lights;
    std::vector<AreaLight> area_lights;
    WorldLight world;
    CameraDesc camera;
    CurveBackfaces curve_backfaces = CurveBackfaces::Ignore;
    CurveShape curve_shape = CurveShape::Thick;
    BvhQuality bvh_quality = BvhQuality::Medium;
    /// Cycles' Curves > Subdivisions, in [0, 24] (Blender's default 2): Embree's tessellation
    /// rate clamp(2^s, 1, 16) + 1, as Cycles sets it; ribbons are intersected as that many
    /// flat pieces per segment.
    int curve_subdivisions = 2;
};

/// What the build did and what it costs.
struct SceneStats {
    std::size_t curves = 0;           ///< curves kept
    std::size_t curve_segments = 0;   ///< Embree segments (points − 1 per curve)
    std::size_t curve_points = 0;     ///< points of the kept curves
    std::size_t skipped_curves = 0;   ///< zero-length or zero-radius curves left out
    std::size_t triangles = 0;        ///< triangles kept
    std::size_t skipped_triangles = 0;///< degenerate triangles left out
    std::size_t emissive_triangles = 0;
    std::size_t lamps = 0;            ///< lamps sampled (suns, points, spots, areas, world)
    std::vector<std::string> warnings;///< one line per kind of skipped item
    std::size_t scene_bytes = 0;      ///< hairis' own copies (curve and mesh buffers, lights)
    std::size_t embree_peak_bytes = 0;///< Embree's peak allocation during the build
    std::size_t embree_bytes = 0;     ///< Embree's allocation after the build
    /// Estimated peak memory of the scene: own buffers + Embree's peak.
    std::size_t estimated_peak_bytes = 0;
    double build_seconds = 0;
};

/// A primitive of the scene: Embree geometry id and primitive index. For a hit the index is
/// the segment or triangle; for a ray's self-intersection skip it is the triangle or, for hair,
/// the curve (all of its segments are skipped).
struct PrimRef {
    static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
    std::uint32_t geometry = kNone;
    std::uint32_t primitive = kNone;
};

/// The closest hit of a ray.
struct Hit {
    float t = 0;
    PrimRef prim;
    float u = 0, v = 0;  ///< Embree's hit coordinates (curve parameter for curves)
};

/// A hair strand a ray crosses (Scene::trace_through_hair): where, on which segment and at
/// which curve parameter, the strand's unit tangent and radius there and its material.
struct StrandCrossing {
    float t = 0;
    PrimRef segment;
    float u = 0;
    Vec3 tangent;
    float radius = 0;
    std::uint32_t material = 0;
};

/// What shading needs at a hit point.
struct SurfacePoint {
    Vec3 position;
    /// Unit geometric normal: the face normal (not flipped) for triangles; for thick curves
    /// the outward tube normal normalize(P − P_curve(u)) (Cycles' thick-curve Ng); for ribbons
    /// −dir, towards the ray's origin (Cycles' ribbon Ng = ω_o).
    Vec3 normal;
    /// Unit curve tangent normalize(dP/du) (zero for triangles).
    Vec3 tangent;
    /// The curve parameter of the hit in its segment, in [0, 1] (0 for triangles).
    float curve_u = 0;
    /// Triangles: the unit shading normal, on the same side as `normal` (equal to it for flat
    /// faces); thick curves: equal to `normal`; ribbons: Cycles' rounded normal, which turns
    /// from the ray's side of the strand at v = 0 to its edges at v = ±1.
    Vec3 shading_normal;
    /// Ribbons: Embree's hit v across the ribbon, in [−1, 1] (Cycles' sd->v; the hair offset
    /// is h = −v); 0 otherwise.
    float curve_v = 0;
    bool is_ribbon = false;
    /// Triangles: the UV map at the hit ((0, 0) without one).
    float u = 0.0f, v = 0.0f;
    /// Curves: the normal attribute interpolated at the hit (not normalized; zero when the
    /// curves have none); zero for triangles.
    Vec3 curve_normal;
    /// Curves: the radius interpolated linearly between the segment's points at u (Cycles'
    /// radius for pixel_coverage; the surface itself follows the Catmull-Rom radius); 0 for
    /// triangles.
    float curve_radius = 0;
    std::uint32_t material = 0;
    bool is_curve = false;
    /// True for a mesh triangle whose emission is in the light set (MIS applies to it).
    bool is_light = false;
    /// The segment or triangle hit.
    PrimRef prim;
    /// What rays leaving this point must not hit: the triangle, or the whole curve.
    PrimRef self;
    /// Triangles: a bound on the position's rounding error; rays leave from
    /// spawn_point(dir), pushed this far off the plane towards dir, so that they cannot hit
    /// the triangles that share an edge with this one at t ≈ 0 (skipping the primitive
    /// itself, as Cycles does, only handles the triangle hit). 0 for curves, whose rays leave
    /// from the hit point itself (Cycles' self-primitive test and backface culling).
    float offset = 0;

    /// Where a ray in direction dir leaves this point from.
    Vec3 spawn_point(Vec3 dir) const {
        return offset == 0.0f ? position
                              : position + normal * (dot(normal, dir) >= 0.0f ? offset : -offset);
    }
};

/// A built, immutable scene. Thread-safe for tracing. Move-only.
class Scene {
  public:
    /// Validates `desc`, builds the lights and Embree's BVH. Takes the buffers by value: move
    /// them in to avoid copies.
    static Expected<Scene> build(SceneDesc desc);

    Scene(Scene &&) noexcept;
    Scene &operator=(Scene &&) noexcept;
    Scene(const Scene &) = delete;
    Scene &operator=(const Scene &) = delete;
    ~Scene();

    const Camera &camera() const;
    /// Replaces the camera, refused as build() refuses one: nothing else in a built scene
    /// depends on it, so a new view needs no new BVH. Not while the scene is being rendered.
    Status set_camera(const CameraDesc &camera);
    /// Replaces the materials, lights and world with `desc`'s (its geometry, camera and curve
    /// settings are not read): the geometry's BVH stays. Refused as build() refuses them, and
    /// when the geometry does not fit the new materials (an index out of range, a hair
    /// material on a mesh, curve inputs the material does not read); a refusal changes
    /// nothing. Not while the scene is being rendered.
    Status set_shading(SceneDesc desc);
    const LightSet &lights() const;
    const std::vector<Material> &materials() const;
    const SceneStats &stats() const;

    /// The closest hit with t in (tmin, tmax), ignoring `skip` (SurfacePoint::self of the
    /// point the ray starts on) and, unless SceneDesc::curve_backfaces is Hit, the inside of
    /// curve tubes. dir must be unit length.
    std::optional<Hit> intersect(Vec3 origin, Vec3 dir, float tmin, float tmax,
                                 PrimRef skip = {}) const;
    /// True when anything blocks the segment (tmin, tmax), ignoring skip_a and skip_b (as in
    /// intersect()). Hair is opaque to shadow rays, as in Cycles.
    bool occluded(Vec3 origin, Vec3 dir, float tmin, float tmax, PrimRef skip_a = {},
                  PrimRef skip_b = {}) const;
    /// The ray (tmin, tmax) with hair let through (dual scattering's shadow rays): returns the
    /// first mesh triangle it hits (nullopt when none; skip_a, skip_b and curve insides are
    /// ignored as in occluded()) and puts the strands it crosses before that hit into
    /// `strands` (cleared first), one entry per crossing of a tube, in order of t. A crossing
    /// is reported once even where two segments of a curve overlap at their joint.
    std::optional<Hit> trace_through_hair(Vec3 origin, Vec3 dir, float tmin, float tmax,
                                          PrimRef skip_a, PrimRef skip_b,
                                          std::vector<StrandCrossing> &strands) const;
    /// trace_through_hair for a caller that needs no more than `cap` strands (cap < 0: every
    /// one): where more than cap lie before the first mesh (or tmax), `strands` holds the first
    /// cap + 1 of them and no mesh is returned, the traversal stopping once that is known;
    /// otherwise as trace_through_hair (so strands.size() > cap says which).
    std::optional<Hit> trace_through_hair_within(Vec3 origin, Vec3 dir, float tmin, float tmax,
                                                 PrimRef skip_a, PrimRef skip_b, int cap,
                                                 std::vector<StrandCrossing> &strands) const;
    /// min(cap, the strands trace_through_hair reports along the ray), cap >= 1: the traversal
    /// stops once cap crossings are known to lie before any mesh (so a long ray through dense
    /// hair costs about what its first cap crossings cost). `scratch` is overwritten.
    int strands_before_mesh(Vec3 origin, Vec3 dir, float tmin, float tmax, PrimRef skip, int cap,
                            std::vector<StrandCrossing> &scratch) const;
    /// trace_through_hair, with curve hits accepted once `accept_after` hits are recorded;
    /// `stopped`: the traversal ended at such a hit (no mesh before it; the strands reported
    /// are those before it).
    std::optional<Hit> trace_through_hair(Vec3 origin, Vec3 dir, float tmin, float tmax,
                                          PrimRef skip_a, PrimRef skip_b,
                                          std::vector<StrandCrossing> &strands,
                                          std::size_t accept_after, bool &stopped) const;
    /// Shading data of a hit of the ray (origin, dir).
    SurfacePoint surface_point(Vec3 origin, Vec3 dir, const Hit &hit) const;
    /// The node inputs a curve hit's curve set gives (HairCurves::inputs) at the hit, in
    /// `values`, and its closure weights in `weights` (when not null); false (both untouched)
    /// for triangles and curves without inputs.
    bool hair_inputs(const SurfacePoint &point, HairInputValues &values,
                     ClosureWeights *weights = nullptr) const;

    /// The centre line of a curve segment at u ∈ [0, 1] (Catmull-Rom, or the straight line
    /// between the segment's points for CurveShape::ThickLinear): position (and radius in
    /// `radius`), and dP/du in `derivative` when not null.
    Vec3 curve_point(PrimRef segment, float u, Vec3 *derivative = nullptr,
                     float *radius = nullptr) const;

  private:
    struct Impl;
    explicit Scene(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace hairis
