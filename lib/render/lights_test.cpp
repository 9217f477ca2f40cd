#include "render/lights.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include "chi2.h"
#include "core/rng.h"

namespace hairis {
namespace {

constexpr float kPiF = float(kPi);

LightSet build(std::vector<SunLight> suns, std::vector<PointLight> points,
               std::vector<AreaLight> areas, WorldLight world = {},
               std::vector<EmissiveTriangle> tris = {}) {
    auto set = LightSet::build(suns, points, areas, world, std::move(tris));
    EXPECT_TRUE(set.ok()) << (set.ok() ? "" : set.error().message);
    return std::move(set).value();
}

// Monte Carlo irradiance at p on a surface of normal n, from the light set's own samples:
// E = mean(value · max(0, n·wi) / pdf). Returns the mean and its standard error.
std::pair<double, double> irradiance(const LightSet &set, Vec3 p, Vec3 n, int count,
                                     int channel = 0) {
    double sum = 0, sum2 = 0;
    for (int i = 0; i < count; ++i) {
        const SampleRng rng(11, 0, std::uint64_t(i));
        const auto s = set.sample(p, rng.get(0), rng.get(1), rng.get(2));
        double v = 0;
        if (s) v = s->value[channel] * std::max(0.0f, dot(n, s->wi)) / s->pdf;
        sum += v;
        sum2 += v * v;
    }
    const double mean = sum / count;
    return {mean, std::sqrt(std::max(0.0, sum2 / count - mean * mean) / count)};
}

TEST(CyclesLight, PointLightNormalisation) {
    // Cycles: strength = color × power; eval_fac = 1/(4π) · 1/(π r²).
    const Rgb c{1.0f, 0.5f, 0.25f};
    const Rgb L = cycles_light::point_radiance(c, 100.0f, 0.2f);
    EXPECT_FLOAT_EQ(L.r, 100.0f / (4.0f * kPiF) / (kPiF * 0.04f));
    EXPECT_FLOAT_EQ(L.g, 50.0f / (4.0f * kPiF) / (kPiF * 0.04f));
    EXPECT_FLOAT_EQ(cycles_light::point_intensity(c, 100.0f).b, 25.0f / (4.0f * kPiF));
    EXPECT_FLOAT_EQ(cycles_light::point_invarea(0.0f), 1.0f);
}

TEST(Mis, PowerHeuristic) {
    EXPECT_FLOAT_EQ(power_heuristic(1.0f, 1.0f), 0.5f);
    EXPECT_FLOAT_EQ(power_heuristic(3.0f, 1.0f), 0.9f);
    EXPECT_FLOAT_EQ(power_heuristic(1.0f, 3.0f) + power_heuristic(3.0f, 1.0f), 1.0f);
    EXPECT_EQ(power_heuristic(0.0f, 1.0f), 0.0f);
    EXPECT_EQ(power_heuristic(2.0f, 0.0f), 1.0f);
    // Densities whose squares overflow a float still weigh correctly.
    EXPECT_FLOAT_EQ(power_heuristic(1e30f, 1e30f), 0.5f);
    EXPECT_FLOAT_EQ(power_heuristic(1e30f, 1.0f), 1.0f);
}

TEST(CyclesLight, AreaLightNormalisation) {
    AreaLight a;
    a.size_x = 2.0f;
    a.size_y = 0.5f;
    a.light_to_world.m[0][0] = 3.0f;  // object scale along X multiplies the size
    a.shape = AreaShape::Square;
    EXPECT_FLOAT_EQ(cycles_light::area_light_area(a), 6.0f * 2.0f);
    a.shape = AreaShape::Rectangle;
    EXPECT_FLOAT_EQ(cycles_light::area_light_area(a), 6.0f * 0.5f);
    a.shape = AreaShape::Disk;
    EXPECT_FLOAT_EQ(cycles_light::area_light_area(a), 6.0f * 2.0f * kPiF / 4.0f);
    a.shape = AreaShape::Ellipse;
    EXPECT_FLOAT_EQ(cycles_light::area_light_area(a), 6.0f * 0.5f * kPiF / 4.0f);
    // Cycles: eval_fac = 0.25 · invarea.
    EXPECT_FLOAT_EQ(cycles_light::area_radiance(Rgb(1.0f), 40.0f, 2.0f).g, 40.0f * 0.25f / 2.0f);
}

TEST(CyclesLight, SunNormalisation) {
    const float angle = float(radians(10.0));
    const float invarea = 1.0f / (kPiF * std::tan(angle / 2) * std::tan(angle / 2));
    EXPECT_FLOAT_EQ(cycles_light::sun_invarea(angle), invarea);
    EXPECT_FLOAT_EQ(cycles_light::sun_invarea(0.0f), 1.0f);
    EXPECT_FLOAT_EQ(cycles_light::sun_radiance(Rgb(2.0f), 3.0f, angle, 0.5f).r,
                    6.0f * invarea / 0.125f);
}

TEST(LightSet, PointLightIrradianceFollowsInverseSquare) {
    // Delta point light: E = P/(4π d²) exactly.
    const LightSet delta = build({}, {{Vec3{0, 0, 3}, Rgb(1.0f), 100.0f, 0.0f}}, {});
    const auto s = delta.sample({0, 0, 0}, 0.5f, 0.5f, 0.5f);
    ASSERT_TRUE(s.has_value());
    EXPECT_TRUE(s->delta);
    EXPECT_NEAR(s->value.r / s->pdf, 100.0f / (4.0f * kPiF * 9.0f), 1e-6f);
    // Radius r: a disk of radiance P/(4π²r²) facing the receiver; on the axis a facing
    // receiver gets E = L·π·r²/(r² + d²) = P/(4π(d² + r²)).
    const float r = 0.5f, d = 2.0f;
    const LightSet disk = build({}, {{Vec3{0, 0, d}, Rgb(1.0f), 100.0f, r}}, {});
    const auto [e, se] = irradiance(disk, {0, 0, 0}, {0, 0, 1}, 20000);
    const double expected = 100.0 / (4.0 * kPi * (d * d + r * r));
    EXPECT_NEAR(e, expected, 4.0 * se + 1e-6);
    EXPECT_LT(se, 0.01 * expected);
}

TEST(LightSet, DiskAreaLightIrradiance) {
    // A disk of diameter 2R facing down (−Z of the light), receiver on its axis facing up:
    // E = L·π R²/(R² + d²) with L = P/(4·πR²), so E = P/(4(R² + d²)).
    AreaLight a;
    a.shape = AreaShape::Disk;
    a.size_x = 2.0f;  // R = 1
    a.power = 50.0f;
    a.light_to_world = Mat4::translation({0, 0, 2});
    const LightSet set = build({}, {}, {a});
    const auto [e, se] = irradiance(set, {0, 0, 0}, {0, 0, 1}, 40000);
    EXPECT_NEAR(e, 50.0 / (4.0 * (1.0 + 4.0)), 4.0 * se);
    // One-sided: nothing reaches a point above the light.
    EXPECT_FALSE(set.sample({0, 0, 3}, 0.5f, 0.3f, 0.3f).has_value());
}

TEST(LightSet, RectangleAreaLightIrradiance) {
    // A 2 × 2 square at height d over a facing receiver, on its axis: with a the half side and
    // q = a/√(a² + d²), E = 4 L q atan(q) (each of the 4 edges adds L·q·atan(q)).
    AreaLight a;
    a.shape = AreaShape::Square;
    a.size_x = 2.0f;
    a.power = 40.0f;
    a.light_to_world = Mat4::translation({0, 0, 1});
    const LightSet set = build({}, {}, {a});
    const double L = 40.0 * 0.25 / 4.0, h = 1.0, d = 1.0;
    const double s = h / std::sqrt(h * h + d * d);
    const double expected = L * 4.0 * s * std::atan(s);
    const auto [e, se] = irradiance(set, {0, 0, 0}, {0, 0, 1}, 60000);
    EXPECT_NEAR(e, expected, 4.0 * se);
}

TEST(SphericalRectangle, SolidAngleAndSamples) {
    // A 2a × 2b rectangle at distance d, seen from its axis:
    // Ω = 4 asin(a b / sqrt((a² + d²)(b² + d²))).
    const float a = 0.7f, b = 0.3f, d = 0.5f;
    const SphericalRectangle rect({0, 0, 0}, {-a, -b, d}, {2 * a, 0, 0}, {0, 2 * b, 0});
    const double expected = 4.0 * std::asin(a * b / std::sqrt((a * a + d * d) * (b * b + d * d)));
    EXPECT_NEAR(rect.solid_angle(), expected, 1e-5 * expected);
    // Uniform in solid angle: the mean of cos θ (θ from the axis) over the samples equals
    // (1/Ω)∫cos dω = E/(L·Ω), with E/L = 4 q_a atan(...) summed over the edges: use an
    // off-axis point and compare against area-sampling quadrature instead.
    const Vec3 p{0.4f, -0.2f, 0.0f};
    const SphericalRectangle off(p, {-a, -b, d}, {2 * a, 0, 0}, {0, 2 * b, 0});
    double omega = 0, mean_cos_quad = 0;
    const int n = 600;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const Vec3 q{-a + 2 * a * (i + 0.5f) / n, -b + 2 * b * (j + 0.5f) / n, d};
            const Vec3 w = q - p;
            const double r2 = dot(w, w), c = d / std::sqrt(r2);
            const double dw = (4.0 * a * b / (double(n) * n)) * c / r2;
            omega += dw;
            mean_cos_quad += c * dw;
        }
    mean_cos_quad /= omega;
    EXPECT_NEAR(off.solid_angle(), omega, 1e-4 * omega);
    double mean_cos = 0;
    const int m = 200000;
    for (int i = 0; i < m; ++i) {
        const SampleRng rng(3, 0, std::uint64_t(i));
        const Vec3 q = off.sample(rng.get(0), rng.get(1));
        ASSERT_NEAR(q.z, d, 1e-5f);
        ASSERT_LE(std::fabs(q.x), a + 1e-5f);
        ASSERT_LE(std::fabs(q.y), b + 1e-5f);
        mean_cos += safe_normalize(q - p).z;
    }
    EXPECT_NEAR(mean_cos / m, mean_cos_quad, 2e-3);
    // Seen from its own plane it has no solid angle.
    EXPECT_EQ(SphericalRectangle({0, 0, d}, {-a, -b, d}, {2 * a, 0, 0}, {0, 2 * b, 0})
                  .solid_angle(),
              0.0f);
}

TEST(LightSet, SunIrradianceIsItsStrength) {
    SunLight sun;
    sun.to_sun = {0, 0, 1};
    sun.strength = 3.0f;
    sun.angle = float(radians(20.0));
    const LightSet set = build({sun}, {}, {});
    // A surface facing the sun: E = ∫ L cos = strength · E[cos θ] over the disc (≈ 0.992).
    const auto [e, se] = irradiance(set, {0, 0, 0}, {0, 0, 1}, 20000);
    EXPECT_NEAR(e, 3.0 * 0.9924, 0.01);
    // Angle 0: exactly the strength.
    sun.angle = 0.0f;
    const LightSet delta = build({sun}, {}, {});
    const auto s = delta.sample({0, 0, 0}, 0.1f, 0.2f, 0.3f);
    ASSERT_TRUE(s.has_value());
    EXPECT_TRUE(s->delta);
    EXPECT_FLOAT_EQ(s->value.r / s->pdf, 3.0f);
}

// Draws 500 light samples at the origin (seeds (seed, k, i)) and calls check(i, sample, hit)
// for each one drawn, with what a BSDF ray along it finds (MIS with the sample's own pdf);
// returns how many were drawn. Area-like samples only: a delta light fails.
template <typename Check>
int for_each_hit(const LightSet &set, std::uint64_t seed, std::size_t k, const Check &check) {
    int drawn = 0;
    for (int i = 0; i < 500 && !::testing::Test::HasFatalFailure(); ++i) {
        const SampleRng rng(seed, k, std::uint64_t(i));
        const auto s = set.sample({0, 0, 0}, rng.get(0), rng.get(1), rng.get(2));
        if (!s) continue;
        EXPECT_FALSE(s->delta);
        const Rgb hit = std::isinf(s->distance)
                            ? set.escaped({0, 0, 0}, s->wi, s->pdf, true)
                            : set.lamps_along_ray({0, 0, 0}, s->wi, 0.0f, INFINITY, s->pdf, true);
        check(i, *s, hit);
        ++drawn;
    }
    return drawn;
}

TEST(LightSet, HitsAgreeWithSamples) {
    // For a sampled direction, the radiance and density a BSDF ray finds there are the
    // sample's own: with bsdf_pdf = the light pdf the power heuristic gives exactly 1/2.
    // One light at a time, so that no other light overlaps the direction.
    SunLight sun;
    sun.to_sun = safe_normalize(Vec3{0.3f, 0.2f, 1.0f});
    sun.angle = 0.3f;
    AreaLight rect;
    rect.shape = AreaShape::Rectangle;
    rect.size_x = 1.0f;
    rect.size_y = 0.5f;
    rect.light_to_world = Mat4::translation({0.5f, 0, 2});
    AreaLight ellipse = rect;
    ellipse.shape = AreaShape::Ellipse;
    ellipse.light_to_world = Mat4::translation({-1, 0.5f, 3});
    const std::vector<LightSet> sets = {
        build({sun}, {}, {}), build({}, {{Vec3{1, 1, 2}, Rgb(1.0f), 30.0f, 0.3f}}, {}),
        build({}, {}, {rect}), build({}, {}, {ellipse})};
    for (std::size_t k = 0; k < sets.size(); ++k) {
        const LightSet &set = sets[k];
        const int checked = for_each_hit(set, 5, k, [&](int i, const LightSample &s, Rgb hit) {
            ASSERT_NEAR(hit.r, 0.5f * s.value.r, 1e-3f * s.value.r) << "light set " << k << ", sample " << i;
            // A ray stopped before the light (tmax < distance) does not see it.
            if (!std::isinf(s.distance)) {
                const Rgb before = set.lamps_along_ray({0, 0, 0}, s.wi, 0.0f, 0.5f * s.distance, s.pdf, true);
                EXPECT_EQ(before.r, 0.0f);
            }
        });
        EXPECT_EQ(checked, 500) << "light set " << k;
    }
}

TEST(LightSet, ConstantWorldIsFoundByBsdfSamplingOnly) {
    // As in Cycles 3.4: a constant world is not a light to sample, and escaping rays get its
    // radiance at full weight, with or without MIS.
    const LightSet set = build({}, {}, {}, {Rgb(0.5f), 2.0f});
    EXPECT_EQ(set.lamp_count(), 0);
    EXPECT_TRUE(set.empty());
    EXPECT_FALSE(set.sample({0, 0, 0}, 0.3f, 0.7f, 0.1f).has_value());
    EXPECT_FLOAT_EQ(set.escaped({0, 0, 0}, {0, 1, 0}, 0.0f, false).b, 1.0f);
    EXPECT_FLOAT_EQ(set.escaped({0, 0, 0}, {0, 1, 0}, 0.3f, true).g, 1.0f);
    EXPECT_FLOAT_EQ(set.escaped({0, 0, 0}, {0, 1, 0}, 0.3f, true, false).g, 0.0f);
    // With a sun, the world does not dilute the sun's selection probability.
    const LightSet with_sun = build({SunLight{}}, {}, {}, {Rgb(0.5f), 2.0f});
    EXPECT_FLOAT_EQ(with_sun.lamp_selection_probability({0, 0, 0}, 0), 1.0f);
}

TEST(LightSet, SelectionFollowsCycles) {
    EmissiveTriangle small{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, Rgb(1.0f), 0, 0};
    EmissiveTriangle big{{0, 0, 0}, {3, 0, 0}, {0, 1, 0}, Rgb(1.0f), 0, 1};
    const LightSet set = build({SunLight{}}, {{Vec3{0, 0, 5}, Rgb(1.0f), 1.0f, 0.0f}}, {}, {},
                               {small, big});
    EXPECT_FLOAT_EQ(set.triangle_group_probability(), 0.5f);
    // The lamps share the other half (by importance: LampsAreChosenByImportanceAtThePoint).
    const Vec3 at{0.2f, 0.2f, 1.0f};
    EXPECT_NEAR(set.lamp_selection_probability(at, 0) + set.lamp_selection_probability(at, 1), 0.5f, 1e-6f);
    // Triangles by area: the big one (3/4 of the area) is picked 3/4 of the time.
    int big_count = 0, tri_count = 0;
    for (int i = 0; i < 8000; ++i) {
        const float u = (i + 0.5f) / 8000.0f;
        const auto s = set.sample({0.2f, 0.2f, 1.0f}, u, 0.3f, 0.4f);
        if (!s || s->skip_geometry != 0) continue;
        ++tri_count;
        big_count += s->skip_primitive == 1;
        // The triangle pdf is (1/2)/total_area · t²/|cos|.
        EXPECT_NEAR(s->pdf, set.emissive_triangle_pdf(s->distance, std::fabs(s->wi.z)), 1e-4f);
    }
    EXPECT_EQ(tri_count, 4000);
    EXPECT_NEAR(double(big_count) / tri_count, 0.75, 0.01);
}

TEST(LightSet, LampsAreChosenByImportanceAtThePoint) {
    // Two equal point lights, one near p and one far: each lamp's share is a tenth uniform and
    // the rest in proportion to I/d²; the draws follow those shares, and each sample's pdf is
    // its lamp's share times the sphere's density, as lamps_along_ray reports it (MIS).
    const LightSet set = build({}, {{Vec3{0, 0, 1}, Rgb(1.0f), 50.0f, 0.1f}, {Vec3{0, 4, 0}, Rgb(1.0f), 50.0f, 0.1f}}, {});
    const Vec3 p{0, 0, 0};
    const double near = 1.0 / 1.0, far = 1.0 / 16.0;
    const double want_near = 0.05 + 0.9 * near / (near + far);
    EXPECT_NEAR(set.lamp_selection_probability(p, 0), want_near, 1e-6);
    EXPECT_NEAR(set.lamp_selection_probability(p, 1), 1.0 - want_near, 1e-6);
    EXPECT_EQ(set.lamp_selection_probability(p, 2), 0.0f);
    // Seen from beside the far one, the far one is the near one.
    EXPECT_GT(set.lamp_selection_probability({0, 4.0f, 0.3f}, 1), 0.9f);
    int near_count = 0, n = 20000;
    for (int i = 0; i < n; ++i) {
        const SampleRng rng(3, 0, std::uint64_t(i));
        const auto s = set.sample(p, rng.get(0), rng.get(1), rng.get(2));
        ASSERT_TRUE(s.has_value());
        const bool is_near = s->distance < 2.0f;
        near_count += is_near;
        const Rgb hit = set.lamps_along_ray(p, s->wi, 0.0f, INFINITY, s->pdf, true);
        ASSERT_NEAR(hit.r, 0.5f * s->value.r, 1e-3f * s->value.r) << i;  // the same density
        ASSERT_NEAR(set.pdf(p, s->wi), s->pdf, 1e-3f * s->pdf) << i;
    }
    const double share = double(near_count) / n;
    EXPECT_NEAR(share, want_near, 4.0 * std::sqrt(want_near * (1.0 - want_near) / n));
}

TEST(LightSet, RefusesInvalidLights) {
    auto error_of = [](std::vector<SunLight> suns, std::vector<PointLight> points,
                       std::vector<AreaLight> areas) {
        auto s = LightSet::build(suns, points, areas, {}, {});
        return s.ok() ? std::string() : s.error().message;
    };
    EXPECT_NE(error_of({}, {{Vec3{NAN, 0, 0}, Rgb(1.0f), 1.0f, 0.0f}}, {}).find("point light 0"),
              std::string::npos);
    EXPECT_NE(error_of({}, {{Vec3{0, 0, 0}, Rgb(1.0f), -1.0f, 0.0f}}, {}).find("power"),
              std::string::npos);
    SunLight wide;
    wide.angle = 4.0f;
    EXPECT_NE(error_of({wide}, {}, {}).find("angle"), std::string::npos);
    SunLight zero;
    zero.to_sun = {0, 0, 0};
    EXPECT_NE(error_of({zero}, {}, {}).find("zero"), std::string::npos);
    AreaLight a;
    a.size_x = -1.0f;
    EXPECT_NE(error_of({}, {}, {a}).find("size_x"), std::string::npos);
    // Zero size: left out with a warning.
    a.size_x = 0.0f;
    std::vector<std::string> warnings;
    auto set = LightSet::build({}, {}, {a}, {}, {}, &warnings);
    ASSERT_TRUE(set.ok());
    EXPECT_EQ(set.value().lamp_count(), 0);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("zero size"), std::string::npos);
}


