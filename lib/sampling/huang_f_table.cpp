#include "sampling/huang_f_table.h"

#include <algorithm>
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

Expected<HuangFTable> HuangFTable::create(const HuangTableSet &set) {
    if (Status s = set.validate()) return *s;
    if (!set.has_f()) return Error{"the Huang table set has no f part (bake it with the f part)"};
    HuangFTable t;
    t.theta_o_count_ = set.theta_o_count();
    t.theta_i_count_ = set.theta_i_count;
    t.phi_count_ = set.phi_count;
    t.sin_points_ = huang_sin_theta_points(set.theta_i_count);
    t.values_ = set.f;
    return t;
}

Rgb HuangFTable::value(int q, int r, int i, int j) const {
    const std::size_t n =
        ((std::size_t(q) * std::size_t(theta_o_count_) + std::size_t(r)) * std::size_t(theta_i_count_) + std::size_t(i)) *
            std::size_t(phi_count_) +
        std::size_t(j);
    return {values_[3 * n], values_[3 * n + 1], values_[3 * n + 2]};
}

Rgb HuangFTable::slice(int q, int r, double sin_theta, double phi) const {
    // θ_i: the points bracketing sin θ_i; beyond the outer points, towards 0 at the pole.
    const int n_i = theta_i_count_;
    const double s = std::clamp(sin_theta, -1.0, 1.0);
    int cell = int(std::floor((std::asin(s) + kHalfPi) / kPi * n_i));
    cell = std::clamp(cell, 0, n_i - 1);
    const int lower = s < sin_points_[std::size_t(cell)] ? cell - 1 : cell;  // point at or below s
    double t;
    if (lower < 0) {
        t = (s + 1.0) / (sin_points_[0] + 1.0);
    } else if (lower >= n_i - 1) {
        t = (s - sin_points_[std::size_t(n_i - 1)]) / (1.0 - sin_points_[std::size_t(n_i - 1)]);
    } else {
        t = (s - sin_points_[std::size_t(lower)]) / (sin_points_[std::size_t(lower) + 1] - sin_points_[std::size_t(lower)]);
    }
    t = std::clamp(t, 0.0, 1.0);
    // φ: periodic, points at the cells' centres.
    const int n_j = phi_count_;
    const double x = (phi + kPi) / kTwoPi * n_j - 0.5;
    const double fx = std::floor(x);
    const double u = x - fx;
    int j0 = int(fx) % n_j;
    if (j0 < 0) j0 += n_j;
    const int j1 = j0 + 1 == n_j ? 0 : j0 + 1;
    auto row = [&](int i) -> Rgb {
        if (i < 0 || i >= n_i) return {};  // a pole
        return value(q, r, i, j0) * float(1.0 - u) + value(q, r, i, j1) * float(u);
    };
    return row(lower) * float(1.0 - t) + row(lower + 1) * float(t);
}

Rgb HuangFTable::f_cos(const HuangTableQuery &q, Vec3 wi) const {
    if (!(wi.x >= -1.0f && wi.x <= 1.0f)) return {};
    const float y = q.sign_y * wi.y, z = q.sign_z * wi.z;
    const double phi = std::atan2(z * q.cos_phi_o - y * q.sin_phi_o, y * q.cos_phi_o + z * q.sin_phi_o);
    const double theta_i = std::asin(double(wi.x));
    Rgb sum;
    for (int k = 0; k < 2; ++k) {
        const float wk = k ? q.theta.t : 1.0f - q.theta.t;
        if (!(wk > 0.0f)) continue;
        const int r = q.theta.lower + k;
        const double s = std::sin(q.warp[k].to_node(theta_i));
        for (int m = 0; m < 2; ++m) {
            const float wm = m ? q.phi.t : 1.0f - q.phi.t;
            if (!(wm > 0.0f)) continue;
            sum += slice(q.phi.lower + m, r, s, phi) * (wk * wm);
        }
    }
    return sum;
}

}  // namespace hairis
