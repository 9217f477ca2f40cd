#include "sampling/huang_absorption_table.h"

#include <algorithm>
#include <cmath>

namespace hairis {

std::vector<float> huang_absorption_nodes(int count, double first, double last) {
    std::vector<float> nodes;
    const double a = std::log(first + kHuangAbsorptionShift), b = std::log(last + kHuangAbsorptionShift);
    for (int k = 0; k < count; ++k)
        nodes.push_back(float(std::exp(a + (b - a) * k / std::max(count - 1, 1)) - kHuangAbsorptionShift));
    return nodes;
}

Expected<HuangAbsorptionTable> HuangAbsorptionTable::create(const HuangTableSet &set) {
    if (Status s = set.validate()) return *s;
    if (!set.has_absorption())
        return Error{"the Huang table set has no absorption part (bake it with the absorption part)"};
    HuangAbsorptionTable t;
    t.grid_ = HuangFGrid(set);
    t.nodes_ = set.absorption_nodes;
    for (float node : t.nodes_) t.axis_.push_back(std::log(double(node) + kHuangAbsorptionShift));
    t.values_ = set.absorption;
    return t;
}

bool HuangAbsorptionTable::reads(const std::array<double, 3> &strand, const std::array<double, 3> &fiber) const {
    const double first = nodes_.front();
    for (std::size_t c = 0; c < 3; ++c) {
        if (!(std::isfinite(strand[c]) && std::isfinite(fiber[c]))) return false;
        if (strand[c] != fiber[c] && !(strand[c] >= first && fiber[c] >= first)) return false;
    }
    return true;
}

HuangAbsorptionTable::Place HuangAbsorptionTable::place(double sigma) const {
    const int n = int(axis_.size());
    const double x = std::log(std::max(sigma, double(nodes_.front())) + kHuangAbsorptionShift);
    int j = 0;
    while (j + 2 < n && x >= axis_[std::size_t(j + 1)]) ++j;
    return {x, j};
}

HuangAbsorptionTable::Nodes HuangAbsorptionTable::nodes_read(Place p, Nodes nodes) const {
    const int n = int(axis_.size());
    return {std::min(nodes.first, std::max(p.j - 1, 0)), std::max(nodes.last, std::min(p.j + 2, n - 1))};
}

void HuangAbsorptionTable::gather(const HuangGridRead &r, Nodes nodes, float *g) const {
    // Only the nodes interpolation reads: each of a read's cells holds every node, and each
    // channel's interpolation reads at most four of them.
    const std::size_t k_count = nodes_.size(), first = std::size_t(nodes.first), last = std::size_t(nodes.last);
    std::fill(g + first, g + last + 1, 0.0f);
    for (int n = 0; n < r.count; ++n) {
        const float *v = values_.data() + k_count * std::size_t(r.cell[std::size_t(n)]);
        const float w = r.weight[std::size_t(n)];
        for (std::size_t k = first; k <= last; ++k) g[k] += w * v[k];
    }
    // The cubic overshoots a little next to sharp features; f is never negative.
    for (std::size_t k = first; k <= last; ++k) g[k] = std::max(g[k], 0.0f);
}

double HuangAbsorptionTable::interpolate(const float *g, Place p) const {
    const int n = int(axis_.size());
    const double x = p.x;
    const int j = p.j;
    const double x0 = axis_[std::size_t(j)], x1 = axis_[std::size_t(j + 1)];
    const double g0 = g[j], g1 = g[j + 1];
    if (x > x1) {  // beyond the last node: log-linear, never rising (more absorption, less light)
        if (!(g0 > 0.0 && g1 > 0.0)) return 0.0;
        const double slope = std::min(std::log(g1 / g0), 0.0);
        return slope == 0.0 ? g1 : g1 * std::exp((x - x1) / (x1 - x0) * slope);
    }
    const double t = (x - x0) / (x1 - x0);
    // The outer neighbours; at the ends a reflected node with a linearly continued value.
    const double xa = j > 0 ? axis_[std::size_t(j - 1)] : 2.0 * x0 - x1;
    const double xb = j + 2 < n ? axis_[std::size_t(j + 2)] : 2.0 * x1 - x0;
    const double ga = j > 0 ? g[j - 1] : 0.0, gb = j + 2 < n ? g[j + 2] : 0.0;
    const bool positive = g0 > 0.0 && g1 > 0.0 && (j == 0 || ga > 0.0) && (j + 2 >= n || gb > 0.0);
    if (!positive) return g0 + (g1 - g0) * t;
    const double y0 = std::log(g0), y1 = std::log(g1);
    const double ya = j > 0 ? std::log(ga) : 2.0 * y0 - y1, yb = j + 2 < n ? std::log(gb) : 2.0 * y1 - y0;
    const double xs[4] = {xa, x0, x1, xb};
    const std::array<float, 4> w = catmull_rom_weights(xs, t);
    return std::exp(w[0] * ya + w[1] * y0 + w[2] * y1 + w[3] * yb);
}

Rgb HuangAbsorptionTable::f_cos(const HuangTableQuery &q, Vec3 wi, const std::array<double, 3> &sigma) const {
    const Place p[3] = {place(sigma[0]), place(sigma[1]), place(sigma[2])};
    Nodes nodes{int(nodes_.size()), -1};  // none
    for (const Place &c : p) nodes = nodes_read(c, nodes);
    float g[kMaxHuangAbsorptionNodes];
    gather(grid_.read(q, wi), nodes, g);
    return {float(interpolate(g, p[0])), float(interpolate(g, p[1])), float(interpolate(g, p[2]))};
}

Rgb HuangAbsorptionTable::difference(const HuangGridRead &read, const std::array<double, 3> &strand,
                                     const std::array<double, 3> &fiber) const {
    // Each absorption is placed on the node axis once, for the nodes to read and to interpolate.
    Place to[3] = {}, from[3] = {};
    Nodes nodes{int(nodes_.size()), -1};  // none
    for (std::size_t c = 0; c < 3; ++c) {
        if (strand[c] == fiber[c]) continue;
        to[c] = place(strand[c]);
        from[c] = place(fiber[c]);
        nodes = nodes_read(from[c], nodes_read(to[c], nodes));
    }
    if (nodes.first > nodes.last) return {0.0f, 0.0f, 0.0f};
    float g[kMaxHuangAbsorptionNodes];
    gather(read, nodes, g);
    float out[3];
    for (std::size_t c = 0; c < 3; ++c)
        out[c] = strand[c] == fiber[c] ? 0.0f : float(interpolate(g, to[c]) - interpolate(g, from[c]));
    return {out[0], out[1], out[2]};
}

}  // namespace hairis
