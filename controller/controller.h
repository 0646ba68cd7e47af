// The virtual-mechanism controller for the PHANTOM Omni (thesis ch. 3).
//
// Each servo tick it reads the six DH joint angles and
//   1. computes the RM pose: wrist centre p (device frame) and stylus axis a
//      (the z column of the OpenHaptics stylus transform);
//   2. places the VM: theta_V by weighted Gauss-Newton (eq. 3.15-3.16) warm
//      started from the last tick, or by the closed forms of §3.3.1/§3.4.1,
//      and theta_R, the VM angles aligned with the stylus;
//   3. forms the error e = X_V - X_R (eq. 3.9) in the `thesis` or the
//      `geometric` formulation, and its rate from the last tick;
//   4. f_motion = (I - W_A J_V (J_V^T W_A J_V)^-1 J_V^T)(K_p e + K_v e_dot)
//      (eq. 3.11, Appendix D's W_A), regularised where J_V loses rank;
//   5. sends rows 0-2 of f_motion as the device force (Appendix D, listing
//      D.3), saturated to the force limit, and tau = J_r^T F for the three
//      actuated joints (eq. 3.12), saturated to the motor limits.
//
// Units. The controller's length unit is `length_unit_mm` (1 mm by default,
// as in the thesis): e rows 0-2, X_V and J_V's translational rows are in it,
// e rows 3-5 in rad; f_motion rows 0-2 in N and rows 3-5 in N x length unit.
// The projection is not invariant to this unit (docs/sources.md §3): J_V^T J_V
// adds length^2 to 1. Gains are stored in physical units (N/mm, N mm/rad)
// and converted, so a change of unit changes only the projection.
//
// Real time. Construction validates the parameters (std::invalid_argument
// naming the field) and allocates everything; tick() allocates nothing and
// throws nothing (tests/controller/no_alloc_test.cc) and returns a status.
#ifndef VMHAPTICS_CONTROLLER_CONTROLLER_H_
#define VMHAPTICS_CONTROLLER_CONTROLLER_H_

#include <cstdint>
#include <memory>

#include "controller/control_law.h"
#include "controller/controller_params.h"
#include "controller/omni_kinematics.h"

namespace vmh {

// Status bits returned by tick(). Faults zero the force; the rest inform.
enum StatusFlag : std::uint32_t {
  kStatusOk = 0,
  kStatusInvalidInput = 1u << 0,       // fault: a joint angle is NaN or inf
  kStatusNumericalFault = 1u << 1,     // fault: a non-finite intermediate
  kStatusOutsideJointLimits = 1u << 2, // q outside OmniParams' ranges
  kStatusVmSingular = 1u << 3,         // J_V^T W_A J_V regularised
  kStatusPlacementNotConverged = 1u << 4,
  kStatusRmAtPivot = 1u << 5,          // theta_V undefined; last one kept
  kStatusOrientationDegenerate = 1u << 6,  // theta_R undefined; last kept
  kStatusForceSaturated = 1u << 7,
  kStatusTorqueSaturated = 1u << 8,
  kStatusContactSliding = 1u << 9,     // surface: friction overcome
  kStatusContactOpen = 1u << 10,       // surface: unilateral, lifted off
};
using ControlStatus = std::uint32_t;
inline constexpr int kStatusFlagCount = 11;
inline constexpr ControlStatus kStatusFaults =
    kStatusInvalidInput | kStatusNumericalFault;

// "invalid_input", "numerical_fault", ... for one bit; "ok" for 0
const char* status_flag_name(ControlStatus flag);
inline bool is_fault(ControlStatus s) { return (s & kStatusFaults) != 0; }

// One tick's inputs, results and diagnostics. Device frame unless named.
struct ControlOutput {
  ControlStatus status = kStatusOk;
  VmAngles theta_v;  // placed VM (rad; surface s1, s2 in the length unit)
  VmAngles theta_r;  // VM aligned with the stylus
  Vec3 p_rm_mm = Vec3::Zero();  // wrist centre
  Vec3 axis_rm = Vec3::UnitZ();  // stylus axis (unit)
  Vec3 x_v_mm = Vec3::Zero();    // X(theta_V) position
  Vec3 x_r_mm = Vec3::Zero();    // X(theta_R) position
  Vec6 e = Vec6::Zero();         // controller units (length unit, rad)
  Vec6 e_dot = Vec6::Zero();     // per s
  Vec6 f_motion = Vec6::Zero();  // N, N x length unit; before saturation
  Vec3 force_device_N = Vec3::Zero();  // commanded, after saturation
  Vec3 force_base_N = Vec3::Zero();    // the same in the DH base frame
  Vec3 tau_dh_Nm = Vec3::Zero();       // tau = J_r^T F, DH joints q1..q3
  Vec3 tau_motor_Nm = Vec3::Zero();    // motor torques, device joints t1..t3
  int placement_iterations = 0;
  double placement_cost = 0.0;
  double vm_rcond = 1.0;
};

class Controller {
 public:
  // Validates and allocates. Throws std::invalid_argument.
  explicit Controller(const ControllerParams& params);

