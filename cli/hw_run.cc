// vmhaptics hw run [--device D] <case1..case7|scene.xml> [--duration s]
//                  [--out DIR] [--set name=value ...] [--gain-scale x]
//                  [--model FILE] [--emulator-fault LIST] [--clock C]
//
// The scene's controller on a device, through the servo chain and the
// safety layer (thesis/hw_run.h for a simulated device and its claims;
// on a real device the scene's parameters, read without MuJoCo, and the
// runtime's session; this file parses, calls and prints). DIR/trace.csv has run's columns; DIR/summary.json the session
// and, on the emulator, the same metrics and thesis claims as `run`
// (measured on the emulator's ground truth); DIR/meta.json the device. The
// three are written together. --model FILE (emulator only) replaces the
// Omni's parameters both in the emulator's scene and in the case's model.
// Exit codes as the other hw verbs, and 1 when a claim fails or, on the
// wall clock, when the session was disturbed so that no claim was judged.
// SIGINT / SIGTERM are caught from the start: before the session (the
// scene loading, the device opening) nothing is written and the exit is
// 130 / 143; during the session it stops there, and the set is written
// whole with the trace so far (as the other hw verbs); after it (the
// claims judged on the emulator's truth) the judging finishes, the set is
// written whole, and then the exit is 130 / 143.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/args.h"
#include "cli/hw.h"
#include "cli/hw_common.h"
#include "device/stop_signal.h"
#include "runtime/stop.h"
#include "runtime/meta.h"
#include "sim/cases/scene_fields.h"
#ifdef VMH_HAVE_SIM
#include "sim/cases/case_catalogue.h"
#include "thesis/hw_run.h"
#endif

namespace vmh::cli {
namespace {

struct HwRunArgs {
  HwCommon common;
  std::string target;
  double duration_s = 0.0;
  bool duration_given = false;  // else the scene's
  std::string out;
  CLI::Option* out_option = nullptr;
  std::vector<std::string> sets;
  double gain_scale = 1.0;
};

// the target's scene: a case name (with the testbed's catalogue) or a file
std::string scene_of(const std::string& target, std::string* name) {
#ifdef VMH_HAVE_SIM
  try {
    return sim::resolve_scene(target, name);
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("hw run: ") + e.what());
  }
#else
  std::error_code ec;
  if (!std::filesystem::is_regular_file(target, ec)) {
    throw UsageError("hw run: '" + target +
                     "' is not a scene file (this build has no case "
                     "catalogue: give the scene's path, e.g. "
                     "models/cases/case1.xml)");
  }
  *name = std::filesystem::path(target).stem().string();
  return target;
#endif
}

// A real device: the scene's parameters read without MuJoCo, the case's
// controller through the safety layer; no truth, so no claims.
Json run_on_device(runtime::OpenedDevice* dev, const std::string& scene,
                   const std::vector<std::string>& sets, double gain_scale,
                   runtime::SessionOptions so, runtime::SessionResult* r) {
  sim::CaseParams params;
  try {
    params = sim::load_scene_params(scene, sets);
  } catch (const sim::ParamError& e) {
    throw UsageError(std::string("hw run: ") + e.what());
  }
  ControllerParams controller = sim::case_controller_params(params);
  runtime::scale_gains(&controller, gain_scale);
  runtime::configure_controller_session(controller, &so);
  so.duration_s = params.sim.duration_s;
  *r = runtime::run_session(dev, so);
  return Json{{"thesis_case", params.thesis_case},
              {"gain_scale", gain_scale},
              {"clock", r->clock},
              {"claims", Json::array()},
              {"claims_measured_on",
               "nothing: a real device has no ground truth for the thesis's "
               "claims"}};
}

// What hw run runs, checked before anything opens: the case's name and
// scene, its overrides (--duration as duration_s's), the device's backend
// and the --model file (empty: none)
struct HwRunPlan {
  std::string name;
  std::string scene;
  std::vector<std::string> sets;
  const runtime::BackendInfo* backend = nullptr;
  std::string model_file;
};

HwRunPlan plan_hw_run(const HwRunArgs& a) {
  if (a.duration_given) {
    check_seconds("hw run: --duration", a.duration_s, 0.0, 3600.0);
  }
  if (!(a.gain_scale >= 0.0) || !std::isfinite(a.gain_scale)) {
    throw UsageError("hw run: --gain-scale must be a number >= 0");
  }
  HwRunPlan p;
  p.scene = scene_of(a.target, &p.name);
  p.sets = a.sets;
  if (a.duration_given) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", a.duration_s);
    p.sets.push_back(std::string("duration_s=") + text);
  }
  std::string argument;
  p.backend = &hw_backend(a.common, &argument);
  if (p.backend->simulated && !argument.empty()) {
    throw UsageError("hw run: the emulator plays the run's own scene; give "
                     "it as the target, not in --device (" + a.common.device +
                     ")");
  }
  const auto model = a.common.options.find("model");
  p.model_file =
      model == a.common.options.end() ? std::string() : model->second;
  if (!p.model_file.empty() && !std::filesystem::is_regular_file(p.model_file)) {
    throw UsageError("--model: no such file '" + p.model_file + "'");
  }
  return p;
}

