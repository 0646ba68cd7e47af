#include "controller/virtual_mechanism.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "controller/omni_kinematics.h"  // wrap_angle
#include "controller/trig.h"

namespace vmh {
namespace {

using constants::kPi;

// below this fraction of L a direction is treated as undefined
constexpr double kDegenerateFraction = 1e-9;
// |sin| below which an axis is treated as lying on a pole
constexpr double kPoleSin = 1e-12;

// hypot(x, y) > t for t > 0, without hypot's care for overflow: the
// arguments here are lengths in mm or unit-vector components
bool above(double x, double y, double t) { return x * x + y * y > t * t; }

double clamp_unit(double x) { return x < -1.0 ? -1.0 : (x > 1.0 ? 1.0 : x); }

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

// any unit vector perpendicular to u
Vec3 perpendicular(const Vec3& u) {
  const Vec3 other = std::abs(u.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return u.cross(other).normalized();
}

// rotation about the local z axis
Mat3 rot_z(double a) {
  Mat3 R;
  const SinCos t = sin_cos(a);
  const double c = t.c, s = t.s;
  R << c, -s, 0, s, c, 0, 0, 0, 1;
  return R;
}

}  // namespace

const char* vm_kind_name(VmKind kind) {
  switch (kind) {
    case VmKind::kCircle:
      return "circle";
    case VmKind::kSphere:
      return "sphere";
    case VmKind::kSurface:
      return "surface";
  }
  return "unknown";
}

bool parse_vm_kind(const char* text, VmKind* kind) {
  for (VmKind k : {VmKind::kCircle, VmKind::kSphere, VmKind::kSurface}) {
    if (std::strcmp(text, vm_kind_name(k)) == 0) {
      *kind = k;
      return true;
    }
  }
  return false;
}

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

double SphereVm::distance_to_path(const Vec3& p) const {
  const Vec3 r = mount_.R.transpose() * (p - mount_.origin);
  return std::abs(r.norm() - length_);
}

Vec3 SphereVm::nearest_on_path(const Vec3& p) const {
  const Vec3 r = mount_.R.transpose() * (p - mount_.origin);
  if (r.norm() < 1e-12) return mount_.origin;
  return mount_.origin + mount_.R * (length_ * r.normalized());
}

double SurfaceVm::distance_to_path(const Vec3& p) const {
  const Vec3 r = mount_.R.transpose() * (p - mount_.origin);
  return std::abs(std::abs(r.z()) - length_);
}

Vec3 SurfaceVm::nearest_on_path(const Vec3& p) const {
  Vec3 r = mount_.R.transpose() * (p - mount_.origin);
  r.z() = r.z() >= 0.0 ? length_ : -length_;
  return mount_.origin + mount_.R * r;
}

ContactState SurfaceVm::contact_state(const Vec3& f_N, double mu,
                                      bool unilateral, bool sticking) const {
  // tangential force below which a held contact never slips, whatever the
  // normal force: keeps rounding-level forces at rest from creeping the
  // contact
  constexpr double kSlipFloor_N = 1e-6;
  const Vec3 n = normal();
  const double f_n = f_N.dot(n);
  const double f_t = (f_N - f_n * n).norm();
  if (unilateral && f_n < 0.0) return ContactState::kOpen;
  if (sticking && f_t > mu * std::abs(f_n) + kSlipFloor_N) {
    return ContactState::kSliding;
  }
  return ContactState::kClosed;
}

VmAngles SurfaceVm::rest_angles() const {
  VmAngles theta = zero_angles();
  theta[2] = theta[3] = 0.5 * kPi;
  return theta;
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

// -------------------------------------------------------------------- circle

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
  const Vec3 n = mount_.R.col(2);
  const Vec3 a = rm.axis - rm.axis.dot(n) * n;
  if (ambiguous != nullptr) *ambiguous = false;
  if (!(a.norm() > kPoleSin)) {
    if (ambiguous != nullptr) *ambiguous = true;
    return Vec3::Zero();
  }
  return n * atan2_fast(n.dot(a.cross(vm.axis)), a.dot(vm.axis));
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

// -------------------------------------------------------------------- sphere

SphereVm::SphereVm(const VmMount& mount, double length)
    : VirtualMechanism(mount, length) {}

namespace {

struct SphereTrig {
  double s1, c1, s2, c2;
  explicit SphereTrig(const VmAngles& theta)
      : SphereTrig(sin_cos(theta[0]), sin_cos(theta[1])) {}
  SphereTrig(SinCos t1, SinCos t2) : s1(t1.s), c1(t1.c), s2(t2.s), c2(t2.c) {}
};

VmPose sphere_pose(const VmMount& mount, double length, const SphereTrig& t,
                   double theta3) {
  // eq. 3.29/3.30 in the pivot frame
  const double s1 = t.s1, c1 = t.c1, s2 = t.s2, c2 = t.c2;
  const SinCos t3 = sin_cos(theta3);
  const double s3 = t3.s, c3 = t3.c;
  Mat3 R;
  R << s1 * s3 + c1 * c2 * c3, s1 * c3 - c1 * c2 * s3, c1 * s2,  //
      s1 * c2 * c3 - c1 * s3, -c1 * c3 - s1 * c2 * s3, s1 * s2,  //
      s2 * c3, -s2 * s3, -c2;
  VmPose out;
  out.R = mount.R * R;
  out.axis = out.R.col(2);
  out.p = mount.origin + length * out.axis;
  return out;
}

void sphere_jacobian(const VmMount& mount, double L, const SphereTrig& t,
                     VmJacobian* J) {
  // eq. 3.31 in the pivot frame
  const double s1 = t.s1, c1 = t.c1, s2 = t.s2, c2 = t.c2;
  Eigen::Matrix<double, 6, 3> Jl;
  Jl << -L * s1 * s2, L * c1 * c2, 0,  //
      L * c1 * s2, L * s1 * c2, 0,     //
      0, L * s2, 0,                    //
      0, s1, c1 * s2,                  //
      0, -c1, s1 * s2,                 //
      1, 0, -c2;
  J->resize(6, 3);
  J->topRows<3>() = mount.R * Jl.topRows<3>();
  J->bottomRows<3>() = mount.R * Jl.bottomRows<3>();
}

}  // namespace

Vec3 SphereVm::position(const VmAngles& theta) const {
  // the link axis, column 3 of eq. 3.29's rotation: no twist needed
  const SphereTrig t(theta);
  return mount_.origin +
         length_ * (mount_.R * Vec3(t.c1 * t.s2, t.s1 * t.s2, -t.c2));
}

VmPose SphereVm::pose(const VmAngles& theta) const {
  return sphere_pose(mount_, length_, SphereTrig(theta), theta[2]);
}

void SphereVm::jacobian(const VmAngles& theta, VmJacobian* J) const {
  sphere_jacobian(mount_, length_, SphereTrig(theta), J);
}

void SphereVm::pose_jacobian(const VmAngles& theta, VmPose* pose,
                             VmJacobian* J) const {
  const SphereTrig t(theta);
  *pose = sphere_pose(mount_, length_, t, theta[2]);
  sphere_jacobian(mount_, length_, t, J);
}

namespace {
// Polar angle from -z and azimuth of a direction d (pivot frame, any length
// > 0): theta2 = pi - acos(d_z/|d|) = atan2(|d_xy|, -d_z) (§3.4.1), theta1 =
// atan2(d_y, d_x); on the pole axis theta1 is left as it was. Both atan2s
// are scale-free, so d needs no normalising, and atan2 keeps its accuracy
// near the poles, where acos loses half its digits. Returns the sines and
// cosines of the angles set, from d itself: s2 = |d_xy|/|d|, c2 = -d_z/|d|,
// (c1, s1) = d_xy/|d_xy| (theta1's own on the pole); nearest() and
// aligned(), which need only the angles, ignore them.
SphereTrig sphere_angles(const Vec3& d, VmAngles* theta) {
  const double rho2 = d.x() * d.x() + d.y() * d.y();
  const double n2 = rho2 + d.z() * d.z();
  const double rho = std::sqrt(rho2);
  (*theta)[1] = atan2_fast(rho, -d.z());
  const double inv_n = 1.0 / std::sqrt(n2);
  const SinCos t2{rho * inv_n, -d.z() * inv_n};
  if (rho2 > kPoleSin * kPoleSin * n2) {
    (*theta)[0] = atan2_fast(d.y(), d.x());
    const double inv_rho = 1.0 / rho;
    return SphereTrig(SinCos{d.y() * inv_rho, d.x() * inv_rho}, t2);
  }
  return SphereTrig(sin_cos((*theta)[0]), t2);
}
}  // namespace

bool SphereVm::nearest(const RmPose& rm, VmAngles* theta) const {
  const Vec3 d = mount_.R.transpose() * (rm.p - mount_.origin);
  // §3.4.1's LL = |d|, compared squared
  if (!(d.squaredNorm() > kDegenerateFraction * kDegenerateFraction *
                              length_ * length_)) {
    return false;
  }
  sphere_angles(d, theta);
  return true;
}

bool SphereVm::aligned(const RmPose& rm, VmAngles* theta) const {
  const Vec3 a = mount_.R.transpose() * rm.axis;
  if (!(a.squaredNorm() > kPoleSin * kPoleSin)) return false;
  sphere_angles(a, theta);
  return true;
}


bool SphereVm::nearest_pose_jacobian(const RmPose& rm, VmAngles* theta,
                                     VmPose* pose, VmJacobian* J) const {
  const Vec3 d = mount_.R.transpose() * (rm.p - mount_.origin);
  if (!(d.squaredNorm() > kDegenerateFraction * kDegenerateFraction *
                              length_ * length_)) {
    return false;
  }
  const SphereTrig t = sphere_angles(d, theta);
  *pose = sphere_pose(mount_, length_, t, (*theta)[2]);
  sphere_jacobian(mount_, length_, t, J);
  return true;
}

bool SphereVm::aligned_position(const RmPose& rm, VmAngles* theta,
                                Vec3* p) const {
  const Vec3 a = mount_.R.transpose() * rm.axis;
  if (!(a.squaredNorm() > kPoleSin * kPoleSin)) {
    *p = position(*theta);
    return false;
  }
  const SphereTrig t = sphere_angles(a, theta);
  *p = mount_.origin +
       length_ * (mount_.R * Vec3(t.c1 * t.s2, t.s1 * t.s2, -t.c2));
  return true;
}

Vec3 SphereVm::thesis_orientation_error(const VmAngles& theta_v,
                                        const VmAngles& theta_r) const {
  // eq. 3.35-3.37: (theta_V3 - theta_R3 = 0, theta_V2 - theta_R2,
  // theta_V1 - theta_R1) as the (theta_x, theta_y, theta_z) rows
  return mount_.R * Vec3(0.0, wrap_angle(theta_v[1] - theta_r[1]),
                         wrap_angle(theta_v[0] - theta_r[0]));
}

void SphereVm::normalize(VmAngles* theta) const {
  double t2 = wrap_angle((*theta)[1]);
  if (t2 < 0.0) {
    // (t1 + pi, -t2, t3 + pi) is the same handle pose
    t2 = -t2;
    (*theta)[0] += kPi;
    (*theta)[2] += kPi;
  }
  (*theta)[0] = wrap_angle((*theta)[0]);
  (*theta)[1] = t2;
  (*theta)[2] = wrap_angle((*theta)[2]);
}

// ------------------------------------------------------------------- surface

SurfaceVm::SurfaceVm(const VmMount& mount, double length)
    : VirtualMechanism(mount, length) {}

Vec3 SurfaceVm::contact(const VmAngles& theta) const {
  return mount_.origin + theta[0] * mount_.R.col(0) +
         theta[1] * mount_.R.col(1);
}

VmPose SurfaceVm::pose(const VmAngles& theta) const {
  // frame = Rx(alpha) Rz(beta) C Rz(gamma) in the plane frame, with C the
  // constant rotation taking (x, y, z) to (y, z, x); its z column is
  // u = (cos b, sin b cos a, sin b sin a)
  const SinCos ta = sin_cos(theta[2]), tb = sin_cos(theta[3]);
  const double sa = ta.s, ca = ta.c;
  const double sb = tb.s, cb = tb.c;
  Mat3 F;
  F.col(0) = Vec3(-sb, cb * ca, cb * sa);  // du/dbeta
  F.col(2) = Vec3(cb, sb * ca, sb * sa);   // u
  F.col(1) = F.col(2).cross(F.col(0));
  VmPose out;
  out.R = mount_.R * F * rot_z(theta[4]);
  out.axis = mount_.R * F.col(2);
  out.p = contact(theta) + length_ * out.axis;
  return out;
}

void SurfaceVm::jacobian(const VmAngles& theta, VmJacobian* J) const {
  const SinCos ta = sin_cos(theta[2]), tb = sin_cos(theta[3]);
  const double sa = ta.s, ca = ta.c;
  const double sb = tb.s, cb = tb.c;
  const Vec3 t1 = mount_.R.col(0);
  const Vec3 u = mount_.R * Vec3(cb, sb * ca, sb * sa);
  const Vec3 w_beta = mount_.R * Vec3(0.0, -sa, ca);
  J->resize(6, 5);
  J->setZero();
  J->block<3, 1>(0, 0) = t1;                         // s1
  J->block<3, 1>(0, 1) = mount_.R.col(1);            // s2
  J->block<3, 1>(0, 2) = length_ * t1.cross(u);      // alpha, about t1
  J->block<3, 1>(3, 2) = t1;                         //
  J->block<3, 1>(0, 3) = length_ * w_beta.cross(u);  // beta
  J->block<3, 1>(3, 3) = w_beta;                     //
  J->block<3, 1>(3, 4) = u;                          // gamma, twist
}

namespace {
// alpha, beta of a unit direction d in the plane frame; alpha kept on the
// poles d = +-t1
void surface_angles(const Vec3& d, VmAngles* theta) {
  (*theta)[3] = std::acos(clamp_unit(d.x()));
  if (std::hypot(d.y(), d.z()) > kPoleSin) {
    (*theta)[2] = std::atan2(d.z(), d.y());
  }
}
}  // namespace

bool SurfaceVm::nearest(const RmPose& rm, VmAngles* theta) const {
  const Vec3 d = mount_.R.transpose() * (rm.p - contact(*theta));
  const double n = d.norm();
  if (!(n > kDegenerateFraction * length_)) return false;
  surface_angles(d / n, theta);
  return true;
}

bool SurfaceVm::aligned(const RmPose& rm, VmAngles* theta) const {
  const double n = rm.axis.norm();
  if (!(n > kPoleSin)) return false;
  const Vec3 a = rm.axis / n;
  surface_angles(mount_.R.transpose() * a, theta);
  const Vec3 tip = rm.p - length_ * a - mount_.origin;
  (*theta)[0] = mount_.R.col(0).dot(tip);
  (*theta)[1] = mount_.R.col(1).dot(tip);
  return true;
}

bool SurfaceVm::placement_minimum(const RmPose& rm, double w_pos,
                                  double w_ornt, bool contact_held,
                                  VmAngles* theta) const {
  if (!(w_ornt > 0.0) || !(w_pos >= 0.0)) return false;
  const double na = rm.axis.norm();
  if (!(na > kPoleSin)) return false;
  const Vec3 a = rm.axis / na;
  // the reference direction e (n, or d toward the RM from a held contact)
  // and the constants of the position term
  Vec3 e;
  double h = 0.0, dn = 0.0;
  if (contact_held) {
    const Vec3 d = rm.p - contact(*theta);
    dn = d.norm();
    if (!(dn > kDegenerateFraction * length_)) return false;
    e = d / dn;
  } else {
    e = normal();
    h = e.dot(rm.p - mount_.origin);
  }
  // t: the unit tangent from e toward a; psi_a the angle between them
  const double ca = e.dot(a);
  const Vec3 ta = a - ca * e;
  const double sa = ta.norm();
  if (!(sa > 1e-9)) return false;
  const Vec3 t = ta / sa;
  const double psi_a = std::atan2(sa, ca);
  // start from the current probe's angle to e
  const SinCos t_alpha = sin_cos((*theta)[2]), t_beta = sin_cos((*theta)[3]);
  const Vec3 u0 = mount_.R * Vec3(t_beta.c, t_beta.s * t_alpha.c,
                                  t_beta.s * t_alpha.s);
  double psi = std::atan2(u0.cross(e).norm(), u0.dot(e));
  const double L = length_;
  // g(psi) up to a constant, g', g''
  auto cost = [&](double x, double* g1, double* g2) {
    const SinCos sc = sin_cos(x);
    const double o = x - psi_a;
    if (contact_held) {
      const double k = w_pos * L * dn;
      if (g1 != nullptr) *g1 = 2.0 * (k * sc.s + w_ornt * o);
      if (g2 != nullptr) *g2 = 2.0 * (k * sc.c + w_ornt);
      return -2.0 * k * sc.c + w_ornt * o * o;
    }
    const double rn = h - L * sc.c;
    if (g1 != nullptr) *g1 = 2.0 * (w_pos * rn * L * sc.s + w_ornt * o);
    if (g2 != nullptr) {
      *g2 = 2.0 * (w_pos * L * (L * sc.s * sc.s + rn * sc.c) + w_ornt);
    }
    return w_pos * rn * rn + w_ornt * o * o;
  };
  double g1 = 0.0, g2 = 0.0;
  double g = cost(psi, &g1, &g2);
  bool done = false;
  for (int it = 0; it < 50 && !done; ++it) {
    // Newton where g is convex, else a bounded descent step; halved until
    // g does not increase; psi stays in [0, pi]
    double step = g2 > 0.0 ? -g1 / g2 : (g1 > 0.0 ? -0.25 : 0.25);
    step = std::clamp(step, -0.5, 0.5);
    for (int half = 0; half < 40; ++half) {
      const double x = std::clamp(psi + step, 0.0, kPi);
      const double gx = cost(x, nullptr, nullptr);
      if (gx <= g) {
        done = std::abs(x - psi) < 1e-15 * (1.0 + std::abs(psi)) ||
               std::abs(step) < 1e-13;
        psi = x;
        g = cost(psi, &g1, &g2);
        break;
      }
      step *= 0.5;
      if (half == 39) done = true;
    }
  }
  if (!std::isfinite(psi)) return false;
  const SinCos sp = sin_cos(psi);
  const Vec3 u = sp.c * e + sp.s * t;
  surface_angles(mount_.R.transpose() * u, theta);
  if (!contact_held) {
    const Vec3 tip = rm.p - L * u - mount_.origin;
    (*theta)[0] = mount_.R.col(0).dot(tip);
    (*theta)[1] = mount_.R.col(1).dot(tip);
  }
  normalize(theta);
  return true;
}

Vec3 SurfaceVm::thesis_orientation_error(const VmAngles& theta_v,
                                         const VmAngles& theta_r) const {
  // no thesis formula: the wrapped revolute differences, each along its own
  // joint axis at theta_V (first order in the differences)
  VmJacobian J;
  jacobian(theta_v, &J);
  Vec3 e = Vec3::Zero();
  for (int j = 2; j < 5; ++j) {
    e += J.block<3, 1>(3, j) * wrap_angle(theta_v[j] - theta_r[j]);
  }
  return e;
}

void SurfaceVm::normalize(VmAngles* theta) const {
  double b = wrap_angle((*theta)[3]);
  if (b < 0.0) {
    // (alpha + pi, -beta, gamma + pi) is the same handle pose
    b = -b;
    (*theta)[2] += kPi;
    (*theta)[4] += kPi;
  }
  (*theta)[2] = wrap_angle((*theta)[2]);
  (*theta)[3] = b;
  (*theta)[4] = wrap_angle((*theta)[4]);
}

}  // namespace vmh
