#include "controller/vm_line.h"

#include "controller/vm_common.h"

namespace vmh {

using namespace vm_detail;  // NOLINT(build/namespaces)

LineVm::LineVm(const VmMount& mount, double length)
    : VirtualMechanism(mount, length) {}

Vec3 LineVm::position(const VmAngles& theta) const {
  return mount_.origin + theta[0] * direction();
}

VmPose LineVm::pose(const VmAngles& theta) const {
  VmPose out;
  out.p = position(theta);
  out.R = mount_.R;
  out.axis = mount_.R.col(0);
  return out;
}

void LineVm::jacobian(const VmAngles&, VmJacobian* J) const {
  J->resize(6, 1);
  J->block<3, 1>(0, 0) = direction();
  J->block<3, 1>(3, 0).setZero();
}

bool LineVm::nearest(const RmPose& rm, VmAngles* theta) const {
  (*theta)[0] = direction().dot(rm.p - mount_.origin);
  return true;
}

bool LineVm::aligned(const RmPose& rm, VmAngles* theta) const {
  return nearest(rm, theta);
}

Vec3 LineVm::thesis_orientation_error(const VmAngles&,
                                      const VmAngles&) const {
  return Vec3::Zero();
}

Vec3 LineVm::geometric_orientation_error(const VmPose& vm, const RmPose& rm,
                                         bool* ambiguous) const {
  return planar_orientation_error(mount_.R.col(2), rm.axis, vm.axis,
                                  ambiguous);
}

Mat3 LineVm::orientation_error_jacobian(const VmPose&, const RmPose&) const {
  const Vec3 n = mount_.R.col(2);
  return n * n.transpose();
}

double LineVm::distance_to_path(const Vec3& p) const {
  return (p - nearest_on_path(p)).norm();
}

Vec3 LineVm::nearest_on_path(const Vec3& p) const {
  const Vec3 t = direction();
  return mount_.origin + t.dot(p - mount_.origin) * t;
}

std::vector<PathPrimitive> LineVm::path_primitives() const {
  PathPrimitive line;
  line.type = PathPrimitive::Type::kLine;
  line.centre = mount_.origin;
  line.u = direction();
  line.v = mount_.R.col(0);
  return {line};
}

bool LineVm::path_start(const Vec3& dir, PathStart* out) const {
  const Vec3 n = mount_.R.col(2);
  out->p = nearest_on_path(mount_.origin + length_ * dir);
  Vec3 w = mount_.origin + length_ * dir - out->p;
  w -= w.dot(n) * n;
  out->outward = w.norm() > 1e-6 * length_ ? w.normalized()
                                           : Vec3(mount_.R.col(0));
  out->tangent = n.cross(out->outward).normalized();
  out->axis = dir;
  out->tilt_b = -out->outward.cross(out->tangent);
  return true;
}

void LineVm::along_path(const PathStart& s, double phi, double across,
                        Vec3* p, Mat3* turn) const {
  turn->setIdentity();
  *p = s.p + (length_ * phi) * s.tangent + across * s.outward;
}

bool predict_line(const VirtualMechanism& vm, const RmPose& rm,
                  bool thesis_error, VmStaticPlacement* out, const char**) {
  const Mat3& R = vm.mount().R;
  const Vec3 t = R.col(1), n = R.col(2), u = R.col(0);
  out->x_v = vm.mount().origin + t.dot(rm.p - vm.mount().origin) * t;
  out->x_r = out->x_v;
  out->e_ornt_rad.setZero();
  Vec3 a;
  if (!thesis_error && unit_direction(project_out(rm.axis, n), &a)) {
    out->e_ornt_rad = n * angle_about(n, a, u);
  }
  out->J.resize(6, 1);
  out->J.col(0) << t, Vec3::Zero();
  return true;
}

}  // namespace vmh
