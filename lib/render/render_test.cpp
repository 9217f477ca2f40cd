#include "render/render.h"
#include "fiber/seed_pdfs.h"

#include <gtest/gtest.h>

#include "scene_fixtures.h"
#include "same_bits.h"

#include "fiber/chiang_strands.h"
#include "core/quadrature.h"
#include "fiber/huang.h"
#include "sampling/analytic_sampler.h"
#include "fiber/principled_hair.h"
#include "sampling/huang_tabulated_fiber.h"
#include "tables/huang_bake.h"
#include "sampling/near_field_table.h"
#include "sampling/strategy.h"
#include "sampling/uniform_sampler.h"

#include "core/quadrature.h"
#include "fiber/fresnel.h"
#include "hemisphere.h"
#include "huang_fixtures.h"

#include <cstdio>

#include <chrono>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace hairis {
namespace {

using testing::same_bits;

HairMaterial hair(std::shared_ptr<const ChiangFiber> fiber, std::shared_ptr<const Sampler> sampler) {
    return HairMaterial{HairShading::create(std::move(fiber), std::move(sampler)).value()};
}

std::shared_ptr<const Sampler> gaussian_sampler(float w, int n_h) {
    StrategyInputs in;
    in.multiple_weight = w;
    in.n_h = n_h;
    return make_sampler(StrategyKind::Gaussian, in).value();
}

constexpr double kPiD = kPi;

// ---- Scene helpers ------------------------------------------------------------------------

using testing::ortho_down;

CameraDesc perspective(Vec3 position, float tan_half, int w, int h) {
    CameraDesc c;
    c.camera_to_world = Mat4::translation(position);
    c.frame = {Vec3{tan_half, tan_half, -1}, Vec3{tan_half, -tan_half, -1},
               Vec3{-tan_half, -tan_half, -1}, Vec3{-tan_half, tan_half, -1}};
    c.width = w;
    c.height = h;
    return c;
}

TriangleMesh quad(float half, float z, std::uint32_t material, bool facing_up = true) {
    TriangleMesh m;
    m.positions = {{-half, -half, z}, {half, -half, z}, {half, half, z}, {-half, half, z}};
    m.indices = facing_up ? std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}
                          : std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2};
    m.materials = {material};
    return m;
}

TriangleMesh sphere(float radius, int rings, int segments, std::uint32_t material) {
    TriangleMesh m;
    for (int i = 0; i <= rings; ++i) {
        const double theta = kPiD * i / rings;
        for (int j = 0; j < segments; ++j) {
            const double phi = 2.0 * kPiD * j / segments;
            m.positions.push_back({float(radius * std::sin(theta) * std::cos(phi)),
                                   float(radius * std::sin(theta) * std::sin(phi)),
                                   float(radius * std::cos(theta))});
        }
    }
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const std::uint32_t a = std::uint32_t(i * segments + j),
                                b = std::uint32_t(i * segments + (j + 1) % segments),
                                c = std::uint32_t((i + 1) * segments + j),
                                d = std::uint32_t((i + 1) * segments + (j + 1) % segments);
            m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
        }
    m.materials = {material};
    return m;
}

std::shared_ptr<const ChiangFiber> fiber_with(Rgb sigma_a) {
    ChiangParams p;
    p.sigma_a = sigma_a;
    auto f = ChiangFiber::create(p);
    EXPECT_TRUE(f.ok());
    return std::make_shared<const ChiangFiber>(std::move(f).value());
}

// Parallel straight hairs along X in the plane z = 0, spaced along Y.
HairCurves parallel_hairs(int count, float spacing, float radius, float half_length = 1.5f) {
    HairCurves c;
    c.first.push_back(0);
    for (int i = 0; i < count; ++i) {
        const float y = (float(i) - 0.5f * float(count - 1)) * spacing;
        for (int k = 0; k < 4; ++k) {
            c.points.push_back({-half_length + 2.0f * half_length * float(k) / 3.0f, y,
                                0.02f * float(k % 2)});
            c.radii.push_back(radius);
        }
        c.first.push_back(std::uint32_t(c.points.size()));
    }
    return c;
}

// A tuft of wavy hairs standing on the XY plane: `count` curves of `points` points.
HairCurves tuft(int count, int points, float radius, std::uint32_t seed = 1) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    HairCurves c;
    c.first.push_back(0);
    for (int i = 0; i < count; ++i) {
        const Vec3 root{0.5f * u(rng), 0.5f * u(rng), 0.0f};
        const Vec3 lean{0.3f * u(rng), 0.3f * u(rng), 1.0f};
        for (int k = 0; k < points; ++k) {
            const float t = float(k) / float(points - 1);
            const Vec3 wiggle{0.03f * std::sin(9.0f * t + float(i)),
                              0.03f * std::cos(7.0f * t + float(i)), 0.0f};
            c.points.push_back(root + lean * t + wiggle);
            c.radii.push_back(radius * (1.0f - 0.5f * t));
        }
        c.first.push_back(std::uint32_t(c.points.size()));
    }
    return c;
}

Scene build(SceneDesc d) {
    auto s = Scene::build(std::move(d));
    EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
    return std::move(s).value();
}

std::vector<float> render_ok(const Scene &scene, const RenderSettings &settings,
                             RenderStats *stats = nullptr) {
    std::vector<float> rgba(std::size_t(scene.camera().width()) * scene.camera().height() * 4);
    const Status st = render(scene, settings, rgba.data(), {}, stats);
    EXPECT_FALSE(st.has_value()) << (st ? st->message : "");
    return rgba;
}

// Mean and per-sample standard deviation of one pixel's estimator (channel c).
struct PixelEstimate {
    double mean = 0, sigma = 0;
};
PixelEstimate estimate(const Scene &scene, const RenderSettings &s, int x, int y, int n,
                       int c = 0) {
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const double v = render_sample(scene, s, x, y, std::uint64_t(i))[c];
        sum += v;
        sum2 += v * v;
    }
    const double mean = sum / n;
    return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean))};
}

float at(const std::vector<float> &rgba, int w, int x, int y, int c) {
    return rgba[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 4 + std::size_t(c)];
}

// ---- Tests --------------------------------------------------------------------------------

TEST(Render, WhiteFurnaceDiffuseSphere) {
    // A Lambertian sphere of albedo 1 in a uniform white world reflects exactly the world:
    // every pixel's expectation is 1, on the sphere and off it. The world is found by cosine
    // sampling alone (it is not light-sampled), so on a convex sphere every path weighs exactly
    // 1 and the spread may be zero; the bounds then allow float rounding only.
    SceneDesc d;
    d.materials = {DiffuseMaterial{Rgb(1.0f), Rgb(0.0f)}};
    d.meshes = {sphere(1.0f, 24, 48, 0)};
    d.world = {Rgb(1.0f), 1.0f};
    d.camera = perspective({0, 0, 4}, 0.35f, 12, 12);
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.samples = 64;
    s.seed = 7;
    const auto img = render_ok(scene, s);
    // The estimator's per-sample spread, measured on the sphere's centre pixel.
    const PixelEstimate centre = estimate(scene, s, 6, 6, 4096);
    EXPECT_NEAR(centre.mean, 1.0, std::max(5.0 * centre.sigma / 64.0, 1e-5));
    const double bound = std::max(6.0 * centre.sigma / std::sqrt(double(s.samples)), 1e-5);
    double sum = 0;
    for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 12; ++x)
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(at(img, 12, x, y, c), 1.0, bound) << x << "," << y;
                if (c == 0) sum += at(img, 12, x, y, c);
            }
    EXPECT_NEAR(sum / 144.0, 1.0, std::max(4.0 * centre.sigma / std::sqrt(144.0 * s.samples), 1e-5));
}

TEST(Render, DiffusePlaneUnderTheSun) {
    // L = albedo/π · E · cos θ for a Lambertian plane under a sun of irradiance E.
    const float theta = float(radians(40.0)), strength = 3.0f, albedo = 0.5f;
    for (const float angle : {0.0f, float(radians(5.0))}) {
        SceneDesc d;
        d.materials = {DiffuseMaterial{Rgb(albedo), Rgb(0.0f)}};
        d.meshes = {quad(100.0f, 0.0f, 0)};
        const Vec3 to_sun{std::sin(theta), 0.0f, std::cos(theta)};
        testing::set_sun(d, to_sun, strength, angle);
        d.camera = ortho_down(1, 1, 8, 8);
        const Scene scene = build(std::move(d));
        RenderSettings s;
        s.samples = 64;
        const auto img = render_ok(scene, s);
        // The disc's irradiance on the plane: E · E[cos] over the sun's disc (quadrature of
        // uniform points on the disc of radius tan(angle/2) at distance 1, as Cycles samples).
        double mean_cos = std::cos(theta);
        if (angle > 0.0f) {
            const Vec3 c = to_sun;
            const Vec3 a{std::cos(theta), 0.0f, -std::sin(theta)}, b{0, 1, 0};
            const double r = std::tan(0.5 * angle);
            double sum = 0, n = 0;
            for (int i = 0; i < 400; ++i)
                for (int j = 0; j < 400; ++j) {
                    const double x = -1 + (i + 0.5) / 200.0, y = -1 + (j + 0.5) / 200.0;
                    if (x * x + y * y > 1) continue;
                    const Vec3 dir = safe_normalize(c + a * float(r * x) + b * float(r * y));
                    sum += dir.z;
                    n += 1;
                }
            mean_cos = sum / n;
        }
        const double expected = albedo / kPiD * strength * mean_cos;
        if (angle == 0.0f) {
            // A delta sun and a black world: no noise at all.
            for (int y = 0; y < 8; ++y)
                for (int x = 0; x < 8; ++x)
                    EXPECT_NEAR(at(img, 8, x, y, 1), expected, 1e-5 * expected);
        } else {
            const PixelEstimate p = estimate(scene, s, 3, 3, 4096, 1);
            EXPECT_NEAR(p.mean, expected, 5.0 * p.sigma / 64.0 + 1e-6);
            double sum = 0;
            for (int y = 0; y < 8; ++y)
                for (int x = 0; x < 8; ++x) {
                    EXPECT_NEAR(at(img, 8, x, y, 1), expected, 6.0 * p.sigma / 8.0 + 1e-6);
                    sum += at(img, 8, x, y, 1);
                }
            EXPECT_NEAR(sum / 64.0, expected, 4.0 * p.sigma / std::sqrt(64.0 * 64.0) + 1e-6);
        }
    }
}

TEST(Render, PointLightInverseSquareWithCyclesNormalisation) {
    // Blender point light of power P and radius 0 at height d over a white Lambertian floor:
    // Cycles' intensity is P/(4π) W/sr, so L(x, y) = (1/π) · P/(4π) · d / (x² + y² + d²)^(3/2).
    const float power = 100.0f, d = 1.0f;
    SceneDesc desc;
    desc.materials = {DiffuseMaterial{Rgb(1.0f), Rgb(0.0f)}};
    desc.meshes = {quad(100.0f, 0.0f, 0)};
    desc.point_lights = {{Vec3{0, 0, d}, Rgb(1.0f), power, 0.0f}};
    desc.camera = ortho_down(2, 2, 8, 8);
    const Scene scene = build(std::move(desc));
    RenderSettings s;
    s.samples = 256;
    const auto img = render_ok(scene, s);
    auto radiance = [&](double x, double y) {
        return (1.0 / kPiD) * (power / (4.0 * kPiD)) * d / std::pow(x * x + y * y + d * d, 1.5);
    };
    for (int py = 0; py < 8; ++py)
        for (int px = 0; px < 8; ++px) {
            // The pixel's footprint is [−2 + px/2, −2 + (px+1)/2] × (the same in y): average
            // and spread of L over it, by a midpoint rule.
            double sum = 0, sum2 = 0;
            const int n = 48;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    const double v = radiance(-2.0 + 0.5 * (px + (i + 0.5) / n),
                                              -2.0 + 0.5 * (py + (j + 0.5) / n));
                    sum += v;
                    sum2 += v * v;
                }
            const double mean = sum / (n * n);
            const double spread = std::sqrt(std::max(0.0, sum2 / (n * n) - mean * mean));
            EXPECT_NEAR(at(img, 8, px, py, 0), mean, 5.0 * spread / 16.0 + 1e-4 * mean)
                << "pixel " << px << "," << py;
        }

    // With a radius r, on the axis: E = P/(4π(d² + r²)) (a facing disk of radiance
    // P/(4π·πr²)), L = E/π.
    const float r = 0.5f;
    SceneDesc desc2;
    desc2.materials = {DiffuseMaterial{Rgb(1.0f), Rgb(0.0f)}};
    desc2.meshes = {quad(100.0f, 0.0f, 0)};
    desc2.point_lights = {{Vec3{0, 0, d}, Rgb(1.0f), power, r}};
    desc2.camera = ortho_down(0.001f, 0.001f, 1, 1, {0, 0, 0.5f});
    const Scene scene2 = build(std::move(desc2));
    const PixelEstimate p = estimate(scene2, s, 0, 0, 20000);
    const double expected = power / (4.0 * kPiD * (d * d + r * r)) / kPiD;
    EXPECT_NEAR(p.mean, expected, 5.0 * p.sigma / std::sqrt(20000.0) + 1e-4 * expected);
}

