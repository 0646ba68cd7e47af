// A HapticDevice whose readings a test sets and which records what it was
// told, for the device layer's decorators (reading guard, fault injector).
#ifndef VMHAPTICS_TESTS_SUPPORT_SCRIPTED_DEVICE_H_
#define VMHAPTICS_TESTS_SUPPORT_SCRIPTED_DEVICE_H_

#include "controller/types.h"
#include "device/haptic_device.h"
#include "tests/support/constants.h"

namespace vmh::testing {

inline constexpr double kCount = 2.0 * kPi / 15000.0;  // one encoder count, rad

// A device whose readings the test sets, and which records what it was told.
class ScriptedDevice final : public HapticDevice {
 public:
  Joints q = Joints::Zero();
  DeviceError read_error = DeviceError::kOk;
  Vec3 written = Vec3::Constant(-1.0);
  int writes = 0;

  DeviceError read_joints(Joints* out) noexcept override {
    if (read_error != DeviceError::kOk) return read_error;
    *out = q;
    return DeviceError::kOk;
  }
  DeviceError write_motor_torques(const Vec3& tau) noexcept override {
    written = tau;
    ++writes;
    return DeviceError::kOk;
  }
};

inline Joints ramp(double t_s) {
  // every joint moving at a plausible 1 rad/s, from different offsets
  Joints q;
  for (int i = 0; i < 6; ++i) q[i] = 0.1 * i + t_s;
  return q;
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_SCRIPTED_DEVICE_H_
