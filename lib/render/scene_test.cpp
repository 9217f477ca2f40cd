#include "render/scene.h"

#include <gtest/gtest.h>

#include "fiber/chiang.h"
#include "fiber/chiang_strands.h"
#include "sampling/uniform_sampler.h"

#include <cmath>
#include <random>
#include <string>

#include "chi2.h"

namespace hairis {
namespace {

CameraDesc small_camera() {
    CameraDesc c;
    c.camera_to_world = Mat4::translation({0, 0, 5});
    c.width = 4;
    c.height = 4;
    return c;
}

std::shared_ptr<const ChiangFiber> default_fiber() {
    auto fiber = ChiangFiber::create(ChiangParams{});
    EXPECT_TRUE(fiber.ok());
    return std::make_shared<const ChiangFiber>(std::move(fiber).value());
}

HairMaterial hair_material() {
    return HairMaterial{HairShading::create(default_fiber(), std::make_shared<const UniformSampler>()).value()};
}

// One straight hair along X at y = z = 0, radius 0.1, through 4 points.
HairCurves straight_hair() {
    HairCurves c;
    c.points = {{-1.5f, 0, 0}, {-0.5f, 0, 0}, {0.5f, 0, 0}, {1.5f, 0, 0}};
    c.radii = {0.1f, 0.1f, 0.1f, 0.1f};
    c.first = {0, 4};
    c.material = 0;
    return c;
}

TriangleMesh quad(float z, std::uint32_t material) {
    TriangleMesh m;
    m.positions = {{-1, -1, z}, {1, -1, z}, {1, 1, z}, {-1, 1, z}};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.materials = {material};
    return m;
}

Scene build_ok(SceneDesc desc) {
    auto s = Scene::build(std::move(desc));
    EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
    return std::move(s).value();
}

// A scene of `curves` (by default straight_hair) in `material` under small_camera.
SceneDesc one_hair(HairMaterial material, HairCurves curves = straight_hair()) {
    SceneDesc d;
    d.materials = {std::move(material)};
    d.curves = {std::move(curves)};
    d.camera = small_camera();
    return d;
}

std::string build_error(SceneDesc desc) {
    auto s = Scene::build(std::move(desc));
    return s.ok() ? std::string("(built without error)") : s.error().message;
}

TEST(Scene, CurvesBecomeCatmullRomSegmentsThroughEveryPoint) {
    SceneDesc d;
    d.materials = {hair_material()};
    HairCurves c;
    c.points = {{0, 0, 0}, {1, 0.5f, 0}, {2, 0, 0.3f}, {3, 1, 0}, {0, 0, 2}, {0, 1, 2}};
    c.radii = {0.1f, 0.2f, 0.15f, 0.05f, 0.3f, 0.3f};
    c.first = {0, 4, 6};
    d.curves = {c};
    d.camera = small_camera();
    const Scene scene = build_ok(std::move(d));
    const SceneStats &st = scene.stats();
    EXPECT_EQ(st.curves, 2u);
    EXPECT_EQ(st.curve_points, 6u);
    EXPECT_EQ(st.curve_segments, 3u + 1u);  // n − 1 segments per curve
    EXPECT_EQ(st.skipped_curves, 0u);
    EXPECT_GT(st.embree_peak_bytes, 0u);
    EXPECT_GE(st.estimated_peak_bytes, st.scene_bytes + st.embree_peak_bytes);
    // With the end points duplicated, segment k runs from point k to point k + 1.
    for (std::uint32_t k = 0; k < 3; ++k) {
        float r0 = 0, r1 = 0;
        const Vec3 a = scene.curve_point({0, k}, 0.0f, nullptr, &r0);
        const Vec3 b = scene.curve_point({0, k}, 1.0f, nullptr, &r1);
        EXPECT_NEAR(length(a - c.points[k]), 0.0f, 1e-6f) << k;
        EXPECT_NEAR(length(b - c.points[k + 1]), 0.0f, 1e-6f) << k;
        EXPECT_NEAR(r0, c.radii[k], 1e-6f);
        EXPECT_NEAR(r1, c.radii[k + 1], 1e-6f);
    }
    // A two-point curve is a straight segment.
    Vec3 derivative;
    const Vec3 mid = scene.curve_point({0, 3}, 0.5f, &derivative);
    EXPECT_NEAR(length(mid - Vec3{0, 0.5f, 2}), 0.0f, 1e-6f);
    EXPECT_NEAR(length(safe_normalize(derivative) - Vec3{0, 1, 0}), 0.0f, 1e-6f);
}

TEST(Scene, RaysHitTheHairTubeWithCyclesShadingData) {
    SceneDesc d;
    d.materials = {hair_material()};
    d.curves = {straight_hair()};
    d.camera = small_camera();
    const Scene scene = build_ok(std::move(d));

    // Straight down onto the top of the tube.
    auto hit = scene.intersect({0.3f, 0, 5}, {0, 0, -1}, 0.0f, INFINITY);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->t, 4.9f, 1e-3f);
    SurfacePoint sp = scene.surface_point({0.3f, 0, 5}, {0, 0, -1}, *hit);
    EXPECT_TRUE(sp.is_curve);
    EXPECT_NEAR(sp.normal.z, 1.0f, 1e-3f);
    EXPECT_NEAR(std::fabs(sp.tangent.x), 1.0f, 1e-5f);

    // Off-centre by half the radius: the normal tilts; P − centre has length r.
    hit = scene.intersect({0.3f, 0.05f, 5}, {0, 0, -1}, 0.0f, INFINITY);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->t, 5.0f - std::sqrt(0.01f - 0.0025f), 1e-3f);
    sp = scene.surface_point({0.3f, 0.05f, 5}, {0, 0, -1}, *hit);
    EXPECT_NEAR(sp.normal.y, 0.5f, 1e-2f);
    EXPECT_NEAR(sp.normal.x, 0.0f, 1e-3f);

