#include "core/frame.h"

#include <gtest/gtest.h>

#include <random>

namespace hairis {
namespace {

TEST(FiberFrame, MatchesCyclesConstruction) {
    // Cycles: X = tangent, Y = normalize(cross(X, wo)), Z = cross(X, Y).
    const Vec3 tangent = safe_normalize(Vec3{0.3f, 1.0f, -0.2f});
    const Vec3 wo = safe_normalize(Vec3{-0.5f, 0.4f, 0.9f});
    const FiberFrame f = FiberFrame::from_tangent_and_view(tangent, wo);
    EXPECT_NEAR(dot(f.x, tangent), 1.0f, 1e-6f);
    EXPECT_NEAR(dot(f.x, f.y), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(f.y, f.z), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(f.y, wo), 0.0f, 1e-6f);  // Y is perpendicular to the view
    EXPECT_NEAR(dot(cross(f.x, f.y), f.z), 1.0f, 1e-6f);  // right-handed
    // In Cycles' frame every view direction has φ_o = −π/2 and sin θ_o = wo·X.
    const FiberAngles a = angles_of(f.to_local(wo));
    EXPECT_NEAR(a.phi, -float(kHalfPi), 1e-5f);
    EXPECT_NEAR(std::sin(a.theta), dot(wo, tangent), 1e-6f);
}

TEST(FiberFrame, ViewAlongTheFiberStillGivesAFrame) {
    const FiberFrame f = FiberFrame::from_tangent_and_view({0, 0, 1}, {0, 0, 1});
    EXPECT_NEAR(length(f.y), 1.0f, 1e-6f);
    EXPECT_NEAR(dot(f.x, f.y), 0.0f, 1e-6f);
    EXPECT_NEAR(length(f.z), 1.0f, 1e-6f);
}

TEST(FiberFrame, AnglesRoundTrip) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> theta(-1.5f, 1.5f), phi(-3.1f, 3.1f);
    for (int i = 0; i < 1000; ++i) {
        const float t = theta(rng), p = phi(rng);
        const Vec3 w = direction_of(t, p);
        EXPECT_NEAR(length(w), 1.0f, 1e-6f);
        const FiberAngles a = angles_of(w);
        EXPECT_NEAR(a.theta, t, 2e-4f);
        EXPECT_NEAR(a.phi, p, 2e-4f);
        const FiberFrame f = FiberFrame::from_tangent_and_view({0.6f, 0.8f, 0}, {0, 0, 1});
        const Vec3 back = f.to_local(f.to_world(w));
        EXPECT_NEAR(back.x, w.x, 1e-6f);
        EXPECT_NEAR(back.z, w.z, 1e-6f);
    }
}

TEST(FiberFrame, WrapAngleAndRelativeAzimuth) {
    EXPECT_NEAR(std::fabs(wrap_angle(3.0 * kPi)), kPi, 1e-12);
    EXPECT_NEAR(wrap_angle(0.5), 0.5, 1e-12);
    EXPECT_NEAR(wrap_angle(-7.0), -7.0 + kTwoPi, 1e-12);
    // TT: light from the far side of the fiber is at relative azimuth ±π.
    EXPECT_NEAR(std::fabs(relative_azimuth(float(kHalfPi), -float(kHalfPi))), float(kPi), 1e-6f);
    EXPECT_NEAR(theta_half(0.2f, 0.4f), 0.3f, 1e-7f);
    EXPECT_NEAR(theta_diff(0.2f, 0.4f), 0.1f, 1e-7f);
}

}  // namespace
}  // namespace hairis