TEST(Render, AreaLightsWithMis) {
    // A disk light of diameter 2R at height d facing down over a white floor, on the axis:
    // E = P/(4(R² + d²)), L = E/π. Close and large, so BSDF samples hit it often (MIS).
    const float power = 50.0f, radius = 1.0f, d = 0.5f;
    for (const AreaShape shape : {AreaShape::Disk, AreaShape::Square}) {
        SceneDesc desc;
        desc.materials = {DiffuseMaterial{Rgb(1.0f), Rgb(0.0f)}};
        desc.meshes = {quad(100.0f, 0.0f, 0)};
        AreaLight a;
        a.shape = shape;
        a.size_x = 2.0f * radius;
        a.power = power;
        a.light_to_world = Mat4::translation({0, 0, d});
        desc.area_lights = {a};
        desc.camera = ortho_down(0.001f, 0.001f, 1, 1, {0, 0, 0.25f});
        const Scene scene = build(std::move(desc));
        RenderSettings s;
        s.samples = 1;
        double expected;
        if (shape == AreaShape::Disk) {
            expected = power / (4.0 * (radius * radius + d * d)) / kPiD;
        } else {
            // A square of half side a at distance d, point on its axis:
            // E = 4 L · a/√(a²+d²) · atan(a/√(a²+d²)), L = P/(4·(2a)²).
            const double L = power * 0.25 / 4.0, q = radius / std::sqrt(radius * radius + d * d);
            expected = 4.0 * L * q * std::atan(q) / kPiD;
        }
        const PixelEstimate p = estimate(scene, s, 0, 0, 20000);
        EXPECT_NEAR(p.mean, expected, 5.0 * p.sigma / std::sqrt(20000.0))
            << (shape == AreaShape::Disk ? "disk" : "square");
    }
}

TEST(Render, SpotDiskWithMis) {
    // A Cycles 3.4 spot of radius r at height d over a white floor, on its axis, the disk
    // inside the cone: E = (2π L/3)(1 − d³/(d² + r²)^(3/2)) with L = P/(4π²r²) (each disk
    // point weighs with c = cos θ), and the floor's radiance is E/π. Large and close, so BSDF
    // samples hit the disk often and MIS matters.
    const float power = 60.0f, r = 0.8f, d = 0.6f;
    SceneDesc desc;
    desc.materials = {DiffuseMaterial{Rgb(1.0f), Rgb(0.0f)}};
    desc.meshes = {quad(100.0f, 0.0f, 0)};
    SpotLight spot;
    spot.light_to_world = Mat4::translation({0, 0, d});
    spot.power = power;
    spot.radius = r;
    spot.spot_size = 2.6f;
    spot.spot_blend = 0.0f;
    desc.spot_lights = {spot};
    desc.camera = ortho_down(0.001f, 0.001f, 1, 1, {0, 0, 0.3f});
    const Scene scene = build(std::move(desc));
    RenderSettings s;
    s.samples = 1;
    s.max_bounces = 0;
    const double L = power / (4.0 * kPiD * kPiD * r * r);
    const double expected =
        2.0 * kPiD * L / 3.0 * (1.0 - std::pow(d, 3) / std::pow(d * d + r * r, 1.5)) / kPiD;
    const PixelEstimate p = estimate(scene, s, 0, 0, 20000);
    EXPECT_NEAR(p.mean, expected, 5.0 * p.sigma / std::sqrt(20000.0));
}

// An environment of w × h black texels but (i, j) of radiance `value`, seen through a
// Mapping rotation.
std::shared_ptr<const EnvironmentMap> hot_texel_world(int w, int h, int i, int j, float value,
                                                      Vec3 rotation) {
    std::vector<float> rgb(std::size_t(w) * std::size_t(h) * 3, 0.0f);
    for (int c = 0; c < 3; ++c) rgb[(std::size_t(j) * std::size_t(w) + std::size_t(i)) * 3 + std::size_t(c)] = value;
    EnvironmentDesc desc;
    desc.image = EnvironmentImage::create(w, h, std::move(rgb)).value();
    MappingNode mapping;
    mapping.rotation = rotation;
    desc.world_to_texture = mapping_node_transform(mapping).value();
    return std::make_shared<const EnvironmentMap>(EnvironmentMap::create(std::move(desc)).value());
}

TEST(Render, EnvironmentHotTexelIsFoundByLightSampling) {
    // One bright texel of a 128 × 64 HDRI (rotated by a Mapping node) over a white floor. The
    // reference integrates, in texture space, the bilinear tent of that texel (Cycles' linear
    // interpolation) times the floor's cosine: E = ∫∫ V·tent_u·tent_v · max(0, (Aᵀĉ)·z) ·
    // 2π²·sin θ du dv, with ĉ(u, v) Cycles' equirectangular direction and A the rotation, and
    // the floor's radiance is E/π. Light sampling finds the texel: the estimate converges to
    // 1.5% in 8000 samples, where BSDF sampling alone is an order of magnitude noisier.
    const int w = 128, h = 64, ti = 40, tj = 44;
    const float value = 2000.0f;
    const Vec3 rotation{0.3f, 0.0f, 0.7f};
    const Mat4 A = mapping_node_transform(MappingNode{MappingType::Point, {}, rotation, {1, 1, 1}}).value();
    double reference = 0;
    {
        const int n = 400;  // per texel width, over the 2 × 2 texel support
        for (int a = 0; a < n; ++a)
            for (int b = 0; b < n; ++b) {
                const double x = ti - 0.5 + 2.0 * (a + 0.5) / n, y = tj - 0.5 + 2.0 * (b + 0.5) / n;
                const double tent = (1.0 - std::fabs(x - (ti + 0.5))) * (1.0 - std::fabs(y - (tj + 0.5)));
                const double u = x / w, v = y / h;
                const double phi = kPiD - 2.0 * kPiD * u, theta = kPiD * (1.0 - v);
                const Vec3 c{float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)),
                             float(std::cos(theta))};
                // Aᵀĉ: the world direction of texture direction ĉ (A is a rotation).
                const double z = A.m[0][2] * c.x + A.m[1][2] * c.y + A.m[2][2] * c.z;
                reference += value * tent * std::max(0.0, z) * 2.0 * kPiD * kPiD * std::sin(theta) *
                             (2.0 / n / w) * (2.0 / n / h);
            }
    }
    ASSERT_GT(reference, 0.1) << reference;
    const double expected = reference / kPiD;
    RenderSettings s;
    s.samples = 1;
    s.max_bounces = 0;
    double sigma_of[2] = {0, 0};
    for (const bool sampled : {true, false}) {
        SceneDesc desc;
        desc.materials = {DiffuseMaterial{Rgb(1.0f), Rgb(0.0f)}};
        desc.meshes = {quad(100.0f, 0.0f, 0)};
        desc.world.environment = hot_texel_world(w, h, ti, tj, value, rotation);
        desc.world.light_sampled = sampled;
        desc.camera = ortho_down(0.001f, 0.001f, 1, 1, {0, 0, 0.3f});
        const Scene scene = build(std::move(desc));
        const int n = 8000;
        const PixelEstimate p = estimate(scene, s, 0, 0, n);
        const double se = p.sigma / std::sqrt(double(n));
        sigma_of[sampled ? 0 : 1] = se;
        if (sampled) {
            EXPECT_NEAR(p.mean, expected, 5.0 * se + 1e-4 * expected);
            EXPECT_LT(se, 0.015 * expected);
        }
    }
    EXPECT_GT(sigma_of[1], 10.0 * sigma_of[0]) << sigma_of[1] << " vs " << sigma_of[0];
}

TEST(Render, EnvironmentMisAgreesWithBsdfSamplingAlone) {
    // A diffuse sphere on a floor under a sky with a bright sun-like spot, two bounces: the
    // world light-sampled with MIS (Sampling Auto) and found by BSDF sampling alone (Sampling
    // None) are two unbiased estimators of the same pixels.
    std::vector<float> rgb;
    const int w = 64, h = 32;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float g = 0.1f + 0.5f * float(y) / float(h);
            const bool sun = (x == 12 || x == 13) && (y == 24 || y == 25);
            const Rgb c = sun ? Rgb{40.0f, 35.0f, 30.0f} : Rgb{0.5f * g, 0.7f * g, g};
            rgb.insert(rgb.end(), {c.r, c.g, c.b});
        }
    EnvironmentDesc env;
    env.image = EnvironmentImage::create(w, h, std::move(rgb)).value();
    env.strength = 1.5f;
    const auto world = std::make_shared<const EnvironmentMap>(EnvironmentMap::create(std::move(env)).value());
    RenderSettings s;
    s.samples = 1;
    s.max_bounces = 2;
    PixelEstimate results[2][3];
    const int n = 12000, pixels[3][2] = {{4, 4}, {2, 5}, {6, 1}};
    for (int k = 0; k < 2; ++k) {
        SceneDesc desc;
        desc.materials = {DiffuseMaterial{Rgb(0.7f, 0.6f, 0.5f), Rgb(0.0f)}};
        desc.meshes = {quad(50.0f, -1.0f, 0), sphere(1.0f, 24, 48, 0)};
        desc.world.environment = world;
        desc.world.light_sampled = k == 0;
        desc.camera = perspective({0, -0.5f, 4.0f}, 0.45f, 8, 8);
        const Scene scene = build(std::move(desc));
        for (int i = 0; i < 3; ++i) results[k][i] = estimate(scene, s, pixels[i][0], pixels[i][1], n, 1);
    }
    for (int i = 0; i < 3; ++i) {
        const double se = std::sqrt((results[0][i].sigma * results[0][i].sigma +
                                     results[1][i].sigma * results[1][i].sigma) / n);
        EXPECT_NEAR(results[0][i].mean, results[1][i].mean, 5.0 * se) << "pixel " << i;
        EXPECT_GT(results[0][i].mean, 0.01);
    }
}

// A straight curve along x at height z (and y), `points` evenly spaced points.
HairCurves straight_hair(float y, float z, float radius, float half_length, int points = 4) {
    HairCurves c;
    c.first = {0};
    for (int k = 0; k < points; ++k) {
        c.points.push_back({-half_length + 2.0f * half_length * float(k) / float(points - 1), y, z});
        c.radii.push_back(radius);
    }
    c.first.push_back(std::uint32_t(c.points.size()));
    return c;
}

// The albedo ∫ f cos θ_i dω_i of a fiber's near field seen perpendicularly (θ_o = 0), by a
// product Gauss rule in (sin θ_i, φ_i), over offsets h across the fiber: its least and greatest.
struct AlbedoRange {
    double low = 1e300, high = -1e300;
};
AlbedoRange perpendicular_albedo(const ChiangFiber &fiber, int sin_panels, int phi_panels) {
    const Vec3 wo = direction_of(0.0f, float(-kHalfPi));  // Cycles' frame puts ω_o at φ = −π/2
    const QuadratureRule sin_theta = QuadratureRule::composite(-1.0, 1.0, sin_panels, 8);
    const QuadratureRule phi = QuadratureRule::composite(-kPi, kPi, phi_panels, 8);
    AlbedoRange range;
    for (int k = -6; k <= 6; ++k) {
        const float h = 0.15f * float(k);
        double albedo = 0;
        for (std::size_t i = 0; i < sin_theta.x.size(); ++i) {
            const double c = std::sqrt(1.0 - sin_theta.x[i] * sin_theta.x[i]);
            for (std::size_t j = 0; j < phi.x.size(); ++j) {
                const Vec3 wi{float(sin_theta.x[i]), float(c * std::cos(phi.x[j])), float(c * std::sin(phi.x[j]))};
                albedo += sin_theta.w[i] * phi.w[j] * double(fiber.f_cos_near(wi, wo, h).g);
            }
        }
        range.low = std::min(range.low, albedo);
        range.high = std::max(range.high, albedo);
    }
    return range;
}