// ---- Spot lights, Cycles 4.5's lights and the environment world --------------------------

// Every χ² test of this file, for the Šidák correction.
constexpr int kChi2Tests = 3;

// Cycles' smoothstepf, written out: 3t² − 2t³.
double smooth(double t) { return t * t * (3.0 - 2.0 * t); }

SpotLight spot_at(Vec3 position, float power, float radius, float size, float blend,
                  CyclesVersion version = CyclesVersion::V3_4) {
    SpotLight s;
    s.light_to_world = Mat4::translation(position);  // shines along −Z
    s.power = power;
    s.radius = radius;
    s.spot_size = size;
    s.spot_blend = blend;
    s.cycles = version;
    return s;
}

LightSet build_lights(LightsDesc d, std::vector<EmissiveTriangle> tris = {}) {
    auto set = LightSet::build(d, std::move(tris));
    EXPECT_TRUE(set.ok()) << (set.ok() ? "" : set.error().message);
    return std::move(set).value();
}

std::shared_ptr<const EnvironmentMap> environment(int w, int h,
                                                  const std::function<Rgb(int, int)> &texel,
                                                  Mat4 world_to_texture = Mat4{},
                                                  float strength = 1.0f) {
    std::vector<float> rgb;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Rgb c = texel(x, y);
            rgb.insert(rgb.end(), {c.r, c.g, c.b});
        }
    EnvironmentDesc desc;
    desc.image = EnvironmentImage::create(w, h, std::move(rgb)).value();
    desc.world_to_texture = world_to_texture;
    desc.strength = strength;
    auto map = EnvironmentMap::create(std::move(desc));
    EXPECT_TRUE(map.ok()) << (map.ok() ? "" : map.error().message);
    return std::make_shared<const EnvironmentMap>(std::move(map).value());
}

