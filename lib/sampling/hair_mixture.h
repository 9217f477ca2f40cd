// A hair material made of several hair closures, as Cycles renders a Mix Shader or Add Shader
// of Principled Hair BSDFs: each closure keeps its own fiber and sampler, f is the weighted sum
// of the closures' f, and a sample draws one closure with probability proportional to its
// weight, so the density of the sample is the same weighted sum of the closures' densities
// (Cycles' surface_shader_bsdf_sample_closure and _surface_shader_bsdf_eval_mis; Mitsuba 3's
// blendbsdf).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/expected.h"
#include "core/scratch.h"
#include "sampling/hair_bsdf.h"

namespace hairis {

/// The most closures one hair material mixes.
inline constexpr int kMaxHairClosures = 8;

/// Closure weights at one hit: where bit k of `given` is set, value[k] replaces closure k's
/// weight (a mix factor that varies per curve or point). Trivially destructible.
struct ClosureWeights {
    std::uint32_t given = 0;
    std::array<float, kMaxHairClosures> value{};
};

/// The mixture at one hit: f = Σ_k w_k f_k and pdf = Σ_k p_k pdf_k with p_k = w_k / Σ_j w_j, the
/// density sample() draws from. Valid while the scratch buffer it was made in is not reset.
class HairMixtureBsdf {
  public:
    /// f·|cos θ_i| and the mixture's density at wi.
    Rgb f_and_pdf(Vec3 wi, float &pdf) const;
    Rgb f(Vec3 wi) const {
        float pdf = 0.0f;
        return f_and_pdf(wi, pdf);
    }
    float pdf(Vec3 wi) const {
        float pdf = 0.0f;
        f_and_pdf(wi, pdf);
        return pdf;
    }
    /// Picks closure k with probability p_k (u0 reused, rescaled, as Cycles does), draws wi
    /// from it, and returns the mixture's f and density there; nullopt when all weights are 0
    /// or the closure draws nothing.
    std::optional<BsdfSample> sample(float u0, float u1, float u2) const;
    /// The ray passes: every closure of non-zero weight is transparent.
    bool transparent() const;
    int size() const { return count_; }
    /// Closure k and its weight, k in [0, size()).
    const HairBsdf &part(int k) const { return *part_[std::size_t(k)]; }
    float weight(int k) const { return weight_[std::size_t(k)]; }

  private:
    friend class HairMixture;
    int count_ = 0;
    std::array<const HairBsdf *, kMaxHairClosures> part_{};
    std::array<float, kMaxHairClosures> weight_{};
    std::array<float, kMaxHairClosures> select_{};  // p_k
};

/// K ≥ 1 hair closures with a weight each (Cycles' closure weight: the product of the mix
/// factors on the way from the output; an Add Shader gives each side 1).
class HairMixture {
  public:
    /// Refuses no closure, more than kMaxHairClosures, a weight count other than the closure
    /// count, and weights that are not finite or negative.
    static Expected<HairMixture> create(std::vector<HairShading> closures, std::vector<float> weights);

    int size() const { return int(closures_.size()); }
    const HairShading &closure(int k) const { return closures_[std::size_t(k)]; }
    float weight(int k) const { return weights_[std::size_t(k)]; }

    /// The mixture at `hit` (every closure sees the same hit and inputs), with `weights` in
    /// place of the material's where given (null: the material's own), made in `scratch`.
    HairMixtureBsdf at(const FiberHit &hit, const ClosureWeights *weights, ScratchBuffer &scratch) const;

  private:
    HairMixture() = default;
    std::vector<HairShading> closures_;
    std::vector<float> weights_;
};

}  // namespace hairis
