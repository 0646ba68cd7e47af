#include "hd/hd_device.h"

#include <algorithm>
#include <cmath>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "hd/hd_config.h"

namespace vmh::hd {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kCountsPerRev = 15000.0;  // docs/sources.md §6
constexpr double kDacFullScale = 2047.0;   // 12-bit offset binary, §9.2

// d q_dh / d t (device_to_dh_joints: q1 = -t1, q2 = t2, q3 = t3 - t2,
// q4 = -t4, q5 = t5, q6 = -t6): device column c = sum_k J_dh(:, k) w[k][c]
constexpr double kDqDt[6][6] = {
    {-1, 0, 0, 0, 0, 0}, {0, 1, 0, 0, 0, 0},  {0, -1, 1, 0, 0, 0},
    {0, 0, 0, -1, 0, 0}, {0, 0, 0, 0, 1, 0},  {0, 0, 0, 0, 0, -1}};

unsigned bit(int i) { return 1u << i; }
constexpr int kErrComm = 0, kErrForce = 1, kErrImpulse = 2, kErrVelocity = 3,
              kErrWarm = 4;

}  // namespace

HdDevice::HdDevice(const runtime::BackendRegistry& registry,
                   const std::string& spec, bool lockstep)
    : spec_(spec) {
  const DeviceSpec ds = parse_device_spec(spec);
  std::string argument;
  const runtime::BackendInfo& info = registry.resolve(ds.device, &argument);
  if (info.name == "openhaptics") {
    throw runtime::RequestError(
        "'" + spec + "': the open HD API cannot open a device through an HD "
        "library (it would load itself); name the device itself (emulator, "
        "firewire, ...)");
  }
  runtime::OpenRequest rq;
  rq.argument = argument;
  for (const auto& option : ds.options) {
    const std::string& key = option.first;
    const std::string& value = option.second;
    const bool taken = std::any_of(
        info.options.begin(), info.options.end(),
        [&](const runtime::BackendOption& o) { return o.key == key; });
    if (!taken) {
      // a flag of the backend's own argument grammar (firewire:GUID?no-20010)
      rq.argument += (rq.argument.find('?') == std::string::npos ? "?" : "&") +
                     key + (value.empty() ? "" : "=" + value);
      continue;
    }
    rq.options[key] = value;
  }
  // a simulated stylus that nothing holds: the program's forces move it
  rq.defaults["hand"] = "none";
  rq.lockstep = lockstep && info.can_lockstep();
  can_lockstep_ = info.can_lockstep();
  opened_ = registry.open(
      info.name + (rq.argument.empty() ? "" : ":" + rq.argument), rq,
      /*servo=*/true);
  identity_ = opened_.backend->identity();
  // the reach: a 13^3 grid over t1..t3 within their ranges
  Joints lo, hi;
  device_joint_ranges(omni_, &lo, &hi);
  for (int i = 0; i < 3; ++i) {
    max_workspace_mm_[i] = 1e9;
    max_workspace_mm_[3 + i] = -1e9;
  }
  constexpr int kGrid = 13;
  for (int a = 0; a < kGrid; ++a) {
    for (int b = 0; b < kGrid; ++b) {
      for (int c = 0; c < kGrid; ++c) {
        Joints q = Joints::Zero();
        const int idx[3] = {a, b, c};
        for (int i = 0; i < 3; ++i) {
          q[i] = lo[i] + (hi[i] - lo[i]) * idx[i] / (kGrid - 1.0);
        }
        const Vec3 p = base_to_device_mm(
            omni_, omni_fk(omni_, device_to_dh_joints(q)).p_base_m);
        for (int i = 0; i < 3; ++i) {
          max_workspace_mm_[i] = std::min(max_workspace_mm_[i], p[i]);
          max_workspace_mm_[3 + i] = std::max(max_workspace_mm_[3 + i], p[i]);
        }
      }
    }
  }
  // one reading now, so that a program reading the state before the
  // scheduler starts sees where the device is (nothing is written)
  arm(period_s_);
  sample(0.0);
  pub_.write(Published{cur_, cur_});
  have_last_ = false;
}

HdDevice::~HdDevice() {
  if (opened_.backend) opened_.backend->stop();
}

