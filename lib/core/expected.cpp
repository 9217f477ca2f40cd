#include "core/expected.h"

#include <sstream>

namespace hairis::check {

namespace {
std::string describe(double value) {
    std::ostringstream out;
    out.precision(9);
    out << value;
    return out.str();
}
}  // namespace

Status finite(const char *name, double value) {
    if (std::isfinite(value)) return std::nullopt;
    return Error{std::string(name) + " must be finite (got " + describe(value) + ")"};
}

Status in_range(const char *name, double value, double lo, double hi) {
    if (std::isfinite(value) && value >= lo && value <= hi) return std::nullopt;
    return Error{std::string(name) + " must be in [" + describe(lo) + ", " + describe(hi) +
                 "] (got " + describe(value) + ")"};
}

Status greater_than(const char *name, double value, double lo) {
    if (std::isfinite(value) && value > lo) return std::nullopt;
    return Error{std::string(name) + " must be finite and greater than " + describe(lo) +
                 " (got " + describe(value) + ")"};
}

Status non_negative(const char *name, double value) {
    if (std::isfinite(value) && value >= 0.0) return std::nullopt;
    return Error{std::string(name) + " must be finite and >= 0 (got " + describe(value) + ")"};
}

Status count_in_range(const char *name, long long value, long long lo, long long hi) {
    if (value >= lo && value <= hi) return std::nullopt;
    return Error{std::string(name) + " must be an integer in [" + std::to_string(lo) + ", " +
                 std::to_string(hi) + "] (got " + std::to_string(value) + ")"};
}

}  // namespace hairis::check
