#include "sampling/hair_mixture.h"

#include <cmath>
#include <string>

namespace hairis {

Expected<HairMixture> HairMixture::create(std::vector<HairShading> closures, std::vector<float> weights) {
    if (closures.empty()) return Error{"hair mixture: no closure was given (a mixture needs 1 to " +
                                       std::to_string(kMaxHairClosures) + ")"};
    if (closures.size() > std::size_t(kMaxHairClosures))
        return Error{"hair mixture: " + std::to_string(closures.size()) + " closures; at most " +
                     std::to_string(kMaxHairClosures) + " are allowed"};
    if (weights.size() != closures.size())
        return Error{"hair mixture: " + std::to_string(weights.size()) + " weights for " +
                     std::to_string(closures.size()) + " closures; give one weight per closure"};
    for (std::size_t k = 0; k < weights.size(); ++k)
        if (!std::isfinite(weights[k]) || weights[k] < 0.0f)
            return Error{"hair mixture: closure " + std::to_string(k) + "'s weight is " + std::to_string(weights[k]) +
                         "; weights must be finite and >= 0"};
    HairMixture m;
    m.closures_ = std::move(closures);
    m.weights_ = std::move(weights);
    return m;
}

HairMixtureBsdf HairMixture::at(const FiberHit &hit, const ClosureWeights *weights, ScratchBuffer &scratch) const {
    HairMixtureBsdf b;
    float sum = 0.0f;
    for (int k = 0; k < size(); ++k) {
        const bool given = weights && ((weights->given >> unsigned(k)) & 1u);
        const float w = given ? weights->value[std::size_t(k)] : weights_[std::size_t(k)];
        if (!(w > 0.0f)) continue;  // Cycles makes no closure of weight 0
        b.part_[std::size_t(b.count_)] = &scratch.make<HairBsdf>(closures_[std::size_t(k)].at(hit, scratch));
        b.weight_[std::size_t(b.count_)] = w;
        sum += w;
        ++b.count_;
    }
    for (int k = 0; k < b.count_; ++k) b.select_[std::size_t(k)] = b.weight_[std::size_t(k)] / sum;
    return b;
}

Rgb HairMixtureBsdf::f_and_pdf(Vec3 wi, float &pdf) const {
    Rgb f{0.0f};
    pdf = 0.0f;
    for (int k = 0; k < count_; ++k) {
        float pdf_k = 0.0f;
        f += part_[std::size_t(k)]->f_and_pdf(wi, pdf_k) * weight_[std::size_t(k)];
        pdf += select_[std::size_t(k)] * pdf_k;
    }
    return f;
}

std::optional<BsdfSample> HairMixtureBsdf::sample(float u0, float u1, float u2) const {
    if (count_ == 0) return std::nullopt;
    // The closure whose share of [0, 1) holds u0; u0 rescaled to [0, 1) within that share.
    int pick = count_ - 1;
    float below = 0.0f;
    for (int k = 0; k < count_ - 1; ++k) {
        if (u0 < below + select_[std::size_t(k)]) {
            pick = k;
            break;
        }
        below += select_[std::size_t(k)];
    }
    const float share = select_[std::size_t(pick)];
    const float u = std::fmin(std::fmax((u0 - below) / share, 0.0f), std::nextafter(1.0f, 0.0f));
    std::optional<BsdfSample> s = part_[std::size_t(pick)]->sample(u, u1, u2);
    if (!s || !(s->pdf > 0.0f)) return std::nullopt;
    Rgb f = s->f * weight_[std::size_t(pick)];
    float pdf = share * s->pdf;
    for (int k = 0; k < count_; ++k) {
        if (k == pick) continue;
        float pdf_k = 0.0f;
        f += part_[std::size_t(k)]->f_and_pdf(s->wi, pdf_k) * weight_[std::size_t(k)];
        pdf += select_[std::size_t(k)] * pdf_k;
    }
    return BsdfSample{s->wi, f, pdf, s->lobe};
}

bool HairMixtureBsdf::transparent() const {
    if (count_ == 0) return false;
    for (int k = 0; k < count_; ++k)
        if (!part_[std::size_t(k)]->transparent()) return false;
    return true;
}

}  // namespace hairis
