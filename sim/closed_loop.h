// The closed loop: the MuJoCo Omni, held by the simulated hand, driven by the
// same Controller and servo_tick() that run on the real device.
//
// Each servo tick (period T, the case's servo_period_s):
//   1. the hand script sets the hand's target for this tick;
//   2. servo_tick(): SimDevice reads the joints through the sensor model, the
//      Controller computes the torques, SimDevice clamps and delays them and
//      puts them in d->ctrl;
//   3. MuJoCo steps n = T / h times with d->ctrl held (zero-order hold); the
//      hand's wrench is recomputed at every step (and at every RK4 stage)
//      by the hand's own mjcb_control (sim/hand.h), installed once: plain
//      mj_step on data() gives the same physics.
// The servo tick is the one servo chain (device/servo_chain.h), the same a
// session on a device runs: [SafetyLayer (the case's `safety_layer`, off
// by default)] over ReadingGuard (the device layer's plausibility check,
// `sensor_guard`) over FaultInjector (sim/fault_injector.h: the case's
// `fault`, none by default) over SimDevice. Each tick fills one TickRecord
// (device/tick_record.h), the chain's part and the plant's truth.
//
// Servo jitter (`servo_jitter_s`): each tick's true period is drawn from
// [min, max] in whole physics steps, and the torque is held over it; the
// controller is still told T, as a servo loop that does not time itself
// would be, so its e_dot is off by the ratio of the periods.
//
// The physics is a Plant (sim/plant.h): MuJoCo's model and data, stepped n
// times per tick, with the passivity observer's energies, MuJoCo's warnings
// and the first bad state. The case (sim/cases/case.h) is the immutable part:
// parameters, script, path. ClosedLoop is the servo chain over the plant.
// Each loop's hand is registered for its own mjData, so loops in different
// threads do not disturb each other.
#ifndef VMHAPTICS_SIM_CLOSED_LOOP_H_
#define VMHAPTICS_SIM_CLOSED_LOOP_H_

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "controller/controller.h"
#include "device/reading_guard.h"
#include "device/servo_chain.h"
#include "device/tick_record.h"
#include "sim/cases/case.h"
#include "sim/cases/case_config.h"
#include "sim/fault_injector.h"
#include "sim/omni_model_edit.h"
#include "sim/plant.h"
#include "sim/hand.h"
#include "sim/hand_script.h"
#include "sim/mujoco_util.h"
#include "sim/sim_device.h"

namespace vmh::sim {

// The scene at `path` compiled, `model_hook` applied (if set): what the
// second ClosedLoop constructor copies. `headless`: without what is only
// drawn (load_model_headless), for runs that render nothing. Throws
// SimError as load_model does.
ModelPtr load_scene_model(const std::string& path,
                          const ModelHook& model_hook = {},
                          bool headless = false);

class ClosedLoop {
 public:
  // Loads the scene, reads its parameters (with `overrides`), builds the
  // hand, device, controller and script, and puts the Omni at the script's
  // start pose. Throws SimError naming the file and field on bad input.
  // `model_hook` (when set) changes the model right after it is loaded,
  // before anything reads it: `--model FILE` and the emulator's seeded
  // parameter faults (sim/omni_model_edit.h).
  ClosedLoop(const std::string& scene_path,
             const std::vector<std::string>& overrides,
             const ModelHook& model_hook = {});
  // The same from a scene already compiled (load_scene_model()), which the
  // loop copies: the runs of one case on its several sides compile the
  // scene once. `scene_path` names the scene in messages.
  ClosedLoop(const std::string& scene_path, const mjModel& compiled,
             const std::vector<std::string>& overrides);
  // The loop of a case already read (sim/cases/case.h), its scene compiled again
  // from the case's file (`model_hook` applied when set): a run of a case
  // changed after it was read (Case::with_gains_scaled).
  explicit ClosedLoop(const Case& c, const ModelHook& model_hook = {});
  ~ClosedLoop();
  ClosedLoop(const ClosedLoop&) = delete;
  ClosedLoop& operator=(const ClosedLoop&) = delete;

