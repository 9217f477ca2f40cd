#include "sampling/hair_mixture.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <tuple>
#include <random>

#include "chi2.h"
#include "core/frame.h"
#include "fiber/chiang.h"
#include "sampling/analytic_sampler.h"
#include "sampling/uniform_sampler.h"

namespace hairis {
namespace {

std::shared_ptr<const ChiangFiber> chiang_fiber(float roughness, Rgb sigma_a) {
    ChiangParams p;
    p.roughness = roughness;
    p.radial_roughness = roughness;
    p.sigma_a = sigma_a;
    return std::make_shared<const ChiangFiber>(ChiangFiber::create(p).value());
}

// A Chiang closure sampled by its analytic sampler.
HairShading chiang_closure(float roughness, Rgb sigma_a) {
    auto fiber = chiang_fiber(roughness, sigma_a);
    return HairShading::create(fiber, std::make_shared<const AnalyticSampler>(fiber)).value();
}

// A Chiang closure sampled uniformly (a sampler far from its f, so the mixture's pdf differs
// from both closures').
HairShading uniform_closure() {
    return HairShading::create(chiang_fiber(0.6f, Rgb{0.05f, 0.1f, 0.2f}), std::make_shared<const UniformSampler>())
        .value();
}

std::vector<HairShading> two_closures() {
    return {chiang_closure(0.25f, Rgb{0.8f, 1.3f, 2.2f}), uniform_closure()};
}

const FiberHit kHit{direction_of(float(radians(25.0)), -float(kHalfPi) + 0.4f), 0.3f};

Vec3 random_direction(std::mt19937 &rng) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    return direction_of(std::asin(2 * u(rng) - 1), float(kTwoPi) * u(rng));
}

// f is Σ w_k f_k and the pdf Σ p_k pdf_k with p_k = w_k / Σ w, against the closures prepared
// on their own; a per-hit weight replaces the material's.
TEST(HairMixture, EvalIsTheWeightedSumOfItsClosures) {
    const std::vector<HairShading> closures = two_closures();
    ScratchBuffer scratch;
    const HairBsdf a = closures[0].at(kHit, scratch), b = closures[1].at(kHit, scratch);
    const HairMixture mixture = HairMixture::create(closures, {0.3f, 1.2f}).value();
    ClosureWeights strand;
    strand.given = 1u << 1;  // closure 1's weight from the strand, closure 0's the material's
    strand.value[1] = 0.1f;
    for (const auto &[weights, wa, wb] : {std::tuple<const ClosureWeights *, float, float>{nullptr, 0.3f, 1.2f},
                                          {&strand, 0.3f, 0.1f}}) {
        const HairMixtureBsdf at = mixture.at(kHit, weights, scratch);
        std::mt19937 rng(4);
        for (int n = 0; n < 200; ++n) {
            const Vec3 wi = random_direction(rng);
            float pdf = 0.0f;
            const Rgb f = at.f_and_pdf(wi, pdf);
            const Rgb expected = a.f(wi) * wa + b.f(wi) * wb;
            EXPECT_NEAR(f.g, expected.g, 1e-5f * (1 + expected.g));
            EXPECT_NEAR(f.b, expected.b, 1e-5f * (1 + expected.b));
            const float expected_pdf = (wa * a.pdf(wi) + wb * b.pdf(wi)) / (wa + wb);
            EXPECT_NEAR(pdf, expected_pdf, 1e-5f * (1 + expected_pdf));
        }
    }
}

// A sample's f and pdf are the mixture's at the sampled direction, and the pdf is the density
// of the samples (χ², one test per weight set: two in the family).
TEST(HairMixture, SamplesItsDensity) {
    const HairMixture mixture = HairMixture::create(two_closures(), {0.3f, 0.7f}).value();
    ClosureWeights strand;
    strand.given = 3u;
    strand.value = {2.0f, 0.5f};
    for (const ClosureWeights *weights : std::array<const ClosureWeights *, 2>{nullptr, &strand}) {
        ScratchBuffer scratch;
        const HairMixtureBsdf at = mixture.at(kHit, weights, scratch);
        std::mt19937 rng(9);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (int n = 0; n < 100; ++n) {
            const std::optional<BsdfSample> s = at.sample(u(rng), u(rng), u(rng));
            if (!s) continue;
            float pdf = 0.0f;
            const Rgb f = at.f_and_pdf(s->wi, pdf);
            EXPECT_NEAR(s->pdf, pdf, 1e-4f * pdf);
            EXPECT_NEAR(s->f.g, f.g, 1e-4f * (1 + f.g));
        }
        testing::Chi2Options options;
        options.test_count = 2;
        const auto r = testing::chi2_sampler_test(at, options);
        EXPECT_TRUE(r.passed) << (weights ? "strand weights: " : "material weights: ") << r.message;
        EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
    }
}

// A closure of weight 0 is left out (Cycles makes none); all 0: nothing is drawn, f is 0.
TEST(HairMixture, LeavesOutClosuresOfWeightZero) {
    const HairMixture mixture = HairMixture::create(two_closures(), {0.0f, 0.5f}).value();
    ScratchBuffer scratch;
    EXPECT_EQ(mixture.at(kHit, nullptr, scratch).size(), 1);
    ClosureWeights none;
    none.given = 2u;
    const HairMixtureBsdf black = mixture.at(kHit, &none, scratch);
    EXPECT_EQ(black.size(), 0);
    EXPECT_FALSE(black.sample(0.5f, 0.5f, 0.5f).has_value());
    EXPECT_TRUE(black.f(kHit.wo).is_black());
    EXPECT_FALSE(black.transparent());
}

// The one closure left keeps its weight: a sample's f is the mixture's f at its direction
// (Σ w_k f_k, here 0.5 f_1), as eval gives it for light samples.
TEST(HairMixture, ALoneClosureKeepsItsWeightWhenSampled) {
    const HairMixture mixture = HairMixture::create(two_closures(), {0.0f, 0.5f}).value();
    ScratchBuffer scratch;
    const HairMixtureBsdf lone = mixture.at(kHit, nullptr, scratch);
    ASSERT_EQ(lone.size(), 1);
    for (float u : {0.2f, 0.5f, 0.8f}) {
        const auto s = lone.sample(u, 0.3f, 0.7f);
        ASSERT_TRUE(s.has_value());
        float pdf = 0.0f;
        const Rgb f = lone.f_and_pdf(s->wi, pdf);
        EXPECT_NEAR(s->pdf, pdf, 1e-5f * pdf);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(s->f[c], f[c], 1e-5f * f[c] + 1e-12f) << c;
    }
}

TEST(HairMixture, RefusesBadWeightsAndClosureCounts) {
    EXPECT_FALSE(HairMixture::create({}, {}).ok());
    auto count = HairMixture::create(two_closures(), {1.0f});
    ASSERT_FALSE(count.ok());
    EXPECT_NE(count.error().message.find("1 weights for 2 closures"), std::string::npos);
    auto negative = HairMixture::create(two_closures(), {1.0f, -0.5f});
    ASSERT_FALSE(negative.ok());
    EXPECT_NE(negative.error().message.find("closure 1's weight"), std::string::npos);
    EXPECT_FALSE(HairMixture::create(two_closures(), {std::nanf(""), 1.0f}).ok());
    EXPECT_FALSE(HairMixture::create(two_closures(), {INFINITY, 1.0f}).ok());
    std::vector<HairShading> many(std::size_t(kMaxHairClosures) + 1, uniform_closure());
    EXPECT_FALSE(HairMixture::create(many, std::vector<float>(many.size(), 1.0f)).ok());
}

}  // namespace
}  // namespace hairis
