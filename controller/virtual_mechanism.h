// Virtual mechanisms (VMs): the imaginary constrained manipulators of
// Beckman & Luecke whose motion the real Omni is made to feel (thesis §3.1).
//
// A VM has m joint coordinates theta (m <= 5), a handle pose X_V(theta) and a
// 6 x m Jacobian J_V whose rows are the handle's linear velocity (rows 0-2)
// and angular velocity (rows 3-5), both in the device frame. Three VMs are
// provided:
//   CircleVm  - 1 DOF: a link of length L turning about a pivot in a plane
//               (eq. 3.25-3.27). Appendix D puts the plane in the device x-y
//               plane; here the plane is the pivot frame's x-y plane.
//   SphereVm  - 3 DOF: a link of length L on a ball joint at the pivot
//               (eq. 3.29-3.31); theta = (azimuth, polar, twist).
//   SurfaceVm - 5 DOF: a probe whose tip slides on a plane (two prismatic
//               joints) with a ball joint at the tip (three revolute joints),
//               thesis §3.1. theta = (s1, s2, alpha, beta, gamma).
//
// Units: the mechanisms do not know about units. Every length (pivot, L,
// positions, prismatic coordinates) is in one length unit chosen by the
// caller; the Controller uses its `length_unit_mm` (mm by default, as in the
// thesis). Angles are in rad.
//
// Orientation: the quantity a VM compares with the Omni is the direction of
// its link, `axis` (pivot or tip -> handle), against the stylus axis (the z
// column of the OpenHaptics stylus transform, pointing from the pen tip back
// toward the gimbal). Twist about the axis is free in every VM.
//
// Nothing here allocates or throws after construction; constructors throw
// std::invalid_argument naming a bad parameter.
#ifndef VMHAPTICS_CONTROLLER_VIRTUAL_MECHANISM_H_
#define VMHAPTICS_CONTROLLER_VIRTUAL_MECHANISM_H_

#include <cstdint>
#include <limits>

#include "controller/types.h"

namespace vmh {

inline constexpr int kMaxVmDof = 5;

// fixed-capacity, run-time-sized: stored inline, so no heap allocation
using VmAngles =
    Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxVmDof, 1>;
using VmJacobian =
    Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::ColMajor, 6, kMaxVmDof>;

enum class VmKind { kCircle, kSphere, kSurface };

// a set of VM joints, bit j for joint j (e.g. locked during placement)
using JointMask = std::uint32_t;

// What a contact does under the force the control law asks for.
enum class ContactState {
  kClosed,   // the contact holds (sticks, or slides freely without friction)
  kSliding,  // it sticks no longer: the force left the friction cone
  kOpen,     // unilateral contact pulled on: the probe lifts off
};

// "circle", "sphere", "surface"
const char* vm_kind_name(VmKind kind);
// parses the names above; false for anything else
bool parse_vm_kind(const char* text, VmKind* kind);

// What a VM sees of the real manipulator (RM): the wrist-centre position and
// the unit stylus axis, both in the device frame (position in the caller's
// length unit).
struct RmPose {
  Vec3 p = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
};

// The handle pose X_V(theta): position, handle frame (the thesis's 0_2T or
// 0_4T rotation), and link axis, all in the device frame.
struct VmPose {
  Vec3 p = Vec3::Zero();
  Mat3 R = Mat3::Identity();
  Vec3 axis = Vec3::UnitX();
};

// Where a VM is attached: its pivot (circle, sphere) or a point of its plane
// (surface), and the pivot frame's orientation in the device frame. The
// circle lies in the pivot frame's x-y plane; the sphere's polar angle is
// measured from the pivot frame's -z axis (eq. 3.30); the surface's normal is
// the pivot frame's z axis.
struct VmMount {
  Vec3 origin = Vec3::Zero();
  Mat3 R = Mat3::Identity();
};

class VirtualMechanism {
 public:
  VirtualMechanism(const VmMount& mount, double length);
  virtual ~VirtualMechanism() = default;

  virtual VmKind kind() const = 0;
  virtual int dof() const = 0;

  // X_V(theta): handle pose in the device frame
  virtual VmPose pose(const VmAngles& theta) const = 0;
  // J_V(theta), 6 x dof(): rows 0-2 linear velocity of the handle (length
  // unit per rad, or per length unit for a prismatic joint), rows 3-5 angular
  // velocity (rad per rad); device frame
  virtual void jacobian(const VmAngles& theta, VmJacobian* J) const = 0;
  // X_V(theta)'s position alone (pose(theta).p), for a VM that can skip
  // the rest
  virtual Vec3 position(const VmAngles& theta) const {
    return pose(theta).p;
  }
  // both at one theta (what a servo tick needs), sharing their sines and
  // cosines where a VM overrides it; the same numbers as pose() and
  // jacobian()
  virtual void pose_jacobian(const VmAngles& theta, VmPose* pose,
                             VmJacobian* J) const {
    *pose = this->pose(theta);
    jacobian(theta, J);
  }