    // A miss beside the tube.
    EXPECT_FALSE(scene.intersect({0.3f, 0.2f, 5}, {0, 0, -1}, 0.0f, INFINITY).has_value());
    // From inside the tube, the exit is a back face: culled, as in Cycles.
    EXPECT_FALSE(scene.intersect({0.3f, 0, 0}, {0, 0, 1}, 0.0f, INFINITY).has_value());
    // A ray leaving the surface into the fiber, skipping its own curve, does not hit it
    // again (Cycles' self-intersection test); without the skip it would at t ≈ 0.
    const auto top = scene.intersect({0.3f, 0, 5}, {0, 0, -1}, 0.0f, INFINITY);
    ASSERT_TRUE(top.has_value());
    const SurfacePoint top_sp = scene.surface_point({0.3f, 0, 5}, {0, 0, -1}, *top);
    EXPECT_EQ(top_sp.self.geometry, top->prim.geometry);
    EXPECT_EQ(top_sp.self.primitive, 0u);  // curve 0, although segment 1 was hit
    EXPECT_EQ(top->prim.primitive, 1u);
    const Vec3 inward = safe_normalize(Vec3{0.2f, 0.1f, -1});
    EXPECT_FALSE(scene.intersect(top_sp.position, inward, 0.0f, INFINITY, top_sp.self));
    const auto unskipped =
        scene.intersect(top_sp.position + Vec3{0, 0, 1e-4f}, inward, 0.0f, INFINITY);
    ASSERT_TRUE(unskipped.has_value());
    EXPECT_LT(unskipped->t, 1e-3f);
    // Near a joint, the neighbouring segment of the same curve is skipped too.
    const auto joint = scene.intersect({0.49f, 0, 5}, {0, 0, -1}, 0.0f, INFINITY);
    ASSERT_TRUE(joint.has_value());
    const SurfacePoint joint_sp = scene.surface_point({0.49f, 0, 5}, {0, 0, -1}, *joint);
    EXPECT_FALSE(scene.intersect(joint_sp.position, safe_normalize(Vec3{1, 0, -0.2f}), 0.0f,
                                 INFINITY, joint_sp.self));
    // Hair blocks shadow rays.
    EXPECT_TRUE(scene.occluded({0.3f, 0, 5}, {0, 0, -1}, 0.0f, 10.0f));
    EXPECT_FALSE(scene.occluded({0.3f, 0, 5}, {0, 0, -1}, 0.0f, 4.0f));
}

// Two parallel strands along X, radius 0.1, whose axes are 0.05 apart in y: each one's
// surface near the other lies inside the other's tube. Rays leave strand 0 from its point
// (x, 0.1, 0), skipping strand 0; that point is 0.05 from strand 1's axis, so going +z the ray
// meets strand 1's tube from inside at z = sqrt(0.1² − 0.05²).
TEST(Scene, CurveBackfacesAreCulledOrHitAsCyclesWithEmbree3Or4) {
    auto overlapping = [](CurveBackfaces backfaces) {
        SceneDesc d;
        d.materials = {hair_material()};
        HairCurves c = straight_hair();
        for (int k = 0; k < 4; ++k) {
            c.points.push_back(c.points[k] + Vec3{0, 0.05f, 0});
            c.radii.push_back(0.1f);
        }
        c.first = {0, 4, 8};
        d.curves = {c};
        d.camera = small_camera();
        d.curve_backfaces = backfaces;
        return build_ok(std::move(d));
    };
    const Vec3 start{0.3f, 0.1f, 0.0f};
    const Vec3 up{0, 0, 1};
    const float exit_t = std::sqrt(0.1f * 0.1f - 0.05f * 0.05f);

    const Scene culled = overlapping(CurveBackfaces::Ignore);
    const PrimRef strand0{0, 0};
    EXPECT_FALSE(culled.intersect(start, up, 0.0f, INFINITY, strand0).has_value());
    EXPECT_FALSE(culled.occluded(start, up, 0.0f, 10.0f, strand0));

    const Scene hits = overlapping(CurveBackfaces::Hit);
    const auto hit = hits.intersect(start, up, 0.0f, INFINITY, strand0);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->t, exit_t, 1e-3f);
    const SurfacePoint sp = hits.surface_point(start, up, *hit);
    EXPECT_EQ(sp.self.primitive, 1u);  // strand 1
    // The outward normal of strand 1 at the exit: (0, 0.05, exit_t) / r.
    EXPECT_NEAR(sp.normal.y, 0.5f, 1e-2f);
    EXPECT_NEAR(sp.normal.z, exit_t / 0.1f, 1e-2f);
    EXPECT_GT(dot(sp.normal, up), 0.0f);
    EXPECT_TRUE(hits.occluded(start, up, 0.0f, 10.0f, strand0));
    EXPECT_FALSE(hits.occluded(start, up, 0.0f, 0.9f * exit_t, strand0));
    // The ray's own strand stays skipped: from inside strand 0 only (0.06 from its axis,
    // 0.11 from strand 1's), going −y, nothing is hit.
    const Vec3 inside0{0.3f, -0.06f, 0.0f};
    EXPECT_FALSE(hits.intersect(inside0, {0, -1, 0}, 0.0f, INFINITY, strand0).has_value());
    // Without the skip, the same ray leaves strand 0 through its back face.
    const auto own = hits.intersect(inside0, {0, -1, 0}, 0.0f, INFINITY);
    ASSERT_TRUE(own.has_value());
    EXPECT_NEAR(own->t, 0.04f, 1e-3f);
    EXPECT_FALSE(culled.intersect(inside0, {0, -1, 0}, 0.0f, INFINITY).has_value());
    // Rays from outside see the same front faces either way.
    const auto front_culled = culled.intersect({0.3f, 0.02f, 5}, {0, 0, -1}, 0.0f, INFINITY);
    const auto front_hits = hits.intersect({0.3f, 0.02f, 5}, {0, 0, -1}, 0.0f, INFINITY);
    ASSERT_TRUE(front_culled.has_value() && front_hits.has_value());
    EXPECT_FLOAT_EQ(front_culled->t, front_hits->t);

    SceneDesc bad;
    bad.materials = {hair_material()};
    bad.curves = {straight_hair()};
    bad.camera = small_camera();
    bad.curve_backfaces = CurveBackfaces(7);
    EXPECT_NE(build_error(std::move(bad)).find("curve_backfaces"), std::string::npos);
}

