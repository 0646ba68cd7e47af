// What the Omni's sensors make of the true joint angles: the three actuated
// joints through optical encoders of 15000 counts per revolution, the three
// gimbal joints through potentiometers read with 11 valid bits
// (OmniParams, docs/sources.md §6). Angles in the device convention, rad.
#ifndef VMHAPTICS_SIM_SENSOR_MODEL_H_
#define VMHAPTICS_SIM_SENSOR_MODEL_H_

#include <array>

#include "controller/omni_params.h"
#include "controller/types.h"

namespace vmh::sim {

class SensorModel {
 public:
  // enabled = false passes the angles through unchanged
  SensorModel(const OmniParams& omni, bool enabled);

  // t1..t3 rounded to whole encoder counts; t4..t6 rounded to one of
  // 2^bits levels spanning the joint's range, ends included, and clamped to
  // them (the potentiometer's span is
  // taken to be the joint's range: an estimate, docs/omni.md).
  Joints measure(const Joints& q_device_rad) const;

  // the size of one step, rad, for each joint (0 when disabled)
  const std::array<double, 6>& resolution_rad() const { return step_; }

 private:
  bool enabled_;
  std::array<double, 6> step_{};
  std::array<double, 6> lower_{};
  std::array<double, 6> levels_{};  // potentiometer levels (0: an encoder)
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_SENSOR_MODEL_H_
