#include "sampling/huang_table.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/frame.h"
#include "core/options.h"
#include "sampling/huang_absorption_table.h"
#include "sampling/huang_f_table.h"
#include "sampling/table_set.h"

namespace hairis {

namespace {

constexpr const char *kOwner = "HuangTable";

Error prefixed(const Error &e) { return Error{std::string(kOwner) + ": " + e.message, e.kind}; }

// Strictly increasing nodes within [lo, hi], named `name`[k] in errors.
Status check_nodes(const char *name, const std::vector<float> &nodes, long long max_count, double lo, double hi) {
    if (Status s = check::count_in_range((std::string(name) + " count").c_str(), (long long)nodes.size(), 1, max_count))
        return s;
    for (std::size_t k = 0; k < nodes.size(); ++k) {
        const std::string entry = std::string(name) + "[" + std::to_string(k) + "]";
        if (Status s = check::in_range(entry.c_str(), nodes[k], lo, hi)) return s;
        if (k > 0 && !(nodes[k] > nodes[k - 1]))
            return Error{std::string(name) + " must be strictly increasing (" + entry + " = " + std::to_string(nodes[k]) +
                         " <= " + name + "[" + std::to_string(k - 1) + "] = " + std::to_string(nodes[k - 1]) + ")"};
    }
    return std::nullopt;
}

// u clamped to [0, 1), NaN to 0.
float unit(float u) {
    if (!(u > 0.0f)) return 0.0f;
    return u < kOneMinusEpsilon ? u : kOneMinusEpsilon;
}

// sin(slope·d)/sin(d) for d ≥ 0: cos of the warped angle over cos of the angle, both d from
// the same pole.
double pole_ratio(double slope, double d) { return d > 1e-12 ? std::sin(slope * d) / std::sin(d) : slope; }

}  // namespace

ThetaWarp ThetaWarp::between(double theta_o, double theta_node) {
    // Both strictly inside the poles, so that both slopes are positive.
    const double inside = kHalfPi * (1.0 - 1e-9);
    ThetaWarp w;
    w.anchor = -std::clamp(theta_o, -inside, inside);
    w.node_anchor = -std::clamp(theta_node, -inside, inside);
    w.below = (w.node_anchor + kHalfPi) / (w.anchor + kHalfPi);
    w.above = (kHalfPi - w.node_anchor) / (kHalfPi - w.anchor);
    return w;
}

double ThetaWarp::jacobian(double theta_i) const {
    return theta_i < anchor ? below * pole_ratio(below, theta_i + kHalfPi)
                            : above * pole_ratio(above, kHalfPi - theta_i);
}

long long HuangTable::bytes_needed(long long theta_o_count, long long phi_o_count, long long theta_i_count,
                                   long long phi_count) {
    // Per slice set (one φ_o node) what DirectTable holds: values, conditional CDFs over φ per
    // θ_i row, marginal CDFs over θ_i per θ_o node, and a row factor per row.
    const long long rows = theta_o_count * theta_i_count;
    const long long per_node = rows * phi_count * (long long)sizeof(float) + DiscreteCdfs::bytes_needed(rows, phi_count) +
                               DiscreteCdfs::bytes_needed(theta_o_count, theta_i_count) +
                               rows * (long long)sizeof(float);
    return phi_o_count * per_node;
}

std::size_t HuangTable::memory_bytes() const {
    return std::size_t(bytes_needed((long long)theta_o_nodes_.size(), (long long)phi_o_nodes_.size(), theta_i_count(),
                                    phi_count()));
}

Status HuangTable::check(const std::vector<float> &theta_o_nodes, const std::vector<float> &phi_o_nodes, int theta_i_count,
                         int phi_count, const std::vector<float> &values) {
    const double half_pi = double(float(kHalfPi));  // π/2 rounded up to float is allowed
    if (Status s = first_error(check_nodes("theta_o_nodes", theta_o_nodes, kMaxThetaRNodes, -half_pi, half_pi),
                               check_nodes("phi_o_nodes", phi_o_nodes, kMaxPhiONodes, 0.0, half_pi),
                               check::count_in_range("theta_i_count", theta_i_count, 1, kMaxTableAxisCells),
                               check::count_in_range("phi_count", phi_count, 1, kMaxTableAxisCells)))
        return prefixed(*s);
    const long long n_r = (long long)theta_o_nodes.size(), n_q = (long long)phi_o_nodes.size();
    const long long slice = (long long)theta_i_count * phi_count;
    const long long cells = n_q * n_r * slice;
    const long long bytes = bytes_needed(n_r, n_q, theta_i_count, phi_count);
    if (cells > kMaxTableCells || bytes > kMaxSamplingTableBytes)
        return Error{std::string(kOwner) + ": " + std::to_string(n_q) + " phi_o nodes × " + std::to_string(n_r) +
                     " theta_o nodes × " + std::to_string(theta_i_count) + " × " + std::to_string(phi_count) +
                     " cells = " + std::to_string(cells) + " cells and " + std::to_string(bytes) +
                     " bytes; at most " + std::to_string(kMaxTableCells) + " cells and " +
                     std::to_string(kMaxSamplingTableBytes) + " bytes are allowed"};
    if ((long long)values.size() != cells)
        return Error{std::string(kOwner) +
                     ": values must hold phi_o node count × theta_o node count × theta_i_count × phi_count = " +
                     std::to_string(cells) + " entries (got " + std::to_string(values.size()) + ")"};
    for (std::size_t n = 0; n < values.size(); ++n) {
        if (std::isfinite(values[n]) && values[n] >= 0.0f) continue;
        const std::size_t j = n % std::size_t(phi_count), i = (n / std::size_t(phi_count)) % std::size_t(theta_i_count),
                          r = (n / std::size_t(slice)) % std::size_t(n_r), q = n / (std::size_t(slice) * std::size_t(n_r));
        const std::string name = "values[phi_o node " + std::to_string(q) + ", theta_o node " + std::to_string(r) +
                                 ", theta_i cell " + std::to_string(i) + ", phi cell " + std::to_string(j) + "]";
        return prefixed(*check::non_negative(name.c_str(), double(values[n])));
    }
    return std::nullopt;
}

Expected<HuangTable> HuangTable::create(const std::vector<float> &theta_o_nodes, const std::vector<float> &phi_o_nodes,
                                        int theta_i_count, int phi_count, const std::vector<float> &values) {
    if (Status s = check(theta_o_nodes, phi_o_nodes, theta_i_count, phi_count, values)) return *s;
    const long long n_r = (long long)theta_o_nodes.size(), n_q = (long long)phi_o_nodes.size();
    const long long slice = (long long)theta_i_count * phi_count;
    HuangTable t;
    t.theta_o_nodes_ = theta_o_nodes;
    t.phi_o_nodes_ = phi_o_nodes;
    Expected<ThetaRNodes> phi_nodes = ThetaRNodes::create(phi_o_nodes);  // already checked: within [0, π/2]
    if (!phi_nodes) return prefixed(phi_nodes.error());
    t.phi_nodes_ = std::move(phi_nodes).value();
    const double outer = std::max(std::fabs(double(theta_o_nodes.front())), std::fabs(double(theta_o_nodes.back())));
    t.theta_limit_ = 0.5 * (std::min(outer, kHalfPi) + kHalfPi);
    if (!(t.theta_limit_ < kHalfPi)) t.theta_limit_ = std::nextafter(kHalfPi, 0.0);
    t.slices_.reserve(std::size_t(n_q));
    const std::size_t block = std::size_t(n_r) * std::size_t(slice);
    for (std::size_t q = 0; q < std::size_t(n_q); ++q) {
        const std::vector<float> node_values(values.begin() + std::ptrdiff_t(q * block),
                                             values.begin() + std::ptrdiff_t((q + 1) * block));
        Expected<DirectTable> d = DirectTable::create(theta_o_nodes, theta_i_count, phi_count, node_values);
        if (!d) return Error{std::string(kOwner) + ": phi_o node " + std::to_string(q) + ": " + d.error().message};
        t.slices_.push_back(std::move(d).value());
    }
    return t;
}

HuangTableQuery HuangTable::locate(Vec3 wo) const {
    HuangTableQuery q;
    // One φ_o node (circular): no fold, the view's own azimuth.
    const bool fold = phi_o_nodes_.size() > 1;
    q.sign_y = fold && wo.y < 0.0f ? -1.0f : 1.0f;
    q.sign_z = fold && wo.z < 0.0f ? -1.0f : 1.0f;
    const float y = q.sign_y * wo.y, z = q.sign_z * wo.z, r = std::sqrt(y * y + z * z);
    if (r > 0.0f) {
        q.cos_phi_o = y / r;
        q.sin_phi_o = z / r;
    }
    const float theta_o = safe_asin(wo.x);
    q.theta = slices_.front().locate(theta_o);
    q.phi = phi_nodes_.locate(std::atan2(q.sin_phi_o, q.cos_phi_o));
    const std::vector<float> &nodes = theta_o_nodes_;
    const double anchor_theta = std::clamp(double(theta_o), -theta_limit_, theta_limit_);
    q.warp[0] = ThetaWarp::between(anchor_theta, nodes[std::size_t(q.theta.lower)]);
    q.warp[1] = nodes.size() > 1 ? ThetaWarp::between(anchor_theta, nodes[std::size_t(q.theta.lower) + 1]) : q.warp[0];
    return q;
}

namespace {

// θ_o node k (0 lower, 1 upper) of a blend, as a blend that selects it alone.
NodeBlend only(NodeBlend b, int k) { return {b.lower, k ? 1.0f : 0.0f}; }

}  // namespace

float HuangTable::slice_pdf(const HuangTableQuery &q, NodeBlend theta_node, float sin_theta_i, float phi) const {
    // (1 − s)·pdf(q) + s·pdf(q + 1), skipping the node without weight (its term is exactly 0).
    const NodeBlend b = q.phi;
    auto node = [&](int k) { return slices_[std::size_t(k)].pdf_sin(theta_node, sin_theta_i, phi); };
    if (b.t <= 0.0f) return node(b.lower);
    if (b.t >= 1.0f) return node(b.lower + 1);
    return (1.0f - b.t) * node(b.lower) + b.t * node(b.lower + 1);
}

std::optional<DirectionSample> HuangTable::sample(const HuangTableQuery &q, float u0, float u1, float u2) const {
    // u2 < s picks the upper φ_o node; its remainder, rescaled to [0, 1), picks the θ_o node.
    const float u = unit(u2), s = q.phi.t;
    const bool upper_phi = u < s;
    const float rest = unit(upper_phi ? u / s : (u - s) / (1.0f - s)), t = q.theta.t;
    const int k = rest < t ? 1 : 0;
    const TableSample ts = slices_[std::size_t(q.phi.lower + (upper_phi ? 1 : 0))].sample(only(q.theta, k), u0, u1, 0.0f);
    // Back from the node's θ_i axis; off the fiber axis like every table sample.
    const double theta_i = q.warp[k].from_node(std::asin(std::clamp(double(ts.sin_theta_i), -1.0, 1.0)));
    const float sin_theta_i = off_axis(float(std::sin(theta_i)));
    const float cos_theta_i = std::sqrt((1.0f - sin_theta_i) * (1.0f + sin_theta_i));
    const float c = q.cos_phi_o * ts.cos_phi - q.sin_phi_o * ts.sin_phi, sn = q.sin_phi_o * ts.cos_phi + q.cos_phi_o * ts.sin_phi;
    const Vec3 wi{sin_theta_i, q.sign_y * cos_theta_i * c, q.sign_z * cos_theta_i * sn};
    const float density = pdf(q, wi);
    if (!(density > 0.0f)) return std::nullopt;
    return DirectionSample{wi, density};
}

float HuangTable::pdf(const HuangTableQuery &q, Vec3 wi) const {
    if (!(wi.x >= -1.0f && wi.x <= 1.0f)) return 0.0f;
    const float y = q.sign_y * wi.y, z = q.sign_z * wi.z;
    const float phi = std::atan2(z * q.cos_phi_o - y * q.sin_phi_o, y * q.cos_phi_o + z * q.sin_phi_o);
    const double theta_i = std::asin(double(wi.x));
    // (1 − t)·pdf(lower) + t·pdf(upper), each through its warp.
    auto node = [&](int k) {
        const ThetaWarp &w = q.warp[k];
        const float density = slice_pdf(q, only(q.theta, k), float(std::sin(w.to_node(theta_i))), phi);
        return density > 0.0f ? float(double(density) * w.jacobian(theta_i)) : 0.0f;
    };
    const float t = q.theta.t;
    if (t <= 0.0f) return node(0);
    if (t >= 1.0f) return node(1);
    return (1.0f - t) * node(0) + t * node(1);
}

std::vector<std::pair<std::string, double>> huang_parameters(const HuangParams &p) {
    return {{"sigma_a_r", p.sigma_a.r},
            {"sigma_a_g", p.sigma_a.g},
            {"sigma_a_b", p.sigma_a.b},
            {"roughness", p.roughness},
            {"ior", p.ior},
            {"offset", p.offset},
            {"aspect_ratio", p.aspect_ratio},
            {"reflection", p.reflection},
            {"transmission", p.transmission},
            {"secondary_reflection", p.secondary_reflection}};
}

Status check_huang_absorption_nodes(const std::vector<float> &nodes, const std::string &name) {
    const int k = int(nodes.size());
    if (k < 2 || k > kMaxHuangAbsorptionNodes)
        return Error{name + " must hold 2 to " + std::to_string(kMaxHuangAbsorptionNodes) + " absorption nodes (got " +
                     std::to_string(k) + ")"};
    for (int a = 0; a < k; ++a) {
        const float node = nodes[std::size_t(a)];
        if (!(node > 0.0f && node <= kMaxHuangAbsorption) || (a > 0 && !(node > nodes[std::size_t(a - 1)])))
            return Error{name + "[" + std::to_string(a) + "] (" + format_number(node) + ") must be in (0, " +
                         std::to_string(int(kMaxHuangAbsorption)) + "] and greater than the node before"};
    }
    return std::nullopt;
}

Status HuangTableSet::validate() const {
    if (model != "huang2022") return Error{"a Huang table must have model \"huang2022\" (got \"" + model + "\")"};
    for (const auto &[name, value] : parameters)
        if (name.empty() || name.find_first_of("=;") != std::string::npos || !std::isfinite(value))
            return Error{"Huang table parameter \"" + name + "\" must have a plain name and a finite value"};
    if (Status s = HuangTable::check(theta_o_nodes, phi_o_nodes, theta_i_count, phi_count, values)) return s;
    if (Status s = check::count_in_range("the Huang table's f_refinement", f_refinement, 1, kMaxHuangFRefinement))
        return s;
    if (!f.empty() && f.size() != 3 * values.size())
        return Error{"the Huang table's f part must hold 3 values (RGB) per cell, " + std::to_string(3 * values.size()) +
                     " in all (got " + std::to_string(f.size()) + ")"};
    for (std::size_t n = 0; n < f.size(); ++n)
        if (!(std::isfinite(f[n]) && f[n] >= 0.0f))
            return Error{"the Huang table's f part: entry " + std::to_string(n) + " (cell " + std::to_string(n / 3) +
                         ", channel " + std::to_string(n % 3) + ") must be finite and >= 0 (got " +
                         std::to_string(f[n]) + ")"};
    if (absorption_nodes.empty()) {
        if (!absorption.empty()) return Error{"the Huang table's absorption part has values but no absorption nodes"};
        return std::nullopt;
    }
    if (Status s = check_huang_absorption_nodes(absorption_nodes, "the Huang table's absorption_nodes")) return s;
    const int k = absorption_count();
    if (f.empty()) return Error{"the Huang table's absorption part needs the f part beside it"};
    if (absorption.size() != std::size_t(k) * values.size())
        return Error{"the Huang table's absorption part must hold " + std::to_string(k) + " values per cell, " +
                     std::to_string(std::size_t(k) * values.size()) + " in all (got " +
                     std::to_string(absorption.size()) + ")"};
    for (std::size_t n = 0; n < absorption.size(); ++n)
        if (!(std::isfinite(absorption[n]) && absorption[n] >= 0.0f))
            return Error{"the Huang table's absorption part: entry " + std::to_string(n) + " (cell " +
                         std::to_string(n / std::size_t(k)) + ", node " + std::to_string(n % std::size_t(k)) +
                         ") must be finite and >= 0 (got " + format_number(absorption[n]) + ")"};
    return std::nullopt;
}

Expected<HuangSamplingTable> HuangSamplingTable::from(const HuangTableSet &set) {
    if (set.model != "huang2022")
        return Error{"a Huang table must have model \"huang2022\" (got \"" + set.model + "\")", ErrorKind::InvalidTable};
    Expected<HuangTable> t =
        HuangTable::create(set.theta_o_nodes, set.phi_o_nodes, set.theta_i_count, set.phi_count, set.values);
    if (!t) return Error{t.error().message, ErrorKind::InvalidTable};
    HuangSamplingTable out{std::make_shared<const HuangTable>(std::move(t).value()), nullptr, nullptr,
                           canonical_parameters(set.parameters)};
    if (set.has_f()) {
        Expected<HuangFTable> f = HuangFTable::create(set);
        if (!f) return Error{f.error().message, ErrorKind::InvalidTable};
        out.f = std::make_shared<const HuangFTable>(std::move(f).value());
    }
    if (set.has_absorption()) {
        Expected<HuangAbsorptionTable> a = HuangAbsorptionTable::create(set);
        if (!a) return Error{a.error().message, ErrorKind::InvalidTable};
        out.absorption = std::make_shared<const HuangAbsorptionTable>(std::move(a).value());
    }
    return out;
}

}  // namespace hairis
