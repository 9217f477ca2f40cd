// Reads fuzz bytes as the values the C API takes: plain numbers and arrays (each read copies
// the next bytes, zero-filling past the end, so any input, however short, is a complete call
// sequence) and option strings. The format of capi_params' inputs is defined here, shared by
// the target and by write_capi_seeds, which writes its seed corpus.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "hairis/hairis.h"

namespace hairis::fuzz {

class FuzzInput {
  public:
    FuzzInput(const uint8_t *data, size_t size) : data_(data), size_(size) {}

    bool empty() const { return offset_ >= size_; }

    /// Copies sizeof(T) bytes into a T (ints, floats).
    template <typename T>
    T take() {
        T value;
        std::memset(&value, 0, sizeof value);
        const size_t n = offset_ < size_ ? std::min(sizeof value, size_ - offset_) : 0;
        if (n) std::memcpy(&value, data_ + offset_, n);
        offset_ += sizeof value;
        return value;
    }

    /// A count in [0, limit] from two bytes (small counts are the interesting ones).
    size_t count(size_t limit) {
        const uint16_t raw = take<uint16_t>();
        return limit ? size_t(raw) % (limit + 1) : 0;
    }

    /// The next n bytes as text (zero bytes past the end).
    std::string text(size_t n) {
        std::string s(n, '\0');
        for (char &c : s) c = char(take<uint8_t>());
        return s;
    }

