#include "sampling/seed_samplers.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "chi2.h"
#include "core/frame.h"
#include "sampler_at.h"
#include "sampling/strategy.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Sample3;
using testing::SamplerAt;

// θ_r on which the gaussian strategy is tested: ordinary, normal incidence and near grazing.
const double kThetaRDegrees[] = {-85.0, -40.0, 0.0, 30.0, 86.0};
const double kWeights[] = {0.0, 0.35, 1.0};
constexpr int kChi2Family = 5 * 3;  // every χ² test in this file (Šidák)

Vec3 view_at(double theta_r_degrees) { return direction_of(float(radians(theta_r_degrees)), -float(kHalfPi)); }

std::shared_ptr<const Sampler> gaussian(double w, int n_h) {
    StrategyInputs in;
    in.multiple_weight = float(w);
    in.n_h = n_h;
    Expected<std::shared_ptr<const Sampler>> made = make_sampler(StrategyKind::Gaussian, in);
    EXPECT_TRUE(made) << (made ? "" : made.error().message);
    return made.value();
}

// The seed's Gaussians written out: a normal of σ around μ renormalized on [lo, hi].
double truncated_normal(double x, double mu, double sigma, double lo, double hi) {
    const auto cdf = [&](double t) { return 0.5 * std::erfc(-(t - mu) / (sigma * std::sqrt(2.0))); };
    return std::exp(-0.5 * sqr((x - mu) / sigma)) / (sigma * std::sqrt(kTwoPi) * (cdf(hi) - cdf(lo)));
}

// (1 − w)·f_ds + w·f_ms per steradian, from the seed's text with its slips corrected.
double reference_pdf(double theta_r, Vec3 wi, double w, double sigma_multiple) {
    const FiberAngles i = angles_of(wi);
    const double phi = wrap_angle(double(i.phi) + kHalfPi);  // φ_o = −π/2
    const double direct = truncated_normal(i.theta, -theta_r, 0.22, -kHalfPi, kHalfPi) *
                          truncated_normal(wrap_angle(phi - kPi), 0.0, 0.52 + sqr(theta_r / kPi), -kPi, kPi);
    const double multiple =
        truncated_normal(i.theta, -theta_r, sigma_multiple + std::fabs(theta_r) / kPi, -kHalfPi, kHalfPi) / kTwoPi;
    return ((1 - w) * direct + w * multiple) / std::cos(double(i.theta));
}

class GaussianStrategy : public ::testing::TestWithParam<std::tuple<double, double>> {};

TEST_P(GaussianStrategy, PdfIsTheSampledDensity) {
    const auto [theta_r_deg, w] = GetParam();
    const SamplerAt at(*gaussian(w, 2), view_at(theta_r_deg));
    Chi2Options options;
    options.test_count = kChi2Family;
    const auto r = testing::chi2_sampler_test(at, options);
    EXPECT_TRUE(r.passed) << "theta_r " << theta_r_deg << " w " << w << ": " << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3);
    EXPECT_EQ(r.failed_samples, 0);
}

TEST_P(GaussianStrategy, PdfIsTheSeedsFormula) {
    const auto [theta_r_deg, w] = GetParam();
    const SamplerAt at(*gaussian(w, 4), view_at(theta_r_deg));
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int n = 0; n < 2000; ++n) {
        const auto s = at.sample(u(rng), u(rng), u(rng));
        ASSERT_TRUE(s);
        const double expected = reference_pdf(radians(theta_r_deg), s->wi, w, 0.37);
        EXPECT_NEAR(s->pdf, expected, 1e-4 * expected + 1e-6);
    }
}

INSTANTIATE_TEST_SUITE_P(Seed, GaussianStrategy,
                         ::testing::Combine(::testing::ValuesIn(kThetaRDegrees), ::testing::ValuesIn(kWeights)));

TEST(SeedSamplers, RefuseBadParameters) {
    SeedPdfParams p;
    p.sigma_longitudinal = 0.0;
    auto direct = SeedDirectSampler::create(p);
    ASSERT_FALSE(direct.ok());
    EXPECT_NE(direct.error().message.find("sigma_longitudinal"), std::string::npos);
    auto multiple = SeedMultipleSampler::create(SeedPdfParams{}, 3);
    ASSERT_FALSE(multiple.ok());
    EXPECT_NE(multiple.error().message.find("n_h must be one of {1, 2, 4, 8, 16}"), std::string::npos);
    StrategyInputs in;
    in.multiple_weight = 1.5f;
    auto s = make_sampler(StrategyKind::Gaussian, in);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("multiple_weight must be in [0, 1]"), std::string::npos) << s.error().message;
}

}  // namespace
}  // namespace hairis