// A sky: a gradient towards the zenith and a bright 2 × 2 spot.
std::shared_ptr<const EnvironmentMap> sky(int w = 64, int h = 32) {
    return environment(w, h, [&](int x, int y) {
        const float g = 0.05f + 0.3f * float(y) / float(h);
        const bool spot = (x == 40 || x == 41) && (y == 22 || y == 23);
        return spot ? Rgb{500.0f, 400.0f, 300.0f} : Rgb{0.6f * g, 0.8f * g, g};
    });
}

TEST(CyclesLight, SpotAttenuation) {
    // Cycles 3.4: c itself inside the cone past the blend, c·smoothstep in the blend, 0 outside.
    const float cos_half = std::cos(0.5f), smooth_width = (1.0f - cos_half) * 0.4f;
    EXPECT_EQ(cycles_light::spot_attenuation(cos_half - 0.01f, cos_half, smooth_width), 0.0f);
    EXPECT_EQ(cycles_light::spot_attenuation(cos_half, cos_half, smooth_width), 0.0f);
    EXPECT_FLOAT_EQ(cycles_light::spot_attenuation(0.99f, cos_half, smooth_width), 0.99f);
    const float c = cos_half + 0.3f * smooth_width;
    EXPECT_NEAR(cycles_light::spot_attenuation(c, cos_half, smooth_width), c * smooth(0.3), 1e-6);
    // Blend 0: a hard edge.
    EXPECT_FLOAT_EQ(cycles_light::spot_attenuation(cos_half + 1e-4f, cos_half, 0.0f),
                    cos_half + 1e-4f);
    // Cycles 4.5: no factor c.
    EXPECT_FLOAT_EQ(cycles_light::spot_attenuation_cycles45(0.99f, cos_half, smooth_width), 1.0f);
    EXPECT_NEAR(cycles_light::spot_attenuation_cycles45(c, cos_half, smooth_width), smooth(0.3),
                1e-6);
    EXPECT_EQ(cycles_light::spot_attenuation_cycles45(cos_half, cos_half, smooth_width), 0.0f);
    EXPECT_EQ(cycles_light::spot_attenuation_cycles45(cos_half + 1e-4f, cos_half, 0.0f), 1.0f);
}

