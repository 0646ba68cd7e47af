// What the emulator's three sources share, not part of its public
// interface: the physics thread's own state (Emulator::PhysicsState). The
// setup and lifecycle (emulator.cc) make and reset it, the physics
// (emulator_physics.cc: the real-time thread, lockstep's advance, one servo
// period with its faults and the device watchdog) steps it, and the
// readings (emulator_readings.cc: the snapshot with its raw sensors, the
// truth, the reads and writes) publish it. sim/emulator.h says what each
// does.
#ifndef VMHAPTICS_SIM_EMULATOR_DETAIL_H_
#define VMHAPTICS_SIM_EMULATOR_DETAIL_H_

#include <mujoco/mujoco.h>

#include <array>
#include <cstdint>
#include <vector>

#include "sim/closed_loop.h"
#include "sim/emulator.h"
#include "sim/emulator_hand.h"
#include "sim/emulator_kinematics.h"
#include "sim/sensor_model.h"

namespace vmh::sim {

struct Emulator::PhysicsState {
  explicit PhysicsState(ClosedLoop* loop)
      : hand(loop),
        sensor(loop->controller_params().omni, true),
        kinematics(loop->model(), loop->controller_params().omni) {
    const mjModel* m = loop->model();
    qpos_before.assign(static_cast<std::size_t>(m->nq), 0.0);
    dq.assign(static_cast<std::size_t>(m->nv), 0.0);
    mv.assign(static_cast<std::size_t>(m->nv), 0.0);
  }
  EmulatorHand hand;
  SensorModel sensor;  // always quantising (see sim/emulator.h)
  EmulatorKinematics kinematics;
  std::vector<mjtNum> qpos_before, dq, mv;
  // past readings, for a late fault
  std::array<Published, kMaxLatePeriods + 1> ring{};
  long periods = 0;
  long lag = 0;
  double t_sim_s = 0.0;
  double energy_motor_J = 0.0;
  double energy_hand_J = 0.0;
  std::array<bool, kMaxFaults> taken{};
  double late_until_s = -1.0;
  int late_count = 0;
  double unplug_until_s = -1.0;
  std::uint64_t replug_writes = 0;  // writes before the last replug
  bool watchdog_fired = false;
  bool invalid_command = false;
  bool stalled = false;
  bool manual_held = false;
  ScriptPose target;
  int segment = 0;
  HandProgram program = HandProgram::kTour;
  Joints q_start_dh = Joints::Zero();  // the true angles at the period's start
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_EMULATOR_DETAIL_H_
