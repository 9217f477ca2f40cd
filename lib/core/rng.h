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

/// Laine and Karras' hash of a bit-reversed word: each bit flipped by a hash of the bits
/// below it (the digits before it in the unreversed word).
constexpr std::uint32_t laine_karras(std::uint32_t x, std::uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/// Owen scrambling of a 0.32 fixed-point number in base 2 (each digit flipped by a hash of the
/// digits before it): Laine and Karras' hash on the bit-reversed word, as Burley 2020 does.
constexpr std::uint32_t nested_uniform_scramble(std::uint32_t x, std::uint32_t seed) {
    return reverse_bits32(laine_karras(reverse_bits32(x), seed));
}

namespace detail {

// A linear map of 32-bit words over GF(2) as four tables, one per byte of the input:
// map(x) = t[0][x & 255] ^ t[1][(x >> 8) & 255] ^ t[2][(x >> 16) & 255] ^ t[3][x >> 24].
struct ByteTables {
    std::uint32_t t[4][256];
    constexpr std::uint32_t operator()(std::uint32_t x) const {
        return t[0][x & 255u] ^ t[1][(x >> 8) & 255u] ^ t[2][(x >> 16) & 255u] ^ t[3][x >> 24];
    }
};

// The Sobol sequence's second dimension (generator: the Pascal matrix mod 2), bit by bit.
constexpr std::uint32_t sobol_second_dimension_bits(std::uint32_t index) {
    std::uint32_t result = 0;
    for (std::uint32_t v = 1u << 31; index != 0; index >>= 1, v ^= v >> 1)
        if (index & 1u) result ^= v;
    return result;
}

// reversed = false: x ↦ sobol2(x); true: y ↦ reverse(sobol2(reverse(y))), the same map on
// bit-reversed words (bit reversal is linear, so it folds into the tables).
constexpr ByteTables make_sobol_second_tables(bool reversed) {
    ByteTables tables{};
    for (int byte = 0; byte < 4; ++byte)
        for (std::uint32_t value = 0; value < 256; ++value) {
            const std::uint32_t x = value << (8 * byte);
            tables.t[byte][value] =
                reversed ? reverse_bits32(sobol_second_dimension_bits(reverse_bits32(x)))
                         : sobol_second_dimension_bits(x);
        }
    return tables;
}

inline constexpr ByteTables kSobolSecond = make_sobol_second_tables(false);
inline constexpr ByteTables kSobolSecondReversed = make_sobol_second_tables(true);

}  // namespace detail

/// The second dimension of the Sobol sequence (the first is reverse_bits32(index)).
constexpr std::uint32_t sobol_second_dimension(std::uint32_t index) {
    return detail::kSobolSecond(index);
}

/// The random numbers of one camera sample as a padded, Owen-scrambled Sobol sequence
/// (Burley 2020): dimensions 2k and 2k + 1 are the two dimensions of a (0, 2)-sequence whose
/// index is shuffled per (seed, pixel, k), and every dimension has its own scramble. So the
/// samples of a pixel are stratified in each dimension and in each pair — with 2^m samples
/// every elementary interval of area 2^-m of a pair holds exactly one — while different
/// pairs and different pixels stay independent. Each number is still uniform on [0, 1), so
/// estimates stay unbiased, and it is a pure function of (seed, pixel, sample, dimension)
/// like SampleRng's. Sample indices are taken modulo 2^32.
///
/// get(d) is, with shuffle = nested_uniform_scramble(sample, hash(pair)) and point =
/// reverse_bits32(shuffle) for even d, sobol_second_dimension(shuffle) for odd d,
/// nested_uniform_scramble(point, hash(d)); it is computed in the bit-reversed domain, where
/// the reversals between the two scrambles cancel.
class SobolSampleRng {
  public:
    constexpr SobolSampleRng(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample)
        : key_(mix64(mix64(seed ^ 0xbb67ae8584caa73bull) ^ pixel)),
          reversed_sample_(reverse_bits32(std::uint32_t(sample))) {}

    /// Dimension `dimension` of this sample, in [0, 1).
    constexpr float get(std::uint32_t dimension) const {
        const std::uint32_t pair = dimension >> 1;
        // reverse(shuffle): the pair's index shuffle without its final reversal.
        const std::uint32_t shuffle_reversed = laine_karras(
            reversed_sample_,
            std::uint32_t(mix64(key_ ^ (std::uint64_t(pair) * 0x9e3779b97f4a7c15ull))));
        // reverse(point): for even d point = reverse(shuffle), so reverse(point) = shuffle.
        const std::uint32_t point_reversed = (dimension & 1u)
                                                 ? detail::kSobolSecondReversed(shuffle_reversed)
                                                 : reverse_bits32(shuffle_reversed);
        const std::uint32_t scrambled = reverse_bits32(laine_karras(
            point_reversed,
            std::uint32_t(mix64(key_ ^ (std::uint64_t(dimension) * 0xc2b2ae3d27d4eb4full) ^
                                0x165667b19e3779f9ull))));
        return float(scrambled >> 8) * (1.0f / 16777216.0f);
    }

  private:
    std::uint64_t key_;
    std::uint32_t reversed_sample_;
};

/// One number: dimension `dimension` of sample `sample` of pixel `pixel` under `seed`.
float random_float(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample,
                   std::uint32_t dimension);

}  // namespace hairis
