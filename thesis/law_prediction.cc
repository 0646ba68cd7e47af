#include "thesis/law_prediction.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/vm_registry.h"

namespace vmh::thesis {

LawPrediction predict_static_law(const ControllerParams& p, const Vec3& p_mm,
                                 const Vec3& axis, const Joints& q_dh) {
  LawPrediction out;
  const VmDescriptor& desc = vm_descriptor(p.vm.kind);
  if (desc.predict == nullptr) {
    out.reason = std::string("no closed-form placement for the ") +
                 desc.name + " VM";
    return out;
  }
  if (!p_mm.allFinite() || !axis.allFinite() || !q_dh.allFinite()) {
    out.reason = "the pose is not finite";
    return out;
  }
  // the mechanism's own closed form (its prediction hook), in mm
  VmMount mount;
  mount.origin = p.vm.pivot_mm;
  mount.R = p.vm.R_pivot;
  const std::unique_ptr<VirtualMechanism> vm =
      make_vm(p.vm.kind, mount, p.vm.length_mm);
  VmStaticPlacement at;
  const char* why_not = "";
  if (!desc.predict(*vm, RmPose{p_mm, axis}, p.error == ErrorFormulation::kThesis,
                    &at, &why_not)) {
    out.reason = why_not;
    return out;
  }
  out.x_v_mm = at.x_v;
  out.x_r_mm = at.x_r;
  out.e_ornt_rad = at.e_ornt_rad;

  // eq. 3.8 with e_dot = 0, in the controller's length unit u
  const double u = p.length_unit_mm;
  Vec6 g;
  g.head<3>() = (p.gains.k_pos_N_per_mm * u) * ((out.x_v_mm - p_mm) / u);
  g.tail<3>() = (p.gains.k_ornt_Nmm_per_rad / u) * out.e_ornt_rad;
  // J_V in u: its linear rows per u (a column's own scale does not change
  // what it spans)
  Eigen::Matrix<double, 6, Eigen::Dynamic> J = at.J;
  J.topRows(3) /= u;
  // eq. 3.11 with the weights: f = g - W J (J^T W J)^-1 J^T g
  const Vec6& W = p.projection_weights;
  const Eigen::MatrixXd WJ = W.asDiagonal() * J;
  const Eigen::MatrixXd A = J.transpose() * WJ;
  const Eigen::VectorXd y = A.ldlt().solve(J.transpose() * g);
  const Vec6 f = g - WJ * y;
  out.force_N = f.head<3>();

  // the limits: |F| at most force_limit_N, then one scale for the motors
  Vec3 F = out.force_N;
  const double F_lim = p.force_limit_N;
  if (F.norm() > F_lim) {
    F *= F_lim / F.norm();
    out.limited = true;
  }
  const Mat3 Jv = omni_jacobian(p.omni, q_dh).topLeftCorner<3, 3>();
  const Vec3 tau_motor =
      dh_to_motor_torques(Jv.transpose() * device_to_base_vector(F));
  double scale = 1.0;
  for (int i = 0; i < 3; ++i) {
    const double lim = p.omni.motor_torque_limit_Nm[static_cast<std::size_t>(i)];
    if (std::abs(tau_motor[i]) * scale > lim) scale = lim / std::abs(tau_motor[i]);
  }
  if (scale < 1.0) {
    F *= scale;
    out.limited = true;
  }
  out.force_limited_N = F;
  out.available = true;
  return out;
}

}  // namespace vmh::thesis
