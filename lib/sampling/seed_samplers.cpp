#include "sampling/seed_samplers.h"

#include <cmath>
#include <string>

#include "core/frame.h"

namespace hairis {

namespace {

// Per steradian from per dθ dφ: the density over (θ_i, φ) divided by cos θ_i.
float per_steradian(double density, Vec3 wi) {
    const double cos_theta_i = std::hypot(double(wi.y), double(wi.z));  // accurate near the poles
    return cos_theta_i > 0.0 ? float(density / cos_theta_i) : 0.0f;
}

// θ_i ~ longitudinal, φ = φ_o + azimuth(u); the density is (pdf_θ · pdf_φ) per dθ dφ.
class SeedDirectPoint final : public SamplerPoint {
  public:
    SeedDirectPoint(const SeedPdfParams &params, Vec3 wo)
        : o_(angles_of(wo)), longitudinal_(seed_longitudinal(o_.theta, params.sigma_longitudinal)),
          azimuthal_(seed_azimuthal(params, o_.theta)) {}
    std::optional<DirectionSample> sample(float, float u1, float u2) const override {
        const double theta_i = longitudinal_.sample(u1);
        const double phi = wrap_angle(azimuthal_.sample(u2) + kPi);
        const Vec3 wi = direction_of(float(theta_i), float(wrap_angle(double(o_.phi) + phi)));
        const float density = pdf(wi);
        if (!(density > 0.0f) || !std::isfinite(density)) return std::nullopt;
        return DirectionSample{wi, density};
    }
    float pdf(Vec3 wi) const override {
        const FiberAngles i = angles_of(wi);
        const double phi = wrap_angle(double(i.phi) - double(o_.phi));
        return per_steradian(longitudinal_.pdf(i.theta) * azimuthal_.pdf(wrap_angle(phi - kPi)), wi);
    }

  private:
    FiberAngles o_;
    TruncatedNormal longitudinal_, azimuthal_;
};

// θ_i ~ the wider longitudinal σ' = σ(n_h) + |θ_r|/π, φ uniform.
class SeedMultiplePoint final : public SamplerPoint {
  public:
    SeedMultiplePoint(double sigma, Vec3 wo)
        : o_(angles_of(wo)), longitudinal_(seed_longitudinal(o_.theta, sigma + std::fabs(double(o_.theta)) * kInvPi)) {}
    std::optional<DirectionSample> sample(float, float u1, float u2) const override {
        const double theta_i = longitudinal_.sample(u1);
        const double phi = kTwoPi * double(u2) - kPi;
        const Vec3 wi = direction_of(float(theta_i), float(wrap_angle(double(o_.phi) + phi)));
        const float density = pdf(wi);
        if (!(density > 0.0f) || !std::isfinite(density)) return std::nullopt;
        return DirectionSample{wi, density};
    }
    float pdf(Vec3 wi) const override { return per_steradian(longitudinal_.pdf(angles_of(wi).theta) * kInvTwoPi, wi); }

  private:
    FiberAngles o_;
    TruncatedNormal longitudinal_;
};

}  // namespace

Expected<SeedDirectSampler> SeedDirectSampler::create(const SeedPdfParams &params) {
    if (Status s = params.validate()) return *s;
    return SeedDirectSampler(params);
}

const SamplerPoint &SeedDirectSampler::at(const FiberHit &hit, const FiberPoint *, ScratchBuffer &scratch) const {
    return scratch.make<SeedDirectPoint>(params_, hit.wo);
}

Expected<SeedMultipleSampler> SeedMultipleSampler::create(const SeedPdfParams &params, int n_h) {
    if (Status s = params.validate()) return *s;
    const double sigma = seed_sigma_multiple(params, n_h);
    if (sigma <= 0.0) {
        std::string allowed;
        for (int v : params.n_h_values) allowed += (allowed.empty() ? "" : ", ") + std::to_string(v);
        return Error{"n_h must be one of {" + allowed + "} (got " + std::to_string(n_h) + ")"};
    }
    return SeedMultipleSampler(sigma);
}

const SamplerPoint &SeedMultipleSampler::at(const FiberHit &hit, const FiberPoint *, ScratchBuffer &scratch) const {
    return scratch.make<SeedMultiplePoint>(sigma_, hit.wo);
}

}  // namespace hairis
