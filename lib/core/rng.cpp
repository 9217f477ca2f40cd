#include "core/rng.h"

namespace hairis {

float random_float(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample,
                   std::uint32_t dimension) {
    return SampleRng(seed, pixel, sample).get(dimension);
}

}  // namespace hairis
