// C API: the library's version and the thread-local last error, with the argument checks
// shared by the other translation units.
#include <cstdio>
#include <sstream>
#include <string>

#include "capi_internal.h"

// The library's version: lib/CMakeLists.txt may define HAIRIS_VERSION from PROJECT_VERSION
// (as bake/ does); the fallback is kept equal to it by tests/capi (which checks the string
// against PROJECT_VERSION).
#ifndef HAIRIS_VERSION
#define HAIRIS_VERSION "0.2.0"
#endif

namespace hairis::capi {

namespace {

thread_local std::string t_last_error;
// Set when a message could not be stored (out of memory); hairis_last_error reports it.
thread_local const char *t_fallback_error = nullptr;

}  // namespace

void set_error(const std::string &message) noexcept {
    try {
        t_last_error = message.empty() ? std::string("unknown error") : message;
        t_fallback_error = nullptr;
    } catch (...) {
        t_last_error.clear();
        t_fallback_error = "out of memory while reporting an error";
    }
}

void set_error(const char *message) noexcept {
    try {
        set_error(std::string(message ? message : ""));
    } catch (...) {
        t_last_error.clear();
        t_fallback_error = "out of memory while reporting an error";
    }
}

void clear_error() noexcept {
    t_last_error.clear();
    t_fallback_error = nullptr;
}

const char *last_error() noexcept {
    return t_fallback_error ? t_fallback_error : t_last_error.c_str();
}

int report_exception(const char *function, std::exception_ptr error) noexcept {
    try {
        std::rethrow_exception(error);
    } catch (const std::bad_alloc &) {
        set_error(std::string(function) + ": out of memory");
    } catch (const std::exception &e) {
        set_error(std::string(function) + ": internal error (please report): " + e.what());
    } catch (...) {
        set_error(std::string(function) + ": internal error (please report): unknown exception");
    }
    return HAIRIS_ERROR_INTERNAL;
}

void report_refusal(const char *function, const Refusal &refusal) noexcept {
    if (refusal.code != HAIRIS_ERROR_INTERNAL) {
        set_error(refusal.message);
        return;
    }
    try {
        set_error(std::string(function) + ": internal error (please report): " + refusal.message);
    } catch (...) {
        set_error(refusal.message);
    }
}

int code_of(ErrorKind kind) {
    switch (kind) {
        case ErrorKind::InvalidTable: return HAIRIS_ERROR_INVALID_TABLE;
        case ErrorKind::Io: return HAIRIS_ERROR_IO;
        case ErrorKind::Cancelled: return HAIRIS_ERROR_CANCELLED;
        case ErrorKind::InvalidArgument: break;
    }
    return HAIRIS_ERROR_INVALID_ARGUMENT;
}

void require_batch_size(size_t n, size_t per_item, const char *name) {
    // Keeps n * per_item * sizeof(float) and every index computation in range.
    const size_t limit = (size_t(1) << 58) / (per_item ? per_item : 1);
    if (n > limit)
        invalid(std::string(name) + " = " + std::to_string(n) + " is too large (at most " +
                std::to_string(limit) + ")");
}

std::string describe(double value) {
    std::ostringstream out;
    out.precision(9);
    out << value;
    return out.str();
}

std::string indexed(const char *name, size_t i) {
    return std::string(name) + "[" + std::to_string(i) + "]";
}

void require_finite(float value, const std::string &name) {
    if (!std::isfinite(value)) invalid(name + " must be finite (got " + describe(value) + ")");
}

void require_non_negative(float value, const std::string &name) {
    if (!(std::isfinite(value) && value >= 0.0f))
        invalid(name + " must be finite and >= 0 (got " + describe(value) + ")");
}

void require_colour(const float *rgb, const char *name) {
    require(rgb, name);
    for (size_t k = 0; k < 3; ++k) require_non_negative(rgb[k], indexed(name, k));
}

void require_unit_direction(const float *w, const char *name, size_t i) {
    const float x = w[3 * i], y = w[3 * i + 1], z = w[3 * i + 2];
    if (!(std::isfinite(x) && std::isfinite(y) && std::isfinite(z)))
        invalid(std::string(name) + " item " + std::to_string(i) + " must be finite (got (" +
                describe(x) + ", " + describe(y) + ", " + describe(z) + "))");
    const double len = std::sqrt(double(x) * x + double(y) * y + double(z) * z);
    if (!(std::fabs(len - 1.0) <= 1e-3))
        invalid(std::string(name) + " item " + std::to_string(i) +
                " must be a unit vector (length 1 within 1e-3; got length " + describe(len) +
                ")");
}

void require_view(const float *wo, const float *h, size_t i) {
    require_unit_direction(wo, "wo", i);
    if (h && !(h[i] >= -1.0f && h[i] <= 1.0f))
        invalid(indexed("h", i) + " must be finite and in [-1, 1] (got " + describe(h[i]) + ")");
}

void require_pair_batch(size_t n, const float *wi, const float *wo, const float *out,
                        const char *out_name) {
    require_batch_size(n, 3, "n");
    require_array(wi, n, "wi");
    require_array(wo, n, "wo");
    require_array(out, n, out_name);
}

void require_pair(const float *wi, const float *wo, const float *h, size_t i) {
    require_unit_direction(wi, "wi", i);
    require_view(wo, h, i);
}

}  // namespace hairis::capi

extern "C" {

HAIRIS_API int hairis_api_version(void) {
    hairis::capi::clear_error();
    return HAIRIS_API_VERSION;
}

HAIRIS_API const char *hairis_version_string(void) {
    hairis::capi::clear_error();
    return HAIRIS_VERSION;
}

HAIRIS_API const char *hairis_last_error(void) { return hairis::capi::last_error(); }

}  // extern "C"
