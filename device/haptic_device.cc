#include "device/haptic_device.h"

namespace vmh {

const char* device_error_name(DeviceError e) {
  switch (e) {
    case DeviceError::kOk: return "ok";
    case DeviceError::kNotConnected: return "not_connected";
    case DeviceError::kIo: return "io";
    case DeviceError::kTimeout: return "timeout";
    case DeviceError::kSensorFault: return "sensor_fault";
    case DeviceError::kInvalidCommand: return "invalid_command";
  }
  return "unknown";
}

DeviceError HapticDevice::read_state(DeviceState* state) noexcept {
  const DeviceError e = read_joints(&state->q_device_rad);
  state->present = e == DeviceError::kOk ? kStateJoints : 0u;
  return e;
}

DeviceError HapticDevice::joints_of_state(Joints* q_device_rad) noexcept {
  DeviceState state;
  const DeviceError e = read_state(&state);
  if (e == DeviceError::kOk) *q_device_rad = state.q_device_rad;
  return e;
}

}  // namespace vmh
