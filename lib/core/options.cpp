#include "core/options.h"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <algorithm>

namespace hairis {

namespace {

std::string trim(const std::string &s) {
    const std::size_t a = s.find_first_not_of(" \t\r\n");
    if (a == std::string::npos) return "";
    return s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
}

// strtod over the whole text (spaces around allowed); false for anything else or non-finite.
bool parse_double(const std::string &text, double &out) {
    const std::string t = trim(text);
    if (t.empty()) return false;
    char *end = nullptr;
    errno = 0;
    const double v = std::strtod(t.c_str(), &end);
    if (end != t.c_str() + t.size() || !std::isfinite(v)) return false;
    out = v;
    return true;
}

bool parse_integer(const std::string &text, long long &out) {
    const std::string t = trim(text);
    if (t.empty()) return false;
    char *end = nullptr;
    errno = 0;
    const long long v = std::strtoll(t.c_str(), &end, 10);
    if (end != t.c_str() + t.size() || errno == ERANGE) return false;
    out = v;
    return true;
}

std::vector<std::string> split(const std::string &text, char separator) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    while (true) {
        const std::size_t at = text.find(separator, start);
        parts.push_back(text.substr(start, at == std::string::npos ? std::string::npos : at - start));
        if (at == std::string::npos) break;
        start = at + 1;
    }
    return parts;
}

std::string range_text(double lo, double hi) {
    return "[" + format_number(lo) + ", " + format_number(hi) + "]";
}

}  // namespace

Expected<OptionItems> parse_options(const std::string &text, const std::string &what) {
    OptionItems items;
    for (const std::string &raw : split(text, ';')) {
        const std::string item = trim(raw);
        if (item.empty()) continue;
        const std::size_t eq = item.find('=');
        if (eq == std::string::npos)
            return Error{what + ": \"" + item + "\" is not name=value"};
        std::string name = trim(item.substr(0, eq)), value = trim(item.substr(eq + 1));
        if (name.empty()) return Error{what + ": \"" + item + "\" has no name before '='"};
        for (const auto &existing : items)
            if (existing.first == name) return Error{what + ": " + name + " is given twice"};
        items.emplace_back(std::move(name), std::move(value));
    }
    return items;
}

std::string format_options(const OptionItems &items) {
    std::string out;
    for (const auto &[name, value] : items) {
        if (!out.empty()) out += ';';
        out += name + "=" + value;
    }
    return out;
}

std::string format_number(float value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", double(value));
    return text;
}

std::string format_number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", value);
    return text;
}

Expected<OptionReader> OptionReader::parse(const std::string &text, const std::string &what) {
    Expected<OptionItems> items = parse_options(text, what);
    if (!items) return items.error();
    OptionReader reader;
    reader.what_ = what;
    reader.items_ = std::move(items).value();
    reader.used_.assign(reader.items_.size(), false);
    return reader;
}

const std::string *OptionReader::find(const char *name) {
    known_.emplace_back(name);
    for (std::size_t i = 0; i < items_.size(); ++i)
        if (items_[i].first == name) {
            used_[i] = true;
            return &items_[i].second;
        }
    return nullptr;
}

bool OptionReader::has(const char *name) const {
    for (const auto &item : items_)
        if (item.first == name) return true;
    return false;
}

Error OptionReader::error(const char *name, const std::string &allowed, const std::string &got) const {
    return Error{what_ + ": " + name + " must be " + allowed + " (got \"" + got + "\")"};
}

Status OptionReader::read(const char *name, int &value, long long lo, long long hi) {
    const std::string *text = find(name);
    if (!text) return std::nullopt;
    long long v = 0;
    if (!parse_integer(*text, v) || v < lo || v > hi)
        return error(name, "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", *text);
    value = int(v);
    return std::nullopt;
}

Status OptionReader::read(const char *name, std::uint64_t &value) {
    const std::string *text = find(name);
    if (!text) return std::nullopt;
    const std::string t = trim(*text);
    char *end = nullptr;
    errno = 0;
    const unsigned long long v = std::strtoull(t.c_str(), &end, 10);
    if (t.empty() || t[0] == '-' || end != t.c_str() + t.size() || errno == ERANGE)
        return error(name, "an integer in [0, 2^64 - 1]", *text);
    value = std::uint64_t(v);
    return std::nullopt;
}

