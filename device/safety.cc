#include "device/safety.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/omni_ratings.h"
#include "device/motor_force_map.h"

namespace vmh {

const char* safety_flag_name(SafetyStatus flag) {
  switch (flag) {
    case kSafetyOk: return "ok";
    case kSafetyForceClamped: return "force_clamped";
    case kSafetyTorqueClamped: return "torque_clamped";
    case kSafetyForceRamping: return "force_ramping";
    case kSafetyForceImpulseLimited: return "force_impulse_limited";
    case kSafetyVelocityExceeded: return "velocity_exceeded";
    case kSafetyMotorWarm: return "motor_warm";
    case kSafetyMotorHot: return "motor_hot";
    case kSafetyWatchdogExpired: return "watchdog_expired";
    case kSafetyCommLost: return "comm_lost";
    case kSafetyDocked: return "docked";
    case kSafetyDeadmanReleased: return "deadman_released";
    case kSafetyForceOutputOff: return "force_output_off";
    case kSafetyNoReading: return "no_reading";
    case kSafetyInvalidCommand: return "invalid_command";
    default: return "unknown";
  }
}

namespace {

void require(bool ok, const char* field, const char* what) {
  if (!ok) {
    throw std::invalid_argument(std::string("SafetyParams: ") + field + " " +
                                what);
  }
}

bool positive(double v) { return std::isfinite(v) && v > 0.0; }

}  // namespace

void SafetyParams::validate() const {
  require(positive(servo_period_s), "servo_period_s", "must be > 0");
  require(positive(max_force_N), "max_force_N", "must be > 0");
  for (double lim : motor_torque_limit_Nm) {
    require(positive(lim), "motor_torque_limit_Nm", "must be > 0");
  }
  require(std::isfinite(singular_damping_m) && singular_damping_m >= 0.0,
          "singular_damping_m", "must be >= 0");
  require(std::isfinite(ramp_s) && ramp_s >= 0.0, "ramp_s", "must be >= 0");
  require(positive(max_force_step_N), "max_force_step_N", "must be > 0");
  require(positive(max_tip_speed_m_s), "max_tip_speed_m_s", "must be > 0");
  require(positive(resume_tip_speed_m_s) &&
              resume_tip_speed_m_s < max_tip_speed_m_s,
          "resume_tip_speed_m_s", "must be in (0, max_tip_speed_m_s)");
  require(positive(max_joint_speed_rad_s), "max_joint_speed_rad_s",
          "must be > 0");
  require(positive(resume_joint_speed_rad_s) &&
              resume_joint_speed_rad_s < max_joint_speed_rad_s,
          "resume_joint_speed_rad_s", "must be in (0, max_joint_speed_rad_s)");
  require(positive(continuous_force_N), "continuous_force_N", "must be > 0");
  require(positive(thermal_time_constant_s), "thermal_time_constant_s",
          "must be > 0");
  require(positive(thermal_cut), "thermal_cut", "must be > 0");
  require(positive(thermal_warn) && thermal_warn < thermal_cut, "thermal_warn",
          "must be in (0, thermal_cut)");
  require(positive(thermal_resume) && thermal_resume < thermal_cut,
          "thermal_resume", "must be in (0, thermal_cut)");
  require(positive(derate_at_cut) && derate_at_cut <= 1.0, "derate_at_cut",
          "must be in (0, 1]");
  require(comm_lost_reads >= 1, "comm_lost_reads", "must be >= 1");
  require(comm_resume_reads >= 1, "comm_resume_reads", "must be >= 1");
  require(watchdog_periods >= 1, "watchdog_periods", "must be >= 1");
}

ServoWatchdog::ServoWatchdog(double servo_period_s, int periods) {
  if (!positive(servo_period_s)) {
    throw std::invalid_argument("ServoWatchdog: servo_period_s must be > 0");
  }
  if (periods < 1) {
    throw std::invalid_argument("ServoWatchdog: periods must be >= 1");
  }
  timeout_s_ = servo_period_s * periods;
}

void ServoWatchdog::kick(double now_s) noexcept {
  if (!std::isfinite(now_s)) return;
  last_kick_s_ = now_s;
  armed_ = true;
}

bool ServoWatchdog::expired(double now_s) const noexcept {
  if (!armed_) return false;
  // a non-finite clock is treated as expired: the safe answer
  if (!std::isfinite(now_s)) return true;
  return now_s - last_kick_s_ > timeout_s_;
}

SafetyLayer::SafetyLayer(HapticDevice* inner, const SafetyParams& params,
                         const OmniParams& omni)
    : inner_(inner),
      params_(params),
      omni_(omni),
      // a placeholder until the parameters are validated, so that a bad
      // period or count is reported by the field's name
      watchdog_(1.0, 1),
      dt_s_(params.servo_period_s) {
  if (inner_ == nullptr) throw std::invalid_argument("SafetyLayer: no device");
  params_.validate();
  omni_.validate();
  watchdog_ = ServoWatchdog(params_.servo_period_s, params_.watchdog_periods);
  // continuous torque of each motor: the largest torque a continuous force
  // in any direction needs at the nominal pose (DH q = 0, arms orthogonal),
  // as the rated torque limits are derived (controller/omni_ratings.h)
  const std::array<double, kOmniActuated> cont =
      motor_torques_for_force_Nm(omni_, params_.continuous_force_N);
  for (int i = 0; i < 3; ++i) {
    tau_cont_[i] = cont[static_cast<std::size_t>(i)];
    if (!positive(tau_cont_[i])) {
      throw std::invalid_argument(
          "SafetyLayer: a motor takes no torque at the nominal pose");
    }
  }
}

Vec3 SafetyLayer::force_device_N(const Vec3& tau_motor_Nm) const noexcept {
  return torque_to_force_ * tau_motor_Nm;
}

void SafetyLayer::set_read_time(double now_s) noexcept {
  stamp_s_ = now_s;
  stamped_ = true;
}

void SafetyLayer::set_inputs(bool docked, bool deadman_pressed) noexcept {
  docked_ = docked;
  deadman_ = deadman_pressed;
}

void SafetyLayer::set_force_output(bool on) noexcept {
  if (on && !force_on_) {
    ramp_elapsed_s_ = 0.0;
    ramp_running_ = false;
  }
  force_on_ = on;
}

void SafetyLayer::cut_state() noexcept {
  tau_prev_.setZero();
  ramp_elapsed_s_ = 0.0;
  ramp_running_ = false;
  ramp_scale_ = 0.0;
}

bool SafetyLayer::service_watchdog(double now_s) noexcept {
  if (!watchdog_.expired(now_s)) return false;
  watchdog_fired_ = true;
  status_ |= kSafetyWatchdogExpired;
  cut_state();
  (void)inner_->write_motor_torques(Vec3::Zero());
  return true;
}

DeviceError SafetyLayer::read_joints(Joints* q_device_rad) noexcept {
  return joints_of_state(q_device_rad);
}

void SafetyLayer::advance_clock(bool good, const DeviceState& state) noexcept {
  double stamp_s = std::nan("");
  if (stamped_) {
    stamp_s = stamp_s_;
  } else if (good && state.has(kStateTimestamp)) {
    stamp_s = state.timestamp_s;
  }
  dt_s_ = params_.servo_period_s;
  if (std::isfinite(stamp_s)) {
    if (have_stamp_ && stamp_s > last_stamp_s_) dt_s_ = stamp_s - last_stamp_s_;
    last_stamp_s_ = stamp_s;
    have_stamp_ = true;
  }
}

DeviceError SafetyLayer::lose_reading(DeviceError err,
                                      DeviceState* state) noexcept {
  state->present = 0;
  have_reading_ = false;
  have_previous_ = false;  // nothing to take a velocity from
  good_reads_ = 0;
  if (++failed_reads_ >= params_.comm_lost_reads) comm_lost_ = true;
  if (comm_lost_) status_ |= kSafetyCommLost;
  if (watchdog_fired_) status_ |= kSafetyWatchdogExpired;
  return err;
}

void SafetyLayer::note_good_read(const DeviceState& state) noexcept {
  failed_reads_ = 0;
  // the switches, where the device reports them (set_inputs() otherwise)
  if (state.has(kStateInkwell)) docked_ = state.docked;
  if (state.has(kStateButtons) && params_.deadman_buttons != 0) {
    deadman_ = (state.buttons & params_.deadman_buttons) != 0;
  }
  // the ramp's clock: the time from the write that started it to this read
  if (ramp_running_) {
    ramp_elapsed_s_ = std::min(ramp_elapsed_s_ + dt_s_, params_.ramp_s);
  }
  if (comm_lost_ && ++good_reads_ >= params_.comm_resume_reads) {
    comm_lost_ = false;
    good_reads_ = 0;
  }
  if (comm_lost_) status_ |= kSafetyCommLost;
  // the servo is ticking again: the watchdog's cut ends (the ramp restarts
  // because the watchdog zeroed the state)
  watchdog_fired_ = false;
}

void SafetyLayer::measure_speeds(const Joints& q, const Vec3& p_m) noexcept {
  tip_speed_ = 0.0;
  joint_speed_ = 0.0;
  if (have_previous_) {
    // speeds over at least half a servo period: two readings stamped closer
    // than that (a device or emulator catching up after a stall) would turn
    // one encoder count (0.42 mrad) into a speed over 0.8 rad/s and more
    const double dt_speed_s = std::max(dt_s_, 0.5 * params_.servo_period_s);
    tip_speed_ = (p_m - p_prev_m_).norm() / dt_speed_s;
    joint_speed_ =
        (q.head<3>() - q_prev_.head<3>()).cwiseAbs().maxCoeff() / dt_speed_s;
    if (tip_speed_ > params_.max_tip_speed_m_s ||
        joint_speed_ > params_.max_joint_speed_rad_s) {
      velocity_exceeded_ = true;
    } else if (tip_speed_ < params_.resume_tip_speed_m_s &&
               joint_speed_ < params_.resume_joint_speed_rad_s) {
      velocity_exceeded_ = false;
    }
  }
  if (velocity_exceeded_) status_ |= kSafetyVelocityExceeded;
}

DeviceError SafetyLayer::read_state(DeviceState* state) noexcept {
  status_ = kSafetyOk;
  DeviceError err = inner_->read_state(state);
  const Joints q = state->q_device_rad;
  if (err == DeviceError::kOk && !q.allFinite()) err = DeviceError::kSensorFault;

  advance_clock(err == DeviceError::kOk, *state);
  // the motors held the last torque over the interval that just ended
  update_heat(tau_prev_);

  if (err != DeviceError::kOk) return lose_reading(err, state);
  note_good_read(*state);

  const Joints q_dh = device_to_dh_joints(q);
  const Vec3 p_m = omni_fk(omni_, q_dh).p_base_m;
  torque_to_force_ =
      motor_torque_to_force_map(omni_, q, params_.singular_damping_m);
  if (!torque_to_force_.allFinite()) {
    // cannot happen for finite angles and l > 0; a cut is the safe answer
    have_reading_ = false;
    have_previous_ = false;
    return DeviceError::kSensorFault;
  }

  measure_speeds(q, p_m);
  q_prev_ = q;
  p_prev_m_ = p_m;
  have_previous_ = true;
  have_reading_ = true;
  return DeviceError::kOk;
}

double SafetyLayer::clamp_factor(const Vec3& tau) const noexcept {
  double s = 1.0;
  for (int i = 0; i < 3; ++i) {
    const double a = std::abs(tau[i]);
    if (a > params_.motor_torque_limit_Nm[i]) {
      s = std::min(s, params_.motor_torque_limit_Nm[i] / a);
    }
  }
  const double f = force_device_N(tau).norm();
  if (f > params_.max_force_N) s = std::min(s, params_.max_force_N / f);
  return s;
}

void SafetyLayer::update_heat(const Vec3& tau) noexcept {
  // exact solution over one interval dt_s_ of dh/dt = (u - h)/T with
  // u = (tau/tau_c)^2, tau the torque the device held over it
  const double decay = std::exp(-dt_s_ / params_.thermal_time_constant_s);
  for (int i = 0; i < 3; ++i) {
    const double r = tau[i] / tau_cont_[i];
    const double u = r * r;
    heat_[i] = u + (heat_[i] - u) * decay;
  }
}

DeviceError SafetyLayer::write_motor_torques(const Vec3& tau_motor_Nm) noexcept {
  // keep the read's flags (velocity, comm); recompute the rest
  status_ &= (kSafetyVelocityExceeded | kSafetyCommLost | kSafetyWatchdogExpired);
  if (stamped_ && std::isfinite(stamp_s_)) watchdog_.kick(stamp_s_);
  stamped_ = false;

  const double hottest = heat_.maxCoeff();
  if (hot_ && hottest <= params_.thermal_resume) hot_ = false;
  if (hottest >= params_.thermal_cut) hot_ = true;

  const bool finite = tau_motor_Nm.allFinite();
  if (!finite) status_ |= kSafetyInvalidCommand;
  if (!force_on_) status_ |= kSafetyForceOutputOff;
  if (!have_reading_) status_ |= kSafetyNoReading;
  if (docked_) status_ |= kSafetyDocked;
  if (params_.require_deadman && !deadman_) status_ |= kSafetyDeadmanReleased;
  if (hot_) status_ |= kSafetyMotorHot;
  have_reading_ = false;  // each write needs a fresh reading

  if ((status_ & kSafetyCuts) != 0) {
    cut_state();
    const DeviceError err = inner_->write_motor_torques(Vec3::Zero());
    return finite ? err : DeviceError::kInvalidCommand;
  }

  // clamps: one factor keeps the direction of the torques and the force
  Vec3 tau = tau_motor_Nm;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(tau[i]) > params_.motor_torque_limit_Nm[i]) {
      status_ |= kSafetyTorqueClamped;
    }
  }
  if (force_device_N(tau).norm() > params_.max_force_N) {
    status_ |= kSafetyForceClamped;
  }
  tau *= clamp_factor(tau);

  // thermal derating, linear from 1 at warn to derate_at_cut at cut
  if (hottest > params_.thermal_warn) {
    status_ |= kSafetyMotorWarm;
    const double x = (hottest - params_.thermal_warn) /
                     (params_.thermal_cut - params_.thermal_warn);
    tau *= 1.0 - (1.0 - params_.derate_at_cut) * std::min(x, 1.0);
  }

  // ramp: the scale is (time since the write that started it) / ramp_s,
  // k dt / ramp_s at the k-th write at a steady period
  ramp_scale_ = params_.ramp_s > 0.0
                    ? std::min(1.0, ramp_elapsed_s_ / params_.ramp_s)
                    : 1.0;
  if (ramp_scale_ < 1.0) status_ |= kSafetyForceRamping;
  tau *= ramp_scale_;
  ramp_running_ = true;

  // impulse: the change of torque is scaled (direction kept) so that the
  // change of force it makes at this pose is at most max_force_step_N
  const Vec3 dtau = tau - tau_prev_;
  const double df = force_device_N(dtau).norm();
  if (df > params_.max_force_step_N) {
    status_ |= kSafetyForceImpulseLimited;
    tau = tau_prev_ + dtau * (params_.max_force_step_N / df);
  }
  // the previous torque may exceed the force limit at the new pose: the
  // limits hold after the rate limiter too
  tau *= clamp_factor(tau);

  tau_prev_ = tau;
  return inner_->write_motor_torques(tau);
}

}  // namespace vmh
