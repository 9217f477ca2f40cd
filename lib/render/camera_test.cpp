#include "render/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

namespace hairis {
namespace {

enum class Fit { Auto, Horizontal, Vertical };

struct BlenderCamera {
    bool ortho = false;
    float lens = 50.0f, sensor_x = 36.0f, sensor_y = 24.0f;
    Fit fit = Fit::Auto;
    float ortho_scale = 4.0f;
    float shift_x = 0.0f, shift_y = 0.0f;
    int res_x = 8, res_y = 4;
};

// Camera.view_frame(scene=...) for square pixels, written from Blender's definition
// (BKE_camera_view_frame_ex with drawsize 1, no clipping, unit scale): the corners
// top right, bottom right, bottom left, top left.
std::array<Vec3, 4> view_frame(const BlenderCamera &c) {
    const float aspx = float(c.res_x), aspy = float(c.res_y);
    Fit fit = c.fit;
    if (fit == Fit::Auto) fit = aspx >= aspy ? Fit::Horizontal : Fit::Vertical;
    const float asp0 = fit == Fit::Horizontal ? 1.0f : aspx / aspy;
    const float asp1 = fit == Fit::Horizontal ? aspy / aspx : 1.0f;
    float facx, facy, sx, sy, depth;
    if (c.ortho) {
        facx = 0.5f * c.ortho_scale * asp0;
        facy = 0.5f * c.ortho_scale * asp1;
        sx = c.shift_x * c.ortho_scale;
        sy = c.shift_y * c.ortho_scale;
        depth = -1.0f;
    } else {
        // The sensor used is the fit SETTING's: Auto uses the width.
        const float half_sensor = 0.5f * (c.fit == Fit::Vertical ? c.sensor_y : c.sensor_x);
        const float drawsize = 0.5f;
        depth = drawsize * c.lens / -half_sensor;
        facx = drawsize * asp0;
        facy = drawsize * asp1;
        sx = c.shift_x * drawsize * 2.0f;
        sy = c.shift_y * drawsize * 2.0f;
    }
    return {Vec3{sx + facx, sy + facy, depth}, Vec3{sx + facx, sy - facy, depth},
            Vec3{sx - facx, sy - facy, depth}, Vec3{sx - facx, sy + facy, depth}};
}

Camera make(const BlenderCamera &c, const Mat4 &m = Mat4::identity(), float clip_start = 0.0f,
            float clip_end = INFINITY) {
    CameraDesc d;
    d.camera_to_world = m;
    d.projection = c.ortho ? Projection::Orthographic : Projection::Perspective;
    d.frame = view_frame(c);
    d.width = c.res_x;
    d.height = c.res_y;
    d.clip_start = clip_start;
    d.clip_end = clip_end;
    auto cam = Camera::create(d);
    EXPECT_TRUE(cam.ok()) << (cam.ok() ? "" : cam.error().message);
    return std::move(cam).value();
}

void expect_dir(Vec3 got, Vec3 want, float tol = 1e-5f) {
    want = safe_normalize(want);
    EXPECT_NEAR(got.x, want.x, tol);
    EXPECT_NEAR(got.y, want.y, tol);
    EXPECT_NEAR(got.z, want.z, tol);
}

// A Blender camera at (0, −10, 0) rotated 90° about X: it looks along +Y, with +Z up.
Mat4 looking_along_y() {
    Mat4 m;
    const float v[16] = {1, 0, 0, 0,   //
                         0, 0, -1, -10, //
                         0, 1, 0, 0,   //
                         0, 0, 0, 1};
    m = Mat4::from_row_major(v);
    return m;
}

TEST(Camera, PerspectivePixelCentresFollowLensAndSensor) {
    // 8 × 4 px, 50 mm lens on a 36 mm sensor, fit Auto (horizontal here): the ray through
    // the centre of pixel (x, y) has slopes ((x+½)/8·2 − 1)·18/50 and ((y+½)/4·2 − 1)·18/50·½.
    const BlenderCamera bc;
    const Camera cam = make(bc);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x) {
            const CameraRay r = cam.generate_ray(x, y, 0.5f, 0.5f);
            const float xn = (x + 0.5f) / 8.0f * 2.0f - 1.0f, yn = (y + 0.5f) / 4.0f * 2.0f - 1.0f;
            expect_dir(r.direction, {xn * 0.36f, yn * 0.36f * 0.5f, -1.0f});
            EXPECT_NEAR(r.origin.x, 0.0f, 1e-6f);
        }
}

TEST(Camera, RowZeroIsTheBottomRow) {
    const Camera cam = make(BlenderCamera{});
    const CameraRay bottom_left = cam.generate_ray(0, 0, 0.5f, 0.5f);
    EXPECT_LT(bottom_left.direction.x, 0.0f);
    EXPECT_LT(bottom_left.direction.y, 0.0f);  // below the view axis: y = 0 is the bottom
    const CameraRay top_right = cam.generate_ray(7, 3, 0.5f, 0.5f);
    EXPECT_GT(top_right.direction.x, 0.0f);
    EXPECT_GT(top_right.direction.y, 0.0f);
    // A point above the camera's axis lands in the top row (index 3).
    const auto p = cam.project({0.0f, 0.5f, -5.0f});
    ASSERT_TRUE(p.has_value());
    EXPECT_EQ(int((*p)[1]), 3);
}

TEST(Camera, KnownPointsLandInTheExpectedPixels) {
    const Camera cam = make(BlenderCamera{}, looking_along_y());
    // The origin is straight ahead, 10 m away: the image centre.
    auto p = cam.project({0, 0, 0});
    ASSERT_TRUE(p.has_value());
    EXPECT_NEAR((*p)[0], 4.0f, 1e-4f);
    EXPECT_NEAR((*p)[1], 2.0f, 1e-4f);
    // World +X is to the right: slope 0.1, i.e. 0.1/0.36 of the half width.
    p = cam.project({1, 0, 0});
    ASSERT_TRUE(p.has_value());
    EXPECT_NEAR((*p)[0], 4.0f + 4.0f * 0.1f / 0.36f, 1e-4f);
    EXPECT_NEAR((*p)[1], 2.0f, 1e-4f);
    // World +Z is up.
    p = cam.project({0, 0, 0.5f});
    ASSERT_TRUE(p.has_value());
    EXPECT_NEAR((*p)[1], 2.0f + 2.0f * 0.05f / 0.18f, 1e-4f);
    EXPECT_EQ(int((*p)[0]), 4);
    EXPECT_EQ(int((*p)[1]), 2);
    // Behind the camera: no projection.
    EXPECT_FALSE(cam.project({0, -20, 0}).has_value());
    // The ray through the centre of that pixel passes close to the point.
    const CameraRay r = cam.ray_through_raster((*p)[0], (*p)[1]);
    EXPECT_NEAR(r.origin.y, -10.0f, 1e-5f);
    const Vec3 q = r.origin + r.direction * length(Vec3{0, 10, 0.5f});
    EXPECT_NEAR(q.x, 0.0f, 1e-4f);
    EXPECT_NEAR(q.z, 0.5f, 1e-4f);
}

TEST(Camera, ObjectScaleIsIgnored) {
    Mat4 scaled = looking_along_y();
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) scaled.m[r][c] *= 3.0f;
    const Camera a = make(BlenderCamera{}, looking_along_y());
    const Camera b = make(BlenderCamera{}, scaled);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x) {
            const CameraRay ra = a.generate_ray(x, y, 0.3f, 0.7f);
            const CameraRay rb = b.generate_ray(x, y, 0.3f, 0.7f);
            expect_dir(rb.direction, ra.direction);
            EXPECT_NEAR(rb.origin.y, ra.origin.y, 1e-6f);
        }
}

