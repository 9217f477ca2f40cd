#include "fiber/seed_pdfs.h"

#include <gtest/gtest.h>

#include "chi2.h"
#include "core/frame.h"

namespace hairis {
namespace {

using testing::Chi2Options;

constexpr int kChi2Family = 1;  // every χ² test in this file (Šidák)

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

TEST(SeedPdfs, ValidationNamesTheParameter) {
    SeedPdfParams p;
    p.sigma_longitudinal = 0.0;
    ASSERT_TRUE(p.validate());
    EXPECT_NE(p.validate()->message.find("sigma_longitudinal"), std::string::npos);
    p = SeedPdfParams{};
    p.sigma_multiple.pop_back();
    EXPECT_TRUE(p.validate());
    EXPECT_EQ(seed_sigma_multiple(SeedPdfParams{}, 3), -1.0);
    EXPECT_EQ(seed_sigma_multiple(SeedPdfParams{}, 8), 0.34);
}

}  // namespace
}  // namespace hairis