TEST(Scene, CurveAttributesAreLinearAlongEachSegment) {
    // Radii that bend the Catmull-Rom radius away from the straight line between two points,
    // and a normal per point: at a hit of parameter u on segment k (from point k to k + 1)
    // both are (1 − u)·a_k + u·a_{k+1}, as Cycles' curve_attribute reads per-point values.
    SceneDesc d;
    d.materials = {hair_material()};
    HairCurves c = straight_hair();
    c.radii = {0.05f, 0.1f, 0.2f, 0.05f};
    c.normals = {{0, 0, 1}, {0, 1, 1}, {0, 2, -1}, {1, 0, 0}};
    d.curves = {c};
    d.camera = small_camera();
    const Scene scene = build_ok(std::move(d));
    for (const float x : {-1.2f, -0.3f, 0.1f, 0.45f, 1.1f}) {
        const Vec3 origin{x, 0, 5};
        const auto hit = scene.intersect(origin, {0, 0, -1}, 0.0f, INFINITY);
        ASSERT_TRUE(hit.has_value()) << x;
        const SurfacePoint sp = scene.surface_point(origin, {0, 0, -1}, *hit);
        const std::uint32_t k = hit->prim.primitive;
        const float u = hit->u;
        EXPECT_NEAR(sp.curve_radius, (1 - u) * c.radii[k] + u * c.radii[k + 1], 1e-6f) << x;
        const Vec3 n = c.normals[k] * (1 - u) + c.normals[k + 1] * u;
        EXPECT_NEAR(length(sp.curve_normal - n), 0.0f, 1e-6f) << x;
        float catmull_rom = 0;
        scene.curve_point(hit->prim, u, nullptr, &catmull_rom);
        if (k == 1 && u > 0.2f && u < 0.8f) {
            EXPECT_GT(std::fabs(catmull_rom - sp.curve_radius), 1e-3f) << "the radius is not Catmull-Rom's";
        }
    }
    // Without normals the attribute reads zero.
    const Scene bare = build_ok(one_hair(hair_material()));
    const auto hit = bare.intersect({0.3f, 0, 5}, {0, 0, -1}, 0.0f, INFINITY);
    ASSERT_TRUE(hit.has_value());
    const SurfacePoint sp = bare.surface_point({0.3f, 0, 5}, {0, 0, -1}, *hit);
    EXPECT_EQ(length(sp.curve_normal), 0.0f);
    EXPECT_NEAR(sp.curve_radius, 0.1f, 1e-7f);
}

TEST(Scene, TrianglesAndSkips) {
    SceneDesc d;
    d.materials = {DiffuseMaterial{Rgb(0.5f), Rgb(0.0f)}, DiffuseMaterial{Rgb(0.0f), Rgb(2.0f)}};
    d.meshes = {quad(0.0f, 0), quad(2.0f, 1)};
    d.camera = small_camera();
    const Scene scene = build_ok(std::move(d));
    EXPECT_EQ(scene.stats().triangles, 4u);
    EXPECT_EQ(scene.stats().emissive_triangles, 2u);
    EXPECT_EQ(scene.lights().emissive_triangle_count(), 2);

    const auto hit = scene.intersect({0.2f, 0.3f, 1}, {0, 0, -1}, 0.0f, INFINITY);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->t, 1.0f, 1e-5f);
    const SurfacePoint sp = scene.surface_point({0.2f, 0.3f, 1}, {0, 0, -1}, *hit);
    EXPECT_FALSE(sp.is_curve);
    EXPECT_FALSE(sp.is_light);
    EXPECT_EQ(sp.material, 0u);
    EXPECT_NEAR(std::fabs(sp.normal.z), 1.0f, 1e-6f);
    // The emitter above.
    const auto up = scene.intersect({0.2f, 0.3f, 1}, {0, 0, 1}, 0.0f, INFINITY);
    ASSERT_TRUE(up.has_value());
    EXPECT_TRUE(scene.surface_point({0.2f, 0.3f, 1}, {0, 0, 1}, *up).is_light);
    // Skipping the primitive a ray starts on.
    EXPECT_FALSE(scene.intersect({0.2f, 0.3f, 0}, {0, 0, -1}, 0.0f, INFINITY, hit->prim));
    EXPECT_TRUE(scene.occluded({0.2f, 0.3f, 1}, {0, 0, 1}, 0.0f, 5.0f));
    EXPECT_FALSE(scene.occluded({0.2f, 0.3f, 1}, {0, 0, 1}, 0.0f, 5.0f, up->prim));
}

TEST(Scene, CornerNormalsAndUvsAreInterpolatedAtTheHit) {
    // One triangle in z = 0 with (0, 0), (2, 0), (0, 2); corner normals tilted three ways.
    TriangleMesh m;
    m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
    m.indices = {0, 1, 2};
    m.normals = {safe_normalize(Vec3{0.3f, 0, 1}), safe_normalize(Vec3{0, 0.4f, 1}), Vec3{0, 0, 2}};
    m.uvs = {0.1f, 0.2f, 0.9f, 0.2f, 0.1f, 0.7f};
    SceneDesc d;
    d.materials = {DiffuseMaterial{}};
    d.meshes = {m};
    d.camera = small_camera();
    const Scene scene = build_ok(std::move(d));
    // At (0.5, 0.3): barycentrics (1 − 0.25 − 0.15, 0.25, 0.15) of the three corners.
    const auto hit = scene.intersect({0.5f, 0.3f, 1}, {0, 0, -1}, 0.0f, INFINITY);
    ASSERT_TRUE(hit.has_value());
    const SurfacePoint sp = scene.surface_point({0.5f, 0.3f, 1}, {0, 0, -1}, *hit);
    const float w0 = 0.6f, w1 = 0.25f, w2 = 0.15f;
    const Vec3 n = safe_normalize(safe_normalize(Vec3{0.3f, 0, 1}) * w0 + safe_normalize(Vec3{0, 0.4f, 1}) * w1 +
                                  Vec3{0, 0, 1} * w2);
    EXPECT_NEAR(sp.shading_normal.x, n.x, 1e-5f);
    EXPECT_NEAR(sp.shading_normal.y, n.y, 1e-5f);
    EXPECT_NEAR(sp.shading_normal.z, n.z, 1e-5f);
    EXPECT_NEAR(sp.u, 0.1f * w0 + 0.9f * w1 + 0.1f * w2, 1e-5f);
    EXPECT_NEAR(sp.v, 0.2f * w0 + 0.2f * w1 + 0.7f * w2, 1e-5f);
    // The face normal stays the geometric normal.
    EXPECT_NEAR(std::fabs(sp.normal.z), 1.0f, 1e-6f);

    // Without corner data: the face normal and UV (0, 0).
    SceneDesc flat;
    flat.materials = {DiffuseMaterial{}};
    flat.meshes = {quad(0.0f, 0)};
    flat.camera = small_camera();
    const Scene plain = build_ok(std::move(flat));
    const auto h2 = plain.intersect({0.2f, 0.3f, 1}, {0, 0, -1}, 0.0f, INFINITY);
    ASSERT_TRUE(h2.has_value());
    const SurfacePoint p2 = plain.surface_point({0.2f, 0.3f, 1}, {0, 0, -1}, *h2);
    EXPECT_EQ(p2.shading_normal.z, p2.normal.z);
    EXPECT_EQ(p2.u, 0.0f);
    EXPECT_EQ(p2.v, 0.0f);
}