  // One servo tick from the six joint angles (DH convention, rad). Never
  // allocates, never throws. On a fault the force and torques are zero and
  // the warm start is kept.
  ControlStatus tick(const Joints& q_dh, ControlOutput* out) noexcept;

  // Forgets the warm start and the previous error (e.g. after a fault).
  void reset() noexcept;

  const ControllerParams& params() const { return params_; }
  const VirtualMechanism& mechanism() const { return *vm_; }

 private:
  // theta_V from the warm start (or the closed form); fills the placement
  // diagnostics of *out. *posed says whether *pose and J_ already hold
  // X_V and J_V at theta_V (the closed form gives them with the angles)
  ControlStatus place(const RmPose& rm, JointMask locked, ControlOutput* out,
                      VmPose* pose, bool* posed) noexcept;
  // place, then e, e_dot and f_motion into *out
  ControlStatus evaluate(const RmPose& rm, JointMask locked,
                         ControlOutput* out) noexcept;
  // evaluate, and for a VM with a contact, hold, slide or open it
  ControlStatus evaluate_with_contact(const RmPose& rm,
                                      ControlOutput* out) noexcept;
  // r^T W r of the placement residual at the placed pose (closed form)
  double closed_form_cost(const VmPose& vm_pose,
                          const RmPose& rm) const noexcept;
  // the RM's pose from the arm's one-pass kinematics (also into *out's
  // p_rm_mm, axis_rm)
  RmPose rm_pose(const OmniArmKinematics& arm,
                 ControlOutput* out) const noexcept;
  // rows 0-2 of f_motion saturated to the force limit, tau = J_r^T F
  // (eq. 3.12, J_r the wrist centre's Jacobian for q1..q3 from the same
  // pass as the pose), the motor torques scaled into their limits; only
  // kStatusNumericalFault, writing nothing, when |F|^2 or a torque is not
  // finite (an overflow must not pass for a saturation)
  ControlStatus saturate_and_map(const Mat3& Jv_arm,
                                 ControlOutput* out) const noexcept;
  // a non-finite joint angle: zero output, restart e_dot
  ControlStatus fail_input(ControlOutput* out) noexcept;

  ControllerParams params_;
  std::unique_ptr<VirtualMechanism> vm_;
  // gains and weights in the controller's units
  Vec6 kp_, kv_;
  double velocity_alpha_ = 1.0;
  // workspace, preallocated
  VmAngles theta_v_, theta_r_, seed_;
  bool placed_ = false;         // theta_v_ holds a placement
  bool have_previous_ = false;  // e_previous_ holds the last tick's error
  Vec6 e_previous_ = Vec6::Zero();
  Vec6 e_dot_filtered_ = Vec6::Zero();
  VmJacobian J_, J_active_;
};

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_CONTROLLER_H_
