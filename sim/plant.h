// The plant: a scene's MuJoCo model and data, advanced a number of physics
// steps at a time, and what the steps tell. It knows nothing of the
// controller, the hand's script or the servo clock: ClosedLoop
// (sim/closed_loop.h) runs the servo chain over it.
//
// What a Plant keeps while it steps:
// - the passivity observer (Hannaford & Ryu 2002, IEEE TRA 18(1)): the
//   energy the motors put in, E = sum over steps of qfrc_actuator .
//   (q_after - q_before), with the torque held over the step and q the true
//   joint angles. The motor torque is constant over a step (ZOH, fixed
//   tendons), so this is the exact work along the integrated motion for any
//   integrator. The hand's work is summed the same way from qfrc_applied
//   (exact for Euler; for RK4 the last stage's wrench);
// - MuJoCo's warnings, counted across the resets a bad state makes
//   MuJoCo do;
// - the first step after which the state went bad (PhysicsFault).
//
// Units: SI, as MuJoCo's (J, s); times are the caller's clock (the loop's),
// passed in, since the servo's clock may run apart from MuJoCo's.
#ifndef VMHAPTICS_SIM_PLANT_H_
#define VMHAPTICS_SIM_PLANT_H_

#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/mujoco_util.h"

namespace vmh::sim {

// Where MuJoCo's state went bad: the first physics step after which
// mjData::warning[] counted a bad qpos, qvel, qacc or ctrl (NaN, inf or
// beyond 1e10: MuJoCo then resets the state and carries on), or qpos or
// qvel was not finite.
struct PhysicsFault {
  double t_s = 0.0;   // the loop's time at the end of that step
  std::string part;   // qpos, qvel, qacc or ctrl
  int index = -1;     // the DOF (ctrl: the actuator) MuJoCo named; -1: none
  // "physics went non-finite at t=0.002 s (qacc, DOF 3)"
  std::string message() const;
};

// A run stopped by a PhysicsFault: a failure of the run (exit 1), not bad
// input.
class PhysicsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Plant {
 public:
  // Takes the compiled model; `path` names the scene in messages. The data
  // is made by make_data(), once the caller has set the model's options.
  Plant(ModelPtr model, std::string path);
  // mjData for the model as it now is (throws SimError if MuJoCo cannot)
  void make_data();

  // mj_resetData, and the energies, warning counts and fault cleared
  void reset();

  // n physics steps of the model's timestep with d->ctrl held. t_s is the
  // caller's time at the start, for the fault's time. Returns whether every
  // step stayed finite (MuJoCo resets a bad state, so the state after the
  // steps may look fine when one was not).
  bool step(int n, double t_s);

  // the kinetic energy of the present state (J)
  double kinetic_J();
  // qpos, qvel, qacc and ctrl all finite now
  bool state_finite() const;

  double energy_motor_J() const { return energy_motor_J_; }
  double energy_hand_J() const { return energy_hand_J_; }
  const std::optional<PhysicsFault>& physics_fault() const {
    return physics_fault_;
  }
  // throws PhysicsError (naming the scene) if the state went bad
  void throw_if_physics_fault() const;
  // MuJoCo's warnings over the run, by mjtWarning, across its resets
  const std::array<std::int64_t, mjNWARNING>& warning_counts() const {
    return warning_counts_;
  }

  const mjModel* model() const { return model_.get(); }
  mjModel* mutable_model() { return model_.get(); }
  mjData* data() { return data_.get(); }
  const mjData* data() const { return data_.get(); }
  const std::string& path() const { return path_; }

 private:
  // after one mj_step: counts the warnings it added and notes the first
  // bad state; true if this step went bad
  bool check_step(double t_s, double time_before);

  std::string path_;
  ModelPtr model_;
  DataPtr data_;
  double energy_motor_J_ = 0.0;
  double energy_hand_J_ = 0.0;
  std::vector<mjtNum> qpos_before_, dq_, mv_;
  std::array<std::int64_t, mjNWARNING> warning_counts_{};
  std::array<int, mjNWARNING> warning_seen_{};  // d->warning[].number
  std::optional<PhysicsFault> physics_fault_;
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_PLANT_H_
