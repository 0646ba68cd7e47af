// For now a small rigid model: each motor joint an inertia with viscous
// damping driven by its torque, the gimbal joints drifting slowly. Enough
// for signs, units and the scheduler path; the MuJoCo emulator
// (sim/emulator.h) is meant to take its place behind fake_hd_make_device.
#include "tests/hw/fake_libhd/fake_hd_device.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "device/tick_timer.h"

namespace vmh::fake_hd {

namespace {

class RigidOmni final : public HapticDevice {
 public:
  // kg m^2 and N m s/rad per motor joint: 0.1 N m turns a joint by about
  // 0.1 rad in 0.1 s, fast enough for a short test, slow enough to stay in
  // the workspace
  static constexpr double kInertia = 5e-3;
  static constexpr double kDamping = 5e-3;
  // gimbal drift: amplitude rad, frequency Hz
  static constexpr double kDriftRad = 0.02;
  static constexpr double kDriftHz = 0.5;

  RigidOmni(bool docked, std::uint32_t buttons)
      : docked_(docked), buttons_(buttons), t0_s_(monotonic_now_s()),
        last_s_(t0_s_) {
    // an arbitrary pose inside the workspace, forearm angle absolute
    q_ << 0.1, 0.2, 0.7, 0.3, -0.2, 0.1;
    q0_ = q_;
  }

  DeviceError read_joints(Joints* q) noexcept override {
    advance();
    *q = q_;
    return DeviceError::kOk;
  }

  DeviceError read_state(DeviceState* s) noexcept override {
    advance();
    s->q_device_rad = q_;
    s->docked = docked_;
    s->buttons = buttons_;
    s->timestamp_s = last_s_;
    s->present = kStateJoints | kStateInkwell | kStateButtons | kStateTimestamp;
    return DeviceError::kOk;
  }

  DeviceError write_motor_torques(const Vec3& tau_Nm) noexcept override {
    if (!tau_Nm.allFinite()) {
      tau_Nm_.setZero();
      return DeviceError::kInvalidCommand;
    }
    tau_Nm_ = tau_Nm;
    return DeviceError::kOk;
  }

 private:
  // semi-implicit Euler up to now, in steps of at most 1 ms
  void advance() noexcept {
    const double now = monotonic_now_s();
    double left = std::min(now - last_s_, 0.05);
    while (left > 0.0) {
      const double dt = std::min(left, 1e-3);
      for (int i = 0; i < 3; ++i) {
        qd_[i] += dt * (tau_Nm_[i] - kDamping * qd_[i]) / kInertia;
        q_[i] += dt * qd_[i];
      }
      left -= dt;
    }
    last_s_ = now;
    const double phase = 2.0 * 3.14159265358979323846 * kDriftHz * (now - t0_s_);
    for (int i = 3; i < 6; ++i) q_[i] = q0_[i] + kDriftRad * std::sin(phase + i);
  }

  bool docked_;
  std::uint32_t buttons_;
  double t0_s_;
  double last_s_;
  Joints q_;
  Joints q0_;
  Vec3 qd_ = Vec3::Zero();
  Vec3 tau_Nm_ = Vec3::Zero();
};

}  // namespace

std::unique_ptr<HapticDevice> fake_hd_make_device(const std::string& config) {
  const ModelTokens m = parse_model_tokens(config);
  if (m.tour) {
    throw std::invalid_argument(
        "fake libHD: \"tour\" needs the emulator (a build with MuJoCo)");
  }
  return std::make_unique<RigidOmni>(m.docked, m.buttons);
}

bool fake_hd_true_q_dh(const HapticDevice&, Joints*) { return false; }

}  // namespace vmh::fake_hd
