// Option strings "name=value;name=value": how the C API takes every parameter set (fibers,
// bakes, samplers, lights, cameras, renders) and how table metadata records parameters.
//
// Grammar: items separated by ';', each `name=value` (spaces around either are ignored, empty
// items too). Numbers are decimal (strtod: round-trip exact with 9 significant digits for
// floats, 17 for doubles); vectors are numbers separated by ','; booleans 0/1/true/false;
// choices are words. A name may appear once. Names a reader never asks for are unknown and
// refused by finish(), which lists the names it knows.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "core/math.h"

namespace hairis {

/// The items of an option string, in order.
using OptionItems = std::vector<std::pair<std::string, std::string>>;

/// Splits an option string; refuses an item without '=', an empty name and repeated names.
/// `what` names the string in messages ("render settings").
Expected<OptionItems> parse_options(const std::string &text, const std::string &what);

/// "name=value;..." from items (values as given).
std::string format_options(const OptionItems &items);

/// A number printed so that it reads back to the same value: 9 significant digits for a
/// float, 17 for a double.
std::string format_number(float value);
std::string format_number(double value);

/// Reads typed values out of an option string. Every read names an option the caller knows;
/// an option that is absent leaves the value as it was (its default). Errors name the option
/// and what it allows.
class OptionReader {
  public:
    static Expected<OptionReader> parse(const std::string &text, const std::string &what);

    Status read(const char *name, int &value, long long lo, long long hi);
    Status read(const char *name, std::uint64_t &value);
    Status read(const char *name, float &value, double lo, double hi);
    Status read(const char *name, double &value, double lo, double hi);
    Status read(const char *name, bool &value);
    Status read(const char *name, std::string &value);
    /// Exactly `count` numbers in [lo, hi] separated by ','.
    Status read(const char *name, float *values, int count, double lo, double hi);
    Status read(const char *name, Rgb &value, double lo, double hi);
    Status read(const char *name, Vec3 &value);
    /// 1 to max_count integers in [lo, hi] separated by ','.
    Status read(const char *name, std::vector<int> &values, int max_count, long long lo, long long hi);
    /// One of `choices`; value receives its index.
    Status read_choice(const char *name, int &value, std::initializer_list<const char *> choices);

    /// The same reads for one description of an option set's fields (see OptionWriter): the
    /// first failure is kept and returned by finish().
    template <typename T, typename... Range>
    void field(const char *name, T &value, Range... range) {
        if (Status s = read(name, value, range...); s && !failure_) failure_ = s;
    }
    void choice(const char *name, int &value, std::initializer_list<const char *> choices) {
        if (Status s = read_choice(name, value, choices); s && !failure_) failure_ = s;
    }

    /// True when the option is present.
    bool has(const char *name) const;
    /// The first failed field(), else refuses the options no read asked for, listing the
    /// known ones.
    Status finish() const;
    const std::string &what() const { return what_; }

  private:
    const std::string *find(const char *name);
    Error error(const char *name, const std::string &allowed, const std::string &got) const;

    std::string what_;
    OptionItems items_;
    std::vector<bool> used_;
    std::vector<std::string> known_;
    Status failure_;
};

/// Writes an option set through the same description of its fields as OptionReader reads it
/// (ranges are ignored), so each set's names and defaults are written down once:
///   template <typename Fields> void describe(Fields &f, Settings &s) { f.field("samples", s.samples, 1, 64); }
class OptionWriter {
  public:
    template <typename... Range>
    void field(const char *name, const int &value, Range...) { add(name, std::to_string(value)); }
    void field(const char *name, const std::uint64_t &value) { add(name, std::to_string(value)); }
    template <typename... Range>
    void field(const char *name, const float &value, Range...) { add(name, format_number(value)); }
    template <typename... Range>
    void field(const char *name, const double &value, Range...) { add(name, format_number(value)); }
    void field(const char *name, const bool &value) { add(name, value ? "1" : "0"); }
    void field(const char *name, const std::string &value) { add(name, value); }
    template <typename... Range>
    void field(const char *name, float *const &values, int count, Range...) {
        std::string text;
        for (int k = 0; k < count; ++k) text += (k ? "," : "") + format_number(values[k]);
        add(name, text);
    }
    template <typename... Range>
    void field(const char *name, const Rgb &value, Range...) {
        add(name, format_number(value.r) + "," + format_number(value.g) + "," + format_number(value.b));
    }
    void field(const char *name, const Vec3 &value) {
        add(name, format_number(value.x) + "," + format_number(value.y) + "," + format_number(value.z));
    }
    template <typename... Range>
    void field(const char *name, const std::vector<int> &values, Range...) {
        std::string text;
        for (std::size_t k = 0; k < values.size(); ++k) text += (k ? "," : "") + std::to_string(values[k]);
        add(name, text);
    }
    void choice(const char *name, const int &value, std::initializer_list<const char *> choices) {
        add(name, value >= 0 && std::size_t(value) < choices.size() ? choices.begin()[value] : "?");
    }
    std::string str() const { return format_options(items_); }

  private:
    void add(const char *name, std::string value) { items_.emplace_back(name, std::move(value)); }
    OptionItems items_;
};

}  // namespace hairis
