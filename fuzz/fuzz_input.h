// Reads fuzz bytes as the plain C values the C API takes: each read copies the next bytes
// (zero-filling past the end), so any input, however short, is a complete call sequence.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "hairis/hairis.h"

namespace hairis::fuzz {

class FuzzInput {
  public:
    FuzzInput(const uint8_t *data, size_t size) : data_(data), size_(size) {}

    bool empty() const { return offset_ >= size_; }

    /// Copies sizeof(T) bytes into a T (trivially copyable C structs, ints, floats).
    template <typename T>
    T take() {
        T value;
        std::memset(&value, 0, sizeof value);
        const size_t n = offset_ < size_ ? std::min(sizeof value, size_ - offset_) : 0;
        if (n) std::memcpy(&value, data_ + offset_, n);
        offset_ += sizeof value;
        return value;
    }

    /// A count in [0, limit] from one or two bytes (small counts are the interesting ones).
    size_t count(size_t limit) {
        const uint16_t raw = take<uint16_t>();
        return limit ? size_t(raw) % (limit + 1) : 0;
    }

  private:
    const uint8_t *data_;
    size_t size_;
    size_t offset_ = 0;
};

/// With HAIRIS_FUZZ_TRACE set, prints each call's outcome (to check what a seed reaches).
inline void trace(const char *call, bool ok) {
    static const bool enabled = std::getenv("HAIRIS_FUZZ_TRACE") != nullptr;
    if (enabled) std::fprintf(stderr, "  %s: %s\n", call, ok ? "ok" : hairis_last_error());
}

/// A C API call whose status says "a bug" is a finding: abort so the fuzzer (or the corpus
/// replay in CTest) reports it with the input that caused it.
inline void check_not_internal(int status, const char *call) {
    trace(call, status == HAIRIS_OK);
    if (status == HAIRIS_ERROR_INTERNAL) {
        std::fprintf(stderr, "%s returned HAIRIS_ERROR_INTERNAL: %s\n", call, hairis_last_error());
        std::abort();
    }
}

/// The same for calls that return NULL or -1 on failure. The C API's boundary words those
/// failures "<function>: internal error (please report): ..." and "<function>: out of
/// memory"; the prefix is matched, since refusals may quote the input, which can hold
/// any text. "out of memory" counts too: sizes an input claims must be refused before
/// allocating.
inline void check_last_error(const char *call) {
    trace(call, false);
    const char *e = hairis_last_error();
    const size_t n = std::strlen(call);
    if (std::strncmp(e, call, n) == 0 &&
        (std::strncmp(e + n, ": internal error", 16) == 0 || std::strncmp(e + n, ": out of memory", 15) == 0)) {
        std::fprintf(stderr, "%s failed with an internal error: %s\n", call, e);
        std::abort();
    }
}

}  // namespace hairis::fuzz
