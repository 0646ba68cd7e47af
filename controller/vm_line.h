// The 1-DOF line VM, a slider: a handle sliding on a straight line, the
// circle VM's limit as its radius grows without bound (this project's
// addition to the thesis's family, docs/control.md "The line slider").
//
// The line passes through the mount's origin along the pivot frame's y
// axis; theta = s, the handle's signed distance from the origin along it
// (a prismatic joint, the caller's length unit). The link stands along the
// pivot frame's x axis and never turns: the handle frame is the pivot
// frame. This is the circle of radius rho centred at origin - rho x at
// theta = 0, as rho -> infinity: same point, same tangent, same link
// direction, and a link that no longer turns as the handle moves.
//
// What follows for the law (eq. 3.11): J_V = [y; 0], so the projection
// removes the part of K_p e_p along the line and leaves the rest; its zero
// angular rows couple nothing of the orientation error into the force. A
// misaligned stylus is not felt: the circle's bending force, K_o e_o L /
// (w_p L^2 + w_o) along the path, goes to zero as L grows.
//
// L (length) is not used by the law. It is the link's drawn length and the
// scale of the scripted moves (the start toward origin + L dir, the sweep's
// arc L phi), so a line case runs the circle case's script.
#ifndef VMHAPTICS_CONTROLLER_VM_LINE_H_
#define VMHAPTICS_CONTROLLER_VM_LINE_H_

#include "controller/virtual_mechanism.h"

namespace vmh {

class LineVm final : public VirtualMechanism {
 public:
  LineVm(const VmMount& mount, double length);
  VmKind kind() const override { return VmKind::kLine; }
  int dof() const override { return 1; }
  VmPose pose(const VmAngles& theta) const override;
  void jacobian(const VmAngles& theta, VmJacobian* J) const override;
  Vec3 position(const VmAngles& theta) const override;
  // the foot of the perpendicular from the RM; always defined
  bool nearest(const RmPose& rm, VmAngles* theta) const override;
  bool nearest_minimises_distance() const override { return true; }
  // Every s turns the link the same way, so no s aligns it better than
  // another: theta_R is taken as theta_V, the aligned configuration
  // nearest the RM (X(theta_R) = X(theta_V)). Always true.
  bool aligned(const RmPose& rm, VmAngles* theta) const override;
  // The thesis's error differences revolute joint angles (eq. 3.32); the
  // line has none, so it is zero.
  Vec3 thesis_orientation_error(const VmAngles& theta_v,
                                const VmAngles& theta_r) const override;
  // the circle's: the planar angle about the normal from the stylus's
  // projection onto the plane to the link (which J_V cannot turn)
  Vec3 geometric_orientation_error(const VmPose& vm, const RmPose& rm,
                                   bool* ambiguous) const override;
  Mat3 orientation_error_jacobian(const VmPose& vm,
                                  const RmPose& rm) const override;
  bool is_revolute(int) const override { return false; }
  void normalize(VmAngles*) const override {}
  double distance_to_path(const Vec3& p) const override;
  Vec3 nearest_on_path(const Vec3& p) const override;

  std::vector<PathPrimitive> path_primitives() const override;
  bool planar() const override { return true; }
  // the point of the line nearest origin + L dir; outward toward dir's
  // side of the line in the plane (the pivot frame's x if dir has no side)
  bool path_start(const Vec3& dir, PathStart* out) const override;
  // slides L phi along the tangent; the stylus does not turn
  void along_path(const PathStart& s, double phi, double across, Vec3* p,
                  Mat3* turn) const override;

  // the line's unit direction (device frame)
  Vec3 direction() const { return mount_.R.col(1); }
};

// The registry's prediction hook (VmPredictFn): the foot of the
// perpendicular for both x_v and x_r, the error zero (the thesis's) or the
// planar angle from the stylus's projection onto the plane to the link
// (the geometric one), J_V = [direction; 0].
bool predict_line(const VirtualMechanism& vm, const RmPose& rm,
                  bool thesis_error, VmStaticPlacement* out,
                  const char** why_not);

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_VM_LINE_H_
