// Helpers the virtual mechanisms share (controller/vm_*.cc): thresholds
// and small geometry. Internal to the controller library.
#ifndef VMHAPTICS_CONTROLLER_VM_COMMON_H_
#define VMHAPTICS_CONTROLLER_VM_COMMON_H_

#include <cmath>

#include "controller/trig.h"
#include "controller/types.h"

namespace vmh::vm_detail {

// below this fraction of L a direction is treated as undefined
inline constexpr double kDegenerateFraction = 1e-9;
// |sin| below which an axis is treated as lying on a pole
inline constexpr double kPoleSin = 1e-12;

// hypot(x, y) > t for t > 0, without hypot's care for overflow: the
// arguments here are lengths in mm or unit-vector components
inline bool above(double x, double y, double t) {
  return x * x + y * y > t * t;
}

inline double clamp_unit(double x) {
  return x < -1.0 ? -1.0 : (x > 1.0 ? 1.0 : x);
}

// any unit vector perpendicular to u
inline Vec3 perpendicular(const Vec3& u) {
  const Vec3 other = std::abs(u.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return u.cross(other).normalized();
}

// rotation about the local z axis
inline Mat3 rot_z(double a) {
  Mat3 R;
  const SinCos t = sin_cos(a);
  const double c = t.c, s = t.s;
  R << c, -s, 0, s, c, 0, 0, 0, 1;
  return R;
}

// The planar VMs' geometric orientation error (the circle, the line): the
// rotation about the plane's unit normal n from the stylus axis's
// projection onto the plane to the link axis u. Zero, and *ambiguous set,
// where the stylus stands along n.
inline Vec3 planar_orientation_error(const Vec3& n, const Vec3& stylus,
                                     const Vec3& u, bool* ambiguous) {
  const Vec3 a = stylus - stylus.dot(n) * n;
  if (ambiguous != nullptr) *ambiguous = false;
  if (!(a.norm() > kPoleSin)) {
    if (ambiguous != nullptr) *ambiguous = true;
    return Vec3::Zero();
  }
  return n * atan2_fast(n.dot(a.cross(u)), a.dot(u));
}

// The prediction hooks' helpers (controller/vm_registry.h)

// the unit direction of v, or false if it has (almost) none
inline bool unit_direction(const Vec3& v, Vec3* out) {
  const double n = v.norm();
  if (!(n > 1e-9)) return false;
  *out = v / n;
  return true;
}

// v less its part along the unit n
inline Vec3 project_out(const Vec3& v, const Vec3& n) {
  return v - v.dot(n) * n;
}

// the signed angle (rad) from a to b about the unit normal n
inline double angle_about(const Vec3& n, const Vec3& a, const Vec3& b) {
  return std::atan2(n.dot(a.cross(b)), a.dot(b));
}

inline constexpr const char* kOnPivotAxis =
    "the wrist centre or the stylus axis is on the VM's pivot axis, where "
    "the placement is not defined";

}  // namespace vmh::vm_detail

#endif  // VMHAPTICS_CONTROLLER_VM_COMMON_H_
