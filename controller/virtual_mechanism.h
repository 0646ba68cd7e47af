// Virtual mechanisms (VMs): the imaginary constrained manipulators of
// Beckman & Luecke whose motion the real Omni is made to feel (thesis §3.1).
//
// A VM has m joint coordinates theta (m <= 5), a handle pose X_V(theta) and a
// 6 x m Jacobian J_V whose rows are the handle's linear velocity (rows 0-2)
// and angular velocity (rows 3-5), both in the device frame. This header is
// the interface; each mechanism has its own files, and
// controller/vm_registry.h lists them once (name, factory, prediction):
//   CircleVm  (vm_circle.h)  - 1 DOF: a link of length L turning about a
//               pivot in a plane (eq. 3.25-3.27). Appendix D puts the plane
//               in the device x-y plane; here it is the pivot frame's x-y.
//   SphereVm  (vm_sphere.h)  - 3 DOF: a link of length L on a ball joint at
//               the pivot (eq. 3.29-3.31); theta = (azimuth, polar, twist).
//   SurfaceVm (vm_surface.h) - 5 DOF: a probe whose tip slides on a plane
//               (two prismatic joints) with a ball joint at the tip (three
//               revolute joints), thesis §3.1. theta = (s1, s2, alpha, beta,
//               gamma).
//   LineVm    (vm_line.h)    - 1 DOF: a handle sliding on a straight line,
//               the circle's limit as its radius grows (this project's
//               addition, docs/control.md).
// The circle and the sphere write once, in RevoluteVm (vm_revolute.h), what
// follows from a link on revolute joints at the pivot: the pose, J_V and
// the closed forms from the angles of one direction.
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
#include <vector>

#include "controller/types.h"

namespace vmh {

inline constexpr int kMaxVmDof = 5;

// fixed-capacity, run-time-sized: stored inline, so no heap allocation
using VmAngles =
    Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxVmDof, 1>;
using VmJacobian =
    Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::ColMajor, 6, kMaxVmDof>;

// Which mechanism; controller/vm_registry.cc gives each its name and
// factory. Adding one is a value here, a row there, and its own files.
enum class VmKind { kCircle, kSphere, kSurface, kLine };

// a set of VM joints, bit j for joint j (e.g. locked during placement)
using JointMask = std::uint32_t;

// What a contact does under the force the control law asks for.
enum class ContactState {
  kClosed,   // the contact holds (sticks, or slides freely without friction)
  kSliding,  // it sticks no longer: the force left the friction cone
  kOpen,     // unilateral contact pulled on: the probe lifts off
};

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

// The path's shape, for figures and the viewer (drawing hook): primitives
// the drawing code knows, so a new mechanism made of them draws with no
// change there. Device frame, the VM's length unit.
struct PathPrimitive {
  enum class Type {
    kCircle,  // centre, in-plane unit axes u and v, radius
    kSphere,  // centre, radius (figures draw its outline)
    kLine,    // through centre along the unit u, unbounded
    kPlane,   // through centre, spanned by the unit u and v (unbounded);
              // the handle moves `radius` to either side of it
  };
  Type type = Type::kCircle;
  Vec3 centre = Vec3::Zero();
  Vec3 u = Vec3::UnitX();
  Vec3 v = Vec3::UnitY();
  double radius = 0.0;
};

// How the thesis's scripted experiments (ch. 4, sim/hand_script.h) hold the
// hand on this VM, device frame: the start point on the path; the unit
// direction "outward" from the path there (the off-path holds move along
// it); the unit tangent of the path there; the stylus axis held there
// (unless the case sets one); and the unit axis the second on-path hold
// tilts the stylus about (by +script_misalign_rad).
struct PathStart {
  Vec3 p = Vec3::Zero();
  Vec3 outward = Vec3::UnitX();
  Vec3 tangent = Vec3::UnitY();
  Vec3 axis = Vec3::UnitX();
  Vec3 tilt_b = Vec3::UnitY();
};

// What the law acts on at a static pose, worked out by a route apart from
// the servo tick's (each VM's prediction hook, controller/vm_registry.h,
// used by thesis/law_prediction.h): from the wrist centre and the stylus
// axis alone, in closed form, the nearest point of the path x_v, the handle
// turned onto the stylus x_r, the orientation error (the thesis's or the
// geometric, device frame, rad) and J_V at x_v built from the geometry, not
// from joint angles. Device frame, the VM's length unit.
struct VmStaticPlacement {
  Vec3 x_v = Vec3::Zero();
  Vec3 x_r = Vec3::Zero();
  Vec3 e_ornt_rad = Vec3::Zero();
  VmJacobian J;
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

  // ---- hooks for what is built on the controller (not the servo tick)

  // The path as drawing primitives (figures, viewer).
  virtual std::vector<PathPrimitive> path_primitives() const = 0;
  // Whether the path lies in the pivot frame's x-y plane (the figures then
  // draw it in that plane's view alone).
  virtual bool planar() const { return false; }

  // The scripts' start toward the unit device-frame direction `dir` from
  // the mount; false where `dir` names none (along the circle's normal).
  // The default (the sphere's): origin + L dir, outward along dir, the
  // tangent about the pivot frame's z axis, the stylus along dir, tilted
  // about the tangent.
  virtual bool path_start(const Vec3& dir, PathStart* out) const;
  // The sweep's motion: the handle moved along the path from the start s
  // by the angle phi (rad) and `across` (length unit) outward of it, *p,
  // with the rotation *turn the stylus turns by there. The default turns
  // about the pivot frame's z axis through the origin by phi, at the radius
  // L + across: the circle's and the sphere's motion. (A straight path
  // slides by the same arc, L phi.)
  virtual void along_path(const PathStart& s, double phi, double across,
                          Vec3* p, Mat3* turn) const;

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

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_VIRTUAL_MECHANISM_H_
