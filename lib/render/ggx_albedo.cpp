#include "render/ggx_albedo.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "core/quadrature.h"
#include "fiber/fresnel.h"
#include "fiber/ggx.h"

namespace hairis {

namespace {

// Quadrature orders of one node: β and ψ lines of the visible-normal rule, the root scan that
// finds where the reflection crosses the horizon, and the μ panels of E_avg.
constexpr int kBetaOrder = 32, kPsiOrder = 16, kScan = 24;
constexpr int kAveragePanels = 4, kAveragePoints = 16;

// ∫ D_w(h) 1(o.z > 0) g(h, o) dh over the visible normals seen from w = (sqrt(1 − μ²), 0, μ).
template <typename G>
double visible_integral(double alpha, double mu, const G &g) {
    const Vec3d n{0, 0, 1};
    const Vec3d w{std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu};
    const auto horizon = [&](Vec3d h) { return std::array<double, 1>{2.0 * dot(w, h) * h.z - w.z}; };
    double sum = 0.0;
    for (const ggx::VisibleNode &node :
         ggx::visible_rule_split(alpha, w, n, kBetaOrder, kPsiOrder, kScan, horizon)) {
        const Vec3d o = ggx::reflect(-1.0 * w, node.h);  // 2(w·h)h − w
        if (!(o.z > 0.0)) continue;
        sum += node.weight * g(node.h, o, w);
    }
    return std::clamp(sum, 0.0, 1.0);
}

// One linear interpolation axis of Cycles' lookup_table_read: index, next index, fraction.
struct Axis {
    int index, next;
    float t;
};

Axis axis(float coordinate, int size) {
    const float x = std::clamp(coordinate, 0.0f, 1.0f) * float(size - 1);
    const int index = std::min(int(x), size - 1);
    return {index, std::min(index + 1, size - 1), x - float(index)};
}

template <typename Slot, typename Compute>
float cached(Slot &slot, const Compute &compute) {
    float value = slot.load(std::memory_order_relaxed);
    if (std::isnan(value)) {
        value = float(compute());
        slot.store(value, std::memory_order_relaxed);
    }
    return value;
}

}  // namespace

double ggx_reflection_albedo(double alpha, double mu) {
    return visible_integral(alpha, mu, [&](Vec3d, Vec3d o, Vec3d) {
        return ggx::shadowing_ratio(alpha, mu, o.z);
    });
}

double ggx_reflection_albedo_average(double alpha) {
    const QuadratureRule rule = QuadratureRule::composite(0.0, 1.0, kAveragePanels, kAveragePoints);
    double sum = 0.0;
    for (std::size_t i = 0; i < rule.x.size(); ++i)
        sum += rule.w[i] * 2.0 * rule.x[i] * ggx_reflection_albedo(alpha, rule.x[i]);
    return std::clamp(sum, 0.0, 1.0);
}

double ggx_fresnel_factor_ior(double alpha, double mu, double eta) {
    const double f0 = fresnel_dielectric(1.0, eta);
    return visible_integral(alpha, mu, [&](Vec3d h, Vec3d, Vec3d w) {
        const double f = fresnel_dielectric(std::fabs(dot(w, h)), eta);
        return std::clamp((f - f0) / (1.0 - f0), 0.0, 1.0);
    });
}

double ggx_fresnel_factor_exponent(double alpha, double mu, double exponent) {
    return visible_integral(alpha, mu, [&](Vec3d h, Vec3d, Vec3d w) {
        return std::pow(std::max(0.0, 1.0 - dot(w, h)), exponent);
    });
}

double GgxAlbedoTables::e_roughness(int x) { return std::clamp(double(x) / (kSizeE - 1), 1e-4, 1.0); }
double GgxAlbedoTables::s_roughness(int x) { return std::clamp(double(x) / (kSizeS - 1), 1e-4, 1.0); }
double GgxAlbedoTables::e_cosine(int y) { return std::clamp(double(y) / (kSizeE - 1), 1e-4, 1.0); }
double GgxAlbedoTables::s_cosine(int y) { return std::clamp(double(y) / (kSizeS - 1), 1e-4, 1.0); }
double GgxAlbedoTables::s_ior_of(int k) {
    const double z = std::clamp(double(k) / (kSizeS - 1), 1e-4, 0.99);
    return (1.0 + z * z) / (1.0 - z * z);
}
double GgxAlbedoTables::s_exponent_of(int k) {
    const double z = std::clamp(double(k) / (kSizeS - 1), 1e-4, 0.99);
    return 5.0 * (1.0 - z) / z;
}

GgxAlbedoTables::GgxAlbedoTables() {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (auto &v : e_) v.store(nan);
    for (auto &v : e_avg_) v.store(nan);
    for (auto &v : s_ior_) v.store(nan);
    for (auto &v : s_exponent_) v.store(nan);
}

const GgxAlbedoTables &GgxAlbedoTables::tables() {
    static const GgxAlbedoTables instance;
    return instance;
}

float GgxAlbedoTables::e_node(int x, int y) const {
    return cached(e_[std::size_t(y * kSizeE + x)], [&] {
        const double r = e_roughness(x);
        return ggx_reflection_albedo(r * r, e_cosine(y));
    });
}

float GgxAlbedoTables::e_avg_node(int x) const {
    return cached(e_avg_[std::size_t(x)], [&] {
        const double r = e_roughness(x);
        return ggx_reflection_albedo_average(r * r);
    });
}

float GgxAlbedoTables::s_ior_node(int x, int y, int k) const {
    return cached(s_ior_[std::size_t((k * kSizeS + y) * kSizeS + x)], [&] {
        const double r = s_roughness(x);
        return ggx_fresnel_factor_ior(r * r, s_cosine(y), s_ior_of(k));
    });
}

float GgxAlbedoTables::s_exponent_node(int x, int y, int k) const {
    return cached(s_exponent_[std::size_t((k * kSizeS + y) * kSizeS + x)], [&] {
        const double r = s_roughness(x);
        return ggx_fresnel_factor_exponent(r * r, s_cosine(y), s_exponent_of(k));
    });
}

float GgxAlbedoTables::e(float rough, float mu) const {
    const Axis ax = axis(rough, kSizeE), ay = axis(mu, kSizeE);
    auto row = [&](int y) { return (1.0f - ax.t) * e_node(ax.index, y) + ax.t * e_node(ax.next, y); };
    return (1.0f - ay.t) * row(ay.index) + ay.t * row(ay.next);
}

float GgxAlbedoTables::e_avg(float rough) const {
    const Axis ax = axis(rough, kSizeE);
    return (1.0f - ax.t) * e_avg_node(ax.index) + ax.t * e_avg_node(ax.next);
}

namespace {

template <typename Node>
float trilinear(float x, float y, float z, int size, const Node &node) {
    const Axis ax = axis(x, size), ay = axis(y, size), az = axis(z, size);
    auto row = [&](int j, int k) { return (1.0f - ax.t) * node(ax.index, j, k) + ax.t * node(ax.next, j, k); };
    auto slice = [&](int k) { return (1.0f - ay.t) * row(ay.index, k) + ay.t * row(ay.next, k); };
    return (1.0f - az.t) * slice(az.index) + az.t * slice(az.next);
}

}  // namespace

float GgxAlbedoTables::s_ior(float rough, float mu, float z) const {
    return trilinear(rough, mu, z, kSizeS, [&](int x, int y, int k) { return s_ior_node(x, y, k); });
}

float GgxAlbedoTables::s_exponent(float rough, float mu, float z) const {
    return trilinear(rough, mu, z, kSizeS, [&](int x, int y, int k) { return s_exponent_node(x, y, k); });
}

}  // namespace hairis
