#include "studies/law_prediction.h"

#include <algorithm>
#include <cmath>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"

namespace vmh::studies {
namespace {

constexpr double kTiny = 1e-9;

// the unit direction of v, or false if it has (almost) none
bool unit(const Vec3& v, Vec3* out) {
  const double n = v.norm();
  if (!(n > kTiny)) return false;
  *out = v / n;
  return true;
}

// signed angle (rad) from a to b about the unit normal n
double angle_about(const Vec3& n, const Vec3& a, const Vec3& b) {
  return std::atan2(n.dot(a.cross(b)), a.dot(b));
}

}  // namespace

LawPrediction predict_static_law(const ControllerParams& p, const Vec3& p_mm,
                                 const Vec3& axis, const Joints& q_dh) {
  LawPrediction out;
  const VmParams& vm = p.vm;
  if (vm.kind != VmKind::kCircle && vm.kind != VmKind::kSphere) {
    out.reason = "no closed-form placement for this VM kind";
    return out;
  }
  if (!p_mm.allFinite() || !axis.allFinite() || !q_dh.allFinite()) {
    out.reason = "the pose is not finite";
    return out;
  }
  const Mat3& R = vm.R_pivot;  // pivot frame in the device frame
  const Vec3 n = R.col(2);     // the circle's normal
  const double L_mm = vm.length_mm;
  // the link axes at X(theta_V) (nearest point) and X(theta_R) (aligned)
  Vec3 u_v, u_r;
  Vec3 a = axis;
  Vec3 d = p_mm - vm.pivot_mm;
  if (vm.kind == VmKind::kCircle) {
    d -= d.dot(n) * n;
    a -= a.dot(n) * n;
  }
  if (!unit(d, &u_v) || !unit(a, &u_r)) {
    out.reason = "the wrist centre or the stylus axis is on the VM's pivot "
                 "axis, where the placement is not defined";
    return out;
  }
  out.x_v_mm = vm.pivot_mm + L_mm * u_v;
  out.x_r_mm = vm.pivot_mm + L_mm * u_r;

  // the orientation error e_o (rad), a rotation about a device-frame axis
  if (vm.kind == VmKind::kCircle) {
    // both formulations: the planar angle from the aligned link to the
    // placed one, about the normal (eq. 3.32 and its geometric form)
    out.e_ornt_rad = n * angle_about(n, u_r, u_v);
  } else if (p.error == ErrorFormulation::kThesis) {
    // eq. 3.35-3.37: differences of the sphere's angles in the pivot frame,
    // theta1 = atan2(y, x), theta2 = acos(-z) (§3.4.1), as rows (x, y, z)
    const Vec3 dv = R.transpose() * u_v, dr = R.transpose() * u_r;
    if (std::hypot(dv.x(), dv.y()) < 1e-6 || std::hypot(dr.x(), dr.y()) < 1e-6) {
      out.reason = "on the sphere's pole, where theta1 is not defined";
      return out;
    }
    const double d1 =
        wrap_angle(std::atan2(dv.y(), dv.x()) - std::atan2(dr.y(), dr.x()));
    const double d2 = std::acos(std::clamp(-dv.z(), -1.0, 1.0)) -
                      std::acos(std::clamp(-dr.z(), -1.0, 1.0));
    out.e_ornt_rad = R * Vec3(0.0, wrap_angle(d2), d1);
  } else {
    // the rotation vector carrying the stylus axis onto the link
    const Vec3 k = u_r.cross(u_v);
    const double s = k.norm();
    if (s < 1e-9) {
      if (u_r.dot(u_v) < 0.0) {
        out.reason = "the stylus is opposite the link: the rotation's axis "
                     "is a choice";
        return out;
      }
      out.e_ornt_rad.setZero();
    } else {
      out.e_ornt_rad = std::atan2(s, u_r.dot(u_v)) / s * k;
    }
  }

  // eq. 3.8 with e_dot = 0, in the controller's length unit u
  const double u = p.length_unit_mm;
  const double L = L_mm / u;
  Vec6 g;
  g.head<3>() = (p.gains.k_pos_N_per_mm * u) * ((out.x_v_mm - p_mm) / u);
  g.tail<3>() = (p.gains.k_ornt_Nmm_per_rad / u) * out.e_ornt_rad;
  // J_V: rigid rotations about the pivot, [w x L u_v; w]
  Eigen::Matrix<double, 6, Eigen::Dynamic> J;
  if (vm.kind == VmKind::kCircle) {
    J.resize(6, 1);
    J.col(0) << L * n.cross(u_v), n;
  } else {
    J.resize(6, 3);
    for (int i = 0; i < 3; ++i) {
      const Vec3 w = Vec3::Unit(i);
      J.col(i) << L * w.cross(u_v), w;
    }
  }
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

}  // namespace vmh::studies
