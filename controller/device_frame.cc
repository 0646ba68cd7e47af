#include "controller/device_frame.h"

namespace vmh {

Joints device_to_dh_joints(const Joints& t) {
  Joints q;
  q << -t[0], t[1], t[2] - t[1], -t[3], t[4], -t[5];
  return q;
}

Joints dh_to_device_joints(const Joints& q) {
  Joints t;
  t << -q[0], q[1], q[1] + q[2], -q[3], q[4], -q[5];
  return t;
}

void device_joint_ranges(const OmniParams& params, Joints* lower_device_rad,
                         Joints* upper_device_rad) {
  Joints lo_dh, hi_dh;
  for (int i = 0; i < 6; ++i) {
    lo_dh[i] = params.joint_lower_rad[static_cast<std::size_t>(i)];
    hi_dh[i] = params.joint_upper_rad[static_cast<std::size_t>(i)];
  }
  const Joints a = dh_to_device_joints(lo_dh);
  const Joints b = dh_to_device_joints(hi_dh);
  *lower_device_rad = a.cwiseMin(b);
  *upper_device_rad = a.cwiseMax(b);
}

Vec3 motor_to_dh_torques(const Vec3& m) {
  return Vec3(-m[0], m[1] + m[2], m[2]);
}

Vec3 device_mm_to_base(const OmniParams& p, const Vec3& p_device_mm) {
  return R_device_base().transpose() * (p_device_mm / kMmPerM) +
         device_origin_base_m(p);
}

Mat3 base_to_device_rotation(const Mat3& R_base) {
  return R_device_base() * R_base;
}

Mat3 device_to_base_rotation(const Mat3& R_device) {
  return R_device_base().transpose() * R_device;
}

}  // namespace vmh