  private:
    const uint8_t *data_;
    size_t size_;
    size_t offset_ = 0;
};

// ---- capi_params' input format ---------------------------------------------------------------
//
// An input is a sequence of calls: an opcode byte (Op, modulo kOpCount) and what the call
// takes. Handles are picked by one byte among those made so far (one past the end: NULL).
// An option string is read as (Options):
//   mode byte m >= kRawOptions      raw text: a uint16 length (modulo kMaxRawText + 1) and
//                                   that many bytes (the string ends at a zero byte);
//   m == kNullOptions               a NULL pointer;
//   otherwise                       m % 16 items, each a name byte and a value:
//     name byte < kGarbageNamesFrom known_names(kind)[byte % count] (hairis_defaults' names);
//                else               kGarbageNames[byte - kGarbageNamesFrom]; kLiteralName
//                                   reads a length byte (modulo 16) and that many bytes;
//     value byte v, by v % 8 (Value): a number from kNumbers (index byte), a float's bytes
//     printed "%.9g", an int32 printed, a word from kWords (index byte), a vector (a count
//     byte modulo 17, then per element a byte b: b >= 128 a float's bytes, else kNumbers[b]),
//     literal bytes (a length byte modulo 32 and the bytes), the name's default value, "".
//   Structured strings for Marschner fibers and lights start with model=marschner / type=<kind>
//   unless an item names model / type itself.

enum Op : uint8_t {
    kFiber = 0,     // kind byte (even: chiang, odd: marschner), options
    kEval,          // fiber, n, wi, wo, h (floats), near byte
    kBake,          // fiber, options
    kSample,        // fiber, tables, options; sampler, n, wo, u, h (floats), h byte
    kHairMaterial,  // fiber, tables
    kSurface,       // options ("diffuse")
    kCurves,        // int8 material, shape byte, counts and arrays (capi_params' add_curves)
    kMesh,          // counts and arrays
    kLight,         // kind byte (% 3: sun, point, area), options
    kWorld,         // options
    kCamera,        // options
    kRender,        // options
    kQuery,         // which byte, handle or text: getters and hairis_defaults
    kOpCount
};

inline constexpr uint8_t kRawOptions = 0xC0;
inline constexpr uint8_t kNullOptions = 0xBF;
inline constexpr size_t kMaxRawText = 1024;
inline constexpr uint8_t kGarbageNamesFrom = 0xE0;

enum Value : uint8_t { kNumber = 0, kFloatBytes, kIntBytes, kWord, kVector, kLiteral, kDefault, kEmpty };

inline const std::vector<std::string> &numbers() {
    static const std::vector<std::string> v = {
        "0", "-0", "1", "-1", "0.5", "2", "3", "4", "7", "8", "16", "17", "31", "64", "100",
        "1024", "1025", "4096", "4097", "65536", "65537", "16777216", "16777217",
        "2147483647", "2147483648", "-2147483648", "4294967296", "18446744073709551615",
        "18446744073709551616", "1e-38", "1.4e-45", "0.001", "1.55", "0.3", "3.40282347e+38",
        "3.5e38", "1e30", "-1e30", "1e308", "1e309", "nan", "-nan", "inf", "-inf", "NaN",
        "Infinity", "0x10", "1e", "", ".", "-", " 5 ", "+5", "3.4", "4.2", "2.8", "1,2",
        "1,2,4,8,16", "0,0,1", "1,1,1", "0.5,0.5,0.5", "1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1"};
    return v;
}

inline const std::vector<std::string> &words() {
    static const std::vector<std::string> v = {
        "chiang", "marschner", "absorption", "melanin", "color", "uniform", "analytic",
        "gaussian", "table", "exact", "sun", "point", "area", "square", "rectangle", "disk",
        "ellipse", "diffuse", "true", "false", "0", "1", "yes", "TABLE", "Chiang", "glossy"};
    return v;
}

/// Names no kind knows (or another kind's), and kLiteralName (bytes from the input).
inline const std::vector<std::string> &garbage_names() {
    static const std::vector<std::string> v = {
        "bogus", "", " ", "model", "type", "samples", "eta", "roughness", "preset",
        "offset_deg", "size_x", "strategy ", "n_h;", "a=b", "\xff", "<literal>"};
    return v;
}
inline constexpr uint8_t kLiteralName = 15;  // garbage_names()[15]

/// The option kinds of hairis_defaults, in the order capi_params indexes them.
inline const std::vector<std::string> &option_kinds() {
    static const std::vector<std::string> v = {"chiang", "marschner", "bake",  "sampler",
                                               "diffuse", "sun",      "point", "area",
                                               "world",  "camera",   "render",
                                               "curve_inputs"};
    return v;
}

/// The items of an option string as the library splits them (';', then the first '=',
/// spaces trimmed); false when an item has no '=' (the library refuses such a string).
inline bool split_options(const std::string &text, std::vector<std::pair<std::string, std::string>> &items) {
    auto trim = [](const std::string &s) {
        const size_t a = s.find_first_not_of(" \t\r\n");
        return a == std::string::npos ? std::string() : s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
    };
    items.clear();
    size_t start = 0;
    while (start <= text.size()) {
        size_t end = text.find(';', start);
        if (end == std::string::npos) end = text.size();
        const std::string item = trim(text.substr(start, end - start));
        start = end + 1;
        if (item.empty()) continue;
        const size_t eq = item.find('=');
        if (eq == std::string::npos) return false;
        items.emplace_back(trim(item.substr(0, eq)), trim(item.substr(eq + 1)));
    }
    return true;
}

/// The names (and defaults) hairis_defaults(kind) lists, plus offset_deg for Chiang.
inline const std::vector<std::pair<std::string, std::string>> &known_names(size_t kind) {
    static std::vector<std::vector<std::pair<std::string, std::string>>> cache;
    if (cache.empty()) {
        for (const std::string &k : option_kinds()) {
            std::vector<std::pair<std::string, std::string>> items;
            const char *defaults = hairis_defaults(k.c_str());
            if (!defaults || !split_options(defaults, items) || items.empty()) {
                std::fprintf(stderr, "hairis_defaults(\"%s\") is not an option string\n", k.c_str());
                std::abort();
            }
            if (k == "chiang") items.emplace_back("offset_deg", "2");
            cache.push_back(std::move(items));
        }
    }
    return cache[kind % cache.size()];
}

/// With HAIRIS_FUZZ_TRACE set, prints each call's outcome (to check what a seed reaches).
inline void trace(const char *call, bool ok, const std::string &detail = {}) {
    static const bool enabled = std::getenv("HAIRIS_FUZZ_TRACE") != nullptr;
    if (enabled)
        std::fprintf(stderr, "  %s%s%s: %s\n", call, detail.empty() ? "" : " ", detail.c_str(),
                     ok ? "ok" : hairis_last_error());
}

/// A C API call whose status says "a bug" is a finding: abort so the fuzzer (or the corpus
/// replay in CTest) reports it with the input that caused it.
inline void check_not_internal(int status, const char *call, const std::string &detail = {}) {
    trace(call, status == HAIRIS_OK, detail);
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
inline void check_last_error(const char *call, const std::string &detail = {}) {
    trace(call, false, detail);
    const char *e = hairis_last_error();
    const size_t n = std::strlen(call);
    if (std::strncmp(e, call, n) == 0 &&
        (std::strncmp(e + n, ": internal error", 16) == 0 || std::strncmp(e + n, ": out of memory", 15) == 0)) {
        std::fprintf(stderr, "%s failed with an internal error: %s\n", call, e);
        std::abort();
    }
}

}  // namespace hairis::fuzz
