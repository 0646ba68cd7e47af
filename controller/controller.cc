#include "controller/controller.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/trig.h"
#include "controller/vm_registry.h"

namespace vmh {

using constants::kPi;

const char* status_flag_name(ControlStatus flag) {
  switch (flag) {
    case kStatusOk:
      return "ok";
    case kStatusInvalidInput:
      return "invalid_input";
    case kStatusNumericalFault:
      return "numerical_fault";
    case kStatusOutsideJointLimits:
      return "outside_joint_limits";
    case kStatusVmSingular:
      return "vm_singular";
    case kStatusPlacementNotConverged:
      return "placement_not_converged";
    case kStatusRmAtPivot:
      return "rm_at_pivot";
    case kStatusOrientationDegenerate:
      return "orientation_degenerate";
    case kStatusForceSaturated:
      return "force_saturated";
    case kStatusTorqueSaturated:
      return "torque_saturated";
    case kStatusContactSliding:
      return "contact_sliding";
    case kStatusContactOpen:
      return "contact_open";
    default:
      return "unknown";
  }
}

Controller::Controller(const ControllerParams& params) : params_(params) {
  params_.validate();
  const double u = params_.length_unit_mm;
  VmMount mount;
  mount.origin = params_.vm.pivot_mm / u;
  mount.R = params_.vm.R_pivot;
  const double L = params_.vm.length_mm / u;
  vm_ = make_vm(params_.vm.kind, mount, L);
  // eq. 3.28 in the controller's unit u: N/u for position, N u/rad for
  // orientation
  const Gains& g = params_.gains;
  kp_ << Eigen::Vector3d::Constant(g.k_pos_N_per_mm * u),
      Eigen::Vector3d::Constant(g.k_ornt_Nmm_per_rad / u);
  kv_ << Eigen::Vector3d::Constant(g.k_vel_Ns_per_mm * u),
      Eigen::Vector3d::Constant(g.k_vel_ornt_Nmms_per_rad / u);
  if (params_.velocity_cutoff_Hz > 0.0) {
    const double tau = 1.0 / (2.0 * kPi * params_.velocity_cutoff_Hz);
    velocity_alpha_ = params_.servo_period_s / (params_.servo_period_s + tau);
  }
  J_.resize(6, vm_->dof());
  J_active_.resize(6, vm_->dof());
  reset();
}

void Controller::reset() noexcept {
  // the surface's probe starts upright; its first tick slides the contact
  // under the stylus
  theta_v_ = vm_->rest_angles();
  theta_r_ = vm_->rest_angles();
  seed_ = vm_->zero_angles();
  placed_ = false;
  have_previous_ = false;
  e_previous_.setZero();
  e_dot_filtered_.setZero();
}

namespace {

// whether `seed` has a lower placement cost r^T W r than `warm`
bool lower_cost(const VirtualMechanism& vm, const RmPose& rm, const Vec6& w,
                const VmAngles& seed, const VmAngles& warm) {
  const Vec6 r_warm = placement_residual(vm, rm, warm);
  const Vec6 r_seed = placement_residual(vm, rm, seed);
  return r_seed.dot(w.cwiseProduct(r_seed)) <
         r_warm.dot(w.cwiseProduct(r_warm));
}

// *theta, the warm start, replaced by the closed form's `seed` where that
// is better under W: a warm start can sit on the wrong side of a circle
// after a fast move, and for W_p the closed form is already the answer
void start_from_better(const VirtualMechanism& vm, const RmPose& rm,
                       const Vec6& w, const VmAngles& seed, VmAngles* theta) {
  if ((w.tail<3>().array() != 0.0).any()) {
    if (lower_cost(vm, rm, w, seed, *theta)) *theta = seed;
  } else if (vm.nearest_minimises_distance() && w[1] == w[0] && w[2] == w[0]) {
    // W_p with equal weights is the distance, and the seed minimises it
    // over the whole path: the warm start cannot be lower
    *theta = seed;
  } else {
    // the orientation rows would add exactly 0: positions only
    const Vec3 r_warm = rm.p - vm.position(*theta);
    const Vec3 r_seed = rm.p - vm.position(seed);
    if (r_seed.dot(w.head<3>().cwiseProduct(r_seed)) <
        r_warm.dot(w.head<3>().cwiseProduct(r_warm))) {
      *theta = seed;
    }
  }
}

// Where the VM has its cost's minimiser in closed form (the surface under
// block-isotropic W), *theta replaced by it if it is better still (*seed
// the workspace): the surface's iteration converges only linearly (its
// residual does not vanish), so from a warm start alone it took ~35
// iterations per tick
void start_from_minimum(const VirtualMechanism& vm, const RmPose& rm,
                        const Vec6& w, JointMask locked, VmAngles* seed,
                        VmAngles* theta) {
  const bool isotropic =
      w[1] == w[0] && w[2] == w[0] && w[4] == w[3] && w[5] == w[3];
  if (!isotropic || !(locked == 0u || locked == vm.stick_joints())) return;
  *seed = *theta;
  if (vm.placement_minimum(rm, w[0], w[3], locked != 0u, seed) &&
      lower_cost(vm, rm, w, *seed, *theta)) {
    *theta = *seed;
  }
}

}  // namespace

ControlStatus Controller::place(const RmPose& rm, JointMask locked,
                                ControlOutput* out, VmPose* pose,
                                bool* posed) noexcept {
  ControlStatus st = kStatusOk;
  *posed = false;
  const bool contact_sliding = vm_->has_contact() && locked == 0u;
  const bool closed_form = params_.placement == PlacementMethod::kClosedForm;
  // the closed form: nearest point (circle, sphere, sticking surface); for
  // a sliding surface the probe aligned with the stylus, tip on the plane.
  // Where it is the placement, its pose and J_V come with it
  // (and Gauss-Newton's first iteration takes them where it starts from
  // the closed form's answer: the circle's and the sphere's nearest point)
  seed_ = theta_v_;
  bool seed_ok;
  bool seed_posed = false;
  if (contact_sliding) {
    seed_ok = vm_->aligned(rm, &seed_);
  } else if (closed_form || vm_->nearest_minimises_distance()) {
    seed_ok = vm_->nearest_pose_jacobian(rm, &seed_, pose, &J_);
    seed_posed = seed_ok;
  } else {
    seed_ok = vm_->nearest(rm, &seed_);
  }
  if (!seed_ok) st |= kStatusRmAtPivot;
  // where *pose and J_ were computed (seed_ is reused below)
  const VmAngles posed_at = seed_;
  if (!placed_ && seed_ok) theta_v_ = seed_;
  if (closed_form) {
    *posed = seed_posed;
    if (seed_ok) theta_v_ = seed_;
    out->placement_iterations = 0;
    // r^T W r at theta_V: evaluate() computes it from the pose it needs
    // anyway (closed_form_cost)
    return st;
  }
  const Vec6& w = params_.placement_options.weights;
  if (seed_ok) start_from_better(*vm_, rm, w, seed_, &theta_v_);
  start_from_minimum(*vm_, rm, w, locked, &seed_, &theta_v_);
  // the pose and J_V at the seed serve while theta_V is still the seed,
  // bit for bit (a converged step below the angles' ulp leaves it so)
  const bool start_posed = seed_posed && theta_v_ == posed_at;
  const PlacementResult res = place_gauss_newton(
      *vm_, rm, params_.placement_options, locked, &theta_v_,
      start_posed ? pose : nullptr, start_posed ? &J_ : nullptr);
  *posed = start_posed && theta_v_ == posed_at;
  if (!res.converged) st |= kStatusPlacementNotConverged;
  out->placement_iterations = res.iterations;
  out->placement_cost = res.cost;
  return st;
}

ControlStatus Controller::evaluate(const RmPose& rm, JointMask locked,
                                   ControlOutput* out) noexcept {
  VmPose vm_pose;
  bool posed = false;
  ControlStatus st = place(rm, locked, out, &vm_pose, &posed);
  const double u = params_.length_unit_mm;
  if (!posed) vm_->pose_jacobian(theta_v_, &vm_pose, &J_);
  if (params_.placement == PlacementMethod::kClosedForm) {
    out->placement_cost = closed_form_cost(vm_pose, rm);
  }
  out->x_v_mm = vm_pose.p * u;
  // eq. 3.9: e = X_V - X_R
  out->e.head<3>() = vm_pose.p - rm.p;
  if (params_.error == ErrorFormulation::kThesis) {
    out->e.tail<3>() = vm_->thesis_orientation_error(theta_v_, theta_r_);
  } else {
    bool ambiguous = false;
    out->e.tail<3>() =
        vm_->geometric_orientation_error(vm_pose, rm, &ambiguous);
    if (ambiguous) st |= kStatusOrientationDegenerate;
  }
  // e_dot by backward difference (angle rows wrapped), low-pass filtered
  if (have_previous_) {
    Vec6 d = out->e - e_previous_;
    for (int i = 3; i < 6; ++i) d[i] = wrap_angle(d[i]);
    // one division instead of six
    const Vec6 raw = d * (1.0 / params_.servo_period_s);
    out->e_dot = e_dot_filtered_ + velocity_alpha_ * (raw - e_dot_filtered_);
  } else {
    out->e_dot.setZero();
  }
  // eq. 3.8 with eq. 3.28's diagonal gains, then eq. 3.11
  const Vec6 g = kp_.cwiseProduct(out->e) + kv_.cwiseProduct(out->e_dot);
  ProjectionResult pr;
  if (params_.vm.kind == VmKind::kSphere && locked == 0u) {
    // the sphere's J^T W_A J in closed form from its polar angle
    const SinCos polar = sin_cos(theta_v_[1]);
    pr = project_motion_force_sphere(
        J_, vm_->length(), polar.s, polar.c, params_.projection_weights, g,
        params_.singular_rcond, params_.singular_damping, &out->f_motion);
  } else {
    active_columns(J_, locked, &J_active_);
    pr = project_motion_force(J_active_, params_.projection_weights, g,
                              params_.singular_rcond,
                              params_.singular_damping, &out->f_motion);
  }
  out->vm_rcond = pr.rcond;
  if (pr.singular) st |= kStatusVmSingular;
  return st;
}

ControlStatus Controller::fail_input(ControlOutput* out) noexcept {
  // a sensor fault: zero force, keep the warm start, restart e_dot
  out->status = kStatusInvalidInput;
  out->f_motion.setZero();
  out->e.setZero();
  out->e_dot.setZero();
  have_previous_ = false;
  return out->status;
}

double Controller::closed_form_cost(const VmPose& vm_pose,
                                    const RmPose& rm) const noexcept {
  // placement_residual's r^T W r at theta_V, from the pose already computed;
  // the orientation rows (an atan2) only where W weighs them, as they would
  // add exactly 0 otherwise
  const Vec6& w = params_.placement_options.weights;
  const Vec3 r_p = rm.p - vm_pose.p;
  double cost = r_p.dot(w.head<3>().cwiseProduct(r_p));
  if ((w.tail<3>().array() != 0.0).any()) {
    const Vec3 r_o = -vm_->geometric_orientation_error(vm_pose, rm, nullptr);
    cost += r_o.dot(w.tail<3>().cwiseProduct(r_o));
  }
  return cost;
}

RmPose Controller::rm_pose(const OmniArmKinematics& arm,
                           ControlOutput* out) const noexcept {
  const OmniParams& omni = params_.omni;
  out->p_rm_mm = base_to_device_mm(omni, arm.p_base_m);
  out->axis_rm = base_to_device_vector(arm.z6_base);
  RmPose rm;
  rm.p = out->p_rm_mm * (1.0 / params_.length_unit_mm);
  rm.axis = out->axis_rm;
  return rm;
}

ControlStatus Controller::evaluate_with_contact(const RmPose& rm,
                                                ControlOutput* out) noexcept {
  // A VM with a contact and friction first tries its contact held (the
  // stick joints locked) and slides only if the force leaves the friction
  // cone; a unilateral contact that would pull opens instead.
  const VmParams& vm = params_.vm;
  if (!vm_->has_contact()) return evaluate(rm, 0u, out);
  const JointMask locked = vm.friction_mu > 0.0 ? vm_->stick_joints() : 0u;
  // first touch: the contact point under the stylus tip
  if (!placed_) vm_->aligned(rm, &theta_v_);
  const VmAngles held = theta_v_;
  ControlStatus st = evaluate(rm, locked, out);
  switch (vm_->contact_state(out->f_motion.head<3>(), vm.friction_mu,
                             vm.unilateral, locked != 0u)) {
    case ContactState::kClosed:
      break;
    case ContactState::kOpen:
      // the plane can only push: the probe lifts off and follows the stylus
      vm_->aligned(rm, &theta_v_);
      out->f_motion.setZero();
      st |= kStatusContactOpen;
      break;
    case ContactState::kSliding:
      theta_v_ = held;
      st = evaluate(rm, 0u, out) | kStatusContactSliding;
      break;
  }
  return st;
}

ControlStatus Controller::saturate_and_map(const Mat3& Jv_arm,
                                           ControlOutput* out) const noexcept {
  ControlStatus st = kStatusOk;
  const OmniParams& omni = params_.omni;
  Vec3 F = out->f_motion.head<3>();
  // |F| only when over the limit: the square root's latency sat on the
  // tick's critical path in perf
  const double F_limit = params_.force_limit_N;
  const double F2 = F.squaredNorm();
  // |F|^2 overflows for |F| > ~1e154 N (a gain of 1e153, say): F / |F|
  // would be 0 and a zero force would pass for a saturated one. A
  // non-finite intermediate is a numerical fault, whatever it came from
  if (!std::isfinite(F2)) return kStatusNumericalFault;
  if (F2 > F_limit * F_limit) {
    F *= F_limit / std::sqrt(F2);
    st |= kStatusForceSaturated;
  }
  // eq. 3.12 with the wrist-centre Jacobian's linear rows (m/rad) and the
  // force in the base frame: tau in N m
  Vec3 F_base = device_to_base_vector(F);
  Vec3 tau = Jv_arm.transpose() * F_base;
  Vec3 tau_motor = dh_to_motor_torques(tau);
  // one scale for every motor over its limit keeps the force's direction
  double scale = 1.0;
  for (int i = 0; i < kOmniActuated; ++i) {
    const double lim = omni.motor_torque_limit_Nm[static_cast<std::size_t>(i)];
    if (std::abs(tau_motor[i]) * scale > lim) {
      scale = lim / std::abs(tau_motor[i]);
    }
  }
  if (scale < 1.0) {
    F *= scale;
    F_base *= scale;
    tau *= scale;
    tau_motor *= scale;
    st |= kStatusTorqueSaturated;
  }
  if (!tau_motor.allFinite() || !F_base.allFinite()) return kStatusNumericalFault;
  out->force_device_N = F;
  out->force_base_N = F_base;
  out->tau_dh_Nm = tau;
  out->tau_motor_Nm = tau_motor;
  return st;
}

ControlStatus Controller::tick(const Joints& q_dh, ControlOutput* out) noexcept {
  out->status = kStatusOk;
  out->force_device_N.setZero();
  out->force_base_N.setZero();
  out->tau_dh_Nm.setZero();
  out->tau_motor_Nm.setZero();
  if (!q_dh.allFinite()) return fail_input(out);
  ControlStatus st = kStatusOk;
  if (!omni_within_limits(params_.omni, q_dh)) st |= kStatusOutsideJointLimits;

  // 1. the RM: wrist centre and stylus axis in the device frame, and the
  // arm's Jacobian for step 5, in one pass over the chain
  const OmniArmKinematics arm = omni_arm_kinematics(params_.omni, q_dh);
  const RmPose rm = rm_pose(arm, out);
  // 2. theta_R: the VM aligned with the stylus (kept where undefined), and
  // X(theta_R)'s position for the output
  Vec3 x_r;
  if (!vm_->aligned_position(rm, &theta_r_, &x_r)) {
    st |= kStatusOrientationDegenerate;
  }
  out->x_r_mm = x_r * params_.length_unit_mm;
  // 3-4. placement, error and projected force
  st |= evaluate_with_contact(rm, out);
  placed_ = true;
  e_previous_ = out->e;
  e_dot_filtered_ = out->e_dot;
  have_previous_ = true;
  out->theta_v = theta_v_;
  out->theta_r = theta_r_;

  // 5. the device force and joint torques; a non-finite value on the way
  // (saturate_and_map writes nothing then) leaves them zero
  ControlStatus mapped = kStatusNumericalFault;
  if (out->f_motion.allFinite() && out->e.allFinite()) {
    mapped = saturate_and_map(arm.Jv_arm, out);
  }
  if ((mapped & kStatusNumericalFault) != 0u) {
    out->status = st | kStatusNumericalFault;
    out->f_motion.setZero();
    reset();
    return out->status;
  }
  st |= mapped;
  out->status = st;
  return st;
}

}  // namespace vmh
