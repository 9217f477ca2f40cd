#include "render/ggx_albedo.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/quadrature.h"
#include "fiber/fresnel.h"
#include "hemisphere.h"
#include "render/microfacet.h"

namespace hairis {
namespace {

// The integrals of the header, written over outgoing directions ω_i instead of visible normals:
// the visible-normal density pushed to ω_i is ggx_reflection_pdf (the sampler's density), the
// single-scattering f·cos with F = 1 is D G2 / (4 μ).
Vec3 view(double mu) { return {float(std::sqrt(1.0 - mu * mu)), 0.0f, float(mu)}; }

double albedo_over_directions(double alpha, double mu) {
    const Vec3 wo = view(mu);
    const float a2 = float(alpha * alpha);
    return testing::integrate_hemisphere([&](Vec3 wi) {
        const Vec3 h = safe_normalize(wo + wi);
        const double d = microfacet::ggx_d(a2, wo + wi);
        const double g = 1.0 / (1.0 + microfacet::ggx_lambda(a2, wo.z) + microfacet::ggx_lambda(a2, wi.z));
        return h.z > 0.0f ? d * g / (4.0 * wo.z) : 0.0;
    });
}

template <typename S>
double factor_over_directions(double alpha, double mu, const S &s) {
    const Vec3 wo = view(mu);
    return testing::integrate_hemisphere([&](Vec3 wi) {
        const Vec3 h = safe_normalize(wo + wi);
        return double(microfacet::ggx_reflection_pdf(wo, wi, float(alpha))) * s(double(dot(wo, h)));
    });
}

TEST(GgxAlbedo, AlbedoEqualsTheIntegralOverDirections) {
    for (double r : {0.35, 0.6, 0.9})
        for (double mu : {0.15, 0.5, 0.95}) {
            const double alpha = r * r;
            EXPECT_NEAR(ggx_reflection_albedo(alpha, mu), albedo_over_directions(alpha, mu), 1e-3)
                << "r " << r << " mu " << mu;
        }
}

TEST(GgxAlbedo, SmoothLobeLosesNothingAndRougherOnesLoseMore) {
    // A mirror-like lobe reflects everything; single scattering loses more with roughness.
    EXPECT_NEAR(ggx_reflection_albedo(1e-6, 0.5), 1.0, 1e-4);
    double previous = 1.0;
    for (double alpha : {0.06, 0.25, 0.5, 1.0}) {
        const double e = ggx_reflection_albedo(alpha, 0.5);
        EXPECT_LT(e, previous) << "alpha " << alpha;
        previous = e;
    }
}

TEST(GgxAlbedo, AverageIsTheCosineWeightedMeanOverViews) {
    const double alpha = 0.49;
    const GaussLegendre &rule = GaussLegendre::rule(12);
    double expected = 0.0;
    rule.for_each(0.0, 1.0, [&](double mu, double w) { expected += w * 2.0 * mu * albedo_over_directions(alpha, mu); });
    EXPECT_NEAR(ggx_reflection_albedo_average(alpha), expected, 2e-3);
}

TEST(GgxAlbedo, FresnelFactorsEqualTheIntegralsOverDirections) {
    for (double r : {0.4, 0.8})
        for (double mu : {0.2, 0.7})
            for (double eta : {1.33, 1.5, 2.5}) {
                const double f0 = fresnel_dielectric(1.0, eta);
                const double expected = factor_over_directions(r * r, mu, [&](double c) {
                    return std::clamp((fresnel_dielectric(c, eta) - f0) / (1.0 - f0), 0.0, 1.0);
                });
                EXPECT_NEAR(ggx_fresnel_factor_ior(r * r, mu, eta), expected, 1e-3)
                    << "r " << r << " mu " << mu << " eta " << eta;
            }
    for (double p : {4.375, 5.0, 5.714}) {
        const double expected = factor_over_directions(0.3, 0.4, [&](double c) { return std::pow(1.0 - c, p); });
        EXPECT_NEAR(ggx_fresnel_factor_exponent(0.3, 0.4, p), expected, 1e-3) << "p " << p;
    }
}

TEST(GgxAlbedo, TablesUseCyclesGridsAndInterpolation) {
    const GgxAlbedoTables &t = GgxAlbedoTables::tables();
    // Nodes sit at multiples of 1/(n − 1) with the ends clamped.
    EXPECT_DOUBLE_EQ(GgxAlbedoTables::e_roughness(0), 1e-4);
    EXPECT_DOUBLE_EQ(GgxAlbedoTables::e_roughness(31), 1.0);
    EXPECT_DOUBLE_EQ(GgxAlbedoTables::e_cosine(10), 10.0 / 31.0);
    EXPECT_DOUBLE_EQ(GgxAlbedoTables::s_ior_of(0), (1.0 + 1e-8) / (1.0 - 1e-8));
    EXPECT_NEAR(GgxAlbedoTables::s_exponent_of(15), 5.0 * 0.01 / 0.99, 1e-12);
    // A node is the integral at its parameters.
    const double r = GgxAlbedoTables::e_roughness(12), mu = GgxAlbedoTables::e_cosine(20);
    EXPECT_NEAR(t.e_node(12, 20), ggx_reflection_albedo(r * r, mu), 1e-6);
    EXPECT_FLOAT_EQ(t.e(12.0f / 31.0f, 20.0f / 31.0f), t.e_node(12, 20));
    // Between nodes the lookup is multilinear (a quarter of the way along r, half along μ).
    const float x = (12.0f + 0.25f) / 31.0f, y = (20.0f + 0.5f) / 31.0f;
    const double bilinear = 0.75 * 0.5 * t.e_node(12, 20) + 0.25 * 0.5 * t.e_node(13, 20) +
                            0.75 * 0.5 * t.e_node(12, 21) + 0.25 * 0.5 * t.e_node(13, 21);
    EXPECT_NEAR(t.e(x, y), bilinear, 1e-6);
    // 3D: the middle of the z axis of the exponent table blends slices 7 and 8 equally.
    const float rx = 6.0f / 15.0f, my = 9.0f / 15.0f;
    EXPECT_NEAR(t.s_exponent(rx, my, 0.5f), 0.5 * (t.s_exponent_node(6, 9, 7) + t.s_exponent_node(6, 9, 8)), 1e-6);
    const double eta = GgxAlbedoTables::s_ior_of(5);
    EXPECT_NEAR(t.s_ior_node(6, 9, 5), ggx_fresnel_factor_ior(sqr(GgxAlbedoTables::s_roughness(6)),
                                                              GgxAlbedoTables::s_cosine(9), eta), 1e-6);
    // Coordinates outside [0, 1] clamp to the edge.
    EXPECT_FLOAT_EQ(t.e(-0.5f, 2.0f), t.e_node(0, 31));
    EXPECT_FLOAT_EQ(t.e_avg(1.5f), t.e_avg_node(31));
}

}  // namespace
}  // namespace hairis