TEST(Scene, CornerDataIsCheckedPerCorner) {
    auto mesh = [] {
        TriangleMesh m;
        m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
        m.indices = {0, 1, 2};
        return m;
    };
    auto error = [&](TriangleMesh m) {
        SceneDesc d;
        d.materials = {DiffuseMaterial{}};
        d.meshes = {std::move(m)};
        d.camera = small_camera();
        return build_error(std::move(d));
    };
    TriangleMesh m = mesh();
    m.normals = {Vec3{0, 0, 1}, Vec3{0, 0, 1}};
    EXPECT_NE(error(m).find("normals has 2 entries; it needs one per triangle corner (3)"), std::string::npos) << error(m);
    m = mesh();
    m.uvs = {0, 0, 1, 0};
    EXPECT_NE(error(m).find("uvs has 4 floats"), std::string::npos) << error(m);
    m = mesh();
    m.normals = {Vec3{0, 0, 1}, Vec3{0, 0, 0}, Vec3{0, 0, 1}};
    EXPECT_NE(error(m).find("corner 1: normal must be finite and not zero"), std::string::npos) << error(m);
    m = mesh();
    m.uvs = {0, 0, 1, NAN, 0, 1};
    EXPECT_NE(error(m).find("corner 1: uv must be finite"), std::string::npos) << error(m);
}

TEST(Scene, RaysEmbreeCannotTraceAreMissesAndBlockedShadows) {
    // Embree asserts (and aborts) on origins or directions beyond ±1.8e18 and NaN t; such
    // rays come from finite but huge inputs (fuzz_capi_params found a camera at ~1e30).
    SceneDesc d;
    d.materials = {DiffuseMaterial{Rgb(0.5f), Rgb(0.0f)}};
    d.meshes = {quad(0.0f, 0)};
    d.camera = small_camera();
    const Scene scene = build_ok(std::move(d));
    EXPECT_FALSE(scene.intersect({0.2f, 0.3f, 1e30f}, {0, 0, -1}, 0.0f, INFINITY));
    EXPECT_FALSE(scene.intersect({0.2f, 0.3f, 1}, {0, 0, -1e30f}, 0.0f, INFINITY));
    EXPECT_FALSE(scene.intersect({0.2f, 0.3f, 1}, {0, NAN, -1}, 0.0f, INFINITY));
    EXPECT_FALSE(scene.intersect({0.2f, 0.3f, 1}, {0, 0, -1}, NAN, INFINITY));
    EXPECT_TRUE(scene.occluded({0.2f, 0.3f, -1e30f}, {0, 0, 1}, 0.0f, 5.0f));
    // Large but traceable rays are traced as before.
    EXPECT_TRUE(scene.intersect({0.2f, 0.3f, 1e6f}, {0, 0, -1}, 0.0f, INFINITY));
}

TEST(Scene, DegenerateCurvesAreSkippedWithAWarning) {
    SceneDesc d;
    d.materials = {hair_material()};
    HairCurves c = straight_hair();
    // A second curve whose points all coincide, and a third of zero radius.
    c.points.insert(c.points.end(), {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {0, 0, 1}, {1, 0, 1}});
    c.radii.insert(c.radii.end(), {0.1f, 0.1f, 0.1f, 0.0f, 0.0f});
    c.first = {0, 4, 7, 9};
    d.curves = {c};
    d.camera = small_camera();
    const Scene scene = build_ok(std::move(d));
    EXPECT_EQ(scene.stats().curves, 1u);
    EXPECT_EQ(scene.stats().skipped_curves, 2u);
    ASSERT_EQ(scene.stats().warnings.size(), 2u);
    EXPECT_NE(scene.stats().warnings[0].find("zero length"), std::string::npos);
    EXPECT_NE(scene.stats().warnings[1].find("zero radius"), std::string::npos);
}

TEST(Scene, ASceneWithoutGeometryIsLegalAndEveryRayMisses) {
    // As in Cycles, which renders the world: no geometry at all, and only skipped curves.
    SceneDesc none;
    none.materials = {hair_material()};
    none.camera = small_camera();
    const Scene empty = build_ok(std::move(none));
    EXPECT_EQ(empty.stats().curves + empty.stats().triangles, 0u);
    EXPECT_TRUE(empty.stats().warnings.empty());

    SceneDesc skipped;
    skipped.materials = {hair_material()};
    HairCurves c = straight_hair();
    c.radii.assign(c.radii.size(), 0.0f);  // zero radius: never hit
    c.points.insert(c.points.end(), {{1, 1, 1}, {1, 1, 1}});  // zero length
    c.radii.insert(c.radii.end(), {0.1f, 0.1f});
    c.first.push_back(std::uint32_t(c.points.size()));
    skipped.curves = {c};
    skipped.camera = small_camera();
    const Scene degenerate = build_ok(std::move(skipped));
    EXPECT_EQ(degenerate.stats().curves, 0u);
    EXPECT_EQ(degenerate.stats().skipped_curves, 2u);
    EXPECT_EQ(degenerate.stats().warnings.size(), 2u);

    // Rays through where the strands were miss (the same rays hit the strand with its radius).
    SceneDesc hair;
    hair.materials = {hair_material()};
    hair.curves = {straight_hair()};
    hair.camera = small_camera();
    const Scene control = build_ok(std::move(hair));
    EXPECT_TRUE(control.intersect({0, 0, 2}, {0, 0, -1}, 0.0f, INFINITY));
    EXPECT_TRUE(control.occluded({0, 0, 2}, {0, 0, -1}, 0.0f, 10.0f));
    for (const Scene *scene : {&empty, &degenerate}) {
        for (float x : {-0.5f, 0.0f, 0.5f}) {
            EXPECT_FALSE(scene->intersect({x, 0, 2}, {0, 0, -1}, 0.0f, INFINITY));
            EXPECT_FALSE(scene->occluded({x, 0, 2}, {0, 0, -1}, 0.0f, 10.0f));
        }
        EXPECT_FALSE(scene->intersect({1, 1, 2}, {0, 0, -1}, 0.0f, INFINITY));
    }
}

