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
//      from mjcb_control.
// The hand's callback is found through a thread-local pointer, so loops in
// different threads do not disturb each other.
#ifndef VMHAPTICS_SIM_CLOSED_LOOP_H_
#define VMHAPTICS_SIM_CLOSED_LOOP_H_

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "controller/controller.h"
#include "controller/haptic_device.h"
#include "sim/case_config.h"
#include "sim/hand.h"
#include "sim/hand_script.h"
#include "sim/mujoco_util.h"
#include "sim/sim_device.h"

namespace vmh::sim {

// One servo tick of a run. Device frame and mm unless named.
struct TraceRow {
  double t_s = 0.0;
  Joints q_dh = Joints::Zero();   // as the controller received them (rad)
  ControlOutput out;              // the controller's output for this tick
  ServoTickResult servo;
  Vec3 motor_torque_Nm = Vec3::Zero();  // held by the motors (after delay)
  ScriptPose hand_target;         // wrist-centre target and stylus axis
  Vec3 hand_force_N = Vec3::Zero();  // the hand's force on the grip, device frame
  double d_path_mm = 0.0;         // RM wrist centre to the VM's path (closed form)
  // ground truth, independent of the sensor and the placement: the true
  // wrist centre (omni_fk of the model's joint angles) and the nearest point
  // of the path to it, in closed form
  Vec3 p_true_mm = Vec3::Zero();
  Vec3 nearest_true_mm = Vec3::Zero();
  int segment = 0;                // index into HandScript::segments()
  // the force a reference gain set would have asked for at the same reading
  // (for claims that compare cases); NaN when there is none
  Vec3 force_reference_N = Vec3::Constant(std::nan(""));
};

class ClosedLoop {
 public:
  // Loads the scene, reads its parameters (with `overrides`), builds the
  // hand, device, controller and script, and puts the Omni at the script's
  // start pose. Throws SimError naming the file and field on bad input.
  ClosedLoop(const std::string& scene_path,
             const std::vector<std::string>& overrides);
  ~ClosedLoop();
  ClosedLoop(const ClosedLoop&) = delete;
  ClosedLoop& operator=(const ClosedLoop&) = delete;

  // Back to t = 0 at the start pose, at rest, controller and delay line
  // cleared.
  void reset();

  // Advances one servo period and describes it in *row.
  void tick(TraceRow* row);

  // Another gain set evaluated on every reading, without acting
  // (TraceRow::force_reference_N).
  void set_reference(const ControllerParams& params);

  double time_s() const;
  int ticks_per_run() const { return ticks_per_run_; }
  int substeps() const { return substeps_; }
  const CaseConfig& config() const { return config_; }
  const ControllerParams& controller_params() const { return params_; }
  const HandScript& script() const { return *script_; }
  const Controller& controller() const { return *controller_; }
  const mjModel* model() const { return model_.get(); }
  mjData* data() { return data_.get(); }
  SimDevice& device() { return *device_; }
  SimHand& hand() { return *hand_; }

  // distance (mm) from a device-frame point to the VM's path: the circle,
  // the sphere or the plane, in closed form
  double distance_to_path_mm(const Vec3& p_mm) const;
  // the point of the VM's path nearest a device-frame point, closed form
  // (for the surface: the point L above the plane over it)
  Vec3 nearest_on_path_mm(const Vec3& p_mm) const;

  // called from mjcb_control for this loop's data
  void on_control(const mjModel* m, mjData* d);

 private:
  void set_hand_target(double t_s);

  std::string path_;
  ModelPtr model_;
  DataPtr data_;
  CaseConfig config_;
  ControllerParams params_;
  std::unique_ptr<SimHand> hand_;
  std::unique_ptr<SimDevice> device_;
  std::unique_ptr<Controller> controller_;
  std::unique_ptr<Controller> reference_;
  std::unique_ptr<HandScript> script_;
  ControlOutput reference_out_;
  Joints q_start_dh_ = Joints::Zero();
  Mat3 R_start_base_ = Mat3::Identity();  // stylus frame at the start pose
  int substeps_ = 1;
  int ticks_per_run_ = 0;
  long tick_count_ = 0;
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_CLOSED_LOOP_H_
