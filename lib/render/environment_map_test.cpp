#include "render/environment_map.h"

#include <gtest/gtest.h>

#include <boost/math/quadrature/gauss.hpp>

#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "chi2.h"
#include "core/rng.h"

namespace hairis {
namespace {

using testing::Chi2Options;
using testing::Chi2Result;
using testing::Sample3;

// Every χ² test of this file, for the Šidák correction.
constexpr int kChi2Tests = 6;

// ---------------------------------------------------------------------------------------------
// Helpers written from the documented formulas, independently of the implementation.

using Mat3 = std::array<std::array<double, 3>, 3>;

Mat3 multiply(const Mat3 &a, const Mat3 &b) {
    Mat3 c{};
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j) c[i][k] += a[i][j] * b[j][k];
    return c;
}
Mat3 transpose(const Mat3 &a) {
    Mat3 t{};
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) t[i][k] = a[k][i];
    return t;
}
Mat3 diagonal(double x, double y, double z) { return Mat3{{{x, 0, 0}, {0, y, 0}, {0, 0, z}}}; }
// Right-handed rotations about the axes; Blender's XYZ Euler applies X first: Rz·Ry·Rx.
Mat3 rotation_x(double a) { return Mat3{{{1, 0, 0}, {0, std::cos(a), -std::sin(a)}, {0, std::sin(a), std::cos(a)}}}; }
Mat3 rotation_y(double a) { return Mat3{{{std::cos(a), 0, std::sin(a)}, {0, 1, 0}, {-std::sin(a), 0, std::cos(a)}}}; }
Mat3 rotation_z(double a) { return Mat3{{{std::cos(a), -std::sin(a), 0}, {std::sin(a), std::cos(a), 0}, {0, 0, 1}}}; }
Mat3 euler_xyz(double x, double y, double z) {
    return multiply(rotation_z(z), multiply(rotation_y(y), rotation_x(x)));
}
Vec3 apply(const Mat3 &m, Vec3 v) {
    return {float(m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z),
            float(m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z),
            float(m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z)};
}
double determinant(const Mat3 &a) {
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

// Cycles' equirectangular map: u = (atan2(y, x) − π)/(−2π), v = (acos z − π)/(−π), and back.
double u_of(Vec3 d) { return (std::atan2(double(d.y), double(d.x)) - kPi) / (-kTwoPi); }
double v_of(Vec3 d) {
    const double len = std::sqrt(double(dot(d, d)));
    return (std::acos(std::clamp(double(d.z) / len, -1.0, 1.0)) - kPi) / (-kPi);
}
Vec3 direction_of(double u, double v) {
    const double phi = kPi - kTwoPi * u, theta = kPi * (1.0 - v);
    return {float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)),
            float(std::cos(theta))};
}

// The χ² harness cuts its sphere in sin θ = local.x and φ = atan2(local.z, local.y): world
// z is its x, the world azimuth atan2(y, x) its φ.
Vec3 to_local(Vec3 d) { return {d.z, d.x, d.y}; }
Vec3 from_local(Vec3 l) { return {l.y, l.z, l.x}; }

// Breaks of a W × H map in the harness' angles: rows are equal in latitude, columns in
// φ = π − 2πu.
void add_map_breaks(Chi2Options &o, int W, int H) {
    for (int j = 1; j < H; ++j) o.theta_breaks.push_back(-kHalfPi + kPi * j / H);
    for (int i = 0; i <= W; ++i) o.phi_breaks.push_back(kPi - kTwoPi * i / W);
}

EnvironmentImage make_image(int w, int h, const std::function<Rgb(int, int)> &texel) {
    std::vector<float> rgb;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Rgb c = texel(x, y);
            rgb.insert(rgb.end(), {c.r, c.g, c.b});
        }
    auto image = EnvironmentImage::create(w, h, std::move(rgb));
    EXPECT_TRUE(image.ok()) << (image.ok() ? "" : image.error().message);
    return std::move(image).value();
}

// map_width = −1: a map at the image's resolution (the cells the χ² tests align to); 0: Auto.
EnvironmentMap make_map(EnvironmentImage image, const Mat4 &world_to_texture = Mat4{},
                        int map_width = -1, int map_height = 0) {
    EnvironmentDesc desc;
    desc.map_width = map_width < 0 ? image.width() : map_width;
    desc.map_height = map_width < 0 ? image.height() : map_height;
    desc.image = std::move(image);
    desc.world_to_texture = world_to_texture;
    auto map = EnvironmentMap::create(std::move(desc));
    EXPECT_TRUE(map.ok()) << (map.ok() ? "" : map.error().message);
    return std::move(map).value();
}