TEST(Render, ClearHairInAWhiteWorldReturnsItsAlbedo) {
    // One straight clear fiber (σ_a = 0) under the camera, in a white world: a path that leaves
    // the convex tube escapes to the world, so whatever the bounce limit a pixel the hair covers
    // has the expectation of the fiber's albedo for ω_o ⟂ the fiber, averaged over the offsets h
    // its samples hit. The reference is the fiber's f integrated by quadrature (independent of
    // the renderer's sampling, MIS and path weights); it must lie within a few standard errors.
    const auto clear = fiber_with(Rgb(0.0f));
    const AlbedoRange albedo = perpendicular_albedo(*clear, 24, 48);
    const AlbedoRange coarse = perpendicular_albedo(*clear, 12, 24);
    ASSERT_NEAR(albedo.low, coarse.low, 1e-4);  // the rule has converged
    ASSERT_NEAR(albedo.high, coarse.high, 1e-4);
    SceneDesc d;
    d.materials = {hair(clear, std::make_shared<const AnalyticSampler>(clear))};
    d.curves = {straight_hair(0.0f, 0.0f, 0.1f, 1.0f)};
    d.world = {Rgb(1.0f), 1.0f};
    d.camera = ortho_down(0.05f, 0.05f, 1, 1);  // one pixel, 0.1 wide, inside the 0.2-wide hair
    const Scene scene = build(std::move(d));
    RenderSettings s;  // the default 12 bounces
    constexpr int kSamples = 20000;
    const PixelEstimate p = estimate(scene, s, 0, 0, kSamples, 1);
    const double se = p.sigma / std::sqrt(double(kSamples));
    EXPECT_GE(p.mean, albedo.low - 4.0 * se - 1e-4) << "albedo " << albedo.low << ".." << albedo.high << ", standard error " << se;
    EXPECT_LE(p.mean, albedo.high + 4.0 * se + 1e-4) << "albedo " << albedo.low << ".." << albedo.high << ", standard error " << se;
    // What this resolves: the albedo's spread over h and the noise are far below a 2% bias.
    EXPECT_LT(albedo.high - albedo.low + 8.0 * se, 0.02);
}

TEST(Render, HairInAWhiteWorldStaysAtMostOne) {
    // σ_a = 0: the fiber absorbs nothing, so in a white furnace no pixel can exceed the world.
    const auto clear = fiber_with(Rgb(0.0f));
    SceneDesc d;
    d.materials = {hair(clear, std::make_shared<const AnalyticSampler>(clear))};
    d.curves = {parallel_hairs(5, 0.15f, 0.06f)};
    d.world = {Rgb(1.0f), 1.0f};
    d.camera = ortho_down(0.5f, 0.5f, 10, 10);
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.samples = 64;
    s.film_transparent = true;  // alpha = hair coverage; rgb/alpha = hair radiance
    const auto img = render_ok(scene, s);
    int hair_pixels = 0;
    double sum = 0;
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 10; ++x) {
            const float alpha = at(img, 10, x, y, 3);
            if (alpha < 0.5f) continue;
            ++hair_pixels;
            for (int c = 0; c < 3; ++c) {
                const float v = at(img, 10, x, y, c) / alpha;
                EXPECT_GT(v, 0.0f);
                EXPECT_LE(v, 1.0f + 0.15f) << x << "," << y;  // 64 samples of noise
            }
            sum += at(img, 10, x, y, 1) / alpha;
        }
    ASSERT_GT(hair_pixels, 10);
    const double mean = sum / hair_pixels;
    EXPECT_LE(mean, 1.0 + 0.02);
    // A full-coverage pixel measured with many samples.
    int cx = -1, cy = -1;
    for (int y = 0; y < 10 && cx < 0; ++y)
        for (int x = 0; x < 10; ++x)
            if (at(img, 10, x, y, 3) == 1.0f) {
                cx = x;
                cy = y;
                break;
            }
    ASSERT_GE(cx, 0);
    const PixelEstimate p = estimate(scene, s, cx, cy, 8192, 1);
    EXPECT_LE(p.mean, 1.0 + 4.0 * p.sigma / std::sqrt(8192.0));
    // Light that reaches a neighbour comes back off it at another θ_o, where the offset's tilt
    // moves the albedo a little, and the bounce limit cuts the rare long paths: both are far
    // below 0.2%, so the pixel is the fiber's own albedo within that and its noise.
    const AlbedoRange albedo = perpendicular_albedo(*clear, 24, 48);
    EXPECT_NEAR(p.mean, 0.5 * (albedo.low + albedo.high),
                0.5 * (albedo.high - albedo.low) + 4.0 * p.sigma / std::sqrt(8192.0) + 0.002);
}

TEST(Render, HairStrategiesAgree) {
    // The same hair lit by a sun and a world, with ω_i drawn by the uniform sampler or by
    // Chiang's analytic sampler: the same expectation (MIS and f/pdf weights are unbiased).
    const auto fiber = fiber_with(Rgb(0.4f, 0.8f, 1.6f));
    auto make = [&](std::shared_ptr<const Sampler> sampler) {
        SceneDesc d;
        d.materials = {hair(fiber, std::move(sampler))};
        d.curves = {parallel_hairs(3, 0.14f, 0.06f)};
        d.world = {Rgb(0.3f, 0.4f, 0.5f), 1.0f};
        testing::set_sun(d, safe_normalize(Vec3{0.3f, 0.5f, 1.0f}), 2.0f, 0.2f);
        d.camera = ortho_down(0.05f, 0.25f, 1, 5);
        return build(std::move(d));
    };
    const Scene analytic = make(std::make_shared<const AnalyticSampler>(fiber));
    const Scene uniform = make(std::make_shared<const UniformSampler>());
    RenderSettings s;
    s.max_bounces = 4;
    for (int y = 0; y < 5; ++y) {
        const PixelEstimate a = estimate(analytic, s, 0, y, 3000, 1);
        const PixelEstimate u = estimate(uniform, s, 0, y, 3000, 1);
        const double se = std::sqrt((a.sigma * a.sigma + u.sigma * u.sigma) / 3000.0);
        EXPECT_NEAR(a.mean, u.mean, 4.5 * se + 1e-6) << "row " << y;
        // The analytic strategy is the better one.
        if (a.mean > 0.01) {
            EXPECT_LT(a.sigma, u.sigma * 1.05) << "row " << y;
        }
    }
}

// Curves whose melanin input is 0.8 everywhere render as a material of melanin 0.8: the
// strand's own fiber is that fiber, bit for bit, for f and for the analytic sampler.
TEST(Render, StrandInputsRenderAsTheFiberOfTheirValues) {
    auto strands_of = [](float melanin) {
        PrincipledHairNode node;
        node.parametrization = HairParametrization::Melanin;
        node.melanin = melanin;
        return std::make_shared<const ChiangStrands>(ChiangStrands::create(node).value());
    };
    auto make = [&](float node_melanin, std::vector<CurveInput> inputs) {
        const auto strands = strands_of(node_melanin);
        SceneDesc d;
        d.materials = {HairMaterial{
            HairShading::create(strands, std::make_shared<const AnalyticSampler>(strands)).value()}};
        HairCurves c = parallel_hairs(3, 0.14f, 0.06f);
        c.inputs = std::move(inputs);
        d.curves = {c};
        d.world = {Rgb(0.3f, 0.4f, 0.5f), 1.0f};
        testing::set_sun(d, safe_normalize(Vec3{0.3f, 0.5f, 1.0f}), 2.0f);
        d.camera = ortho_down(0.3f, 0.3f, 6, 6);
        return build(std::move(d));
    };
    RenderSettings s;
    s.samples = 8;
    s.max_bounces = 3;
    const std::vector<float> expected = render_ok(make(0.8f, {}), s);
    const std::vector<float> per_curve = render_ok(make(0.3f, {{HairInput::Melanin, false, {0.8f, 0.8f, 0.8f}}}), s);
    const std::vector<float> per_point =
        render_ok(make(0.3f, {{HairInput::Melanin, true, std::vector<float>(12, 0.8f)}}), s);
    const std::vector<float> node_value = render_ok(make(0.3f, {}), s);
    double total = 0;
    for (std::size_t i = 0; i < expected.size(); ++i) {
        ASSERT_EQ(per_curve[i], expected[i]) << i;
        ASSERT_EQ(per_point[i], expected[i]) << i;
        total += expected[i];
    }
    EXPECT_GT(total, 0.0);
    EXPECT_NE(node_value, expected);  // the inputs did change the image
}

// TABLE samples the tables of the node's own values and ANALYTIC each strand's own fiber:
// both are unbiased, so strands far from the tables' parameters still render the same.
TEST(Render, TableAndAnalyticAgreeOnStrandsAwayFromTheTables) {
    PrincipledHairNode node;
    node.parametrization = HairParametrization::Melanin;
    node.melanin = 0.5f;
    const auto strands = std::make_shared<const ChiangStrands>(ChiangStrands::create(node).value());
    const auto table = std::make_shared<const NearFieldTable>(NearFieldTable::create(strands->fiber()).value());
    auto make = [&](std::shared_ptr<const Sampler> sampler) {
        SceneDesc d;
        d.materials = {HairMaterial{HairShading::create(strands, std::move(sampler)).value()}};
        HairCurves c = parallel_hairs(3, 0.14f, 0.06f);
        // Per curve: smoother and darker, rougher and lighter, the node's own; per point coat.
        c.inputs = {{HairInput::Roughness, false, {0.12f, 0.6f, 0.3f}},
                    {HairInput::RadialRoughness, false, {0.15f, 0.55f, 0.3f}},
                    {HairInput::Melanin, false, {0.9f, 0.2f, 0.5f}},
                    {HairInput::Coat, true, {0, 0.3f, 0.6f, 0.9f, 0, 0, 0, 0, 0.2f, 0.2f, 0.2f, 0.2f}}};
        d.curves = {c};
        d.world = {Rgb(0.3f, 0.4f, 0.5f), 1.0f};
        testing::set_sun(d, safe_normalize(Vec3{0.3f, 0.5f, 1.0f}), 2.0f, 0.2f);
        d.camera = ortho_down(0.05f, 0.25f, 1, 5);
        return build(std::move(d));
    };
    const Scene analytic = make(std::make_shared<const AnalyticSampler>(strands));
    const Scene tabled = make(std::make_shared<const NearFieldTableSampler>(table, strands));
    RenderSettings s;
    s.max_bounces = 4;
    for (int y = 0; y < 5; ++y) {
        const PixelEstimate a = estimate(analytic, s, 0, y, 3000, 1);
        const PixelEstimate t = estimate(tabled, s, 0, y, 3000, 1);
        const double se = std::sqrt((a.sigma * a.sigma + t.sigma * t.sigma) / 3000.0);
        EXPECT_NEAR(a.mean, t.mean, 4.5 * se + 1e-6) << "row " << y;
    }
}

TEST(Render, HairStrategiesAgreeOnDeepPaths) {
    // Twelve bounces among dense hairs under a sun and a sky: the analytic and the gaussian
    // strategies (very different densities) must give the same expectation. The uniform
    // strategy is left out on purpose: its path weight's second moment grows like
    // E[(f/pdf)²]^depth ≈ 26^depth, so at this depth its unbiased estimate is so heavy-tailed
    // that 2·10^6 samples still come out 1-3% low (at depth ≤ 1 it agrees to 0.1%).
    const auto fiber = fiber_with(Rgb(0.1f, 0.3f, 0.9f));
    auto make = [&](std::shared_ptr<const Sampler> sampler) {
        SceneDesc d;
        d.materials = {hair(fiber, std::move(sampler))};
        d.curves = {parallel_hairs(9, 0.1f, 0.05f)};
        d.world = {Rgb(0.4f, 0.5f, 0.7f), 1.0f};
        testing::set_sun(d, safe_normalize(Vec3{0.3f, -0.6f, 0.5f}), 3.0f, 0.05f);
        d.camera = ortho_down(0.05f, 0.05f, 1, 1);
        return build(std::move(d));
    };
    const Scene analytic = make(std::make_shared<const AnalyticSampler>(fiber));
    const Scene gauss =
        make(gaussian_sampler(0.3f, 2));
    RenderSettings s;
    s.max_bounces = 12;
    const PixelEstimate a = estimate(analytic, s, 0, 0, 20000, 1);
    const PixelEstimate g = estimate(gauss, s, 0, 0, 300000, 1);
    const double se = std::sqrt(a.sigma * a.sigma / 20000.0 + g.sigma * g.sigma / 300000.0);
    EXPECT_NEAR(a.mean, g.mean, 4.5 * se);
    EXPECT_GT(a.mean, 0.1);
}

