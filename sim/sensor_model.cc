#include "sim/sensor_model.h"

#include <cmath>

#include "controller/device_frame.h"

namespace vmh::sim {

SensorModel::SensorModel(const OmniParams& omni, bool enabled)
    : enabled_(enabled) {
  const double two_pi = 2.0 * constants::kPi;
  // joint ranges are given in the DH convention; the device's gimbal angles
  // are the DH ones with t4 = -q4, t6 = -q6, and the ranges are symmetric,
  // so the span is the same; the lower bound is mapped explicitly
  Joints a, b;
  device_joint_ranges(omni, &a, &b);
  for (int i = 0; i < 6; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (i < 3) {
      step_[k] = two_pi / omni.encoder_counts_per_rev;
      lower_[k] = 0.0;
    } else {
      // 2^bits levels with both ends of the range among them: 2^bits - 1
      // steps across the span
      levels_[k] = std::ldexp(1.0, omni.gimbal_pot_bits);
      step_[k] = std::abs(b[i] - a[i]) / (levels_[k] - 1.0);
      lower_[k] = std::min(a[i], b[i]);
    }
    if (!enabled_) step_[k] = 0.0;
  }
}

Joints SensorModel::measure(const Joints& q_device_rad) const {
  if (!enabled_) return q_device_rad;
  Joints out;
  for (int i = 0; i < 6; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double rel = q_device_rad[i] - lower_[k];
    double level = std::round(rel / step_[k]);
    // a potentiometer cannot read past the ends of its track (a NaN passes
    // through both comparisons and stays NaN)
    if (levels_[k] > 0.0) {
      if (level < 0.0) level = 0.0;
      if (level > levels_[k] - 1.0) level = levels_[k] - 1.0;
    }
    out[i] = lower_[k] + level * step_[k];
  }
  return out;
}

}  // namespace vmh::sim
