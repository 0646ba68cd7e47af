// vmhaptics study precision [--case N] [--duration S] [--steps h1,h2,...]
//                           [--integrators euler,implicit,rk4]
//                           [--reference-step S] [--reference-check-step S]
//                           [--set name=value ...] [--out DIR]
//                           [--modelling-spread sensitivity.json]
//
// Error of the stylus's trajectory against wall time, per MuJoCo integrator
// and physics step (studies/precision_study.h). Prints one JSON object; with
// --out writes DIR/precision.csv, DIR/precision.svg (error vs wall time) and
// DIR/precision_order.svg (error vs h). Exit 2 on bad usage, naming the
// option; nothing is written then. SIGINT / SIGTERM exit 130 / 143, --out
// as it was (or its files all written if the signal came as they went
// in). With --modelling-spread, the sensitivity
// study's spread of the RMS path error for the same case is drawn across
// precision.svg and compared with the default setting's error in the JSON.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli/args.h"
#include "runtime/json_util.h"
#include "cli/study.h"
#include "cli/study_files.h"
#include "device/stop_signal.h"
#include "output/progress.h"
#include "sim/cases/case.h"
#include "sim/mujoco_util.h"
#include "studies/precision_study.h"

namespace vmh::cli {
namespace {

struct PrecisionCli {
  std::string case_name = "1";
  double duration_s = studies::PrecisionOptions{}.duration_s;
  std::string steps;        // empty: the default ladder
  std::string integrators;  // empty: all three
  double reference_step_s = studies::PrecisionOptions{}.reference_step_s;
  double reference_check_step_s = studies::PrecisionOptions{}.reference_check_step_s;
  std::vector<std::string> sets;
  std::string out;
  std::string modelling_spread;  // a sensitivity.json (or its folder)
};

std::string g(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

// the check ClosedLoop's loader makes (sim/closed_loop.cc)
bool divides(double step_s, double period_s) {
  const double n = std::round(period_s / step_s);
  return n >= 1.0 && std::abs(n * step_s - period_s) <= 1e-9 * period_s;
}

// "euler,rk4" as integrators; UsageError naming --integrators otherwise
std::vector<studies::Integrator> parse_integrators(const std::string& text) {
  std::vector<studies::Integrator> out;
  std::string::size_type start = 0;
  while (true) {
    const auto comma = text.find(',', start);
    const std::string item = text.substr(start, comma - start);
    studies::Integrator i;
    if (!studies::parse_integrator(item, &i)) {
      throw UsageError("--integrators: unknown integrator '" + item +
                       "' (euler, implicit or rk4)");
    }
    out.push_back(i);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// The options as the study takes them, each checked on its own.
studies::PrecisionOptions to_options(const PrecisionCli& o) {
  studies::PrecisionOptions p;
  p.scene = study_scene("--case", o.case_name, &p.name);
  if (!(o.duration_s > 0.0)) {
    throw UsageError("--duration: must be > 0 (s), got " + g(o.duration_s));
  }
  p.duration_s = o.duration_s;
  if (!o.steps.empty()) {
    p.steps_s = parse_number_list("--steps", o.steps);
    for (double h : p.steps_s) {
      if (!(h > 0.0)) throw UsageError("--steps: every step must be > 0 (s)");
    }
  }
  if (!o.integrators.empty()) p.integrators = parse_integrators(o.integrators);
  p.reference_step_s = o.reference_step_s;
  p.reference_check_step_s = o.reference_check_step_s;
  for (const std::string& set : o.sets) {
    const std::string field = set.substr(0, set.find('='));
    if (field == "quantize" || field == "integrator" || field == "physics_step_s") {
      throw UsageError("--set " + field + ": the study sets it for every run "
                       "(quantize=0; --integrators, --steps)");
    }
  }
  p.overrides = o.sets;
  p.out_dir = o.out;
  if (!o.modelling_spread.empty()) {
    try {
      p.modelling_spread = studies::read_modelling_spread(o.modelling_spread, p.name);
    } catch (const sim::SimError& e) {
      throw UsageError(std::string("--modelling-spread: ") + e.what());
    }
  }
  return p;
}

// The options against the case: its servo period and script length (the
// study checks them too, but here the error names the option).
void check_against_case(const studies::PrecisionOptions& p) {
  double period_s = 0.0, script_s = 0.0;
  try {
    const sim::Case probe = sim::load_case(p.scene, p.overrides);
    period_s = probe.controller_params().servo_period_s;
    script_s = probe.config().sim.duration_s;
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("study precision: ") + e.what());
  }
  if (p.duration_s > script_s) {
    throw UsageError("--duration: " + g(p.duration_s) +
                     " s is beyond the case's script (duration_s = " +
                     g(script_s) + " s)");
  }
  for (double h : p.steps_s) {
    if (!divides(h, period_s)) {
      throw UsageError("--steps: " + g(h) + " s does not divide the servo "
                       "period " + g(period_s) + " s");
    }
    if (!(h > p.reference_step_s)) {
      throw UsageError("--steps: " + g(h) + " s is not above the reference "
                       "step " + g(p.reference_step_s) + " s");
    }
  }
  if (!(p.reference_step_s > 0.0) || !divides(p.reference_step_s, period_s)) {
    throw UsageError("--reference-step: must be > 0 and divide the servo "
                     "period " + g(period_s) + " s, got " +
                     g(p.reference_step_s));
  }
  // 1e-12 s divides 1 ms, but a billion steps per tick is past the closed
  // loop's bound, which then named servo_period_s instead of the option
  if (period_s / p.reference_step_s >
      static_cast<double>(sim::kMaxSubstepsPerTick)) {
    throw UsageError("--reference-step: at most " +
                     std::to_string(sim::kMaxSubstepsPerTick) +
                     " steps per servo period " + g(period_s) + " s, got " +
                     g(p.reference_step_s));
  }
  if (!(p.reference_check_step_s > p.reference_step_s) ||
      !divides(p.reference_check_step_s, period_s)) {
    throw UsageError("--reference-check-step: must be above --reference-step "
                     "and divide the servo period " + g(period_s) +
                     " s, got " + g(p.reference_check_step_s));
  }
}

void run(const PrecisionCli& o) {
  // SIGINT / SIGTERM only set a flag for the whole run, which the study
  // polls (cli/study_files.h): exit 130 / 143, --out as it was
  StopSignals signals;
  const studies::PrecisionOptions p = to_options(o);
  check_against_case(p);
  studies::PrecisionResult r;
  try {
    output::Progress bar("study precision", 0);
    studies::PrecisionOptions with_bar = p;
    with_bar.progress = bar.part(0);
    with_bar.should_stop = study_stop();
    r = run_stoppable("study precision",
                      [&] { return studies::run_precision_study(with_bar); });
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("study precision: ") + e.what());
  }
  throw_if_stopped_after_writing("study precision", o.out);
  std::cout << dump_readable(studies::precision_json(r)) << '\n';
}

}  // namespace

void register_study_precision(CLI::App* study, const char* name) {
  auto o = std::make_shared<PrecisionCli>();
  CLI::App* cmd = study->add_subcommand(
      name,
      "trajectory error against wall time for each MuJoCo integrator and a "
      "ladder of physics steps, against an RK4 reference (quantisation off)");
  cmd->add_option("--case", o->case_name,
                  "1..7, case1..case7 or a scene file (default 1)");
  cmd->add_option("--duration", o->duration_s,
                  "simulated seconds from the start of the case's script "
                  "(default 3: the settle, the move off the path and the "
                  "hold there)");
  // an empty list is refused, not read as "not given" (issue 17)
  refuse_empty(
      cmd->add_option("--steps", o->steps,
                      "physics steps h (s), comma-separated, each dividing "
                      "the servo period (default "
                      "1e-3,5e-4,2e-4,1e-4,5e-5,2e-5,1e-5)"),
      "a list of steps");
  refuse_empty(cmd->add_option("--integrators", o->integrators,
                               "comma-separated subset of euler,implicit,rk4 "
                               "(default all)"),
               "a list of integrators");
  cmd->add_option("--reference-step", o->reference_step_s,
                  "RK4 reference step (s), default 2e-6");
  cmd->add_option("--reference-check-step", o->reference_check_step_s,
                  "a second RK4 reference (s) bounding the first one's "
                  "error, default 4e-6");
  cmd->add_option("--set", o->sets,
                  "override a case parameter, name=value; repeatable")
      ->allow_extra_args(false);
  cmd->add_option("--out", o->out,
                  "write DIR/precision.csv, precision.svg, precision_order.svg");
  cmd->add_option("--modelling-spread", o->modelling_spread,
                  "a sensitivity.json (or its folder) of the same case: its "
                  "spread of the RMS path error is drawn across precision.svg "
                  "and compared with the default setting's error");
  cmd->callback([o] { run(*o); });
}

}  // namespace vmh::cli
