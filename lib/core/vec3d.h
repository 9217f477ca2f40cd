// A double-precision 3-vector for the microfacet code (ggx.h, huang.h), whose quadratures
// need more than float's 24 bits near the specular peaks of smooth microfacets.
#pragma once

#include <cmath>

#include "core/math.h"

namespace hairis {

struct Vec3d {
    double x = 0, y = 0, z = 0;

    constexpr Vec3d() = default;
    constexpr Vec3d(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
    constexpr explicit Vec3d(Vec3 v) : x(v.x), y(v.y), z(v.z) {}

    constexpr Vec3d operator+(Vec3d b) const { return {x + b.x, y + b.y, z + b.z}; }
    constexpr Vec3d operator-(Vec3d b) const { return {x - b.x, y - b.y, z - b.z}; }
    constexpr Vec3d operator-() const { return {-x, -y, -z}; }
    constexpr Vec3d operator*(double s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3d operator/(double s) const { return {x / s, y / s, z / s}; }

    /// The nearest float vector.
    constexpr Vec3 to_float() const { return {float(x), float(y), float(z)}; }
};

constexpr Vec3d operator*(double s, Vec3d v) { return v * s; }
constexpr double dot(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3d cross(Vec3d a, Vec3d b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(Vec3d v) { return std::sqrt(dot(v, v)); }
/// v / |v|, or the zero vector for a zero input.
inline Vec3d safe_normalize(Vec3d v) {
    const double len = length(v);
    return len > 0.0 ? v / len : Vec3d{};
}

}  // namespace hairis