// A bright 2 × 2 spot on a dim gradient.
EnvironmentImage spot_and_gradient(int w, int h) {
    return make_image(w, h, [&](int x, int y) {
        const float g = 0.02f + 0.1f * float(x) / float(w) + 0.05f * float(y) / float(h);
        const bool spot = (x == 30 || x == 31) && (y == 15 || y == 16);
        return spot ? Rgb{400.0f, 300.0f, 200.0f} : Rgb{g, 0.5f * g, 2.0f * g};
    });
}

// Bright texels among black ones, one at the seam and one in the top row (whose bilinear
// footprint wraps, as Cycles' REPEAT does, onto the bottom row at the other pole).
EnvironmentImage sparse_texels(int w, int h) {
    return make_image(w, h, [&](int x, int y) {
        if (y == 5 && (x == 5 || x == 6)) return Rgb{100.0f, 80.0f, 60.0f};
        if (x == 20 && y == 10) return Rgb{0.0f, 0.0f, 50.0f};
        if (x == w - 1 && y == 8) return Rgb{10.0f};
        if (x == 3 && y == h - 1) return Rgb{30.0f};
        return Rgb{0.0f};
    });
}

Chi2Result world_frame_chi2(const EnvironmentMap &map, Chi2Options o) {
    add_map_breaks(o, map.map_width(), map.map_height());
    return testing::chi2_direction_test(
        [&](Sample3 u) -> std::optional<Vec3> { return to_local(map.sample(u.u0, u.u1).wi); },
        [&](Vec3 l) { return double(map.pdf(from_local(l))); }, o);
}

Chi2Options chi2_options() {
    Chi2Options o;
    o.test_count = kChi2Tests;
    return o;
}

// ---------------------------------------------------------------------------------------------
// The mapping as Cycles applies it.

TEST(EnvironmentMapping, EulerIsBlendersXyzOrder) {
    const Vec3 r{0.4f, -0.7f, 1.9f};
    const Mat4 code = euler_xyz_rotation(r);
    const Mat3 ref = euler_xyz(r.x, r.y, r.z);
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(code.m[i][k], ref[i][k], 1e-6) << i << k;
}

TEST(EnvironmentMapping, NodeTypes) {
    const Vec3 r{0.3f, 0.5f, -1.2f}, s{2.0f, 0.5f, 1.5f};
    const Mat3 R = euler_xyz(r.x, r.y, r.z);
    const std::pair<MappingType, Mat3> cases[] = {
        {MappingType::Point, multiply(R, diagonal(s.x, s.y, s.z))},
        {MappingType::Vector, multiply(R, diagonal(s.x, s.y, s.z))},
        {MappingType::Texture, multiply(diagonal(1 / s.x, 1 / s.y, 1 / s.z), transpose(R))},
        {MappingType::Normal, multiply(R, diagonal(1 / s.x, 1 / s.y, 1 / s.z))},
    };
    for (const auto &[type, ref] : cases) {
        const auto a = mapping_node_transform({type, {0, 0, 0}, r, s});
        ASSERT_TRUE(a.ok()) << a.error().message;
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(a.value().m[i][k], ref[i][k], 1e-6);
    }
    // Vector and Normal ignore Location, as Cycles' svm_mapping does.
    EXPECT_TRUE(mapping_node_transform({MappingType::Vector, {1, 2, 3}, r, s}).ok());
}

// ---------------------------------------------------------------------------------------------
// eval: the texel Cycles' formula names. Texel (x, y) holds r = x + 1, g = (y + 1)²,
// b = (x + 1)², so a blend of two columns or rows is told apart from any other.

class EnvironmentEval : public ::testing::Test {
  protected:
    static constexpr int kW = 16, kH = 8;
    EnvironmentImage image() const {
        return make_image(kW, kH, [](int x, int y) {
            return Rgb{float(x + 1), float((y + 1) * (y + 1)), float((x + 1) * (x + 1))};
        });
    }
    static void expect_rgb(Rgb got, Rgb want, const char *what) {
        EXPECT_NEAR(got.r, want.r, 2e-3f * want.r) << what;
        EXPECT_NEAR(got.g, want.g, 2e-3f * want.g) << what;
        EXPECT_NEAR(got.b, want.b, 2e-3f * want.b) << what;
    }
};

