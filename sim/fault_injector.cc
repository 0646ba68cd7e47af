#include "sim/fault_injector.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace vmh::sim {

const char* sensor_fault_kind_name(SensorFaultKind k) {
  switch (k) {
    case SensorFaultKind::kNone: return "none";
    case SensorFaultKind::kNan: return "nan";
    case SensorFaultKind::kJump: return "jump";
    case SensorFaultKind::kStuck: return "stuck";
  }
  return "unknown";
}

bool parse_sensor_fault_kind(const std::string& text, SensorFaultKind* k) {
  for (SensorFaultKind c : {SensorFaultKind::kNone, SensorFaultKind::kNan,
                            SensorFaultKind::kJump, SensorFaultKind::kStuck}) {
    if (text == sensor_fault_kind_name(c)) {
      *k = c;
      return true;
    }
  }
  return false;
}

FaultInjector::FaultInjector(HapticDevice* inner, const FaultSpec& spec)
    : inner_(inner), spec_(spec) {
  if (inner_ == nullptr) throw std::invalid_argument("FaultInjector: no device");
  if (spec_.joint < 0 || spec_.joint > 5) {
    throw std::invalid_argument("FaultInjector: joint must be 0..5");
  }
  if (!std::isfinite(spec_.at_s) || !std::isfinite(spec_.jump_rad)) {
    throw std::invalid_argument("FaultInjector: at_s and jump_rad must be finite");
  }
  reset();
}

void FaultInjector::reset() noexcept {
  active_ = false;
  have_stuck_ = false;
  stuck_rad_ = 0.0;
  last_.setZero();
}

DeviceError FaultInjector::read_joints(Joints* q_device_rad) noexcept {
  Joints q;
  const DeviceError err = inner_->read_joints(&q);
  active_ = false;
  if (err != DeviceError::kOk) {
    last_.setConstant(std::numeric_limits<double>::quiet_NaN());
    return err;
  }
  const bool on = spec_.kind != SensorFaultKind::kNone && t_s_ >= spec_.at_s;
  if (on) {
    const int j = spec_.joint;
    switch (spec_.kind) {
      case SensorFaultKind::kNone:
        break;
      case SensorFaultKind::kNan:
        q[j] = std::numeric_limits<double>::quiet_NaN();
        break;
      case SensorFaultKind::kJump:
        q[j] += spec_.jump_rad;
        break;
      case SensorFaultKind::kStuck:
        if (!have_stuck_) {
          // the encoder stops at what it reads now
          stuck_rad_ = q[j];
          have_stuck_ = true;
        }
        q[j] = stuck_rad_;
        break;
    }
    active_ = true;
  }
  last_ = q;
  *q_device_rad = q;
  return DeviceError::kOk;
}

DeviceError FaultInjector::write_motor_torques(const Vec3& tau_motor_Nm) noexcept {
  return inner_->write_motor_torques(tau_motor_Nm);
}

const char* guard_fault_name(GuardFault f) {
  switch (f) {
    case GuardFault::kNone: return "none";
    case GuardFault::kNonFinite: return "sensor_nan";
    case GuardFault::kJump: return "sensor_jump";
  }
  return "unknown";
}

ReadingGuard::ReadingGuard(HapticDevice* inner, const GuardParams& params)
    : inner_(inner), params_(params) {
  if (inner_ == nullptr) throw std::invalid_argument("ReadingGuard: no device");
  if (!(std::isfinite(params_.max_speed_rad_s) && params_.max_speed_rad_s > 0.0)) {
    throw std::invalid_argument("ReadingGuard: max_speed_rad_s must be > 0");
  }
  if (!(std::isfinite(params_.max_period_s) && params_.max_period_s > 0.0)) {
    throw std::invalid_argument("ReadingGuard: max_period_s must be > 0");
  }
  max_step_rad_ = params_.max_speed_rad_s * params_.max_period_s;
  reset();
}

void ReadingGuard::reset() noexcept {
  have_previous_ = false;
  latched_ = false;
  fault_ = GuardFault::kNone;
  previous_.setZero();
}

DeviceError ReadingGuard::read_joints(Joints* q_device_rad) noexcept {
  Joints q;
  const DeviceError err = inner_->read_joints(&q);
  fault_ = GuardFault::kNone;
  if (err != DeviceError::kOk) {
    // nothing to compare the next reading with
    have_previous_ = false;
    return err;
  }
  if (!params_.enabled) {
    *q_device_rad = q;
    return DeviceError::kOk;
  }
  if (latched_) {
    fault_ = GuardFault::kJump;
    return DeviceError::kSensorFault;
  }
  if (!q.allFinite()) {
    fault_ = GuardFault::kNonFinite;
    // after a gap the joints may have moved any distance: the first good
    // reading is not compared (a jump that coincides with it goes unseen)
    have_previous_ = false;
    return DeviceError::kSensorFault;
  }
  if (have_previous_) {
    // the encoders count increments, so a slip shows as a step no hand can
    // make; the gimbal's potentiometers are absolute and are not checked
    for (int j = 0; j < 3; ++j) {
      if (std::abs(q[j] - previous_[j]) > max_step_rad_) {
        latched_ = true;
        fault_ = GuardFault::kJump;
        return DeviceError::kSensorFault;
      }
    }
  }
  previous_ = q;
  have_previous_ = true;
  *q_device_rad = q;
  return DeviceError::kOk;
}

DeviceError ReadingGuard::write_motor_torques(const Vec3& tau_motor_Nm) noexcept {
  return inner_->write_motor_torques(tau_motor_Nm);
}

}  // namespace vmh::sim