  // Back to t = 0 at the start pose, at rest, controller and delay line
  // cleared.
  void reset();

  // Advances one servo period and describes it in *row (every field: the
  // chain's and the truth, has_truth set; period_s is this tick's own
  // length, n physics steps). Past duration_s
  // (a run continued beyond its script) the hand holds the script's last
  // target, at rest. After every physics step it reads mjData::warning[]
  // (counted per kind, mujoco_warning_counts()) and checks the state; the
  // first bad state is kept as physics_fault() and that tick's
  // row->state_finite is false. tick() itself goes on (a study may want to
  // see what follows): a run that must stop calls throw_if_physics_fault()
  // after each tick.
  void tick(TickRecord* row);

  // the first bad physics state since reset(), if any
  const std::optional<PhysicsFault>& physics_fault() const {
    return plant_.physics_fault();
  }
  // throws PhysicsError(physics_fault()->message()) if there is one
  void throw_if_physics_fault() const { plant_.throw_if_physics_fault(); }
  // MuJoCo's per-step warnings since reset(), by mjtWarning: every count
  // mjData::warning[] reached, summed over its resets
  const std::array<std::int64_t, mjNWARNING>& mujoco_warning_counts() const {
    return plant_.warning_counts();
  }

  // Another gain set evaluated on every reading, without acting
  // (TickRecord::force_reference_N).
  void set_reference(const ControllerParams& params);

  // the physics' time since reset(): ticks (or, jittered, physics steps)
  // times their period
  double time_s() const;
  // The script's clock: time_s() plus what skip_script_to() skipped (equal
  // to time_s() until then). The hand's target, TickRecord::t_s and
  // ::segment, the fault schedule and finished() read it.
  double script_time_s() const { return time_s() + script_skipped_s_; }
  // Moves the script's clock forward to t_s (no earlier than
  // script_time_s(), no later than duration_s), the physics' state as it
  // is: what a run does once the plant has settled in a hold whose target
  // stands still, to spare simulating the rest of the hold
  // (thesis/side_runs.h). Throws std::invalid_argument out of that range.
  void skip_script_to(double t_s);
  // the run's length in ticks at the nominal period; with servo jitter the
  // count differs, so loop until finished()
  std::int64_t ticks_per_run() const { return case_.ticks_per_run(); }
  // whether script_time_s() has reached duration_s
  bool finished() const;
  // physics steps per tick at the nominal period
  int substeps() const { return case_.substeps(); }
  // the range of physics steps per tick (both substeps() without jitter)
  int substeps_min() const { return case_.substeps_min(); }
  int substeps_max() const { return case_.substeps_max(); }
  bool jitter() const { return case_.jitter(); }
  // the passivity observer's totals so far, J (see the file comment)
  double energy_motor_J() const { return plant_.energy_motor_J(); }
  double energy_hand_J() const { return plant_.energy_hand_J(); }
  // the case this loop runs (sim/cases/case.h): parameters, controller, script
  // and timing, read once from the scene
  const Case& the_case() const { return case_; }
  const CaseConfig& config() const { return case_.config(); }
  const ControllerParams& controller_params() const {
    return case_.controller_params();
  }
  const HandScript& script() const { return case_.script(); }
  const Controller& controller() const { return *chain_->controller(); }
  const mjModel* model() const { return plant_.model(); }
  mjData* data() { return plant_.data(); }
  // the physics (model, data, energies, warnings)
  Plant& plant() { return plant_; }
  const Plant& plant() const { return plant_; }
  SimDevice& device() { return *device_; }
  FaultInjector& injector() { return *injector_; }
  ReadingGuard& guard() { return chain_->guard(); }
  // the servo chain (its safety layer, when the case has one)
  ServoChain& chain() { return *chain_; }
  SimHand& hand() { return *hand_; }
  const SimHand& hand() const { return *hand_; }
  // Sets the hand's target (and its velocity) for simulated time t_s from
  // the script, as tick() does before it steps: what a caller that steps
  // data() itself (a viewer, a test) does to play the script.
  void set_hand_target(double t_s);

