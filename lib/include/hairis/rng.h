// Counter-based random numbers for the renderer: every number is a pure function of
// (seed, pixel, sample, dimension), so an image does not depend on how many threads drew it,
// in which order tiles ran, or how many numbers another path consumed.
//
// The function is a chain of 64-bit avalanche mixers (the "splitmix64" finaliser): each input
// word is folded into the state and the state is mixed, so a change of any bit of any input
// changes about half of the output bits. Floats take the top 24 bits: u = k·2^-24, k an
// integer in [0, 2^24), so u ∈ [0, 1) exactly and never rounds up to 1.
#pragma once

#include <cstdint>

namespace hairis {

/// The splitmix64 output mixer: a bijection of 64-bit words with full avalanche.
constexpr std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/// The top 24 bits of a word as a float in [0, 1).
constexpr float to_unit_float(std::uint64_t bits) {
    return float(bits >> 40) * (1.0f / 16777216.0f);
}

/// The random numbers of one camera sample: sample `sample` of pixel `pixel` under `seed`.
/// get(d) is the d-th dimension; different dimensions are independent.
class SampleRng {
  public:
    constexpr SampleRng(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample)
        : key_(mix64(mix64(mix64(seed ^ 0x6a09e667f3bcc909ull) ^ pixel) ^ sample)) {}

    /// Dimension `dimension` of this sample, in [0, 1).
    constexpr float get(std::uint32_t dimension) const {
        return to_unit_float(mix64(key_ ^ (std::uint64_t(dimension) * 0x9e3779b97f4a7c15ull)));
    }

    /// The 64-bit key all dimensions derive from (for tests).
    constexpr std::uint64_t key() const { return key_; }

  private:
    std::uint64_t key_;
};

/// One number: dimension `dimension` of sample `sample` of pixel `pixel` under `seed`.
float random_float(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample,
                   std::uint32_t dimension);

}  // namespace hairis