TEST_F(EnvironmentEval, AxesHitTheTexelsOfCyclesFormula) {
    const EnvironmentMap map = make_map(image());
    // With x = u·16 − ½ and y = v·8 − ½ (texel centres at integers), by hand:
    // +X: atan2 = 0 → u = ½, x = 7.5 (columns 7, 8); v = ½, y = 3.5 (rows 3, 4).
    expect_rgb(map.eval({1, 0, 0}), {(8 + 9) / 2.0f, (16 + 25) / 2.0f, (64 + 81) / 2.0f}, "+X");
    // +Y: atan2 = π/2 → u = ¼, x = 3.5 (columns 3, 4).
    expect_rgb(map.eval({0, 1, 0}), {(4 + 5) / 2.0f, 20.5f, (16 + 25) / 2.0f}, "+Y");
    // −Y: atan2 = −π/2 → u = ¾, x = 11.5 (columns 11, 12).
    expect_rgb(map.eval({0, -1, 0}), {(12 + 13) / 2.0f, 20.5f, (144 + 169) / 2.0f}, "-Y");
    // −X: atan2 = π → u = 0, x = −0.5: the seam, columns 15 and 0 (REPEAT).
    expect_rgb(map.eval({-1, 0, 0}), {(16 + 1) / 2.0f, 20.5f, (256 + 1) / 2.0f}, "-X");
    // +Z: v = 1, y = 7.5: rows 7 and 0 (REPEAT across the pole); atan2(0, 0) = 0 → u = ½.
    expect_rgb(map.eval({0, 0, 1}), {8.5f, (64 + 1) / 2.0f, 72.5f}, "+Z");
    // −Z: v = 0, y = −0.5: rows 7 and 0 again.
    expect_rgb(map.eval({0, 0, -1}), {8.5f, (64 + 1) / 2.0f, 72.5f}, "-Z");
    // 45° above +X: acos z = π/4 → v = ¾, y = 5.5 (rows 5, 6); below: v = ¼, y = 1.5.
    const float r = std::sqrt(0.5f);
    expect_rgb(map.eval({r, 0, r}), {8.5f, (36 + 49) / 2.0f, 72.5f}, "45 deg up");
    expect_rgb(map.eval({r, 0, -r}), {8.5f, (4 + 9) / 2.0f, 72.5f}, "45 deg down");
    // Exactly on texel (5, 2)'s centre: u = 5.5/16, v = 2.5/8.
    expect_rgb(map.eval(direction_of(5.5 / 16, 2.5 / 8)), {6, 9, 36}, "texel (5, 2)");
}

TEST_F(EnvironmentEval, NinetyDegreeZRotation) {
    // Point mapping, Rotation Z = 90°: lookup = Rz(90°)·d, which takes +X to +Y, +Y to −X,
    // −X to −Y, and keeps Z.
    const auto a = mapping_node_transform({MappingType::Point, {0, 0, 0}, {0, 0, float(kHalfPi)}, {1, 1, 1}});
    ASSERT_TRUE(a.ok());
    const EnvironmentMap map = make_map(image(), a.value());
    expect_rgb(map.eval({1, 0, 0}), {4.5f, 20.5f, 20.5f}, "+X reads +Y's columns 3, 4");
    expect_rgb(map.eval({0, 1, 0}), {8.5f, 20.5f, 128.5f}, "+Y reads the seam");
    expect_rgb(map.eval({-1, 0, 0}), {12.5f, 20.5f, 156.5f}, "-X reads -Y's columns 11, 12");
    expect_rgb(map.eval({0, 0, 1}), {8.5f, 32.5f, 72.5f}, "+Z unchanged");
    // The Texture type applies the inverse: Rzᵀ takes +X to −Y.
    const auto t = mapping_node_transform({MappingType::Texture, {0, 0, 0}, {0, 0, float(kHalfPi)}, {1, 1, 1}});
    ASSERT_TRUE(t.ok());
    expect_rgb(make_map(image(), t.value()).eval({1, 0, 0}), {12.5f, 20.5f, 156.5f}, "Texture +X");
}

TEST_F(EnvironmentEval, ScaleStretchesTheLookupVector) {
    // Vector mapping with Scale (2, 1, 1): the texture is read at normalize(2x, y, z).
    const auto a = mapping_node_transform({MappingType::Vector, {0, 0, 0}, {0, 0, 0}, {2, 1, 1}});
    ASSERT_TRUE(a.ok());
    const EnvironmentMap scaled = make_map(image(), a.value()), plain = make_map(image());
    const Vec3 dirs[] = {{0.6f, 0.8f, 0.0f}, {0.3f, -0.4f, 0.866f}, {-0.5f, 0.5f, -0.7071f}};
    for (Vec3 d : dirs) {
        const Rgb want = plain.eval(safe_normalize(Vec3{2 * d.x, d.y, d.z}));
        expect_rgb(scaled.eval(d), want, "scaled");
    }
}

