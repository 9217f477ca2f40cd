#include "fiber/huang.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/frame.h"
#include "core/quadrature.h"
#include "hemisphere.h"

namespace hairis {
namespace {

HuangFiber make_fiber(float roughness, float aspect, Rgb sigma = {0.245531f, 0.52f, 1.365f}) {
    HuangParams p;
    p.roughness = roughness;
    p.aspect_ratio = aspect;
    p.sigma_a = sigma;
    Expected<HuangFiber> f = HuangFiber::create(p);
    EXPECT_TRUE(f.ok()) << (f.ok() ? "" : f.error().message);
    return std::move(f).value();
}

// Renderer-frame view at θ_o (frame.h: ω_o = (sin θ, 0, −cos θ)).
Vec3 view_at(double theta) { return {float(std::sin(theta)), 0.0f, float(-std::cos(theta))}; }
// A renderer-frame direction at θ and azimuth φ relative to ω_o (φ_o = −π/2).
Vec3 light_at(double theta, double phi) { return direction_of(float(theta), float(phi - kHalfPi)); }
// A curve normal in the renderer frame that puts the major axis at angle `psi` from y.
Vec3 normal_at(double psi) { return {0.3f, float(std::cos(psi)), float(std::sin(psi))}; }

Vec3 normalize_huang(Vec3 v) { return v / length(v); }

// ---------------------------------------------------------------------------------------
// The deterministic expectation against Cycles' one-sample eval.

struct EstimateCase {
    double theta_o, normal_angle, aspect, roughness;
};

class HuangExpectationTest : public ::testing::TestWithParam<EstimateCase> {};

// HuangExpectation (reference rule) is the mean of Cycles' eval over its microfacet samples:
// 12000 replayed evals per direction agree with it within 4 standard errors plus the rule's
// quadrature error (2e-3 relative). Grazing views (|θ_o| ≥ 1.4) included: there the internal
// reflection straddles the critical angle, which the rule must split at.
TEST_P(HuangExpectationTest, MatchesMeanOfCyclesEvals) {
    const EstimateCase c = GetParam();
    const HuangFiber fiber = make_fiber(float(c.roughness), float(c.aspect));
    FiberHit hit;
    hit.wo = view_at(c.theta_o);
    hit.normal = normal_at(c.normal_angle);
    const HuangPoint point = fiber.at(hit);
    HuangQuadrature reference;
    reference.first_order = 16;
    reference.second_order = 12;
    const HuangExpectation expectation = fiber.expectation(point.huang_hit(), reference);
    const double lights[][2] = {{-0.3, 0.4}, {-c.theta_o * 0.9, 2.9}, {0.5, -1.8}, {-0.2, 1.3}};
    CyclesLcg lcg{977};
    // The rule's error is relative to the lobe's scale: 2e-3 of the largest value tested.
    std::vector<Rgb> expected;
    std::vector<std::array<double, 6>> moments;
    double largest = 0.0;
    for (const auto &l : lights) {
        const Vec3 wi = light_at(l[0], l[1]);
        expected.push_back(expectation.f(point.to_huang(wi)));
        const int n = 12000;
        std::array<double, 6> m{};
        for (int i = 0; i < n; ++i) {
            const Rgb e = point.f_estimate(wi, lcg);
            for (int k = 0; k < 3; ++k) {
                m[std::size_t(k)] += e[k] / n;
                m[std::size_t(k) + 3] += double(e[k]) * e[k] / n;
            }
        }
        moments.push_back(m);
        largest = std::max(largest, m[0]);
    }
    for (std::size_t j = 0; j < expected.size(); ++j) {
        for (int k = 0; k < 3; ++k) {
            const double mean = moments[j][std::size_t(k)];
            const double se = std::sqrt(std::max(moments[j][std::size_t(k) + 3] - mean * mean, 0.0) / 12000.0);
            EXPECT_NEAR(expected[j][k], mean, 4.0 * se + 2e-3 * std::max(std::fabs(mean), largest) + 1e-7)
                << "θ_o " << c.theta_o << " light (" << lights[j][0] << ", " << lights[j][1] << ") channel " << k;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(
    Views, HuangExpectationTest,
    ::testing::Values(EstimateCase{0.0, 0.0, 1.0, 0.3}, EstimateCase{0.5, 0.0, 1.0, 0.3},
                      EstimateCase{1.4, 0.0, 1.0, 0.3}, EstimateCase{-1.4, 0.0, 1.0, 0.3},
                      EstimateCase{1.5, 0.0, 1.0, 0.3}, EstimateCase{1.4, 0.6, 0.85, 0.3},
                      EstimateCase{-1.45, 1.2, 0.5, 0.3}, EstimateCase{0.8, 2.0, 0.5, 0.8},
                      EstimateCase{1.4, 0.3, 1.0, 0.8}, EstimateCase{0.3, 0.9, 0.85, 0.05},
                      EstimateCase{1.4, 0.9, 0.85, 0.05}));

// ---------------------------------------------------------------------------------------
// Far field against near field.

// Cycles' near field at offset h with a tiny pixel coverage is J(h)·g(γ(h))/cos θ_v; its
// average over h is the far field's integral without Cycles' discretization. So the far field
// with a refined Simpson rule (16× Cycles' resolution; it converges to the exact integral over
// |u| ≤ 0.999) equals ½∫ near(h) dh, computed here by Gauss–Legendre in γ = −asin(h/R)
// (absorbing the edge singularity of the Jacobian). Same microfacet rule on both sides.
TEST(Huang, FarFieldIsNearFieldAveragedOverOffset) {
    for (double aspect : {1.0, 0.5}) {
        const HuangFiber fiber = make_fiber(0.4f, float(aspect));
        const Vec3 wo = normalize_huang({0.45f, 0.6f, 0.66f});
        HuangQuadrature rule;
        rule.first_order = 5;
        rule.second_order = 3;
        HuangQuadrature refined = rule;
        refined.simpson_refinement = 16;
        const HuangExpectation far = fiber.expectation({wo, 0.0f, 1.0f}, refined);
        const double radius = far.view().radius, edge = std::asin(0.999);
        const QuadratureRule gamma = QuadratureRule::composite(-edge, edge, 6, 8);
        const Vec3 lights[] = {normalize_huang({-0.3f, 0.5f, -0.8f}), normalize_huang({-0.5f, -0.6f, 0.2f}),
                               normalize_huang({0.2f, 0.9f, 0.3f})};
        for (const Vec3 &wi : lights) {
            double average = 0.0;
            for (std::size_t k = 0; k < gamma.x.size(); ++k) {
                const double u = std::sin(gamma.x[k]);
                const HuangExpectation near =
                    fiber.expectation({wo, float(u * radius), 1e-3f}, rule);
                ASSERT_TRUE(near.view().near);
                // far = ½∫ near du over u = h/R; du = cos γ dγ
                average += 0.5 * gamma.w[k] * std::cos(gamma.x[k]) * luminance(near.f(wi));
            }
            EXPECT_NEAR(luminance(far.f(wi)), average, 5e-3 * average + 1e-6) << "aspect " << aspect;
        }
    }
}

// ---------------------------------------------------------------------------------------
// White furnace.

// ∫ f dω_i over the sphere.
template <typename F>
double albedo(const F &f) {
    return testing::integrate_fiber_sphere(f);
}

struct FurnaceCase {
    double theta_o_degrees, roughness, aspect;
};
class HuangFurnaceTest : public ::testing::TestWithParam<FurnaceCase> {};

// A clear fiber (σ = 0, multipliers 1). Cycles' far field is ½ Σ_k s_k A(u_k): the Simpson
// weights s_k = (2Δ/3)c_k over u = h/R clamped to ±0.999 applied to the near-field albedo
// A(u) (the albedo of the fiber hit at offset u, near field with a tiny pixel), for R on its
// 0.7α grid and the other lobes on their 0.8α grid. The test predicts the furnace albedo that
// way, from near fields, and compares.
// Views whose h-range ends at the clamp ±0.999 (θ_o ≤ ~50° for Offset 2°): where it ends at
// the mesonormal's visibility limit instead, Cycles' end node has v·n₁ = 0 up to rounding
// and its TRRT+ term (which has no cosine factor) counts or not by rounding, in Cycles too.
TEST_P(HuangFurnaceTest, AlbedoIsCyclesSimpsonRuleOfNearFieldAlbedo) {
    const FurnaceCase c = GetParam();
    const HuangFiber fiber = make_fiber(float(c.roughness), float(c.aspect), Rgb(0.0f));
    const double theta = radians(c.theta_o_degrees);
    const Vec3 wo{float(std::sin(theta)), float(std::cos(theta) * 0.8), float(std::cos(theta) * 0.6)};
    HuangQuadrature rule;
    rule.first_order = 4;
    rule.second_order = 3;
    const HuangExpectation far = fiber.expectation({wo, 0.0f, 1.0f}, rule);
    const huang::View &v = far.view();
    ASSERT_FALSE(v.empty);
    const double far_albedo = albedo([&](Vec3 wi) { return double(far.f(wi).r); });
    // The prediction: near-field albedos at Cycles' nodes, per lobe group.
    auto near_albedo = [&](double u, int first_lobe, int last_lobe) {
        // A pixel of 1e-6 radii, kept inside [u_min, u_max]: at an end Cycles' pixel interval
        // would be cut in half by the clamp (or the visible range) while d counts all of it.
        const double inside = std::clamp(u, v.u_min + 2e-6, v.u_max - 2e-6);
        const HuangExpectation near = fiber.expectation({wo, float(inside * v.radius), 1e-6f}, rule);
        return albedo([&](Vec3 wi) {
            const std::array<Rgb, 4> l = near.lobes(wi);
            double s = 0.0;
            for (int p = first_lobe; p <= last_lobe; ++p) s += l[std::size_t(p)].r;
            return s;
        });
    };
    auto simpson = [&](int intervals, double delta, int first_lobe, int last_lobe) {
        double sum = 0.0;
        for (int k = 0; k <= intervals; ++k) {
            const double ck = (k == 0 || k == intervals) ? 0.5 : double(k % 2 + 1);
            sum += (2.0 / 3.0) * delta * ck * near_albedo(v.u_min + k * delta, first_lobe, last_lobe);
        }
        return 0.5 * sum;
    };
    const double predicted = simpson(v.r_intervals, v.r_delta, 0, 0) + simpson(v.res_intervals, v.res_delta, 1, 3);
    EXPECT_NEAR(far_albedo, predicted, 0.01 * predicted) << "θ_o " << c.theta_o_degrees;
    RecordProperty("far_albedo", std::to_string(far_albedo));
}

INSTANTIATE_TEST_SUITE_P(Views, HuangFurnaceTest,
                         ::testing::Values(FurnaceCase{-85, 0.3, 1.0}, FurnaceCase{0, 0.3, 1.0},
                                           FurnaceCase{-60, 0.8, 0.85}, FurnaceCase{-85, 0.1, 0.5},
                                           FurnaceCase{-40, 0.1, 1.0}, FurnaceCase{45, 0.8, 1.0},
                                           FurnaceCase{30, 0.3, 0.5}));

// ---------------------------------------------------------------------------------------
// Symmetries, lobes, frames and validation.

// A circular fiber depends on the relative azimuth only, symmetrically: f(φ) = f(−φ). The R
// lobe is deterministic (exact to rounding); the others mirror up to the microfacet rule.
TEST(Huang, CircularFiberIsSymmetricInRelativeAzimuth) {
    const HuangFiber fiber = make_fiber(0.3f, 1.0f);
    FiberHit hit;
    hit.wo = view_at(0.4);
    const HuangHit h = fiber.at(hit).huang_hit();
    HuangQuadrature rule;
    rule.first_order = 10;
    rule.second_order = 6;
    const HuangExpectation e = fiber.expectation(h, rule);
    for (double phi : {0.3, 1.1, 2.0, 2.9}) {
        const std::array<Rgb, 4> a = e.lobes(light_at(-0.5, phi)), b = e.lobes(light_at(-0.5, -phi));
        EXPECT_NEAR(a[0].g, b[0].g, 1e-5 * a[0].g + 1e-9) << phi;  // float directions
        for (int p = 1; p < 4; ++p) EXPECT_NEAR(a[std::size_t(p)].g, b[std::size_t(p)].g, 0.02 * a[std::size_t(p)].g + 1e-5) << phi << " lobe " << p;
    }
}

// The ellipse is symmetric about both axes: mirroring ω_o and ω_i across the major axis
// (y → −y in Huang's frame) or the minor axis (z → −z) leaves f unchanged.
TEST(Huang, EllipseIsSymmetricAboutItsAxes) {
    const HuangFiber fiber = make_fiber(0.3f, 0.6f);
    HuangQuadrature rule;
    rule.first_order = 6;
    rule.second_order = 4;
    const Vec3 wo = normalize_huang({0.3f, 0.5f, 0.8f}), wi = normalize_huang({-0.4f, -0.2f, 0.6f});
    const HuangExpectation e = fiber.expectation({wo, 0.0f, 1.0f}, rule);
    const double reference = luminance(e.f(wi));
    ASSERT_GT(reference, 0.0);
    const HuangExpectation ey = fiber.expectation({{wo.x, -wo.y, wo.z}, 0.0f, 1.0f}, rule);
    const HuangExpectation ez = fiber.expectation({{wo.x, wo.y, -wo.z}, 0.0f, 1.0f}, rule);
    EXPECT_NEAR(luminance(ey.f({wi.x, -wi.y, wi.z})), reference, 0.02 * reference);
    EXPECT_NEAR(luminance(ez.f({wi.x, wi.y, -wi.z})), reference, 0.02 * reference);
    // An elliptical fiber is not rotationally symmetric: turning ω_o alone changes f.
    const Vec3 turned{wo.x, wo.z, -wo.y};
    const HuangExpectation et = fiber.expectation({turned, 0.0f, 1.0f}, rule);
    EXPECT_GT(std::fabs(luminance(et.f({wi.x, wi.z, -wi.y})) - reference), 0.02 * reference);
}

// Each multiplier scales its own lobe; 0 switches it off. TRRT+ is not scaled by any
// multiplier, but disappears with Secondary Reflection = 0 (§6.2).
TEST(Huang, LobeMultipliers) {
    auto lobes = [](float r, float tt, float trt) {
        HuangParams p;
        p.reflection = r;
        p.transmission = tt;
        p.secondary_reflection = trt;
        p.aspect_ratio = 1.0f;
        const HuangFiber fiber = HuangFiber::create(p).value();
        HuangQuadrature rule;
        rule.first_order = 4;
        rule.second_order = 3;
        const HuangExpectation e = fiber.expectation({normalize_huang({0.3f, 0.0f, 1.0f}), 0.0f, 1.0f}, rule);
        std::array<Rgb, 4> sum{};
        for (const Vec3 wi : {normalize_huang({-0.2f, 0.1f, -1.0f}), normalize_huang({-0.4f, 0.9f, 0.5f})}) {
            const std::array<Rgb, 4> l = e.lobes(wi);
            for (int q = 0; q < 4; ++q) sum[std::size_t(q)] += l[std::size_t(q)];
        }
        return sum;
    };
    const std::array<Rgb, 4> all = lobes(1, 1, 1);
    for (int q = 0; q < 4; ++q) ASSERT_GT(all[std::size_t(q)].g, 0.0f) << q;
    const std::array<Rgb, 4> no_r = lobes(0, 1, 1), no_tt = lobes(1, 0, 1), no_trt = lobes(1, 1, 0);
    EXPECT_EQ(no_r[0].g, 0.0f);
    EXPECT_EQ(no_tt[1].g, 0.0f);
    EXPECT_EQ(no_trt[2].g, 0.0f);
    EXPECT_EQ(no_trt[3].g, 0.0f);
    for (int q : {1, 2, 3}) EXPECT_FLOAT_EQ(no_r[std::size_t(q)].g, all[std::size_t(q)].g) << q;
    for (int q : {0, 2, 3}) EXPECT_FLOAT_EQ(no_tt[std::size_t(q)].g, all[std::size_t(q)].g) << q;
    EXPECT_FLOAT_EQ(no_trt[1].g, all[1].g);
    const std::array<Rgb, 4> half = lobes(0.5f, 2.0f, 0.5f);
    EXPECT_FLOAT_EQ(half[0].g, 0.5f * all[0].g);
    EXPECT_FLOAT_EQ(half[1].g, 2.0f * all[1].g);
    EXPECT_FLOAT_EQ(half[2].g, 0.5f * all[2].g);
    EXPECT_FLOAT_EQ(half[3].g, all[3].g);  // TRRT+ ignores the multiplier
    // Transmission 0 and Reflection 0 leave TRRT+ on (it follows Secondary Reflection only).
    EXPECT_FLOAT_EQ(lobes(0, 0, 1)[3].g, all[3].g);
}

// With Secondary Reflection 0, TT is a lobe's whole transmitted part, and TT chains that
// leave at the edge of total internal reflection sum to a rounding error below zero there (the
// bake refused such a material as "not finite and non-negative"): no lobe is ever negative.
TEST(Huang, LobesAreNeverNegative) {
    HuangParams p;
    p.secondary_reflection = 0.0f;
    const HuangFiber fiber = HuangFiber::create(p).value();
    HuangQuadrature rule;
    rule.tt_order = 8;
    // The bake's θ_o node 20 of 24 (63.8°) at φ_o = 60°, and its (θ_i, φ) cell midpoints.
    const float theta_o = float(-kHalfPi + kPi * 20.5 / 24.0), phi_o = float(kPi / 3.0);
    const HuangExpectation e = fiber.expectation({direction_of(theta_o, phi_o), 0.0f, 1.0f}, rule);
    int lit = 0;
    for (int i = 0; i < 48; ++i)
        for (int j = 0; j < 64; ++j) {
            const float theta_i = float(std::asin(-1.0 + (2.0 * i + 1.0) / 48.0));
            const float phi = float(-kPi + kTwoPi * (j + 0.5) / 64.0);
            const std::array<Rgb, 4> l = e.lobes(direction_of(theta_i, phi_o + phi));
            for (int q = 0; q < 4; ++q)
                for (float v : {l[std::size_t(q)].r, l[std::size_t(q)].g, l[std::size_t(q)].b})
                    ASSERT_GE(v, 0.0f) << "lobe " << q << " at cell " << i << ", " << j;
            lit += l[1].g > 0.0f;
        }
    EXPECT_GT(lit, 100);  // TT is there
}

TEST(Huang, ValidationNamesParameterAndRange) {
    auto message = [](HuangParams p) {
        const Expected<HuangFiber> f = HuangFiber::create(p);
        return f.ok() ? std::string("ok") : f.error().message;
    };
    HuangParams p;
    p.roughness = 1.5f;
    EXPECT_NE(message(p).find("roughness"), std::string::npos);
    EXPECT_NE(message(p).find("[0, 1]"), std::string::npos) << message(p);
    p = {};
    p.ior = 0.9f;
    EXPECT_NE(message(p).find("ior must be in (1, 1000]"), std::string::npos) << message(p);
    p = {};
    p.aspect_ratio = 0.0f;
    EXPECT_NE(message(p).find("aspect_ratio must be in (0, 1000]"), std::string::npos) << message(p);
    p = {};
    p.offset = 2.0f;
    EXPECT_NE(message(p).find("offset"), std::string::npos);
    p = {};
    p.sigma_a.g = -1.0f;
    EXPECT_NE(message(p).find("sigma_a.g"), std::string::npos);
    p = {};
    p.transmission = -0.5f;
    EXPECT_NE(message(p).find("transmission"), std::string::npos);
    p = {};
    p.secondary_reflection = std::nanf("");
    EXPECT_NE(message(p).find("secondary_reflection"), std::string::npos);
    p = {};
    p.reflection = p.transmission = p.secondary_reflection = 0.0f;
    EXPECT_NE(message(p).find("Cycles allocates no closure"), std::string::npos) << message(p);
    p = {};
    p.aspect_ratio = 2.0f;  // inverted like Cycles
    EXPECT_EQ(message(p), "ok");
    EXPECT_DOUBLE_EQ(HuangFiber::create(p).value().aspect_ratio(), 0.5);
}

// Cycles' make_orthonormals fallback for curves without normals, at two tangents.
TEST(Huang, FallbackFrameIsCyclesMakeOrthonormals) {
    const Vec3 a = HuangFiber::fallback_major_axis({0, 0, 1});
    // c = normalize((1,1,1) × t) = (1, −1, 0)/√2, a = t × c = (1, 1, 0)/√2.
    EXPECT_NEAR(a.x, 1.0 / std::sqrt(2.0), 1e-6);
    EXPECT_NEAR(a.y, 1.0 / std::sqrt(2.0), 1e-6);
    EXPECT_NEAR(a.z, 0.0, 1e-6);
    // Equal components: c = normalize(t_z − t_y, t_x + t_z, −t_y − t_x) = (0, 1, −1)/√2.
    const float s = float(1.0 / std::sqrt(3.0));
    const Vec3 b = HuangFiber::fallback_major_axis({s, s, s});
    const Vec3 c{0.0f, float(1.0 / std::sqrt(2.0)), float(-1.0 / std::sqrt(2.0))};
    const Vec3 expected = cross(Vec3{s, s, s}, c);
    EXPECT_NEAR(b.x, expected.x, 1e-6);
    EXPECT_NEAR(b.y, expected.y, 1e-6);
    EXPECT_NEAR(b.z, expected.z, 1e-6);
    // A normal along the tangent has no perpendicular part: no major axis.
    const Vec3 none = HuangFiber::major_axis({1, 0, 0}, {2, 0, 0});
    EXPECT_EQ(length(none), 0.0f);
}

// The renderer's point puts the major axis on the curve normal: turning the normal about the
// tangent is the same as turning ω_o and ω_i the other way in Huang's frame.
TEST(Huang, PointRotatesIntoHuangFrame) {
    const HuangFiber fiber = make_fiber(0.3f, 0.5f);
    FiberHit hit;
    hit.wo = view_at(0.3);
    hit.normal = {0.4f, 0.0f, 2.0f};  // major axis along the renderer's z (towards the view)
    const HuangPoint point = fiber.at(hit);
    const HuangHit h = point.huang_hit();
    EXPECT_NEAR(h.wo.x, hit.wo.x, 1e-6);
    EXPECT_NEAR(h.wo.y, hit.wo.z, 1e-6);   // y_h = z_r
    EXPECT_NEAR(h.wo.z, -hit.wo.y, 1e-6);  // z_h = x × y_h = −y_r
    // Looking along the major axis the ellipse is as wide as its minor axis: R = b.
    EXPECT_NEAR(point.projected_radius(), 0.5, 1e-6);
    FiberHit across = hit;
    across.normal = {0.0f, 1.0f, 0.0f};  // major axis across the view: R = 1
    EXPECT_NEAR(fiber.at(across).projected_radius(), 1.0, 1e-6);
    FiberHit side = hit;
    // Offsets beyond the projected radius are Cycles' transparent hits: no scattering.
    side.h = 0.6f;
    EXPECT_TRUE(fiber.at(side).transparent());
    CyclesLcg lcg{1};
    EXPECT_EQ(fiber.at(side).f_estimate(light_at(0.1, 1.0), lcg).g, 0.0f);
    EXPECT_FALSE(fiber.at(side).sample_cycles(0.5f, 0.5f, 0.5f, lcg).has_value());
}

// Cycles' bsdf_hair_huang_albedo in its closure frame (N the major axis, Y the tangent, Z = N × Y):
// the macro normal at h is (h, 0, √(1 − h²)), F is fresnel_dielectric of its cosine with ω_o,
// which takes |cos| with the fiber's η, cos_t = −√(η² − 1 + cos²)/η, the refracted view's Y is
// −ω_o·Y/η, A = exp(2σ cos_t / (1 − Y²)) and the albedo (A − 2FA + F)/(1 − FA). F here is
// Cycles' fresnel_dielectric_cos form, not the library's. An elliptic fiber hit near the edge
// whose major axis is turned away from the view has a negative cosine.
TEST(Huang, AlbedoIsCyclesEstimate) {
    const HuangFiber fiber = make_fiber(0.3f, 0.5f);
    const double eta = fiber.ior();
    for (const double axis_degrees : {70.0, 20.0, -50.0}) {
        const double a = axis_degrees * kPi / 180.0;
        FiberHit hit;
        hit.wo = view_at(0.4);
        hit.normal = {0.0f, float(std::cos(a)), float(std::sin(a))};
        hit.h = 0.55f;
        const HuangPoint point = fiber.at(hit);
        ASSERT_FALSE(point.transparent()) << axis_degrees;
        const Vec3d n{0.0, std::cos(a), std::sin(a)}, tangent{1.0, 0.0, 0.0}, z = cross(n, tangent);
        const Vec3d wo(hit.wo);
        const double ix = dot(wo, n), iy = dot(wo, tangent), iz = dot(wo, z), h = hit.h;
        const double cos_i = h * ix + std::sqrt(1.0 - h * h) * iz;
        if (axis_degrees == 70.0) {
            ASSERT_LT(cos_i, 0.0);  // the macro normal faces away
        }
        const double c = std::fabs(cos_i), g = std::sqrt(eta * eta - 1.0 + c * c);
        const double fa = (g - c) / (g + c), fb = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
        const double f = 0.5 * fa * fa * (1.0 + fb * fb);
        const double cos_t = -g / eta, wt_y = -iy / eta;
        const Rgb albedo = point.albedo();
        for (int k = 0; k < 3; ++k) {
            const double t = std::exp(2.0 * double(fiber.sigma()[std::size_t(k)]) * cos_t / (1.0 - wt_y * wt_y));
            EXPECT_NEAR(albedo[k], (t - 2.0 * f * t + f) / (1.0 - f * t), 1e-5) << axis_degrees << " " << k;
        }
    }
}

// f_estimate_difference is the fiber's eval minus another absorption's along the same chains:
// draw by draw the difference of the two fibers' own evals replaying one stream, at far and
// near field, a grazing view (total internal reflection at most exits) and a clear fiber.
TEST(Huang, EstimateDifferenceIsTheDifferenceOfTwoEvalsOnOneStream) {
    const Rgb sigmas[] = {{0.0f, 0.0f, 0.0f}, {2.0f, 0.7f, 0.05f}};
    for (const double theta_o : {0.4, 1.45})
        for (const float h : {0.0f, 0.35f}) {
            const HuangFiber a = make_fiber(0.3f, 0.8f), b = make_fiber(0.3f, 0.8f, sigmas[h > 0.0f ? 1 : 0]);
            FiberHit hit;
            hit.wo = view_at(theta_o);
            hit.normal = normal_at(0.4);
            hit.h = h;
            hit.pixel_coverage = h > 0.0f ? 0.01f : 1.0f;  // near field: a pixel narrower than the fiber
            const HuangPoint pa = a.at(hit), pb = b.at(hit);
            ASSERT_EQ(pa.near_field(), h > 0.0f);
            CyclesLcg lcg{41};
            double largest = 0.0;
            for (int n = 0; n < 200; ++n) {
                const Vec3 wi = light_at(-0.6 + 0.006 * n, 0.031 * n);
                CyclesLcg replay_a = lcg, replay_b = lcg;
                const Rgb expected = pa.f_estimate(wi, replay_a) - pb.f_estimate(wi, replay_b);
                const Rgb d = pa.f_estimate_difference(wi, lcg, b);
                for (int k = 0; k < 3; ++k) {
                    ASSERT_NEAR(d[k], expected[k], 1e-6 * (1.0 + std::fabs(expected[k]))) << theta_o << " " << n;
                    largest = std::max(largest, std::fabs(double(expected[k])));
                }
                ASSERT_EQ(lcg.state, replay_a.state);  // it draws as one eval does
            }
            EXPECT_GT(largest, 1e-3) << "the absorptions must differ visibly at θ_o " << theta_o;
        }
}

// Cycles' sampler is an unbiased estimator of its own scattering: the mean weight over many
// samples is the sampler's albedo. The reference is Cycles itself: a thin clear fiber in a white
// world with BSDF sampling only renders the sampler's albedo (docs/huang.md §14: bpy 4.5, σ = 0,
// α = 0.3, aspect 1, Offset 2°), quoted to three decimals; the estimate must match within four
// of its standard errors plus that rounding and the render's own noise.
TEST(Huang, CyclesSamplerAlbedoIsCyclesFurnace) {
    struct Furnace {
        double theta_o, cycles;
    };
    for (const Furnace &c : {Furnace{0.0, 1.007}, Furnace{0.5, 1.010}, Furnace{1.0, 1.017}, Furnace{1.4, 0.994}}) {
        const HuangFiber fiber = make_fiber(0.3f, 1.0f, Rgb(0.0f));
        FiberHit hit;
        hit.wo = view_at(c.theta_o);
        const HuangPoint point = fiber.at(hit);
        CyclesLcg lcg{5};
        CyclesLcg rand{11};
        const int n = 600000;
        double sum = 0.0, sum2 = 0.0;
        for (int i = 0; i < n; ++i) {
            const float u0 = rand.next(), u1 = rand.next(), u2 = rand.next();
            const std::optional<HuangCyclesSample> s = point.sample_cycles(u0, u1, u2, lcg);
            const double w = s ? double(s->weight.g) : 0.0;
            sum += w;
            sum2 += w * w;
        }
        const double mean = sum / n;
        const double standard_error = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
        EXPECT_NEAR(mean, c.cycles, 4.0 * standard_error + 0.002)
            << "θ_o " << c.theta_o << ", standard error " << standard_error;
        EXPECT_LT(4.0 * standard_error + 0.002, 0.005);  // resolves a 1% error
    }
}

}  // namespace
}  // namespace hairis

namespace hairis {
namespace {

// A far-field view remembers the last ω_i's lobes per thread; a new view must never see the
// lobes of a destroyed one, even when it is allocated at the same address.
TEST(Huang, FarFieldViewsNeverShareCachedLobes) {
    HuangQuadrature rule;
    rule.first_order = 3;
    rule.second_order = 2;
    const HuangFiber fiber = HuangFiber::create(HuangParams{}, rule).value();
    const Vec3 wi = direction_of(-0.3f, 0.4f + float(kPi));  // forward scattering: all lobes
    const Vec3 first = direction_of(0.3f, 0.4f), second = direction_of(0.2f, 0.1f);
    const std::array<Rgb, 4> a = fiber.expectation({first, 0.0f, 1.0f}, rule).lobes(wi);
    const std::array<Rgb, 4> b = fiber.expectation({second, 0.0f, 1.0f}, rule).lobes(wi);
    for (int p = 0; p < 4; ++p) ASSERT_NE(luminance(a[size_t(p)]), luminance(b[size_t(p)])) << p;
    for (int k = 0; k < 4; ++k) {
        fiber.view(first)->lobe_f_cos(0, wi);  // destroyed at once
        const std::unique_ptr<const FarFieldView> v = fiber.view(second);
        for (int p = 0; p < 4; ++p) EXPECT_EQ(luminance(v->lobe_f_cos(p, wi)), luminance(b[size_t(p)])) << k << " lobe " << p;
    }
}

// HuangQuadrature::tt_order refines TT's entry rule alone: TT is then the TT of the finer first
// rule, TRT and TRRT+ stay the coarse rule's, and TT comes closer to the reference rule.
TEST(Huang, TtOrderRefinesTtAlone) {
    const HuangFiber fiber = make_fiber(0.3f, 0.85f);
    FiberHit hit;
    hit.wo = view_at(0.2);
    hit.normal = normal_at(0.4);
    const HuangPoint point = fiber.at(hit);
    HuangQuadrature coarse, refined, fine, reference;
    coarse.first_order = refined.first_order = 4;
    coarse.second_order = refined.second_order = fine.second_order = 3;
    refined.tt_order = fine.first_order = 8;
    reference.first_order = 16;
    reference.second_order = 1;  // TT reads the first rule only
    const HuangHit h = point.huang_hit();
    const HuangExpectation ec = fiber.expectation(h, coarse), er = fiber.expectation(h, refined),
                           ef = fiber.expectation(h, fine), ref = fiber.expectation(h, reference);
    double error_coarse = 0, error_refined = 0, total = 0;
    for (int i = 0; i < 24; ++i)
        for (int j = 0; j < 48; ++j) {
            const Vec3 wi = point.to_huang(light_at(-1.5 + 3.0 * (i + 0.5) / 24, -kPi + kTwoPi * (j + 0.5) / 48));
            const auto c = ec.lobes(wi), r = er.lobes(wi), f = ef.lobes(wi), x = ref.lobes(wi);
            for (int k = 0; k < 3; ++k) {
                EXPECT_NEAR(r[1][k], f[1][k], 1e-6 * (1.0 + f[1][k])) << i << " " << j;  // TT: the fine rule's
                EXPECT_EQ(r[2][k], c[2][k]) << i << " " << j;                              // TRT: the coarse rule's
                EXPECT_EQ(r[3][k], c[3][k]) << i << " " << j;                              // TRRT+
            }
            error_coarse += std::fabs(double(c[1].g) - x[1].g);
            error_refined += std::fabs(double(r[1].g) - x[1].g);
            total += x[1].g;
        }
    EXPECT_GT(total, 0.0);
    EXPECT_LT(error_refined, error_coarse / 3.0) << "TT's L1 error: coarse " << error_coarse / total << ", refined "
                                                 << error_refined / total;
}

}  // namespace
}  // namespace hairis