TEST(Camera, ShiftMovesTheFrameInUnitsOfTheSensor) {
    BlenderCamera bc;
    bc.shift_x = 0.25f;
    bc.shift_y = -0.1f;
    const Camera cam = make(bc);
    // Blender's shift is a fraction of the larger image side: slopes shift·sensor/lens.
    const CameraRay centre = cam.ray_through_raster(4.0f, 2.0f);
    expect_dir(centre.direction, {0.25f * 36.0f / 50.0f, -0.1f * 36.0f / 50.0f, -1.0f});
    const CameraRay corner = cam.ray_through_raster(8.0f, 4.0f);
    expect_dir(corner.direction, {0.18f + 0.36f, -0.072f + 0.18f, -1.0f});
}

TEST(Camera, SensorFitComesThroughTheCorners) {
    // Portrait 4 × 8, fit Vertical on a 24 mm sensor height: vertical half slope 12/50.
    BlenderCamera vertical;
    vertical.res_x = 4;
    vertical.res_y = 8;
    vertical.fit = Fit::Vertical;
    const Camera v = make(vertical);
    expect_dir(v.ray_through_raster(2.0f, 8.0f).direction, {0.0f, 0.24f, -1.0f});
    expect_dir(v.ray_through_raster(4.0f, 4.0f).direction, {0.12f, 0.0f, -1.0f});
    // Portrait with fit Auto: the larger side (height) spans the sensor WIDTH, 36 mm.
    BlenderCamera automatic = vertical;
    automatic.fit = Fit::Auto;
    const Camera a = make(automatic);
    expect_dir(a.ray_through_raster(2.0f, 8.0f).direction, {0.0f, 0.36f, -1.0f});
    expect_dir(a.ray_through_raster(4.0f, 4.0f).direction, {0.18f, 0.0f, -1.0f});
    // Landscape with fit Horizontal uses the width as well.
    BlenderCamera horizontal;
    horizontal.fit = Fit::Horizontal;
    const Camera h = make(horizontal);
    expect_dir(h.ray_through_raster(8.0f, 2.0f).direction, {0.36f, 0.0f, -1.0f});
}