TEST(EnvironmentRadiance, SrgbIsDecodedAfterInterpolation) {
    // Columns alternate encoded 0.2 and 0.8. +X reads x = 4·½ − ½ = 1.5, halfway between
    // columns 1 and 2: Cycles decodes the blend, srgb_to_linear(0.5) = 0.214041, not the
    // blend of the decoded texels, (0.0331 + 0.6038)/2 = 0.318.
    std::vector<float> rgb;
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x) {
            const float v = x % 2 == 0 ? 0.2f : 0.8f;
            rgb.insert(rgb.end(), {v, v, v});
        }
    auto image = EnvironmentImage::create(4, 2, rgb, ImageColorSpace::Srgb);
    ASSERT_TRUE(image.ok());
    const EnvironmentMap map = make_map(std::move(image).value());
    EXPECT_NEAR(map.eval({1, 0, 0}).g, 0.214041f, 1e-4f);
    // At a texel centre (u = 2.5/4, v = 0.5/2) the texel itself: srgb_to_linear(0.2) = 0.0331.
    EXPECT_NEAR(map.eval(direction_of(2.5 / 4, 0.5 / 2)).r, 0.0331048f, 1e-4f);
}

TEST(EnvironmentRadiance, StrengthAndColorMultiply) {
    EnvironmentDesc desc;
    desc.image = make_image(4, 2, [](int, int) { return Rgb{0.5f, 1.0f, 2.0f}; });
    desc.strength = 3.0f;
    desc.color = Rgb{1.0f, 0.5f, 0.25f};
    auto map = EnvironmentMap::create(std::move(desc));
    ASSERT_TRUE(map.ok());
    const Rgb L = map.value().eval({0.3f, 0.4f, safe_normalize(Vec3{0.3f, 0.4f, 0.5f}).z});
    EXPECT_FLOAT_EQ(L.r, 1.5f);
    EXPECT_FLOAT_EQ(L.g, 1.5f);
    EXPECT_FLOAT_EQ(L.b, 1.5f);
}

// ---------------------------------------------------------------------------------------------
// χ²: pdf() is the density of sample().

TEST(EnvironmentChi2, SpotAndGradient) {
    const EnvironmentMap map = make_map(spot_and_gradient(48, 24));
    const Chi2Result r = world_frame_chi2(map, chi2_options());
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_EQ(r.failed_samples, 0);
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-4);
}

TEST(EnvironmentChi2, ManualMapResolutionNotAlignedWithTexels) {
    const EnvironmentMap map = make_map(spot_and_gradient(48, 24), Mat4{}, 20, 7);
    ASSERT_EQ(map.map_width(), 20);
    ASSERT_EQ(map.map_height(), 7);
    const Chi2Result r = world_frame_chi2(map, chi2_options());
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-4);
}

TEST(EnvironmentChi2, ZeroTexelsNextToBrightOnes) {
    const EnvironmentMap map = make_map(sparse_texels(32, 16));
    const Chi2Result r = world_frame_chi2(map, chi2_options());
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-4);
}

// With a rotation the map's cells are not aligned with the world's angles; the test looks
// at samples in texture space, through its own rotation, where they are.
TEST(EnvironmentChi2, RotatedMapping) {
    const Vec3 rot{0.4f, -0.7f, 1.9f};
    const auto a = mapping_node_transform({MappingType::Point, {0, 0, 0}, rot, {1, 1, 1}});
    ASSERT_TRUE(a.ok());
    const EnvironmentMap map = make_map(spot_and_gradient(48, 24), a.value());
    const Mat3 R = euler_xyz(rot.x, rot.y, rot.z), Rt = transpose(R);
    Chi2Options o = chi2_options();
    add_map_breaks(o, map.map_width(), map.map_height());
    const Chi2Result r = testing::chi2_direction_test(
        [&](Sample3 u) -> std::optional<Vec3> {
            return to_local(safe_normalize(apply(R, map.sample(u.u0, u.u1).wi)));
        },
        // A rotation keeps solid angle: the texture-space density is the world one.
        [&](Vec3 l) { return double(map.pdf(apply(Rt, from_local(l)))); }, o);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-4);
}

// A rotation and a non-uniform scale: texture-space density = world density / |dĉ/dω|, with
// ĉ = A·d/|A·d| and |dĉ/dω| = |det A| / |A·d|³ (the solid-angle Jacobian of a linear map of
// directions, as in Heitz et al. 2016's linearly transformed distributions).
TEST(EnvironmentChi2, RotatedAndScaledMapping) {
    const Vec3 rot{-0.2f, 0.9f, 0.3f}, scale{1.0f, 2.5f, 0.6f};
    const auto a = mapping_node_transform({MappingType::Vector, {0, 0, 0}, rot, scale});
    ASSERT_TRUE(a.ok());
    const EnvironmentMap map = make_map(sparse_texels(32, 16), a.value());
    const Mat3 R = euler_xyz(rot.x, rot.y, rot.z);
    const Mat3 A = multiply(R, diagonal(scale.x, scale.y, scale.z));
    const Mat3 A_inv = multiply(diagonal(1 / scale.x, 1 / scale.y, 1 / scale.z), transpose(R));
    const double det = std::fabs(determinant(A));
    Chi2Options o = chi2_options();
    add_map_breaks(o, map.map_width(), map.map_height());
    const Chi2Result r = testing::chi2_direction_test(
        [&](Sample3 u) -> std::optional<Vec3> {
            return to_local(safe_normalize(apply(A, map.sample(u.u0, u.u1).wi)));
        },
        [&](Vec3 l) {
            const Vec3 d = safe_normalize(apply(A_inv, from_local(l)));
            const double len = length(apply(A, d));
            return double(map.pdf(d)) / (det / (len * len * len));
        },
        o);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3);
}

