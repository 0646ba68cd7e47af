// The emulated device's own kinematics (sim/emulator.h says the
// conventions): the wrist site's pose, velocity and Jacobian in the device
// frame, from MuJoCo's true state, as OpenHaptics reports
// HD_CURRENT_TRANSFORM, HD_CURRENT_VELOCITY and HD_CURRENT_JACOBIAN.
//
// Computed on a scratch mjData of its own (qpos, qvel and mocap copied in,
// then mj_kinematics and mj_comPos), so that the physics' mjData is never
// touched between steps: after mj_step its positions are a step old, and
// refreshing them would change nothing the next step uses but would make
// the emulator's physics depend on whether the kinematics are reported.
#ifndef VMHAPTICS_SIM_EMULATOR_KINEMATICS_H_
#define VMHAPTICS_SIM_EMULATOR_KINEMATICS_H_

#include <mujoco/mujoco.h>

#include <array>
#include <vector>

#include "controller/omni_params.h"
#include "device/device_state.h"
#include "sim/mujoco_util.h"

namespace vmh::sim {

class EmulatorKinematics {
 public:
  // Finds the site "wrist" and joints q1..q6 of models/omni in m (throws
  // SimError naming the missing one) and allocates every buffer. `omni`
  // places the device frame (base_to_device_mm).
  EmulatorKinematics(const mjModel* m, const OmniParams& omni);

  // Fills s's transform_mm, velocity_mm_s and jacobian from d's qpos, qvel
  // and mocap poses, and sets their `present` bits. No allocation.
  void fill(const mjModel* m, const mjData* d, DeviceState* s) noexcept;

 private:
  OmniParams omni_;
  int site_ = -1;
  std::array<int, 6> dof_{};  // dof address of q1..q6
  DataPtr scratch_;
  std::vector<mjtNum> jacp_, jacr_, v_;  // 3 x nv, row-major; 3
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_EMULATOR_KINEMATICS_H_