TEST(LightSet, SpotIrradianceClosedForms) {
    const float power = 80.0f, d = 2.0f;
    // Delta spot on its axis: E = P/(4π d²), c = 1.
    {
        const LightSet set = build_lights({{}, {}, {spot_at({0, 0, d}, power, 0.0f, 1.0f, 0.2f)}, {}, {}});
        const auto s = set.sample({0, 0, 0}, 0.5f, 0.5f, 0.5f);
        ASSERT_TRUE(s.has_value());
        EXPECT_TRUE(s->delta);
        EXPECT_NEAR(s->value.r / s->pdf, power / (4.0 * kPi * d * d), 1e-6);
    }
    // Delta spot seen at angle β from its axis, inside the blend: a receiver facing the light
    // gets P/(4π ρ²) · cos β · smoothstep((cos β − cos_half)/((1 − cos_half)·blend)) in 3.4,
    // without cos β in 4.5.
    {
        const float size = 1.0f, blend = 0.6f, beta = 0.42f;
        const double cos_half = std::cos(0.5 * size), width = (1.0 - cos_half) * blend;
        const double t = (std::cos(beta) - cos_half) / width;
        ASSERT_GT(t, 0.0);
        ASSERT_LT(t, 1.0);
        const Vec3 p{float(d * std::sin(beta)), 0.0f, float(d - d * std::cos(beta))};
        for (const CyclesVersion v : {CyclesVersion::V3_4, CyclesVersion::V4_5}) {
            const LightSet set =
                build_lights({{}, {}, {spot_at({0, 0, d}, power, 0.0f, size, blend, v)}, {}, {}});
            const auto s = set.sample(p, 0.1f, 0.2f, 0.3f);
            ASSERT_TRUE(s.has_value());
            const double expected = power / (4.0 * kPi * d * d) * smooth(t) *
                                    (v == CyclesVersion::V3_4 ? std::cos(beta) : 1.0);
            EXPECT_NEAR(s->value.r / s->pdf, expected, 1e-5 * expected) << int(v);
            // Outside the cone nothing arrives.
            EXPECT_FALSE(set.sample({float(d), 0.0f, 0.0f}, 0.5f, 0.5f, 0.5f).has_value());
        }
    }
    // A disk spot of radius r over a facing receiver on its axis, the whole disk inside the
    // cone (blend 0): 3.4 weighs each disk point by c = cos θ, so E = L ∫ cos²θ dω
    // = (2π L/3)(1 − d³/(d² + r²)^(3/2)); 4.5 has no c: E = L π r²/(d² + r²). L = P/(4π²r²).
    {
        const float r = 0.6f;
        const double L = power / (4.0 * kPi * kPi * r * r);
        const double expected34 = 2.0 * kPi * L / 3.0 * (1.0 - std::pow(d, 3) / std::pow(d * d + r * r, 1.5));
        const double expected45 = L * kPi * r * r / (d * d + r * r);
        for (const CyclesVersion v : {CyclesVersion::V3_4, CyclesVersion::V4_5}) {
            const LightSet set =
                build_lights({{}, {}, {spot_at({0, 0, d}, power, r, 1.2f, 0.0f, v)}, {}, {}});
            const auto [e, se] = irradiance(set, {0, 0, 0}, {0, 0, 1}, 40000);
            const double expected = v == CyclesVersion::V3_4 ? expected34 : expected45;
            EXPECT_NEAR(e, expected, 4.0 * se) << int(v);
            EXPECT_LT(se, 0.01 * expected);
        }
        EXPECT_GT(expected45 / expected34, 1.02);  // the two versions are told apart
    }
}