TEST(EnvironmentMap, AutoResolutionIsCyclesOwn) {
    // Cycles' Auto for an Environment Texture world: the image's size, but at least 4096 × 2048
    // in each axis (the fallback for a world without a single Nishita sun).
    const auto flat = [](int, int) { return Rgb{1.0f}; };
    const EnvironmentMap small = make_map(make_image(64, 32, flat), Mat4{}, 0);
    EXPECT_EQ(small.map_width(), 4096);
    EXPECT_EQ(small.map_height(), 2048);
    const EnvironmentMap wide = make_map(make_image(5000, 3, flat), Mat4{}, 0);
    EXPECT_EQ(wide.map_width(), 5000);
    EXPECT_EQ(wide.map_height(), 2048);
    const EnvironmentMap manual = make_map(make_image(64, 32, flat), Mat4{}, 64, 32);
    EXPECT_EQ(manual.map_width(), 64);
    EXPECT_EQ(manual.map_height(), 32);
}

TEST(EnvironmentChi2, FineMapOfALargeImage) {
    // A map at the image's resolution of 512 × 256 cells, much finer than the χ² cells.
    const EnvironmentMap map = make_map(make_image(512, 256, [](int x, int y) {
        const float s = std::sin(0.05f * float(x)) * std::cos(0.11f * float(y));
        return Rgb{1.0f + 0.9f * s, 0.5f, (x / 16 + y / 16) % 3 == 0 ? 5.0f : 0.0f};
    }));
    ASSERT_EQ(map.map_width(), 512);
    ASSERT_EQ(map.map_height(), 256);
    Chi2Options o = chi2_options();
    o.simpson_points = 5;
    const Chi2Result r = testing::chi2_direction_test(
        [&](Sample3 u) -> std::optional<Vec3> { return to_local(map.sample(u.u0, u.u1).wi); },
        [&](Vec3 l) { return double(map.pdf(from_local(l))); }, [&] {
            add_map_breaks(o, map.map_width(), map.map_height());
            return o;
        }());
    EXPECT_TRUE(r.passed) << r.message;
}

// ---------------------------------------------------------------------------------------------
// Support and normalisation.

// ∫ pdf dω by the midpoint rule on a fine grid in (z, φ), independent of the map's cells.
double pdf_integral(const EnvironmentMap &map, int nz, int nphi) {
    double sum = 0;
    for (int a = 0; a < nz; ++a) {
        const double z = -1.0 + 2.0 * (a + 0.5) / nz, r = std::sqrt(1.0 - z * z);
        for (int b = 0; b < nphi; ++b) {
            const double phi = -kPi + kTwoPi * (b + 0.5) / nphi;
            sum += map.pdf({float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)});
        }
    }
    return sum * (2.0 / nz) * (kTwoPi / nphi);
}

TEST(EnvironmentPdf, IntegratesToOne) {
    const auto rotation = mapping_node_transform({MappingType::Point, {0, 0, 0}, {1.0f, 0.5f, -2.0f}, {1, 1, 1}});
    const auto stretch = mapping_node_transform({MappingType::Texture, {0, 0, 0}, {0.3f, 0.0f, 0.8f}, {0.5f, 1.0f, 3.0f}});
    ASSERT_TRUE(rotation.ok() && stretch.ok());
    struct Case {
        const char *name;
        Mat4 a;
        int map_w, map_h;
    };
    const Case cases[] = {{"identity", Mat4{}, 0, 0},
                          {"rotation", rotation.value(), 0, 0},
                          {"rotation and scale", stretch.value(), 0, 0},
                          {"manual 20 x 7", rotation.value(), 20, 7}};
    for (const Case &c : cases) {
        const EnvironmentMap map = make_map(spot_and_gradient(48, 24), c.a, c.map_w, c.map_h);
        EXPECT_NEAR(pdf_integral(map, 1500, 3000), 1.0, 2e-3) << c.name;
    }
}

