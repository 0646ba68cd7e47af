#include "device/servo_chain.h"

#include <stdexcept>
#include <string>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "device/servo_tick.h"

namespace vmh {
namespace {

// the reading's wrist centre and stylus axis (device frame), by the same
// one-pass kinematics the controller uses, so that a record without a
// controller has the pose a controller would have seen
void pose_of_reading(const OmniParams& omni, TickRecord* rec) noexcept {
  if (!rec->q_dh.allFinite()) {
    rec->p_mm.setConstant(std::nan(""));
    rec->axis.setConstant(std::nan(""));
    return;
  }
  const OmniArmKinematics arm = omni_arm_kinematics(omni, rec->q_dh);
  rec->p_mm = base_to_device_mm(omni, arm.p_base_m);
  rec->axis = base_to_device_vector(arm.z6_base);
}

}  // namespace

ServoChain::ServoChain(HapticDevice* device, const ChainOptions& options)
    : device_(device), options_(options) {
  if (device_ == nullptr) {
    throw std::invalid_argument("ServoChain: no device");
  }
  if (options_.mode == ChainMode::kRun && !options_.controller) {
    throw std::invalid_argument("ServoChain: mode run needs a controller");
  }
  if (options_.mode == ChainMode::kMotorTest &&
      (options_.pulse.motor < 1 || options_.pulse.motor > 3)) {
    throw std::invalid_argument("ServoChain: the pulse's motor must be 1, 2 "
                                "or 3, got " +
                                std::to_string(options_.pulse.motor));
  }
  if (options_.controller) {
    // the device is the controller's Omni: one geometry for everything
    options_.omni = options_.controller->omni;
    length_unit_mm_ = options_.controller->length_unit_mm;
    if (options_.mode == ChainMode::kRun) {
      controller_ = std::make_unique<Controller>(*options_.controller);
    }
  }
  if (options_.reference && options_.mode == ChainMode::kRun) {
    reference_ = std::make_unique<Controller>(*options_.reference);
  }
  guard_ = std::make_unique<ReadingGuard>(device_, options_.guard);
  if (options_.safety) {
    safety_ = std::make_unique<SafetyLayer>(guard_.get(),
                                            options_.safety_params,
                                            options_.omni);
  }
}

ServoChain::~ServoChain() = default;

SafetyParams safety_params_for(const ControllerParams& params) {
  SafetyParams s;
  s.servo_period_s = params.servo_period_s;
  s.motor_torque_limit_Nm = params.omni.motor_torque_limit_Nm;
  return s;
}

void ServoChain::set_reference(const ControllerParams& params) {
  options_.reference = params;
  reference_ = std::make_unique<Controller>(params);
}

HapticDevice* ServoChain::top() noexcept {
  return safety_ ? static_cast<HapticDevice*>(safety_.get())
                 : static_cast<HapticDevice*>(guard_.get());
}

void ServoChain::reset() {
  guard_->reset();
  if (controller_) controller_->reset();
  if (reference_) reference_->reset();
  if (safety_) {
    // a fresh layer: no reading, no heat, the ramp from zero
    safety_ = std::make_unique<SafetyLayer>(guard_.get(),
                                            options_.safety_params,
                                            options_.omni);
  }
  have_last_ = false;
  last_t_s_ = 0.0;
}

void ServoChain::command_without_controller(double t_s,
                                            TickRecord* rec) noexcept {
  HapticDevice* top = this->top();
  rec->servo = ServoTickResult{};
  rec->servo.read = top->read_state(&rec->state);
  Vec3 tau = Vec3::Zero();
  const MotorPulse& p = options_.pulse;
  if (options_.mode == ChainMode::kMotorTest && t_s >= p.start_s &&
      t_s < p.start_s + p.length_s) {
    tau[p.motor - 1] = p.torque_Nm;
  }
  if (rec->servo.read != DeviceError::kOk) {
    rec->state.present = 0;
    tau.setZero();
    rec->servo.zeroed = true;
  }
  rec->tau_cmd_Nm = tau;
  rec->servo.write = top->write_motor_torques(tau);
  if (rec->servo.write != DeviceError::kOk) rec->servo.zeroed = true;
}

void ServoChain::tick(double t_s, double now_s, TickRecord* rec) noexcept {
  rec->t_s = t_s;
  rec->period_s = have_last_ ? t_s - last_t_s_ : 0.0;
  have_last_ = true;
  last_t_s_ = t_s;
  rec->has_truth = false;
  if (safety_) safety_->set_read_time(now_s);

  const double nan = std::nan("");
  rec->has_controller = controller_ != nullptr;
  if (controller_) {
    rec->servo = servo_tick(top(), controller_.get(), &rec->out, &rec->state);
    rec->tau_cmd_Nm = rec->servo.zeroed ? Vec3::Zero() : rec->out.tau_motor_Nm;
  } else {
    command_without_controller(t_s, rec);
  }

  const bool read = rec->servo.read == DeviceError::kOk;
  if (read) {
    rec->q_dh = device_to_dh_joints(rec->state.q_device_rad);
  } else {
    rec->q_dh.setConstant(nan);
  }
  if (controller_) {
    // the controller's own reading of the pose (the same kinematics); after
    // a failed read, the last one it had (its output is left as it was)
    rec->p_mm = rec->out.p_rm_mm;
    rec->axis = rec->out.axis_rm;
    rec->d_path_mm =
        controller_->mechanism().distance_to_path(rec->p_mm / length_unit_mm_) *
        length_unit_mm_;
  } else {
    pose_of_reading(options_.omni, rec);
    rec->d_path_mm = nan;
  }
  if (reference_ && read) {
    reference_->tick(rec->q_dh, &reference_out_);
    rec->force_reference_N = reference_out_.force_device_N;
  } else {
    rec->force_reference_N.setConstant(nan);
  }

  if (safety_) {
    rec->tau_sent_Nm = safety_->last_torque_Nm();
    rec->safety = safety_->status();
    rec->ramp_scale = safety_->ramp_scale();
    rec->thermal = safety_->thermal_state();
  } else {
    rec->tau_sent_Nm = rec->servo.write == DeviceError::kOk
                           ? rec->tau_cmd_Nm
                           : Vec3::Zero();
    rec->safety = kSafetyOk;
    rec->ramp_scale = 1.0;
    rec->thermal.setZero();
  }
  rec->guard = guard_->last_fault();
  rec->fault_injected = false;
}

}  // namespace vmh
