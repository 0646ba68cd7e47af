#include "device/motor_force_map.h"

#include <Eigen/LU>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"

namespace vmh {

Mat3 motor_torque_to_force_map(const OmniParams& omni,
                               const Joints& q_device_rad,
                               double damping_m) noexcept {
  const Joints q_dh = device_to_dh_joints(q_device_rad);
  const Mat3 J = omni_jacobian(omni, q_dh).topLeftCorner<3, 3>();
  const Mat3 JJt = J * J.transpose() + damping_m * damping_m * Mat3::Identity();
  // the columns of motor_to_dh_torques as a matrix (it is linear)
  Mat3 M;
  for (int i = 0; i < 3; ++i) M.col(i) = motor_to_dh_torques(Vec3::Unit(i));
  return R_device_base() * JJt.inverse() * J * M;
}

}  // namespace vmh