TEST(LightSet, ASpotIsChosenOnlyWhereItsConeCanReach) {
    // A disk spot straight down (half angle 0.4; lamp 1, after the sun) beside a sun: where no point of the disk can
    // light p inside the cone the spot keeps only its uniform share; where the disk's edge can
    // (p just outside the bare cone) it keeps its importance. Either way the irradiance is the
    // sum of the two lamps' own (each alone in its set, so picked with probability 1).
    const float h = 2.0f, r = 0.3f, size = 0.8f;
    SunLight sun;
    sun.to_sun = safe_normalize(Vec3{0.3f, 0.0f, 1.0f});
    sun.strength = 1.0f;
    for (const CyclesVersion v : {CyclesVersion::V3_4, CyclesVersion::V4_5}) {
        LightsDesc both, spot_only, sun_only;
        both.spots = spot_only.spots = {spot_at({0, 0, h}, 2000.0f, r, size, 0.2f, v)};
        both.suns = sun_only.suns = {sun};
        const LightSet set = build_lights(both), spot = build_lights(spot_only), sun_set = build_lights(sun_only);
        const float bare = h * std::tan(0.5f * size);  // the bare cone's radius on the floor
        const float edge = bare + 0.5f * r;             // outside it, within the disk's reach
        const float far = bare + 3.0f * r;              // out of reach
        EXPECT_GT(set.lamp_selection_probability({0.5f * bare, 0, 0}, 1), 0.9f) << int(v);
        EXPECT_GT(set.lamp_selection_probability({edge, 0, 0}, 1), 0.9f) << int(v);
        EXPECT_NEAR(set.lamp_selection_probability({far, 0, 0}, 1), 0.05f, 1e-6f) << int(v);
        for (const float x : {0.5f * bare, edge, far}) {
            const Vec3 p{x, 0, 0}, n{0, 0, 1};
            const auto [e, se] = irradiance(set, p, n, 40000);
            const auto [e_spot, se_spot] = irradiance(spot, p, n, 40000);
            const auto [e_sun, se_sun] = irradiance(sun_set, p, n, 40000);
            EXPECT_NEAR(e, e_spot + e_sun, 4.0 * std::sqrt(se * se + se_spot * se_spot + se_sun * se_sun))
                << int(v) << " x " << x;
        }
    }
}

