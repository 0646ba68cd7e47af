// The rig the safety layer's tests share: a scripted device behind a
// SafetyLayer at a fixed pose, parameters with every limit but the one under
// test out of the way, and the force/torque maps computed here from a
// finite-difference Jacobian of omni_fk (not the layer's own).
#ifndef VMHAPTICS_TESTS_DEVICE_SAFETY_RIG_H_
#define VMHAPTICS_TESTS_DEVICE_SAFETY_RIG_H_

#include <cmath>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "device/safety.h"
#include "tests/support/scripted_device.h"

namespace vmh::testing {

inline constexpr double kDt = 1e-3;

// Every limit but the one under test out of the way: no ramp, no impulse
// limit, a motor that does not warm, speeds no hand reaches.
inline SafetyParams quiet() {
  SafetyParams p;
  p.servo_period_s = kDt;
  p.ramp_s = 0.0;
  p.max_force_step_N = 1e6;
  p.thermal_time_constant_s = 1e9;
  p.max_tip_speed_m_s = 1e3;
  p.resume_tip_speed_m_s = 5e2;
  p.max_joint_speed_rad_s = 1e4;
  p.resume_joint_speed_rad_s = 5e3;
  return p;
}

// a pose well inside the workspace, away from singularities (DH convention)
inline Joints pose_dh() {
  Joints q;
  q << 0.2, 0.3, 0.4, 0.1, -0.2, 0.3;
  return q;
}

// J_v by central differences of omni_fk: independent of omni_jacobian
inline Mat3 fd_jacobian(const Joints& q_dh) {
  const OmniParams omni;
  const double h = 1e-6;
  Mat3 J;
  for (int j = 0; j < 3; ++j) {
    Joints a = q_dh, b = q_dh;
    a[j] += h;
    b[j] -= h;
    J.col(j) = (omni_fk(omni, a).p_base_m - omni_fk(omni, b).p_base_m) / (2 * h);
  }
  return J;
}

// motor torques that make device-frame force F_dev at the wrist centre
inline Vec3 torque_for_force(const Joints& q_dh, const Vec3& F_dev_N) {
  const Vec3 F_base = R_device_base().transpose() * F_dev_N;
  return dh_to_motor_torques(fd_jacobian(q_dh).transpose() * F_base);
}

// device-frame force that motor torques make at the wrist centre
inline Vec3 force_for_torque(const Joints& q_dh, const Vec3& tau_motor_Nm) {
  const Vec3 tau_dh = motor_to_dh_torques(tau_motor_Nm);
  return R_device_base() *
         fd_jacobian(q_dh).transpose().partialPivLu().solve(tau_dh);
}

inline double parallel_error(const Vec3& a, const Vec3& b) {
  return (a.normalized() - b.normalized()).norm();
}

struct Rig {
  explicit Rig(const SafetyParams& p = quiet()) : layer(&dev, p) {
    dev.q = dh_to_device_joints(pose_dh());
  }
  // one servo tick: read, then write the command; returns what reached the
  // device
  Vec3 tick(const Vec3& tau) {
    read_only();
    return write_only(tau);
  }
  void read_only() {
    Joints q;
    read = layer.read_joints(&q);
  }
  Vec3 write_only(const Vec3& tau) {
    write = layer.write_motor_torques(tau);
    return dev.written;
  }
  ScriptedDevice dev;
  SafetyLayer layer;
  DeviceError read = DeviceError::kOk;
  DeviceError write = DeviceError::kOk;
};

inline const Vec3 kSmall(0.01, -0.02, 0.015);  // N m, far under every limit

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_DEVICE_SAFETY_RIG_H_
