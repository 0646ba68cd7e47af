// The 3-DOF sphere VM (thesis §3.4, eq. 3.29-3.31): a link of length L on
// a ball joint at the pivot; theta = (azimuth, polar angle from the pivot
// frame's -z, twist about the link). Units and frames:
// controller/virtual_mechanism.h.
#ifndef VMHAPTICS_CONTROLLER_VM_SPHERE_H_
#define VMHAPTICS_CONTROLLER_VM_SPHERE_H_

#include "controller/virtual_mechanism.h"
#include "controller/vm_revolute.h"

namespace vmh {

namespace vm_detail {
struct SphereGeometry;  // vm_sphere.cc
}  // namespace vm_detail
extern template class RevoluteVm<vm_detail::SphereGeometry>;

// The pose, J_V, the closed forms and the path's drawing: RevoluteVm's,
// from the link's azimuth and polar angle (and the twist, for the pose)
class SphereVm final : public RevoluteVm<vm_detail::SphereGeometry> {
 public:
  SphereVm(const VmMount& mount, double length);
  VmKind kind() const override { return VmKind::kSphere; }
  int dof() const override { return 3; }
  Vec3 thesis_orientation_error(const VmAngles& theta_v,
                                const VmAngles& theta_r) const override;
  void normalize(VmAngles* theta) const override;
  double distance_to_path(const Vec3& p) const override;
  Vec3 nearest_on_path(const Vec3& p) const override;
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