TEST(EnvironmentPdf, EveryLitDirectionHasDensity) {
    // Also half a texel from the bright ones, where their bilinear footprint lights black
    // texels, at the seam and across the pole. A map weighted by the texels' own luminance
    // (not the interpolant's) leaves these at pdf 0.
    const auto rotation = mapping_node_transform({MappingType::Point, {0, 0, 0}, {0.2f, 1.1f, 0.4f}, {1, 1, 1}});
    ASSERT_TRUE(rotation.ok());
    for (const Mat4 &a : {Mat4{}, rotation.value()}) {
        const EnvironmentMap map = make_map(sparse_texels(32, 16), a);
        long long lit = 0;
        const int nz = 800, nphi = 1600;
        for (int i = 0; i < nz; ++i) {
            const double z = -1.0 + 2.0 * (i + 0.5) / nz, r = std::sqrt(1.0 - z * z);
            for (int k = 0; k < nphi; ++k) {
                const double phi = -kPi + kTwoPi * (k + 0.5) / nphi;
                const Vec3 d{float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)};
                if (!(luminance(map.eval(d)) > 0.0f)) continue;
                ++lit;
                ASSERT_GT(map.pdf(d), 0.0f) << "lit direction " << d.x << " " << d.y << " " << d.z;
            }
        }
        EXPECT_GT(lit, 1000);
    }
    // The top-row texel lights the −Z pole's half texel through the wrap (identity mapping).
    const EnvironmentMap map = make_map(sparse_texels(32, 16));
    const Vec3 below = direction_of((3 + 0.5) / 32, 0.2 / 16);
    EXPECT_GT(luminance(map.eval(below)), 0.0f);
    EXPECT_GT(map.pdf(below), 0.0f);
}

TEST(EnvironmentPdf, LuminanceIntegralMatchesQuadratureOfEval) {
    const EnvironmentMap map = make_map(spot_and_gradient(48, 24));
    double sum = 0;
    const int nz = 1200, nphi = 2400;
    for (int a = 0; a < nz; ++a) {
        const double z = -1.0 + 2.0 * (a + 0.5) / nz, r = std::sqrt(1.0 - z * z);
        for (int b = 0; b < nphi; ++b) {
            const double phi = -kPi + kTwoPi * (b + 0.5) / nphi;
            sum += luminance(map.eval({float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)}));
        }
    }
    sum *= (2.0 / nz) * (kTwoPi / nphi);
    // The map's cell integrals ignore the variation of sin θ inside a row (24 rows).
    EXPECT_NEAR(map.luminance_integral() / sum, 1.0, 1e-2);
}

TEST(EnvironmentPdf, BlackImage) {
    const EnvironmentMap map = make_map(make_image(8, 4, [](int, int) { return Rgb{0.0f}; }));
    EXPECT_TRUE(map.black());
    EXPECT_EQ(map.luminance_integral(), 0.0);
    const EnvironmentSample s = map.sample(0.3f, 0.7f);
    EXPECT_GT(s.pdf, 0.0f);
    EXPECT_EQ(luminance(s.radiance), 0.0f);
    EXPECT_NEAR(pdf_integral(map, 400, 800), 1.0, 2e-3);
}

// ---------------------------------------------------------------------------------------------
// A tiny very bright spot in a black map.

// One texel of radiance c at (column i, row j) in a 512 × 256 map, black elsewhere.
struct Spot {
    static constexpr int kW = 512, kH = 256;
    static constexpr float kC = 1e4f;
    int i, j;
    EnvironmentMap map;
    Spot(int column, int row)
        : i(column), j(row), map(make_map(make_image(kW, kH, [&](int x, int y) {
              return x == column && y == row ? Rgb{kC} : Rgb{0.0f};
          }))) {}

