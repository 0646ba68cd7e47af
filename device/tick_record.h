// One servo tick, as every servo loop of the project records it: the
// simulated closed loop (sim/closed_loop.h, `vmhaptics run`) and a session
// on a device, real or emulated (runtime/session.h, `vmhaptics hw`). One
// record type, so that one trace writer (runtime/trace_writer.h) writes the
// same columns the same way for both, and the claims read either.
//
// The record has two parts:
//   - what the servo chain saw and did (device/servo_chain.h): the reading,
//     the controller's output, the torques asked for and sent, the safety
//     layer's and the reading guard's verdicts. A real device fills only
//     this part.
//   - PlantTruth: what only a simulated plant knows (MuJoCo's true joint
//     angles, the hand, the energy put in). has_truth says whether it was
//     filled.
//
// Plain data: it crosses threads through SpscRing and Seqlock, and the
// loop fills it without allocating.
//
// Frames and units: device frame and mm unless a name says otherwise
// (`_dh` joint angles are DH, rad; `q_device` is the device convention).
// Times in s on the loop's clock: simulated time for `run` and for a
// lockstep session, CLOCK_MONOTONIC since the session's first tick for a
// wall-clock one (TraceClock says which).
#ifndef VMHAPTICS_DEVICE_TICK_RECORD_H_
#define VMHAPTICS_DEVICE_TICK_RECORD_H_

#include <cmath>

#include "controller/controller.h"
#include "controller/types.h"
#include "device/device_state.h"
#include "device/reading_guard.h"
#include "device/safety.h"
#include "device/servo_tick.h"

namespace vmh {

// A wrist-centre position and a stylus axis, device frame (mm, unit vector):
// where a hand script or a hand program puts the stylus.
struct ScriptPose {
  Vec3 p_mm = Vec3::Zero();   // wrist centre
  Vec3 axis = Vec3::UnitZ();  // stylus axis
};

// What a simulated plant knows about a tick that no sensor reports.
struct PlantTruth {
  // the motors' torque held over the tick (after the simulated device's
  // delay line and clamps), N m, t1..t3
  Vec3 motor_torque_Nm = Vec3::Zero();
  ScriptPose hand_target;             // the hand's target over the tick
  Vec3 hand_force_N = Vec3::Zero();   // the hand's force on the grip, end
  // MuJoCo's joint angles at the start of the tick (DH, rad), the wrist
  // centre they put the stylus at (omni_fk) and the VM path's point
  // nearest to it (closed form)
  Joints q_true_dh = Joints::Zero();
  Vec3 p_true_mm = Vec3::Zero();
  Vec3 nearest_true_mm = Vec3::Zero();
  int segment = 0;       // the hand script's segment (HandScript::segments)
  int substeps = 0;      // physics steps in the tick
  // passivity observer: energy put into the device since t = 0 by the
  // motors and by the hand, and the mechanism's kinetic energy, at the
  // tick's end, J (sim/closed_loop.h says how they are summed)
  double energy_motor_J = 0.0;
  double energy_hand_J = 0.0;
  double kinetic_J = 0.0;
  // qpos, qvel, qacc and ctrl all finite over the tick
  bool state_finite = true;
};

struct TickRecord : PlantTruth {
  double t_s = 0.0;       // the loop's time at the tick
  // the tick's own length: to the next tick (simulated: its physics
  // steps; a session's last tick: the nominal period)
  double period_s = 0.0;

  // the reading as it left the device layer (present = 0 if it failed)
  DeviceState state;
  // the reading in DH (rad): what the controller received, NaN when the
  // read failed. In the simulated loop, what the (possibly injected)
  // sensor said even when the guard refused it
  Joints q_dh = Joints::Constant(std::nan(""));
  // the wrist centre and stylus axis of that reading (omni_fk): with a
  // controller, the controller's (ControlOutput::p_rm_mm, axis_rm; after a
  // failed read, the last it had); without one, NaN when there is none
  Vec3 p_mm = Vec3::Constant(std::nan(""));
  Vec3 axis = Vec3::Constant(std::nan(""));

  ServoTickResult servo;  // read and write errors, controller status
  ControlOutput out;      // the controller's output (a run's chain only)
  bool has_controller = false;
  // distance from p_mm to the VM's path, mm (closed form; NaN without a
  // controller)
  double d_path_mm = std::nan("");
  // the force a reference gain set asks for at the same reading (claims
  // that compare cases); NaN when there is none
  Vec3 force_reference_N = Vec3::Constant(std::nan(""));

  Vec3 tau_cmd_Nm = Vec3::Zero();   // what the chain asked of the device
  Vec3 tau_sent_Nm = Vec3::Zero();  // what reached the device (after safety)
  SafetyStatus safety = kSafetyOk;  // the safety layer's flags (none: 0)
  double ramp_scale = 1.0;          // its force ramp (1 without it)
  Vec3 thermal = Vec3::Zero();      // its thermal state per motor
  GuardFault guard = GuardFault::kNone;  // the reading guard's verdict
  bool fault_injected = false;      // a simulated sensor fault was active

  bool has_truth = false;  // PlantTruth's fields are filled
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_TICK_RECORD_H_