TEST(Scene, InvalidScenesGiveClearErrors) {
    auto base = [] {
        SceneDesc d;
        d.materials = {hair_material(), DiffuseMaterial{}};
        d.curves = {straight_hair()};
        d.camera = small_camera();
        return d;
    };
    ASSERT_TRUE(Scene::build(base()).ok());

    SceneDesc d = base();
    d.curves[0].points[2].y = NAN;
    std::string e = build_error(std::move(d));
    EXPECT_NE(e.find("curve set 0, curve 0, point 2"), std::string::npos) << e;
    EXPECT_NE(e.find("finite"), std::string::npos) << e;

    d = base();
    d.curves[0].points.push_back({2, 0, 0});
    d.curves[0].radii.push_back(0.1f);
    d.curves[0].first = {0, 4, 5};  // a second curve with one point
    e = build_error(std::move(d));
    EXPECT_NE(e.find("curve 1"), std::string::npos) << e;
    EXPECT_NE(e.find("at least 2"), std::string::npos) << e;

    d = base();
    d.curves[0].radii[1] = -0.1f;
    e = build_error(std::move(d));
    EXPECT_NE(e.find("radius"), std::string::npos) << e;

    d = base();
    d.curves[0].radii.pop_back();
    e = build_error(std::move(d));
    EXPECT_NE(e.find("one radius per point"), std::string::npos) << e;

    d = base();
    d.curves[0].normals = {{0, 0, 1}, {0, 0, 1}};
    e = build_error(std::move(d));
    EXPECT_NE(e.find("one normal per point"), std::string::npos) << e;

    d = base();
    d.curves[0].normals.assign(4, Vec3{0, 0, 1});
    d.curves[0].normals[3].z = INFINITY;
    e = build_error(std::move(d));
    EXPECT_NE(e.find("curve set 0, point 3: normal must be finite"), std::string::npos) << e;

    d = base();
    d.curves[0].material = 7;
    e = build_error(std::move(d));
    EXPECT_NE(e.find("out of range"), std::string::npos) << e;

    d = base();
    d.meshes = {quad(0.0f, 0)};
    e = build_error(std::move(d));
    EXPECT_NE(e.find("meshes need a surface material"), std::string::npos) << e;

    d = base();
    d.meshes = {quad(0.0f, 1)};
    d.meshes[0].indices[4] = 9;
    e = build_error(std::move(d));
    EXPECT_NE(e.find("vertex index out of range"), std::string::npos) << e;

    d = base();
    d.materials[0] = HairMaterial{HairShading::create(nullptr, std::make_shared<const UniformSampler>()).value()};
    e = build_error(std::move(d));
    EXPECT_NE(e.find("hair material has no fiber"), std::string::npos) << e;

    d = base();
    d.point_lights = {{Vec3{0, 0, 0}, Rgb(1.0f), NAN, 0.0f}};
    e = build_error(std::move(d));
    EXPECT_NE(e.find("point light 0: power"), std::string::npos) << e;

    d = base();
    d.camera.width = 0;
    e = build_error(std::move(d));
    EXPECT_NE(e.find("camera: width"), std::string::npos) << e;
}

// A hair material whose inputs vary per strand (Melanin Concentration).
HairMaterial strands_material() {
    PrincipledHairNode node;
    node.parametrization = HairParametrization::Melanin;
    auto strands = std::make_shared<const ChiangStrands>(ChiangStrands::create(node).value());
    return HairMaterial{HairShading::create(strands, std::make_shared<const UniformSampler>()).value()};
}

// Melanin linear in x along curves of evenly spaced points (x = −2.5 .. 2.5).
float melanin_at(float x) { return 0.5f + 0.15f * x; }

// Two parallel hairs along X (y = 0 and y = 3) of 6 evenly spaced points each, melanin per
// point melanin_at(x), roughness per curve 0.2 and 0.7.
HairCurves hairs_with_inputs() {
    HairCurves c;
    for (float y : {0.0f, 3.0f})
        for (int k = 0; k < 6; ++k) {
            c.points.push_back({-2.5f + float(k), y, 0});
            c.radii.push_back(0.1f);
        }
    c.first = {0, 6, 12};
    CurveInput melanin{HairInput::Melanin, true, {}};
    for (const Vec3 &p : c.points) melanin.values.push_back(melanin_at(p.x));
    c.inputs = {melanin, CurveInput{HairInput::Roughness, false, {0.2f, 0.7f}}};
    return c;
}

// The inputs where a ray straight down at (x, y) meets the curves.
HairInputValues inputs_at(const Scene &scene, float x, float y) {
    const Vec3 origin{x, y, 5}, dir{0, 0, -1};
    const auto hit = scene.intersect(origin, dir, 0.0f, INFINITY);
    EXPECT_TRUE(hit.has_value()) << x << ", " << y;
    HairInputValues v;
    if (!hit) return v;
    EXPECT_TRUE(scene.hair_inputs(scene.surface_point(origin, dir, *hit), v));
    return v;
}

TEST(Scene, PointInputsInterpolateAlongTheCurveAndCurveInputsAreTheCurves) {
    SceneDesc d;
    d.materials = {strands_material()};
    d.curves = {hairs_with_inputs()};
    d.camera = small_camera();
    const Scene scene = build_ok(std::move(d));
    // Inner segments of evenly spaced collinear points: the Catmull-Rom centre line is linear in
    // u, so the hit's interpolated melanin is the linear function itself at the hit's x.
    for (float y : {0.0f, 3.0f})
        for (float x : {-1.37f, -0.5f, -0.02f, 0.61f, 1.0f, 1.44f}) {
            const HairInputValues v = inputs_at(scene, x, y);
            ASSERT_TRUE(v.has(HairInput::Melanin));
            EXPECT_NEAR(*v.get(HairInput::Melanin), melanin_at(x), 2e-5f) << x << ", " << y;
            ASSERT_TRUE(v.has(HairInput::Roughness));
            EXPECT_EQ(*v.get(HairInput::Roughness), y == 0.0f ? 0.2f : 0.7f);
            EXPECT_FALSE(v.has(HairInput::Coat));
        }
    // End segments (the end point doubled): between the two points' values.
    for (float x : {-2.3f, 2.2f}) {
        const float m = *inputs_at(scene, x, 0.0f).get(HairInput::Melanin);
        const float a = melanin_at(x < 0 ? -2.5f : 1.5f), b = melanin_at(x < 0 ? -1.5f : 2.5f);
        EXPECT_GE(m, a) << x;
        EXPECT_LE(m, b) << x;
    }
    // Triangles and curves without inputs have none.
    const Scene without = build_ok(one_hair(strands_material()));
    const auto hit = without.intersect({0.3f, 0, 5}, {0, 0, -1}, 0.0f, INFINITY);
    ASSERT_TRUE(hit.has_value());
    HairInputValues none;
    EXPECT_FALSE(without.hair_inputs(without.surface_point({0.3f, 0, 5}, {0, 0, -1}, *hit), none));
}

TEST(Scene, InputsOfSkippedCurvesAreLeftOut) {
    SceneDesc d;
    d.materials = {strands_material()};
    HairCurves c = hairs_with_inputs();
    // A zero-length curve between the two: its values must not shift the second curve's.
    c.points.insert(c.points.begin() + 6, {{9, 9, 9}, {9, 9, 9}});
    c.radii.insert(c.radii.begin() + 6, {0.1f, 0.1f});
    c.first = {0, 6, 8, 14};
    c.inputs[0].values.insert(c.inputs[0].values.begin() + 6, {0.99f, 0.99f});
    c.inputs[1].values = {0.2f, 0.99f, 0.7f};
    d.curves = {c};
    d.camera = small_camera();
    const Scene scene = build_ok(std::move(d));
    EXPECT_EQ(scene.stats().skipped_curves, 1u);
    const HairInputValues v = inputs_at(scene, 0.61f, 3.0f);
    EXPECT_NEAR(*v.get(HairInput::Melanin), melanin_at(0.61f), 2e-5f);
    EXPECT_EQ(*v.get(HairInput::Roughness), 0.7f);
}

