#include "controller/vm_sphere.h"

#include <algorithm>
#include <cmath>

#include "controller/omni_kinematics.h"  // wrap_angle
#include "controller/trig.h"
#include "controller/vm_common.h"

namespace vmh {

using namespace vm_detail;  // NOLINT(build/namespaces)
using constants::kPi;

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

namespace vm_detail {

// RevoluteVm's geometry of the sphere: the azimuth and polar angle of a
// direction (§3.4.1), the twist kept; nearest() is undefined for the wrist
// centre (almost) at the pivot (§3.4.1's LL = |d|, compared squared),
// aligned() for a stylus axis of (almost) no length
struct SphereGeometry {
  using Trig = SphereTrig;
  static constexpr PathPrimitive::Type kPath = PathPrimitive::Type::kSphere;

  static Trig trig(const VmAngles& theta) { return SphereTrig(theta); }
  static Trig angles(const Vec3& d, VmAngles* theta) {
    return sphere_angles(d, theta);
  }
  static bool reaches(const Vec3& d, double length) {
    return d.squaredNorm() >
           kDegenerateFraction * kDegenerateFraction * length * length;
  }
  static bool points(const Vec3& a) {
    return a.squaredNorm() > kPoleSin * kPoleSin;
  }
  static VmPose pose(const VmMount& mount, double length, const Trig& t,
                     const VmAngles& theta) {
    return sphere_pose(mount, length, t, theta[2]);
  }
  static void jacobian(const VmMount& mount, double length, const Trig& t,
                       VmJacobian* J) {
    sphere_jacobian(mount, length, t, J);
  }
  // column 3 of eq. 3.29's rotation
  static Vec3 link(const Trig& t) {
    return Vec3(t.c1 * t.s2, t.s1 * t.s2, -t.c2);
  }
};

}  // namespace vm_detail

template class RevoluteVm<vm_detail::SphereGeometry>;

SphereVm::SphereVm(const VmMount& mount, double length)
    : RevoluteVm(mount, length) {}

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

double SphereVm::distance_to_path(const Vec3& p) const {
  const Vec3 r = from_pivot(p);
  return std::abs(r.norm() - length_);
}

Vec3 SphereVm::nearest_on_path(const Vec3& p) const {
  const Vec3 r = from_pivot(p);
  if (r.norm() < 1e-12) return mount_.origin;
  return mount_.origin + mount_.R * (length_ * r.normalized());
}

bool predict_sphere(const VirtualMechanism& vm, const RmPose& rm,
                    bool thesis_error, VmStaticPlacement* out,
                    const char** why_not) {
  const Mat3& R = vm.mount().R;
  const double L = vm.length();
  Vec3 u_v, u_r;
  if (!unit_direction(rm.p - vm.mount().origin, &u_v) ||
      !unit_direction(rm.axis, &u_r)) {
    *why_not = kOnPivotAxis;
    return false;
  }
  out->x_v = vm.mount().origin + L * u_v;
  out->x_r = vm.mount().origin + L * u_r;
  if (thesis_error) {
    // differences of the sphere's angles in the pivot frame, theta1 =
    // atan2(y, x), theta2 = acos(-z) (§3.4.1), as rows (x, y, z)
    const Vec3 dv = R.transpose() * u_v, dr = R.transpose() * u_r;
    if (std::hypot(dv.x(), dv.y()) < 1e-6 ||
        std::hypot(dr.x(), dr.y()) < 1e-6) {
      *why_not = "on the sphere's pole, where theta1 is not defined";
      return false;
    }
    const double d1 =
        wrap_angle(std::atan2(dv.y(), dv.x()) - std::atan2(dr.y(), dr.x()));
    const double d2 = std::acos(clamp_unit(-dv.z())) -
                      std::acos(clamp_unit(-dr.z()));
    out->e_ornt_rad = R * Vec3(0.0, wrap_angle(d2), d1);
  } else {
    // the rotation vector carrying the stylus axis onto the link
    const Vec3 k = u_r.cross(u_v);
    const double s = k.norm();
    if (s < 1e-9) {
      if (u_r.dot(u_v) < 0.0) {
        *why_not = "the stylus is opposite the link: the rotation's axis is "
                   "a choice";
        return false;
      }
      out->e_ornt_rad.setZero();
    } else {
      out->e_ornt_rad = std::atan2(s, u_r.dot(u_v)) / s * k;
    }
  }
  out->J.resize(6, 3);
  for (int i = 0; i < 3; ++i) {
    const Vec3 w = Vec3::Unit(i);
    out->J.col(i) << L * w.cross(u_v), w;
  }
  return true;
}

}  // namespace vmh
