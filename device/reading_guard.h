// The reading guard: a plausibility check on a device's joint readings, the
// part of fault detection a device layer can do on the readings alone. It is
// a HapticDevice decorator, so it sits between servo_tick and any device,
// simulated (sim/) or real (hw/):
//   servo_tick -> ReadingGuard -> device
//
//   non-finite angle          -> kSensorFault, named "sensor_nan", for as
//                                long as the reading stays non-finite
//   an encoder (t1..t3) moving more in one servo period than a hand can
//   move it (max_speed_rad_s x max_period_s)
//                             -> kSensorFault, named "sensor_jump", latched
//                                until reset() or a reading that says the
//                                device re-homed (DeviceState::rehomed):
//                                after a count slip the absolute angle is
//                                wrong until the Omni is re-homed in its
//                                inkwell, and a re-homed reading may step
// A stuck encoder is not detected: a joint held still by the hand reads
// exactly the same, so no check on the readings alone can tell the two
// apart without false alarms (the study reports it as undetected).
//
// Angles are in the device convention (t1..t6, rad). read/write are
// noexcept and allocate nothing.
#ifndef VMHAPTICS_DEVICE_READING_GUARD_H_
#define VMHAPTICS_DEVICE_READING_GUARD_H_

#include "controller/types.h"
#include "device/haptic_device.h"

namespace vmh {

enum class GuardFault { kNone, kNonFinite, kJump };
const char* guard_fault_name(GuardFault f);  // none, sensor_nan, sensor_jump

struct GuardParams {
  bool enabled = true;
  // the fastest a hand can turn an actuated joint of the Omni, rad/s: an
  // estimate with a wide margin (a 2 m/s flick of the wrist centre at the
  // 0.133 m lever is 15 rad/s). A 1000-count slip is 0.42 rad: 419 rad/s
  // over a 1 ms period, 150 rad/s over the longest jittered one (2.8 ms)
  double max_speed_rad_s = 50.0;
  // the longest servo period the loop may run at, s (the nominal period, or
  // the longest jittered one)
  double max_period_s = 1e-3;
};

class ReadingGuard final : public HapticDevice {
 public:
  // `inner` is not owned and must outlive this. Throws std::invalid_argument
  // for a non-positive or non-finite speed or period.
  ReadingGuard(HapticDevice* inner, const GuardParams& params);

  DeviceError read_joints(Joints* q_device_rad) noexcept override;
  // the inner device's state, refused (present = 0, kSensorFault) when its
  // joint angles fail the checks; the other fields pass through
  DeviceError read_state(DeviceState* state) noexcept override;
  DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override;

  // clears the latch and the previous reading (re-homing)
  void reset() noexcept;

  // what the last read found (kNone when it passed or the guard is off)
  GuardFault last_fault() const noexcept { return fault_; }
  bool latched() const noexcept { return latched_; }
  // the largest accepted change of t1..t3 in one read, rad
  double max_step_rad() const noexcept { return max_step_rad_; }

 private:
  HapticDevice* inner_;
  GuardParams params_;
  double max_step_rad_;
  bool have_previous_ = false;
  bool latched_ = false;
  GuardFault fault_ = GuardFault::kNone;
  Joints previous_ = Joints::Zero();
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_READING_GUARD_H_