#ifdef VMH_HAVE_SIM
// a simulated device: the case with its script and claims, loaded first
// so that a bad scene is refused before the device opens (null for a
// real device)
std::unique_ptr<thesis::HwRunCase> simulated_case(const HwRunPlan& p,
                                                  double gain_scale) {
  if (!p.backend->simulated) return nullptr;
  try {
    return std::make_unique<thesis::HwRunCase>(p.scene, p.sets, p.model_file,
                                               gain_scale);
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("hw run: ") + e.what());
  }
}

// The session judged on a simulated plant's truth: the emulator's, or
// that of a device that is not the emulator but has one behind it (the
// project's own HD library over the emulator, docs/libhd.md), whose
// claims are judged as the emulator's are. Null with no truth: nothing ran.
Json run_on_truth(std::unique_ptr<thesis::HwRunCase>* run_case,
                  const HwRunPlan& p, double gain_scale,
                  runtime::OpenedDevice* dev,
                  const runtime::SessionOptions& so,
                  runtime::SessionResult* r) {
  if (!*run_case && dev->truth != nullptr) {
    *run_case = std::make_unique<thesis::HwRunCase>(p.scene, p.sets,
                                                    p.model_file, gain_scale);
  }
  if (*run_case) return (*run_case)->run(dev, so, r);
  return Json();
}
#endif

// summary.json: the case and scene, what was measured, the model and the
// session
Json summary_json(const HwRunPlan& p, const Json& measured,
                  const runtime::SessionResult& r) {
  Json summary{{"case", p.name}, {"scene", p.scene}};
  for (auto it = measured.begin(); it != measured.end(); ++it) {
    summary[it.key()] = it.value();
  }
  summary["model"] = p.model_file.empty() ? Json(nullptr) : Json(p.model_file);
  summary["session"] = runtime::session_json(r);
  return summary;
}

// summary.json and meta.json beside the trace, the three put in place
// together
void commit_set(output::OutputSet* set, runtime::OpenedDevice* dev,
                const runtime::SessionResult& r, const HwRunPlan& p,
                const HwRunArgs& a, const Json& summary) {
  set->write("summary.json", dump_readable(summary) + "\n");
  set->write("meta.json",
             dump_readable(runtime::meta_json(
                 dev, r, "run",
                 Json{{"case", p.name}, {"scene", p.scene}, {"sets", a.sets},
                      {"gain_scale", a.gain_scale}})) +
                 "\n");
  set->commit();
}

