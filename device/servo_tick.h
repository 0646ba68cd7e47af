// servo_tick(): one tick of the servo loop, the same on the simulator and on
// a real device. It is the only place where the device layer meets the
// controller.
#ifndef VMHAPTICS_DEVICE_SERVO_TICK_H_
#define VMHAPTICS_DEVICE_SERVO_TICK_H_

#include "controller/controller.h"
#include "device/haptic_device.h"

namespace vmh {

// What one servo tick did.
struct ServoTickResult {
  DeviceError read = DeviceError::kOk;
  DeviceError write = DeviceError::kOk;
  ControlStatus control = kStatusOk;
  // true when the controller's torque did not go out: zero was sent in its
  // place (a failed read, a controller fault), or the write itself failed
  // (then `write` says why, and what the motors hold is up to the device)
  bool zeroed = false;
};

// One servo tick, the same on the simulator and the device: read the joints,
// convert them to the DH convention, run the controller, and write its motor
// torques, or zero torque if the read failed or the controller reports a
// fault. *out holds the controller's output (untouched if the read failed).
// Never throws or allocates.
ServoTickResult servo_tick(HapticDevice* device, Controller* controller,
                           ControlOutput* out) noexcept;

// The same, reading the device's whole state (HapticDevice::read_state)
// into *state for the caller to record (buttons, inkwell, timestamp, the
// device's own kinematics). *state has present = 0 after a failed read.
ServoTickResult servo_tick(HapticDevice* device, Controller* controller,
                           ControlOutput* out, DeviceState* state) noexcept;

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_SERVO_TICK_H_
