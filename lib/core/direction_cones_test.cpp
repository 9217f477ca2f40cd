#include "core/direction_cones.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace hairis {
namespace {

Vec3d random_direction(std::mt19937_64 &rng) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double z = 2.0 * u(rng) - 1.0, phi = kTwoPi * u(rng), s = std::sqrt(1.0 - z * z);
    return {s * std::cos(phi), s * std::sin(phi), z};
}

// Directions spread about one axis, as a fiber's internal paths are.
std::vector<Vec3d> clustered(std::mt19937_64 &rng, Vec3d axis, double spread, int count) {
    std::vector<Vec3d> out;
    std::normal_distribution<double> n(0.0, spread);
    for (int k = 0; k < count; ++k) out.push_back(safe_normalize(axis + Vec3d{n(rng), n(rng), n(rng)}));
    return out;
}

std::vector<Vec3d> uniform(std::mt19937_64 &rng, int count) {
    std::vector<Vec3d> out;
    for (int k = 0; k < count; ++k) out.push_back(random_direction(rng));
    return out;
}

TEST(DirectionCones, TileTheInputAndBoundTheirMembers) {
    std::mt19937_64 rng(3);
    for (const std::vector<Vec3d> &d : {uniform(rng, 5000), clustered(rng, {0.3, -0.2, 0.93}, 0.2, 5000)}) {
        const DirectionCones cones(d);
        std::vector<int> seen(d.size(), 0);
        for (std::uint32_t index : cones.order()) ++seen.at(index);
        for (int s : seen) ASSERT_EQ(s, 1);
        std::uint32_t next = 0;
        for (const DirectionCones::Cone &cone : cones.cones()) {
            ASSERT_EQ(cone.begin, next);
            ASSERT_LT(cone.begin, cone.end);
            next = cone.end;
            EXPECT_NEAR(length(cone.axis), 1.0, 1e-12);
            EXPECT_NEAR(cone.cos_radius * cone.cos_radius + cone.sin_radius * cone.sin_radius, 1.0, 1e-12);
            for (std::uint32_t k = cone.begin; k < cone.end; ++k) {
                EXPECT_GE(dot(d[cones.order()[k]], cone.axis), cone.cos_radius);
                if (k > cone.begin) {
                    EXPECT_LT(cones.order()[k - 1], cones.order()[k]);
                }
            }
        }
        EXPECT_EQ(next, d.size());
        EXPECT_GT(cones.cones().size(), 20u);  // a grid, not one cone
    }
    EXPECT_TRUE(DirectionCones(std::vector<Vec3d>{}).cones().empty());
    // bands < 1 means one band of two sectors: two directions in one half of the longitudes
    // make one cone, one in each half two.
    EXPECT_EQ(DirectionCones(std::vector<Vec3d>{{0, 0.6, 0.8}, {0, 0.8, -0.6}}, 0).cones().size(), 1u);
    EXPECT_EQ(DirectionCones(std::vector<Vec3d>{{0, 0.6, 0.8}, {0, -0.8, -0.6}}, 0).cones().size(), 2u);
}

// A direction that is not finite leaves its cone undecided, whatever the threshold.
TEST(DirectionCones, NonFiniteMembersAreNeverDecided) {
    const double nan = std::nan("");
    const DirectionCones cones(std::vector<Vec3d>{{nan, 0, 1}, {0, 0, 1}, {0, 0, -1}});
    int undecided = 0;
    for (const DirectionCones::Cone &cone : cones.cones()) {
        bool has_nan = false;
        for (std::uint32_t k = cone.begin; k < cone.end; ++k) has_nan = has_nan || cones.order()[k] == 0;
        if (!has_nan) continue;
        ++undecided;
        EXPECT_EQ(DirectionCones::side(cone, {0, 0, 1}, 2.0), DirectionCones::Side::Mixed);
        EXPECT_EQ(DirectionCones::side(cone, {0, 0, 1}, -2.0), DirectionCones::Side::Mixed);
    }
    EXPECT_EQ(undecided, 1);
}

// Every decided cone agrees with the test member by member, for thresholds exactly at members'
// values (ties), just beside them and anywhere, and for l a float's rounding away from unit.
TEST(DirectionCones, DecisionsAgreeWithEveryMember) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const std::vector<Vec3d> sets[] = {uniform(rng, 3000), clustered(rng, {0.0, 1.0, 0.0}, 0.05, 3000),
                                       clustered(rng, {0.6, 0.0, -0.8}, 0.4, 3000)};
    long decided = 0, members = 0;
    for (const std::vector<Vec3d> &d : sets) {
        const DirectionCones cones(d, 24);
        for (int trial = 0; trial < 300; ++trial) {
            Vec3d l = trial % 5 == 0 ? d[std::size_t(trial) % d.size()] : random_direction(rng);
            if (trial % 2 == 0) l = Vec3d(l.to_float());  // not exactly unit
            double c = u(rng);
            if (trial % 3 == 0) c = dot(d[std::size_t(trial * 7) % d.size()], l);
            if (trial % 3 == 1) c = std::nextafter(dot(d[std::size_t(trial * 13) % d.size()], l), 2.0);
            for (const DirectionCones::Cone &cone : cones.cones()) {
                // Also at the cone's own extreme values, where a decision is closest to wrong.
                double low = 2.0, high = -2.0;
                for (std::uint32_t k = cone.begin; k < cone.end; ++k) {
                    low = std::min(low, dot(d[cones.order()[k]], l));
                    high = std::max(high, dot(d[cones.order()[k]], l));
                }
                for (const double edge : {low, high, std::nextafter(low, -2.0), std::nextafter(high, 2.0)}) {
                    const DirectionCones::Side side = DirectionCones::side(cone, l, edge);
                    if (side == DirectionCones::Side::Mixed) continue;
                    for (std::uint32_t k = cone.begin; k < cone.end; ++k)
                        ASSERT_EQ(dot(d[cones.order()[k]], l) < edge, side == DirectionCones::Side::Below)
                            << "trial " << trial << ", edge " << edge;
                }
                const DirectionCones::Side side = DirectionCones::side(cone, l, c);
                members += cone.end - cone.begin;
                if (side == DirectionCones::Side::Mixed) continue;
                decided += cone.end - cone.begin;
                for (std::uint32_t k = cone.begin; k < cone.end; ++k) {
                    const bool below = dot(d[cones.order()[k]], l) < c;
                    ASSERT_EQ(below, side == DirectionCones::Side::Below) << "trial " << trial << ", c " << c;
                }
            }
        }
    }
    // The grid decides most members without looking at them.
    EXPECT_GT(double(decided) / double(members), 0.6);
}

TEST(DirectionCones, ThresholdsOutsideTheDotsRangeDecideEveryCone) {
    std::mt19937_64 rng(5);
    const std::vector<Vec3d> d = uniform(rng, 2000);
    const DirectionCones cones(d);
    const Vec3d l = random_direction(rng);
    for (const DirectionCones::Cone &cone : cones.cones()) {
        EXPECT_EQ(DirectionCones::side(cone, l, 1.01), DirectionCones::Side::Below);
        EXPECT_EQ(DirectionCones::side(cone, l, -1.01), DirectionCones::Side::AtOrAbove);
        EXPECT_EQ(DirectionCones::side(cone, {0, 0, 0}, 0.0), DirectionCones::Side::Mixed);
    }
}

}  // namespace
}  // namespace hairis
