// Sensor faults, injected and detected, at the device boundary
// (device/haptic_device.h), for the extreme-case study (issue 5).
//
// A HapticDevice decorator, chained inside ClosedLoop as
//   servo_tick -> ReadingGuard (device/reading_guard.h) -> FaultInjector
//   -> SimDevice
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
// The detection is the device layer's ReadingGuard (device/reading_guard.h),
// which knows nothing of the injector.
//
// Angles are in the device convention (t1..t6, rad) throughout. Its
// read/write are noexcept and allocate nothing.
#ifndef VMHAPTICS_SIM_FAULT_INJECTOR_H_
#define VMHAPTICS_SIM_FAULT_INJECTOR_H_

#include <string>

#include "device/haptic_device.h"
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

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_FAULT_INJECTOR_H_