  // Closed-form placements (§3.2). `nearest` puts the handle at the point of
  // the VM's path closest to the RM's position (weight W_p, eq. 3.21-3.24,
  // the thesis's theta_V); `aligned` turns the link onto the stylus axis
  // (weight W_o, eq. 3.17-3.20, the thesis's theta_R). Each returns false
  // and leaves *theta untouched where the answer is undefined (the RM at the
  // pivot, or the axis along the circle's normal / the sphere's pole axis);
  // otherwise angles the closed form does not fix (twist, and for the
  // surface the contact point) keep their values from *theta.
  virtual bool nearest(const RmPose& rm, VmAngles* theta) const = 0;
  virtual bool aligned(const RmPose& rm, VmAngles* theta) const = 0;

  // Whether nearest() returns the minimiser of |p_RM - X_V(theta)| over the
  // whole path (not only a nearby one): true for the circle and the sphere,
  // whose nearest point is their closed form's answer (§3.3.1, §3.4.1).
  // Under W_p with equal position weights, Gauss-Newton can then start from
  // it without comparing it with the warm start.
  virtual bool nearest_minimises_distance() const { return false; }

  // What a closed-form servo tick asks for, each in one call: nearest() and,
  // where it succeeds, pose_jacobian() at the angles it set; aligned() and
  // then the handle's position at *theta (changed or kept). A VM whose
  // closed form yields the pose's sines and cosines from the direction it
  // measured (the circle, the sphere) overrides them and skips the round
  // trip through the angles (atan2, then sin and cos: one on the other's
  // result, on the tick's critical path). The same numbers as the calls
  // they combine, to rounding.
  virtual bool nearest_pose_jacobian(const RmPose& rm, VmAngles* theta,
                                     VmPose* pose, VmJacobian* J) const {
    if (!nearest(rm, theta)) return false;
    pose_jacobian(*theta, pose, J);
    return true;
  }
  virtual bool aligned_position(const RmPose& rm, VmAngles* theta,
                                Vec3* p) const {
    const bool ok = aligned(rm, theta);
    *p = position(*theta);
    return ok;
  }

  // The thesis's orientation error rows (theta_x, theta_y, theta_z) from
  // joint-angle differences, each wrapped to (-pi, pi] (eq. 3.32-3.37 and
  // §3.3.1). The surface has no thesis formula; it maps the wrapped revolute
  // differences through its rotational Jacobian rows (docs/control.md).
  virtual Vec3 thesis_orientation_error(const VmAngles& theta_v,
                                        const VmAngles& theta_r) const = 0;

  // The rotation vector (device frame) of the smallest rotation that carries
  // the stylus axis onto the VM's link axis; consistent with the angular
  // velocity rows of J_V. Planar VMs first project the stylus axis into
  // their plane. *ambiguous (optional) is set when the two are opposite or
  // the projection vanishes, where the direction is a choice.
  virtual Vec3 geometric_orientation_error(const VmPose& vm, const RmPose& rm,
                                           bool* ambiguous) const;

  // The derivative of geometric_orientation_error with respect to a small
  // rotation dw of the VM's link (d e = M dw), so that M times J_V's angular
  // rows is the exact Jacobian of the error. M -> I - u u^T as the axes
  // align; the planar VMs' error turns only about their normal (n n^T).
  virtual Mat3 orientation_error_jacobian(const VmPose& vm,
                                          const RmPose& rm) const;

  // true for angular joints (wrapped, unbounded or periodic), false for
  // prismatic ones
  virtual bool is_revolute(int joint) const = 0;
  // brings theta to its canonical range (angles wrapped to (-pi, pi], the
  // polar angle to [0, pi]) without moving the handle
  virtual void normalize(VmAngles* theta) const = 0;

  // The VM's path in closed form, device frame, the caller's length unit:
  // the circle or the sphere the handle moves on; for the surface, the
  // handle positions with the probe upright (the two planes L from the
  // plane). distance_to_path is the distance from p to it; nearest_on_path
  // the point of it nearest p (at the pivot, where every point is nearest,
  // the pivot itself).
  virtual double distance_to_path(const Vec3& p) const = 0;
  virtual Vec3 nearest_on_path(const Vec3& p) const = 0;