void HdDevice::arm(double period_s) {
  period_s_ = period_s;
  GuardParams gp;
  gp.max_period_s = std::max(period_s, 2.8e-3);
  guard_ = std::make_unique<ReadingGuard>(opened_.backend->device(), gp);
  SafetyParams sp;
  sp.servo_period_s = period_s;
  sp.motor_torque_limit_Nm = omni_.motor_torque_limit_Nm;
  sp.ramp_s = settings_.force_ramping.load()
                  ? sp.max_force_N / std::max(1e-6, settings_.ramp_rate_N_s.load())
                  : 0.0;
  sp.max_force_step_N =
      settings_.impulse_limit_on.load() ? settings_.impulse_limit_N.load() : 1e9;
  if (settings_.velocity_limit_on.load()) {
    sp.max_tip_speed_m_s = settings_.velocity_limit_mm_s.load() * 1e-3;
    sp.resume_tip_speed_m_s = 2.0 / 3.0 * sp.max_tip_speed_m_s;
  } else {
    sp.max_tip_speed_m_s = 1e9;
    sp.resume_tip_speed_m_s = 1e9;
    sp.max_joint_speed_rad_s = 1e9;
    sp.resume_joint_speed_rad_s = 1e9;
  }
  sp.validate();
  safety_ = std::make_unique<SafetyLayer>(guard_.get(), sp, omni_);
  have_last_ = false;
  read_failed_ = false;
  last_status_ = 0;
  cur_ = HdFrame{};
  last_ = HdFrame{};
}

void HdDevice::fill_kinematics(const DeviceState& st, double dt_s) noexcept {
  const Joints& q = st.q_device_rad;
  HdFrame& f = cur_;
  Eigen::Matrix4d T;
  Eigen::Matrix<double, 6, 6> J;
  Vec3 v_mm_s;
  if (st.has(kStateTransform) && st.has(kStateJacobian)) {
    // the device's (the emulator's) own kinematics
    T = st.transform_mm;
    J = st.jacobian;
  } else {
    const Joints q_dh = device_to_dh_joints(q);
    OmniPose pose;
    Mat6 J_dh;
    omni_fk_jacobian(omni_, q_dh, &pose, &J_dh);
    T.setIdentity();
    T.topLeftCorner<3, 3>() = base_to_device_rotation(pose.R_base);
    T.topRightCorner<3, 1>() = base_to_device_mm(omni_, pose.p_base_m);
    const Mat3 R = R_device_base();
    for (int c = 0; c < 6; ++c) {
      Vec3 lin = Vec3::Zero(), ang = Vec3::Zero();
      for (int k = 0; k < 6; ++k) {
        lin += kDqDt[k][c] * J_dh.block<3, 1>(0, k);
        ang += kDqDt[k][c] * J_dh.block<3, 1>(3, k);
      }
      J.block<3, 1>(0, c) = 1e3 * (R * lin);
      J.block<3, 1>(3, c) = R * ang;
    }
  }
  Eigen::Matrix<double, 6, 1> qdot = Eigen::Matrix<double, 6, 1>::Zero();
  if (have_last_ && dt_s > 0.0) qdot = (q - q_last_) / dt_s;
  v_mm_s = st.has(kStateVelocity) ? st.velocity_mm_s
                                  : Vec3(J.topRows<3>() * qdot);
  const Vec3 w = J.bottomRows<3>() * qdot;
  Eigen::Map<Eigen::Matrix4d>(f.transform) = T;
  Eigen::Map<Eigen::Matrix<double, 6, 6>>(f.jacobian) = J;
  for (int i = 0; i < 3; ++i) {
    f.position_mm[i] = T(i, 3);
    f.velocity_mm_s[i] = v_mm_s[i];
    f.angular_velocity_rad_s[i] = w[i];
  }
}

