// The device interface: what the servo loop needs from a haptic device,
// whether it is the MuJoCo model (sim/SimDevice) or a real Omni (hw/).
//
// Conventions at this boundary are the device's own (OpenHaptics): joint
// angles t1..t6 in rad with t3 the absolute forearm angle, and torques on the
// three motors t1..t3 in N m. device_frame.h converts to the DH convention the
// controller works in.
//
// Real time: both calls are noexcept and return a DeviceError; an
// implementation must not allocate in them.
//
// This header is the device layer's interface alone: it needs only the
// controller's vector types. servo_tick.h joins it to the Controller.
#ifndef VMHAPTICS_DEVICE_HAPTIC_DEVICE_H_
#define VMHAPTICS_DEVICE_HAPTIC_DEVICE_H_

#include "controller/types.h"
#include "device/device_state.h"

namespace vmh {

// Errors at the device boundary, in the manner of libuvc's uvc_error_t.
enum class DeviceError : int {
  kOk = 0,
  kNotConnected,   // unplugged, powered off, or never opened
  kIo,             // a transfer failed
  kTimeout,        // no reading within the servo period
  kSensorFault,    // a reading that cannot be a joint angle (NaN, a jump)
  kInvalidCommand, // a non-finite torque was asked for; zero was sent
};

// "ok", "not_connected", "io", "timeout", "sensor_fault", "invalid_command"
const char* device_error_name(DeviceError e);

class HapticDevice {
 public:
  virtual ~HapticDevice() = default;

  // The six joint angles, device convention (t1..t6, rad). On an error
  // *q_device_rad is left unspecified.
  virtual DeviceError read_joints(Joints* q_device_rad) noexcept = 0;

  // Everything the device reports this tick (device/device_state.h), read
  // once. The default is read_joints() alone (present = kStateJoints);
  // backends with switches, a clock or their own kinematics override it,
  // and decorators forward it. On an error *state is left unspecified
  // apart from `present`, which is then 0.
  virtual DeviceError read_state(DeviceState* state) noexcept;

  // Torques for motors t1..t3 (N m), held until the next call (zero-order
  // hold). A non-finite entry must make the device send zero torque.
  virtual DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept = 0;

 protected:
  // read_joints() for a device whose own read is read_state() (the
  // decorators, the emulator, the backends): the joints of one read_state()
  DeviceError joints_of_state(Joints* q_device_rad) noexcept;
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_HAPTIC_DEVICE_H_