TEST(Scene, InvalidCurveInputsAreRefusedByName) {
    auto error_of = [](auto change, HairMaterial material) {
        SceneDesc d;
        d.materials = {std::move(material)};
        HairCurves c = hairs_with_inputs();
        change(c);
        d.curves = {c};
        d.camera = small_camera();
        return build_error(std::move(d));
    };
    std::string e = error_of([](HairCurves &c) { c.inputs[1].values.push_back(0.5f); }, strands_material());
    EXPECT_NE(e.find("curve set 0, input roughness: has 3 values; 2 curves of 1 need 2"), std::string::npos) << e;
    e = error_of([](HairCurves &c) { c.inputs[0].values[7] = 1.5f; }, strands_material());
    EXPECT_NE(e.find("curve set 0, point 7: melanin must be in [0, 1] (got 1.5)"), std::string::npos) << e;
    e = error_of([](HairCurves &c) { c.inputs[1].values[1] = NAN; }, strands_material());
    EXPECT_NE(e.find("curve set 0, curve 1: roughness must be in [0, 1] (got nan)"), std::string::npos) << e;
    e = error_of([](HairCurves &c) { c.inputs.push_back(c.inputs[1]); }, strands_material());
    EXPECT_NE(e.find("input roughness: given twice"), std::string::npos) << e;
    e = error_of([](HairCurves &c) { c.inputs.push_back({HairInput::Color, false, {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f}}); },
                 strands_material());
    EXPECT_NE(e.find("input color: the material's parametrization does not read it"), std::string::npos) << e;
    e = error_of([](HairCurves &) {}, hair_material());
    EXPECT_NE(e.find("curve set 0: has curve inputs, but its material 0 does not vary per strand"), std::string::npos)
        << e;
    e = error_of([](HairCurves &) {}, hair_material());
    SceneDesc d;
    d.materials = {DiffuseMaterial{}};
    d.curves = {hairs_with_inputs()};
    d.camera = small_camera();
    e = build_error(std::move(d));
    EXPECT_NE(e.find("does not vary per strand"), std::string::npos) << e;
}

// A hair along X over a quad at z = −1 whose material 1 glows, seen from above.
SceneDesc hair_over_glowing_quad() {
    SceneDesc d;
    d.materials = {hair_material(), DiffuseMaterial{Rgb(0.5f), Rgb(2.0f)}};
    d.curves = {straight_hair()};
    d.meshes = {quad(-1.0f, 1)};
    d.camera = small_camera();
    return d;
}

TEST(Scene, SetShadingReplacesMaterialsAndLightsAndKeepsTheGeometry) {
    Scene scene = build_ok(hair_over_glowing_quad());
    EXPECT_EQ(scene.stats().emissive_triangles, 2u);
    const auto quad_hit = scene.intersect({0.5f, 0.5f, 5}, {0, 0, -1}, 0.0f, 100.0f);
    ASSERT_TRUE(quad_hit);
    EXPECT_TRUE(scene.surface_point({0.5f, 0.5f, 5}, {0, 0, -1}, *quad_hit).is_light);

    SceneDesc shading;
    shading.materials = {hair_material(), DiffuseMaterial{Rgb(0.25f), Rgb(0.0f)}};
    shading.suns = {SunLight{}};
    shading.curves = {straight_hair(), straight_hair()};  // geometry is not read
    ASSERT_FALSE(scene.set_shading(std::move(shading)));
    EXPECT_EQ(scene.stats().emissive_triangles, 0u);
    EXPECT_EQ(scene.stats().lamps, 1u);
    EXPECT_EQ(std::get<DiffuseMaterial>(scene.materials()[1]).albedo.r, 0.25f);
    EXPECT_EQ(scene.stats().curves, 1u);
    EXPECT_EQ(scene.stats().triangles, 2u);
    const auto again = scene.intersect({0.5f, 0.5f, 5}, {0, 0, -1}, 0.0f, 100.0f);
    ASSERT_TRUE(again);
    EXPECT_EQ(again->t, quad_hit->t);
    EXPECT_FALSE(scene.surface_point({0.5f, 0.5f, 5}, {0, 0, -1}, *again).is_light);
    const auto hair_hit = scene.intersect({0.3f, 0, 5}, {0, 0, -1}, 0.0f, 100.0f);
    ASSERT_TRUE(hair_hit);
    EXPECT_NEAR(hair_hit->t, 4.9f, 1e-3f);
}

TEST(Scene, SetShadingRefusesMaterialsTheGeometryCannotUseAndKeepsItsOwn) {
    Scene scene = build_ok(hair_over_glowing_quad());
    auto refusal = [&](std::vector<Material> materials) {
        SceneDesc shading;
        shading.materials = std::move(materials);
        const Status s = scene.set_shading(std::move(shading));
        return s ? s->message : std::string("accepted");
    };
    std::string e = refusal({hair_material()});
    EXPECT_NE(e.find("mesh 0: material index 1 is out of range (the scene has 1 materials)"), std::string::npos) << e;
    e = refusal({hair_material(), hair_material()});
    EXPECT_NE(e.find("mesh 0: material 1 is a hair material; meshes need a surface material"), std::string::npos) << e;
    e = refusal({hair_material(), DiffuseMaterial{Rgb(1.5f), Rgb(0.0f)}});
    EXPECT_NE(e.find("material 1: albedo"), std::string::npos) << e;
    SceneDesc bad_light;
    bad_light.materials = {hair_material(), DiffuseMaterial{}};
    bad_light.suns = {SunLight{Vec3{0, 0, 0}}};
    EXPECT_TRUE(scene.set_shading(std::move(bad_light)));
    // Nothing changed: the quad still glows with its own material.
    EXPECT_EQ(scene.stats().emissive_triangles, 2u);
    EXPECT_EQ(std::get<DiffuseMaterial>(scene.materials()[1]).emission.r, 2.0f);

    SceneDesc with_inputs;
    with_inputs.materials = {strands_material()};
    with_inputs.curves = {hairs_with_inputs()};
    with_inputs.camera = small_camera();
    Scene strands = build_ok(std::move(with_inputs));
    SceneDesc plain;
    plain.materials = {hair_material()};
    const Status s = strands.set_shading(std::move(plain));
    ASSERT_TRUE(s);
    EXPECT_NE(s->message.find("curve set 0: has curve inputs, but its material 0 does not vary per strand"),
              std::string::npos) << s->message;
}

