#include "hairis/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "chi2.h"

namespace hairis {
namespace {

TEST(Rng, SameInputsSameNumber) {
    EXPECT_EQ(random_float(7, 123, 4, 9), random_float(7, 123, 4, 9));
    EXPECT_EQ(SampleRng(7, 123, 4).get(9), random_float(7, 123, 4, 9));
}

TEST(Rng, EveryInputMatters) {
    const float base = random_float(7, 123, 4, 9);
    EXPECT_NE(base, random_float(8, 123, 4, 9));
    EXPECT_NE(base, random_float(7, 124, 4, 9));
    EXPECT_NE(base, random_float(7, 123, 5, 9));
    EXPECT_NE(base, random_float(7, 123, 4, 10));
}

TEST(Rng, UnitFloatIsInHalfOpenRange) {
    EXPECT_EQ(to_unit_float(0), 0.0f);
    EXPECT_LT(to_unit_float(~0ull), 1.0f);
    EXPECT_GT(to_unit_float(~0ull), 0.9999f);
    for (std::uint32_t d = 0; d < 100000; ++d) {
        const float u = SampleRng(1, 2, 3).get(d);
        ASSERT_GE(u, 0.0f);
        ASSERT_LT(u, 1.0f);
    }
}

TEST(Rng, UniformAlongEachAxis) {
    // One χ² test per axis that varies: dimension, sample, pixel and seed.
    const int n = 200000;
    for (int axis = 0; axis < 4; ++axis) {
        int i = 0;
        testing::Chi2Options options;
        options.sample_count = n;
        options.test_count = 4;
        const auto result = testing::chi2_interval_test(
            [&](double) -> std::optional<double> {
                const std::uint64_t k = std::uint64_t(i++);
                switch (axis) {
                    case 0: return random_float(1, 2, 3, std::uint32_t(k));
                    case 1: return random_float(1, 2, k, 3);
                    case 2: return random_float(1, k, 2, 3);
                    default: return random_float(k, 1, 2, 3);
                }
            },
            [](double) { return 1.0; }, 0.0, 1.0, 64, options);
        EXPECT_TRUE(result.passed) << "axis " << axis << ": " << result.message;
    }
}

TEST(Rng, NeighbouringDimensionsAreUncorrelated) {
    const int n = 100000;
    double sxy = 0, sx = 0, sy = 0, sxx = 0, syy = 0;
    for (int s = 0; s < n; ++s) {
        const SampleRng rng(42, 17, std::uint64_t(s));
        const double x = rng.get(0), y = rng.get(1);
        sx += x; sy += y; sxy += x * y; sxx += x * x; syy += y * y;
    }
    const double cov = sxy / n - (sx / n) * (sy / n);
    const double corr = cov / std::sqrt((sxx / n - sqr(sx / n)) * (syy / n - sqr(sy / n)));
    // The standard error of a correlation estimate is 1/sqrt(n) ≈ 0.0032: allow 5 of them.
    EXPECT_LT(std::fabs(corr), 5.0 / std::sqrt(double(n)));
}

}  // namespace
}  // namespace hairis
