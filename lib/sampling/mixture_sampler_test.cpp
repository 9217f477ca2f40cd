#include "sampling/mixture_sampler.h"

#include <gtest/gtest.h>

#include <random>

#include "chi2.h"
#include "core/frame.h"
#include "sampler_at.h"
#include "sampling/seed_samplers.h"
#include "sampling/uniform_sampler.h"

namespace hairis {
namespace {

using testing::SamplerAt;

std::shared_ptr<const Sampler> seed_direct() {
    return std::make_shared<const SeedDirectSampler>(SeedDirectSampler::create({}).value());
}
std::shared_ptr<const Sampler> uniform() { return std::make_shared<const UniformSampler>(); }

Vec3 view_at(double theta_deg) { return direction_of(float(radians(theta_deg)), -float(kHalfPi)); }

// The mixture's pdf is (1 − w)·p_a + w·p_b of its components' (prepared separately), and it is
// the density it samples.
TEST(MixtureSampler, IsTheWeightedSumOfItsComponentsAndSamplesIt) {
    const double seed_family = 3;
    for (float w : {0.0f, 0.3f, 1.0f}) {
        const MixtureSampler mixture = MixtureSampler::create(seed_direct(), uniform(), w).value();
        const SamplerAt at(mixture, view_at(25.0)), a(*seed_direct(), view_at(25.0)), b(*uniform(), view_at(25.0));
        std::mt19937 rng(2);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (int n = 0; n < 200; ++n) {
            const Vec3 wi = direction_of(std::asin(2 * u(rng) - 1), float(kTwoPi) * u(rng));
            EXPECT_NEAR(at.pdf(wi), (1 - w) * a.pdf(wi) + w * b.pdf(wi), 1e-6f * at.pdf(wi));
        }
        testing::Chi2Options options;
        options.test_count = int(seed_family);
        const auto r = testing::chi2_sampler_test(at, options);
        EXPECT_TRUE(r.passed) << "w " << w << ": " << r.message;
        EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
    }
}

TEST(MixtureSampler, RefusesBadWeightsAndMissingComponents) {
    EXPECT_FALSE(MixtureSampler::create(nullptr, uniform(), 0.5f).ok());
    EXPECT_FALSE(MixtureSampler::create(uniform(), nullptr, 0.5f).ok());
    auto e = MixtureSampler::create(uniform(), uniform(), 1.5f);
    ASSERT_FALSE(e.ok());
    EXPECT_NE(e.error().message.find("multiple_weight must be in [0, 1]"), std::string::npos);
    EXPECT_FALSE(MixtureSampler::create(uniform(), uniform(), std::nanf("")).ok());
}

}  // namespace
}  // namespace hairis
