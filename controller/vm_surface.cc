#include "controller/vm_surface.h"

#include <algorithm>
#include <cmath>

#include "controller/omni_kinematics.h"  // wrap_angle
#include "controller/trig.h"
#include "controller/vm_common.h"

namespace vmh {

using namespace vm_detail;  // NOLINT(build/namespaces)
using constants::kPi;

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

// The contact under the probe's tip, p - L u projected on the plane, into
// theta's s1, s2
void slide_under(const VmMount& mount, double L, const Vec3& p, const Vec3& u,
                 VmAngles* theta) {
  const Vec3 tip = p - L * u - mount.origin;
  (*theta)[0] = mount.R.col(0).dot(tip);
  (*theta)[1] = mount.R.col(1).dot(tip);
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
  slide_under(mount_, length_, rm.p, a, theta);
  return true;
}

namespace {

// placement_minimum's cost along the angle psi between the probe and the
// reference direction e, up to a constant (vm_surface.h): with the contact
// held at distance dn from the RM, -2 w_pos L dn cos psi + w_ornt (psi -
// psi_a)^2; free, with the RM at height h over the plane, w_pos (h - L cos
// psi)^2 + w_ornt (psi - psi_a)^2. Its derivatives g' and g'' into *g1 and
// *g2 where given
struct ProbeAngleCost {
  bool contact_held;
  double w_pos, w_ornt, L, dn, h, psi_a;

  double operator()(double x, double* g1, double* g2) const {
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
  }
};

// The minimiser of the cost over psi in [0, pi] from psi: Newton where it
// is convex, else a bounded descent step, each halved until the cost does
// not increase
double minimise_probe_angle(const ProbeAngleCost& cost, double psi) {
  double g1 = 0.0, g2 = 0.0;
  double g = cost(psi, &g1, &g2);
  bool done = false;
  for (int it = 0; it < 50 && !done; ++it) {
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
  return psi;
}

}  // namespace

bool SurfaceVm::placement_minimum(const RmPose& rm, double w_pos, double w_ornt,
                                  bool contact_held, VmAngles* theta) const {
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
  const Vec3 u0 =
      mount_.R * Vec3(t_beta.c, t_beta.s * t_alpha.c, t_beta.s * t_alpha.s);
  const double L = length_;
  const ProbeAngleCost cost{contact_held, w_pos, w_ornt, L, dn, h, psi_a};
  const double psi =
      minimise_probe_angle(cost, std::atan2(u0.cross(e).norm(), u0.dot(e)));
  if (!std::isfinite(psi)) return false;
  const SinCos sp = sin_cos(psi);
  const Vec3 u = sp.c * e + sp.s * t;
  surface_angles(mount_.R.transpose() * u, theta);
  if (!contact_held) slide_under(mount_, L, rm.p, u, theta);
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

std::vector<PathPrimitive> SurfaceVm::path_primitives() const {
  // the plane the tip slides on; the handle moves L to either side of it
  PathPrimitive plane;
  plane.type = PathPrimitive::Type::kPlane;
  plane.centre = mount_.origin;
  plane.u = mount_.R.col(0);
  plane.v = mount_.R.col(1);
  plane.radius = length_;
  return {plane};
}

bool SurfaceVm::path_start(const Vec3&, PathStart* out) const {
  const Vec3 n = normal();
  out->outward = n;
  out->p = mount_.origin + length_ * n;
  out->tangent = n.unitOrthogonal().normalized();
  out->axis = n;
  out->tilt_b = -out->outward.cross(out->tangent);
  return true;
}

}  // namespace vmh
