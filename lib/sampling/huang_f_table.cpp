#include "sampling/huang_f_table.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace hairis {

std::vector<double> huang_sin_theta_points(int theta_i_count) {
    std::vector<double> points(std::size_t(std::max(theta_i_count, 0)));
    for (int i = 0; i < theta_i_count; ++i) {
        const double s0 = std::sin(-kHalfPi + kPi * i / theta_i_count);
        const double s1 = std::sin(-kHalfPi + kPi * (i + 1) / theta_i_count);
        points[std::size_t(i)] = 0.5 * (s0 + s1);
    }
    return points;
}

HuangFGrid::HuangFGrid(const HuangTableSet &set)
    : theta_o_count_(set.theta_o_count()), theta_i_count_(set.theta_i_count), phi_count_(set.phi_count),
      sin_points_(huang_sin_theta_points(set.theta_i_count)), phi_o_nodes_(set.phi_o_nodes) {}

Expected<HuangFTable> HuangFTable::create(const HuangTableSet &set) {
    if (Status s = set.validate()) return *s;
    if (!set.has_f()) return Error{"the Huang table set has no f part (bake it with the f part)"};
    HuangFTable t;
    t.grid_ = HuangFGrid(set);
    t.values_ = set.f;
    return t;
}

Rgb HuangFTable::value(int q, int r, int i, int j) const {
    const std::size_t n = grid_.cell(q, r, i, j);
    return {values_[3 * n], values_[3 * n + 1], values_[3 * n + 2]};
}

std::array<float, 4> catmull_rom_weights(const double x[4], double t) {
    const double t2 = t * t, t3 = t2 * t;
    const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t, h01 = -2 * t3 + 3 * t2, h11 = t3 - t2;
    const double d = x[2] - x[1], a = d / (x[2] - x[0]), b = d / (x[3] - x[1]);
    return {float(-h10 * a), float(h00 - h11 * b), float(h01 + h10 * a), float(h11 * b)};
}

HuangFGrid::Stencil HuangFGrid::theta_i_stencil(double sin_theta) const {
    // Rows −1 and n_i are the poles (s = ∓1), where f·|cos θ_i| is 0. Next to a pole the value
    // behaves like √(1 − s²), which no polynomial follows, so that interval is linear.
    const int n_i = theta_i_count_;
    const double s = std::clamp(sin_theta, -1.0, 1.0);
    int cell = int(std::floor((std::asin(s) + kHalfPi) / kPi * n_i));
    cell = std::clamp(cell, 0, n_i - 1);
    const int lower = s < sin_points_[std::size_t(cell)] ? cell - 1 : cell;  // point at or below s
    auto x = [&](int row) { return row < 0 ? -1.0 : row >= n_i ? 1.0 : sin_points_[std::size_t(row)]; };
    const double t = std::clamp((s - x(lower)) / (x(lower + 1) - x(lower)), 0.0, 1.0);
    if (lower < 0 || lower >= n_i - 1) return {lower - 1, {0.0f, float(1.0 - t), float(t), 0.0f}};
    const double nodes[4] = {x(lower - 1), x(lower), x(lower + 1), x(lower + 2)};
    return {lower - 1, catmull_rom_weights(nodes, t)};
}

HuangFGrid::Stencil HuangFGrid::phi_stencil(double phi) const {
    // Points at the cells' centres, evenly spaced and periodic.
    const int n_j = phi_count_;
    const double x = (phi + kPi) / kTwoPi * n_j - 0.5;
    const double fx = std::floor(x);
    const double even[4] = {-1.0, 0.0, 1.0, 2.0};
    int first = (int(fx) - 1) % n_j;
    if (first < 0) first += n_j;
    return {first, catmull_rom_weights(even, x - fx)};
}

