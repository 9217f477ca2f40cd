// The benchmarks' and studies' ball of hair without Blender: strands of 9 points rooted
// uniformly on the unit sphere, 0.5 long and leaning at random (or straight along the normal,
// as Blender's particle hair grows without dynamics), over a diffuse sphere of radius 0.98,
// under a sun and a dim world, seen along +y from 6 m.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <utility>

#include "fiber/fiber_spec.h"
#include "fiber/principled_hair.h"
#include "render/dual_scattering_integrator.h"
#include "render/scene.h"
#include "sampling/strategy.h"
#include "tables/bake.h"

namespace hairis::bench {

constexpr int kBallStrandPoints = 9;

/// How ball_strands grow: out from the root along the sphere's normal, bending towards a
/// random lean (x and y uniform in ±spread/2, z `droop`), the radius falling linearly.
struct StrandShape {
    float length = 0.5f;
    float spread = 0.4f, droop = -0.3f;
    float root_radius = 0.004f, tip_radius = 0.001f;
};

/// `count` strands of kBallStrandPoints points rooted uniformly on the unit sphere (material 0).
inline HairCurves ball_strands(std::size_t count, const StrandShape &shape = {}) {
    HairCurves c;
    c.points.reserve(count * kBallStrandPoints);
    c.radii.reserve(count * kBallStrandPoints);
    c.first.reserve(count + 1);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    c.first.push_back(0);
    for (std::size_t s = 0; s < count; ++s) {
        const float z = 2.0f * u(rng) - 1.0f, phi = 6.2831853f * u(rng);
        const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        const Vec3 root{r * std::cos(phi), r * std::sin(phi), z};
        const Vec3 lean{shape.spread * (u(rng) - 0.5f), shape.spread * (u(rng) - 0.5f), shape.droop};
        for (int k = 0; k < kBallStrandPoints; ++k) {
            const float t = float(k) / float(kBallStrandPoints - 1);
            c.points.push_back(root + (shape.length * t) * (root + t * lean));
            c.radii.push_back(shape.root_radius + (shape.tip_radius - shape.root_radius) * t);
        }
        c.first.push_back(std::uint32_t(c.points.size()));
    }
    c.material = 0;
    return c;
}

/// A UV sphere of radius 0.98 (under the roots) with material 1.
inline TriangleMesh ball_mesh(int rings = 24, int segments = 48) {
    TriangleMesh m;
    for (int i = 0; i <= rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const float theta = float(M_PI) * float(i) / float(rings);
            const float phi = 2.0f * float(M_PI) * float(j) / float(segments);
            m.positions.push_back(0.98f * Vec3{std::sin(theta) * std::cos(phi),
                                               std::sin(theta) * std::sin(phi), std::cos(theta)});
        }
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const std::uint32_t a = std::uint32_t(i * segments + j);
            const std::uint32_t b = std::uint32_t(i * segments + (j + 1) % segments);
            const std::uint32_t c = a + std::uint32_t(segments), d = b + std::uint32_t(segments);
            for (std::uint32_t k : {a, c, b, b, c, d}) m.indices.push_back(k);
        }
    m.materials = {1};
    return m;
}

struct HairBall {
    std::size_t strands = 1000;
    float thickness = 1.0f;  ///< scales StrandShape's radii
    float melanin = 0.25f;   ///< Principled Hair's, Roughness 0.3
    bool mesh = true;        ///< the sphere under the roots
    bool straight = false;   ///< strands straight along the sphere's normal (no lean or droop)
    DualScatteringParams dual;  ///< the dual-scattering averages' (the paper's d_f = d_b = 0.7)
    int size = 96;           ///< pixels a side
    BvhQuality bvh_quality = BvhQuality::Medium;
};

/// The ball as a scene: material 0 the Principled Hair fiber sampled by `kind` (its tables,
/// dual-scattering averages and multiple table baked when kind is Table or `dual`), material 1
/// a skin-coloured diffuse.
inline Expected<Scene> hair_ball_scene(const HairBall &ball, StrategyKind kind, bool dual) {
    PrincipledHairNode node;
    node.parametrization = HairParametrization::Melanin;
    node.melanin = ball.melanin;
    node.roughness = 0.3f;
    auto params = to_chiang_params(node);
    if (!params) return params.error();
    auto fiber_or = ChiangFiber::create(params.value());
    if (!fiber_or) return fiber_or.error();
    auto fiber = std::make_shared<const ChiangFiber>(std::move(fiber_or).value());
    StrategyInputs inputs;
    inputs.chiang = fiber;
    std::optional<SamplingTables> tables;
    if (kind == StrategyKind::Table || dual) {
        auto baked = bake_tables(*fiber, chiang_parameters(params.value()), BakeOptions{});
        if (!baked) return baked.error();
        auto loaded = SamplingTables::from(baked.value());
        if (!loaded) return loaded.error();
        tables = std::move(loaded).value();
        if (kind == StrategyKind::Table) inputs.tables = &*tables;
    }
    auto sampler = make_sampler(kind, inputs);
    if (!sampler) return sampler.error();
    auto shading = HairShading::create(fiber, sampler.value());
    if (!shading) return shading.error();

    SceneDesc desc;
    HairMaterial hair{shading.value()};
    if (dual) {
        auto averages = DualScattering::create(*fiber, ball.dual);
        if (!averages) return averages.error();
        hair.dual = std::make_shared<const DualScattering>(std::move(averages).value());
        hair.multiple = tables->multiple;
    }
    desc.materials.push_back(std::move(hair));
    DiffuseMaterial skin;
    skin.albedo = {0.6f, 0.5f, 0.45f};
    desc.materials.push_back(skin);
    StrandShape shape;
    shape.root_radius *= ball.thickness;
    shape.tip_radius *= ball.thickness;
    if (ball.straight) shape.spread = shape.droop = 0.0f;
    desc.curves.push_back(ball_strands(ball.strands, shape));
    if (ball.mesh) desc.meshes.push_back(ball_mesh());
    SunLight sun;
    sun.to_sun = safe_normalize(Vec3{0.5f, -0.6f, 0.6f});
    sun.strength = 3.0f;
    sun.angle = 0.05f;
    desc.suns.push_back(sun);
    desc.world.color = {0.2f, 0.22f, 0.25f};
    desc.world.strength = 0.3f;
    const float to_world[16] = {1, 0, 0, 0, 0, 0, -1, -6, 0, 1, 0, 0, 0, 0, 0, 1};
    desc.camera.camera_to_world = Mat4::from_row_major(to_world);
    for (Vec3 &corner : desc.camera.frame) corner = Vec3{corner.x * 0.6f, corner.y * 0.6f, -1.0f};
    desc.camera.width = ball.size;
    desc.camera.height = ball.size;
    desc.bvh_quality = ball.bvh_quality;
    return Scene::build(std::move(desc));
}

}  // namespace hairis::bench