// Curves (by default straight_hair, a straight hair along +X) as a scene of the given shape.
Scene curve_scene(CurveShape shape, HairCurves curves = straight_hair(),
                  CurveBackfaces backfaces = CurveBackfaces::Ignore) {
    SceneDesc d = one_hair(hair_material(), std::move(curves));
    d.curve_shape = shape;
    d.curve_backfaces = backfaces;
    return build_ok(std::move(d));
}

// Rays aimed at (0.3, 0, 0) + s·r·Y, Y = normalize(X × ω_o) the direction across the strand
// as seen from ω_o, from several directions (some along the tangent, some against it): a ribbon
// is the strip through the axis that faces the ray, so each hits at the distance of that point,
// with Ng = ω_o, v = s, and Cycles' rounded normal s·Y + sqrt(1 − s²)·(ω_o across the strand).
TEST(Scene, RibbonsFaceEveryRayWithCyclesRoundedNormal) {
    const Scene ribbons = curve_scene(CurveShape::Ribbons);
    const Vec3 tangent{1, 0, 0};
    const float r = 0.1f, L = 3.0f;
    for (const Vec3 d : {Vec3{0, 0, -1}, Vec3{0, -1, 0}, Vec3{0, 0.6f, 0.8f}, Vec3{0.4f, -0.6f, -0.7f},
                         Vec3{-0.5f, 0.3f, 0.6f}, Vec3{0.7f, 0.7f, 0.1f}}) {
        const Vec3 dir = safe_normalize(d), wo = -dir;
        const Vec3 across = safe_normalize(cross(tangent, wo));
        const Vec3 facing = safe_normalize(wo - tangent * dot(wo, tangent));
        for (float s : {-0.8f, -0.3f, 0.0f, 0.5f, 0.9f}) {
            const Vec3 target = Vec3{0.3f, 0, 0} + across * (s * r);
            const Vec3 origin = target - dir * L;
            const auto hit = ribbons.intersect(origin, dir, 0.0f, INFINITY);
            ASSERT_TRUE(hit.has_value()) << d.x << "," << d.y << "," << d.z << " s=" << s;
            EXPECT_NEAR(hit->t, L, 1e-4f);
            const SurfacePoint sp = ribbons.surface_point(origin, dir, *hit);
            EXPECT_TRUE(sp.is_curve && sp.is_ribbon);
            EXPECT_NEAR(length(sp.normal - wo), 0.0f, 1e-6f);
            EXPECT_NEAR(sp.curve_v, s, 1e-4f);
            EXPECT_NEAR(length(sp.tangent - tangent), 0.0f, 1e-5f);
            const Vec3 rounded = across * s + facing * std::sqrt(1.0f - s * s);
            EXPECT_NEAR(length(sp.shading_normal - rounded), 0.0f, 1e-4f) << s;
            EXPECT_EQ(sp.self.primitive, 0u);
        }
        // Beside the strip: a miss; a shadow ray is blocked by the strip, whichever its side.
        EXPECT_FALSE(ribbons.intersect(Vec3{0.3f, 0, 0} + across * (1.2f * r) - dir * L, dir, 0.0f, INFINITY));
        EXPECT_TRUE(ribbons.occluded(Vec3{0.3f, 0, 0} - dir * L, dir, 0.0f, 2 * L));
    }

    SceneDesc bad;
    bad.materials = {hair_material()};
    bad.curves = {straight_hair()};
    bad.camera = small_camera();
    bad.curve_shape = CurveShape(5);
    const std::string e = build_error(std::move(bad));
    EXPECT_NE(e.find("curve_shape must be thick (0), ribbons (1) or thick_linear (2) (got 5)"), std::string::npos)
        << e;
}

// Embree's build quality changes the BVH, never what a ray hits: a tangle of bent strands built
// at each quality gives every ray the same closest hit, bit for bit, and the same occlusion.
TEST(Scene, EveryBvhQualityGivesTheSameHits) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    HairCurves c;
    c.first = {0};
    for (int strand = 0; strand < 300; ++strand) {
        Vec3 p{u(rng), u(rng), u(rng)};
        for (int k = 0; k < 6; ++k) {
            c.points.push_back(p);
            c.radii.push_back(0.01f + 0.01f * std::fabs(u(rng)));
            p = p + Vec3{0.3f, 0.1f * u(rng), 0.1f * u(rng)};
        }
        c.first.push_back(std::uint32_t(c.points.size()));
    }
    std::vector<Scene> scenes;
    for (BvhQuality quality : {BvhQuality::Low, BvhQuality::Medium, BvhQuality::High}) {
        SceneDesc d;
        d.materials = {hair_material()};
        d.curves = {c};
        d.camera = small_camera();
        d.bvh_quality = quality;
        scenes.push_back(build_ok(std::move(d)));
    }
    int hits = 0;
    for (int ray = 0; ray < 4000; ++ray) {
        const Vec3 from{u(rng) - 3.0f, 1.5f * u(rng), 1.5f * u(rng)};
        const Vec3 dir = safe_normalize(Vec3{1.0f, 0.3f * u(rng), 0.3f * u(rng)});
        const std::optional<Hit> medium = scenes[1].intersect(from, dir, 0.0f, INFINITY);
        hits += medium.has_value();
        for (std::size_t q : {0u, 2u}) {
            const std::optional<Hit> other = scenes[q].intersect(from, dir, 0.0f, INFINITY);
            ASSERT_EQ(other.has_value(), medium.has_value()) << "ray " << ray << ", quality " << q;
            if (medium) {
                EXPECT_EQ(other->t, medium->t) << "ray " << ray << ", quality " << q;
                EXPECT_EQ(other->prim.primitive, medium->prim.primitive) << "ray " << ray;
                EXPECT_EQ(other->u, medium->u) << "ray " << ray << ", quality " << q;
            }
            EXPECT_EQ(scenes[q].occluded(from, dir, 0.0f, 4.0f), scenes[1].occluded(from, dir, 0.0f, 4.0f))
                << "ray " << ray << ", quality " << q;
        }
    }
    EXPECT_GT(hits, 400);  // the rays meet the tangle often enough to compare

    SceneDesc bad;
    bad.materials = {hair_material()};
    bad.curves = {straight_hair()};
    bad.camera = small_camera();
    bad.bvh_quality = BvhQuality(3);
    const std::string e = build_error(std::move(bad));
    EXPECT_NE(e.find("bvh_quality must be low (0), medium (1) or high (2) (got 3)"), std::string::npos) << e;
}

