// The 3-DOF sphere VM (thesis §3.4, eq. 3.29-3.31): a link of length L on
// a ball joint at the pivot; theta = (azimuth, polar angle from the pivot
// frame's -z, twist about the link). Units and frames:
// controller/virtual_mechanism.h.
#ifndef VMHAPTICS_CONTROLLER_VM_SPHERE_H_
#define VMHAPTICS_CONTROLLER_VM_SPHERE_H_

#include "controller/virtual_mechanism.h"

namespace vmh {

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
  std::vector<PathPrimitive> path_primitives() const override;
};

// The registry's prediction hook (VmPredictFn): the nearest point and the
// aligned link along the wrist centre's and the stylus's directions from the
// pivot (§3.4.1); the thesis's error from the sphere's angles of the two
// directions (eq. 3.35-3.37) or the rotation vector carrying the stylus onto
// the link; J_V's columns the rigid rotations about the pivot, [L w x u; w]
// for w each device axis (they span what the ball joint's do).
bool predict_sphere(const VirtualMechanism& vm, const RmPose& rm,
                    bool thesis_error, VmStaticPlacement* out,
                    const char** why_not);

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_VM_SPHERE_H_
