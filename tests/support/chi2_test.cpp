// The χ² test itself: it must accept correct samplers and reject subtly wrong ones.
#include "chi2.h"

#include <gtest/gtest.h>

#include <cmath>

namespace hairis::testing {
namespace {

// Uniform on the sphere: sin θ uniform in [−1, 1], φ uniform.
std::optional<Vec3> uniform_sphere(Sample3 u) {
    const float x = 1.0f - 2.0f * u.u0;
    const float r = std::sqrt(std::max(0.0f, 1.0f - x * x));
    const float phi = float(kTwoPi) * u.u1;
    return Vec3{x, r * std::cos(phi), r * std::sin(phi)};
}

// Density ∝ (1 + x)² over the sphere, sampled by inverting its CDF in x.
std::optional<Vec3> skewed_sphere(Sample3 u) {
    const float x = 2.0f * std::cbrt(u.u0) - 1.0f;  // CDF ((1 + x)/2)³
    const float r = std::sqrt(std::max(0.0f, 1.0f - x * x));
    const float phi = float(kTwoPi) * u.u1;
    return Vec3{x, r * std::cos(phi), r * std::sin(phi)};
}
double skewed_pdf(Vec3 w) { return 3.0 * sqr(1.0 + w.x) / 8.0 * kInvTwoPi; }

TEST(Chi2, AcceptsUniformSphere) {
    const Chi2Result r = chi2_direction_test(uniform_sphere, [](Vec3) { return kInvFourPi; });
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-9);
}

TEST(Chi2, AcceptsSkewedDensity) {
    const Chi2Result r = chi2_direction_test(skewed_sphere, skewed_pdf);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-6);
}

TEST(Chi2, RejectsPdfThatIsNotTheSampledDensity) {
    // The sampler is uniform, the pdf claims a 3% tilt: 10^6 samples must notice.
    const Chi2Result r = chi2_direction_test(
        uniform_sphere, [](Vec3 w) { return kInvFourPi * (1.0 + 0.03 * w.x); });
    EXPECT_FALSE(r.passed) << r.message;
}

TEST(Chi2, RejectsSamplesWherePdfIsZero) {
    const Chi2Result r = chi2_direction_test(
        uniform_sphere, [](Vec3 w) { return w.x > 0 ? 2.0 * kInvFourPi : 0.0; });
    EXPECT_FALSE(r.passed);
    EXPECT_NE(r.message.find("expected count 0"), std::string::npos) << r.message;
}

TEST(Chi2, IntervalAcceptsAndRejects) {
    // Density 2x on [0, 1], sampled as sqrt(u).
    auto sample = [](double u) -> std::optional<double> { return std::sqrt(u); };
    const Chi2Result good =
        chi2_interval_test(sample, [](double x) { return 2.0 * x; }, 0.0, 1.0, 100);
    EXPECT_TRUE(good.passed) << good.message;
    const Chi2Result bad = chi2_interval_test(
        sample, [](double x) { return 1.96 * x + 0.02; }, 0.0, 1.0, 100);
    EXPECT_FALSE(bad.passed) << bad.message;
}

TEST(Chi2, SidakCorrectionLowersTheThreshold) {
    Chi2Options one, many;
    many.test_count = 100;
    const Chi2Result a = chi2_direction_test(uniform_sphere, [](Vec3) { return kInvFourPi; }, one);
    const Chi2Result b = chi2_direction_test(uniform_sphere, [](Vec3) { return kInvFourPi; }, many);
    EXPECT_EQ(a.statistic, b.statistic);  // same samples, same statistic
    EXPECT_NEAR(a.threshold, 0.01, 1e-15);
    EXPECT_NEAR(b.threshold, 1.0 - std::pow(0.99, 0.01), 1e-15);  // Šidák: 1 − (1 − α)^(1/m)
}

}  // namespace
}  // namespace hairis::testing
