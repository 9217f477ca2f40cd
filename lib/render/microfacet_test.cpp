#include "render/microfacet.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "chi2.h"
#include "fiber/ggx.h"
#include "hemisphere.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Chi2Result;
using testing::Sample3;

// Every χ² test of this file, for the Šidák correction.
constexpr int kChi2Tests = 7;

// ∫₀¹ 2π g(h) c dc for an isotropic g of the normal h = (sin θ, 0, c) sharply peaked at
// c = 1: in t = −ln(1 − c), with sin θ from 1 − c in double so that h keeps its tilt in float.
template <typename G>
double integrate_cosine_peaked(const G &g) {
    const GaussLegendre &rule = GaussLegendre::rule(8);
    double sum = 0.0;
    for (int i = 0; i < 400; ++i)
        rule.for_each(0.05 * i, 0.05 * (i + 1), [&](double t, double w) {
            const double one_minus_c = std::exp(-t), c = 1.0 - one_minus_c;
            const Vec3 h{float(std::sqrt(one_minus_c * (1.0 + c))), 0.0f, float(c)};
            sum += w * one_minus_c * kTwoPi * g(h) * c;
        });
    return sum;
}

TEST(Microfacet, GgxDistributionProjectsToUnitArea) {
    // ∫ D(h) cos θ_h dω_h = 1 for every α (the normalization of a microfacet distribution).
    for (float alpha : {0.01f, 0.1f, 0.3f, 0.6f, 1.0f}) {
        const double area = integrate_cosine_peaked(
            [&](Vec3 h) { return double(microfacet::ggx_d(alpha * alpha, h)); });
        EXPECT_NEAR(area, 1.0, 2e-4) << "alpha " << alpha;
    }
}

TEST(Microfacet, GgxVisibleAreaIsTheProjectedView) {
    // Heitz 2014: ∫ G1(ω_o) max(0, ω_o·h) D(h) dω_h = cos θ_o, tying Λ to D.
    for (float alpha : {0.15f, 0.5f, 0.9f})
        for (double theta : {0.2, 0.9, 1.35}) {
            const Vec3 wo = testing::polar_direction(theta, 0.4);
            const float a2 = alpha * alpha;
            const double visible = testing::integrate_hemisphere([&](Vec3 h) {
                return microfacet::ggx_g1(a2, wo.z) * std::max(0.0f, dot(wo, h)) *
                       microfacet::ggx_d(a2, h.z);
            }, 192, 96);
            EXPECT_NEAR(visible, wo.z, 5e-4 * wo.z + 1e-5) << "alpha " << alpha << " theta " << theta;
        }
}

TEST(Microfacet, GgxLambdaClosedFormAtAlphaOne) {
    // α = 1: Λ(θ) = (sqrt(1 + tan²θ) − 1)/2 = (1/cos θ − 1)/2.
    for (double c : {0.05, 0.3, 0.7, 0.99})
        EXPECT_NEAR(microfacet::ggx_lambda(1.0f, float(c)), 0.5 * (1.0 / c - 1.0), 1e-5 / c);
    EXPECT_EQ(microfacet::ggx_lambda(0.3f, 1.0f), 0.0f);
}

TEST(Microfacet, FloatTermsAgreeWithTheDoublePrecisionModel) {
    // lib/fiber/ggx is a separate double-precision implementation (Huang's fiber uses it).
    for (double alpha : {0.05, 0.3, 0.8})
        for (double c : {0.02, 0.4, 0.97}) {
            const float a = float(alpha);
            EXPECT_NEAR(microfacet::ggx_d(a * a, float(c)), ggx::distribution(alpha, c),
                        2e-5 * ggx::distribution(alpha, c));
            EXPECT_NEAR(microfacet::ggx_lambda(a * a, float(c)), ggx::smith_lambda(alpha, c),
                        1e-4 * (1.0 + ggx::smith_lambda(alpha, c)));
            const Vec3 h{float(std::sqrt(1.0 - c * c)), 0.0f, float(c)};
            EXPECT_NEAR(microfacet::ggx_d(a * a, h), ggx::distribution(alpha, c),
                        2e-5 * ggx::distribution(alpha, c));
        }
}

