#include "core/rng.h"

#include <gtest/gtest.h>

#include <algorithm>
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

// The χ² test of draw(0), draw(1), ..., draw(n − 1) against the uniform density on [0, 1) in
// 64 cells, one of `test_count` tests of its family.
template <typename Draw>
testing::Chi2Result chi2_uniform(int n, int test_count, const Draw &draw) {
    testing::Chi2Options options;
    options.sample_count = n;
    options.test_count = test_count;
    std::uint64_t k = 0;
    return testing::chi2_interval_test([&](double) -> std::optional<double> { return draw(k++); },
                                       [](double) { return 1.0; }, 0.0, 1.0, 64, options);
}

TEST(Rng, UniformAlongEachAxis) {
    // One χ² test per axis that varies: dimension, sample, pixel and seed.
    const int n = 200000;
    for (int axis = 0; axis < 4; ++axis) {
        const auto result = chi2_uniform(n, 4, [&](std::uint64_t k) {
            switch (axis) {
                case 0: return random_float(1, 2, 3, std::uint32_t(k));
                case 1: return random_float(1, 2, k, 3);
                case 2: return random_float(1, k, 2, 3);
                default: return random_float(k, 1, 2, 3);
            }
        });
        EXPECT_TRUE(result.passed) << "axis " << axis << ": " << result.message;
    }
}

// The sample correlation of dimensions a and b over samples 0..n−1 of one pixel (seed 42,
// pixel 17) of generator Rng.
template <typename Rng>
double correlation(int n, std::uint32_t a, std::uint32_t b) {
    double sxy = 0, sx = 0, sy = 0, sxx = 0, syy = 0;
    for (int s = 0; s < n; ++s) {
        const Rng rng(42, 17, std::uint64_t(s));
        const double x = rng.get(a), y = rng.get(b);
        sx += x; sy += y; sxy += x * y; sxx += x * x; syy += y * y;
    }
    const double cov = sxy / n - (sx / n) * (sy / n);
    return cov / std::sqrt((sxx / n - sqr(sx / n)) * (syy / n - sqr(sy / n)));
}

TEST(Rng, NeighbouringDimensionsAreUncorrelated) {
    const int n = 100000;
    const double corr = correlation<SampleRng>(n, 0, 1);
    // The standard error of a correlation estimate is 1/sqrt(n) ≈ 0.0032: allow 5 of them.
    EXPECT_LT(std::fabs(corr), 5.0 / std::sqrt(double(n)));
}

TEST(SobolRng, BitHelpers) {
    EXPECT_EQ(reverse_bits32(1u), 0x80000000u);
    EXPECT_EQ(reverse_bits32(0x12345678u), 0x1e6a2c48u);
    // The Sobol sequence's second dimension: 0, 1/2, 3/4, 1/4, 5/8, 1/8, ...
    const std::uint32_t expected[] = {0u, 0x80000000u, 0xc0000000u, 0x40000000u, 0xa0000000u, 0x20000000u};
    for (std::uint32_t i = 0; i < 6; ++i) EXPECT_EQ(sobol_second_dimension(i), expected[i]) << i;
    // Owen scrambling permutes: distinct inputs stay distinct.
    std::vector<std::uint32_t> seen;
    for (std::uint32_t i = 0; i < 4096; ++i) seen.push_back(nested_uniform_scramble(i << 20, 77u));
    std::sort(seen.begin(), seen.end());
    EXPECT_EQ(std::adjacent_find(seen.begin(), seen.end()), seen.end());
}

// SobolSampleRng::get as its comment defines it, step by step with the bit-by-bit Sobol
// generator: the reference for the table-driven, reversal-folded implementation.
float sobol_sample_by_definition(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample,
                                 std::uint32_t dimension) {
    const std::uint64_t key = mix64(mix64(seed ^ 0xbb67ae8584caa73bull) ^ pixel);
    const std::uint32_t pair_hash =
        std::uint32_t(mix64(key ^ (std::uint64_t(dimension >> 1) * 0x9e3779b97f4a7c15ull)));
    const std::uint32_t dimension_hash = std::uint32_t(
        mix64(key ^ (std::uint64_t(dimension) * 0xc2b2ae3d27d4eb4full) ^ 0x165667b19e3779f9ull));
    const std::uint32_t shuffle = nested_uniform_scramble(std::uint32_t(sample), pair_hash);
    std::uint32_t point = 0;
    if (dimension & 1u) {
        for (std::uint32_t v = 1u << 31, i = shuffle; i != 0; i >>= 1, v ^= v >> 1)
            if (i & 1u) point ^= v;
    } else {
        point = reverse_bits32(shuffle);
    }
    return float(nested_uniform_scramble(point, dimension_hash) >> 8) * (1.0f / 16777216.0f);
}