TEST(LightSet, SpotConeFollowsTheObjectScaleInCycles45) {
    // Cycles 4.5 measures the cone in the light's frame: with the object scaled 2× along X, a
    // direction at angle β from the axis in the XZ plane has local z = cos β / √(cos²β +
    // sin²β/4), in the YZ plane local z = cos β. 3.4 uses the world angle alone.
    const float size = 1.0f, blend = 0.5f, beta = 0.45f, d = 3.0f;
    const double cos_half = std::cos(0.5 * size), width = (1.0 - cos_half) * blend;
    SpotLight spot = spot_at({0, 0, d}, 50.0f, 0.0f, size, blend, CyclesVersion::V4_5);
    spot.light_to_world.m[0][0] = 2.0f;
    const LightSet set = build_lights({{}, {}, {spot}, {}, {}});
    auto received = [&](Vec3 dir_from_light) {
        const Vec3 p = Vec3{0, 0, d} + dir_from_light * d;
        const auto s = set.sample(p, 0.5f, 0.5f, 0.5f);
        return s ? double(s->value.r / s->pdf) * d * d * 4.0 * kPi / 50.0 : 0.0;
    };
    const Vec3 in_xz{std::sin(beta), 0.0f, -std::cos(beta)}, in_yz{0.0f, std::sin(beta), -std::cos(beta)};
    const double zx = std::cos(beta) / std::sqrt(std::cos(beta) * std::cos(beta) +
                                                 std::sin(beta) * std::sin(beta) / 4.0);
    auto expected = [&](double z) {
        const double t = (z - cos_half) / width;
        return t <= 0.0 ? 0.0 : (t >= 1.0 ? 1.0 : smooth(t));
    };
    EXPECT_NEAR(received(in_xz), expected(zx), 1e-4);
    EXPECT_NEAR(received(in_yz), expected(std::cos(beta)), 1e-4);
    EXPECT_GT(received(in_xz), received(in_yz) + 0.05);  // the scale widens the cone in X
}

TEST(LightSet, Cycles45Conversions) {
    // Area: L = P/(π·area), so a disk of radius R at height d gives a facing receiver on its
    // axis E = L π R²/(R² + d²) = P/(π(R² + d²)).
    {
        AreaLight a;
        a.shape = AreaShape::Disk;
        a.size_x = 2.0f;
        a.power = 50.0f;
        a.light_to_world = Mat4::translation({0, 0, 2});
        a.cycles = CyclesVersion::V4_5;
        const LightSet set = build({}, {}, {a});
        const auto [e, se] = irradiance(set, {0, 0, 0}, {0, 0, 1}, 40000);
        EXPECT_NEAR(e, 50.0 / (kPi * (1.0 + 4.0)), 4.0 * se);
        EXPECT_FLOAT_EQ(cycles_light::area_radiance(Rgb(1.0f), 40.0f, 2.0f, CyclesVersion::V4_5).r,
                        40.0f / (kPiF * 2.0f));
    }
    // Sun: a cone of constant radiance; a facing surface receives exactly its strength.
    {
        SunLight sun;
        sun.strength = 3.0f;
        sun.angle = float(radians(20.0));
        sun.cycles = CyclesVersion::V4_5;
        const LightSet set = build({sun}, {}, {});
        const auto [e, se] = irradiance(set, {0, 0, 0}, {0, 0, 1}, 20000);
        EXPECT_NEAR(e, 3.0, 4.0 * se + 1e-5);
        const auto s = set.sample({0, 0, 0}, 0.5f, 0.3f, 0.8f);
        ASSERT_TRUE(s.has_value());
        EXPECT_FLOAT_EQ(s->value.r, 3.0f / (kPiF * std::pow(std::sin(sun.angle / 2), 2.0f)));
    }
    // Point without soft falloff: a sphere of radiance P/(4π²r²); a facing receiver on the
    // line to its centre at distance d gets E = L π sin²α = L π r²/d² = P/(4π d²), as a
    // point light would, at any distance outside it.
    for (const float d : {0.5f, 3.0f}) {
        PointLight p{Vec3{0, 0, d}, Rgb(1.0f), 100.0f, 0.4f};
        p.cycles = CyclesVersion::V4_5;
        p.soft_falloff = false;
        const LightSet set = build({}, {p}, {});
        const auto [e, se] = irradiance(set, {0, 0, 0}, {0, 0, 1}, 40000);
        EXPECT_NEAR(e, 100.0 / (4.0 * kPi * d * d), 4.0 * se) << d;
        EXPECT_LT(se, 0.01 * 100.0 / (4.0 * kPi * d * d));
    }
    // Inside the sphere every direction sees radiance L: E = π L on any surface.
    {
        PointLight p{Vec3{0, 0, 0.1f}, Rgb(1.0f), 100.0f, 0.5f};
        p.cycles = CyclesVersion::V4_5;
        p.soft_falloff = false;
        const LightSet set = build({}, {p}, {});
        const auto [e, se] = irradiance(set, {0, 0, 0}, {0.6f, 0.0f, 0.8f}, 40000);
        const double L = 100.0 / (4.0 * kPi * kPi * 0.25);
        EXPECT_NEAR(e, kPi * L, 4.0 * se);
    }
    // Soft falloff needs 4.5; Cycles 3.4 has only the disk.
    PointLight hard{Vec3{0, 0, 1}, Rgb(1.0f), 10.0f, 0.1f};
    hard.soft_falloff = false;
    auto refused = LightSet::build({}, {hard}, {}, {}, {});
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().message.find("soft_falloff"), std::string::npos);
}

