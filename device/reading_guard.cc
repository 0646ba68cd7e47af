#include "device/reading_guard.h"

#include <cmath>
#include <stdexcept>

namespace vmh {

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
  return joints_of_state(q_device_rad);
}

DeviceError ReadingGuard::read_state(DeviceState* state) noexcept {
  const DeviceError err = inner_->read_state(state);
  const Joints q = state->q_device_rad;
  fault_ = GuardFault::kNone;
  if (err != DeviceError::kOk) {
    // nothing to compare the next reading with
    have_previous_ = false;
    return err;
  }
  if (!params_.enabled) return DeviceError::kOk;
  if (state->rehomed && q.allFinite()) {
    // the offsets were set in the inkwell: the angle is right again, and
    // the step to it is the calibration, not a slip
    latched_ = false;
    previous_ = q;
    have_previous_ = true;
    return DeviceError::kOk;
  }
  if (latched_) {
    fault_ = GuardFault::kJump;
    state->present = 0;
    return DeviceError::kSensorFault;
  }
  if (!q.allFinite()) {
    fault_ = GuardFault::kNonFinite;
    state->present = 0;
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
        state->present = 0;
        return DeviceError::kSensorFault;
      }
    }
  }
  previous_ = q;
  have_previous_ = true;
  return DeviceError::kOk;
}

DeviceError ReadingGuard::write_motor_torques(const Vec3& tau_motor_Nm) noexcept {
  return inner_->write_motor_torques(tau_motor_Nm);
}

}  // namespace vmh
