// OpenHaptics forward kinematics written out from its published form, as a
// reference that shares no code with controller/ (docs/sources.md §4).
// t are device (OpenHaptics) joint angles in rad, t3 the absolute forearm
// angle; results are in the device frame.
#ifndef VMHAPTICS_TESTS_SUPPORT_OPENHAPTICS_REFERENCE_H_
#define VMHAPTICS_TESTS_SUPPORT_OPENHAPTICS_REFERENCE_H_

#include <cmath>

#include "controller/types.h"

namespace vmh::testing {

// Wrist centre, mm (Ubitrack PhantomForwardKinematics, "Phantom Omni
// defaults" l1 = l2 = 133.35 mm).
inline Vec3 openhaptics_wrist_mm(const Joints& t, double l1_mm, double l2_mm) {
  const double reach = l1_mm * std::cos(t[1]) + l2_mm * std::sin(t[2]);
  return Vec3(-std::sin(t[0]) * reach,
              l2_mm - l2_mm * std::cos(t[2]) + l1_mm * std::sin(t[1]),
              std::cos(t[0]) * reach - l1_mm);
}

// Stylus rotation: the arm, RotY(-t1) RotX(-t3), then the gimbal as composed
// in Ubitrack's PhantomForwardKinematics, RotY(t4) RotX(-t5) RotZ(-t6).
inline Mat3 openhaptics_stylus_rotation(const Joints& t) {
  const auto rot = [](double a, const Vec3& axis) {
    return Eigen::AngleAxisd(a, axis).matrix();
  };
  return rot(-t[0], Vec3::UnitY()) * rot(-t[2], Vec3::UnitX()) *
         rot(t[3], Vec3::UnitY()) * rot(-t[4], Vec3::UnitX()) *
         rot(-t[5], Vec3::UnitZ());
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_OPENHAPTICS_REFERENCE_H_
