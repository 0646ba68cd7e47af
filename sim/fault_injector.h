// Sensor faults, injected and detected, at the device boundary
// (controller/haptic_device.h), for the extreme-case study (issue 5).
//
// Two HapticDevice decorators, chained inside ClosedLoop as
//   servo_tick -> ReadingGuard -> FaultInjector -> SimDevice
//
// FaultInjector corrupts the readings of one joint from a given time on, the
// way a failing sensor would:
//   nan    the joint reads NaN (a broken read, a division by a zero pot sum)
//   jump   the joint reads kJumpCounts encoder counts too high from then on
//          (a count slip: the encoder's count is off and stays off)
//   stuck  the joint keeps reading the value it had when the fault began
//          (a stalled encoder or a frozen packet field)
// It does not detect anything.
//
// ReadingGuard is the detection, and knows nothing of the injector: it is
// what a device layer can check on the readings alone.
//   non-finite angle          -> kSensorFault, named "sensor_nan", for as
//                                long as the reading stays non-finite
//   an encoder (t1..t3) moving more in one servo period than a hand can
//   move it (max_speed_rad_s x max_period_s)
//                             -> kSensorFault, named "sensor_jump", latched
//                                until reset(): after a count slip the
//                                absolute angle is wrong for good, and the
//                                real Omni must be re-homed in its inkwell
// A stuck encoder is not detected: a joint held still by the hand reads
// exactly the same, so no check on the readings alone can tell the two
// apart without false alarms (the study reports it as undetected).
//
// Angles are in the device convention (t1..t6, rad) throughout. Both
// classes' read/write are noexcept and allocate nothing.
#ifndef VMHAPTICS_SIM_FAULT_INJECTOR_H_
#define VMHAPTICS_SIM_FAULT_INJECTOR_H_

#include <string>

#include "controller/haptic_device.h"
#include "controller/types.h"

namespace vmh::sim {

// a count slip of this many encoder counts (issue 5)
inline constexpr double kJumpCounts = 1000.0;

enum class SensorFaultKind { kNone, kNan, kJump, kStuck };
const char* sensor_fault_kind_name(SensorFaultKind k);  // none, nan, jump, stuck
bool parse_sensor_fault_kind(const std::string& text, SensorFaultKind* k);

struct FaultSpec {
  SensorFaultKind kind = SensorFaultKind::kNone;
  int joint = 0;        // 0-based device joint index (0 = t1 .. 5 = t6)
  double at_s = 0.0;    // the fault begins at the first read at t >= at_s
  // the size of a jump, rad: kJumpCounts on a 15000-count encoder
  double jump_rad = kJumpCounts * 2.0 * 3.14159265358979323846 / 15000.0;
};

class FaultInjector final : public HapticDevice {
 public:
  // `inner` is not owned and must outlive this. Throws std::invalid_argument
  // for a joint outside 0..5 or a non-finite time or jump.
  FaultInjector(HapticDevice* inner, const FaultSpec& spec);

  // the simulated time of the next read (the fault's clock)
  void set_time_s(double t_s) noexcept { t_s_ = t_s; }

  DeviceError read_joints(Joints* q_device_rad) noexcept override;
  DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override;

  // forgets the stuck value; the fault starts again at spec.at_s
  void reset() noexcept;

  // whether the last read was corrupted
  bool active() const noexcept { return active_; }
  // what the last read returned (NaN everywhere if the inner read failed)
  const Joints& last_reading() const noexcept { return last_; }
  const FaultSpec& spec() const noexcept { return spec_; }

 private:
  HapticDevice* inner_;
  FaultSpec spec_;
  double t_s_ = 0.0;
  bool active_ = false;
  bool have_stuck_ = false;
  double stuck_rad_ = 0.0;
  Joints last_ = Joints::Zero();
};

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

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_FAULT_INJECTOR_H_
