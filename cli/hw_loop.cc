#include "cli/hw_loop.h"

#include "controller/device_frame.h"

namespace vmh::cli {

bool HwLoop::tick(double now_s) noexcept {
  if (!started_) {
    t0_s_ = now_s;
    last_s_ = now_s;
    started_ = true;
  }
  HwSample& s = sample_;
  s.t_s = now_s - t0_s_;
  s.period_s = now_s - last_s_;
  last_s_ = now_s;
  safety_.set_read_time(now_s);

  if (o_.mode == HwMode::kRun && controller_ != nullptr) {
    s.servo = servo_tick(&safety_, controller_.get(), &s.out, &s.state);
    s.tau_cmd_Nm = s.servo.zeroed ? Vec3::Zero() : s.out.tau_motor_Nm;
    if (reference_ && s.servo.read == DeviceError::kOk) {
      reference_->tick(device_to_dh_joints(s.state.q_device_rad), &ref_out_);
      s.force_reference_N = ref_out_.force_device_N;
    }
  } else {
    s.servo = ServoTickResult{};
    s.servo.read = safety_.read_state(&s.state);
    Vec3 tau = Vec3::Zero();
    if (o_.mode == HwMode::kMotorTest && s.t_s >= o_.pulse_start_s &&
        s.t_s < o_.pulse_start_s + o_.pulse_s) {
      tau[o_.motor - 1] = o_.torque_Nm;
    }
    if (s.servo.read != DeviceError::kOk) {
      s.state.present = 0;
      tau.setZero();
      s.servo.zeroed = true;
    }
    s.tau_cmd_Nm = tau;
    s.servo.write = safety_.write_motor_torques(tau);
  }
  s.tau_sent_Nm = safety_.last_torque_Nm();
  s.safety = safety_.status();
  s.ramp_scale = safety_.ramp_scale();
  s.thermal = safety_.thermal_state();
  s.guard = guard_.last_fault();
  s.has_truth = emulator_ != nullptr;
  if (emulator_ != nullptr) s.truth = emulator_->truth();
  ring_.push(s);
  latest_.write(s);
  ticks_.store(ticks_.load(std::memory_order_relaxed) + 1,
               std::memory_order_release);
  return s.t_s < o_.duration_s;
}


}  // namespace vmh::cli