TEST(Microfacet, SmoothLobeDistributionKeepsItsPrecision) {
    // Near the mirror, 1 − cos² θ_h is below float resolution; the vector form reads sin² θ_h
    // from the components: D at a tilt of 3α equals the double-precision value.
    const double alpha = 3.2e-4, tilt = 3.0 * alpha;
    const Vec3 h{float(std::sin(tilt)), 0.0f, float(std::cos(tilt))};
    const double expected = ggx::distribution(alpha, std::cos(tilt));
    EXPECT_NEAR(microfacet::ggx_d(float(alpha * alpha), h), expected, 1e-3 * expected);
}

TEST(Microfacet, Gtr1IsNormalized) {
    for (float alpha : {0.001f, 0.01f, 0.1f, 0.5f, 1.0f}) {
        const double area = integrate_cosine_peaked([&](Vec3 h) { return double(microfacet::gtr1_d(alpha, h)); });
        EXPECT_NEAR(area, 1.0, 1e-3) << "alpha " << alpha;
    }
}

Chi2Options options() {
    Chi2Options o;
    o.test_count = kChi2Tests;
    o.sin_theta_cells = 60;
    o.phi_cells = 120;
    return o;
}

// The reflection sampler against its density, with draws below the horizon as missing mass.
Chi2Result ggx_chi2(Vec3 wo, float alpha) {
    return testing::chi2_direction_test(
        [&](Sample3 u) -> std::optional<Vec3> {
            const Vec3 h = microfacet::sample_ggx_visible(wo, alpha, u.u0, u.u1);
            const Vec3 wi = safe_normalize(microfacet::reflect(wo, h));
            if (!(wi.z > 0.0f)) return std::nullopt;
            return wi;
        },
        [&](Vec3 wi) { return wi.z > 0.0f ? double(microfacet::ggx_reflection_pdf(wo, wi, alpha)) : 0.0; },
        options());
}

TEST(Microfacet, GgxVisibleNormalSamplerMatchesItsDensity) {
    for (const auto &[theta, alpha] : {std::pair{0.3, 0.5f}, {1.1, 0.3f}, {1.45, 0.7f}, {0.0, 0.25f}}) {
        const Vec3 wo = testing::polar_direction(theta, 0.7);
        const Chi2Result r = ggx_chi2(wo, alpha);
        EXPECT_TRUE(r.passed) << "theta " << theta << " alpha " << alpha << ": " << r.message;
        // The missing mass is the share below the horizon: the density integrates to the rest.
        EXPECT_NEAR(r.pdf_integral, 1.0 - double(r.failed_samples) / 1e6, 3e-3);
    }
}

TEST(Microfacet, Gtr1SamplerMatchesItsDensity) {
    for (const auto &[theta, a] : {std::pair{0.4, 0.3f}, {1.2, 0.6f}, {0.9, 1.0f}}) {
        const float alpha = a;  // a lambda may not capture a structured binding in C++17
        const Vec3 wo = testing::polar_direction(theta, -1.1);
        const Chi2Result r = testing::chi2_direction_test(
            [&](Sample3 u) -> std::optional<Vec3> {
                const Vec3 h = microfacet::sample_gtr1(alpha, u.u0, u.u1);
                if (!(dot(wo, h) > 0.0f)) return std::nullopt;
                const Vec3 wi = safe_normalize(microfacet::reflect(wo, h));
                if (!(wi.z > 0.0f)) return std::nullopt;
                return wi;
            },
            [&](Vec3 wi) { return wi.z > 0.0f ? double(microfacet::gtr1_reflection_pdf(wo, wi, alpha)) : 0.0; },
            options());
        EXPECT_TRUE(r.passed) << "theta " << theta << " alpha " << alpha << ": " << r.message;
    }
}

}  // namespace
}  // namespace hairis
