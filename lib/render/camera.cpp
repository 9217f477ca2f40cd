#include "render/camera.h"

#include <cmath>
#include <sstream>
#include <string>

namespace hairis {

Mat4 Mat4::from_row_major(const float values[16]) {
    Mat4 r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) r.m[i][j] = values[4 * i + j];
    return r;
}

Mat4 Mat4::translation(Vec3 t) {
    Mat4 r;
    r.m[0][3] = t.x;
    r.m[1][3] = t.y;
    r.m[2][3] = t.z;
    return r;
}

Vec3 Mat4::transform_point(Vec3 p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
}

Vec3 Mat4::transform_vector(Vec3 v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

Mat4 Mat4::operator*(const Mat4 &b) const {
    Mat4 r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            float s = 0;
            for (int k = 0; k < 4; ++k) s += m[i][k] * b.m[k][j];
            r.m[i][j] = s;
        }
    return r;
}

bool Mat4::finite() const {
    for (const auto &row : m)
        for (float v : row)
            if (!std::isfinite(v)) return false;
    return true;
}

namespace {

std::string describe(Vec3 v) {
    std::ostringstream out;
    out.precision(6);
    out << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return out.str();
}

// The inverse of an affine matrix whose 3×3 part is invertible; false when it is singular.
bool invert_affine(const Mat4 &a, Mat4 &inv) {
    const double m00 = a.m[0][0], m01 = a.m[0][1], m02 = a.m[0][2];
    const double m10 = a.m[1][0], m11 = a.m[1][1], m12 = a.m[1][2];
    const double m20 = a.m[2][0], m21 = a.m[2][1], m22 = a.m[2][2];
    const double c00 = m11 * m22 - m12 * m21, c01 = m02 * m21 - m01 * m22,
                 c02 = m01 * m12 - m02 * m11;
    const double det = m00 * c00 + m10 * c01 + m20 * c02;
    if (!(std::fabs(det) > 1e-12)) return false;
    const double s = 1.0 / det;
    double r[3][3] = {{c00 * s, c01 * s, c02 * s},
                      {(m12 * m20 - m10 * m22) * s, (m00 * m22 - m02 * m20) * s,
                       (m02 * m10 - m00 * m12) * s},
                      {(m10 * m21 - m11 * m20) * s, (m01 * m20 - m00 * m21) * s,
                       (m00 * m11 - m01 * m10) * s}};
    inv = Mat4{};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) inv.m[i][j] = float(r[i][j]);
        inv.m[i][3] = -float(r[i][0] * a.m[0][3] + r[i][1] * a.m[1][3] + r[i][2] * a.m[2][3]);
    }
    return true;
}

}  // namespace

