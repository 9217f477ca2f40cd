// Small value types shared by the whole core: 3-vectors, RGB triples, constants.
#pragma once

#include <algorithm>
#include <cmath>

namespace hairis {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 2.0 * kPi;
inline constexpr double kHalfPi = 0.5 * kPi;
inline constexpr double kInvPi = 1.0 / kPi;
inline constexpr double kInvTwoPi = 1.0 / kTwoPi;
inline constexpr double kInvFourPi = 1.0 / (4.0 * kPi);

/// The largest float below 1: where uniform numbers are clamped so that u ∈ [0, 1), and the
/// largest |sin θ| of a sampled direction (frame.h's off_axis).
inline constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

/// Degrees to radians.
constexpr double radians(double degrees) { return degrees * (kPi / 180.0); }
/// Radians to degrees.
constexpr double degrees(double radians) { return radians * (180.0 / kPi); }

template <typename T>
constexpr T sqr(T x) { return x * x; }

/// cos from sin on [-pi/2, pi/2], safe against |s| slightly above 1.
inline float cos_from_sin(float s) { return std::sqrt(std::max(0.0f, 1.0f - s * s)); }
inline double cos_from_sin(double s) { return std::sqrt(std::max(0.0, 1.0 - s * s)); }
/// asin clamped to its domain.
inline float safe_asin(float s) { return std::asin(std::clamp(s, -1.0f, 1.0f)); }
inline double safe_asin(double s) { return std::asin(std::clamp(s, -1.0, 1.0)); }

/// A 3-vector of floats: directions and points.
struct Vec3 {
    float x = 0, y = 0, z = 0;

    constexpr Vec3() = default;
    constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}

    constexpr Vec3 operator+(Vec3 b) const { return {x + b.x, y + b.y, z + b.z}; }
    constexpr Vec3 operator-(Vec3 b) const { return {x - b.x, y - b.y, z - b.z}; }
    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3 operator*(float s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3 operator/(float s) const { return {x / s, y / s, z / s}; }
};

constexpr Vec3 operator*(float s, Vec3 v) { return v * s; }
constexpr float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(Vec3 v) { return std::sqrt(dot(v, v)); }
/// v / |v|, or the zero vector for a zero input (never NaN).
inline Vec3 safe_normalize(Vec3 v) {
    const float len = length(v);
    return len > 0.0f ? v / len : Vec3{};
}

/// Linear Rec.709 RGB, the colour space of Blender's and Cycles' scene-linear defaults.
struct Rgb {
    float r = 0, g = 0, b = 0;

    constexpr Rgb() = default;
    constexpr explicit Rgb(float v) : r(v), g(v), b(v) {}
    constexpr Rgb(float r_, float g_, float b_) : r(r_), g(g_), b(b_) {}

    constexpr Rgb operator+(Rgb o) const { return {r + o.r, g + o.g, b + o.b}; }
    constexpr Rgb operator-(Rgb o) const { return {r - o.r, g - o.g, b - o.b}; }
    constexpr Rgb operator*(Rgb o) const { return {r * o.r, g * o.g, b * o.b}; }
    constexpr Rgb operator*(float s) const { return {r * s, g * s, b * s}; }
    constexpr Rgb operator/(float s) const { return {r / s, g / s, b / s}; }
    Rgb &operator+=(Rgb o) { r += o.r; g += o.g; b += o.b; return *this; }
    Rgb &operator*=(Rgb o) { r *= o.r; g *= o.g; b *= o.b; return *this; }
    Rgb &operator*=(float s) { r *= s; g *= s; b *= s; return *this; }

    constexpr float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }
    constexpr float max_component() const { return std::max(r, std::max(g, b)); }
    /// Exactly zero in every channel (what a light or BSDF returns where it adds nothing).
    constexpr bool is_black() const { return r == 0.0f && g == 0.0f && b == 0.0f; }
};

constexpr Rgb operator*(float s, Rgb c) { return c * s; }
inline Rgb exp(Rgb c) { return {std::exp(c.r), std::exp(c.g), std::exp(c.b)}; }

/// Rec.709 luminance, as Cycles' default `linear_rgb_to_gray` (scene-linear Rec.709).
constexpr float luminance(Rgb c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

}  // namespace hairis