  // Manual hand (a viewer's mouse in the script's place): while on, tick()
  // holds the manual target instead of the script's (the hand's impedance
  // still acts at every physics step), and TickRecord::hand_target is the
  // wrist pose that target asks for. Turning it on starts from the target
  // the hand holds now, so nothing jumps; reset() keeps the mode and puts
  // the manual target back at the script's start. Off by default: the
  // script plays as before.
  void set_manual_hand(bool on);
  bool manual_hand() const { return manual_hand_; }
  // the grip's target (world = DH base frame, SI), used from the next tick
  void set_manual_target(const HandTargetState& target);
  const HandTargetState& manual_target() const { return manual_target_; }

  // distance (mm) from a device-frame point to the VM's path: the circle,
  // the sphere or the plane, in closed form (VirtualMechanism::
  // distance_to_path)
  double distance_to_path_mm(const Vec3& p_mm) const;
  // the point of the VM's path nearest a device-frame point, closed form
  // (for the surface: the point L above the plane over it)
  Vec3 nearest_on_path_mm(const Vec3& p_mm) const;

 private:
  // construction, in order, once the case is read (make_case: parameters,
  // controller, script, timing): the case's physics step and integrator
  // put in the model; the gimbal limits and motor ranges it asks for; the
  // device chain SimDevice <- FaultInjector <- ServoChain (guard, safety,
  // controller); the start pose (sets R_start_base_, returns the joint
  // angles)
  void init();  // both constructors' work once model_ and case_ are set
  void apply_model_options();
  void build_controller();
  void build_device_chain();
  Joints start_pose();

  // the next tick's physics steps (drawn when jittered)
  int draw_substeps();
  // the wrist pose (device frame) a grip target asks for
  ScriptPose wrist_pose_of(const HandTargetState& grip) const;
  // set_hand_target(t_s); returns the script's pose at min(t_s, duration_s)
  ScriptPose script_target(double t_s);
  // turn_to_axis(R_start_base_, axis_base), remembered for the last two
  // axes (compared bit for bit)
  const Mat3& stylus_turned_to(const Vec3& axis_base);

  std::string path_;
  Plant plant_;  // before case_, which reads its model
  Case case_;
  std::unique_ptr<SimHand> hand_;
  std::unique_ptr<SimDevice> device_;
  std::unique_ptr<FaultInjector> injector_;
  std::unique_ptr<ServoChain> chain_;
  Joints q_start_dh_ = Joints::Zero();
  Mat3 R_start_base_ = Mat3::Identity();  // stylus frame at the start pose
  // the grip site in the stylus body: offset (m) and rotation
  Vec3 grip_local_ = Vec3::Zero();
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R_site_ =
      Eigen::Matrix<double, 3, 3, Eigen::RowMajor>::Identity();
  struct TurnMemo {
    bool valid = false;
    Vec3 axis_base = Vec3::Zero();
    Mat3 R = Mat3::Identity();
  };
  std::array<TurnMemo, 2> turn_memo_{};
  int turn_memo_next_ = 0;
  std::int64_t tick_count_ = 0;
  double script_skipped_s_ = 0.0;  // skip_script_to()'s total
  // servo jitter: the generator's state (steps per tick drawn from the
  // case's [substeps_min, substeps_max])
  std::uint64_t rng_state_ = 1;
  std::int64_t substep_count_ = 0;  // physics steps since t = 0
  bool manual_hand_ = false;
  HandTargetState manual_target_;
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_CLOSED_LOOP_H_