TEST(Render, HairOffsetIsCyclesH) {
    SceneDesc d;
    d.materials = {hair(fiber_with(Rgb(0.5f)), std::make_shared<const UniformSampler>())};
    d.curves = {parallel_hairs(1, 0.1f, 0.1f)};
    d.camera = ortho_down(1, 1, 2, 2);
    const Scene scene = build(std::move(d));
    const Vec3 dir{0, 0, -1};
    auto offset = [&](float y) {
        const Vec3 o{0.2f, y, 3.0f};
        const auto hit = scene.intersect(o, dir, 0.0f, INFINITY);
        EXPECT_TRUE(hit.has_value());
        return hit ? cycles_fiber_hit(scene.surface_point(o, dir, *hit), -dir, false, 0.0f, 0).h : NAN;
    };
    for (const float y : {0.05f, -0.05f, 0.0f, 0.099f}) {
        const float h = offset(y);
        // |h| is the offset across the width over the radius; its sign follows the side.
        EXPECT_NEAR(std::fabs(h), std::fabs(y) / 0.1f, 2e-2f) << y;
        if (y != 0.0f) {
            EXPECT_LT(h * offset(-y), 0.0f) << y;
        }
    }
}

// ---- Huang hair: the fiber hit as Cycles sets it up ---------------------------------------

std::shared_ptr<const HuangFiber> huang_fiber(float aspect_ratio) {
    HuangParams p;
    p.aspect_ratio = aspect_ratio;
    auto f = HuangFiber::create(p);
    EXPECT_TRUE(f.ok()) << (f.ok() ? "" : f.error().message);
    return std::make_shared<const HuangFiber>(std::move(f).value());
}

HairMaterial huang_hair(float aspect_ratio) {
    return HairMaterial{
        HairShading::create(huang_fiber(aspect_ratio), std::make_shared<const UniformSampler>()).value()};
}

void expect_vec(Vec3 got, Vec3 want, float tol, const char *what) {
    EXPECT_NEAR(got.x, want.x, tol) << what;
    EXPECT_NEAR(got.y, want.y, tol) << what;
    EXPECT_NEAR(got.z, want.z, tol) << what;
}

TEST(Render, BackFacingHairHitTurnsTheFrameAsCycles) {
    // A ray from inside the tube (as through an open curve end) meets its far wall from behind.
    // Cycles turns Ng, N and dP/du towards ω_o there: θ_o is mirrored (the tangent reversed)
    // while h, from both turned vectors, is the front hit's on the same line.
    SceneDesc d;
    d.materials = {hair(fiber_with(Rgb(0.5f)), std::make_shared<const UniformSampler>())};
    d.curves = {straight_hair(0.0f, 0.0f, 0.1f, 1.5f)};
    d.curve_backfaces = CurveBackfaces::Hit;
    d.camera = ortho_down(1, 1, 2, 2);
    const Scene scene = build(std::move(d));
    const Vec3 dir = safe_normalize(Vec3{0.6f, 0.0f, -1.0f});
    for (const float y : {0.06f, -0.03f}) {
        const Vec3 inside{0.2f, y, 0.0f}, outside = inside - 3.0f * dir;
        const auto front = scene.intersect(outside, dir, 0.0f, INFINITY);
        const auto back = scene.intersect(inside, dir, 0.0f, INFINITY);
        ASSERT_TRUE(front && back) << y;
        const SurfacePoint sf = scene.surface_point(outside, dir, *front);
        const SurfacePoint sb = scene.surface_point(inside, dir, *back);
        ASSERT_GT(dot(sb.normal, dir), 0.0f) << "the far wall is hit from inside";
        const FiberHit hf = cycles_fiber_hit(sf, -dir, false, 0.0f, 0);
        const FiberHit hb = cycles_fiber_hit(sb, -dir, false, 0.0f, 0);
        EXPECT_NEAR(std::fabs(hf.h), std::fabs(y) / 0.1f, 2e-2f) << y;
        EXPECT_NEAR(hb.h, hf.h, 2e-2f) << y;
        const float sin_theta = dot(-dir, sf.tangent);  // along the tangent, which is ±x
        EXPECT_NEAR(std::fabs(sin_theta), 0.6f / std::sqrt(1.36f), 1e-3f);
        EXPECT_NEAR(hf.wo.x, sin_theta, 1e-5f) << y;
        EXPECT_NEAR(hb.wo.x, -sin_theta, 1e-5f) << y;
    }
}

TEST(Render, HuangMajorAxisFollowsTheCurveNormal) {
    // Huang's frame (x tangent, y major axis) for a view in the renderer's frame: the major axis
    // is the normal's part across the tangent (Gram-Schmidt here; Cycles writes a double cross
    // product), rotated into the frame built from the tangent and the view.
    const auto fiber = huang_fiber(0.5f);
    SurfacePoint sp;
    sp.tangent = safe_normalize(Vec3{1.0f, 0.2f, -0.3f});
    sp.normal = safe_normalize(cross(sp.tangent, Vec3{0.3f, 1.0f, 0.4f}));
    const Vec3 n{0.4f, -0.7f, 1.3f};  // not unit, not perpendicular
    sp.curve_normal = n;
    sp.curve_radius = 0.01f;
    const Vec3 wo = safe_normalize(Vec3{-0.2f, 0.5f, 0.9f});
    const FiberHit hit = cycles_fiber_hit(sp, wo, false, 0.0f, 7);
    const Vec3 x = sp.tangent;
    const Vec3 y = safe_normalize(n - x * dot(n, x)), z = cross(x, y);
    const HuangPoint point = fiber->at(hit);
    const HuangHit hh = point.huang_hit();
    expect_vec(hh.wo, {dot(wo, x), dot(wo, y), dot(wo, z)}, 2e-6f, "ω_o in Huang's frame");
    ASSERT_GT(dot(sp.normal, wo), 0.0f);  // front-facing: the frame's x is the tangent
    // Cycles' h = dot(cross(Ng, X), Z) = −Ng·Y.
    EXPECT_NEAR(hh.h, -dot(sp.normal, safe_normalize(cross(sp.tangent, wo))), 1e-6f);
    EXPECT_EQ(hit.pixel_coverage, 1.0f);  // not a camera ray
    EXPECT_EQ(hit.seed, 7u);
}

TEST(Render, HuangFallbackFrameWithoutCurveNormals) {
    // Cycles' make_orthonormals(tangent): c = normalize((1, 1, 1) × t) (with (−1, 1, 1) and the
    // middle component negated when t's components are equal), major axis t × c. Closed forms
    // for two tangents; a normal along the tangent falls back the same way; at a back-facing
    // hit the tangent is reversed first (make_orthonormals((0, 0, −1)) has the axis (1, 1, 0)/√2).
    const auto fiber = huang_fiber(0.85f);
    struct Case {
        Vec3 tangent, axis, normal;
        bool back;
    };
    const float r2 = 1.0f / std::sqrt(2.0f), r3 = 1.0f / std::sqrt(3.0f), r6 = 1.0f / std::sqrt(6.0f);
    const Case cases[] = {{{0, 0, 1}, {r2, r2, 0}, {0, 0, 0}, false},
                          {{r3, r3, r3}, {-2 * r6, r6, r6}, {0, 0, 0}, false},
                          {{0, 0, 1}, {r2, r2, 0}, {0, 0, 2}, false},
                          {{0, 0, 1}, {r2, r2, 0}, {0, 0, 0}, true}};
    for (const Case &c : cases) {
        const Vec3 wo = safe_normalize(Vec3{0.3f, -0.8f, 0.2f});
        SurfacePoint sp;
        sp.tangent = c.tangent;
        sp.curve_normal = c.normal;
        const Vec3 facing = safe_normalize(wo - c.tangent * dot(wo, c.tangent));
        sp.normal = c.back ? -facing : facing;
        const FiberHit hit = cycles_fiber_hit(sp, wo, false, 0.0f, 0);
        const Vec3 x = c.back ? -c.tangent : c.tangent, y = c.axis, z = cross(x, y);
        expect_vec(fiber->at(hit).huang_hit().wo, {dot(wo, x), dot(wo, y), dot(wo, z)}, 2e-6f,
                   c.back ? "fallback frame, back-facing" : "fallback frame");
    }
}

TEST(Render, PixelCoverageIsHalfTheFootprintInRadii) {
    SurfacePoint sp;
    sp.tangent = {1, 0, 0};
    sp.normal = {0, 0, 1};
    sp.curve_radius = 0.004f;
    const FiberHit camera = cycles_fiber_hit(sp, {0, 0, 1}, true, 0.002f, 0);
    EXPECT_FLOAT_EQ(camera.pixel_coverage, 0.25f);
    EXPECT_EQ(cycles_fiber_hit(sp, {0, 0, 1}, false, 0.002f, 0).pixel_coverage, 1.0f);
    sp.curve_radius = 0.0f;  // a closed tip: never near field
    EXPECT_TRUE(std::isinf(cycles_fiber_hit(sp, {0, 0, 1}, true, 0.002f, 0).pixel_coverage));

    // In a scene: a fiber of radius r under a perspective camera at height 5, hit on its top by
    // the ray through the image centre at t = 5 − r, whose footprint is the chord of one
    // pixel's angle times t (camera_test's closed form).
    const float r = 0.05f;
    SceneDesc d;
    d.materials = {huang_hair(1.0f)};
    d.curves = {straight_hair(0.0f, 0.0f, r, 2.0f)};
    d.camera = perspective({0, 0, 5}, 0.25f, 40, 40);
    const Scene scene = build(std::move(d));
    const std::optional<FiberHit> hit = camera_hair_hit(scene, 20, 20, 0.0f, 0.0f);
    ASSERT_TRUE(hit.has_value());
    const double step = 0.5 / 40.0;
    const double spread = std::sqrt(2.0 - 2.0 / std::sqrt(step * step + 1.0));
    EXPECT_NEAR(hit->pixel_coverage, 0.5 * spread * (5.0 - r) / r, 1e-4 * hit->pixel_coverage);
    EXPECT_NEAR(hit->h, 0.0f, 1e-3f);
}

// The hair's share of an orthographic image with a transparent film: the mean alpha.
double hair_coverage(const std::vector<HairCurves> &curves, float aspect_ratio, int max_transparent,
                     TransparentLimit limit = TransparentLimit::PlusOne) {
    SceneDesc d;
    d.materials = {huang_hair(aspect_ratio)};
    d.curves = curves;
    d.camera = ortho_down(1.0f, 1.0f, 32, 32, {0, 0, 5});
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.samples = 32;
    s.max_bounces = 0;
    s.film_transparent = true;
    s.max_transparent_bounces = max_transparent;
    s.transparent_limit = int(limit);
    const auto img = render_ok(scene, s);
    double alpha = 0;
    for (std::size_t i = 3; i < img.size(); i += 4) alpha += img[i];
    return alpha / (32.0 * 32.0);
}

TEST(Render, HuangIsTransparentOutsideItsEllipse) {
    // Seen along its major axis (the curve normal on the view), an elliptical fiber of aspect b
    // covers b of its round tube's width 2r (Cycles' transparent closure beyond the projected
    // radius R = b); seen across it, all of it. Orthographic, across a frame of 2 x 2: the mean
    // alpha is the covered width over 2.
    const float r = 0.2f, b = 0.5f;
    HairCurves along = straight_hair(0.0f, 0.0f, r, 3.0f);
    along.normals.assign(along.points.size(), Vec3{0, 0, 1});
    HairCurves across = along;
    across.normals.assign(across.points.size(), Vec3{0, 1, 0});
    const double tolerance = 0.01;  // stratified pixel jitter: the edges' error is far smaller
    EXPECT_NEAR(hair_coverage({along}, b, 8), r * b, tolerance * r);
    EXPECT_NEAR(hair_coverage({across}, b, 8), r, tolerance * r);
    EXPECT_NEAR(hair_coverage({along}, 1.0f, 8), r, tolerance * r);
}

// Three straight fibers of radius r stacked one unit apart under the camera, major axis on z.
std::vector<HairCurves> stacked_fibers(float r) {
    std::vector<HairCurves> stack;
    for (int k = 0; k < 3; ++k) {
        HairCurves c = straight_hair(0.0f, -float(k), r, 3.0f);
        c.normals.assign(c.points.size(), Vec3{0, 0, 1});
        stack.push_back(c);
    }
    return stack;
}

TEST(Render, TransparentCrossingsStopAfterTheLimit) {
    // Three such fibers stacked under the camera: a ray outside the ellipses crosses all three
    // (and escapes: alpha 0) when max_transparent_bounces allows 3 crossings (limit 2, Cycles'
    // setting + 1), but ends on the third fiber (alpha 1) when it allows 2.
    const float r = 0.2f, b = 0.5f;
    const std::vector<HairCurves> stack = stacked_fibers(r);
    EXPECT_NEAR(hair_coverage(stack, b, 2), r * b, 0.01 * r);
    EXPECT_NEAR(hair_coverage(stack, b, 1), r, 0.01 * r);
}

