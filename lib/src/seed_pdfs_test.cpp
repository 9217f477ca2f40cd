#include "hairis/seed_pdfs.h"

#include <gtest/gtest.h>

#include <random>

#include "chi2.h"
#include "hairis/frame.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Sample3;

// θ_r on which the gaussian strategy is tested: ordinary, normal incidence and near grazing.
const double kThetaRDegrees[] = {-85.0, -40.0, 0.0, 30.0, 86.0};
const double kWeights[] = {0.0, 0.35, 1.0};
constexpr int kChi2Family = 5 * 3 + 1;  // every χ² test in this file (Šidák)

Vec3 view_at(double theta_r_degrees) {
    return direction_of(float(radians(theta_r_degrees)), -float(kHalfPi));
}

TEST(TruncatedNormal, SamplesItsDensity) {
    const TruncatedNormal n(-1.2, 0.44, -kHalfPi, kHalfPi);  // θ_r ≈ 69°: mass piles on the edge
    Chi2Options options;
    options.test_count = kChi2Family;
    const auto r = testing::chi2_interval_test(
        [&](double u) -> std::optional<double> { return n.sample(u); },
        [&](double x) { return n.pdf(x); }, -kHalfPi, kHalfPi, 200, options);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-6);
    EXPECT_EQ(n.pdf(-2.0), 0.0);
    EXPECT_GE(n.sample(0.0), -kHalfPi);
    EXPECT_LE(n.sample(1.0), kHalfPi);
}

class GaussianStrategy : public ::testing::TestWithParam<std::tuple<double, double>> {};

TEST_P(GaussianStrategy, PdfIsTheSampledDensity) {
    const auto [theta_r_deg, w] = GetParam();
    const auto sampler = GaussianSampler::create(SeedPdfParams{}, w, 2);
    ASSERT_TRUE(sampler.ok()) << sampler.error().message;
    const Vec3 wo = view_at(theta_r_deg);
    Chi2Options options;
    options.test_count = kChi2Family;
    const auto r = testing::chi2_direction_test(
        [&](Sample3 u) -> std::optional<Vec3> {
            auto s = sampler.value().sample(wo, 0.0f, u.u0, u.u1, u.u2);
            return s ? std::optional<Vec3>(s->wi) : std::nullopt;
        },
        [&](Vec3 wi) { return double(sampler.value().pdf(wi, wo, 0.0f)); }, options);
    EXPECT_TRUE(r.passed) << "theta_r " << theta_r_deg << " w " << w << ": " << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
    EXPECT_EQ(r.failed_samples, 0);
}

TEST_P(GaussianStrategy, PdfOfSampleMatches) {
    const auto [theta_r_deg, w] = GetParam();
    const auto sampler = GaussianSampler::create(SeedPdfParams{}, w, 4).value();
    const Vec3 wo = view_at(theta_r_deg);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int n = 0; n < 20000; ++n) {
        const auto s = sampler.sample(wo, 0.0f, u(rng), u(rng), u(rng));
        ASSERT_TRUE(s);
        EXPECT_NEAR(sampler.pdf(s->wi, wo, 0.0f), s->pdf, 1e-5f * s->pdf);
    }
}

INSTANTIATE_TEST_SUITE_P(Seed, GaussianStrategy,
                         ::testing::Combine(::testing::ValuesIn(kThetaRDegrees),
                                            ::testing::ValuesIn(kWeights)));

TEST(SeedPdfs, ShapesFollowTheSeed) {
    const SeedPdfParams p;
    // f_ds peaks at θ_i = −θ_r and on the TT lobe φ = ±π; f_ms at θ_i = −θ_r.
    const double theta_r = radians(30.0);
    const double peak = seed_direct_pdf(p, theta_r, -theta_r, kPi);
    EXPECT_GT(peak, seed_direct_pdf(p, theta_r, -theta_r + 0.1, kPi));
    EXPECT_GT(peak, seed_direct_pdf(p, theta_r, -theta_r, kPi - 0.1));
    EXPECT_GT(peak, seed_direct_pdf(p, theta_r, -theta_r, 0.0) * 5.0);
    EXPECT_NEAR(seed_direct_pdf(p, theta_r, -theta_r, kPi), seed_direct_pdf(p, theta_r, -theta_r, -kPi), 1e-9);
    // σ' uses |θ_r|: the band is as wide for −θ_r as for θ_r (mirror image).
    EXPECT_NEAR(seed_multiple_pdf(p, -theta_r, 0.2, 2), seed_multiple_pdf(p, theta_r, -0.2, 2), 1e-12);
    // Table 1: σ shrinks with n_h, so the band narrows and its peak rises.
    EXPECT_GT(seed_multiple_pdf(p, 0.0, 0.0, 16), seed_multiple_pdf(p, 0.0, 0.0, 1));
}

TEST(SeedPdfs, RefusesBadParameters) {
    SeedPdfParams p;
    p.sigma_longitudinal = 0.0;
    auto s = GaussianSampler::create(p, 0.5, 1);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("sigma_longitudinal"), std::string::npos);
    s = GaussianSampler::create(SeedPdfParams{}, 1.5, 1);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("multiple_weight must be in [0, 1]"), std::string::npos);
    s = GaussianSampler::create(SeedPdfParams{}, 0.5, 3);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("n_h must be one of {1, 2, 4, 8, 16}"), std::string::npos)
        << s.error().message;
    p = SeedPdfParams{};
    p.sigma_multiple.pop_back();
    EXPECT_FALSE(GaussianSampler::create(p, 0.5, 1).ok());
}

}  // namespace
}  // namespace hairis
