// The simulated human hand: a 6-DOF impedance (mass, damping, stiffness in
// translation and rotation) between the stylus grip and a scripted target.
//
// The hand's mass and inertia are added to the body that carries the "grip"
// site, so the model keeps its six degrees of freedom (and its keyframes).
// The spring-damper is a wrench computed at every physics step from the grip
// site's pose and velocity and the target's, and applied at the grip through
// d->qfrc_applied:
//   F   = K_p (p_target - p_grip) + B_p (v_target - v_grip)
//   tau = K_r r(R_target R_grip^T) + B_r (w_target - w_grip)
// with r(.) the rotation vector, all in the world (DH base) frame, SI units.
// Parameters: models/hand/README.md (docs/sources.md §10).
//
// Who computes the wrench: MuJoCo's global mjcb_control, whose one owner is
// this file. The first SimHand installs hand_control_callback() there; each
// SimHand registers the mjData it was built for, and the callback applies
// the hand registered for the data being stepped (and does nothing for data
// without one). So the physics of a scene is the same whoever calls mj_step
// or mj_forward on its data (the closed loop, a viewer, a test), in any
// thread, and nobody sets mjcb_control per tick. Where other code owns
// mjcb_control already (another copy of this file: libHD.so over the
// emulator, loaded by the command line), the first SimHand keeps that
// callback and hands it the data it has no hand for; the last one gone
// puts it back. While a hand is
// registered, d->qfrc_applied is the hand's: it is overwritten at every
// evaluation.
#ifndef VMHAPTICS_SIM_HAND_H_
#define VMHAPTICS_SIM_HAND_H_

#include <mujoco/mujoco.h>

#include <string>

#include "controller/types.h"
#include "sim/cases/case_config.h"

namespace vmh::sim {

struct HandParams {
  double mass_kg = 0.554;
  Vec3 inertia_kgm2 = Vec3::Constant(2e-4);  // about the grip, grip-site axes
  double k_pos_N_per_m = 135.0;
  double b_pos_Ns_per_m = 6.45;
  // an anisotropic hand: stiffness and damping along the device frame's x,
  // y, z (docs/frames: x right, y up, z toward the user) instead of the
  // scalars; zero: the scalar on every axis
  Vec3 k_pos_axes_N_per_m = Vec3::Zero();
  Vec3 b_pos_axes_Ns_per_m = Vec3::Zero();
  double k_rot_Nm_per_rad = 0.5;
  double b_rot_Nms_per_rad = 0.02;
};

// The hand of a case (its hand_* parameters).
HandParams hand_params(const CaseParams& c);

// The target's pose and twist, world (DH base) frame, SI.
struct HandTargetState {
  Vec3 p_m = Vec3::Zero();
  Mat3 R = Mat3::Identity();
  Vec3 v_m_s = Vec3::Zero();
  Vec3 w_rad_s = Vec3::Zero();
};

class SimHand {
 public:
  // Finds the "grip" site and the "hand_target" mocap body, adds the hand's
  // mass to the grip's body, recomputes the model's constants
  // (mj_setConst), and registers itself as the hand of `d` (see above).
  // Throws SimError naming what is missing, if `d` already has a hand, if
  // too many hands are registered at once (kMaxHands). `m` and `d` must
  // outlive the hand.
  SimHand(mjModel* m, mjData* d, const HandParams& params,
          const std::string& source);
  // unregisters: stepping `d` afterwards applies no hand
  ~SimHand();
  SimHand(const SimHand&) = delete;
  SimHand& operator=(const SimHand&) = delete;

  // the most hands registered at once (one per concurrently simulated scene)
  static constexpr int kMaxHands = 64;

  // Sets the target (and moves the mocap body, for viewing).
  void set_target(const mjModel* m, mjData* d, const HandTargetState& target);

  // Clears d->qfrc_applied and adds the hand's wrench. Positions and
  // velocities in d must be current (mjcb_control calls it; or after
  // mj_forward). Allocates nothing.
  void apply(const mjModel* m, mjData* d);

  // the data this hand is registered for
  const mjData* data() const { return data_; }

  // the last wrench applied at the grip, world frame
  const Vec3& force_N() const { return force_N_; }
  const Vec3& torque_Nm() const { return torque_Nm_; }
  const HandParams& params() const { return params_; }
  int grip_site() const { return grip_site_; }
  const HandTargetState& target() const { return target_; }

 private:
  HandParams params_;
  // the per-axis stiffness and damping as world (DH base) frame matrices,
  // when given
  bool k_axes_ = false, b_axes_ = false;
  Mat3 K_world_ = Mat3::Zero(), B_world_ = Mat3::Zero();
  const mjData* data_ = nullptr;
  int grip_site_ = -1;
  int grip_body_ = -1;
  // the hinge joints between the grip's body and the world, when every
  // joint there is a hinge (the Omni's chain): apply() maps the wrench to
  // them as axis . (tau + (p - anchor) x F), the same J^T [F; tau] that
  // mj_applyFT forms through mj_jac, without its stack and its loop over
  // the whole tree. chain_count_ < 0: some other joint, so mj_applyFT.
  static constexpr int kMaxChain = 16;
  int chain_joint_[kMaxChain] = {};
  int chain_count_ = -1;
  int target_mocap_ = -1;
  HandTargetState target_;
  Vec3 force_N_ = Vec3::Zero();
  Vec3 torque_Nm_ = Vec3::Zero();
};

// The control callback the hands install (exposed for tests): applies the
// hand registered for `d`, if any.
void hand_control_callback(const mjModel* m, mjData* d);

// The hand registered for `d`, or nullptr. Allocates nothing, takes no lock.
SimHand* registered_hand(const mjData* d);

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_HAND_H_