TEST(Render, Cycles50TransparentLimitIsTheSetting) {
    // The same stack under transparent_limit=setting (Cycles 5.0 stores the setting itself):
    // 3 allows the 3 crossings (alpha r·b), 2 ends on the third fiber (alpha r); 0 and 1 both
    // allow one crossing (the second fiber ends the ray), as Cycles 5.0's path state does.
    const float r = 0.2f, b = 0.5f;
    const std::vector<HairCurves> stack = stacked_fibers(r);
    const TransparentLimit setting = TransparentLimit::Setting;
    EXPECT_NEAR(hair_coverage(stack, b, 3, setting), r * b, 0.01 * r);
    EXPECT_NEAR(hair_coverage(stack, b, 2, setting), r, 0.01 * r);
    const std::vector<HairCurves> two(stack.begin(), stack.begin() + 2);
    EXPECT_NEAR(hair_coverage(two, b, 1, setting), r, 0.01 * r);
    EXPECT_NEAR(hair_coverage(two, b, 0, setting), r, 0.01 * r);
    EXPECT_NEAR(hair_coverage(two, b, 2, setting), r * b, 0.01 * r);
}

TEST(Render, TransparentCrossingsFollowEachCyclesStorage) {
    EXPECT_EQ(transparent_crossings(TransparentLimit::PlusOne, 0), 1);
    EXPECT_EQ(transparent_crossings(TransparentLimit::PlusOne, 4), 5);
    EXPECT_EQ(transparent_crossings(TransparentLimit::Setting, 0), 1);
    EXPECT_EQ(transparent_crossings(TransparentLimit::Setting, 1), 1);
    EXPECT_EQ(transparent_crossings(TransparentLimit::Setting, 4), 4);
}

// A thin Huang fiber along x across an orthographic view down −z, narrower than the pixel
// footprint (far field), shaded by `model` (no lights yet).
SceneDesc thin_fiber_scene(std::shared_ptr<const ShadingModel> model) {
    SceneDesc d;
    d.materials = {HairMaterial{HairShading::create(std::move(model), std::make_shared<const UniformSampler>()).value()}};
    d.curves = {straight_hair(0.0f, 0.0f, 0.01f, 3.0f)};  // pixels 0.025 wide: pixel_coverage 1.25
    d.camera = ortho_down(0.05f, 0.05f, 4, 4, {0, 0, 5});
    return d;
}

// Direct light only, transparent film: the green radiance over the alpha of the hair pixels,
// over the whole image (mean) and per pixel covered by at least 5% (low, high).
struct HairRadiance {
    double mean = 0, low = 1e300, high = -1e300;
};
HairRadiance direct_hair_radiance(const Scene &scene, int samples, HuangSampling sampling, std::uint64_t seed) {
    RenderSettings s;
    s.samples = samples;
    s.max_bounces = 0;
    s.film_transparent = true;
    s.huang_sampling = int(sampling);
    s.seed = seed;
    const auto img = render_ok(scene, s);
    HairRadiance out;
    double radiance = 0, alpha = 0;
    for (std::size_t i = 0; i < img.size(); i += 4) {
        radiance += img[i + 1];
        alpha += img[i + 3];
        if (img[i + 3] < 0.05f) continue;
        const double ratio = img[i + 1] / img[i + 3];
        out.low = std::min(out.low, ratio);
        out.high = std::max(out.high, ratio);
    }
    out.mean = radiance / alpha;
    return out;
}

// A thin clear Huang fiber (σ = 0, α = 0.3, aspect 1, offset 2°) in a white world: the radiance
// over the alpha of the hair pixels is the far field's albedo from this view. Returns its mean
// over `seeds` renders and the standard error of that mean.
struct FurnaceEstimate {
    double mean = 0, standard_error = 0;
};
FurnaceEstimate huang_furnace(const std::shared_ptr<const HuangFiber> &fiber, HuangSampling huang_sampling, int seeds) {
    SceneDesc d = thin_fiber_scene(fiber);
    d.world = {Rgb(1.0f), 1.0f};
    const Scene scene = build(std::move(d));
    std::vector<double> ratios;
    for (int seed = 0; seed < seeds; ++seed)
        ratios.push_back(direct_hair_radiance(scene, 4096, huang_sampling, std::uint64_t(seed)).mean);
    double mean = 0, var = 0;
    for (double r : ratios) mean += r / double(seeds);
    for (double r : ratios) var += sqr(r - mean) / double(seeds - 1);
    return {mean, std::sqrt(var / double(seeds))};
}

TEST(Render, HuangFurnaceFollowsEvalOrCyclesSampler) {
    // The strategy's sampling (uniform) converges to Cycles' eval: the far field's albedo by
    // quadrature. Cycles' own sampling converges to what Cycles renders for this furnace:
    // 1.007 (docs/huang.md §14, bpy 4.5: Cycles' sampler, whose albedo is not its eval's).
    HuangParams p;
    p.sigma_a = Rgb(0.0f);
    p.aspect_ratio = 1.0f;
    auto fiber = std::make_shared<const HuangFiber>(HuangFiber::create(p).value());
    // ∫ f dω_i of the far field seen along −z across a fiber along x, in Huang's frame
    // (circular: y = normalize(tangent × ω_o)), by a product Gauss rule in (sin θ_i, φ_i).
    const HuangExpectation far = fiber->expectation({{0.0f, 0.0f, -1.0f}, 0.0f, 1.0f});
    const double albedo = testing::integrate_fiber_sphere([&](Vec3 wi) { return far.f(wi).g; });
    EXPECT_GT(albedo, 1.3);  // the edges' overweight (docs/huang.md §6)
    const FurnaceEstimate eval_mode = huang_furnace(fiber, HuangSampling::Strategy, 6);
    EXPECT_NEAR(eval_mode.mean, albedo, 4.0 * eval_mode.standard_error + 0.005 * albedo)
        << "standard error " << eval_mode.standard_error;
    const FurnaceEstimate cycles_mode = huang_furnace(fiber, HuangSampling::Cycles, 6);
    EXPECT_NEAR(cycles_mode.mean, 1.007, 4.0 * cycles_mode.standard_error + 0.01)
        << "standard error " << cycles_mode.standard_error;
}

// The thin fiber under a sun, direct light only: every hair sample is f·E at the sun's ω_i, so
// radiance / alpha is f there.
HairRadiance sunlit_fiber(std::shared_ptr<const ShadingModel> model, Vec3 to_sun, HuangSampling sampling,
                          std::uint64_t seed) {
    SceneDesc d = thin_fiber_scene(std::move(model));
    testing::set_sun(d, to_sun, 2.0f);
    return direct_hair_radiance(build(std::move(d)), 64, sampling, seed);
}

TEST(Render, HuangCyclesSamplingShadesLightSamplesWithTheBakedF) {
    // With Cycles' own Huang sampling, a material whose table holds a baked f shades light
    // samples with it (the expectation of Cycles' eval, huang_tabulated_fiber_test), as the
    // strategy's sampling does: under a sun, direct light only, both images are the baked f,
    // the same at every sample of every seed, where Cycles' one-sample eval is noisy.
    HuangParams p;
    p.sigma_a = principled_hair::sigma_from_reflectance({0.55f, 0.4f, 0.25f}, 0.3f);
    auto fiber = std::make_shared<const HuangFiber>(HuangFiber::create(p).value());
    const HuangBakeOptions o = testing::small_huang_bake();
    auto table = std::make_shared<const HuangSamplingTable>(
        HuangSamplingTable::from(bake_huang_table(*fiber, o).value()).value());
    auto tabulated = std::make_shared<const HuangTabulatedFiber>(HuangTabulatedFiber::create(fiber, table).value());
    // Lit from behind (TT), from the side (TRT and R) and from the front (R).
    for (const Vec3 to_sun : {safe_normalize(Vec3{0.2f, 0.1f, -1.0f}), safe_normalize(Vec3{0.3f, 0.9f, 0.3f}),
                              safe_normalize(Vec3{-0.4f, 0.2f, 0.9f})}) {
        for (std::uint64_t seed = 0; seed < 4; ++seed) {
            const HairRadiance baked = sunlit_fiber(tabulated, to_sun, HuangSampling::Cycles, seed);
            const HairRadiance strategy = sunlit_fiber(tabulated, to_sun, HuangSampling::Strategy, seed);
            EXPECT_GT(baked.mean, 0.0) << "to_sun " << to_sun.z;
            EXPECT_NEAR(baked.low, baked.high, 1e-4 * baked.high) << "to_sun " << to_sun.z << ", seed " << seed;
            EXPECT_NEAR(baked.mean, strategy.mean, 1e-4 * strategy.mean) << "to_sun " << to_sun.z << ", seed " << seed;
            const HairRadiance cycles = sunlit_fiber(fiber, to_sun, HuangSampling::Cycles, seed);
            EXPECT_GT(cycles.high - cycles.low, 0.02 * cycles.mean) << "to_sun " << to_sun.z << ", seed " << seed;
        }
    }
}

TEST(Render, MaxBouncesCountLikeCycles) {
    // Camera between an infinite white-ish floor (albedo a_f) and an emissive, reflective
    // ceiling (emission L_e, albedo a_c). Light reaching the floor after j round trips needs
    // 2j shaded bounces, so L(k) = a_f L_e Σ_{j ≤ k/2} (a_f a_c)^j: 0 and 1 bounce give the
    // same (direct light only at 0, as in Cycles), 2 adds one round trip.
    const float af = 0.8f, ac = 0.5f, le = 1.0f;
    SceneDesc d;
    d.materials = {DiffuseMaterial{Rgb(af), Rgb(0.0f)}, DiffuseMaterial{Rgb(ac), Rgb(le)}};
    d.meshes = {quad(400.0f, 0.0f, 0), quad(400.0f, 2.0f, 1, false)};
    d.camera = ortho_down(0.5f, 0.5f, 4, 4, {0, 0, 1});
    const Scene scene = build(std::move(d));
    auto mean_of = [&](int bounces, int rr_start, int diffuse = 1024) {
        RenderSettings s;
        s.max_bounces = bounces;
        s.max_diffuse_bounces = diffuse;
        s.rr_start_bounce = rr_start;
        return estimate(scene, s, 1, 2, 6000);
    };
    for (int k : {0, 1, 2, 3, 4}) {
        double expected = 0;
        for (int j = 0; 2 * j <= k; ++j) expected += af * le * std::pow(af * ac, j);
        const PixelEstimate p = mean_of(k, 100);
        EXPECT_NEAR(p.mean, expected, 5.0 * p.sigma / std::sqrt(6000.0) + 2e-3 * expected)
            << "max_bounces " << k;
    }
    // The diffuse limit counts the same way (all bounces here are diffuse).
    {
        const PixelEstimate limited = mean_of(12, 100, 2);
        const double expected = af * le * (1.0 + af * ac);
        EXPECT_NEAR(limited.mean, expected,
                    5.0 * limited.sigma / std::sqrt(6000.0) + 2e-3 * expected);
    }
    // Russian roulette does not change the expectation.
    const PixelEstimate no_rr = mean_of(8, 100), rr = mean_of(8, 1);
    EXPECT_NEAR(no_rr.mean, rr.mean,
                4.5 * std::sqrt((no_rr.sigma * no_rr.sigma + rr.sigma * rr.sigma) / 6000.0));
}

// Cycles' Film > Exposure scales the image's light when it is read out; alpha stays coverage.
TEST(Render, ExposureScalesTheLightAndNotTheAlpha) {
    SceneDesc d;
    d.materials = {DiffuseMaterial{Rgb(0.7f), Rgb(0.0f)}};
    d.meshes = {sphere(1.0f, 12, 24, 0)};
    d.world = {Rgb(0.4f, 0.5f, 0.6f), 1.0f};
    d.camera = perspective({0, 0, 4}, 0.35f, 8, 8);
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.samples = 4;
    s.film_transparent = true;
    const auto plain = render_ok(scene, s);
    s.exposure = 2.5f;
    const auto bright = render_ok(scene, s);
    int covered = 0, empty = 0;
    for (std::size_t i = 0; i < plain.size(); i += 4) {
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(bright[i + c], 2.5f * plain[i + c], 1e-6f * (1.0f + plain[i + c]));
        EXPECT_EQ(bright[i + 3], plain[i + 3]);
        (plain[i + 3] > 0.0f ? covered : empty) += 1;
    }
    EXPECT_GT(covered, 0);
    EXPECT_GT(empty, 0);
}

