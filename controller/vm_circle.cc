#include "controller/vm_circle.h"

#include <algorithm>
#include <cmath>

#include "controller/omni_kinematics.h"  // wrap_angle
#include "controller/trig.h"
#include "controller/vm_common.h"

namespace vmh {

using namespace vm_detail;  // NOLINT(build/namespaces)

namespace {

VmPose circle_pose(const VmMount& mount, double length, double c, double s) {
  // eq. 3.25/3.26 in the pivot frame, then into the device frame:
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
  // eq. 3.27: (-L sin, L cos, 0, 0, 0, 1) in the pivot frame
  J->resize(6, 1);
  J->block<3, 1>(0, 0) = mount.R * Vec3(-length * s, length * c, 0.0);
  J->block<3, 1>(3, 0) = mount.R.col(2);
}

// theta = atan2(y, x) (§3.3.1) for (x, y) off the origin; returns its sine
// and cosine from (x, y) itself, which callers needing only the angle drop
SinCos circle_angle(double x, double y, VmAngles* theta) {
  (*theta)[0] = atan2_fast(y, x);
  const double inv = 1.0 / std::sqrt(x * x + y * y);
  return SinCos{y * inv, x * inv};
}

}  // namespace

namespace vm_detail {

// RevoluteVm's geometry of the circle: the one angle of a direction's
// projection onto the plane, theta_V = atan2(Y - Y0, X - X0) of the wrist
// centre and theta_R = atan2(Z_y, Z_x) of the stylus z axis (§3.3.1),
// each undefined where the projection (almost) vanishes
struct CircleGeometry {
  using Trig = SinCos;
  static constexpr PathPrimitive::Type kPath = PathPrimitive::Type::kCircle;

  static Trig trig(const VmAngles& theta) { return sin_cos(theta[0]); }
  static Trig angles(const Vec3& d, VmAngles* theta) {
    return circle_angle(d.x(), d.y(), theta);
  }
  static bool reaches(const Vec3& d, double length) {
    return above(d.x(), d.y(), kDegenerateFraction * length);
  }
  static bool points(const Vec3& a) { return above(a.x(), a.y(), kPoleSin); }
  static VmPose pose(const VmMount& mount, double length, const Trig& t,
                     const VmAngles&) {
    return circle_pose(mount, length, t.c, t.s);
  }
  static void jacobian(const VmMount& mount, double length, const Trig& t,
                       VmJacobian* J) {
    circle_jacobian(mount, length, t.c, t.s, J);
  }
  static Vec3 link(const Trig& t) { return Vec3(t.c, t.s, 0.0); }
};

}  // namespace vm_detail

template class RevoluteVm<vm_detail::CircleGeometry>;

CircleVm::CircleVm(const VmMount& mount, double length)
    : RevoluteVm(mount, length) {}

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
  const Vec3 r = from_pivot(p);
  const double rho = std::hypot(r.x(), r.y());
  return std::hypot(rho - length_, r.z());
}

Vec3 CircleVm::nearest_on_path(const Vec3& p) const {
  Vec3 r = from_pivot(p);
  r.z() = 0.0;
  if (r.norm() < 1e-12) return mount_.origin;
  return mount_.origin + mount_.R * (length_ * r.normalized());
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
