#include "controller/omni_ratings.h"

#include <stdexcept>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"

namespace vmh {

const char* torque_limits_name(TorqueLimits t) {
  switch (t) {
    case TorqueLimits::kRated:
      return "rated";
    case TorqueLimits::kOpenHapticsSamples:
      return "openhaptics_samples";
  }
  return "unknown";
}

TorqueLimits parse_torque_limits(const std::string& text) {
  if (text == "rated") return TorqueLimits::kRated;
  if (text == "openhaptics_samples") return TorqueLimits::kOpenHapticsSamples;
  throw std::invalid_argument("torque_limits: '" + text +
                              "' is not one of rated, openhaptics_samples");
}

Vec3 motor_torque_per_force_m(const OmniParams& omni, const Joints& q_dh) {
  const Mat3 Jv = omni_jacobian(omni, q_dh).topLeftCorner<3, 3>();
  // D as a matrix: its columns are the images of the unit DH torques
  Mat3 D;
  for (int i = 0; i < 3; ++i) D.col(i) = dh_to_motor_torques(Vec3::Unit(i));
  const Mat3 DJt = D * Jv.transpose();
  return Vec3(DJt.row(0).norm(), DJt.row(1).norm(), DJt.row(2).norm());
}

std::array<double, kOmniActuated> motor_torques_for_force_Nm(const OmniParams& omni,
                                                            double force_N) {
  const Vec3 r = motor_torque_per_force_m(omni, Joints::Zero());
  return {force_N * r[0], force_N * r[1], force_N * r[2]};
}

std::array<double, kOmniActuated> motor_torque_limits_Nm(const OmniParams& omni,
                                                         TorqueLimits t) {
  if (t == TorqueLimits::kOpenHapticsSamples) return kOpenHapticsSampleTorqueLimit_Nm;
  return motor_torques_for_force_Nm(omni, omni.max_force_N);
}

}  // namespace vmh
