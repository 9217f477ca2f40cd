#include "render/filter_glossy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "fiber/chiang.h"
#include "render/render.h"
#include "sampling/analytic_sampler.h"
#include "scene_fixtures.h"

namespace hairis {
namespace {

TEST(FilterGlossy, BlurRoughnessIsCyclesFormula) {
    EXPECT_EQ(glossy_blur_roughness(0.0f, 0.1f), 0.0f);       // Filter Glossy 0: off
    EXPECT_EQ(glossy_blur_roughness(1.0f, INFINITY), 0.0f);   // before the first bounce
    EXPECT_EQ(glossy_blur_roughness(1.0f, 1.0f), 0.0f);       // density at the filter: none
    EXPECT_EQ(glossy_blur_roughness(0.5f, 0.7f), 0.0f);
    EXPECT_NEAR(glossy_blur_roughness(1.0f, 0.36f), 0.4f, 1e-6f);
    EXPECT_NEAR(glossy_blur_roughness(2.0f, 0.36f), 0.5f * std::sqrt(1.0f - 0.18f), 1e-6f);
    EXPECT_NEAR(glossy_blur_roughness(1.0f, 0.0f), 0.5f, 1e-6f);
}

TEST(FilterGlossy, ClampScalesTheChannelSumToThreeTimesTheLimit) {
    const Rgb c{4.0f, 2.0f, 0.5f};  // sum 6.5
    const Rgb same = clamp_contribution(c, 0.0f);
    EXPECT_EQ(same.r, 4.0f);
    const Rgb kept = clamp_contribution(c, 2.2f);  // limit 6.6 > 6.5
    EXPECT_EQ(kept.g, 2.0f);
    const Rgb cut = clamp_contribution(c, 1.0f);  // limit 3
    EXPECT_NEAR(cut.r + cut.g + cut.b, 3.0f, 1e-6f);
    EXPECT_NEAR(cut.r / cut.b, 8.0f, 1e-5f);  // the colour is kept
}

// A white diffuse floor under a small, strong disk light: next-event estimation and the
// BSDF sample that reaches the light are each one contribution of up to many times the
// limits below.
Scene lit_floor() {
    SceneDesc d;
    d.materials = {DiffuseMaterial{Rgb(0.9f), Rgb(0.0f)}};
    TriangleMesh floor;
    floor.positions = {{-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}};
    floor.indices = {0, 1, 2, 0, 2, 3};
    TriangleMesh wall = floor;  // a second floor above the light, facing down: indirect light
    for (Vec3 &p : wall.positions) p.z = 1.5f;
    wall.indices = {0, 2, 1, 0, 3, 2};
    d.meshes = {floor, wall};
    AreaLight a;
    a.shape = AreaShape::Disk;
    a.size_x = 0.3f;
    a.power = 400.0f;
    a.light_to_world = Mat4::translation({0, 0, 0.6f});
    d.area_lights = {a};
    d.camera = testing::ortho_down(0.5f, 0.5f, 4, 4, {0, 0, 0.5f});
    return std::move(Scene::build(std::move(d))).value();
}

// Clamping Direct limits what one camera sample gets at its first vertex (next-event estimation
// and the emission its BSDF sample reaches: two contributions); Clamping Indirect leaves that
// alone and limits each contribution of the later vertices.
TEST(FilterGlossy, ClampingDirectAndIndirectSplitAtTheFirstBounce) {
    const Scene scene = lit_floor();
    RenderSettings direct_only;
    direct_only.max_bounces = 0;
    RenderSettings deeper;
    deeper.max_bounces = 2;
    deeper.max_diffuse_bounces = 4;
    const float limit = 0.05f;  // 3 × limit in R + G + B
    int above = 0, differs = 0;
    for (std::uint64_t i = 0; i < 2000; ++i) {
        const int x = int(i % 4), y = int(i / 4 % 4);
        RenderSettings clamped = direct_only;
        clamped.clamp_direct = limit;
        const Rgb raw = render_sample(scene, direct_only, x, y, i);
        const Rgb cut = render_sample(scene, clamped, x, y, i);
        if (raw.r + raw.g + raw.b > 6.0f * limit) ++above;
        EXPECT_LE(cut.r + cut.g + cut.b, 2.0f * 3.0f * limit * (1.0f + 1e-5f));
        // Indirect clamping does not touch the first vertex's light.
        RenderSettings indirect = direct_only;
        indirect.clamp_indirect = limit;
        const Rgb same = render_sample(scene, indirect, x, y, i);
        EXPECT_EQ(same.r, raw.r);
        EXPECT_EQ(same.b, raw.b);
        // Deeper paths: the same first vertex plus at most four clamped contributions (two
        // vertices, each next-event estimation and emission reached).
        RenderSettings deep_clamped = deeper;
        deep_clamped.clamp_indirect = limit;
        const Rgb deep = render_sample(scene, deep_clamped, x, y, i);
        const Rgb deep_raw = render_sample(scene, deeper, x, y, i);
        const float extra = (deep.r + deep.g + deep.b) - (raw.r + raw.g + raw.b);
        EXPECT_GE(extra, -1e-4f * (raw.r + raw.g + raw.b));
        EXPECT_LE(extra, 4.0f * 3.0f * limit * (1.0f + 1e-5f) + 1e-4f * (raw.r + raw.g + raw.b));
        if (deep_raw.r != deep.r) ++differs;
    }
    // The limits bind: the test would see a clamp that did nothing.
    EXPECT_GT(above, 100);
    EXPECT_GT(differs, 100);
}

// Filter Glossy widens nothing at the camera's vertex, so a render without bounces is the same
// with it or without; after a diffuse bounce (density below 1) the hair is widened.
TEST(FilterGlossy, WidensHairOnlyAfterABounce) {
    auto fiber = std::make_shared<const ChiangFiber>(ChiangFiber::create(ChiangParams{}).value());
    SceneDesc d;
    d.materials = {HairMaterial{HairShading::create(fiber, std::make_shared<const AnalyticSampler>(fiber)).value()},
                   DiffuseMaterial{Rgb(0.8f), Rgb(0.0f)}};
    HairCurves c;
    for (int k = 0; k < 20; ++k) {
        const float y = -0.5f + 0.05f * float(k);
        const std::uint32_t first = std::uint32_t(c.points.size());
        c.points.insert(c.points.end(), {{-1, y, 0.1f}, {-0.3f, y, 0.1f}, {0.3f, y, 0.1f}, {1, y, 0.1f}});
        c.radii.insert(c.radii.end(), 4, 0.01f);
        c.first.push_back(first);
    }
    c.first.push_back(std::uint32_t(c.points.size()));
    d.curves = {c};
    TriangleMesh floor;
    floor.positions = {{-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}};
    floor.indices = {0, 1, 2, 0, 2, 3};
    floor.materials = {1};
    d.meshes = {floor};
    testing::set_sun(d, safe_normalize(Vec3{0.3f, 0.2f, 1.0f}), 3.0f);
    d.world = {Rgb(0.3f), 1.0f};
    d.camera = testing::ortho_down(0.6f, 0.6f, 8, 8);
    const Scene scene = std::move(Scene::build(std::move(d))).value();
    RenderSettings s;
    s.samples = 8;
    s.max_bounces = 0;
    RenderSettings blurred = s;
    blurred.filter_glossy = 1.0f;
    std::vector<float> a(8 * 8 * 4), b(8 * 8 * 4);
    ASSERT_FALSE(render(scene, s, a.data(), {}, nullptr).has_value());
    ASSERT_FALSE(render(scene, blurred, b.data(), {}, nullptr).has_value());
    EXPECT_EQ(a, b);
    s.max_bounces = blurred.max_bounces = 3;
    int differ = 0;
    for (std::uint64_t i = 0; i < 400; ++i) {
        const Rgb p = render_sample(scene, s, int(i % 8), int(i / 8 % 8), i);
        const Rgb q = render_sample(scene, blurred, int(i % 8), int(i / 8 % 8), i);
        if (p.r != q.r) ++differ;
    }
    EXPECT_GT(differ, 20);
}

}  // namespace
}  // namespace hairis
