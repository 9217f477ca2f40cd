// Test helper: the cameras and lights that the render tests share.
#pragma once

#include "core/math.h"
#include "render/camera.h"
#include "render/scene.h"

namespace hairis::testing {

/// An orthographic camera at `position` looking down −Z onto a half_x × half_y window, with
/// w × h pixels.
inline CameraDesc ortho_down(float half_x, float half_y, int w, int h,
                             Vec3 position = {0, 0, 5}) {
    CameraDesc c;
    c.camera_to_world = Mat4::translation(position);
    c.projection = Projection::Orthographic;
    c.frame = {Vec3{half_x, half_y, -1}, Vec3{half_x, -half_y, -1}, Vec3{-half_x, -half_y, -1},
               Vec3{-half_x, half_y, -1}};
    c.width = w;
    c.height = h;
    return c;
}

/// Makes a sun towards `to_sun` (strength in W/m², angular diameter in radians) the scene's only
/// sun.
inline void set_sun(SceneDesc &d, Vec3 to_sun, float strength, float angle = 0.0f) {
    SunLight sun;
    sun.to_sun = to_sun;
    sun.strength = strength;
    sun.angle = angle;
    d.suns = {sun};
}

}  // namespace hairis::testing
