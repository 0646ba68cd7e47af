// What the MJCF Omni does from a recorded state under recorded motor
// torques: the prediction compare's force-direction check sets against a
// motor-test recording, and the model identification fits to recordings.
//
// Each simulate() loads the scene (the recording's own, e.g. the emulator's
// case scene, or models/omni/scene.xml for a bare device) afresh with an
// OmniModelEdit applied as it loads, as the emulator applies its seeded
// faults, before the hand adds its mass to the grip (a hypothesis, or
// identification's trial parameters: the hand's mass is not the Omni's
// and is not scaled). It puts the Omni at the
// first sample's angles and velocity, and steps it with the torques held
// from one sample to the next (a zero-order hold, as the device holds its
// last command) through the scene's SimDevice (its clamps and delay line:
// the nominal actuation). Nobody holds the stylus: the hand lets go before
// every physics step, as the emulator's HandProgram::kNone does, so its
// mass stays on the grip and its spring exerts nothing.
//
// Device convention throughout (t1..t6 rad, t3 absolute; motor torques N m
// on t1..t3; positions mm in the device frame).
#ifndef VMHAPTICS_BRINGUP_RESPONSE_SIM_H_
#define VMHAPTICS_BRINGUP_RESPONSE_SIM_H_

#include <string>
#include <vector>

#include "controller/types.h"
#include "sim/omni_model_edit.h"

namespace vmh::bringup {

struct ResponseInput {
  std::vector<double> t_s;           // sample times, increasing
  Joints q0_device_rad = Joints::Zero();     // the state at t_s[0]
  Joints qdot0_device_rad_s = Joints::Zero();
  std::vector<Vec3> tau_motor_Nm;    // sent at each sample, held until the next
};

struct SimulatedResponse {
  std::vector<double> t_s;             // as the input's
  std::vector<Joints> q_device_rad;    // true angles at each sample time
  std::vector<Vec3> p_mm;              // wrist centre (MuJoCo's site "wrist")
  bool finite = true;
};

class ResponseSimulator {
 public:
  // Loads the scene once to check it (throws sim::SimError naming it), with
  // `model_file` (a calibrated Omni, --model) applied first when not empty.
  explicit ResponseSimulator(const std::string& scene,
                             const std::string& model_file = {});
  ~ResponseSimulator();
  ResponseSimulator(const ResponseSimulator&) = delete;
  ResponseSimulator& operator=(const ResponseSimulator&) = delete;

  // Simulates input under `edit` (applied to the scene's model as loaded).
  // extra_delay_s shifts the torques later (a hypothesis of a slower
  // device); torque_scale multiplies them before the clamps.
  SimulatedResponse simulate(const ResponseInput& input,
                             const sim::OmniModelEdit& edit = {},
                             double extra_delay_s = 0.0,
                             double torque_scale = 1.0);

  double servo_period_s() const;
  const std::string& scene() const { return scene_; }

 private:
  std::string scene_;
  std::string model_file_;
  double servo_period_s_ = 1e-3;
};

// The angles' velocity at row index k of a series, from a least-squares
// line through the samples within +-half_window_s (rad/s)
Joints velocity_estimate(const std::vector<double>& t_s,
                         const std::vector<Joints>& q, std::size_t k,
                         double half_window_s);

}  // namespace vmh::bringup

#endif  // VMHAPTICS_BRINGUP_RESPONSE_SIM_H_