    bool in_texel(Vec3 d) const {
        const double u = u_of(d), v = v_of(d);
        return u >= double(i) / kW && u < double(i + 1) / kW && v >= double(j) / kH &&
               v < double(j + 1) / kH;
    }
    // Solid angle of map row r (rows equal in v, r taken modulo H): 2π/W · Δ(−cos πv).
    static double row_solid_angle(int r) {
        r = (r + kH) % kH;
        return kTwoPi / kW * (std::cos(kPi * r / kH) - std::cos(kPi * (r + 1) / kH));
    }
    // The map's weights are the interpolant's cell means times the cells' solid angles: the
    // texel spreads over its 3 × 3 neighbours by [1 6 1]/8 in each axis (wrapping over the
    // pole, as the interpolation does). So, by hand, P(its own cell) =
    // ¾ · ¾ ΔΩ_j / (⅛ ΔΩ_{j−1} + ¾ ΔΩ_j + ⅛ ΔΩ_{j+1}).
    double predicted_probability() const {
        return 0.75 * 0.75 * row_solid_angle(j) /
               (0.125 * row_solid_angle(j - 1) + 0.75 * row_solid_angle(j) +
                0.125 * row_solid_angle(j + 1));
    }
    static double tent(double t) { return std::max(0.0, 1.0 - std::fabs(t)); }
    // ∫ g(ω, L(ω)) over the texel's support (±1 texel around its centre), with the bilinear
    // radiance by hand, L = c · tent(x − i) · tent(y − j) (x = u·w − ½, y = v·h − ½):
    // Gauss–Legendre on the four pieces where the tents are smooth,
    // dω = sin θ · (π/h) dy · (2π/w) dx. Away from the seam and the poles.
    double over_support(const std::function<double(Vec3, double)> &g) const {
        using Rule = boost::math::quadrature::gauss<double, 20>;
        double total = 0;
        for (int qx = 0; qx < 2; ++qx)
            for (int qy = 0; qy < 2; ++qy) {
                const double x0 = i - 1.0 + qx, y0 = j - 1.0 + qy;
                total += Rule::integrate(
                    [&](double y) {
                        return Rule::integrate(
                            [&](double x) {
                                const double u = (x + 0.5) / kW, v = (y + 0.5) / kH;
                                const double L = kC * tent(x - i) * tent(y - j);
                                const double jac = std::sin(kPi * (1.0 - v)) * (kPi / kH) * (kTwoPi / kW);
                                return g(direction_of(u, v), L) * jac;
                            },
                            x0, x0 + 1.0);
                    },
                    y0, y0 + 1.0);
            }
        return total;
    }
};

TEST(EnvironmentSpot, SamplesLandInTheSpotTexelAsPredicted) {
    // Near the equator the rows' solid angles hardly differ: P ≈ 9/16. At the bottom row the
    // neighbours are the row above (3 times its solid angle) and, across the pole, the top
    // row (the same): P = (9/16) / (⅛ + ¾ + ⅜) = 0.45.
    for (const auto &[column, row] : {std::pair{300, 140}, std::pair{77, 0}}) {
        const Spot spot(column, row);
        const double P = spot.predicted_probability();
        if (row == 0) {
            EXPECT_NEAR(P, 0.45, 1e-4);
        }
        const int n = 200000;
        int hits = 0;
        for (int k = 0; k < n; ++k) {
            const SampleRng rng(3, 0, std::uint64_t(k));
            hits += spot.in_texel(spot.map.sample(rng.get(0), rng.get(1)).wi);
        }
        const double sigma = std::sqrt(P * (1 - P) / n);
        EXPECT_NEAR(double(hits) / n, P, 5 * sigma) << "row " << row;
        // And ∫ pdf over the texel's solid angle says the same.
        using Rule = boost::math::quadrature::gauss<double, 10>;
        const double mass = Rule::integrate([&](double v) {
            return Rule::integrate([&](double u) {
                return double(spot.map.pdf(direction_of(u, v))) * std::sin(kPi * (1 - v)) * kPi * kTwoPi;
            }, double(column) / Spot::kW, double(column + 1) / Spot::kW);
        }, double(row) / Spot::kH, double(row + 1) / Spot::kH);
        EXPECT_NEAR(mass, P, 1e-4) << "row " << row;
    }
}

TEST(EnvironmentSpot, IrradianceConvergesFarFasterThanCosineSampling) {
    const Spot spot(300, 140);
    // A surface facing the spot's centre.
    const Vec3 n = direction_of((spot.i + 0.5) / Spot::kW, (spot.j + 0.5) / Spot::kH);
    const double E = spot.over_support([&](Vec3 w, double L) { return L * std::max(0.0, double(dot(n, w))); });
    // Closed form to second order in the texel's angular size: the tents integrate to one
    // texel, whose solid angle is sin θ · 2π²/(w·h), and cos ≈ 1 over it.
    const double theta = kPi * (1.0 - (spot.j + 0.5) / Spot::kH);
    EXPECT_NEAR(E / (Spot::kC * std::sin(theta) * 2 * kPi * kPi / (Spot::kW * Spot::kH)), 1.0, 1e-3);

    // Light sampling.
    const int count = 20000;
    double sum = 0, sum2 = 0;
    for (int k = 0; k < count; ++k) {
        const SampleRng rng(5, 0, std::uint64_t(k));
        const EnvironmentSample s = spot.map.sample(rng.get(0), rng.get(1));
        const double v = s.pdf > 0 ? s.radiance.r * std::max(0.0f, dot(n, s.wi)) / s.pdf : 0.0;
        sum += v;
        sum2 += v * v;
    }
    const double mean = sum / count, var = sum2 / count - mean * mean;
    EXPECT_NEAR(mean, E, 5 * std::sqrt(var / count) + 1e-6 * E);
    // Cosine sampling's variance in closed form: π ∫ L² cos dω − E² (the estimator π·L).
    const double var_cosine =
        kPi * spot.over_support([&](Vec3 w, double L) { return L * L * std::max(0.0, double(dot(n, w))); }) -
        E * E;
    EXPECT_GT(var_cosine / var, 100.0) << "light " << var << " cosine " << var_cosine;
}

