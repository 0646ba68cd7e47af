// The emulator's seeded faults (sim/emulator_faults.h, SeededFaults) from
// their text form (sim/fault_vocabulary.h parses it), and their effect on the
// reported joint angles.
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>

#include "sim/emulator_faults.h"
#include "sim/fault_vocabulary.h"

namespace vmh::sim {
SeededFaults parse_seeded_faults(const std::string& text) {
  SeededFaults f;
  for (const FaultItem& it : parse_faults(text, kSeededFaults)) {
    const std::string kind = it.kind->name;
    const double x = it.values.empty() ? 0.0 : it.values[0];
    if (kind == "gimbal_swap") {
      f.gimbal_swap = true;
    } else if (kind == "motor3_relative") {
      f.edit.motor3_relative = true;
    } else if (kind == "torque_units_Nm") {
      f.torque_scale = 1000.0;
    } else if (kind == "torque_units_mNm") {
      f.torque_scale = 0.001;
    } else if (kind == "joint<N>_sign") {
      f.joint_sign[static_cast<std::size_t>(x) - 1] = true;
    } else if (kind == "motor<N>_sign") {
      f.edit.motor_gain[static_cast<int>(x) - 1] = -1.0;
    } else if (kind == "link_length_<P>pct") {
      f.edit.link1_scale = 1.0 + x / 100.0;
    } else if (kind == "delay_<M>ms") {
      f.delay_ms = x;
    } else if (kind == "mass_x<K>") {
      f.edit.mass_scale = x;
    } else if (kind == "friction_x<K>") {
      f.edit.friction_scale = x;
    } else if (kind == "damping_x<K>") {
      f.edit.damping_scale = x;
    } else {
      // a seeded kind in the table that this function does not apply
      throw std::logic_error("parse_seeded_faults: no effect for " + kind);
    }
    f.items.push_back(it.text);
  }
  return f;
}

void apply_seeded_readings(const SeededFaults& seeded,
                           Joints* q_device_rad) noexcept {
  if (seeded.gimbal_swap) std::swap((*q_device_rad)[4], (*q_device_rad)[5]);
  for (int i = 0; i < 6; ++i) {
    if (seeded.joint_sign[static_cast<std::size_t>(i)]) {
      (*q_device_rad)[i] = -(*q_device_rad)[i];
    }
  }
}

}  // namespace vmh::sim