void HuangFGrid::add_slice(int q, int r, const Stencil &rows, const Stencil &columns, float scale,
                           HuangGridRead &out) const {
    for (int a = 0; a < 4; ++a) {
        const int i = rows.first + a;
        const float wa = rows.w[std::size_t(a)] * scale;
        if (wa == 0.0f || i < 0 || i >= theta_i_count_) continue;  // a pole
        for (int b = 0; b < 4; ++b) {
            const std::size_t k = std::size_t(out.count++);
            out.cell[k] = std::uint32_t(cell(q, r, i, (columns.first + b) % phi_count_));
            out.weight[k] = wa * columns.w[std::size_t(b)];
        }
    }
}

HuangGridRead HuangFGrid::read(const HuangTableQuery &q, Vec3 wi) const {
    HuangGridRead out;
    if (!(wi.x >= -1.0f && wi.x <= 1.0f)) return out;
    const float y = q.sign_y * wi.y, z = q.sign_z * wi.z;
    const double phi = std::atan2(z * q.cos_phi_o - y * q.sin_phi_o, y * q.cos_phi_o + z * q.sin_phi_o);
    const double theta_i = std::asin(double(wi.x));
    // Across φ_o, four nodes: beyond the fold's edges (0 and π/2) the nodes continue as mirror
    // images, where f is f of the mirrored node at −φ. One node (a round fiber): that node.
    struct Node {
        int index;
        bool mirrored;
        float weight;
    };
    const int n_q = int(phi_o_nodes_.size());
    Node nodes[4] = {{0, false, 1.0f}, {0, false, 0.0f}, {0, false, 0.0f}, {0, false, 0.0f}};
    if (n_q > 1) {
        double x[4];
        for (int m = 0; m < 4; ++m) {
            int index = q.phi.lower + m - 1;
            bool mirrored = false;
            double at;
            if (index < 0) {  // mirrored about φ_o = 0: the first node not at 0
                index = phi_o_nodes_[0] > 0.0f ? 0 : std::min(1, n_q - 1);
                at = -double(phi_o_nodes_[std::size_t(index)]);
                mirrored = true;
            } else if (index >= n_q) {  // mirrored about φ_o = π/2
                index = phi_o_nodes_[std::size_t(n_q - 1)] < float(kHalfPi) ? n_q - 1 : std::max(n_q - 2, 0);
                at = kPi - double(phi_o_nodes_[std::size_t(index)]);
                mirrored = true;
            } else {
                at = phi_o_nodes_[std::size_t(index)];
            }
            x[m] = at;
            nodes[m] = {index, mirrored, 0.0f};
        }
        const std::array<float, 4> w = catmull_rom_weights(x, q.phi.t);
        for (int m = 0; m < 4; ++m) nodes[m].weight = w[std::size_t(m)];
    }
    const Stencil columns = phi_stencil(phi), mirrored_columns = phi_stencil(-phi);
    for (int k = 0; k < 2; ++k) {
        const float wk = k ? q.theta.t : 1.0f - q.theta.t;
        if (!(wk > 0.0f)) continue;
        const int r = q.theta.lower + k;
        const Stencil rows = theta_i_stencil(std::sin(q.warp[k].to_node(theta_i)));
        for (const Node &m : nodes)
            if (m.weight != 0.0f) add_slice(m.index, r, rows, m.mirrored ? mirrored_columns : columns, wk * m.weight, out);
    }
    return out;
}

Rgb HuangFTable::f_cos(const HuangGridRead &read) const {
    float sum[3] = {0.0f, 0.0f, 0.0f};
    for (int k = 0; k < read.count; ++k) {
        const float *v = values_.data() + 3 * std::size_t(read.cell[std::size_t(k)]);
        const float w = read.weight[std::size_t(k)];
        sum[0] += w * v[0];
        sum[1] += w * v[1];
        sum[2] += w * v[2];
    }
    // The cubic overshoots a little next to sharp features; f is never negative.
    return {std::max(sum[0], 0.0f), std::max(sum[1], 0.0f), std::max(sum[2], 0.0f)};
}

}  // namespace hairis
