// The safety layer: the output limits a haptic device must enforce whatever
// the controller asks for, modelled on the limits OpenHaptics enforces and
// reports (docs/sources.md §9.1: HD_EXCEEDED_MAX_FORCE, ..._FORCE_IMPULSE,
// ..._VELOCITY, HD_WARM_MOTORS, HD_COMM_ERROR). It is a HapticDevice
// decorator, like the reading guard:
//   servo_tick -> SafetyLayer -> ReadingGuard -> device
//
// On every write, in this order (docs/safety.md gives each one's numbers):
//   cuts (zero torque, at once, bypassing the impulse limit): force output
//     off, no valid reading this tick, a non-finite command, communication
//     lost, docked in the inkwell, dead-man released, tip or joint velocity
//     over its limit, a motor hot;
//   clamps keeping direction: one factor on all three motors so that no
//     motor exceeds its torque limit and the force at the wrist centre does
//     not exceed max_force_N;
//   thermal derating (one factor, from the warmest motor), the force ramp;
//   the force-impulse limit: a rate limiter on the motor torques whose bound
//     is the change of wrist-centre force it causes at the current pose;
//   a final clamp, so the limits hold after the rate limiter too.
// After any cut clears, the ramp starts again from zero.
//
// Frames and units: joint angles in the device convention (t1..t6, rad);
// motor torques t1..t3 in N m; forces in N in the device frame (the norm is
// the same in the DH base frame); positions in m in the DH base frame.
//
// Time: no clock is read here. Each read is servo_period_s after the last
// unless the caller stamps it with set_read_time(); a watchdog check is
// given its time explicitly. read/write are noexcept and allocate nothing.
// Not thread-safe: a device thread that services the watchdog must
// serialise that call with the servo tick.
#ifndef VMHAPTICS_DEVICE_SAFETY_H_
#define VMHAPTICS_DEVICE_SAFETY_H_

#include <array>
#include <cstdint>

#include "controller/omni_params.h"
#include "controller/types.h"
#include "device/haptic_device.h"

namespace vmh {

// Status bits of the safety layer, one per limit. Names after OpenHaptics's
// error list where it has one (in brackets).
enum SafetyFlag : std::uint32_t {
  kSafetyOk = 0,
  kSafetyForceClamped = 1u << 0,         // [EXCEEDED_MAX_FORCE]
  kSafetyTorqueClamped = 1u << 1,        // a motor's torque limit
  kSafetyForceRamping = 1u << 2,         // [FORCE_RAMPING]
  kSafetyForceImpulseLimited = 1u << 3,  // [EXCEEDED_MAX_FORCE_IMPULSE]
  kSafetyVelocityExceeded = 1u << 4,     // [EXCEEDED_MAX_VELOCITY] cut
  kSafetyMotorWarm = 1u << 5,            // [WARM_MOTORS] derating
  kSafetyMotorHot = 1u << 6,             // cut until cooled
  kSafetyWatchdogExpired = 1u << 7,      // servo stalled; zero was sent
  kSafetyCommLost = 1u << 8,             // [COMM_ERROR] cut, latched
  kSafetyDocked = 1u << 9,               // in the inkwell: cut
  kSafetyDeadmanReleased = 1u << 10,     // cut (when required)
  kSafetyForceOutputOff = 1u << 11,      // [FORCE_OUTPUT disabled] cut
  kSafetyNoReading = 1u << 12,           // no valid reading this tick: cut
  kSafetyInvalidCommand = 1u << 13,      // non-finite torque: cut
};
using SafetyStatus = std::uint32_t;
inline constexpr int kSafetyFlagCount = 14;
// the flags under which the layer sends zero torque
inline constexpr SafetyStatus kSafetyCuts =
    kSafetyVelocityExceeded | kSafetyMotorHot | kSafetyWatchdogExpired |
    kSafetyCommLost | kSafetyDocked | kSafetyDeadmanReleased |
    kSafetyForceOutputOff | kSafetyNoReading | kSafetyInvalidCommand;

// Name of one flag: "ok", "force_clamped", "torque_clamped", "force_ramping",
// "force_impulse_limited", "velocity_exceeded", "motor_warm", "motor_hot",
// "watchdog_expired", "comm_lost", "docked", "deadman_released",
// "force_output_off", "no_reading", "invalid_command"; "unknown" otherwise.
const char* safety_flag_name(SafetyStatus flag);

// Every limit's parameter. [§n] cites docs/sources.md; "estimate" marks a
// value no public source gives (docs/safety.md gives the reasoning).
struct SafetyParams {
  // nominal servo period, s: 1 kHz [§6]
  double servo_period_s = 1e-3;