TEST(SobolRng, MatchesItsDefinition) {
    std::uint64_t state = 1;
    for (int k = 0; k < 200000; ++k) {
        state = mix64(state + 0x9e3779b97f4a7c15ull);
        const std::uint64_t seed = state & 0xff, pixel = (state >> 8) & 0xfffff;
        const std::uint64_t sample = (k & 1) ? std::uint64_t(k >> 1) : (state >> 28);
        const std::uint32_t dimension = std::uint32_t((state >> 60) + (state >> 40) % 37);
        ASSERT_EQ(SobolSampleRng(seed, pixel, sample).get(dimension),
                  sobol_sample_by_definition(seed, pixel, sample, dimension))
            << "seed " << seed << " pixel " << pixel << " sample " << sample << " dimension "
            << dimension;
    }
    for (std::uint32_t i = 0; i < (1u << 16); ++i)
        ASSERT_EQ(sobol_second_dimension(i * 65599u), detail::sobol_second_dimension_bits(i * 65599u));
}

TEST(SobolRng, EachDimensionAndPairIsStratified) {
    // 256 samples of one pixel: one per 1/256 interval in every dimension, and one per
    // elementary interval of area 1/256 (1×256, 2×128, ..., 256×1) in every pair.
    constexpr int n = 256;
    for (std::uint64_t pixel : {0ull, 12345ull}) {
        for (std::uint32_t pair = 0; pair < 6; ++pair) {
            std::vector<float> x(n), y(n);
            for (int s = 0; s < n; ++s) {
                const SobolSampleRng rng(3, pixel, std::uint64_t(s));
                x[size_t(s)] = rng.get(2 * pair);
                y[size_t(s)] = rng.get(2 * pair + 1);
            }
            for (int log_w = 0; log_w <= 8; ++log_w) {
                const int wx = 1 << log_w, wy = n / wx;
                std::vector<int> count(size_t(n), 0);
                for (int s = 0; s < n; ++s)
                    ++count[size_t(int(x[size_t(s)] * wx) * wy + int(y[size_t(s)] * wy))];
                EXPECT_EQ(*std::max_element(count.begin(), count.end()), 1)
                    << "pixel " << pixel << " pair " << pair << " intervals " << wx << "x" << wy;
            }
        }
    }
}

TEST(SobolRng, UniformAcrossPixelsAndSeeds) {
    // Over many pixels (one sample each) each dimension is uniform: the scrambles make the
    // points random, which is what keeps the estimates unbiased.
    const int n = 200000;
    for (std::uint32_t dimension : {0u, 1u, 7u}) {
        const auto result = chi2_uniform(n, 3, [&](std::uint64_t k) {
            return SobolSampleRng(9, k, 5).get(dimension);
        });
        EXPECT_TRUE(result.passed) << "dimension " << dimension << ": " << result.message;
    }
}

TEST(SobolRng, PairsArePaddedIndependently) {
    // Dimension 0 and dimension 2 belong to different pairs: their shuffles differ, so over a
    // pixel's samples they are uncorrelated (unlike a plain Sobol sequence's dimensions).
    const int n = 4096;
    const double corr = correlation<SobolSampleRng>(n, 0, 2);
    EXPECT_LT(std::fabs(corr), 5.0 / std::sqrt(double(n)));
    EXPECT_NE(SobolSampleRng(1, 2, 3).get(0), SobolSampleRng(2, 2, 3).get(0));
    EXPECT_NE(SobolSampleRng(1, 2, 3).get(0), SobolSampleRng(1, 3, 3).get(0));
}

}  // namespace
}  // namespace hairis
