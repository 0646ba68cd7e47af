#include "controller/omni_params.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace vmh {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("OmniParams: " + what);
}

std::string num(double v) { return std::to_string(v); }

}  // namespace

void OmniParams::validate() const {
  require(std::isfinite(l0_m), "l0_m must be finite, got " + num(l0_m));
  require(std::isfinite(l1_m) && l1_m > 0,
          "l1_m must be finite and > 0, got " + num(l1_m));
  require(std::isfinite(l2_m) && l2_m > 0,
          "l2_m must be finite and > 0, got " + num(l2_m));
  require(std::isfinite(tool_offset_m),
          "tool_offset_m must be finite, got " + num(tool_offset_m));
  for (int i = 0; i < kOmniJoints; ++i) {
    const double lo = joint_lower_rad[i], hi = joint_upper_rad[i];
    require(std::isfinite(lo) && std::isfinite(hi) && lo < hi,
            std::string("joint range of ") + joint_name(i) +
                " must be finite with lower < upper, got [" + num(lo) + ", " +
                num(hi) + "]");
  }
  for (int i = 0; i < kOmniActuated; ++i) {
    require(
        std::isfinite(motor_torque_limit_Nm[i]) && motor_torque_limit_Nm[i] > 0,
        std::string("motor_torque_limit_Nm of ") + joint_name(i) +
            " must be > 0, got " + num(motor_torque_limit_Nm[i]));
  }
  require(std::isfinite(max_force_N) && max_force_N > 0,
          "max_force_N must be > 0, got " + num(max_force_N));
  require(std::isfinite(continuous_force_N) && continuous_force_N > 0 &&
              continuous_force_N <= max_force_N,
          "continuous_force_N must be in (0, max_force_N], got " +
              num(continuous_force_N));
  require(
      std::isfinite(encoder_counts_per_rev) && encoder_counts_per_rev > 0,
      "encoder_counts_per_rev must be > 0, got " + num(encoder_counts_per_rev));
  require(gimbal_pot_bits > 0 && gimbal_pot_bits <= 16,
          "gimbal_pot_bits must be in [1, 16], got " +
              std::to_string(gimbal_pot_bits));
}

const char* joint_name(int i) {
  static const char* const kNames[kOmniJoints] = {"q1", "q2", "q3",
                                                  "q4", "q5", "q6"};
  return (i >= 0 && i < kOmniJoints) ? kNames[i] : "q?";
}

}  // namespace vmh