  // Contact with the environment the VM stands for: none by default; the
  // surface's probe touches its plane. stick_joints() are the joints held
  // while the contact sticks (the surface's prismatic pair); contact_state()
  // says what the contact does under f_N, the force the law asks for
  // (device frame, N), with Coulomb coefficient mu and, if `unilateral`,
  // a contact that can only push; `sticking` says whether stick_joints()
  // were held when f_N was computed.
  virtual bool has_contact() const { return false; }
  virtual JointMask stick_joints() const { return 0u; }
  virtual ContactState contact_state(const Vec3& f_N, double mu,
                                     bool unilateral, bool sticking) const;

  // Where the VM can say so in closed form, the minimiser of the placement
  // cost r^T W r (W = diag(w_pos I, w_ornt I), r = placement_residual) near
  // *theta, for a Gauss-Newton placement to start from: true and *theta
  // replaced; false (nothing written) where the VM has no such form or it
  // is undefined. `contact_held`: the stick joints are locked. None by
  // default.
  virtual bool placement_minimum(const RmPose& rm, double w_pos,
                                 double w_ornt, bool contact_held,
                                 VmAngles* theta) const {
    (void)rm, (void)w_pos, (void)w_ornt, (void)contact_held, (void)theta;
    return false;
  }

  // a VmAngles of size dof(), zero
  VmAngles zero_angles() const;
  // the angles before any placement (zero, or the surface's upright probe)
  virtual VmAngles rest_angles() const { return zero_angles(); }

  const VmMount& mount() const { return mount_; }
  double length() const { return length_; }

 protected:
  VmMount mount_;
  double length_;
};

class CircleVm final : public VirtualMechanism {
 public:
  CircleVm(const VmMount& mount, double length);
  VmKind kind() const override { return VmKind::kCircle; }
  int dof() const override { return 1; }
  VmPose pose(const VmAngles& theta) const override;
  void jacobian(const VmAngles& theta, VmJacobian* J) const override;
  void pose_jacobian(const VmAngles& theta, VmPose* pose,
                     VmJacobian* J) const override;
  Vec3 position(const VmAngles& theta) const override;
  bool nearest(const RmPose& rm, VmAngles* theta) const override;
  bool aligned(const RmPose& rm, VmAngles* theta) const override;
  bool nearest_pose_jacobian(const RmPose& rm, VmAngles* theta, VmPose* pose,
                             VmJacobian* J) const override;
  bool nearest_minimises_distance() const override { return true; }
  bool aligned_position(const RmPose& rm, VmAngles* theta,
                        Vec3* p) const override;
  Vec3 thesis_orientation_error(const VmAngles& theta_v,
                                const VmAngles& theta_r) const override;
  Vec3 geometric_orientation_error(const VmPose& vm, const RmPose& rm,
                                   bool* ambiguous) const override;
  Mat3 orientation_error_jacobian(const VmPose& vm,
                                  const RmPose& rm) const override;
  bool is_revolute(int) const override { return true; }
  void normalize(VmAngles* theta) const override;
  double distance_to_path(const Vec3& p) const override;
  Vec3 nearest_on_path(const Vec3& p) const override;
};

class SphereVm final : public VirtualMechanism {
 public:
  SphereVm(const VmMount& mount, double length);
  VmKind kind() const override { return VmKind::kSphere; }
  int dof() const override { return 3; }
  VmPose pose(const VmAngles& theta) const override;
  void jacobian(const VmAngles& theta, VmJacobian* J) const override;
  void pose_jacobian(const VmAngles& theta, VmPose* pose,
                     VmJacobian* J) const override;
  Vec3 position(const VmAngles& theta) const override;
  bool nearest(const RmPose& rm, VmAngles* theta) const override;
  bool aligned(const RmPose& rm, VmAngles* theta) const override;
  bool nearest_pose_jacobian(const RmPose& rm, VmAngles* theta, VmPose* pose,
                             VmJacobian* J) const override;
  bool nearest_minimises_distance() const override { return true; }
  bool aligned_position(const RmPose& rm, VmAngles* theta,
                        Vec3* p) const override;
  Vec3 thesis_orientation_error(const VmAngles& theta_v,
                                const VmAngles& theta_r) const override;
  bool is_revolute(int) const override { return true; }
  void normalize(VmAngles* theta) const override;
  double distance_to_path(const Vec3& p) const override;
  Vec3 nearest_on_path(const Vec3& p) const override;
};

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
};

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_VIRTUAL_MECHANISM_H_
