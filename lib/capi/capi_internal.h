// Internals shared by the C API's translation units (lib/include/hairis/hairis.h): the
// thread-local last error, the exception boundary every exported function runs inside, the
// argument checks, and the definitions of the opaque handles.
//
// Error model: an implementation reports a refused input by throwing capi::Refusal (a code
// and a message); the boundary (guard_status / guard_handle / guard_value / guard_void)
// catches it and every other exception, stores the message as the calling thread's last
// error and returns the failure value. On success the boundary clears the last error. No C++
// exception ever crosses into C.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "fiber/chiang.h"
#include "core/expected.h"
#include "fiber/fiber.h"
#include "fiber/fiber_spec.h"
#include "fiber/huang.h"
#include "core/options.h"
#include "hairis/hairis.h"
#include "sampling/hair_bsdf.h"
#include "sampling/strategy.h"
#include "tables/table_file.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace hairis::capi {

// ---- The last error -------------------------------------------------------------------------

/// Sets the calling thread's last error. Never throws: if the message cannot be stored (out
/// of memory), a fixed message is reported instead.
void set_error(const std::string &message) noexcept;
void set_error(const char *message) noexcept;
/// Clears the calling thread's last error ("" = the last call succeeded).
void clear_error() noexcept;
/// The calling thread's last error ("" after a successful call); never NULL.
const char *last_error() noexcept;

/// A refused call: thrown inside an implementation, turned into a status at the boundary.
struct Refusal {
    int code;
    std::string message;
};

[[noreturn]] inline void refuse(int code, std::string message) {
    throw Refusal{code, std::move(message)};
}
[[noreturn]] inline void invalid(std::string message) {
    refuse(HAIRIS_ERROR_INVALID_ARGUMENT, std::move(message));
}

/// Records an exception that is not a Refusal as an internal error of `function`.
int report_exception(const char *function, std::exception_ptr error) noexcept;
/// Records a refusal; one with HAIRIS_ERROR_INTERNAL is worded as report_exception words its
/// errors ("<function>: internal error (please report): ..."), so that calls returning a
/// handle, which have no status, still say that it is a bug.
void report_refusal(const char *function, const Refusal &refusal) noexcept;

/// Runs f() -> int (a status) at the boundary: clears the last error on HAIRIS_OK.
template <typename F>
int guard_status(const char *function, F &&f) noexcept {
    try {
        const int code = f();
        if (code == HAIRIS_OK) clear_error();
        return code;
    } catch (const Refusal &r) {
        report_refusal(function, r);
        return r.code;
    } catch (...) {
        return report_exception(function, std::current_exception());
    }
}

/// Runs f() -> T at the boundary: `failure` when it throws.
template <typename T, typename F>
T guard_value(const char *function, T failure, F &&f) noexcept {
    try {
        T value = f();
        clear_error();
        return value;
    } catch (const Refusal &r) {
        report_refusal(function, r);
    } catch (...) {
        report_exception(function, std::current_exception());
    }
    return failure;
}

/// Runs f() -> T* (a new handle) at the boundary: NULL on failure.
template <typename T, typename F>
T *guard_handle(const char *function, F &&f) noexcept {
    return guard_value<T *>(function, nullptr, std::forward<F>(f));
}

/// Runs f() -> void at the boundary.
template <typename F>
void guard_void(const char *function, F &&f) noexcept {
    try {
        f();
        clear_error();
    } catch (const Refusal &r) {
        report_refusal(function, r);
    } catch (...) {
        report_exception(function, std::current_exception());
    }
}

// ---- Argument checks (each throws a Refusal naming the argument) ----------------------------

