// What the circle and the sphere share (vm_circle.h, vm_sphere.h): a link
// of length L on revolute joints at the pivot, whose closed forms (§3.3.1,
// §3.4.1) are the angles of one direction in the pivot frame, the wrist
// centre's from the pivot for nearest() and the stylus axis for aligned(),
// and whose pose and J_V follow from those angles' sines and cosines. The
// closed forms measure the sines and cosines from the direction itself, so
// that a servo tick's nearest_pose_jacobian() and aligned_position() skip
// the round trip through the angles (atan2, then sin and cos of its result,
// on the tick's critical path).
//
// RevoluteVm<Geometry> writes these overrides once. Each mechanism's
// Geometry, defined in its own .cc (which instantiates the template there:
// the headers declare it `extern template`), says the rest with static
// functions, all in the pivot frame:
//   Trig trig(theta)                the sines and cosines of theta
//   Trig angles(d, *theta)          the closed form: the angles of the
//                                   direction d into *theta, and their
//                                   sines and cosines measured from d
//   bool reaches(d, L)              whether nearest() is defined for the
//                                   wrist centre at d from the pivot
//   bool points(a)                  whether aligned() is defined for the
//                                   stylus axis a
//   VmPose pose(mount, L, t, theta) X_V from the sines and cosines t (and
//                                   theta, for an angle t leaves out)
//   void jacobian(mount, L, t, *J)  J_V from them
//   Vec3 link(t)                    the link's unit direction
//   kPath                           the path's drawing primitive
// Units and frames: controller/virtual_mechanism.h.
#ifndef VMHAPTICS_CONTROLLER_VM_REVOLUTE_H_
#define VMHAPTICS_CONTROLLER_VM_REVOLUTE_H_

#include <vector>

#include "controller/virtual_mechanism.h"

namespace vmh {

template <class Geometry>
class RevoluteVm : public VirtualMechanism {
 public:
  using VirtualMechanism::VirtualMechanism;

  VmPose pose(const VmAngles& theta) const final;
  void jacobian(const VmAngles& theta, VmJacobian* J) const final;
  void pose_jacobian(const VmAngles& theta, VmPose* pose,
                     VmJacobian* J) const final;
  Vec3 position(const VmAngles& theta) const final;
  bool nearest(const RmPose& rm, VmAngles* theta) const final;
  bool aligned(const RmPose& rm, VmAngles* theta) const final;
  bool nearest_pose_jacobian(const RmPose& rm, VmAngles* theta, VmPose* pose,
                             VmJacobian* J) const final;
  // the nearest point of the circle or the sphere is the closed form's
  bool nearest_minimises_distance() const final { return true; }
  bool aligned_position(const RmPose& rm, VmAngles* theta, Vec3* p) const final;
  bool is_revolute(int) const final { return true; }
  // the circle or the sphere of radius L about the pivot, drawn in the
  // pivot frame's x-y axes
  std::vector<PathPrimitive> path_primitives() const final;

 protected:
  // the point p in the pivot frame
  Vec3 from_pivot(const Vec3& p) const {
    return mount_.R.transpose() * (p - mount_.origin);
  }
  // the handle's position for the link's direction u in the pivot frame
  Vec3 handle_at(const Vec3& u) const {
    return mount_.origin + length_ * (mount_.R * u);
  }
};

template <class Geometry>
VmPose RevoluteVm<Geometry>::pose(const VmAngles& theta) const {
  return Geometry::pose(mount_, length_, Geometry::trig(theta), theta);
}

template <class Geometry>
void RevoluteVm<Geometry>::jacobian(const VmAngles& theta,
                                    VmJacobian* J) const {
  Geometry::jacobian(mount_, length_, Geometry::trig(theta), J);
}

template <class Geometry>
void RevoluteVm<Geometry>::pose_jacobian(const VmAngles& theta, VmPose* pose,
                                         VmJacobian* J) const {
  const auto t = Geometry::trig(theta);
  *pose = Geometry::pose(mount_, length_, t, theta);
  Geometry::jacobian(mount_, length_, t, J);
}

template <class Geometry>
Vec3 RevoluteVm<Geometry>::position(const VmAngles& theta) const {
  // the link's direction alone: no twist needed
  return handle_at(Geometry::link(Geometry::trig(theta)));
}

template <class Geometry>
bool RevoluteVm<Geometry>::nearest(const RmPose& rm, VmAngles* theta) const {
  const Vec3 d = from_pivot(rm.p);
  if (!Geometry::reaches(d, length_)) return false;
  Geometry::angles(d, theta);
  return true;
}

template <class Geometry>
bool RevoluteVm<Geometry>::aligned(const RmPose& rm, VmAngles* theta) const {
  const Vec3 a = mount_.R.transpose() * rm.axis;
  if (!Geometry::points(a)) return false;
  Geometry::angles(a, theta);
  return true;
}

template <class Geometry>
bool RevoluteVm<Geometry>::nearest_pose_jacobian(const RmPose& rm,
                                                 VmAngles* theta, VmPose* pose,
                                                 VmJacobian* J) const {
  const Vec3 d = from_pivot(rm.p);
  if (!Geometry::reaches(d, length_)) return false;
  const auto t = Geometry::angles(d, theta);
  *pose = Geometry::pose(mount_, length_, t, *theta);
  Geometry::jacobian(mount_, length_, t, J);
  return true;
}

template <class Geometry>
bool RevoluteVm<Geometry>::aligned_position(const RmPose& rm, VmAngles* theta,
                                            Vec3* p) const {
  const Vec3 a = mount_.R.transpose() * rm.axis;
  if (!Geometry::points(a)) {
    *p = position(*theta);
    return false;
  }
  *p = handle_at(Geometry::link(Geometry::angles(a, theta)));
  return true;
}

template <class Geometry>
std::vector<PathPrimitive> RevoluteVm<Geometry>::path_primitives() const {
  PathPrimitive path;
  path.type = Geometry::kPath;
  path.centre = mount_.origin;
  path.u = mount_.R.col(0);
  path.v = mount_.R.col(1);
  path.radius = length_;
  return {path};
}

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_VM_REVOLUTE_H_
