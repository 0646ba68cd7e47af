// The 1-DOF circle VM (thesis §3.3, eq. 3.25-3.27): a link of length L
// turning about the pivot in the pivot frame's x-y plane; theta = the
// link's angle from the pivot frame's x axis. Units and frames:
// controller/virtual_mechanism.h.
#ifndef VMHAPTICS_CONTROLLER_VM_CIRCLE_H_
#define VMHAPTICS_CONTROLLER_VM_CIRCLE_H_

#include "controller/virtual_mechanism.h"

namespace vmh {

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
  std::vector<PathPrimitive> path_primitives() const override;
  bool planar() const override { return true; }
  bool path_start(const Vec3& dir, PathStart* out) const override;
};

// The registry's prediction hook (VmPredictFn): the nearest point and the
// aligned link from the wrist centre's and the stylus's projections onto the
// plane (§3.3.1), the planar error about the normal (eq. 3.32, the same in
// both formulations), J_V = [L n x u; n] for the link axis u at x_v.
bool predict_circle(const VirtualMechanism& vm, const RmPose& rm,
                    bool thesis_error, VmStaticPlacement* out,
                    const char** why_not);

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_VM_CIRCLE_H_
