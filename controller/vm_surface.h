// The 5-DOF surface VM (thesis §3.1): a probe of length L whose tip slides
// on a plane (two prismatic joints) with a ball joint at the tip (three
// revolute joints); theta = (s1, s2, alpha, beta, gamma). Units and frames:
// controller/virtual_mechanism.h.
#ifndef VMHAPTICS_CONTROLLER_VM_SURFACE_H_
#define VMHAPTICS_CONTROLLER_VM_SURFACE_H_

#include "controller/virtual_mechanism.h"

namespace vmh {

// The plane passes through mount.origin with normal mount.R.col(2); the
// prismatic joints slide along mount.R.col(0) and col(1). The link direction
// is u = cos(beta) t1 + sin(beta) (cos(alpha) t2 + sin(alpha) n), so the
// probe standing upright (u = n) is at alpha = beta = pi/2, far from the
// parametrisation's poles (u = +-t1, the probe lying in the plane).
class SurfaceVm final : public VirtualMechanism {
 public:
  SurfaceVm(const VmMount& mount, double length);
  VmKind kind() const override { return VmKind::kSurface; }
  int dof() const override { return 5; }
  VmPose pose(const VmAngles& theta) const override;
  void jacobian(const VmAngles& theta, VmJacobian* J) const override;
  // nearest: keeps the contact point and turns the probe toward the RM
  // (the sticking probe); aligned: turns the probe onto the stylus axis and
  // slides the contact under the stylus tip, p - L * axis projected on the
  // plane
  bool nearest(const RmPose& rm, VmAngles* theta) const override;
  bool aligned(const RmPose& rm, VmAngles* theta) const override;
  Vec3 thesis_orientation_error(const VmAngles& theta_v,
                                const VmAngles& theta_r) const override;
  bool is_revolute(int joint) const override { return joint >= 2; }
  void normalize(VmAngles* theta) const override;
  // the handle positions with the probe upright: L above or below the plane
  double distance_to_path(const Vec3& p) const override;
  Vec3 nearest_on_path(const Vec3& p) const override;
  bool has_contact() const override { return true; }
  // the prismatic joints s1, s2: the contact point
  JointMask stick_joints() const override { return 3u; }
  // kOpen if unilateral and f_N . n < 0 (the plane would have to pull the
  // probe toward it; the handle stands on the +n side); kSliding if
  // sticking and the tangential part exceeds mu |f_n| (plus a floor of
  // 1e-6 N that keeps rounding-level forces at rest from creeping the
  // contact); kClosed otherwise
  ContactState contact_state(const Vec3& f_N, double mu, bool unilateral,
                             bool sticking) const override;
  // the probe upright (alpha = beta = pi/2), the contact at the origin
  VmAngles rest_angles() const override;
  // The placement cost reduces to one angle (docs/control.md): with the
  // contact free, the best contact leaves only the normal part of the
  // position residual, h - L u.n (h the RM's height over the plane); with it
  // held at c, the position part depends on u only through u.d (d = p - c).
  // Either way, for a fixed angle psi between u and n (or d), the angle phi
  // between u and the stylus axis is smallest, |psi - psi_a|, with u in the
  // plane of n (or d) and the axis. So u = cos psi n + sin psi t, and psi
  // minimises w_pos (h - L cos psi)^2 + w_ornt (psi - psi_a)^2 (free), or
  // -2 w_pos L |d| cos psi + w_ornt (psi - psi_a)^2 (held), by safeguarded
  // Newton from *theta's psi. False where w_ornt = 0 (a family of minima),
  // the axis lies along n (or d) (no plane), or the RM sits on the contact.
  bool placement_minimum(const RmPose& rm, double w_pos, double w_ornt,
                         bool contact_held, VmAngles* theta) const override;

  // the contact point (device frame) for theta
  Vec3 contact(const VmAngles& theta) const;
  // unit normal of the plane (device frame)
  Vec3 normal() const { return mount_.R.col(2); }
  std::vector<PathPrimitive> path_primitives() const override;
  // the probe upright over the plane's origin, outward along the normal
  bool path_start(const Vec3& dir, PathStart* out) const override;
};

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_VM_SURFACE_H_
