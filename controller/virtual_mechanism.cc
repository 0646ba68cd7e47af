#include "controller/virtual_mechanism.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "controller/omni_kinematics.h"  // wrap_angle
#include "controller/trig.h"

#include "controller/vm_common.h"

namespace vmh {

using namespace vm_detail;  // NOLINT(build/namespaces)
using constants::kPi;

namespace {

void check_mount(const VmMount& mount, double length) {
  if (!mount.origin.allFinite()) {
    throw std::invalid_argument("virtual mechanism: pivot is not finite");
  }
  if (!mount.R.allFinite() ||
      !(mount.R.transpose() * mount.R).isIdentity(1e-9) ||
      std::abs(mount.R.determinant() - 1.0) > 1e-9) {
    throw std::invalid_argument(
        "virtual mechanism: pivot orientation is not a rotation matrix");
  }
  if (!std::isfinite(length) || length <= 0.0) {
    throw std::invalid_argument(
        "virtual mechanism: length must be finite and > 0, got " +
        std::to_string(length));
  }
}


}  // namespace

// ---------------------------------------------------------------- base class

VirtualMechanism::VirtualMechanism(const VmMount& mount, double length)
    : mount_(mount), length_(length) {
  check_mount(mount, length);
}

VmAngles VirtualMechanism::zero_angles() const {
  return VmAngles::Zero(dof());
}

ContactState VirtualMechanism::contact_state(const Vec3&, double, bool,
                                             bool) const {
  return ContactState::kClosed;
}

bool VirtualMechanism::path_start(const Vec3& dir, PathStart* out) const {
  const Vec3 n = mount_.R.col(2);
  out->outward = dir;
  out->p = mount_.origin + length_ * dir;
  const Vec3 t = n.cross(dir);
  out->tangent = (t.norm() < 1e-6 ? dir.unitOrthogonal() : t).normalized();
  out->axis = dir;
  out->tilt_b = out->tangent;
  return true;
}

void VirtualMechanism::along_path(const PathStart& s, double phi,
                                  double across, Vec3* p, Mat3* turn) const {
  *turn = Eigen::AngleAxisd(phi, mount_.R.col(2).normalized())
              .toRotationMatrix();
  const Vec3 r = *turn * s.outward;
  *p = mount_.origin + (length_ + across) * r;
}

Vec3 VirtualMechanism::geometric_orientation_error(const VmPose& vm,
                                                   const RmPose& rm,
                                                   bool* ambiguous) const {
  // smallest rotation carrying the stylus axis a onto the link axis u:
  // axis a x u, angle atan2(|a x u|, a.u), so e = angle * (a x u)/|a x u|
  const Vec3 a = rm.axis.normalized();
  const Vec3 k = a.cross(vm.axis);
  const double s = k.norm();
  const double c = a.dot(vm.axis);
  if (ambiguous != nullptr) *ambiguous = false;
  if (s < kPoleSin) {
    if (c > 0.0) return Vec3::Zero();
    // opposite: every axis perpendicular to u turns a onto u by pi
    if (ambiguous != nullptr) *ambiguous = true;
    return kPi * perpendicular(vm.axis);
  }
  return std::atan2(s, c) / s * k;
}

Mat3 VirtualMechanism::orientation_error_jacobian(const VmPose& vm,
                                                  const RmPose& rm) const {
  // e = phi n/s with n = a x u, s = |n|, c = a.u, phi = atan2(s, c). Turning
  // the link by dw moves u by dw x u, so dn = N dw with N = -[a]x [u]x,
  // dc = -n.dw, ds = nhat.dn, dphi = c ds - s dc (s^2 + c^2 = 1), and
  // de = nhat dphi + (phi/s)(I - nhat nhat^T) dn.
  const Vec3 a = rm.axis.normalized();
  const Vec3& u = vm.axis;
  Mat3 ax, ux;
  ax << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  ux << 0, -u.z(), u.y(), u.z(), 0, -u.x(), -u.y(), u.x(), 0;
  const Mat3 N = -ax * ux;
  const Vec3 n = a.cross(u);
  const double s = n.norm();
  const double c = a.dot(u);
  if (s < 1e-8) {
    // aligned: e ~ n to first order (phi/s -> 1); opposite: the error's
    // direction is a choice and its derivative is not defined, so use the
    // same first-order form
    return N;
  }
  const Vec3 nh = n / s;
  const double phi = std::atan2(s, c);
  const Eigen::RowVector3d dphi = c * (nh.transpose() * N) + s * n.transpose();
  return nh * dphi + (phi / s) * (Mat3::Identity() - nh * nh.transpose()) * N;
}


}  // namespace vmh
