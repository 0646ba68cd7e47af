// A stand-in device, in-process: each motor joint t1..t3 is a rotor of
// fixed inertia with viscous damping, integrated one servo period per write
// (semi-implicit Euler) from the torque written; the gimbal t4..t6 stays
// where it started. Its only job is to give servo_tick() a device that
// answers at once and moves, so the bench times real controller work. It is
// not a model of the Omni.
#include "bench/servo_jitter_device.h"

#include <cmath>

namespace vmh {

namespace {

class RotorDevice : public HapticDevice {
 public:
  RotorDevice(double period_s, const Joints& q0) : dt_s_(period_s), q_(q0) {}

  DeviceError read_joints(Joints* q_device_rad) noexcept override {
    *q_device_rad = q_;
    return DeviceError::kOk;
  }

  DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override {
    if (!tau_motor_Nm.allFinite()) return DeviceError::kInvalidCommand;
    for (int i = 0; i < 3; ++i) {
      const double acc = (tau_motor_Nm[i] - kDamping_Nms * qd_[i]) / kInertia;
      qd_[i] += acc * dt_s_;
      q_[i] += qd_[i] * dt_s_;
      // stay in a range where the arm's kinematics make sense
      if (std::abs(q_[i]) > 1.5) {
        q_[i] = std::copysign(1.5, q_[i]);
        qd_[i] = 0.0;
      }
    }
    return DeviceError::kOk;
  }

 private:
  static constexpr double kInertia = 2e-3;      // kg m^2, per motor joint
  static constexpr double kDamping_Nms = 2e-2;  // N m s/rad
  double dt_s_;
  Joints q_;
  Vec3 qd_ = Vec3::Zero();  // rad/s
};

}  // namespace

std::unique_ptr<HapticDevice> make_jitter_device(double period_s,
                                                 const Joints& q0_device_rad) {
  return std::make_unique<RotorDevice>(period_s, q0_device_rad);
}

std::string jitter_device_name() { return "a stand-in rotor model"; }

}  // namespace vmh
