// vmhaptics hw run [--device D] <case1..case6|scene.xml> [--duration s]
//                  [--out DIR] [--set name=value ...] [--gain-scale x]
//                  [--model FILE] [--emulator-fault LIST]
//
// The scene's controller on a device, through the same servo_tick as `run`
// and the safety layer. DIR/trace.csv has run's columns for the same
// quantities plus the device's and the safety layer's; DIR/summary.json the
// session and, on the emulator, the same metrics and thesis claims as
// `run` (measured on the emulator's ground truth); DIR/meta.json the device.
// --model FILE (emulator only) replaces the Omni's parameters both in the
// emulator's scene and in the run's own model, which the claims measure on.
// Exit codes as the other hw verbs, and 1 when a claim fails.
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/args.h"
#include "cli/hw.h"
#include "cli/hw_common.h"
#include "controller/device_frame.h"
#include "report/output_file.h"
#include "sim/closed_loop.h"
#include "studies/claims.h"
#include "studies/run_case.h"

namespace vmh::cli {
namespace {

struct HwRunOptions {
  HwCommon common;
  std::string target;
  double duration_s = 0.0;
  bool duration_given = false;  // else the scene's
  std::string out;
  std::vector<std::string> sets;
  double gain_scale = 1.0;
};

// A tick of the session as the claims read it: the reading and the
// controller's output from the servo loop, everything else from the
// emulator's ground truth at that tick.
sim::TraceRow trace_row(const HwSample& h) {
  sim::TraceRow r;
  const sim::EmulatorTruth& t = h.truth;
  r.t_s = t.t_sim_s;
  r.q_dh = h.state.has(kStateJoints)
               ? device_to_dh_joints(h.state.q_device_rad)
               : Joints::Constant(std::nan(""));
  r.out = h.out;
  r.servo = h.servo;
  r.motor_torque_Nm = t.motor_torque_Nm;
  r.hand_target = t.hand_target;
  r.hand_force_N = t.hand_force_N;
  r.d_path_mm = t.d_path_mm;
  r.p_true_mm = t.p_true_mm;
  r.nearest_true_mm = t.nearest_true_mm;
  r.segment = t.segment;
  r.force_reference_N = h.force_reference_N;
  r.q_true_dh = t.q_true_dh;
  r.period_s = h.period_s;
  r.energy_motor_J = t.energy_motor_J;
  r.energy_hand_J = t.energy_hand_J;
  r.kinetic_J = t.kinetic_J;
  r.state_finite = t.state_finite;
  return r;
}

void hw_run(const HwRunOptions& o) {
  if (o.duration_given) {
    check_seconds("hw run: --duration", o.duration_s, 0.0, 3600.0);
  }
  if (!(o.gain_scale >= 0.0) || !std::isfinite(o.gain_scale)) {
    throw UsageError("hw run: --gain-scale must be a number >= 0");
  }
  std::string name;
  std::string scene;
  try {
    scene = studies::resolve_scene(o.target, &name);
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("hw run: ") + e.what());
  }
  std::vector<std::string> sets = o.sets;
  if (o.duration_given) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", o.duration_s);
    sets.push_back(std::string("duration_s=") + text);
  }
  // the scene's parameters, its script and the claims' geometry
  std::unique_ptr<sim::ClosedLoop> model;
  if (!o.common.model.empty() && !std::filesystem::is_regular_file(o.common.model)) {
    throw UsageError("--model: no such file '" + o.common.model + "'");
  }
  if (!o.common.model.empty() && parse_device_spec(o.common.device).backend != "emulator") {
    throw UsageError("--model: only the emulator simulates a model, not --device " +
                     o.common.device);
  }
  try {
    model = std::make_unique<sim::ClosedLoop>(scene, sets,
                                              sim::omni_model_hook(o.common.model));
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("hw run: ") + e.what());
  }
  ControllerParams params = model->controller_params();
  params.gains.k_pos_N_per_mm *= o.gain_scale;
  params.gains.k_ornt_Nmm_per_rad *= o.gain_scale;
  params.gains.k_vel_Ns_per_mm *= o.gain_scale;
  params.gains.k_vel_ornt_Nmms_per_rad *= o.gain_scale;
  const int thesis_case = model->config().thesis_case;

  // the emulator plays the scene itself, held by the scene's hand script
  HwCommon common = o.common;
  const DeviceSpec spec = parse_device_spec(common.device);
  if (spec.backend == "emulator") {
    if (!spec.argument.empty()) {
      throw UsageError("hw run: the emulator plays the run's own scene; give "
                       "it as the target, not in --device (" + common.device +
                       ")");
    }
    DeviceSpec with_scene = spec;  // emulator or emulator:firewire
    with_scene.argument = scene;
    common.device = with_scene.text();
  }
  const double duration_s = model->config().sim.duration_s;
  if (spec.backend != "emulator") {
    // no ground truth to measure claims on: the scene's model is not needed
    // beyond its parameters, and it lets go of MuJoCo's control callback
    model.reset();
  }
  OpenedDevice dev = open_hw_device(common, "case", sets);

  SessionOptions so = session_options(o.common, "run");
  so.mode = HwMode::kRun;
  so.duration_s = duration_s;
  so.out_dir = o.out;
  so.controller = params;
  so.reference = studies::reference_params(thesis_case, params);
  so.keep_samples = dev.emulator != nullptr;
  so.servo.period_s = params.servo_period_s;
  so.safety.servo_period_s = params.servo_period_s;
  // the case's torque limits (torque_limits) bound the safety layer too
  so.safety.motor_torque_limit_Nm = params.omni.motor_torque_limit_Nm;
  so.guard.max_period_s = 4.0 * params.servo_period_s;
  const SessionResult r = run_session(&dev, so);

  Json summary{{"case", name},
               {"scene", scene},
               {"thesis_case", thesis_case},
               {"gain_scale", o.gain_scale},
               {"model", dev.model_file.empty() ? Json(nullptr) : Json(dev.model_file)},
               {"session", session_json(r)}};
  bool claims_pass = true;
  std::string failed;
  if (dev.emulator != nullptr && model && !r.samples.empty()) {
    std::vector<sim::TraceRow> rows;
    rows.reserve(r.samples.size());
    for (const HwSample& h : r.samples) rows.push_back(trace_row(h));
    const studies::RunMetrics m = studies::run_metrics(rows, *model);
    const auto claims = studies::evaluate_claims(thesis_case, rows, *model);
    Json cj = Json::array();
    for (const studies::Claim& c : claims) {
      cj.push_back(Json::parse(studies::claim_json(c).dump()));
      claims_pass &= c.pass;
      if (!c.pass) failed += " " + c.name;
    }
    summary["metrics"] = Json::parse(studies::metrics_json(m).dump());
    summary["claims"] = cj;
    summary["all_claims_pass"] = claims_pass;
    summary["claims_measured_on"] = "the emulator's ground truth";
  } else {
    summary["claims"] = Json::array();
    summary["claims_measured_on"] =
        "nothing: a real device has no ground truth for the thesis's claims";
  }
  if (!o.out.empty()) {
    report::write_file_in(o.out, "summary.json", dump_readable(summary) + "\n");
  }
  write_meta(o.out, meta_json(dev, r, "run",
                              Json{{"case", name}, {"scene", scene}, {"sets", o.sets},
                                   {"gain_scale", o.gain_scale}}));
  std::cout << dump_readable(summary) << '\n';
  raise_if_cut_short(r, "run");
  if (!claims_pass) {
    throw std::runtime_error("hw run: thesis claim(s) not met:" + failed);
  }
}

}  // namespace

void register_hw_run(CLI::App* hw) {
  auto o = std::make_shared<HwRunOptions>();
  CLI::App* cmd = hw->add_subcommand(
      "run",
      "a case's controller on the device, through servo_tick and the safety "
      "layer; on the emulator, the thesis's claims checked as in `run`");
  add_hw_common(cmd, &o->common);
  cmd->add_option("target", o->target, "case1..case6, or a scene .xml")
      ->required();
  cmd->add_option_function<double>(
         "--duration",
         [o](double v) {
           o->duration_s = v;
           o->duration_given = true;
         },
         "seconds, > 0 and <= 3600 (default: the scene's duration_s)")
      ->type_name("FLOAT");
  cmd->add_option("--out", o->out,
                  "write DIR/trace.csv, DIR/summary.json, DIR/meta.json");
  cmd->add_option("--set", o->sets,
                  "override a case parameter, name=value; repeatable")
      ->allow_extra_args(false);
  cmd->add_option("--gain-scale", o->gain_scale,
                  "multiply every controller gain (bring-up: start low, "
                  "e.g. 0.1); default 1");
  cmd->callback([o]() { hw_run(*o); });
}

}  // namespace vmh::cli
