#include "fiber/ggx.h"

#include <algorithm>
#include <cmath>

#include "core/quadrature.h"

namespace hairis::ggx {

double shadowing_g1(double alpha, double cos_m) { return 1.0 / (1.0 + smith_lambda(alpha, cos_m)); }

double shadowing_g2(double alpha, double cos_m1, double cos_m2) {
    return 1.0 / (1.0 + smith_lambda(alpha, cos_m1) + smith_lambda(alpha, cos_m2));
}

double shadowing_ratio(double alpha, double cos_m1, double cos_m2) {
    const double l1 = smith_lambda(alpha, cos_m1);
    const double l2 = smith_lambda(alpha, cos_m2);
    if (std::isinf(l1)) return std::isinf(l2) ? 0.5 : 1.0;
    return (1.0 + l1) / (1.0 + l1 + l2);
}

double visible_density(double alpha, Vec3d w, Vec3d m, Vec3d h) {
    const double cos_wm = dot(w, m), cos_wh = dot(w, h), cos_mh = dot(m, h);
    if (!(cos_wm > 0.0) || !(cos_wh > 0.0) || !(cos_mh > 0.0)) return 0.0;
    return shadowing_g1(alpha, cos_wm) * cos_wh * distribution(alpha, cos_mh) / cos_wm;
}

void orthonormal_basis(Vec3d n, Vec3d &a, Vec3d &b) {
    if (n.x != n.y || n.x != n.z) {
        a = Vec3d{n.z - n.y, n.x - n.z, n.y - n.x};
    } else {
        a = Vec3d{n.z - n.y, n.x + n.z, -n.y - n.x};
    }
    a = a / length(a);
    b = cross(n, a);
}

namespace {

// The stretched view direction and the disk basis of Heitz 2018, in m's local frame.
struct Stretched {
    Vec3d w;       // normalize(α w_1, α w_2, w_3)
    Vec3d t1, t2;  // orthonormal basis of the plane perpendicular to w
};

Stretched stretch(double alpha, Vec3d local_w) {
    Stretched s;
    s.w = safe_normalize(Vec3d{alpha * local_w.x, alpha * local_w.y, local_w.z});
    const double lensq = s.w.x * s.w.x + s.w.y * s.w.y;
    if (lensq > 1e-7) {
        s.t1 = Vec3d{-s.w.y, s.w.x, 0.0} / std::sqrt(lensq);
        s.t2 = cross(s.w, s.t1);
    } else {
        s.t1 = Vec3d{1, 0, 0};
        s.t2 = Vec3d{0, 1, 0};
    }
    return s;
}

// Unstretches a point H of the stretched hemisphere (local coordinates) to a world normal.
Vec3d unstretch(double alpha, Vec3d H, Vec3d a, Vec3d b, Vec3d m) {
    const Vec3d local = safe_normalize(Vec3d{alpha * H.x, alpha * H.y, std::max(0.0, H.z)});
    return a * local.x + b * local.y + m * local.z;
}

}  // namespace

Vec3d sample_visible(double alpha, Vec3d w, Vec3d m, double u1, double u2) {
    Vec3d a, b;
    orthonormal_basis(m, a, b);
    const Stretched s = stretch(alpha, Vec3d{dot(w, a), dot(w, b), dot(w, m)});

    // Shirley–Chiu concentric map of [0, 1]² onto the unit disk.
    double dx = 0.0, dy = 0.0;
    const double p = 2.0 * u1 - 1.0, q = 2.0 * u2 - 1.0;
    if (p != 0.0 || q != 0.0) {
        double radius, angle;
        if (p * p > q * q) {
            radius = p;
            angle = 0.25 * kPi * (q / p);
        } else {
            radius = q;
            angle = 0.5 * kPi - 0.25 * kPi * (p / q);
        }
        dx = radius * std::cos(angle);
        dy = radius * std::sin(angle);
    }
    // Warp the lower half of the disk onto the visible part of the projected hemisphere.
    const double k = 0.5 * (1.0 + s.w.z);
    dy = (1.0 - k) * std::sqrt(std::max(0.0, 1.0 - dx * dx)) + k * dy;
    const double dz = std::sqrt(std::max(0.0, 1.0 - dx * dx - dy * dy));
    const Vec3d H = s.t1 * dx + s.t2 * dy + s.w * dz;
    return unstretch(alpha, H, a, b, m);
}

VisibleParametrization::VisibleParametrization(double alpha, Vec3d w, Vec3d m)
    : alpha_(alpha), m_(m) {
    orthonormal_basis(m, a_, b_);
    const Stretched s = stretch(alpha, Vec3d{dot(w, a_), dot(w, b_), dot(w, m)});
    valid_ = s.w.z > -1.0;
    if (!valid_) return;
    w_ = s.w;
    t1_ = s.t1;
    t2_ = s.t2;
    const double wz = std::clamp(s.w.z, -1.0, 1.0);
    psi_min_ = -std::asin(wz);
    // Area of the projected region: π/2 (half disk) + π w'_z / 2 (half ellipse, signed).
    area_ = 0.5 * kPi * (1.0 + wz);
}

Vec3d VisibleParametrization::normal(double sin_beta, double cos_beta, double psi) const {
    const Vec3d H = t1_ * sin_beta + t2_ * (cos_beta * std::sin(psi)) + w_ * (cos_beta * std::cos(psi));
    return unstretch(alpha_, H, a_, b_, m_);
}

double VisibleParametrization::density(double beta, double psi) const {
    const double cb = std::cos(beta);
    return cb * cb * std::cos(psi) / area_;
}

std::vector<VisibleNode> visible_rule(double alpha, Vec3d w, Vec3d m, int beta_order,
                                      int psi_order) {
    std::vector<VisibleNode> nodes;
    const VisibleParametrization p(alpha, w, m);
    if (!p.valid()) return nodes;
    const GaussLegendre &rule_beta = GaussLegendre::rule(beta_order);
    const GaussLegendre &rule_psi = GaussLegendre::rule(psi_order);
    const double psi_half = 0.5 * (0.5 * kPi - p.psi_min());
    const double psi_mid = 0.5 * (0.5 * kPi + p.psi_min());
    nodes.reserve(rule_beta.nodes.size() * rule_psi.nodes.size());
    for (size_t i = 0; i < rule_beta.nodes.size(); ++i) {
        const double beta = 0.5 * kPi * rule_beta.nodes[i];
        for (size_t j = 0; j < rule_psi.nodes.size(); ++j) {
            const double psi = psi_mid + psi_half * rule_psi.nodes[j];
            const double weight = rule_beta.weights[i] * 0.5 * kPi * rule_psi.weights[j] * psi_half *
                                  p.density(beta, psi);
            nodes.push_back({p.normal(beta, psi), weight});
        }
    }
    return nodes;
}

bool refract(Vec3d w, Vec3d h, double eta, Vec3d &out) {
    const double c = dot(w, h);
    const double root = eta * eta - 1.0 + c * c;
    if (root <= 0.0) return false;
    const double cos_t = -std::sqrt(root) / eta;
    out = (c / eta + cos_t) * h - w / eta;
    return true;
}

}  // namespace hairis::ggx
