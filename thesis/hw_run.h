// `vmhaptics hw run`: a thesis case's controller on a device, through the
// runtime's session (runtime/session.h: the servo chain behind the safety
// layer), and on a simulated device the case's metrics and claims measured
// on the plant's truth, as `run` measures them (thesis/run_case.h).
//
// On the emulator in lockstep the session is the simulated closed loop
// behind the safety layer, tick for tick: `run CASE --set safety_layer=1`
// and `hw run CASE --device emulator` differ only by the emulator's sensor
// path (raw counts and pot codes decoded back to angles, within 1e-15 rad
// of the sensor model's), so their claims agree (docs/hardware.md, "Two
// clocks", gives the measured bound; tests/thesis/hw_run_test.cc checks
// it). On the wall clock the claims are judged only when the session kept
// real time (no overrun, no read timeout, no record dropped, no emulator
// stall); otherwise they are reported as not judged, never as failed or
// passed on a run the host disturbed.
#ifndef VMHAPTICS_THESIS_HW_RUN_H_
#define VMHAPTICS_THESIS_HW_RUN_H_

#include <memory>
#include <string>
#include <vector>

#include "runtime/backend_registry.h"
#include "runtime/json_util.h"
#include "runtime/session.h"
#include "sim/closed_loop.h"

namespace vmh::thesis {

// The case as `hw run` plays it on a simulated device: its scene's
// parameters, script and claims' settings (the scene loaded once), and the
// controller scaled for bring-up. (On a real device `hw run` needs only
// the parameters: sim/cases/scene_fields.h and runtime's
// configure_controller_session.)
class HwRunCase {
 public:
  // Throws SimError naming the scene and field. `model_file` (may be
  // empty): a calibrated Omni MJCF (sim::omni_model_hook). `sets` are the
  // scene's --set overrides.
  HwRunCase(const std::string& scene, const std::vector<std::string>& sets,
            const std::string& model_file, double gain_scale);

  // the session options' chain, period and duration for this case
  void configure(runtime::SessionOptions* so) const;
  // Runs the session on `dev` (which must play this scene if simulated)
  // and returns summary.json's content. Throws what run_session throws.
  Json run(runtime::OpenedDevice* dev, runtime::SessionOptions so,
           runtime::SessionResult* result) const;

  int thesis_case() const { return thesis_case_; }
  double duration_s() const { return duration_s_; }
  const ControllerParams& params() const { return params_; }

 private:
  // the case: parameters, script, the claims' geometry
  std::unique_ptr<sim::ClosedLoop> loop_;
  ControllerParams params_;
  int thesis_case_ = 0;
  double duration_s_ = 0.0;
  double gain_scale_;
};

// Why a wall-clock session's claims cannot be trusted ("" when they can):
// overruns, read timeouts, dropped records, an emulator stall.
std::string realtime_disturbance(const runtime::SessionResult& r);

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_HW_RUN_H_
