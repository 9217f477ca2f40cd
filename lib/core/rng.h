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

/// Bit reversal of a 32-bit word.
constexpr std::uint32_t reverse_bits32(std::uint32_t x) {
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
}

/// Owen scrambling of a 0.32 fixed-point number in base 2 (each digit flipped by a hash of the
/// digits before it): Laine and Karras' hash on the bit-reversed word, as Burley 2020 does.
constexpr std::uint32_t nested_uniform_scramble(std::uint32_t x, std::uint32_t seed) {
    x = reverse_bits32(x);
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return reverse_bits32(x);
}

/// The second dimension of the Sobol sequence (the first is reverse_bits32(index)).
constexpr std::uint32_t sobol_second_dimension(std::uint32_t index) {
    std::uint32_t result = 0;
    for (std::uint32_t v = 1u << 31; index != 0; index >>= 1, v ^= v >> 1)
        if (index & 1u) result ^= v;
    return result;
}

/// The random numbers of one camera sample as a padded, Owen-scrambled Sobol sequence
/// (Burley 2020): dimensions 2k and 2k + 1 are the two dimensions of a (0, 2)-sequence whose
/// index is shuffled per (seed, pixel, k), and every dimension has its own scramble. So the
/// samples of a pixel are stratified in each dimension and in each pair — with 2^m samples
/// every elementary interval of area 2^-m of a pair holds exactly one — while different
/// pairs and different pixels stay independent. Each number is still uniform on [0, 1), so
/// estimates stay unbiased, and it is a pure function of (seed, pixel, sample, dimension)
/// like SampleRng's. Sample indices are taken modulo 2^32.
class SobolSampleRng {
  public:
    constexpr SobolSampleRng(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample)
        : key_(mix64(mix64(seed ^ 0xbb67ae8584caa73bull) ^ pixel)), sample_(std::uint32_t(sample)) {}

    /// Dimension `dimension` of this sample, in [0, 1).
    constexpr float get(std::uint32_t dimension) const {
        const std::uint32_t pair = dimension >> 1;
        const std::uint32_t shuffled = nested_uniform_scramble(
            sample_, std::uint32_t(mix64(key_ ^ (std::uint64_t(pair) * 0x9e3779b97f4a7c15ull))));
        const std::uint32_t point = (dimension & 1u) ? sobol_second_dimension(shuffled)
                                                     : reverse_bits32(shuffled);
        const std::uint32_t scrambled = nested_uniform_scramble(
            point, std::uint32_t(mix64(key_ ^ (std::uint64_t(dimension) * 0xc2b2ae3d27d4eb4full) ^
                                       0x165667b19e3779f9ull)));
        return float(scrambled >> 8) * (1.0f / 16777216.0f);
    }

  private:
    std::uint64_t key_;
    std::uint32_t sample_;
};

/// One number: dimension `dimension` of sample `sample` of pixel `pixel` under `seed`.
float random_float(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample,
                   std::uint32_t dimension);

}  // namespace hairis
