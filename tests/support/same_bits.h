#pragma once
// Bit-for-bit equality of float arrays: sizes equal and every byte equal (empty arrays included,
// whose data() may be null and must not reach memcmp).
#include <cstring>
#include <vector>

namespace hairis::testing {

inline bool same_bits(const std::vector<float> &a, const std::vector<float> &b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

}  // namespace hairis::testing