/// Refuses a NULL pointer: "<name> must not be NULL".
inline void require(const void *pointer, const char *name) {
    if (pointer == nullptr) invalid(std::string(name) + " must not be NULL");
}
/// Refuses a NULL array unless it holds no items: "<name> must not be NULL (n = 5)".
inline void require_array(const void *pointer, size_t n, const char *name) {
    if (pointer == nullptr && n > 0)
        invalid(std::string(name) + " must not be NULL when n > 0 (n = " + std::to_string(n) + ")");
}
/// Refuses n whose arrays of `per_item` floats would not fit in memory.
void require_batch_size(size_t n, size_t per_item, const char *name);
/// The status code of a core error's kind.
int code_of(ErrorKind kind);
/// Turns a failed core check into a Refusal (by its kind), with an optional prefix.
inline void ok_or_invalid(const Status &status, const std::string &prefix = {}) {
    if (status) refuse(code_of(status->kind), prefix + status->message);
}
/// The options string `text` (NULL reads as "") described by describe(fields, value): every
/// name read into `value`, unknown names and bad values refused naming them.
template <typename T>
void read_options(const char *text, const std::string &what, T &value) {
    Expected<OptionReader> reader = OptionReader::parse(text ? text : "", what);
    if (!reader) invalid(reader.error().message);
    describe(reader.value(), value);
    ok_or_invalid(reader.value().finish());
}
/// The options string of value's fields.
template <typename T>
std::string write_options(T value) {
    OptionWriter writer;
    describe(writer, value);
    return writer.str();
}
/// Prints a float for messages (9 significant digits; nan, inf).
std::string describe(double value);
/// "<name>[i]" for messages.
std::string indexed(const char *name, size_t i);
/// Refuses a non-finite float: "<name> must be finite (got nan)".
void require_finite(float value, const std::string &name);
/// Refuses a non-finite or negative float: "<name> must be finite and >= 0 (got -1)".
void require_non_negative(float value, const std::string &name);
/// Refuses a colour with a non-finite or negative component, naming it "<name>[k]".
void require_colour(const float *rgb, const char *name);
/// Refuses a direction that is not finite or not of unit length (within 1e-3).
void require_unit_direction(const float *w, const char *name, size_t i);
/// Refuses item i of a view: wo a unit direction, h NULL (the far field) or in [-1, 1].
void require_view(const float *wo, const float *h, size_t i);
/// Refuses a batch of n direction pairs and its output before anything is read: a size that
/// fits in memory and no NULL array.
void require_pair_batch(size_t n, const float *wi, const float *wo, const float *out,
                        const char *out_name);
/// Refuses item i of a batch of direction pairs: wi as require_unit_direction, wo and h as
/// require_view.
void require_pair(const float *wi, const float *wo, const float *h, size_t i);
/// Item i of an array of 3-vectors.
inline Vec3 vec3_at(const float *a, size_t i) { return {a[3 * i], a[3 * i + 1], a[3 * i + 2]}; }
/// Stores c as item i of an array of RGB triples.
inline void store_rgb(float *out, size_t i, Rgb c) {
    out[3 * i] = c.r;
    out[3 * i + 1] = c.g;
    out[3 * i + 2] = c.b;
}

/// Calls f(i) for every i < n: in order for small batches, in parallel (oneTBB) for large
/// ones. Items must be independent. Exceptions propagate to the caller.
template <typename F>
void for_each_item(size_t n, const F &f) {
    constexpr size_t kParallelFrom = 2048, kGrain = 512;
    if (n < kParallelFrom) {
        for (size_t i = 0; i < n; ++i) f(i);
        return;
    }
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrain),
                      [&](const tbb::blocked_range<size_t> &r) {
                          for (size_t i = r.begin(); i != r.end(); ++i) f(i);
                      });
}

// ---- Shared conversions ---------------------------------------------------------------------

/// The canonical "name=value;..." string of a fiber spec (what table metadata records).
std::string spec_parameters(const FiberSpec &spec);
/// What hairis_fiber_create starts from for a model (hairis_defaults lists it): the node's
/// defaults for Chiang and Huang, the seed's blonde parameters for Marschner.
FiberSpec default_fiber_spec(FiberKind kind);

}  // namespace hairis::capi

// ---- The handles ----------------------------------------------------------------------------

/// A fiber: its FiberSpec (the source of its model name and parameter string, as the table
/// metadata records them) and the model built from it. Immutable after creation.
struct hairis_fiber {
    hairis::FiberSpec spec;
    std::shared_ptr<const hairis::FiberModel> model;
    std::shared_ptr<const hairis::ChiangFiber> chiang;  // the same object, for Chiang fibers
    std::shared_ptr<const hairis::HuangFiber> huang;    // the same object, for Huang fibers
    std::string model_name;
    std::string parameters;  // canonical_parameters(spec.parameters())
};

/// Baked or loaded tables: the table set (for writing) and the samplers' tables built from it,
/// shared with every sampler and scene material made from them.
struct hairis_tables {
    hairis::TableSet set;
    hairis::SamplingTables sampling;
    std::string parameters;  // canonical_parameters(set.parameters)
    std::string info;        // hairis_tables_info
};

/// A direction sampler bound to its fiber (when it reads one): owns everything it samples from.
struct hairis_sampler {
    hairis::HairShading shading;
};