Status OptionReader::read(const char *name, double &value, double lo, double hi) {
    const std::string *text = find(name);
    if (!text) return std::nullopt;
    double v = 0;
    if (!parse_double(*text, v) || v < lo || v > hi) return error(name, "a finite number in " + range_text(lo, hi), *text);
    value = v;
    return std::nullopt;
}

Status OptionReader::read(const char *name, float &value, double lo, double hi) {
    double v = value;
    if (Status s = read(name, v, lo, hi)) return s;
    value = float(v);
    return std::nullopt;
}

Status OptionReader::read(const char *name, bool &value) {
    const std::string *text = find(name);
    if (!text) return std::nullopt;
    if (*text == "1" || *text == "true") value = true;
    else if (*text == "0" || *text == "false") value = false;
    else return error(name, "0, 1, true or false", *text);
    return std::nullopt;
}

Status OptionReader::read(const char *name, std::string &value) {
    if (const std::string *text = find(name)) value = *text;
    return std::nullopt;
}

Status OptionReader::read(const char *name, float *values, int count, double lo, double hi) {
    const std::string *text = find(name);
    if (!text) return std::nullopt;
    const std::vector<std::string> parts = split(*text, ',');
    const std::string allowed = std::to_string(count) + " finite numbers in " + range_text(lo, hi) + " separated by ','";
    if (int(parts.size()) != count) return error(name, allowed, *text);
    std::vector<float> parsed(std::size_t(count), 0.0f);
    for (int k = 0; k < count; ++k) {
        double v = 0;
        if (!parse_double(parts[std::size_t(k)], v) || v < lo || v > hi) return error(name, allowed, *text);
        parsed[std::size_t(k)] = float(v);
    }
    std::copy(parsed.begin(), parsed.end(), values);
    return std::nullopt;
}

Status OptionReader::read(const char *name, Rgb &value, double lo, double hi) {
    float c[3] = {value.r, value.g, value.b};
    if (Status s = read(name, c, 3, lo, hi)) return s;
    value = Rgb(c[0], c[1], c[2]);
    return std::nullopt;
}

Status OptionReader::read(const char *name, Vec3 &value) {
    const double big = double(std::numeric_limits<float>::max());
    float c[3] = {value.x, value.y, value.z};
    if (Status s = read(name, c, 3, -big, big)) return s;
    value = Vec3(c[0], c[1], c[2]);
    return std::nullopt;
}

Status OptionReader::read(const char *name, std::vector<int> &values, int max_count, long long lo, long long hi) {
    const std::string *text = find(name);
    if (!text) return std::nullopt;
    const std::vector<std::string> parts = split(*text, ',');
    const std::string allowed = "1 to " + std::to_string(max_count) + " integers in [" + std::to_string(lo) + ", " +
                                std::to_string(hi) + "] separated by ','";
    if (parts.empty() || int(parts.size()) > max_count) return error(name, allowed, *text);
    std::vector<int> parsed;
    for (const std::string &part : parts) {
        long long v = 0;
        if (!parse_integer(part, v) || v < lo || v > hi) return error(name, allowed, *text);
        parsed.push_back(int(v));
    }
    values = std::move(parsed);
    return std::nullopt;
}

Status OptionReader::read_choice(const char *name, int &value, std::initializer_list<const char *> choices) {
    const std::string *text = find(name);
    if (!text) return std::nullopt;
    int index = 0;
    std::string allowed;
    for (const char *choice : choices) {
        if (*text == choice) {
            value = index;
            return std::nullopt;
        }
        allowed += std::string(index ? ", " : "one of ") + choice;
        ++index;
    }
    return error(name, allowed, *text);
}

Status OptionReader::finish() const {
    if (failure_) return failure_;
    for (std::size_t i = 0; i < items_.size(); ++i) {
        if (used_[i]) continue;
        std::string known;
        for (const std::string &k : known_)
            if (known.find(" " + k + ",") == std::string::npos) known += " " + k + ",";
        if (!known.empty()) known.pop_back();
        return Error{what_ + ": unknown option \"" + items_[i].first + "\" (known:" + known + ")"};
    }
    return std::nullopt;
}

}  // namespace hairis
