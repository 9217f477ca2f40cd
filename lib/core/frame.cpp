#include "core/frame.h"

namespace hairis {

FiberFrame FiberFrame::from_tangent_and_view(Vec3 tangent, Vec3 wo) {
    FiberFrame f;
    f.x = safe_normalize(tangent);
    f.y = safe_normalize(cross(f.x, wo));
    if (dot(f.y, f.y) == 0.0f) {
        // The view looks along the fiber: any normal-plane axis will do.
        const Vec3 helper = std::fabs(f.x.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
        f.y = safe_normalize(cross(f.x, helper));
    }
    f.z = cross(f.x, f.y);
    return f;
}

FiberAngles angles_of(Vec3 l) {
    // atan2 rather than asin(x): near the poles x rounds to ±1 while y and z still carry θ.
    return {std::atan2(l.x, std::hypot(l.y, l.z)), std::atan2(l.z, l.y)};
}

Vec3 direction_of(float theta, float phi) {
    const float c = std::cos(theta);
    return {std::sin(theta), c * std::cos(phi), c * std::sin(phi)};
}

Vec3 direction_of(FiberAngles a) { return direction_of(a.theta, a.phi); }

float wrap_angle(float a) {
    const float two_pi = float(kTwoPi);
    return a - two_pi * std::floor((a + float(kPi)) / two_pi);
}

double wrap_angle(double a) { return a - kTwoPi * std::floor((a + kPi) / kTwoPi); }

}  // namespace hairis
