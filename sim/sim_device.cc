#include "sim/sim_device.h"

#include <algorithm>
#include <cmath>

#include "controller/device_frame.h"
#include "sim/mujoco_util.h"

namespace vmh::sim {

SimDevice::SimDevice(const mjModel* m, mjData* d, const OmniParams& omni,
                     bool quantize, int delay_ticks, const std::string& source)
    : d_(d), sensor_(omni, quantize), delay_ticks_(delay_ticks) {
  if (delay_ticks < 0 || delay_ticks > kMaxDelayTicks) {
    throw SimError(source + ": delay_ticks must be in [0, " +
                   std::to_string(kMaxDelayTicks) + "]");
  }
  for (int i = 0; i < 6; ++i) {
    const std::string name = "q" + std::to_string(i + 1);
    const int j = require_id(m, mjOBJ_JOINT, name.c_str(), source);
    if (m->jnt_type[j] != mjJNT_HINGE) {
      throw SimError(source + ": joint '" + name + "' must be a hinge");
    }
    qpos_adr_[static_cast<std::size_t>(i)] = m->jnt_qposadr[j];
  }
  for (int i = 0; i < 3; ++i) {
    const std::string name = "m" + std::to_string(i + 1);
    const int a = require_id(m, mjOBJ_ACTUATOR, name.c_str(), source);
    const auto k = static_cast<std::size_t>(i);
    actuator_[k] = a;
    if (m->actuator_ctrllimited[a]) {
      lo_[k] = m->actuator_ctrlrange[2 * a];
      hi_[k] = m->actuator_ctrlrange[2 * a + 1];
    } else {
      // no range in the model: fall back on the OpenHaptics clamps
      lo_[k] = -omni.motor_torque_limit_Nm[k];
      hi_[k] = omni.motor_torque_limit_Nm[k];
    }
  }
  reset();
}

void SimDevice::reset() noexcept {
  for (Vec3& p : pending_) p.setZero();
  head_ = 0;
  clamped_ = false;
  for (int a : actuator_) d_->ctrl[a] = 0.0;
}

Joints SimDevice::true_q_dh() const noexcept {
  Joints q;
  for (int i = 0; i < 6; ++i) {
    q[i] = d_->qpos[qpos_adr_[static_cast<std::size_t>(i)]];
  }
  return q;
}

Vec3 SimDevice::motor_torque_Nm() const noexcept {
  return Vec3(d_->ctrl[actuator_[0]], d_->ctrl[actuator_[1]],
              d_->ctrl[actuator_[2]]);
}

DeviceError SimDevice::read_joints(Joints* q_device_rad) noexcept {
  const Joints q = true_q_dh();
  if (!q.allFinite()) return DeviceError::kSensorFault;
  *q_device_rad = sensor_.measure(dh_to_device_joints(q));
  return DeviceError::kOk;
}

DeviceError SimDevice::write_motor_torques(const Vec3& tau_motor_Nm) noexcept {
  DeviceError err = DeviceError::kOk;
  Vec3 tau = tau_motor_Nm;
  if (!tau.allFinite()) {
    tau.setZero();
    err = DeviceError::kInvalidCommand;
  }
  clamped_ = false;
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double c = std::clamp(tau[i], lo_[k], hi_[k]);
    clamped_ = clamped_ || c != tau[i];
    tau[i] = c;
  }
  // the command written now reaches the motors delay_ticks writes later
  const int n = delay_ticks_ + 1;
  pending_[static_cast<std::size_t>(head_)] = tau;
  const int out = (head_ + 1) % n;
  const Vec3& applied = pending_[static_cast<std::size_t>(delay_ticks_ == 0 ? head_ : out)];
  for (int i = 0; i < 3; ++i) {
    d_->ctrl[actuator_[static_cast<std::size_t>(i)]] = applied[i];
  }
  head_ = out;
  return err;
}

}  // namespace vmh::sim