TEST(Render, ImageIsWrittenBottomRowFirst) {
    // An emitter covering only the upper half of an orthographic view (camera space y > 0).
    SceneDesc d;
    d.materials = {DiffuseMaterial{Rgb(0.0f), Rgb(2.0f)}};
    TriangleMesh m;
    m.positions = {{-1, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 1, 0}};
    m.indices = {0, 1, 2, 0, 2, 3};
    d.meshes = {m};
    d.camera = ortho_down(1, 1, 4, 6);
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.samples = 4;
    const auto img = render_ok(scene, s);
    for (int y = 0; y < 6; ++y)
        for (int x = 0; x < 4; ++x) {
            EXPECT_FLOAT_EQ(at(img, 4, x, y, 0), y >= 3 ? 2.0f : 0.0f) << x << "," << y;
            EXPECT_FLOAT_EQ(at(img, 4, x, y, 3), 1.0f);
        }
}

SceneDesc hair_tuft_desc(int width, int height, int curves = 64) {
    const auto fiber = fiber_with(Rgb(0.3f, 0.6f, 1.2f));
    SceneDesc d;
    d.materials = {hair(fiber, std::make_shared<const AnalyticSampler>(fiber)),
                   DiffuseMaterial{Rgb(0.5f), Rgb(0.0f)}};
    d.curves = {tuft(curves, 8, 0.01f)};
    d.meshes = {quad(3.0f, 0.0f, 1)};
    d.world = {Rgb(0.2f, 0.25f, 0.3f), 1.0f};
    testing::set_sun(d, safe_normalize(Vec3{0.4f, -0.3f, 1.0f}), 3.0f, float(radians(2.0)));
    d.point_lights = {{Vec3{1, 1, 2}, Rgb(1.0f, 0.9f, 0.8f), 200.0f, 0.2f}};
    // Looking at the tuft from the side and above.
    CameraDesc c = perspective({0, 0, 0}, 0.45f, width, height);
    const float v[16] = {1, 0, 0, 0,        //
                         0, 0.8f, -0.6f, -3.0f,  //
                         0, 0.6f, 0.8f, 2.8f,   //
                         0, 0, 0, 1};
    c.camera_to_world = Mat4::from_row_major(v);
    d.camera = c;
    return d;
}

Scene hair_tuft_scene(int width, int height, int curves = 64) { return build(hair_tuft_desc(width, height, curves)); }

// New materials, lights and world on a built scene render what a build of the whole new scene
// renders, to the bit.
TEST(Render, SetShadingRendersAsABuildOfTheNewScene) {
    SceneDesc changed = hair_tuft_desc(24, 20);
    const auto blond = fiber_with(Rgb(0.1f, 0.2f, 0.4f));
    changed.materials = {hair(blond, std::make_shared<const AnalyticSampler>(blond)),
                         DiffuseMaterial{Rgb(0.3f), Rgb(1.0f, 0.5f, 0.2f)}};  // the quad glows now
    changed.world = {Rgb(0.05f, 0.1f, 0.2f), 2.0f};
    changed.suns[0].strength = 1.0f;
    changed.point_lights.clear();
    const Scene fresh = build(changed);
    Scene updated = hair_tuft_scene(24, 20);
    RenderSettings s;
    s.samples = 4;
    s.threads = 2;
    const std::vector<float> before = render_ok(updated, s);
    const Status st = updated.set_shading(changed);
    ASSERT_FALSE(st) << st->message;
    EXPECT_EQ(updated.stats().emissive_triangles, fresh.stats().emissive_triangles);
    EXPECT_EQ(updated.stats().lamps, fresh.stats().lamps);
    const std::vector<float> after = render_ok(updated, s), want = render_ok(fresh, s);
    EXPECT_TRUE(same_bits(after, want));
    EXPECT_FALSE(same_bits(after, before));
}

TEST(Render, BitIdenticalWhateverTheThreadCount) {
    const Scene scene = hair_tuft_scene(24, 20);
    RenderSettings s;
    s.samples = 4;
    s.seed = 1234;
    s.threads = 1;
    const auto one = render_ok(scene, s);
    s.threads = 2;
    const auto two = render_ok(scene, s);
    s.tile_size = 5;  // another tile schedule
    const auto tiles = render_ok(scene, s);
    ASSERT_EQ(one.size(), two.size());
    EXPECT_TRUE(same_bits(one, two));
    EXPECT_TRUE(same_bits(one, tiles));
    s.seed = 1235;
    const auto other = render_ok(scene, s);
    EXPECT_FALSE(same_bits(one, other));
    double sum = 0;
    for (std::size_t i = 0; i < one.size(); ++i) sum += one[i];
    EXPECT_GT(sum, 0.0);
}

TEST(Render, CancelStopsPromptlyAndSaysSo) {
    const Scene scene = hair_tuft_scene(64, 64);
    RenderSettings s;
    s.samples = 1 << 20;  // hours of work
    s.threads = 2;
    std::vector<float> rgba(64 * 64 * 4, -1.0f);
    RenderStats stats;
    // Cancel at the first call.
    auto t0 = std::chrono::steady_clock::now();
    Status st = render(scene, s, rgba.data(), [](float) { return false; }, &stats);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_TRUE(st.has_value());
    EXPECT_EQ(st->message.rfind("cancelled", 0), 0u) << st->message;
    EXPECT_TRUE(stats.cancelled);
    EXPECT_LT(stats.progress, 1.0f);
    EXPECT_LT(seconds, 1.0);
    for (float v : rgba) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);

    // Cancel once some work is done: render() returns well under a second later.
    std::chrono::steady_clock::time_point cancelled_at{};
    float last = 0;
    int calls = 0;
    st = render(
        scene, s, rgba.data(),
        [&](float p) {
            ++calls;
            last = p;
            if (p > 0.0f || calls > 40) {
                cancelled_at = std::chrono::steady_clock::now();
                return false;
            }
            return true;
        },
        &stats);
    const double latency =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - cancelled_at).count();
    ASSERT_TRUE(st.has_value());
    EXPECT_TRUE(stats.cancelled);
    EXPECT_LT(latency, 0.5);
    EXPECT_LT(stats.progress, 0.01f);
    EXPECT_GT(stats.camera_rays, 0u);
    double sum = 0;
    for (std::size_t i = 0; i < rgba.size(); i += 4) sum += rgba[i + 3];
    EXPECT_GT(sum, 0.0);  // finished samples were written
}

// ---- Progressive rendering -------------------------------------------------------------------

// The image as a non-progressive renderer makes it: each pixel's samples 0..n-1 summed in
// double in sample order, times 1/n.
std::vector<float> per_sample_reference(const Scene &scene, const RenderSettings &s) {
    const int w = scene.camera().width(), h = scene.camera().height();
    std::vector<float> rgba(std::size_t(w) * std::size_t(h) * 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double sum[4] = {0, 0, 0, 0};
            for (int k = 0; k < s.samples; ++k) {
                float alpha = 1.0f;
                const Rgb l = render_sample(scene, s, x, y, std::uint64_t(k), &alpha);
                sum[0] += l.r;
                sum[1] += l.g;
                sum[2] += l.b;
                sum[3] += alpha;
            }
            const double inv = 1.0 / double(s.samples);
            for (int c = 0; c < 4; ++c) rgba[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 4 + std::size_t(c)] = float(sum[c] * inv);
        }
    return rgba;
}

std::vector<float> render_rounds(const Scene &scene, const RenderSettings &s, const RoundSchedule &schedule,
                                 const UpdateFn &update = {}, RenderStats *stats = nullptr) {
    std::vector<float> rgba(std::size_t(scene.camera().width()) * scene.camera().height() * 4, -1.0f);
    const Status st = render_progressive(scene, s, rgba.data(), nullptr, update, stats, schedule);
    EXPECT_FALSE(st.has_value()) << (st ? st->message : "");
    return rgba;
}

TEST(Progressive, RoundsGiveTheOneRoundImageBitForBit) {
    const Scene scene = hair_tuft_scene(12, 10);
    RenderSettings s;
    s.samples = 5;
    s.seed = 77;
    s.threads = 2;
    s.tile_size = 4;
    const auto reference = per_sample_reference(scene, s);
    RoundSchedule one;
    one.one_round = true;
    EXPECT_TRUE(same_bits(render_rounds(scene, s, one), reference));
    RoundSchedule each;
    each.max_round_samples = 1;
    std::vector<int> seen;
    int finals = 0;
    const auto rounds = render_rounds(scene, s, each, [&](float, int done, bool final) {
        if (final) ++finals;
        else if (seen.empty() || seen.back() != done) seen.push_back(done);
        return true;
    });
    EXPECT_TRUE(same_bits(rounds, reference));
    EXPECT_EQ(finals, 1);
    // Every round but the last is shown (and 0 when a call came before the first round ended).
    if (!seen.empty() && seen.front() == 0) seen.erase(seen.begin());
    const std::vector<int> want{1, 2, 3, 4};
    EXPECT_EQ(seen, want);
    s.samples = 6;  // another image: the comparison can fail
    EXPECT_FALSE(same_bits(render_rounds(scene, s, one), reference));
}

TEST(Progressive, UpdateShowsTheAverageOfTheSamplesDone) {
    const Scene scene = hair_tuft_scene(10, 8);
    RenderSettings s;
    s.samples = 4;
    RoundSchedule each;
    each.max_round_samples = 1;
    std::vector<float> rgba(10 * 8 * 4), after_two;
    const Status st = render_progressive(scene, s, rgba.data(), nullptr, [&](float, int done, bool) {
        if (done == 2 && after_two.empty()) after_two = rgba;
        return true;
    }, nullptr, each);
    ASSERT_FALSE(st.has_value());
    s.samples = 2;
    EXPECT_TRUE(same_bits(after_two, per_sample_reference(scene, s)));
    EXPECT_FALSE(same_bits(after_two, rgba));
}

TEST(Progressive, CancelFromUpdateKeepsTheRoundsDone) {
    const Scene scene = hair_tuft_scene(10, 8);
    RenderSettings s;
    s.samples = 1 << 20;
    RoundSchedule each;
    each.max_round_samples = 1;
    std::vector<float> rgba(10 * 8 * 4);
    RenderStats stats;
    int finals = 0;
    const Status st = render_progressive(scene, s, rgba.data(), nullptr, [&](float, int done, bool final) {
        finals += final;
        return done < 3;
    }, &stats, each);
    ASSERT_TRUE(st.has_value());
    EXPECT_TRUE(stats.cancelled);
    EXPECT_EQ(finals, 1);
    EXPECT_GE(stats.samples, 3);
    EXPECT_LT(stats.samples, 100);
    s.samples = 3;
    const auto three = per_sample_reference(scene, s);
    // Pixels with exactly three samples are the 3-sample image's.
    EXPECT_EQ(stats.camera_rays, std::uint64_t(3 * 80)) << "cancelled between rounds";
    EXPECT_TRUE(same_bits(rgba, three));
}

TEST(Progressive, RegionPixelsAreTheFullRendersAndTheRestIsZero) {
    const Scene scene = hair_tuft_scene(14, 11);
    RenderSettings s;
    s.samples = 3;
    s.tile_size = 4;
    const auto full = render_ok(scene, s);
    s.region = {3, 2, 10, 7};
    RenderStats stats;
    const auto part = render_ok(scene, s, &stats);
    EXPECT_EQ(stats.camera_rays, std::uint64_t(7 * 5 * 3));
    for (int y = 0; y < 11; ++y)
        for (int x = 0; x < 14; ++x)
            for (int c = 0; c < 4; ++c) {
                const bool inside = x >= 3 && x < 10 && y >= 2 && y < 7;
                const float want = inside ? at(full, 14, x, y, c) : 0.0f;
                ASSERT_TRUE(same_bits(std::vector<float>{at(part, 14, x, y, c)}, std::vector<float>{want}))
                    << x << "," << y << "," << c;
            }
    std::vector<float> rgba(14 * 11 * 4);
    for (const std::vector<int> &bad : {std::vector<int>{3, 2, 3, 7}, {0, 0, 15, 11}, {1, 2, 3}}) {
        s.region = bad;
        const Status st = render(scene, s, rgba.data(), {}, nullptr);
        ASSERT_TRUE(st.has_value());
        EXPECT_NE(st->message.find("region"), std::string::npos) << st->message;
    }
}

// A scene that is the constant world everywhere: every sample of a pixel is the same.
Scene world_only(int w, int h) {
    SceneDesc d;
    d.materials = {DiffuseMaterial{}};
    d.meshes = {quad(0.1f, 0.0f, 0)};
    for (Vec3 &p : d.meshes[0].positions) p = p + Vec3{100, 0, 0};  // out of view
    d.world = {Rgb(0.3f, 0.4f, 0.5f), 1.0f};
    d.camera = ortho_down(1, 1, w, h);
    return build(std::move(d));
}

