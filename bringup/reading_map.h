// How a device's reported joint angles may differ from the true ones by a
// wiring or codec mistake: a sign flipped, two channels swapped. compare's
// kinematics finds the map that makes the project's FK agree with the
// device's own transform; force direction and the Jacobian check then read
// the recording through it, so that one mistake is named once.
//
// Device convention (t1..t6, t3 absolute; controller/device_frame.h):
// reported[i] = sign[i] * true[perm[i]].
#ifndef VMHAPTICS_BRINGUP_READING_MAP_H_
#define VMHAPTICS_BRINGUP_READING_MAP_H_

#include <array>
#include <string>

#include "controller/types.h"

namespace vmh::bringup {

struct ReadingMap {
  std::array<int, 6> perm{0, 1, 2, 3, 4, 5};
  std::array<double, 6> sign{1, 1, 1, 1, 1, 1};
  // the fault's name in compare's vocabulary ("" for the identity):
  // "joint1_sign", "gimbal_swap", ...
  std::string name;

  bool is_identity() const { return name.empty(); }
  // the true device angles from the reported ones (the map inverted)
  Joints true_from_reported(const Joints& reported_device_rad) const {
    Joints t;
    for (int i = 0; i < 6; ++i) t[perm[i]] = sign[i] * reported_device_rad[i];
    return t;
  }
  Joints reported_from_true(const Joints& true_device_rad) const {
    Joints r;
    for (int i = 0; i < 6; ++i) r[i] = sign[i] * true_device_rad[perm[i]];
    return r;
  }
};

}  // namespace vmh::bringup

#endif  // VMHAPTICS_BRINGUP_READING_MAP_H_