TEST(Camera, OrthographicRaysAreParallel) {
    BlenderCamera bc;
    bc.ortho = true;
    const Camera cam = make(bc, Mat4::identity(), 0.5f, 100.0f);
    // ortho_scale 4 over 8 × 4 px: x ∈ [−2, 2], y ∈ [−1, 1], half a unit per pixel.
    const CameraRay r = cam.generate_ray(0, 0, 0.5f, 0.5f);
    EXPECT_NEAR(r.origin.x, -1.75f, 1e-6f);
    EXPECT_NEAR(r.origin.y, -0.75f, 1e-6f);
    EXPECT_NEAR(r.origin.z, -0.5f, 1e-6f);  // starts on the clip_start plane
    expect_dir(r.direction, {0, 0, -1});
    EXPECT_NEAR(r.tmax, 99.5f, 1e-4f);
    const CameraRay r2 = cam.generate_ray(7, 3, 0.5f, 0.5f);
    EXPECT_NEAR(r2.origin.x, 1.75f, 1e-6f);
    EXPECT_NEAR(r2.origin.y, 0.75f, 1e-6f);
    expect_dir(r2.direction, {0, 0, -1});
    // Shift moves the frame by shift × ortho_scale.
    bc.shift_x = 0.25f;
    const Camera shifted = make(bc);
    EXPECT_NEAR(shifted.generate_ray(0, 0, 0.5f, 0.5f).origin.x, -1.75f + 1.0f, 1e-6f);
    // Rotated: rays run along the camera's −Z, here world +Y.
    const Camera rotated = make(bc, looking_along_y());
    expect_dir(rotated.generate_ray(3, 1, 0.2f, 0.9f).direction, {0, 1, 0});
}

TEST(Camera, ProjectInvertsGenerateRay) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (bool ortho : {false, true}) {
        BlenderCamera bc;
        bc.ortho = ortho;
        bc.shift_x = 0.1f;
        bc.res_x = 13;
        bc.res_y = 7;
        const Camera cam = make(bc, looking_along_y());
        for (int i = 0; i < 200; ++i) {
            const int x = int(u(rng) * 13), y = int(u(rng) * 7);
            const float su = u(rng), sv = u(rng);
            const CameraRay r = cam.generate_ray(x, y, su, sv);
            const auto p = cam.project(r.origin + r.direction * (1.0f + 9.0f * u(rng)));
            ASSERT_TRUE(p.has_value());
            EXPECT_NEAR((*p)[0], x + su, 2e-3f);
            EXPECT_NEAR((*p)[1], y + sv, 2e-3f);
        }
    }
}

