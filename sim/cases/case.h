// A case as data (issue 33): what a scene and its `--set` overrides say a
// run is, read once and then only read. Its parameters (sim/cases/case_params.h,
// overrides applied), its controller's parameters (validated), its hand
// script, and the timing the run will have: the physics step and
// integrator, the physics steps per servo tick, the ticks of a run.
//
// A Case holds no MuJoCo object: it is copied, kept and handed to claims,
// figures and studies without a model or data beside it. Reading one
// compiles the scene (its <custom> fields and <option> come from MuJoCo's
// reader, includes and defaults resolved), so that what a Case says and
// what a ClosedLoop over the same scene runs cannot differ: ClosedLoop
// reads its own Case through make_case() too.
//
// Everything a bad scene or override can get wrong is refused here with a
// SimError naming the file (or `--set`) and the field, before any mjData
// exists.
#ifndef VMHAPTICS_SIM_CASES_CASE_H_
#define VMHAPTICS_SIM_CASES_CASE_H_

#include <mujoco/mujoco.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "controller/controller.h"
#include "sim/cases/case_config.h"
#include "sim/hand_script.h"
#include "sim/mujoco_util.h"
#include "sim/omni_model_edit.h"

namespace vmh::sim {

// A run's physics step and counts (Case says what each is).
struct CaseTiming {
  IntegratorSetting integrator = IntegratorSetting::kEuler;
  double step_s = 0.0;
  int substeps = 1;
  bool jitter = false;
  int jitter_lo = 1, jitter_hi = 1;
  std::int64_t ticks_per_run = 0;
};

class Case {
 public:
  // the scene file, as given
  const std::string& scene_path() const { return path_; }
  // the parameters, overrides applied (summary.json's "parameters")
  const CaseConfig& config() const { return config_; }
  // the controller as the simulated device runs it (case_controller_params:
  // the gimbal's ranges opened without gimbal limits), validated
  const ControllerParams& controller_params() const { return controller_; }
  // the hand's script over the run (sim/hand_script.h)
  const HandScript& script() const { return script_; }

  // The physics the run steps with: the scene's <option timestep> and
  // integrator unless physics_step_s or integrator override them (s).
  double physics_step_s() const { return t_.step_s; }
  IntegratorSetting integrator() const { return t_.integrator; }
  // physics steps per servo tick at the nominal period
  int substeps() const { return t_.substeps; }
  // with servo jitter, the range of physics steps a tick may take (both
  // substeps() without)
  int substeps_min() const { return t_.jitter_lo; }
  int substeps_max() const { return t_.jitter_hi; }
  // servo_jitter_s is set: each tick's period is drawn from that range
  bool jitter() const { return t_.jitter; }
  // duration_s / servo_period_s, rounded: the run's ticks at the nominal
  // period
  std::int64_t ticks_per_run() const { return t_.ticks_per_run; }
  const CaseTiming& timing() const { return t_; }

  // The same case with the controller's four gains (K_p, K_ornt, K_v and
  // K_v,ornt, in the parameters and the controller alike) times `scale`:
  // a session run at scaled gains, as `hw run --gain-scale` runs one and
  // the replay of its recording must (bringup/compare_replay.cc).
  // Throws SimError naming the scene when `scale` is not finite and > 0.
  Case with_gains_scaled(double scale) const;

 private:
  friend Case make_case(const std::string& path, const mjModel& m,
                        const std::vector<std::string>& overrides);
  Case(std::string path, CaseConfig config, ControllerParams controller,
       HandScript script, const CaseTiming& timing)
      : path_(std::move(path)),
        config_(std::move(config)),
        controller_(std::move(controller)),
        script_(std::move(script)),
        t_(timing) {}

  std::string path_;
  CaseConfig config_;
  ControllerParams controller_;
  HandScript script_;
  CaseTiming t_;
};

// The case of a scene already compiled (`m`, whose file is `path`), with
// `overrides` ("name=value") on top. Throws SimError naming the file (or
// --set) and the field: an unknown or bad parameter, a controller the
// parameters make invalid, a physics step that does not divide the servo
// period, a duration outside [1, kMaxTicksPerRun] ticks, a servo jitter
// that is not whole physics steps.
Case make_case(const std::string& path, const mjModel& m,
               const std::vector<std::string>& overrides);

// The case of the scene at `path` (compiled without what is only drawn,
// `model_hook` applied first when set): for whatever needs a case's
// parameters, script or timing and runs nothing. Throws SimError as
// load_model() and make_case() do.
Case load_case(const std::string& path,
               const std::vector<std::string>& overrides,
               const ModelHook& model_hook = {});

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_CASES_CASE_H_
