#include "sim/fault_injector.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "sim/fault_vocabulary.h"

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
  if (text == "none") {
    *k = SensorFaultKind::kNone;
    return true;
  }
  // the sensor kinds of the one fault table (sim/fault_vocabulary.h)
  for (const FaultKind& f : fault_kinds()) {
    if (!(f.layers & kSensorFaults) || text != f.name) continue;
    for (SensorFaultKind c :
         {SensorFaultKind::kNan, SensorFaultKind::kJump, SensorFaultKind::kStuck}) {
      if (text == sensor_fault_kind_name(c)) {
        *k = c;
        return true;
      }
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

}  // namespace vmh::sim