TEST(LightSet, NewLampsHitsAgreeWithSamples) {
    // As HitsAgreeWithSamples: a BSDF ray along a light sample finds the sample's radiance and
    // density (power heuristic 1/2 against itself).
    PointLight sphere{Vec3{1, 1, 2}, Rgb(1.0f), 30.0f, 0.4f};
    sphere.cycles = CyclesVersion::V4_5;
    sphere.soft_falloff = false;
    SpotLight sphere_spot = spot_at({0.3f, -0.2f, 2.0f}, 40.0f, 0.3f, 1.4f, 0.5f, CyclesVersion::V4_5);
    sphere_spot.soft_falloff = false;
    SunLight sun;
    sun.to_sun = safe_normalize(Vec3{0.3f, 0.2f, 1.0f});
    sun.angle = 0.3f;
    sun.cycles = CyclesVersion::V4_5;
    LightsDesc env;
    env.world.environment = sky();
    const std::vector<LightSet> sets = {
        build_lights({{}, {}, {spot_at({0.3f, -0.2f, 2.0f}, 40.0f, 0.3f, 1.4f, 0.5f)}, {}, {}}),
        build_lights({{}, {}, {spot_at({0.3f, -0.2f, 2.0f}, 40.0f, 0.3f, 1.4f, 0.5f,
                                       CyclesVersion::V4_5)}, {}, {}}),
        build_lights({{}, {}, {sphere_spot}, {}, {}}), build({}, {sphere}, {}), build({sun}, {}, {}),
        build_lights(env)};
    for (std::size_t k = 0; k < sets.size(); ++k) {
        const LightSet &set = sets[k];
        const int checked = for_each_hit(set, 7, k, [&](int i, const LightSample &s, Rgb hit) {
            ASSERT_NEAR(hit.g, 0.5f * s.value.g, 1e-3f * s.value.g) << "set " << k << ", sample " << i;
            ASSERT_NEAR(set.pdf({0, 0, 0}, s.wi), s.pdf, 1e-3f * s.pdf) << "set " << k;
        });
        EXPECT_GT(checked, 450) << "light set " << k;
    }
}

TEST(LightSet, EnvironmentWorldIsALampAmongLamps) {
    // The background light is one of the lamps, chosen by its importance (πL̄) among them;
    // with emissive triangles the lamps share half.
    LightsDesc d;
    d.suns = {SunLight{}};
    d.world.environment = sky();
    const LightSet set = build_lights(d);
    EXPECT_EQ(set.lamp_count(), 2);
    EXPECT_TRUE(set.world_light_sampled());
    // By importance: the sun's E = 1 against the environment's ∫L dω / 4, a tenth uniform.
    const Vec3 p{0.3f, -0.2f, 0.1f};
    const double sun = 1.0, env = d.world.environment->luminance_integral() / 4.0;
    const double env_pick = 0.1 * 0.5 + 0.9 * env / (sun + env);
    EXPECT_NEAR(set.lamp_selection_probability(p, 1), env_pick, 1e-5);
    EXPECT_NEAR(set.lamp_selection_probability(p, 0), 1.0 - env_pick, 1e-5);
    const Vec3 dir = safe_normalize(Vec3{0.2f, -0.4f, 0.7f});
    EXPECT_NEAR(set.world_pdf(p, dir), env_pick * d.world.environment->pdf(dir), 1e-5 * set.world_pdf(p, dir));
    // Escaped rays get the environment's radiance, weighted against that density.
    const Rgb L = d.world.environment->eval(dir);
    const float bsdf_pdf = 0.3f;
    EXPECT_FLOAT_EQ(set.escaped(p, dir, bsdf_pdf, true).b, L.b * power_heuristic(bsdf_pdf, set.world_pdf(p, dir)));
    EXPECT_FLOAT_EQ(set.escaped(p, dir, bsdf_pdf, false).b, L.b);
    EXPECT_EQ(set.escaped(p, dir, bsdf_pdf, true, false).b, 0.0f);

    EmissiveTriangle tri{{0, 0, 5}, {1, 0, 5}, {0, 1, 5}, Rgb(1.0f), 0, 0};
    const LightSet with_triangle = build_lights(d, {tri});
    EXPECT_NEAR(with_triangle.lamp_selection_probability(p, 0) + with_triangle.lamp_selection_probability(p, 1),
                0.5f, 1e-6f);

    // Sampling None: not a lamp; escaped rays take it at full weight.
    d.world.light_sampled = false;
    const LightSet none = build_lights(d);
    EXPECT_EQ(none.lamp_count(), 1);
    EXPECT_FALSE(none.world_light_sampled());
    EXPECT_EQ(none.world_pdf(p, dir), 0.0f);
    EXPECT_FLOAT_EQ(none.escaped(p, dir, bsdf_pdf, true).b, L.b);
    // A black environment has nothing to sample.
    LightsDesc black;
    black.world.environment = environment(8, 4, [](int, int) { return Rgb(0.0f); });
    EXPECT_TRUE(build_lights(black).empty());
}

// The χ² harness cuts its sphere in sin θ = local.x and φ = atan2(local.z, local.y): world z
// is its x. Lights above (+Z) and below (−Z) the shading point have cone edges at constant θ.
Vec3 to_local(Vec3 d) { return {d.z, d.x, d.y}; }
Vec3 from_local(Vec3 l) { return {l.y, l.z, l.x}; }

testing::Chi2Result light_set_chi2(const LightSet &set, Vec3 p, testing::Chi2Options o) {
    o.test_count = kChi2Tests;
    std::sort(o.theta_breaks.begin(), o.theta_breaks.end());
    return testing::chi2_direction_test(
        [&](testing::Sample3 u) -> std::optional<Vec3> {
            // u2 selects the light, (u0, u1) place the sample.
            const auto s = set.sample(p, u.u2, u.u0, u.u1);
            if (!s) return std::nullopt;
            return to_local(s->wi);
        },
        [&](Vec3 l) { return double(set.pdf(p, from_local(l))); }, o);
}

void add_map_breaks(testing::Chi2Options &o, int W, int H) {
    for (int j = 1; j < H; ++j) o.theta_breaks.push_back(-kHalfPi + kPi * j / H);
    for (int i = 0; i <= W; ++i) o.phi_breaks.push_back(kPi - kTwoPi * i / W);
}

TEST(LightSetChi2, EnvironmentSphereLightAndSun) {
    // The world (a 64 × 32 sky), a sphere light above (4.5, no soft falloff) and a 4.5 sun
    // below: each chosen with probability 1/3; pdf() sums the three densities.
    LightsDesc d;
    d.world.environment = sky();
    const Vec3 p{0.1f, -0.2f, 0.0f};
    PointLight sphere{p + Vec3{0, 0, 2.0f}, Rgb(1.0f), 30.0f, 0.8f};
    sphere.cycles = CyclesVersion::V4_5;
    sphere.soft_falloff = false;
    d.points = {sphere};
    SunLight sun;
    sun.to_sun = {0, 0, -1};
    sun.angle = 0.5f;
    sun.cycles = CyclesVersion::V4_5;
    d.suns = {sun};
    const LightSet set = build_lights(d);
    ASSERT_EQ(set.lamp_count(), 3);
    testing::Chi2Options o;
    add_map_breaks(o, 64, 32);
    o.theta_breaks.push_back(kHalfPi - std::asin(0.8 / 2.0));
    o.theta_breaks.push_back(-kHalfPi + 0.25);
    const testing::Chi2Result r = light_set_chi2(set, p, o);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3);
}

