#include "device/servo_tick.h"

#include "controller/device_frame.h"

namespace vmh {

ServoTickResult servo_tick(HapticDevice* device, Controller* controller,
                           ControlOutput* out) noexcept {
  DeviceState state;
  return servo_tick(device, controller, out, &state);
}

ServoTickResult servo_tick(HapticDevice* device, Controller* controller,
                           ControlOutput* out, DeviceState* state) noexcept {
  ServoTickResult r;
  r.read = device->read_state(state);
  if (r.read != DeviceError::kOk) {
    state->present = 0;
    // nothing trustworthy to act on: zero torque, and forget the error rate
    // so that the next good reading does not produce a derivative kick
    controller->reset();
    r.zeroed = true;
    r.write = device->write_motor_torques(Vec3::Zero());
    return r;
  }
  r.control = controller->tick(device_to_dh_joints(state->q_device_rad), out);
  // the controller already zeroes its output on a fault; say so explicitly
  const Vec3 tau = is_fault(r.control) ? Vec3::Zero() : out->tau_motor_Nm;
  r.zeroed = is_fault(r.control);
  r.write = device->write_motor_torques(tau);
  if (r.write != DeviceError::kOk) r.zeroed = true;
  return r;
}

}  // namespace vmh
