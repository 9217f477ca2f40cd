#include "render/bsdf.h"

#include <gtest/gtest.h>

#include <cmath>

#include "fiber/chiang_strands.h"
#include "fiber/principled_hair.h"
#include "sampling/uniform_sampler.h"

namespace hairis {
namespace {

// The typed accessors the renderer and the bake pick a model's path by (in place of casts).
TEST(Bsdf, ModelsSayWhatTheyAre) {
    PrincipledHairNode node;
    const ChiangFiber chiang = ChiangFiber::create(to_chiang_params(node).value()).value();
    const HuangFiber huang = HuangFiber::create(HuangParams{}).value();
    const ChiangStrands strands = ChiangStrands::create(node).value();

    const FiberModel &chiang_model = chiang, &huang_model = huang;
    const ShadingModel &chiang_shading = chiang, &huang_shading = huang, &strands_shading = strands;
    EXPECT_EQ(chiang_model.as_chiang(), &chiang);
    EXPECT_EQ(chiang_model.as_huang(), nullptr);
    EXPECT_EQ(huang_model.as_huang(), &huang);
    EXPECT_EQ(huang_model.as_chiang(), nullptr);
    EXPECT_EQ(huang_shading.as_huang(), &huang);
    EXPECT_EQ(chiang_shading.as_huang(), nullptr);
    EXPECT_EQ(strands_shading.as_huang(), nullptr);
    EXPECT_EQ(strands_shading.strand_inputs(), static_cast<const StrandInputReader *>(&strands));
    EXPECT_EQ(chiang_shading.strand_inputs(), nullptr);
    EXPECT_EQ(huang_shading.strand_inputs(), nullptr);
}

// Cycles' h at a hit across a strand, seen from ω_o: −s at the point s·r along X × ω_o from
// the axis, for a round tube (from Ng) and a ribbon (h = −v) alike, whatever the direction.
TEST(Bsdf, RibbonsAndTubesGiveTheSameOffsetAcrossTheStrand) {
    auto scene_of = [](CurveShape shape) {
        PrincipledHairNode node;
        auto fiber = std::make_shared<const ChiangFiber>(ChiangFiber::create(to_chiang_params(node).value()).value());
        SceneDesc d;
        d.materials = {HairMaterial{HairShading::create(fiber, std::make_shared<const UniformSampler>()).value()}};
        HairCurves c;
        c.points = {{-1.5f, 0, 0}, {-0.5f, 0, 0}, {0.5f, 0, 0}, {1.5f, 0, 0}};
        c.radii = {0.1f, 0.1f, 0.1f, 0.1f};
        c.first = {0, 4};
        d.curves = {c};
        d.camera.camera_to_world = Mat4::translation({0, 0, 5});
        d.camera.width = d.camera.height = 4;
        d.curve_shape = shape;
        return std::move(Scene::build(std::move(d))).value();
    };
    const Scene ribbons = scene_of(CurveShape::Ribbons), tubes = scene_of(CurveShape::Thick);
    for (const Vec3 d : {Vec3{0, 0, -1}, Vec3{0.4f, -0.6f, -0.7f}, Vec3{-0.5f, 0.3f, 0.6f}}) {
        const Vec3 dir = safe_normalize(d), wo = -dir;
        // The crossing seen from wo: perpendicular to the tangent and to the view.
        const Vec3 across = safe_normalize(cross(Vec3{1, 0, 0}, wo));
        for (float s : {-0.9f, -0.4f, 0.0f, 0.3f, 0.8f}) {
            const Vec3 origin = Vec3{0.3f, 0, 0} + across * (0.1f * s) - dir * 3.0f;
            for (const Scene *scene : {&ribbons, &tubes}) {
                const auto hit = scene->intersect(origin, dir, 0.0f, INFINITY);
                ASSERT_TRUE(hit.has_value());
                const SurfacePoint sp = scene->surface_point(origin, dir, *hit);
                const FiberHit fh = cycles_fiber_hit(sp, wo, false, 0.0f, 0);
                EXPECT_NEAR(fh.h, -s, scene == &ribbons ? 1e-4f : 2e-3f)
                    << (scene == &ribbons ? "ribbons" : "tubes") << " s=" << s;
            }
        }
    }
}

}  // namespace
}  // namespace hairis
