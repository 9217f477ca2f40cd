#include "sampling/table_set.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/math.h"
#include "sampling/huang_table.h"

namespace hairis {

namespace {

Error file_error(const std::string &what) { return Error{"hairis table: " + what, ErrorKind::InvalidTable}; }

}  // namespace

std::string canonical_parameters(const std::vector<std::pair<std::string, double>> &params) {
    std::string out;
    char value[64];
    for (const auto &[name, v] : params) {
        std::snprintf(value, sizeof value, "%.9g", v);
        if (!out.empty()) out += ';';
        out += name + "=" + value;
    }
    return out;
}

Status TableSet::validate() const {
    for (const auto &[name, value] : parameters)
        if (name.empty() || name.find_first_of("=;") != std::string::npos || !std::isfinite(value))
            return file_error("parameter \"" + name + "\" must have a plain name and a finite value");
    if (model == "huang2022") return validate_huang();
    if (huang) return file_error("a Huang part is only for huang2022 tables (got " + model + ")");
    if (model != "chiang2016" && model != "marschner2003")
        return file_error("model must be \"chiang2016\", \"marschner2003\" or \"huang2022\" (got \"" + model + "\")");
    if (source != "exact" && source != "gaussian")
        return file_error("source must be \"exact\" or \"gaussian\" (got \"" + source + "\")");
    if (Status s = first_error(resolution().validate(),
                               check::count_in_range("n_h count", (long long)n_h_values.size(), 0,
                                                     std::min(phi_count, kMaxStrandCounts))))
        return file_error(s->message);
    if (Status s = validate_axes()) return s;
    const long long cells = resolution().cells();
    if (direct.size() != size_t(cells))
        return file_error("direct table holds " + std::to_string(direct.size()) + " values; the grid needs " +
                          std::to_string(cells));
    for (size_t n = 0; n < direct.size(); ++n)
        if (!std::isfinite(direct[n]) || direct[n] < 0.0f)
            return file_error("direct table value " + std::to_string(n) + " is negative, NaN or infinite");
    if (Status s = validate_multiple()) return s;
    if (near_field) {
        if (model != "chiang2016") return file_error("a near-field part is only for chiang2016 tables (got " + model + ")");
        if (Status s = near_field->validate()) return file_error(s->message);
    }
    return std::nullopt;
}

Status TableSet::validate_axes() const {
    for (int r = 0; r < theta_r_count(); ++r) {
        const float t = theta_r_nodes[r];
        if (!std::isfinite(t) || std::fabs(t) > float(kHalfPi) + 1e-6f)
            return file_error("theta_r node " + std::to_string(r) + " must be finite and in [-pi/2, pi/2]");
        if (r > 0 && !(t > theta_r_nodes[r - 1]))
            return file_error("theta_r nodes must be strictly increasing (node " + std::to_string(r) + ")");
    }
    for (size_t k = 0; k < n_h_values.size(); ++k) {
        if (n_h_values[k] < 1 || n_h_values[k] > 1024)
            return file_error("n_h values must be in [1, 1024] (got " + std::to_string(n_h_values[k]) + ")");
        if (k > 0 && n_h_values[k] <= n_h_values[k - 1])
            return file_error("n_h values must be strictly increasing");
    }
    return std::nullopt;
}

Status TableSet::validate_multiple() const {
    const size_t multiple_size = size_t(theta_r_count()) * n_h_values.size() * theta_i_count;
    if (multiple.size() != multiple_size)
        return file_error("multiple table holds " + std::to_string(multiple.size()) +
                          " values; the grid needs " + std::to_string(multiple_size));
    for (size_t n = 0; n < multiple.size(); ++n)
        if (!std::isfinite(multiple[n]) || multiple[n] < 0.0f)
            return file_error("multiple table value " + std::to_string(n) + " is negative, NaN or infinite");
    return std::nullopt;
}

Status TableSet::validate_huang() const {
    if (!huang) return file_error("huang2022 tables need their Huang part (there is none)");
    if (source != "exact") return file_error("huang2022 tables have source \"exact\" (got \"" + source + "\")");
    if (phi_count != 0 || !direct.empty() || near_field)
        return file_error("huang2022 tables hold the Huang part and, optionally, a multiple-scattering part (no "
                          "direct far-field or near-field part)");
    if (has_multiple()) {
        if (Status s = first_error(
                check::count_in_range("theta_r_count", theta_r_count(), 1, kMaxThetaRNodes),
                check::count_in_range("theta_i_count", theta_i_count, 2, kMaxTableAxisCells),
                check::count_in_range("n_h count", (long long)n_h_values.size(), 1, kMaxStrandCounts)))
            return file_error(s->message);
        if (Status s = validate_axes()) return s;
        if (Status s = validate_multiple()) return s;
    } else if (theta_i_count != 0 || !n_h_values.empty() || !multiple.empty())
        return file_error("a huang2022 multiple-scattering part needs its theta_r nodes, theta_i cells, n_h values "
                          "and values (some are missing)");
    if (Status s = huang->validate()) return file_error(s->message);
    // Every parameter of a Huang fiber, by name and in order (the staleness check compares them).
    std::string names, expected;
    for (const auto &entry : parameters) names += (names.empty() ? "" : ",") + entry.first;
    for (const auto &entry : huang_parameters(HuangParams{})) expected += (expected.empty() ? "" : ",") + entry.first;
    if (names != expected)
        return file_error("huang2022 tables record the parameters " + expected + " (got \"" + names + "\")");
    if (canonical_parameters(huang->parameters) != canonical_parameters(parameters))
        return file_error("the Huang part was baked for \"" + canonical_parameters(huang->parameters) +
                          "\", but the tables record \"" + canonical_parameters(parameters) + "\"");
    return std::nullopt;
}

}  // namespace hairis
