#include "render/microfacet.h"

#include <algorithm>
#include <cmath>

#include "render/lights.h"

namespace hairis::microfacet {

namespace {
constexpr float kPiF = float(kPi);
}

float ggx_d(float alpha2, float cos_h) {
    const float c2 = std::min(cos_h * cos_h, 1.0f);
    const float t = (1.0f - c2) + alpha2 * c2;
    return alpha2 / (kPiF * t * t);
}

float ggx_d(float alpha2, Vec3 h) {
    const float len2 = dot(h, h);
    if (!(len2 > 0.0f)) return 0.0f;
    const float t = (h.x * h.x + h.y * h.y + alpha2 * h.z * h.z) / len2;
    return alpha2 / (kPiF * t * t);
}

float ggx_lambda(float alpha2, float cos_theta) {
    const float c2 = cos_theta * cos_theta;
    if (!(c2 < 1.0f)) return 0.0f;
    const float tan2 = (1.0f - c2) / c2;  // +inf at c = 0: Λ = +inf, G1 = 0
    return 0.5f * (std::sqrt(1.0f + alpha2 * tan2) - 1.0f);
}

float gtr1_d(float alpha, float cos_h) {
    if (alpha >= 1.0f) return float(kInvPi);
    const float a2 = alpha * alpha;
    const float t = 1.0f + (a2 - 1.0f) * cos_h * cos_h;
    return (a2 - 1.0f) / (kPiF * std::log(a2) * t);
}

float gtr1_d(float alpha, Vec3 h) {
    if (alpha >= 1.0f) return float(kInvPi);
    const float len2 = dot(h, h);
    if (!(len2 > 0.0f)) return 0.0f;
    const float a2 = alpha * alpha;
    const float t = (h.x * h.x + h.y * h.y + a2 * h.z * h.z) / len2;  // 1 + (α² − 1) cos²
    return (a2 - 1.0f) / (kPiF * std::log(a2) * t);
}

Vec3 sample_ggx_visible(Vec3 wo, float alpha, float u0, float u1) {
    // The view in the configuration where the distribution is the unit hemisphere.
    const Vec3 v = safe_normalize(Vec3{alpha * wo.x, alpha * wo.y, wo.z});
    const float lensq = v.x * v.x + v.y * v.y;
    const Vec3 t1 = lensq > 1e-7f ? Vec3{-v.y, v.x, 0.0f} / std::sqrt(lensq) : Vec3{1, 0, 0};
    const Vec3 t2 = cross(v, t1);
    // A uniform point on the disk, its lower half warped onto the visible half-ellipse.
    float x, y;
    concentric_disk(u0, u1, x, y);
    const float s = 0.5f * (1.0f + v.z);
    y = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - x * x)) + s * y;
    const float z = std::sqrt(std::max(0.0f, 1.0f - x * x - y * y));
    const Vec3 n = t1 * x + t2 * y + v * z;
    return safe_normalize(Vec3{alpha * n.x, alpha * n.y, std::max(0.0f, n.z)});
}

float ggx_reflection_pdf(Vec3 wo, Vec3 wi, float alpha) {
    if (!(wo.z > 0.0f)) return 0.0f;
    const Vec3 h = safe_normalize(wo + wi);
    if (!(h.z > 0.0f)) return 0.0f;
    const float alpha2 = alpha * alpha;
    return ggx_g1(alpha2, wo.z) * ggx_d(alpha2, h) / (4.0f * wo.z);
}

Vec3 sample_gtr1(float alpha, float u0, float u1) {
    const float a2 = std::min(alpha * alpha, 1.0f);
    // The CDF of c² is ln(1 + (α² − 1) c²) / ln α²; it tends to c² = u as α → 1.
    const float c2 = std::fabs(1.0f - a2) < 1e-4f ? u0 : (1.0f - std::pow(a2, u0)) / (1.0f - a2);
    const float c = std::sqrt(std::clamp(c2, 0.0f, 1.0f));
    const float s = std::sqrt(std::max(0.0f, 1.0f - c * c));
    const float phi = 2.0f * kPiF * u1;
    return {s * std::cos(phi), s * std::sin(phi), c};
}

float gtr1_reflection_pdf(Vec3 wo, Vec3 wi, float alpha) {
    const Vec3 h = safe_normalize(wo + wi);
    const float woh = dot(wo, h);
    if (!(h.z > 0.0f) || !(woh > 0.0f)) return 0.0f;
    return gtr1_d(alpha, wo + wi) * h.z / (4.0f * woh);
}

}  // namespace hairis::microfacet