  // -- clamps --
  // force at the wrist centre, N: the Omni's peak force [§7]
  double max_force_N = 3.3;
  // motors t1..t3, N m: OmniParams' (the OpenHaptics samples' clamps [§7]);
  // the limits derived from the rated force are
  // motor_torque_limits_Nm(omni, TorqueLimits::kRated)
  std::array<double, kOmniActuated> motor_torque_limit_Nm =
      OmniParams{}.motor_torque_limit_Nm;
  // regularisation of J_v J_v^T when turning torques into a force, m
  // (damped least squares). It changes the force by about
  // (damping / sigma_min)^2 relative, sigma_min the smallest singular value
  // of J_v: under 1e-7 where sigma_min > 0.03 m. A choice, not a rating.
  double singular_damping_m = 1e-5;

  // -- force ramp [OpenHaptics FORCE_RAMPING; its rate is not published] --
  // time for the torque scale to rise from 0 to 1, s; 0: no ramp. Estimate.
  double ramp_s = 0.5;

  // -- force impulse --
  // largest change of wrist-centre force per tick, N: a 700 N/m wall [§7,
  // CHAI3D's Omni stiffness] entered at 0.14 m/s. Estimate.
  double max_force_step_N = 0.1;

  // -- velocity (the HD software velocity limit's value is not published) --
  // wrist-centre speed, m/s: cut above max, resume below resume. Estimate.
  double max_tip_speed_m_s = 1.5;
  double resume_tip_speed_m_s = 1.0;
  // speed of each actuated joint t1..t3, rad/s. Estimate (12 rad/s is
  // 1.6 m/s at the 0.133 m links).
  double max_joint_speed_rad_s = 12.0;
  double resume_joint_speed_rad_s = 8.0;

  // -- I^2 t thermal model, per motor (derivation in docs/safety.md) --
  // the force the motors must sustain forever, N [§7 continuous force]; at
  // the nominal pose (DH q = 0, arms orthogonal) its worst direction sets
  // each motor's continuous torque, the unit of the thermal state
  double continuous_force_N = 0.88;
  // first-order thermal time constant, s. Estimate (small DC motors).
  double thermal_time_constant_s = 30.0;
  // thermal state levels, in units of (continuous torque)^2: derate above
  // warn, cut at cut, resume once every motor is below resume
  double thermal_warn = 1.2;
  double thermal_cut = 2.0;
  double thermal_resume = 1.0;
  // torque factor reached at the cut level (1 at warn, linear between)
  double derate_at_cut = 0.5;

  // -- communication --
  // failed reads in a row that declare the link lost, and good reads in a
  // row that restore it. Estimates.
  int comm_lost_reads = 3;
  int comm_resume_reads = 50;

  // -- watchdog: servo periods without a kick before it expires. Estimate.
  int watchdog_periods = 10;

  // -- dead-man: cut force unless the button is held (from the device's
  // buttons, the bits of deadman_buttons, any of them; or set_inputs())
  bool require_deadman = false;
  std::uint32_t deadman_buttons = kButton1;

  // Throws std::invalid_argument naming the first bad field.
  void validate() const;
};

// Expires when no kick() came for `periods` servo periods. Not armed (never
// expired) before the first kick. The caller supplies every time stamp.
class ServoWatchdog {
 public:
  // throws std::invalid_argument for a non-positive period or count
  ServoWatchdog(double servo_period_s, int periods);
  void kick(double now_s) noexcept;
  bool expired(double now_s) const noexcept;
  bool armed() const noexcept { return armed_; }
  void disarm() noexcept { armed_ = false; }
  double timeout_s() const noexcept { return timeout_s_; }

 private:
  double timeout_s_;
  double last_kick_s_ = 0.0;
  bool armed_ = false;
};

class SafetyLayer final : public HapticDevice {
 public:
  // `inner` is not owned and must outlive this. Throws std::invalid_argument
  // (params.validate(), omni.validate(), or no device).
  SafetyLayer(HapticDevice* inner, const SafetyParams& params,
              const OmniParams& omni = OmniParams());

  DeviceError read_joints(Joints* q_device_rad) noexcept override;
  // The inner device's state. Its inkwell switch and buttons (where
  // present) feed the docked and dead-man cuts, and its timestamp the time
  // step, unless set_read_time() stamped this read.
  DeviceError read_state(DeviceState* state) noexcept override;
  // Sends the limited torque. Returns the inner device's error, or
  // kInvalidCommand for a non-finite command (zero is then sent).
  DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override;

