#include "fiber/gaussian_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/math.h"

namespace hairis {
namespace {

std::vector<double> grid(int n, double lo, double hi) {
    std::vector<double> x(n);
    for (int k = 0; k < n; ++k) x[k] = lo + (hi - lo) * (k + 0.5) / n;
    return x;
}

TEST(GaussianFit, RecoversAKnownGaussian) {
    const GaussianFit truth{0.37, 0.41, -0.52, 0, 0};
    const std::vector<double> x = grid(180, -kHalfPi, kHalfPi);
    std::vector<double> y;
    for (double t : x) y.push_back(scaled_gaussian(truth, t));
    const auto fit = fit_scaled_gaussian(x, y);
    ASSERT_TRUE(fit.ok()) << fit.error().message;
    EXPECT_NEAR(fit.value().scale, 0.37, 1e-5);
    EXPECT_NEAR(fit.value().sigma, 0.41, 1e-5);
    EXPECT_NEAR(fit.value().mean, -0.52, 1e-5);
    EXPECT_LT(fit.value().relative_error, 1e-5);
}

TEST(GaussianFit, RobustToNoiseAndTruncation) {
    // A Gaussian whose centre lies near the end of the domain, with 2% noise.
    const GaussianFit truth{2.0, 0.65, 1.3, 0, 0};
    const std::vector<double> x = grid(90, -kHalfPi, kHalfPi);
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 0.02);
    std::vector<double> y;
    for (double t : x) y.push_back(scaled_gaussian(truth, t) * (1.0 + noise(rng)));
    const auto fit = fit_scaled_gaussian(x, y).value();
    EXPECT_NEAR(fit.sigma, 0.65, 0.02);
    EXPECT_NEAR(fit.mean, 1.3, 0.02);
    EXPECT_NEAR(fit.scale, 2.0, 0.05);
}

TEST(GaussianFit, FixedMeanFitsOnlyWidthAndScale) {
    const GaussianFit truth{1.0, 0.3, 0.2, 0, 0};
    const std::vector<double> x = grid(100, -1.5, 1.5);
    std::vector<double> y;
    for (double t : x) y.push_back(scaled_gaussian(truth, t));
    const auto fit = fit_scaled_gaussian(x, y, 0.0).value();
    EXPECT_EQ(fit.mean, 0.0);
    EXPECT_GT(fit.sigma, 0.3);  // the off-centre bump looks wider around 0
    EXPECT_GT(fit.relative_error, 0.01);
}

TEST(GaussianFit, RefusesBadData) {
    EXPECT_FALSE(fit_scaled_gaussian({0.0, 1.0}, {1.0, 2.0}).ok());
    EXPECT_FALSE(fit_scaled_gaussian({0.0, 1.0, 2.0}, {1.0, NAN, 2.0}).ok());
    const auto r = fit_scaled_gaussian({0.0, 1.0, 2.0}, {1.0, 2.0, 1.0}, std::nullopt, 0.5, 0.1);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("sigma_max"), std::string::npos);
}

}  // namespace
}  // namespace hairis