TEST(Progressive, AdaptiveSamplingChecksAsCyclesSchedules) {
    const Scene scene = world_only(6, 5);
    RenderSettings s;
    s.samples = 500;
    s.adaptive_threshold = 0.01f;
    RenderStats stats;
    render_ok(scene, s, &stats);
    // Cycles' automatic minimum for 0.01 is 64; the first check follows sample index
    // (64 + 1) | 15 = 79, where every pixel (no noise) stops.
    EXPECT_EQ(stats.samples, 80);
    EXPECT_EQ(stats.converged_pixels, 30u);
    EXPECT_EQ(stats.camera_rays, std::uint64_t(30 * 80));
    s.adaptive_min_samples = 20;  // first check after index (20 + 1) | 15 = 31
    render_ok(scene, s, &stats);
    EXPECT_EQ(stats.samples, 32);
    s.adaptive_threshold = 0;
    s.samples = 40;
    render_ok(scene, s, &stats);
    EXPECT_EQ(stats.samples, 40);
    EXPECT_EQ(stats.converged_pixels, 0u);
}

TEST(Progressive, AdaptiveSamplingStopsQuietPixelsFirstAndIsDeterministic) {
    const Scene scene = hair_tuft_scene(16, 12);
    RenderSettings s;
    s.samples = 256;
    s.adaptive_threshold = 0.05f;
    s.adaptive_min_samples = 16;
    s.threads = 1;
    RenderStats one_stats, two_stats;
    const auto one = render_ok(scene, s, &one_stats);
    s.threads = 2;
    s.tile_size = 5;
    const auto two = render_ok(scene, s, &two_stats);
    EXPECT_TRUE(same_bits(one, two));
    EXPECT_EQ(one_stats.camera_rays, two_stats.camera_rays);
    EXPECT_GT(one_stats.converged_pixels, 0u);
    EXPECT_LT(one_stats.camera_rays, std::uint64_t(16 * 12 * 256));
    s.adaptive_threshold = 0.0f;
    RenderStats full;
    render_ok(scene, s, &full);
    EXPECT_GT(full.camera_rays, one_stats.camera_rays);
}

TEST(Progressive, TimeLimitStopsAfterTheRoundThatPassesIt) {
    const Scene scene = hair_tuft_scene(16, 12);
    RenderSettings s;
    s.samples = 1 << 24;
    s.time_limit = 0.2;
    RenderStats stats;
    const auto t0 = std::chrono::steady_clock::now();
    const auto img = render_ok(scene, s, &stats);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_FALSE(stats.cancelled);
    EXPECT_GE(seconds, 0.2);
    EXPECT_LT(seconds, 2.0);
    EXPECT_GT(stats.samples, 0);
    EXPECT_LT(stats.samples, 1 << 24);
    EXPECT_EQ(stats.camera_rays, std::uint64_t(16 * 12) * std::uint64_t(stats.samples));
}

TEST(Progressive, DepthAndNormalPassesAsCyclesWritesThem) {
    // A quad facing up at z = 0.5 seen from z = 5 covers the middle of the image.
    SceneDesc d;
    d.materials = {DiffuseMaterial{}};
    d.meshes = {quad(0.5f, 0.5f, 0)};
    d.world = {Rgb(0.2f), 1.0f};
    d.camera = ortho_down(1, 1, 8, 8);
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.samples = 2;
    s.passes = "normal,depth";
    std::vector<float> rgba(8 * 8 * 4), passes(8 * 8 * 4, -1.0f);
    ASSERT_FALSE(render_progressive(scene, s, rgba.data(), passes.data(), {}, nullptr).has_value());
    const float *normal = passes.data(), *depth = passes.data() + 8 * 8 * 3;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            const std::size_t p = std::size_t(y) * 8 + std::size_t(x);
            const bool hit = x >= 2 && x < 6 && y >= 2 && y < 6;
            EXPECT_FLOAT_EQ(depth[p], hit ? 4.5f : 1e10f) << x << "," << y;
            EXPECT_FLOAT_EQ(normal[p * 3 + 2], hit ? 1.0f : 0.0f) << x << "," << y;
            EXPECT_FLOAT_EQ(normal[p * 3 + 0], 0.0f);
        }
    s.passes = "depth,nonsense";
    const Status st = render_progressive(scene, s, rgba.data(), passes.data(), {}, nullptr);
    ASSERT_TRUE(st.has_value());
    EXPECT_NE(st->message.find("nonsense"), std::string::npos);
    s.passes = "depth";
    EXPECT_TRUE(render_progressive(scene, s, rgba.data(), nullptr, {}, nullptr).has_value());
}

TEST(Progressive, DenoisingPassesOfADiffusePlaneAreItsAlbedoAndNormal) {
    // The quad of DepthAndNormalPasses, albedo (0.3, 0.5, 0.7), in a world of 0.2: Cycles'
    // denoising albedo is the closure weight on the quad and the world the camera sees around
    // it (0 with a transparent film); the normal is the quad's in camera space (z along the
    // view, so −1 facing the camera) and 0 around it.
    SceneDesc d;
    d.materials = {DiffuseMaterial{Rgb(0.3f, 0.5f, 0.7f)}};
    d.meshes = {quad(0.5f, 0.5f, 0)};
    d.world = {Rgb(0.2f), 1.0f};
    d.camera = ortho_down(1, 1, 8, 8);
    const Scene scene = build(std::move(d));
    for (const bool transparent : {false, true}) {
        RenderSettings s;
        s.samples = 4;
        s.film_transparent = transparent;
        s.passes = "denoising_albedo,denoising_normal";
        std::vector<float> rgba(8 * 8 * 4), passes(8 * 8 * 6, -1.0f);
        ASSERT_FALSE(render_progressive(scene, s, rgba.data(), passes.data(), {}, nullptr).has_value());
        const float *albedo = passes.data(), *normal = passes.data() + 8 * 8 * 3;
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) {
                const std::size_t p = std::size_t(y) * 8 + std::size_t(x);
                const bool hit = x >= 2 && x < 6 && y >= 2 && y < 6;
                const Rgb want = hit ? Rgb(0.3f, 0.5f, 0.7f) : Rgb(transparent ? 0.0f : 0.2f);
                for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(albedo[p * 3 + std::size_t(c)], want[c]) << x << "," << y;
                expect_vec({normal[p * 3], normal[p * 3 + 1], normal[p * 3 + 2]}, Vec3{0, 0, hit ? -1.0f : 0.0f},
                           1e-6f, "denoising normal");
            }
    }
}

// The denoising passes of the one pixel of a camera looking down at a hair along X through its
// axis (θ_o = 0, h within ±1% of 0), in a black world.
std::array<float, 6> strand_denoising_passes(HairMaterial material) {
    SceneDesc d;
    d.materials = {std::move(material)};
    d.curves = {straight_hair(0.0f, 0.0f, 0.1f, 1.0f)};
    d.world = {Rgb(0.0f), 1.0f};
    d.camera = ortho_down(0.001f, 0.001f, 1, 1);
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.samples = 4;
    s.passes = "denoising_albedo,denoising_normal";
    std::vector<float> rgba(4);
    std::array<float, 6> passes{};
    EXPECT_FALSE(render_progressive(scene, s, rgba.data(), passes.data(), {}, nullptr).has_value());
    return passes;
}

TEST(Progressive, DenoisingPassesOfAChiangStrandAreCyclesEstimate) {
    // Cycles' bsdf_hair_chiang_albedo: exp(−√σ · scale(v)) + F(cos θ_o cos γ_o) with v the
    // mapped longitudinal variance of the default Roughness 0.3 and scale its polynomial; the
    // normal is Y = cross(tangent, ω_o) = −y, perpendicular to the strand and the view.
    // Cycles 3.4's albedo (the tilt on θ_i) has no F term.
    const Rgb sigma(0.2f, 0.5f, 1.0f);
    for (const ChiangTilt tilt : {ChiangTilt::Incident, ChiangTilt::Outgoing}) {
        ChiangParams params;
        params.sigma_a = sigma;
        params.tilt = tilt;
        const auto fiber = std::make_shared<const ChiangFiber>(ChiangFiber::create(params).value());
        const std::array<float, 6> p =
            strand_denoising_passes(hair(fiber, std::make_shared<const AnalyticSampler>(fiber)));
        const double beta = 0.3, v = sqr(0.726 * beta + 0.812 * beta * beta + 3.7 * std::pow(beta, 20));
        const double scale = (((((0.245 * v) + 5.574) * v - 10.73) * v + 2.532) * v - 0.215) * v + 5.969;
        const double f0 = tilt == ChiangTilt::Outgoing ? sqr((1.55 - 1.0) / (1.55 + 1.0)) : 0.0;
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(p[std::size_t(c)], std::exp(-std::sqrt(double(sigma[c])) * scale) + f0, 1e-4)
                << chiang_tilt_name(tilt) << " " << c;
        expect_vec({p[3], p[4], p[5]}, Vec3{0, -1, 0}, 1e-4f, "Chiang denoising normal");
    }
}

TEST(Progressive, DenoisingPassesOfAHuangStrandAreCyclesEstimate) {
    // Cycles' bsdf_hair_huang_albedo seen perpendicularly through the axis: F = F0, the
    // refracted view crosses the diameter (A = exp(−2σ)), albedo (A − 2FA + F) / (1 − FA);
    // the normal is the tangent (+x, the curve's direction).
    const std::array<float, 6> p = strand_denoising_passes(huang_hair(1.0f));
    const Rgb sigma = HuangParams{}.sigma_a;
    const double f0 = sqr((1.55 - 1.0) / (1.55 + 1.0));
    for (int c = 0; c < 3; ++c) {
        const double a = std::exp(-2.0 * double(sigma[c]));
        EXPECT_NEAR(p[std::size_t(c)], (a - 2.0 * f0 * a + f0) / (1.0 - f0 * a), 1e-4) << c;
    }
    expect_vec({p[3], p[4], p[5]}, Vec3{1, 0, 0}, 1e-4f, "Huang denoising normal");
}

class NanPoint final : public SamplerPoint {
  public:
    std::optional<DirectionSample> sample(float u0, float u1, float) const override {
        const float z = 1.0f - 2.0f * u0, r = std::sqrt(std::max(0.0f, 1.0f - z * z));
        // A density so small that f/pdf overflows to infinity.
        return DirectionSample{{z, r * std::cos(6.2831853f * u1), r * std::sin(6.2831853f * u1)}, 1e-44f};
    }
    float pdf(Vec3) const override { return NAN; }
};

class NanSampler final : public Sampler {
  public:
    const SamplerPoint &at(const FiberHit &, const FiberPoint *, ScratchBuffer &scratch) const override {
        return scratch.make<NanPoint>();
    }
};

TEST(Render, NonFiniteContributionsAreDroppedAndCounted) {
    const auto fiber = fiber_with(Rgb(0.5f));
    SceneDesc d;
    d.materials = {hair(fiber, std::make_shared<NanSampler>())};
    d.curves = {parallel_hairs(3, 0.14f, 0.06f)};
    d.world = {Rgb(1.0f), 1.0f};
    d.camera = ortho_down(0.5f, 0.5f, 8, 8);
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.samples = 4;
    RenderStats stats;
    const auto img = render_ok(scene, s, &stats);
    EXPECT_GT(stats.dropped_samples, 0u);
    for (float v : img) ASSERT_TRUE(std::isfinite(v));
}

TEST(Render, RefusesInvalidSettings) {
    SceneDesc d;
    d.materials = {DiffuseMaterial{}};
    d.meshes = {quad(1.0f, 0.0f, 0)};
    d.camera = ortho_down(1, 1, 2, 2);
    const Scene scene = build(std::move(d));
    std::vector<float> rgba(16);
    RenderSettings s;
    s.samples = 0;
    auto st = render(scene, s, rgba.data(), {}, nullptr);
    ASSERT_TRUE(st.has_value());
    EXPECT_NE(st->message.find("samples"), std::string::npos);
    s = {};
    s.max_bounces = -1;
    st = render(scene, s, rgba.data(), {}, nullptr);
    ASSERT_TRUE(st.has_value());
    EXPECT_NE(st->message.find("max_bounces"), std::string::npos);
    st = render(scene, RenderSettings{}, nullptr, {}, nullptr);
    ASSERT_TRUE(st.has_value());
    EXPECT_NE(st->message.find("rgba"), std::string::npos);
}

// ---- Surface materials ------------------------------------------------------------------------

