#include "controller/vm_circle.h"

#include <algorithm>
#include <cmath>

#include "controller/omni_kinematics.h"  // wrap_angle
#include "controller/trig.h"
#include "controller/vm_common.h"

namespace vmh {

using namespace vm_detail;  // NOLINT(build/namespaces)
using constants::kPi;

CircleVm::CircleVm(const VmMount& mount, double length)
    : VirtualMechanism(mount, length) {}

namespace {

VmPose circle_pose(const VmMount& mount, double length, double c, double s) {
  // R rot_z(theta) column by column: rot_z mixes only the first two
  // columns, and the link axis R (c, s, 0) is the first of them, so neither
  // needs a 3 x 3 product
  VmPose out;
  out.R.col(0) = c * mount.R.col(0) + s * mount.R.col(1);
  out.R.col(1) = c * mount.R.col(1) - s * mount.R.col(0);
  out.R.col(2) = mount.R.col(2);
  out.axis = out.R.col(0);
  out.p = mount.origin + length * out.axis;
  return out;
}

void circle_jacobian(const VmMount& mount, double length, double c, double s,
                     VmJacobian* J) {
  J->resize(6, 1);
  J->block<3, 1>(0, 0) = mount.R * Vec3(-length * s, length * c, 0.0);
  J->block<3, 1>(3, 0) = mount.R.col(2);
}

}  // namespace

void CircleVm::pose_jacobian(const VmAngles& theta, VmPose* pose,
                             VmJacobian* J) const {
  const SinCos t = sin_cos(theta[0]);
  const double c = t.c, s = t.s;
  *pose = circle_pose(mount_, length_, c, s);
  circle_jacobian(mount_, length_, c, s, J);
}

Vec3 CircleVm::position(const VmAngles& theta) const {
  const SinCos t = sin_cos(theta[0]);
  const double c = t.c, s = t.s;
  return mount_.origin + length_ * (mount_.R * Vec3(c, s, 0.0));
}

VmPose CircleVm::pose(const VmAngles& theta) const {
  // eq. 3.25/3.26 in the pivot frame, then into the device frame
  const SinCos t = sin_cos(theta[0]);
  const double c = t.c, s = t.s;
  return circle_pose(mount_, length_, c, s);
}

void CircleVm::jacobian(const VmAngles& theta, VmJacobian* J) const {
  // eq. 3.27: (-L sin, L cos, 0, 0, 0, 1) in the pivot frame
  const SinCos t = sin_cos(theta[0]);
  const double c = t.c, s = t.s;
  circle_jacobian(mount_, length_, c, s, J);
}

namespace {
// theta = atan2(y, x) (§3.3.1) for (x, y) off the origin; returns its sine
// and cosine from (x, y) itself, which callers needing only the angle drop
SinCos circle_angle(double x, double y, VmAngles* theta) {
  (*theta)[0] = atan2_fast(y, x);
  const double inv = 1.0 / std::sqrt(x * x + y * y);
  return SinCos{y * inv, x * inv};
}
}  // namespace

bool CircleVm::nearest(const RmPose& rm, VmAngles* theta) const {
  // §3.3.1: theta_V = atan2(Y - Y0, X - X0), in the pivot frame
  const Vec3 d = mount_.R.transpose() * (rm.p - mount_.origin);
  if (!above(d.x(), d.y(), kDegenerateFraction * length_)) return false;
  circle_angle(d.x(), d.y(), theta);
  return true;
}

bool CircleVm::aligned(const RmPose& rm, VmAngles* theta) const {
  // §3.3.1: theta_R = atan2(Z_y, Z_x) of the stylus z axis
  const Vec3 a = mount_.R.transpose() * rm.axis;
  if (!above(a.x(), a.y(), kPoleSin)) return false;
  circle_angle(a.x(), a.y(), theta);
  return true;
}

bool CircleVm::nearest_pose_jacobian(const RmPose& rm, VmAngles* theta,
                                     VmPose* pose, VmJacobian* J) const {
  const Vec3 d = mount_.R.transpose() * (rm.p - mount_.origin);
  if (!above(d.x(), d.y(), kDegenerateFraction * length_)) return false;
  const SinCos t = circle_angle(d.x(), d.y(), theta);
  *pose = circle_pose(mount_, length_, t.c, t.s);
  circle_jacobian(mount_, length_, t.c, t.s, J);
  return true;
}

bool CircleVm::aligned_position(const RmPose& rm, VmAngles* theta,
                                Vec3* p) const {
  const Vec3 a = mount_.R.transpose() * rm.axis;
  if (!above(a.x(), a.y(), kPoleSin)) {
    *p = position(*theta);
    return false;
  }
  const SinCos t = circle_angle(a.x(), a.y(), theta);
  *p = mount_.origin + length_ * (mount_.R * Vec3(t.c, t.s, 0.0));
  return true;
}

Vec3 CircleVm::thesis_orientation_error(const VmAngles& theta_v,
                                        const VmAngles& theta_r) const {
  return mount_.R.col(2) * wrap_angle(theta_v[0] - theta_r[0]);
}

Vec3 CircleVm::geometric_orientation_error(const VmPose& vm, const RmPose& rm,
                                           bool* ambiguous) const {
  // the planar rotation from the stylus axis's projection onto the plane to
  // the link; about the plane normal, so J_V's one angular row absorbs it
  return planar_orientation_error(mount_.R.col(2), rm.axis, vm.axis,
                                  ambiguous);
}

Mat3 CircleVm::orientation_error_jacobian(const VmPose&,
                                          const RmPose&) const {
  // the error is an angle about the normal: only that part of dw moves it
  const Vec3 n = mount_.R.col(2);
  return n * n.transpose();
}

void CircleVm::normalize(VmAngles* theta) const {
  (*theta)[0] = wrap_angle((*theta)[0]);
}


double CircleVm::distance_to_path(const Vec3& p) const {
  const Vec3 r = mount_.R.transpose() * (p - mount_.origin);
  const double rho = std::hypot(r.x(), r.y());
  return std::hypot(rho - length_, r.z());
}

Vec3 CircleVm::nearest_on_path(const Vec3& p) const {
  Vec3 r = mount_.R.transpose() * (p - mount_.origin);
  r.z() = 0.0;
  if (r.norm() < 1e-12) return mount_.origin;
  return mount_.origin + mount_.R * (length_ * r.normalized());
}

std::vector<PathPrimitive> CircleVm::path_primitives() const {
  PathPrimitive circle;
  circle.type = PathPrimitive::Type::kCircle;
  circle.centre = mount_.origin;
  circle.u = mount_.R.col(0);
  circle.v = mount_.R.col(1);
  circle.radius = length_;
  return {circle};
}

bool CircleVm::path_start(const Vec3& dir, PathStart* out) const {
  // only dir's projection on the plane counts, so the stylus along dir is
  // aligned with the link there too
  const Vec3 n = mount_.R.col(2);
  const Vec3 in_plane = dir - dir.dot(n) * n;
  if (in_plane.norm() < 1e-6) return false;
  out->outward = in_plane.normalized();
  out->p = mount_.origin + length_ * out->outward;
  out->tangent = n.cross(out->outward).normalized();
  out->axis = dir;
  // the second on-path hold turns the stylus the other way about the normal
  out->tilt_b = -out->outward.cross(out->tangent);
  return true;
}

bool predict_circle(const VirtualMechanism& vm, const RmPose& rm, bool,
                    VmStaticPlacement* out, const char** why_not) {
  const Vec3 n = vm.mount().R.col(2);
  const double L = vm.length();
  Vec3 u_v, u_r;
  if (!unit_direction(project_out(rm.p - vm.mount().origin, n), &u_v) ||
      !unit_direction(project_out(rm.axis, n), &u_r)) {
    *why_not = kOnPivotAxis;
    return false;
  }
  out->x_v = vm.mount().origin + L * u_v;
  out->x_r = vm.mount().origin + L * u_r;
  out->e_ornt_rad = n * angle_about(n, u_r, u_v);
  out->J.resize(6, 1);
  out->J.col(0) << L * n.cross(u_v), n;
  return true;
}

}  // namespace vmh
