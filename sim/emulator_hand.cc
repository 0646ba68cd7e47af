#include "sim/emulator_hand.h"

#include <algorithm>
#include <cmath>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"

namespace vmh::sim {
namespace {

using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

using constants::kPi;
constexpr double kTwoPi = 2.0 * kPi;
// the time the hand takes to carry the stylus to the inkwell, s
constexpr double kDockMove_s = 1.5;
// kDock: rate at which the remaining error corrects the target, 1/s, and
// the largest correction, m
constexpr double kDockGain_per_s = 3.0;
constexpr double kDockMaxCorrection_m = 0.03;
// kGimbalSweep: how far past each end of the range the target goes, rad
constexpr double kSweepPast_rad = 0.15;

// 0 -> 1 with zero slope at both ends
double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

Mat3 rot(const Vec3& axis, double angle_rad) {
  return Eigen::AngleAxisd(angle_rad, axis).toRotationMatrix();
}

Joints inkwell_dh() {
  Joints t;
  for (int i = 0; i < 6; ++i) t[i] = kInkwellDevice_rad[i];
  return device_to_dh_joints(t);
}

}  // namespace

EmulatorHand::EmulatorHand(ClosedLoop* loop)
    : loop_(loop), omni_(loop->controller_params().omni) {
  const mjModel* m = loop->model();
  const int g = loop->hand().grip_site();
  grip_local_m_ = Vec3(m->site_pos + 3 * g);
  RowMat3 R_site;
  mju_quat2Mat(R_site.data(), m->site_quat + 4 * g);
  R_site_ = R_site;
  const OmniPose start = omni_fk(omni_, loop->device().true_q_dh());
  p_start_m_ = start.p_base_m;
  R_start_ = start.R_base;
  inkwell_dh_ = inkwell_dh();
  const OmniPose ink = omni_fk(omni_, inkwell_dh_);
  inkwell_m_ = ink.p_base_m;
  R_inkwell_ = ink.R_base;
  inkwell_mm_ = base_to_device_mm(omni_, ink.p_base_m);
  inkwell_axis_ = base_to_device_vector(ink.R_base.col(2));
  q_from_dh_ = loop->device().true_q_dh();
  p_from_m_ = p_start_m_;
  R_from_ = R_start_;
}

void EmulatorHand::pose_at(HandProgram p, double tau, Vec3* wrist_m,
                           Mat3* R) const noexcept {
  switch (p) {
    case HandProgram::kCase:
    case HandProgram::kNone:
    case HandProgram::kManual:
      *wrist_m = p_from_m_;
      *R = R_from_;
      return;
    case HandProgram::kTour: {
      // a Lissajous curve (1, 2, 3 turns per period) through the start
      // point; the stylus tilts about its x and y axes and rolls about z
      const double w = kTwoPi / kTourPeriod_s;
      const double a = kTourAmplitude_mm * 1e-3;
      const Vec3 d_device_m(a * std::sin(w * tau), 0.7 * a * std::sin(2 * w * tau),
                            0.6 * a * std::sin(3 * w * tau));
      *wrist_m = p_start_m_ + device_to_base_vector(d_device_m);
      *R = R_start_ * rot(Vec3::UnitX(), 0.5 * std::sin(w * tau)) *
           rot(Vec3::UnitY(), 0.5 * std::sin(2 * w * tau)) *
           rot(Vec3::UnitZ(), 0.6 * std::sin(w * tau));
      return;
    }
    case HandProgram::kDock: {
      const double s = smoothstep(tau / kDockMove_s);
      *wrist_m = (1.0 - s) * p_from_m_ + s * inkwell_m_ + dock_correction_m_;
      const Eigen::Quaterniond q0(R_from_), q1(R_inkwell_);
      *R = q0.slerp(s, q1).toRotationMatrix();
      return;
    }
    case HandProgram::kGimbalSweep: {
      // joint j = 3, 4, 5 in turn: to its upper end, to its lower end, back
      Joints q = q_from_dh_;
      const int leg = static_cast<int>(std::floor(tau / kSweepLeg_s));
      if (leg >= 0 && leg < 9) {
        const int j = 3 + leg / 3;
        const auto k = static_cast<std::size_t>(j);
        const double hi = omni_.joint_upper_rad[k] + kSweepPast_rad;
        const double lo = omni_.joint_lower_rad[k] - kSweepPast_rad;
        const double from[3] = {q_from_dh_[j], hi, lo};
        const double to[3] = {hi, lo, q_from_dh_[j]};
        const double s = smoothstep(tau / kSweepLeg_s - leg);
        q[j] = from[leg % 3] + s * (to[leg % 3] - from[leg % 3]);
      }
      *wrist_m = p_from_m_;
      *R = omni_fk(omni_, q).R_base;
      return;
    }
  }
}

void EmulatorHand::send(const Vec3& wrist_m, const Mat3& R,
                        const Vec3& wrist2_m, const Mat3& R2,
                        double dt_s) noexcept {
  HandTargetState target;
  target.p_m = wrist_m + R * grip_local_m_;
  target.R = R * R_site_;
  const Vec3 p2 = wrist2_m + R2 * grip_local_m_;
  target.v_m_s = (p2 - target.p_m) / dt_s;
  const Eigen::AngleAxisd dR(R2 * R_site_ * target.R.transpose());
  target.w_rad_s = dR.angle() * dR.axis() / dt_s;
  loop_->hand().set_target(loop_->model(), loop_->data(), target);
}

void EmulatorHand::set_target(HandProgram p, double t_s, ScriptPose* target,
                              int* segment) noexcept {
  *segment = 0;
  if (static_cast<int>(p) != program_) {
    // a new program starts from where the stylus is
    program_ = static_cast<int>(p);
    t0_s_ = t_s;
    q_from_dh_ = loop_->device().true_q_dh();
    const OmniPose now = omni_fk(omni_, q_from_dh_);
    p_from_m_ = now.p_base_m;
    R_from_ = now.R_base;
    dock_correction_m_.setZero();
    last_t_s_ = t_s;
  }
  if (p == HandProgram::kCase) {
    loop_->set_hand_target(t_s);
    const double t_end = loop_->config().sim.duration_s;
    const double t = std::min(t_s, t_end);
    *segment = loop_->script().segment_at(t);
    *target = loop_->script().at(t);
    return;
  }
  const double tau = t_s - t0_s_;
  if (p == HandProgram::kDock && tau > kDockMove_s) {
    // guide the stylus by the remaining error (an integrator on the target)
    const Vec3 p_true = omni_fk(omni_, loop_->device().true_q_dh()).p_base_m;
    dock_correction_m_ += kDockGain_per_s * (t_s - last_t_s_) * (inkwell_m_ - p_true);
    for (int i = 0; i < 3; ++i) {
      dock_correction_m_[i] = std::clamp(dock_correction_m_[i],
                                         -kDockMaxCorrection_m,
                                         kDockMaxCorrection_m);
    }
  }
  last_t_s_ = t_s;
  Vec3 w1, w2;
  Mat3 R1, R2;
  const double dt = 1e-5;
  pose_at(p, tau, &w1, &R1);
  pose_at(p, tau + dt, &w2, &R2);
  // kNone lets go and kManual is set by the emulator: neither is sent here
  if (p != HandProgram::kNone && p != HandProgram::kManual) {
    send(w1, R1, w2, R2, dt);
  }
  target->p_mm = base_to_device_mm(omni_, w1);
  target->axis = base_to_device_vector(R1.col(2));
}

ScriptPose EmulatorHand::wrist_pose_of(const HandTargetState& g) const noexcept {
  const Mat3 R_stylus = g.R * R_site_.transpose();
  ScriptPose pose;
  pose.p_mm = base_to_device_mm(omni_, g.p_m - R_stylus * grip_local_m_);
  pose.axis = base_to_device_vector(R_stylus.col(2));
  return pose;
}

void EmulatorHand::let_go() noexcept {
  const mjModel* m = loop_->model();
  mjData* d = loop_->data();
  // the grip's pose and velocity at the present state, computed as the
  // hand's own callback will compute them
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  const int g = loop_->hand().grip_site();
  HandTargetState target;
  target.p_m = Vec3(d->site_xpos + 3 * g);
  target.R = Eigen::Map<const RowMat3>(d->site_xmat + 9 * g);
  mjtNum vel[6];
  mj_objectVelocity(m, d, mjOBJ_SITE, g, vel, 0);
  target.w_rad_s = Vec3(vel[0], vel[1], vel[2]);
  target.v_m_s = Vec3(vel[3], vel[4], vel[5]);
  loop_->hand().set_target(m, d, target);
}

bool EmulatorHand::docked(const Joints& q_true_dh, Vec3* p_mm,
                          Vec3* axis) const noexcept {
  const OmniPose pose = omni_fk(omni_, q_true_dh);
  *p_mm = base_to_device_mm(omni_, pose.p_base_m);
  *axis = base_to_device_vector(pose.R_base.col(2));
  const double cos_angle = std::clamp(axis->dot(inkwell_axis_), -1.0, 1.0);
  return (*p_mm - inkwell_mm_).norm() <= kDockRadius_mm &&
         std::acos(cos_angle) <= kDockAngle_deg * kPi / 180.0;
}

}  // namespace vmh::sim
