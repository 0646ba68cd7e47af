// The 1-DOF circle VM (thesis §3.3, eq. 3.25-3.27): a link of length L
// turning about the pivot in the pivot frame's x-y plane; theta = the
// link's angle from the pivot frame's x axis. Units and frames:
// controller/virtual_mechanism.h.
#ifndef VMHAPTICS_CONTROLLER_VM_CIRCLE_H_
#define VMHAPTICS_CONTROLLER_VM_CIRCLE_H_

#include "controller/virtual_mechanism.h"
#include "controller/vm_revolute.h"

namespace vmh {

namespace vm_detail {
struct CircleGeometry;  // vm_circle.cc
}  // namespace vm_detail
extern template class RevoluteVm<vm_detail::CircleGeometry>;

// The pose, J_V, the closed forms and the path's drawing: RevoluteVm's,
// from the link's angle in the plane
class CircleVm final : public RevoluteVm<vm_detail::CircleGeometry> {
 public:
  CircleVm(const VmMount& mount, double length);
  VmKind kind() const override { return VmKind::kCircle; }
  int dof() const override { return 1; }
  Vec3 thesis_orientation_error(const VmAngles& theta_v,
                                const VmAngles& theta_r) const override;
  Vec3 geometric_orientation_error(const VmPose& vm, const RmPose& rm,
                                   bool* ambiguous) const override;
  Mat3 orientation_error_jacobian(const VmPose& vm,
                                  const RmPose& rm) const override;
  void normalize(VmAngles* theta) const override;
  double distance_to_path(const Vec3& p) const override;
  Vec3 nearest_on_path(const Vec3& p) const override;
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