// exit 1 when the claims were not judged (a disturbed wall-clock
// session) or one failed, naming them
void throw_if_claims_failed(const Json& summary) {
  if (summary.contains("claims_judged") && !summary["claims_judged"].get<bool>()) {
    throw std::runtime_error("hw run: claims not judged: " +
                             summary["claims_not_judged_because"].get<std::string>());
  }
  if (summary.contains("all_claims_pass") &&
      !summary["all_claims_pass"].get<bool>()) {
    std::string failed;
    for (const Json& c : summary["claims"]) {
      if (c.contains("pass") && c["pass"].is_boolean() && !c["pass"].get<bool>()) {
        failed += " " + c["name"].get<std::string>();
      }
    }
    throw std::runtime_error("hw run: thesis claim(s) not met:" + failed);
  }
}

void hw_run(const HwRunArgs& a) {
  // SIGINT / SIGTERM only set a flag (device/stop_signal.h), for the
  // whole verb; the session shares it
  StopSignals signals;
  const HwRunPlan p = plan_hw_run(a);
  const bool out_given = a.out_option != nullptr && a.out_option->count() > 0;
  auto set = hw_output_set("run", a.out, out_given);
#ifdef VMH_HAVE_SIM
  std::unique_ptr<thesis::HwRunCase> run_case = simulated_case(p, a.gain_scale);
#endif
  if (!p.backend->simulated) {
    // refuse a bad scene before the device opens
    try {
      (void)sim::load_scene_params(p.scene, p.sets);
    } catch (const sim::ParamError& e) {
      throw UsageError(std::string("hw run: ") + e.what());
    }
  }
  runtime::throw_if_stopped("hw run", "; nothing written");
  // a simulated device plays the scene itself, held by its hand script
  runtime::OpenedDevice dev = open_hw_device(
      a.common, "case", p.sets, p.backend->simulated ? p.scene : std::string());
  runtime::SessionOptions so = session_options(a.common, "run");
  trace_into(set.get(), a.out, &so);
  runtime::SessionResult r;
  Json measured;
#ifdef VMH_HAVE_SIM
  measured = run_on_truth(&run_case, p, a.gain_scale, &dev, so, &r);
#endif
  if (measured.is_null()) {
    measured = run_on_device(&dev, p.scene, p.sets, a.gain_scale, so, &r);
  }
  const Json summary = summary_json(p, measured, r);
  if (set) commit_set(set.get(), &dev, r, p, a, summary);
  std::cout << dump_readable(summary) << '\n';
  runtime::raise_if_cut_short(r, "hw run");
  // a signal after the session, while its claims were judged or its set
  // went in
  runtime::throw_if_stopped(
      "hw run", "; after its session" +
                    (set ? ": the set in " + a.out + " is whole" : std::string()));
  throw_if_claims_failed(summary);
}

}  // namespace

void register_hw_run(CLI::App* hw) {
  auto a = std::make_shared<HwRunArgs>();
  CLI::App* cmd = hw->add_subcommand(
      "run",
      "a case's controller on the device, through the servo chain and the "
      "safety layer; on the emulator, the thesis's claims checked as in `run`");
  add_hw_common(cmd, &a->common);
  cmd->add_option("target", a->target, "case1..case7, or a scene .xml")
      ->required();
  cmd->add_option_function<double>(
         "--duration",
         [a](double v) {
           a->duration_s = v;
           a->duration_given = true;
         },
         "seconds, > 0 and <= 3600 (default: the scene's duration_s)")
      ->type_name("FLOAT");
  a->out_option = cmd->add_option(
      "--out", a->out,
      "write DIR/trace.csv, DIR/summary.json, DIR/meta.json, together");
  cmd->add_option("--set", a->sets,
                  "override a case parameter, name=value; repeatable")
      ->allow_extra_args(false);
  cmd->add_option("--gain-scale", a->gain_scale,
                  "multiply every controller gain (bring-up: start low, "
                  "e.g. 0.1); default 1");
  cmd->callback([a]() { hw_run(*a); });
}

}  // namespace vmh::cli
