// The camera of a Blender scene, as the Hairis render engine receives it.
//
// Inputs, all in Blender's conventions:
//  - camera_to_world: the camera object's matrix_world, row-major (m[row][col], so the columns
//    are the camera's axes in world space and column 3 its position). The camera looks down
//    its local −Z axis with +Y up and +X to the right. Scale is removed (the axes are
//    normalised) as Blender does for render cameras (BKE_camera_multiview_model_matrix
//    normalises the matrix; Cycles takes that matrix).
//  - frame: the 4 corners that Camera.view_frame(scene=scene) returns, in camera space, in
//    Blender's order: top right, bottom right, bottom left, top left (BKE_camera_view_frame_ex
//    in blender/blenkernel/intern/camera.c). They already hold lens, sensor size and fit,
//    the render aspect and the shift. For a perspective camera they lie on a plane z = d < 0
//    (d = −lens/sensor for the fitted sensor axis, at drawsize 1) and only their directions
//    matter; for an orthographic camera only x and y matter (z = −1 there).
//  - width, height: the render resolution (after the percentage scale).
//
// Pixels: pixel (x, y) covers [x, x+1) × [y, y+1) in raster space, with y = 0 the BOTTOM row
// and x = 0 the left column: Blender's render buffers are stored bottom row first, so the
// image written by render() is too. The raster point (x + u, y + v), (u, v) ∈ [0, 1)², maps
// linearly onto the frame: raster (0, 0) is the bottom-left corner of the frame and
// (width, height) the top-right one. The pixel centre is (x + 0.5, y + 0.5), as in Cycles.
// Drawing (u, v) uniformly in [0, 1)² is a 1-pixel box filter; the path tracer draws them
// from Cycles' pixel filter (render/pixel_filter.h), which may reach beyond the pixel.
//
// Clipping as in Cycles (kernel/camera/camera.h): perspective rays start on the plane
// z = −clip_start and end on z = −clip_end (t is scaled by 1/cos of the angle to the view
// axis); orthographic rays start on the plane z = −clip_start and run clip_end − clip_start.
//
// Footprint: Cycles' compact ray differentials (kernel/camera/camera.h, util/differential.h).
// A perspective ray through camera-space point d (on the frame's plane) spreads by
// ½(|n(d + s_x) − n(d)| + |n(d + s_y) − n(d)|) per unit distance from the eye, with n() the
// normalization and s_x, s_y one pixel's steps across the frame in x and y; its footprint at
// distance t is that spread × t. An orthographic ray's footprint is one pixel's width in x
// (Cycles takes the x step for both axes) and does not grow.
#pragma once

#include <array>
#include <optional>

#include "core/expected.h"
#include "core/math.h"

namespace hairis {

/// A 4×4 affine matrix, row-major: m[row][col]. Points are columns: p' = M·(p, 1).
struct Mat4 {
    float m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};

    static Mat4 identity() { return {}; }
    /// From 16 floats in row-major order (what the C API passes).
    static Mat4 from_row_major(const float values[16]);
    /// A translation.
    static Mat4 translation(Vec3 t);

    /// Column c (0..3) as a vector: the image of axis c, or the translation for c = 3.
    Vec3 column(int c) const { return {m[0][c], m[1][c], m[2][c]}; }
    /// M·(p, 1), ignoring the last row (affine).
    Vec3 transform_point(Vec3 p) const;
    /// M·(v, 0).
    Vec3 transform_vector(Vec3 v) const;
    /// The product this·b.
    Mat4 operator*(const Mat4 &b) const;
    /// True when every entry is finite.
    bool finite() const;
};

/// Perspective (pinhole) or orthographic projection.
enum class Projection { Perspective = 0, Orthographic = 1 };

/// The camera as Blender describes it (see the file comment).
struct CameraDesc {
    Mat4 camera_to_world;
    Projection projection = Projection::Perspective;
    /// view_frame corners in camera space: top right, bottom right, bottom left, top left.
    std::array<Vec3, 4> frame{Vec3{0.5f, 0.5f, -1.0f}, Vec3{0.5f, -0.5f, -1.0f},
                              Vec3{-0.5f, -0.5f, -1.0f}, Vec3{-0.5f, 0.5f, -1.0f}};
    int width = 0;
    int height = 0;
    /// Blender's Clip Start and Clip End (metres), 0 ≤ clip_start < clip_end (clip_end may be
    /// infinite). The defaults do not clip.
    float clip_start = 0.0f;
    float clip_end = INFINITY;
};

/// A camera ray: points origin + t·direction for t in [tmin, tmax]; direction is unit length.
struct CameraRay {
    Vec3 origin;
    Vec3 direction;
    float tmin = 0;
    float tmax = INFINITY;
    /// Cycles' footprint radius (ray.dP) at the origin and its growth per unit t (ray.dD).
    float footprint = 0;
    float spread = 0;

    /// The footprint at origin + t·direction (Cycles' sd->dP of a hit at distance t).
    float footprint_at(float t) const { return footprint + spread * t; }
};

/// A validated camera that turns raster positions into rays.
class Camera {
  public:
    /// The largest width or height accepted.
    static constexpr int kMaxResolution = 65536;

    /// Refuses a non-finite or degenerate matrix (an axis of zero length), a frame that is not
    /// an axis-aligned rectangle with positive width and height (and, for a perspective camera,
    /// in front of the camera: z < 0), a resolution outside [1, kMaxResolution] and invalid
    /// clip distances. Errors name the field.
    static Expected<Camera> create(const CameraDesc &desc);

    int width() const { return width_; }
    int height() const { return height_; }
    Projection projection() const { return projection_; }
    /// The camera position in world space.
    Vec3 position() const { return to_world_.column(3); }
    /// The scale-free camera-to-world matrix actually used.
    const Mat4 &camera_to_world() const { return to_world_; }

    /// The ray through raster point (x + u, y + v): y = 0 is the bottom row, (u, v) ∈ [0, 1)²
    /// the position inside the pixel ((0.5, 0.5) is its centre).
    CameraRay generate_ray(int x, int y, float u, float v) const;
    /// The same for any raster point (rx, ry) ∈ [0, width] × [0, height].
    CameraRay ray_through_raster(float rx, float ry) const;

    /// Where a world point projects to, in raster coordinates (x right, y up, pixel (i, j)
    /// covers [i, i+1) × [j, j+1)); nullopt for a perspective camera when the point is not
    /// in front of it. Points outside the image give coordinates outside [0, w] × [0, h].
    std::optional<std::array<float, 2>> project(Vec3 world_point) const;

  private:
    Camera() = default;

    Mat4 to_world_;
    Mat4 to_camera_;  // the inverse (rigid: transpose of the rotation)
    Projection projection_ = Projection::Perspective;
    int width_ = 0, height_ = 0;
    float x0_ = 0, x1_ = 0, y0_ = 0, y1_ = 0;  // frame extent in camera space
    float depth_ = -1;                          // the frame's z (perspective)
    float clip_start_ = 0, clip_end_ = INFINITY;
};

}  // namespace hairis