TEST(LightSetChi2, DiskSpotAndSun34) {
    // A 3.4 disk spot above (the whole disk inside its cone, so no sample is refused) and a
    // 3.4 sun below (pdf invarea/cos³ on its tangent disc).
    const Vec3 p{0.0f, 0.0f, 0.0f};
    const float h = 1.5f, r = 0.7f;
    LightsDesc d;
    d.spots = {spot_at({0, 0, h}, 40.0f, r, 1.6f, 0.3f)};
    SunLight sun;
    sun.to_sun = {0, 0, -1};
    sun.angle = 0.6f;
    d.suns = {sun};
    const LightSet set = build_lights(d);
    testing::Chi2Options o;
    o.theta_breaks = {kHalfPi - std::atan(r / h), -kHalfPi + 0.3};
    const testing::Chi2Result r_ = light_set_chi2(set, p, o);
    EXPECT_TRUE(r_.passed) << r_.message;
    EXPECT_NEAR(r_.pdf_integral, 1.0, 2e-3);
}

TEST(LightSetChi2, InsideASphereSpot) {
    // Inside a 4.5 sphere spot: uniform directions (density 1/(4π)), with the world's map.
    LightsDesc d;
    SpotLight s = spot_at({0, 0, 0.2f}, 40.0f, 0.5f, 1.0f, 0.3f, CyclesVersion::V4_5);
    s.soft_falloff = false;
    d.spots = {s};
    d.world.environment = sky(32, 16);
    const LightSet set = build_lights(d);
    testing::Chi2Options o;
    add_map_breaks(o, 32, 16);
    const testing::Chi2Result r = light_set_chi2(set, {0, 0, 0}, o);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3);
}

TEST(LightSet, MisOfTheEnvironmentIsUnbiased) {
    // The irradiance at a point from an environment and a sun, estimated by light sampling
    // alone, by cosine-weighted BSDF sampling alone and by both with the power heuristic,
    // against a quadrature of eval() over the hemisphere: all four agree within the noise.
    LightsDesc d;
    const Mat4 rotation = euler_xyz_rotation({0.3f, -0.2f, 1.1f});
    d.world.environment = environment(64, 32, [](int x, int y) {
        const float g = 0.1f + 0.4f * float(y) / 32.0f;
        return (x == 20 && y == 25) ? Rgb{300.0f, 200.0f, 100.0f} : Rgb{g, g, 1.5f * g};
    }, rotation);
    SunLight sun;
    sun.to_sun = safe_normalize(Vec3{0.5f, 0.1f, 0.8f});
    sun.angle = 0.2f;
    sun.strength = 2.0f;
    sun.cycles = CyclesVersion::V4_5;
    d.suns = {sun};
    const LightSet set = build_lights(d);
    const Vec3 n{0, 0, 1}, p{0, 0, 0};
    Vec3 a, b;
    orthonormal_basis(n, a, b);
    // Reference: the sun's exact E = strength·cos(θ_sun) (its cone lies above the horizon),
    // plus the environment by a 2D midpoint rule over the hemisphere in (cos θ, φ).
    double reference = 2.0 * double(dot(sun.to_sun, n));
    {
        const int m = 1500;
        double sum = 0;
        for (int i = 0; i < m; ++i)
            for (int j = 0; j < 2 * m; ++j) {
                const double z = (i + 0.5) / m, phi = kTwoPi * (j + 0.5) / (2 * m);
                const double s = std::sqrt(1.0 - z * z);
                const Vec3 w = safe_normalize(a * float(s * std::cos(phi)) + b * float(s * std::sin(phi)) + n * float(z));
                sum += double(d.world.environment->eval(w).r) * z;
            }
        reference += sum * kTwoPi / (double(m) * 2 * m);
    }
    const int count = 400000;
    double mean[3] = {0, 0, 0}, m2[3] = {0, 0, 0};
    for (int i = 0; i < count; ++i) {
        const SampleRng rng(21, 0, std::uint64_t(i));
        double light_only = 0, bsdf_only = 0, mis = 0;
        if (const auto s = set.sample(p, rng.get(0), rng.get(1), rng.get(2))) {
            const float c = std::max(0.0f, dot(n, s->wi));
            const double f = double(s->value.r) * c / s->pdf;
            light_only = f;
            mis += f * power_heuristic(s->pdf, c * float(kInvPi));
        }
        float x, y;
        concentric_disk(rng.get(3), rng.get(4), x, y);
        const float z = std::sqrt(std::max(0.0f, 1.0f - x * x - y * y));
        const Vec3 w = safe_normalize(a * x + b * y + n * z);
        const float bsdf_pdf = z * float(kInvPi);
        if (bsdf_pdf > 0.0f) {
            bsdf_only = double(set.escaped(p, w, bsdf_pdf, false).r) * z / bsdf_pdf;
            mis += double(set.escaped(p, w, bsdf_pdf, true).r) * z / bsdf_pdf;
        }
        const double v[3] = {light_only, bsdf_only, mis};
        for (int k = 0; k < 3; ++k) {
            const double delta = v[k] - mean[k];
            mean[k] += delta / (i + 1);
            m2[k] += delta * (v[k] - mean[k]);
        }
    }
    const char *names[3] = {"light only", "BSDF only", "MIS"};
    for (int k = 0; k < 3; ++k) {
        const double se = std::sqrt(m2[k] / (count - 1.0) / count);
        EXPECT_NEAR(mean[k], reference, 4.0 * se + 1e-3 * reference) << names[k];
    }
    // MIS is the estimator with the least variance here, and light sampling beats BSDF
    // sampling on the bright texel.
    EXPECT_LT(m2[2], m2[1]);
    EXPECT_LT(m2[0], m2[1]);
}

}  // namespace
}  // namespace hairis
