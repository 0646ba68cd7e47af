// The emulator's hand programs (sim/emulator.h, HandProgram): where the hand
// puts the stylus while nobody holds the device, and the inkwell switch.
// Runs in the emulator's physics thread only: noexcept, no allocation.
#ifndef VMHAPTICS_SIM_EMULATOR_HAND_H_
#define VMHAPTICS_SIM_EMULATOR_HAND_H_

#include "controller/types.h"
#include "sim/closed_loop.h"
#include "sim/emulator.h"

namespace vmh::sim {

class EmulatorHand {
 public:
  // Takes the loop's current pose (its start pose, after reset) as the
  // tour's centre and the stylus's reference orientation.
  explicit EmulatorHand(ClosedLoop* loop);

  // Sets the hand's target for program p at emulator time t_s (a program
  // other than kCase runs on its own clock from when it was selected).
  // Fills the target as a ScriptPose (device frame) and, for kCase, the
  // script's segment (0 otherwise).
  void set_target(HandProgram p, double t_s, ScriptPose* target,
                  int* segment) noexcept;

  // the wrist pose (device frame, mm; stylus axis) that a grip target
  // (world frame, SI) asks for: kManual's target as the truth records it
  ScriptPose wrist_pose_of(const HandTargetState& grip_target) const noexcept;

  // kNone: puts the target on the grip's present pose and velocity, so the
  // hand's spring and damper exert nothing at the start of the next step.
  // Call before each mj_step.
  void let_go() noexcept;

  // Whether the true joint angles (DH) put the stylus in the inkwell
  // (kDockRadius_mm, kDockAngle_deg); the true wrist centre (mm) and
  // stylus axis (device frame) on the way.
  bool docked(const Joints& q_true_dh, Vec3* p_mm, Vec3* axis) const noexcept;

  const Vec3& inkwell_mm() const { return inkwell_mm_; }
  const Vec3& inkwell_axis() const { return inkwell_axis_; }

 private:
  // wrist centre (m) and stylus rotation, DH base frame, at program time
  // tau of program p
  void pose_at(HandProgram p, double tau_s, Vec3* wrist_m, Mat3* R) const
      noexcept;
  void send(const Vec3& wrist_m, const Mat3& R, const Vec3& wrist2_m,
            const Mat3& R2, double dt_s) noexcept;

  ClosedLoop* loop_;
  OmniParams omni_;
  Vec3 grip_local_m_ = Vec3::Zero();  // grip site in the stylus body
  Mat3 R_site_ = Mat3::Identity();
  // the start pose: the tour's centre and reference orientation
  Vec3 p_start_m_ = Vec3::Zero();
  Mat3 R_start_ = Mat3::Identity();
  // the inkwell
  Joints inkwell_dh_ = Joints::Zero();
  Vec3 inkwell_m_ = Vec3::Zero();
  Mat3 R_inkwell_ = Mat3::Identity();
  Vec3 inkwell_mm_ = Vec3::Zero();
  Vec3 inkwell_axis_ = Vec3::UnitZ();
  // the program running, since when, and the pose it started from
  int program_ = -1;
  double t0_s_ = 0.0;
  Joints q_from_dh_ = Joints::Zero();
  Vec3 p_from_m_ = Vec3::Zero();
  Mat3 R_from_ = Mat3::Identity();
  // kDock: the target's correction by the remaining error, m
  Vec3 dock_correction_m_ = Vec3::Zero();
  double last_t_s_ = 0.0;
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_EMULATOR_HAND_H_