  // Time of the next read, s (any monotonic clock). Without it a read is
  // one servo period after the last. Also the watchdog's kick time.
  void set_read_time(double now_s) noexcept;

  // Inkwell switch and dead-man button, for a device that does not report
  // them in its DeviceState (a report, when present, overrides these).
  void set_inputs(bool docked, bool deadman_pressed) noexcept;

  // Force output on/off (OpenHaptics HD_FORCE_OUTPUT). On at construction;
  // turning it on (and construction) starts the ramp.
  void set_force_output(bool on) noexcept;

  // For the device thread: if no servo tick kicked the watchdog for
  // watchdog_periods periods, sends zero torque to the inner device, flags
  // watchdog_expired (cleared by the next good read, which restarts the
  // ramp) and returns true. Call it from the thread that owns the device.
  bool service_watchdog(double now_s) noexcept;
  const ServoWatchdog& watchdog() const noexcept { return watchdog_; }

  // Status of the last read and write (flags of this tick)
  SafetyStatus status() const noexcept { return status_; }
  // The torque last sent to the inner device, N m
  const Vec3& last_torque_Nm() const noexcept { return tau_prev_; }
  // Thermal state per motor, (continuous torque)^2 units, as of the last
  // read (each read adds the interval since the previous one, over which
  // the motors held the last torque sent)
  const Vec3& thermal_state() const noexcept { return heat_; }
  // Each motor's continuous torque, N m (the thermal model's unit)
  const Vec3& continuous_torque_Nm() const noexcept { return tau_cont_; }
  // Torque scale of the ramp used at the last write
  double ramp_scale() const noexcept { return ramp_scale_; }
  // Speeds measured at the last read (0 when there was nothing to compare)
  double tip_speed_m_s() const noexcept { return tip_speed_; }
  double joint_speed_rad_s() const noexcept { return joint_speed_; }
  // Device-frame force (N) at the wrist centre that motor torques make at
  // the pose of the last good read (zero before the first one)
  Vec3 force_device_N(const Vec3& tau_motor_Nm) const noexcept;

 private:
  // read_state's steps. The time step since the last read, dt_s_: between
  // the caller's stamps, else the device's own clock (a `good` reading's),
  // else one servo period
  void advance_clock(bool good, const DeviceState& state) noexcept;
  // a failed read: no reading and no previous one to take a velocity from,
  // one more failure toward comm_lost; returns err
  DeviceError lose_reading(DeviceError err, DeviceState* state) noexcept;
  // a good read: the switches where the device reports them, the ramp's
  // clock, the link's recovery, the end of a watchdog cut
  void note_good_read(const DeviceState& state) noexcept;
  // the tip's and the joints' speeds since the previous reading (q device
  // joints, p_m the wrist centre in m), and the velocity cut's latch
  void measure_speeds(const Joints& q, const Vec3& p_m) noexcept;
  void cut_state() noexcept;
  double clamp_factor(const Vec3& tau) const noexcept;
  void update_heat(const Vec3& tau) noexcept;

  HapticDevice* inner_;
  SafetyParams params_;
  OmniParams omni_;
  Vec3 tau_cont_;
  ServoWatchdog watchdog_;

  SafetyStatus status_ = kSafetyOk;
  // pose-dependent map from motor torques to device-frame force
  Mat3 torque_to_force_ = Mat3::Zero();
  bool have_reading_ = false;
  bool have_previous_ = false;
  Joints q_prev_ = Joints::Zero();
  Vec3 p_prev_m_ = Vec3::Zero();
  double dt_s_;
  bool stamped_ = false;
  bool have_stamp_ = false;
  double stamp_s_ = 0.0;
  double last_stamp_s_ = 0.0;

  double tip_speed_ = 0.0;
  double joint_speed_ = 0.0;
  bool velocity_exceeded_ = false;
  int failed_reads_ = 0;
  int good_reads_ = 0;
  bool comm_lost_ = false;
  bool docked_ = false;
  bool deadman_ = false;
  bool force_on_ = true;
  bool watchdog_fired_ = false;
  bool hot_ = false;

  Vec3 heat_ = Vec3::Zero();
  double ramp_elapsed_s_ = 0.0;
  bool ramp_running_ = false;  // a write since the last cut: reads advance it
  double ramp_scale_ = 0.0;
  Vec3 tau_prev_ = Vec3::Zero();
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_SAFETY_H_