// An orthographic camera looking at the origin along −ω (ω in the XZ plane at `tilt` from +Z).
CameraDesc ortho_towards(double tilt, float half, int w, int h) {
    CameraDesc c = ortho_down(half, half, w, h, {0, 0, 0});
    const Vec3 from{float(5.0 * std::sin(tilt)), 0.0f, float(5.0 * std::cos(tilt))};
    c.camera_to_world = Mat4::translation(from) * euler_xyz_rotation({0.0f, float(tilt), 0.0f});
    return c;
}

// A quad in z = 0 whose UV map spans [0, 1]² over x, y ∈ [−half, half].
TriangleMesh uv_quad(float half, std::uint32_t material) {
    TriangleMesh m = quad(half, 0.0f, material);
    const float corner_uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (std::uint32_t i : m.indices) m.uvs.insert(m.uvs.end(), {corner_uv[i][0], corner_uv[i][1]});
    return m;
}

Material surface(std::vector<SurfaceNode> nodes) {
    Expected<SurfaceMaterial> m = SurfaceMaterial::create(std::move(nodes));
    EXPECT_TRUE(m) << (m ? "" : m.error().message);
    return std::move(m).value();
}

TEST(Render, DenoisingPassesLookThroughAMirror) {
    // A sharp Glossy BSDF of colour C is specular for the denoising passes: they look on
    // through it with throughput C and meet the world W, which Cycles adds as throughput ×
    // its contribution (itself C·W): albedo C²·W, and no vertex writes a normal. A rough
    // one (roughness 0.5, α² > 0.075²) is where they stop: albedo C, normal (0, 0, −1).
    const Rgb c(0.9f, 0.6f, 0.3f), world(0.5f);
    for (const float roughness : {0.0f, 0.5f}) {
        GlossyBsdfNode glossy;
        glossy.color.value = c;
        glossy.roughness = roughness;
        SceneDesc d;
        d.materials = {surface({glossy})};
        d.meshes = {quad(10.0f, 0.5f, 0)};
        d.world = {world, 1.0f};
        d.camera = ortho_down(1, 1, 2, 2);
        const Scene scene = build(std::move(d));
        RenderSettings s;
        s.samples = 4;
        s.passes = "denoising_albedo,denoising_normal";
        std::vector<float> rgba(2 * 2 * 4), passes(2 * 2 * 6, -1.0f);
        ASSERT_FALSE(render_progressive(scene, s, rgba.data(), passes.data(), {}, nullptr).has_value());
        const Rgb want = roughness == 0.0f ? c * c * world : c;
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(passes[std::size_t(k)], want[k], 1e-5) << roughness;
        const float *normal = passes.data() + 2 * 2 * 3;
        expect_vec({normal[0], normal[1], normal[2]}, Vec3{0, 0, roughness == 0.0f ? 0.0f : -1.0f}, 1e-6f,
                   "denoising normal");
    }
}

TEST(Render, TexturedDiffusePlaneUnderTheSun) {
    // A 2 × 2 texture (Closest) on a Diffuse BSDF lit from straight above by a delta sun of
    // strength E: every pixel sees its texel's colour × E / π, exactly (no noise: one light, a
    // black world, direct light only).
    const std::vector<float> rgb = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f, 0.3f, 0.6f, 0.9f};
    ImageTextureDesc t;
    t.image = std::make_shared<const EnvironmentImage>(EnvironmentImage::create(2, 2, rgb).value());
    t.interpolation = TextureInterpolation::Closest;
    DiffuseBsdfNode node;
    node.color.texture = std::make_shared<const ImageTexture>(ImageTexture::create(t).value());
    SceneDesc d;
    d.materials = {surface({node})};
    d.meshes = {uv_quad(1.0f, 0)};
    d.suns = {SunLight{Vec3{0, 0, 1}, Rgb(1.0f), 3.0f, 0.0f}};
    d.camera = ortho_down(0.8f, 0.8f, 8, 8);
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.samples = 4;
    s.max_bounces = 0;
    const auto img = render_ok(scene, s);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            const int texel = (y >= 4 ? 2 : 0) + (x >= 4 ? 1 : 0);  // rows bottom first
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(at(img, 8, x, y, c), rgb[std::size_t(texel * 3 + c)] * 3.0 / kPiD, 1e-5)
                    << x << "," << y;
        }
}

// Cycles 3.4's Principled closures (diffuse + GGX with the interpolated Fresnel), written out in
// double precision from their formulas: f·cos θ_i for one channel.
double principled_34_reference(double base, double metallic, double specular, double roughness,
                               Vec3 wo_f, Vec3 wi_f) {
    const double wo[3] = {wo_f.x, wo_f.y, wo_f.z}, wi[3] = {wi_f.x, wi_f.y, wi_f.z};
    const double co = wo[2], ci = wi[2];
    const double oi = wo[0] * wi[0] + wo[1] * wi[1] + wo[2] * wi[2];
    auto schlick = [](double c) { return std::pow(1.0 - c, 5.0); };
    const double rr = roughness * (oi + 1.0);
    const double fo = schlick(co), fi = schlick(ci);
    const double diffuse = (1.0 - metallic) * base * ci / kPiD *
                           ((1.0 - 0.5 * fo) * (1.0 - 0.5 * fi) + rr * (fi + fo + fi * fo * (rr - 1.0)));
    // h = (ω_o + ω_i)/|ω_o + ω_i|: cos θ_h and ω_i·h.
    const double len = std::sqrt(2.0 + 2.0 * oi);
    const double hz = (co + ci) / len, ih = (1.0 + oi) / len;
    const double a2 = std::pow(roughness, 4.0);
    const double d = a2 / (kPiD * std::pow(1.0 - hz * hz + a2 * hz * hz, 2.0));
    auto g1 = [&](double c) { return 2.0 / (1.0 + std::sqrt(1.0 + a2 * (1.0 - c * c) / (c * c))); };
    const double eta = 2.0 / (1.0 - std::sqrt(0.08 * specular)) - 1.0;
    const double f0 = fresnel_dielectric(1.0, eta);
    const double s = (fresnel_dielectric(ih, eta) - f0) / (1.0 - f0);
    const double cspec0 = std::min(1.0, 0.08 * specular * (1.0 - metallic) + base * metallic);
    const double f = cspec0 * (1.0 - s) + s;
    return diffuse + f * d * g1(co) * g1(ci) / (4.0 * co);
}

TEST(Render, Principled34PlaneUnderADeltaSunMatchesItsFormula) {
    const double tilt = 0.7;
    PrincipledBsdfNode p;
    p.base_color.value = Rgb(0.8f, 0.5f, 0.2f);
    p.metallic = 0.3f;
    p.specular = 0.6f;
    p.roughness = 0.35f;
    SceneDesc d;
    d.materials = {surface({p})};
    d.meshes = {quad(3.0f, 0.0f, 0)};
    const Vec3 to_sun = safe_normalize(Vec3{-0.5f, 0.2f, 0.8f});
    d.suns = {SunLight{to_sun, Rgb(1.0f), 2.0f, 0.0f}};
    d.camera = ortho_towards(tilt, 0.5f, 4, 4);
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.samples = 2;
    s.max_bounces = 0;
    const auto img = render_ok(scene, s);
    const Vec3 wo{float(std::sin(tilt)), 0.0f, float(std::cos(tilt))};
    const float base[3] = {0.8f, 0.5f, 0.2f};
    for (int c = 0; c < 3; ++c) {
        const double expected = 2.0 * principled_34_reference(base[c], 0.3, 0.6, 0.35, wo, to_sun);
        EXPECT_NEAR(at(img, 4, 1, 2, c), expected, 2e-4 * expected) << "channel " << c;
    }
}

TEST(Render, Principled4UnderAWhiteWorldReflectsItsAlbedo) {
    // No lights: the constant world is found by BSDF sampling alone, so the pixel's expectation
    // is ∫ f cos over the hemisphere, here by an independent quadrature of the BSDF's eval.
    PrincipledBsdfNode p;
    p.cycles = CyclesVersion::V4_5;
    p.multiscatter = true;
    p.base_color.value = Rgb(0.7f, 0.5f, 0.3f);
    p.metallic = 0.4f;
    p.roughness = 0.3f;
    p.coat = 0.5f;
    p.coat_roughness = 0.1f;
    const Material m = surface({p});
    SceneDesc d;
    d.materials = {m};
    d.meshes = {quad(1000.0f, 0.0f, 0)};
    d.world = {Rgb(1.0f), 1.0f};
    const double tilt = 1.0;
    d.camera = ortho_towards(tilt, 0.5f, 2, 2);
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.max_bounces = 0;
    const Vec3 wo{float(std::sin(tilt)), 0.0f, float(std::cos(tilt))};
    const SurfaceBsdf b = std::get<SurfaceMaterial>(m).prepare({wo, Vec3{0, 0, 1}, Vec3{0, 0, 1}, 0, 0});
    const int n = 1 << 16;
    for (int c = 0; c < 3; ++c) {
        const double expected = testing::integrate_hemisphere([&](Vec3 wi) {
            float pdf;
            return double(b.eval(wi, pdf)[c]);
        });
        const PixelEstimate e = estimate(scene, s, 0, 1, n, c);
        EXPECT_NEAR(e.mean, expected, 4.0 * e.sigma / std::sqrt(double(n)) + 1e-5) << "channel " << c;
    }
}

TEST(Render, GlossyPlaneUnderASunDiscWithMis) {
    // A Glossy BSDF sees a sun of 12°: light sampling and BSDF sampling (which hits the disc
    // often at this roughness) combine by MIS. Reference: the disc quadrature of
    // f cos θ_i · L, L = E / (π tan²(a/2)) / cos³ θ over the disc of radius tan(a/2) at
    // distance 1 (Cycles 3.4's sun), so ∫ f cos θ_i L dω = E/(π R²) ∫_disc f cos θ_i dA.
    GlossyBsdfNode g;
    g.color.value = Rgb(1.0f);
    g.roughness = 0.25f;
    const Material m = surface({g});
    const double tilt = 0.5, angle = radians(12.0);
    const Vec3 to_sun = safe_normalize(Vec3{-0.45f, 0.05f, 0.9f});
    SceneDesc d;
    d.materials = {m};
    d.meshes = {quad(1000.0f, 0.0f, 0)};
    d.suns = {SunLight{to_sun, Rgb(1.0f), 1.5f, float(angle)}};
    d.camera = ortho_towards(tilt, 0.5f, 2, 2);
    const Scene scene = build(std::move(d));
    RenderSettings s;
    s.max_bounces = 0;
    const Vec3 wo{float(std::sin(tilt)), 0.0f, float(std::cos(tilt))};
    const SurfaceBsdf b = std::get<SurfaceMaterial>(m).prepare({wo, Vec3{0, 0, 1}, Vec3{0, 0, 1}, 0, 0});
    Vec3 e1, e2;
    orthonormal_basis(to_sun, e1, e2);
    const double radius = std::tan(0.5 * angle);
    const GaussLegendre &rule = GaussLegendre::rule(32);
    double integral = 0.0;
    rule.for_each(0.0, radius, [&](double r, double wr) {
        rule.for_each(0.0, kTwoPi, [&](double phi, double wp) {
            const Vec3 wi = safe_normalize(to_sun + e1 * float(r * std::cos(phi)) + e2 * float(r * std::sin(phi)));
            float pdf;
            integral += wr * wp * r * double(b.eval(wi, pdf).g);
        });
    });
    const double expected = 1.5 / (kPiD * radius * radius) * integral;
    const int n = 1 << 16;
    const PixelEstimate e = estimate(scene, s, 1, 1, n, 1);
    EXPECT_NEAR(e.mean, expected, 4.0 * e.sigma / std::sqrt(double(n)) + 1e-5);
}

TEST(Render, HairThroughput) {
    // Not a pass/fail check of speed: reports samples per second on a small hair scene.
    const Scene scene = hair_tuft_scene(48, 48, 200);
    RenderSettings s;
    s.samples = 8;
    s.threads = 2;
    RenderStats stats;
    render_ok(scene, s, &stats);
    std::printf("hair tuft: %zu curves, %zu segments; 48x48 px x %d spp, %d threads: %.3f s, "
                "%.0f samples/s, %.0f rays/s (+ %.0f shadow rays/s), scene peak %.1f KiB, "
                "build %.3f s\n",
                scene.stats().curves, scene.stats().curve_segments, s.samples, stats.threads,
                stats.seconds, stats.samples_per_second, double(stats.rays) / stats.seconds,
                double(stats.shadow_rays) / stats.seconds,
                double(scene.stats().estimated_peak_bytes) / 1024.0, scene.stats().build_seconds);
    RecordProperty("samples_per_second", int(stats.samples_per_second));
    EXPECT_EQ(stats.camera_rays, 48u * 48u * 8u);
    EXPECT_GT(stats.samples_per_second, 0.0);
}

}  // namespace
}  // namespace hairis
