#include "viz/mouse_hand.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace vmh::viz {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

}  // namespace

CameraFrame camera_frame(const ViewCamera& cam) {
  const double a = cam.azimuth_deg * kDegToRad;
  const double e = cam.elevation_deg * kDegToRad;
  CameraFrame f;
  f.forward = Vec3(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a),
                   std::sin(e));
  f.up = Vec3(-std::sin(e) * std::cos(a), -std::sin(e) * std::sin(a),
              std::cos(e));
  f.right = f.forward.cross(f.up);
  f.eye_m = cam.lookat_m - cam.distance_m * f.forward;
  return f;
}

double metres_per_pixel(const ViewCamera& cam, const Vec3& point_m,
                        int height_px) {
  if (height_px < 1) {
    throw std::invalid_argument("mouse hand: viewport height " +
                                std::to_string(height_px) +
                                " px (must be >= 1)");
  }
  const CameraFrame f = camera_frame(cam);
  const double depth_m = (point_m - f.eye_m).dot(f.forward);
  if (!(depth_m > 0.0)) {
    throw std::invalid_argument(
        "mouse hand: the dragged point is not in front of the camera "
        "(depth " + std::to_string(depth_m) + " m)");
  }
  return 2.0 * depth_m * std::tan(0.5 * cam.fovy_deg * kDegToRad) / height_px;
}

Vec3 drag_translation_m(const ViewCamera& cam, int height_px,
                        const Vec3& point_m, double dx_px, double dy_px) {
  const CameraFrame f = camera_frame(cam);
  const double s = metres_per_pixel(cam, point_m, height_px);
  // window y grows downwards, the camera's up upwards
  return s * (dx_px * f.right - dy_px * f.up);
}

Mat3 drag_rotation(const ViewCamera& cam, double dx_px, double dy_px,
                   double rad_per_px) {
  const CameraFrame f = camera_frame(cam);
  const Eigen::AngleAxisd about_up(dx_px * rad_per_px, f.up);
  const Eigen::AngleAxisd about_right(dy_px * rad_per_px, f.right);
  return (about_right * about_up).toRotationMatrix();
}

void apply_drag(const ViewCamera& cam, int height_px, double dx_px,
                double dy_px, bool rotate, sim::HandTargetState* target) {
  if (rotate) {
    const Mat3 R = drag_rotation(cam, dx_px, dy_px, kDragRadPerPx) * target->R;
    // re-orthonormalise: many small drags would let rounding accumulate
    target->R = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  } else {
    target->p_m += drag_translation_m(cam, height_px, target->p_m, dx_px, dy_px);
  }
  target->v_m_s.setZero();
  target->w_rad_s.setZero();
}

}  // namespace vmh::viz
