#include "render/bsdf.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/scratch.h"
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
// One straight strand of radius 0.1 along x through the origin, of a Chiang fiber of `params`
// sampled uniformly, traced as `shape`.
Scene one_strand(const ChiangParams &params, CurveShape shape = CurveShape::Thick) {
    auto fiber = std::make_shared<const ChiangFiber>(ChiangFiber::create(params).value());
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
}

TEST(Bsdf, RibbonsAndTubesGiveTheSameOffsetAcrossTheStrand) {
    const ChiangParams params = to_chiang_params(PrincipledHairNode{}).value();
    auto scene_of = [&](CurveShape shape) { return one_strand(params, shape); };
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

// The roughness β in [0.001, 1] whose mapping `map` gives `target` (the mappings rise with β).
double invert_mapping(double (*map)(double), double target) {
    double lo = 0.001, hi = 1.0;
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (map(mid) < target ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// Filter Glossy at a Chiang hit: the BSDF is the fiber whose inputs map to Cycles' widened
// v, s and coat variance (found here by inverting Cycles' mappings), sampled by the analytic
// sampler whatever the material's sampler; a blur below every roughness changes nothing.
TEST(Bsdf, FilterGlossyWidensChiangToTheFiberOfTheWidenedRoughness) {
    PrincipledHairNode node;
    node.coat = 0.4f;
    const ChiangParams own = to_chiang_params(node).value();
    const Scene scene = one_strand(own);
    const Vec3 dir = safe_normalize(Vec3{0.2f, -0.5f, -0.8f}), origin = Vec3{0.1f, 0.03f, 0} - dir * 3.0f;
    const auto hit = scene.intersect(origin, dir, 0.0f, INFINITY);
    ASSERT_TRUE(hit.has_value());
    const SurfacePoint sp = scene.surface_point(origin, dir, *hit);
    const double v = chiang::longitudinal_variance(own.roughness);
    const double v_m0 = chiang::longitudinal_variance((1.0 - own.coat) * own.roughness);
    const double s = chiang::logistic_scale(own.radial_roughness);
    ASSERT_LT(v_m0, v);
    const Vec3 wis[] = {safe_normalize(Vec3{0.3f, 0.2f, 0.9f}), safe_normalize(Vec3{-0.6f, 0.7f, -0.2f}),
                        safe_normalize(Vec3{0.1f, -0.9f, 0.3f}), safe_normalize(Vec3{0.8f, 0.1f, -0.5f})};
    // One blur above all three, one between the coat's variance and the others, one below all.
    for (const double blur : {0.35, 0.5 * (v_m0 + std::min(v, s)), 0.5 * v_m0}) {
        ScratchBuffer scratch;
        HitContext context;
        context.blur_roughness = float(blur);
        const Bsdf bsdf(scene.materials()[sp.material], sp, -dir, context, nullptr, scratch);
        ChiangParams widened = own;
        widened.roughness = float(invert_mapping(chiang::longitudinal_variance, std::max(blur, v)));
        widened.coat = float(1.0 - invert_mapping(chiang::longitudinal_variance, std::max(blur, v_m0)) /
                                       double(widened.roughness));
        widened.radial_roughness = float(invert_mapping(chiang::logistic_scale, std::max(blur, s)));
        const ChiangFiber reference = ChiangFiber::create(widened).value();
        const FiberHit fh = fiber_hit(sp, -dir, bsdf.frame(), HitContext{});
        const ChiangPoint point = reference.at(fh);
        const bool widens = blur > v_m0;
        for (const Vec3 wi : wis) {
            float pdf = 0;
            const Rgb f = bsdf.eval(wi, pdf);
            const Rgb want = point.f(bsdf.frame().to_local(wi));
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(f[ch], want[ch], 2e-4 * std::max(1.0f, want[ch])) << "blur " << blur;
            if (widens)
                EXPECT_NEAR(pdf, point.pdf(bsdf.frame().to_local(wi)), 2e-4 * std::max(1.0f, pdf)) << "blur " << blur;
            else
                EXPECT_NEAR(pdf, 1.0 / (4.0 * kPi), 1e-6) << "the material's own (uniform) sampler";
        }
    }
}

}  // namespace
}  // namespace hairis
