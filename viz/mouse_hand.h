// The mouse in the simulated hand's place: a drag on the viewer's window
// moves the hand's target in the view plane, or turns it.
//
// The camera is MuJoCo's free camera (mjvCamera: lookat, azimuth,
// elevation, distance; the vertical field of view is the model's
// vis.global.fovy). Its frame, as mjv_updateCamera builds it (MuJoCo 2.2.2,
// engine_vis_visualize.c), with a = azimuth, e = elevation:
//   forward = (cos e cos a, cos e sin a, sin e)
//   up      = (-sin e cos a, -sin e sin a, cos e)
//   right   = forward x up = (sin a, -cos a, 0)
//   eye     = lookat - distance * forward
// A pinhole camera with that field of view over a viewport of height H
// pixels sees, at depth z along forward, 2 z tan(fovy / 2) / H metres per
// pixel in both directions. So a drag of (dx, dy) pixels (y down, as window
// coordinates are) moves a point at the target's depth by
//   (dx right - dy up) * 2 z tan(fovy / 2) / H
// and the target follows the cursor.
//
// With the rotate modifier the drag turns the target's orientation instead:
// dx about the camera's up axis, dy about its right axis, rad_per_px each,
// about the target's own position.
//
// World = the DH base frame of the Omni model, metres. No OpenGL here.
#ifndef VMHAPTICS_VIZ_MOUSE_HAND_H_
#define VMHAPTICS_VIZ_MOUSE_HAND_H_

#include "controller/types.h"
#include "sim/hand.h"

namespace vmh::viz {

// MuJoCo's free camera, in the units the viewer reads from mjvCamera and
// the model.
struct ViewCamera {
  Vec3 lookat_m = Vec3::Zero();  // world (DH base) frame
  double azimuth_deg = 90.0;
  double elevation_deg = -45.0;
  double distance_m = 0.5;
  double fovy_deg = 45.0;  // vertical, the model's vis.global.fovy
};

// The camera's frame (world, unit vectors) and the eye's position (m).
struct CameraFrame {
  Vec3 eye_m = Vec3::Zero();
  Vec3 forward = Vec3::UnitX();
  Vec3 up = Vec3::UnitZ();
  Vec3 right = -Vec3::UnitY();
};
CameraFrame camera_frame(const ViewCamera& cam);

// Metres per pixel at the depth of `point_m` (along forward from the eye)
// on a viewport height_px tall. Throws std::invalid_argument for a
// height below 1 px or a point not in front of the camera.
double metres_per_pixel(const ViewCamera& cam, const Vec3& point_m,
                        int height_px);

// The move (world, m) that keeps a point at `point_m` under a cursor
// dragged by (dx_px, dy_px), window coordinates (y down).
Vec3 drag_translation_m(const ViewCamera& cam, int height_px,
                        const Vec3& point_m, double dx_px, double dy_px);

// The rotation (world frame) for a drag with the rotate modifier: dx_px
// about the camera's up axis, then dy_px about its right axis.
Mat3 drag_rotation(const ViewCamera& cam, double dx_px, double dy_px,
                   double rad_per_px);

inline constexpr double kDragRadPerPx = 0.01;

// One drag applied to the hand's target: moved (rotate = false) or turned
// about its own position (rotate = true). The target is left at rest (its
// velocity and angular velocity zero): the hand holds where the mouse put
// it.
void apply_drag(const ViewCamera& cam, int height_px, double dx_px,
                double dy_px, bool rotate, sim::HandTargetState* target);

}  // namespace vmh::viz

#endif  // VMHAPTICS_VIZ_MOUSE_HAND_H_
