#include "render/lights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

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

TEST(LightSet, HitsAgreeWithSamples) {
    // For a sampled direction, the radiance and density a BSDF ray finds there are the
    // sample's own: with bsdf_pdf = the light pdf the power heuristic gives exactly 1/2.
    // One light at a time, so that no other light overlaps the direction.
    SunLight sun;
    sun.to_sun = safe_normalize({0.3f, 0.2f, 1.0f});
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
        int checked = 0;
        for (int i = 0; i < 500; ++i) {
            const SampleRng rng(5, k, std::uint64_t(i));
            const auto s = set.sample({0, 0, 0}, rng.get(0), rng.get(1), rng.get(2));
            if (!s) continue;
            ASSERT_FALSE(s->delta);
            const Rgb hit = std::isinf(s->distance)
                                ? set.escaped(s->wi, s->pdf, true)
                                : set.lamps_along_ray({0, 0, 0}, s->wi, 0.0f, INFINITY, s->pdf,
                                                      true);
            ASSERT_NEAR(hit.r, 0.5f * s->value.r, 1e-3f * s->value.r)
                << "light set " << k << ", sample " << i;
            // A ray stopped before the light (tmax < distance) does not see it.
            if (!std::isinf(s->distance)) {
                const Rgb before = set.lamps_along_ray({0, 0, 0}, s->wi, 0.0f,
                                                       0.5f * s->distance, s->pdf, true);
                EXPECT_EQ(before.r, 0.0f);
            }
            ++checked;
        }
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
    EXPECT_FLOAT_EQ(set.escaped({0, 1, 0}, 0.0f, false).b, 1.0f);
    EXPECT_FLOAT_EQ(set.escaped({0, 1, 0}, 0.3f, true).g, 1.0f);
    EXPECT_FLOAT_EQ(set.escaped({0, 1, 0}, 0.3f, true, false).g, 0.0f);
    // With a sun, the world does not dilute the sun's selection probability.
    const LightSet with_sun = build({SunLight{}}, {}, {}, {Rgb(0.5f), 2.0f});
    EXPECT_FLOAT_EQ(with_sun.lamp_selection_probability(), 1.0f);
}

TEST(LightSet, SelectionFollowsCycles) {
    EmissiveTriangle small{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, Rgb(1.0f), 0, 0};
    EmissiveTriangle big{{0, 0, 0}, {3, 0, 0}, {0, 1, 0}, Rgb(1.0f), 0, 1};
    const LightSet set = build({SunLight{}}, {{Vec3{0, 0, 5}, Rgb(1.0f), 1.0f, 0.0f}}, {}, {},
                               {small, big});
    EXPECT_FLOAT_EQ(set.triangle_group_probability(), 0.5f);
    EXPECT_FLOAT_EQ(set.lamp_selection_probability(), 0.25f);
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

}  // namespace
}  // namespace hairis
