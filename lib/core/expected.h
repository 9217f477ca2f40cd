// Errors as values: every public constructor of hairis returns Expected<T>.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace hairis {

/// What kind of input an error refuses (the C API maps it to a status code).
enum class ErrorKind { InvalidArgument, InvalidTable, Io, Cancelled };

/// A human-readable error: names what is wrong and what is allowed.
struct Error {
    std::string message;
    ErrorKind kind = ErrorKind::InvalidArgument;
};

/// Either a value of T or an Error; never both, never neither.
template <typename T>
class Expected {
  public:
    Expected(T value) : state_(std::move(value)) {}         // NOLINT: implicit by design
    Expected(Error error) : state_(std::move(error)) {}     // NOLINT: implicit by design

    /// True when a value is held.
    bool ok() const { return std::holds_alternative<T>(state_); }
    explicit operator bool() const { return ok(); }

    /// The value; only valid when ok().
    const T &value() const & { return std::get<T>(state_); }
    T &value() & { return std::get<T>(state_); }
    T &&value() && { return std::get<T>(std::move(state_)); }

    /// The error; only valid when !ok().
    const Error &error() const { return std::get<Error>(state_); }

  private:
    std::variant<T, Error> state_;
};

/// A check that either passes (no error) or names what failed.
using Status = std::optional<Error>;

namespace check {

/// Refuses NaN and infinities: "<name> must be finite (got nan)".
Status finite(const char *name, double value);
/// Refuses values outside [lo, hi] (and non-finite values).
Status in_range(const char *name, double value, double lo, double hi);
/// Refuses values <= lo (and non-finite values): for IOR > 1 and friends.
Status greater_than(const char *name, double value, double lo);
/// Refuses negative or non-finite values.
Status non_negative(const char *name, double value);
/// Refuses integers outside [lo, hi].
Status count_in_range(const char *name, long long value, long long lo, long long hi);

}  // namespace check

/// Runs checks in order and returns the first failure.
template <typename... S>
Status first_error(S &&...statuses) {
    Status result;
    ((result = result ? result : std::forward<S>(statuses)), ...);
    return result;
}

}  // namespace hairis