TEST(Camera, PerspectiveClippingIsPlanar) {
    const Camera cam = make(BlenderCamera{}, Mat4::identity(), 2.0f, 10.0f);
    const CameraRay r = cam.ray_through_raster(0.0f, 0.0f);  // the bottom-left corner
    EXPECT_NEAR((r.origin + r.direction * r.tmin).z, -2.0f, 1e-5f);
    EXPECT_NEAR((r.origin + r.direction * r.tmax).z, -10.0f, 1e-4f);
}

// The chord between the unit directions (0, 0, -depth) and (step, 0, -depth).
double chord(double step, double depth) {
    return std::sqrt(2.0 - 2.0 * depth / std::sqrt(step * step + depth * depth));
}

TEST(Camera, PerspectiveFootprintIsCyclesRayDifferential) {
    BlenderCamera bc;  // 50 mm on a 36 mm sensor, 8 x 4 px: square pixels of 1/8 of the frame
    const Camera cam = make(bc, looking_along_y(), 0.1f, 100.0f);
    const double depth = 0.5 * 50.0 / 18.0, step = 1.0 / 8.0;
    // At the image centre both steps move the direction by the chord of atan(step / depth).
    const CameraRay centre = cam.ray_through_raster(4.0f, 2.0f);
    EXPECT_NEAR(centre.spread, chord(step, depth), 1e-6);
    EXPECT_EQ(centre.footprint, 0.0f);  // from the eye: Cycles' dP is 0 there
    EXPECT_NEAR(centre.footprint_at(7.0f), 7.0 * chord(step, depth), 1e-5);
    // Elsewhere, the mean of the direction changes to the next pixel in x and in y, measured
    // on the world-space rays themselves.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 50; ++i) {
        const float rx = 7.0f * u(rng), ry = 3.0f * u(rng);
        const Vec3 d = cam.ray_through_raster(rx, ry).direction;
        const double dx = length(cam.ray_through_raster(rx + 1.0f, ry).direction - d);
        const double dy = length(cam.ray_through_raster(rx, ry + 1.0f).direction - d);
        EXPECT_NEAR(cam.ray_through_raster(rx, ry).spread, 0.5 * (dx + dy), 2e-6) << rx << " " << ry;
    }
    // Towards the corners a pixel subtends less: the spread falls off.
    EXPECT_LT(cam.ray_through_raster(0.0f, 0.0f).spread, centre.spread);
}

TEST(Camera, OrthographicFootprintIsOnePixelWide) {
    BlenderCamera bc;
    bc.ortho = true;
    const Camera cam = make(bc, looking_along_y(), 0.5f, 100.0f);
    const CameraRay r = cam.generate_ray(2, 5, 0.3f, 0.6f);
    EXPECT_NEAR(r.footprint, 4.0 / 8.0, 1e-7);  // ortho_scale 4 over 8 px
    EXPECT_EQ(r.spread, 0.0f);
    EXPECT_NEAR(r.footprint_at(50.0f), 0.5, 1e-7);
}

TEST(Camera, RefusesInvalidInput) {
    CameraDesc good;
    good.frame = view_frame(BlenderCamera{});
    good.width = 8;
    good.height = 4;
    ASSERT_TRUE(Camera::create(good).ok());

    auto expect_error = [](const CameraDesc &d, const std::string &needle) {
        const auto c = Camera::create(d);
        ASSERT_FALSE(c.ok()) << "expected an error mentioning " << needle;
        EXPECT_NE(c.error().message.find(needle), std::string::npos) << c.error().message;
    };
    CameraDesc d = good;
    d.camera_to_world.m[1][2] = NAN;
    expect_error(d, "finite");
    d = good;
    d.width = 0;
    expect_error(d, "width");
    d = good;
    std::swap(d.frame[0], d.frame[2]);  // wrong corner order
    expect_error(d, "order");
    d = good;
    for (auto &c : d.frame) c.z = 1.0f;  // behind the camera
    expect_error(d, "z < 0");
    d = good;
    d.frame[1].x += 0.2f;  // not a rectangle
    expect_error(d, "rectangle");
    d = good;
    for (int r = 0; r < 3; ++r) d.camera_to_world.m[r][0] = 0.0f;
    expect_error(d, "zero length");
    d = good;
    d.clip_start = 5.0f;
    d.clip_end = 1.0f;
    expect_error(d, "clip_end");
}

}  // namespace
}  // namespace hairis