Expected<Camera> Camera::create(const CameraDesc &desc) {
    if (!desc.camera_to_world.finite())
        return Error{"camera: camera_to_world must be finite (it holds NaN or infinity)"};
    if (auto e = check::count_in_range("camera: width", desc.width, 1, kMaxResolution)) return *e;
    if (auto e = check::count_in_range("camera: height", desc.height, 1, kMaxResolution))
        return *e;
    if (!(desc.clip_start >= 0.0f) || !std::isfinite(desc.clip_start))
        return Error{"camera: clip_start must be finite and >= 0 (got " +
                     std::to_string(desc.clip_start) + ")"};
    if (!(desc.clip_end > desc.clip_start))
        return Error{"camera: clip_end must be greater than clip_start (got " +
                     std::to_string(desc.clip_end) + " <= " + std::to_string(desc.clip_start) +
                     ")"};

    Camera cam;
    cam.projection_ = desc.projection;
    cam.width_ = desc.width;
    cam.height_ = desc.height;
    cam.clip_start_ = desc.clip_start;
    cam.clip_end_ = desc.clip_end;

    // Remove the scale: normalise the three axes, as Blender does for render cameras.
    cam.to_world_ = desc.camera_to_world;
    for (int c = 0; c < 3; ++c) {
        const Vec3 axis = desc.camera_to_world.column(c);
        const float len = length(axis);
        if (!(len > 1e-12f))
            return Error{"camera: camera_to_world axis " + std::to_string(c) +
                         " has zero length (a degenerate matrix)"};
        for (int r = 0; r < 3; ++r) cam.to_world_.m[r][c] = desc.camera_to_world.m[r][c] / len;
    }
    cam.to_world_.m[3][0] = cam.to_world_.m[3][1] = cam.to_world_.m[3][2] = 0.0f;
    cam.to_world_.m[3][3] = 1.0f;
    if (!invert_affine(cam.to_world_, cam.to_camera_))
        return Error{"camera: camera_to_world is singular (its axes are coplanar)"};

    // The frame: Blender's order is top right, bottom right, bottom left, top left.
    const auto &f = desc.frame;
    for (int i = 0; i < 4; ++i)
        if (!std::isfinite(f[i].x) || !std::isfinite(f[i].y) || !std::isfinite(f[i].z))
            return Error{"camera: frame corner " + std::to_string(i) + " must be finite (got " +
                         describe(f[i]) + ")"};
    const float x1 = f[0].x, x0 = f[2].x, y1 = f[0].y, y0 = f[2].y;
    if (!(x1 > x0) || !(y1 > y0))
        return Error{"camera: frame must list view_frame's corners in Blender's order (top right, "
                     "bottom right, bottom left, top left) with a positive width and height; got "
                     "top right " + describe(f[0]) + " and bottom left " + describe(f[2])};
    const float tol = 1e-4f * std::max({x1 - x0, y1 - y0, std::fabs(f[0].z), 1e-6f});
    const bool rectangle = std::fabs(f[1].x - x1) <= tol && std::fabs(f[1].y - y0) <= tol &&
                           std::fabs(f[3].x - x0) <= tol && std::fabs(f[3].y - y1) <= tol;
    if (!rectangle)
        return Error{"camera: frame corners do not form an axis-aligned rectangle in Blender's "
                     "order (top right, bottom right, bottom left, top left): " +
                     describe(f[0]) + " " + describe(f[1]) + " " + describe(f[2]) + " " +
                     describe(f[3])};
    if (desc.projection == Projection::Perspective) {
        const float z = f[0].z;
        if (!(z < 0.0f))
            return Error{"camera: a perspective frame must lie in front of the camera (z < 0; got "
                         "z = " + std::to_string(z) + ")"};
        for (int i = 1; i < 4; ++i)
            if (std::fabs(f[i].z - z) > tol)
                return Error{"camera: the frame corners of a perspective camera must share one z "
                             "(got " + std::to_string(z) + " and " + std::to_string(f[i].z) +
                             ")"};
        cam.depth_ = z;
    } else if (desc.projection != Projection::Orthographic) {
        return Error{"camera: projection must be Perspective (0) or Orthographic (1)"};
    }
    cam.x0_ = x0;
    cam.x1_ = x1;
    cam.y0_ = y0;
    cam.y1_ = y1;
    return cam;
}

CameraRay Camera::ray_through_raster(float rx, float ry) const {
    const float cx = x0_ + (x1_ - x0_) * (rx / float(width_));
    const float cy = y0_ + (y1_ - y0_) * (ry / float(height_));
    CameraRay ray;
    if (projection_ == Projection::Perspective) {
        const Vec3 d_cam{cx, cy, depth_};
        const float len = length(d_cam);
        const float inv_cos = len / -depth_;  // 1 / cos(angle to the view axis)
        ray.origin = position();
        ray.direction = safe_normalize(to_world_.transform_vector(d_cam));
        ray.tmin = clip_start_ * inv_cos;
        ray.tmax = clip_end_ * inv_cos;
        // The change of the unit direction over one pixel in x and in y (camera space: the
        // rotation to world space keeps lengths).
        const float sx = (x1_ - x0_) / float(width_), sy = (y1_ - y0_) / float(height_);
        const Vec3 n = d_cam * (1.0f / len);
        ray.spread = 0.5f * (length(safe_normalize(d_cam + Vec3{sx, 0, 0}) - n) +
                             length(safe_normalize(d_cam + Vec3{0, sy, 0}) - n));
    } else {
        ray.origin = to_world_.transform_point({cx, cy, -clip_start_});
        ray.direction = safe_normalize(to_world_.transform_vector({0, 0, -1}));
        ray.tmin = 0.0f;
        ray.tmax = clip_end_ - clip_start_;
        ray.footprint = (x1_ - x0_) / float(width_);
    }
    return ray;
}

CameraRay Camera::generate_ray(int x, int y, float u, float v) const {
    return ray_through_raster(float(x) + u, float(y) + v);
}

std::optional<std::array<float, 2>> Camera::project(Vec3 world_point) const {
    const Vec3 p = to_camera_.transform_point(world_point);
    float cx = p.x, cy = p.y;
    if (projection_ == Projection::Perspective) {
        if (!(p.z < 0.0f)) return std::nullopt;
        const float s = depth_ / p.z;
        cx *= s;
        cy *= s;
    }
    return std::array<float, 2>{(cx - x0_) / (x1_ - x0_) * float(width_),
                                (cy - y0_) / (y1_ - y0_) * float(height_)};
}

}  // namespace hairis