// Cycles' Curves > Subdivisions sets Embree's tessellation rate: the default (2) is what a
// scene without the setting gets, and another value changes where rays meet bent ribbons
// (Embree intersects flat curves as that many pieces per segment); out of Blender's range it
// is refused.
TEST(Scene, CurveSubdivisionsSetEmbreesTessellation) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    HairCurves c;
    c.first = {0};
    for (int strand = 0; strand < 200; ++strand) {
        Vec3 p{u(rng), u(rng), u(rng)};
        for (int k = 0; k < 5; ++k) {
            c.points.push_back(p);
            c.radii.push_back(0.03f);
            p = p + Vec3{0.3f, 0.4f * u(rng), 0.4f * u(rng)};  // strongly bent
        }
        c.first.push_back(std::uint32_t(c.points.size()));
    }
    auto scene_with = [&](std::optional<int> subdivisions) {
        SceneDesc d;
        d.materials = {hair_material()};
        d.curves = {c};
        d.camera = small_camera();
        d.curve_shape = CurveShape::Ribbons;
        if (subdivisions) d.curve_subdivisions = *subdivisions;
        return build_ok(std::move(d));
    };
    const Scene by_default = scene_with(std::nullopt), two = scene_with(2), coarse = scene_with(0),
                fine = scene_with(4);
    int hits = 0, differ = 0;
    for (int ray = 0; ray < 4000; ++ray) {
        const Vec3 from{u(rng) - 3.0f, 1.5f * u(rng), 1.5f * u(rng)};
        const Vec3 dir = safe_normalize(Vec3{1.0f, 0.3f * u(rng), 0.3f * u(rng)});
        const std::optional<Hit> a = by_default.intersect(from, dir, 0.0f, INFINITY);
        const std::optional<Hit> b = two.intersect(from, dir, 0.0f, INFINITY);
        ASSERT_EQ(a.has_value(), b.has_value());
        if (a) {
            EXPECT_EQ(a->t, b->t);
        }
        hits += a.has_value();
        const std::optional<Hit> p = coarse.intersect(from, dir, 0.0f, INFINITY);
        const std::optional<Hit> q = fine.intersect(from, dir, 0.0f, INFINITY);
        if (p.has_value() != q.has_value() || (p && q && p->t != q->t)) ++differ;
    }
    EXPECT_GT(hits, 400);
    EXPECT_GT(differ, 0);

    SceneDesc bad;
    bad.materials = {hair_material()};
    bad.curves = {straight_hair()};
    bad.camera = small_camera();
    bad.curve_subdivisions = 25;
    const std::string e = build_error(std::move(bad));
    EXPECT_NE(e.find("curve_subdivisions must be in [0, 24] (got 25)"), std::string::npos) << e;
}

// Linear 3D curves: segment k is the straight round cone from point k to point k + 1; a
// Catmull-Rom curve through the same points bends away from it.
TEST(Scene, LinearCurvesRunStraightBetweenTheirPoints) {
    HairCurves c;
    c.points = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 2, 0}, {0, 3, 0}, {1, 3, 0}};
    c.radii.assign(6, 0.05f);
    c.first = {0, 4, 6};
    const Scene linear = curve_scene(CurveShape::ThickLinear, c), thick = curve_scene(CurveShape::Thick, c);
    const Vec3 points[4] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 2, 0}};
    for (std::uint32_t k = 0; k < 3; ++k)
        for (float u : {0.0f, 0.3f, 0.5f, 1.0f}) {
            Vec3 derivative;
            const Vec3 p = linear.curve_point({0, k}, u, &derivative);
            EXPECT_NEAR(length(p - (points[k] * (1 - u) + points[k + 1] * u)), 0.0f, 1e-6f);
            EXPECT_NEAR(length(derivative - (points[k + 1] - points[k])), 0.0f, 1e-6f);
        }
    // Straight down onto the middle of each segment: the top of the cone, r above the line.
    const Vec3 down{0, 0, -1};
    for (std::uint32_t k = 0; k < 3; ++k) {
        const Vec3 mid = (points[k] + points[k + 1]) * 0.5f;
        const Vec3 origin = mid + Vec3{0, 0, 5};
        const auto hit = linear.intersect(origin, down, 0.0f, INFINITY);
        ASSERT_TRUE(hit.has_value()) << k;
        EXPECT_NEAR(hit->t, 5.0f - 0.05f, 1e-4f);
        EXPECT_EQ(hit->prim.primitive, k);
        const SurfacePoint sp = linear.surface_point(origin, down, *hit);
        EXPECT_NEAR(length(sp.normal - Vec3{0, 0, 1}), 0.0f, 1e-3f);
        EXPECT_NEAR(length(sp.tangent - safe_normalize(points[k + 1] - points[k])), 0.0f, 1e-5f);
        EXPECT_FALSE(sp.is_ribbon);
    }
    // Off the line by half the radius across segment 1: the normal tilts by 30°.
    const auto side = linear.intersect({1.5f, 0.025f, 5}, down, 0.0f, INFINITY);
    ASSERT_TRUE(side.has_value());
    EXPECT_NEAR(linear.surface_point({1.5f, 0.025f, 5}, down, *side).normal.y, 0.5f, 1e-3f);
    // The Catmull-Rom curve passes 0.125 below segment 1's middle (y = −2/16): a miss there.
    EXPECT_FALSE(thick.intersect({1.5f, 0, 5}, down, 0.0f, INFINITY).has_value());
    // No segment joins one curve's last point to the next curve's first.
    EXPECT_FALSE(linear.intersect({1.5f, 2.5f, 5}, down, 0.0f, INFINITY).has_value());
    const auto second = linear.intersect({0.5f, 3, 5}, down, 0.0f, INFINITY);
    ASSERT_TRUE(second.has_value());
    EXPECT_EQ(second->prim.primitive, 3u);
    EXPECT_EQ(linear.surface_point({0.5f, 3, 5}, down, *second).self.primitive, 1u);

    // From inside a linear strand a ray passes its wall, where a Catmull-Rom tube is hit from
    // inside under curve_backfaces = hit.
    const Scene linear_hit = curve_scene(CurveShape::ThickLinear, straight_hair(), CurveBackfaces::Hit);
    const Scene tube_hit = curve_scene(CurveShape::Thick, straight_hair(), CurveBackfaces::Hit);
    EXPECT_FALSE(linear_hit.intersect({0.3f, 0, 0}, {0, 0, 1}, 0.0f, INFINITY).has_value());
    EXPECT_FALSE(linear_hit.occluded({0.3f, 0, 0}, {0, 0, 1}, 0.0f, 10.0f));
    EXPECT_TRUE(linear_hit.intersect({0.3f, 0, 5}, down, 0.0f, INFINITY).has_value());
    EXPECT_TRUE(tube_hit.intersect({0.3f, 0, 0}, {0, 0, 1}, 0.0f, INFINITY).has_value());
}

}  // namespace
}  // namespace hairis