// ---------------------------------------------------------------------------------------------
// Bad input.

std::string create_error(EnvironmentDesc desc) {
    auto map = EnvironmentMap::create(std::move(desc));
    return map.ok() ? "(no error)" : map.error().message;
}

void expect_mentions(const std::string &message, const std::string &needle) {
    EXPECT_NE(message.find(needle), std::string::npos)
        << "\"" << message << "\" does not mention \"" << needle << "\"";
}

EnvironmentDesc valid_desc() {
    EnvironmentDesc desc;
    desc.image = make_image(4, 2, [](int, int) { return Rgb{1.0f}; });
    return desc;
}

TEST(EnvironmentBadInput, DescriptionFields) {
    expect_mentions(create_error(EnvironmentDesc{}), "image is empty");
    auto with = [](const std::function<void(EnvironmentDesc &)> &edit) {
        EnvironmentDesc d = valid_desc();
        edit(d);
        return create_error(std::move(d));
    };
    expect_mentions(with([](EnvironmentDesc &d) { d.world_to_texture.m[1][2] = NAN; }),
                    "world_to_texture must be finite");
    expect_mentions(with([](EnvironmentDesc &d) { d.world_to_texture.m[0][3] = 2.0f; }),
                    "world_to_texture must not translate");
    expect_mentions(with([](EnvironmentDesc &d) { d.world_to_texture.m[3][0] = 1.0f; }),
                    "last row 0 0 0 1");
    expect_mentions(with([](EnvironmentDesc &d) { d.world_to_texture.m[2][2] = 0.0f; }),
                    "world_to_texture is singular");
    expect_mentions(with([](EnvironmentDesc &d) { d.world_to_texture.m[2][2] = 1e-8f; }),
                    "nearly singular");
    expect_mentions(with([](EnvironmentDesc &d) { d.strength = -1.0f; }),
                    "world strength must be finite and >= 0 (got -1)");
    expect_mentions(with([](EnvironmentDesc &d) { d.color.g = NAN; }), "world color G");
    expect_mentions(with([](EnvironmentDesc &d) { d.map_width = 9000; }),
                    "map_width must be an integer in [1, 8192] (got 9000)");
    expect_mentions(with([](EnvironmentDesc &d) { d.map_width = 64, d.map_height = 5000; }),
                    "map_height must be an integer in [1, 4096] (got 5000)");
    expect_mentions(with([](EnvironmentDesc &d) {
                        d.strength = 3e38f;
                        d.image = make_image(4, 2, [](int, int) { return Rgb{3e38f}; });
                    }),
                    "overflows a float");
}

TEST(EnvironmentBadInput, MappingNode) {
    auto error = [](MappingType type, Vec3 location, Vec3 rotation, Vec3 scale) {
        auto a = mapping_node_transform({type, location, rotation, scale});
        return a.ok() ? std::string("(no error)") : a.error().message;
    };
    const Vec3 zero{0, 0, 0}, one{1, 1, 1};
    expect_mentions(error(MappingType::Point, zero, {NAN, 0, 0}, one),
                    "mapping rotation.x must be finite");
    expect_mentions(error(MappingType::Point, zero, zero, {1, INFINITY, 1}), "mapping scale.y");
    expect_mentions(error(MappingType::Point, zero, zero, {1, 1, 0}),
                    "mapping scale.z must not be 0");
    expect_mentions(error(MappingType::Point, {0, 0.5f, 0}, zero, one),
                    "mapping location must be (0, 0, 0)");
    expect_mentions(error(MappingType::Texture, {1, 0, 0}, zero, one), "location");
    expect_mentions(error(MappingType(7), zero, zero, one), "mapping type");
}

TEST(EnvironmentBadInput, DefaultMapIsInert) {
    const EnvironmentMap map;
    EXPECT_EQ(map.pdf({0, 0, 1}), 0.0f);
    EXPECT_EQ(map.sample(0.5f, 0.5f).pdf, 0.0f);
    EXPECT_EQ(luminance(map.eval({0, 0, 1})), 0.0f);
}

TEST(EnvironmentBadInput, NonFiniteDirections) {
    const EnvironmentMap map = make_map(spot_and_gradient(48, 24));
    EXPECT_EQ(map.pdf({NAN, 0, 1}), 0.0f);
    EXPECT_EQ(map.pdf({0, 0, 0}), 0.0f);
    EXPECT_EQ(luminance(map.eval({0, INFINITY, 0})), 0.0f);
}

}  // namespace
}  // namespace hairis