unsigned HdDevice::sample(double now_s) noexcept {
  last_ = cur_;
  const double dt_s = have_last_ ? now_s - last_now_s_ : period_s_;
  command_ = HdCommand{};
  DeviceState st;
  safety_->set_read_time(now_s);
  const DeviceError e = safety_->read_state(&st);
  unsigned errors = 0;
  HdFrame& f = cur_;
  f.t_s = now_s;
  f.rate_hz = dt_s > 0.0 ? 1.0 / dt_s : 0.0;
  if (e != DeviceError::kOk || !st.has(kStateJoints)) {
    if (!read_failed_) errors |= bit(kErrComm);
    read_failed_ = true;
    f.valid = false;
    last_now_s_ = now_s;
    return errors;
  }
  read_failed_ = false;
  f.valid = true;
  const Joints& q = st.q_device_rad;
  for (int i = 0; i < 3; ++i) {
    f.joint_angles_rad[i] = q[i];
    f.gimbal_angles_rad[i] = q[3 + i];
  }
  fill_kinematics(st, dt_s);
  for (int i = 0; i < 3; ++i) {
    f.encoders[i] = st.has(kStateEncoders)
                        ? st.encoder_counts[static_cast<std::size_t>(i)]
                        : std::lround(q[i] * kCountsPerRev / (2.0 * kPi));
    f.encoders[3 + i] = st.has(kStatePots)
                            ? st.gimbal_pots[static_cast<std::size_t>(i)]
                            : 0;
  }
  f.buttons = st.has(kStateButtons) ? static_cast<int>(st.buttons) : 0;
  const bool docked = st.has(kStateInkwell) && st.docked;
  f.inkwell = docked ? 0 : 1;
  f.safety_switch = st.has(kStateSafetySwitch) && st.safety_switch ? 1 : 0;
  const Vec3& heat = safety_->thermal_state();
  for (int i = 0; i < 3; ++i) {
    f.motor_temperature[i] = std::clamp(heat[i] / 2.0, 0.0, 1.0);
  }
  safety_->set_inputs(docked, true);
  q_last_ = q;
  have_last_ = true;
  last_now_s_ = now_s;
  return errors;
}

unsigned HdDevice::send() noexcept {
  HdFrame& f = cur_;
  const HdCommand& c = command_;
  Vec3 tau_motor_Nm = Vec3::Zero();
  if (f.valid) {
    // a force at the wrist centre (device frame) to the DH joints by J_v^T,
    // then to the motors (controller/device_frame.h)
    const Vec3 F_device(c.force_N[0], c.force_N[1], c.force_N[2]);
    const Joints q_dh = device_to_dh_joints(Joints(
        (Joints() << f.joint_angles_rad[0], f.joint_angles_rad[1],
         f.joint_angles_rad[2], f.gimbal_angles_rad[0], f.gimbal_angles_rad[1],
         f.gimbal_angles_rad[2])
            .finished()));
    const OmniArmKinematics arm = omni_arm_kinematics(omni_, q_dh);
    const Vec3 F_base = R_device_base().transpose() * F_device;
    tau_motor_Nm = dh_to_motor_torques(arm.Jv_arm.transpose() * F_base);
    for (int i = 0; i < 3; ++i) {
      tau_motor_Nm[i] += c.joint_torque_mNm[i] * 1e-3;
      if (c.dac_set) {
        tau_motor_Nm[i] += static_cast<double>(c.dac[i]) / kDacFullScale *
                           omni_.motor_torque_limit_Nm[static_cast<std::size_t>(i)];
      }
    }
  }
  for (int i = 0; i < 3; ++i) {
    f.force_N[i] = c.force_N[i];
    f.joint_torque_mNm[i] = c.joint_torque_mNm[i];
    f.gimbal_torque_mNm[i] = c.gimbal_torque_mNm[i];
    f.dac[i] = c.dac[i];
  }
  safety_->set_force_output(settings_.force_output.load(std::memory_order_relaxed));
  safety_->write_motor_torques(tau_motor_Nm);
  const SafetyStatus s = safety_->status();
  const SafetyStatus rising = s & ~last_status_;
  last_status_ = s;
  unsigned errors = 0;
  if ((rising & (kSafetyForceClamped | kSafetyTorqueClamped)) &&
      !settings_.max_force_clamping.load(std::memory_order_relaxed)) {
    errors |= bit(kErrForce);
  }
  if ((rising & kSafetyForceImpulseLimited) &&
      settings_.impulse_limit_on.load(std::memory_order_relaxed)) {
    errors |= bit(kErrImpulse);
  }
  if (rising & kSafetyVelocityExceeded) errors |= bit(kErrVelocity);
  if (rising & (kSafetyMotorWarm | kSafetyMotorHot)) errors |= bit(kErrWarm);
  if (rising & kSafetyCommLost) errors |= bit(kErrComm);
  pub_.write(Published{cur_, last_});
  return errors;
}

void HdDevice::send_zero() noexcept {
  if (opened_.backend) opened_.backend->device()->write_motor_torques(Vec3::Zero());
}

void HdDevice::published(HdFrame* current, HdFrame* last) const noexcept {
  const Published p = pub_.read();
  if (current) *current = p.current;
  if (last) *last = p.last;
}

bool HdDevice::read_truth(PlantTruth* truth) const noexcept {
  if (opened_.truth == nullptr) return false;
  opened_.truth->read_truth(truth);
  return true;
}

}  // namespace vmh::hd
