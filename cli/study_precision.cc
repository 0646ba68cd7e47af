// vmhaptics study precision [--case N] [--duration S] [--steps h1,h2,...]
//                           [--integrators euler,implicit,rk4]
//                           [--reference-step S] [--reference-check-step S]
//                           [--set name=value ...] [--out DIR]
//
// Error of the stylus's trajectory against wall time, per MuJoCo integrator
// and physics step (sim/precision_study.h). Prints one JSON object; with
// --out writes DIR/precision.csv, DIR/precision.svg (error vs wall time) and
// DIR/precision_order.svg (error vs h). Exit 2 on bad usage, naming the
// option; nothing is written then.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli/args.h"
#include "cli/json_util.h"
#include "cli/study.h"
#include "cli/study_files.h"
#include "sim/closed_loop.h"
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

// NaN (a run that blew up) as JSON null
Json number_or_null(double x) { return std::isfinite(x) ? Json(x) : Json(); }

Json error_json(const studies::TrajectoryError& e) {
  return {{"rms_error_mm", number_or_null(e.rms_mm)},
          {"max_error_mm", number_or_null(e.max_mm)},
          {"rms_axis_error_rad", number_or_null(e.rms_axis_rad)},
          {"max_axis_error_rad", number_or_null(e.max_axis_rad)},
          {"rms_torque_diff_mNm", number_or_null(e.rms_torque_mNm)},
          {"status_mismatch_ticks", e.status_mismatch_ticks},
          {"iteration_mismatch_ticks", e.iteration_mismatch_ticks},
          {"finite", e.finite}};
}

void run(const PrecisionCli& o) {
  studies::PrecisionOptions p;
  std::string name;
  p.scene = study_scene("--case", o.case_name, &name);
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
  if (!o.integrators.empty()) {
    p.integrators.clear();
    std::string::size_type start = 0;
    while (true) {
      const auto comma = o.integrators.find(',', start);
      const std::string item = o.integrators.substr(start, comma - start);
      studies::Integrator i;
      if (!studies::parse_integrator(item, &i)) {
        throw UsageError("--integrators: unknown integrator '" + item +
                         "' (euler, implicit or rk4)");
      }
      p.integrators.push_back(i);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
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

  // the case's servo period and script length, to check the options against
  double period_s = 0.0, script_s = 0.0;
  try {
    sim::ClosedLoop probe(p.scene, p.overrides);
    period_s = probe.controller_params().servo_period_s;
    script_s = probe.config().number("duration_s");
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("study precision: ") + e.what());
  }
  if (o.duration_s > script_s) {
    throw UsageError("--duration: " + g(o.duration_s) +
                     " s is beyond the case's script (duration_s = " +
                     g(script_s) + " s)");
  }
  for (double h : p.steps_s) {
    if (!divides(h, period_s)) {
      throw UsageError("--steps: " + g(h) + " s does not divide the servo "
                       "period " + g(period_s) + " s");
    }
    if (!(h > o.reference_step_s)) {
      throw UsageError("--steps: " + g(h) + " s is not above the reference "
                       "step " + g(o.reference_step_s) + " s");
    }
  }
  if (!(o.reference_step_s > 0.0) || !divides(o.reference_step_s, period_s)) {
    throw UsageError("--reference-step: must be > 0 and divide the servo "
                     "period " + g(period_s) + " s, got " +
                     g(o.reference_step_s));
  }
  if (!(o.reference_check_step_s > o.reference_step_s) ||
      !divides(o.reference_check_step_s, period_s)) {
    throw UsageError("--reference-check-step: must be above --reference-step "
                     "and divide the servo period " + g(period_s) +
                     " s, got " + g(o.reference_check_step_s));
  }

  studies::PrecisionResult r;
  try {
    r = studies::run_precision_study(p);
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("study precision: ") + e.what());
  }

  Json rows = Json::array();
  for (const studies::PrecisionRow& row : r.rows) {
    Json j = {{"integrator", studies::integrator_name(row.integrator)},
              {"h_s", row.step_s},
              {"substeps_per_tick", row.substeps}};
    j.update(error_json(row.error));
    j.update(Json{{"wall_time_s", row.wall_time_s},
                  {"cpu_time_s", row.cpu_time_s},
                  {"repeats", row.repeats},
                  {"steps_per_s", row.steps_per_s},
                  {"realtime_factor", row.realtime_factor},
                  {"local_order", number_or_null(row.local_order)},
                  {"used_in_fit", row.used_in_fit},
                  {"on_front", row.on_front},
                  {"on_front_cpu", row.on_front_cpu},
                  {"is_default", row.is_default},
                  {"mujoco_warnings", row.mujoco_warnings}});
    rows.push_back(j);
  }
  Json orders = Json::array();
  for (const studies::OrderFit& f : r.fits) {
    orders.push_back({{"integrator", studies::integrator_name(f.integrator)},
                      {"order", number_or_null(f.order)},
                      {"log10_coefficient", number_or_null(f.log10_coefficient)},
                      {"points", f.points},
                      {"h_used_s", f.steps_used_s}});
  }
  Json def = Json::object();
  for (const studies::PrecisionRow& row : r.rows) {
    if (!row.is_default) continue;
    def = {{"integrator", studies::integrator_name(row.integrator)},
           {"h_s", row.step_s},
           {"rms_error_mm", number_or_null(row.error.rms_mm)},
           {"max_error_mm", number_or_null(row.error.max_mm)},
           {"wall_time_s", row.wall_time_s},
           {"cpu_time_s", row.cpu_time_s},
           {"on_front", row.on_front},
           {"on_front_cpu", row.on_front_cpu}};
    // the settings that beat it on both error and time
    Json better = Json::array();
    for (const studies::PrecisionRow& other : r.rows) {
      if (other.error.finite && row.error.finite &&
          other.error.rms_mm < row.error.rms_mm &&
          other.wall_time_s < row.wall_time_s) {
        better.push_back({{"integrator", studies::integrator_name(other.integrator)},
                          {"h_s", other.step_s}});
      }
    }
    def["dominated_by"] = better;
  }
  if (def.empty()) {
    // the default integrator was left out with --integrators
    def = {{"integrator", studies::integrator_name(r.default_integrator)},
           {"h_s", r.default_step_s},
           {"on_front", nullptr},
           {"on_front_cpu", nullptr}};
  }
  Json front = Json::array();
  for (const studies::PrecisionRow& row : r.rows) {
    if (row.on_front) {
      front.push_back({{"integrator", studies::integrator_name(row.integrator)},
                       {"h_s", row.step_s}});
    }
  }

  Json segments = Json::array();
  for (const sim::ScriptSegment& seg : r.segments) {
    segments.push_back({{"name", seg.name}, {"t0_s", seg.t0_s}, {"t1_s", seg.t1_s}});
  }
  Json result = {
      {"study", "precision"},
      {"case", name},
      {"scene", r.scene},
      {"duration_s", r.duration_s},
      {"servo_period_s", r.servo_period_s},
      {"ticks", r.ticks},
      {"quantize", 0},
      {"segments", segments},
      {"trajectory",
       "true wrist centre (omni_fk of MuJoCo's joint angles, device frame) "
       "and stylus axis at the end of every servo tick"},
      {"reference",
       {{"integrator", "rk4"},
        {"h_s", r.reference.step_s},
        {"wall_time_s", r.reference.wall_time_s},
        {"check_h_s", r.reference.check_step_s},
        {"check_wall_time_s", r.reference.check_wall_time_s},
        {"self_error", error_json(r.reference.self_error)}}},
      {"fit_floor_mm", r.floor_mm},
      {"orders", orders},
      {"default", def},
      {"front", front},
      {"rows", rows},
      {"study_wall_time_s", r.study_wall_time_s},
  };
  if (!o.out.empty()) {
    Json files = Json::array();
    files.push_back(write_study_file(o.out, "precision.csv", studies::precision_csv(r)));
    files.push_back(write_study_file(o.out, "precision.svg",
                                     report::chart_svg(studies::precision_chart(r))));
    files.push_back(write_study_file(
        o.out, "precision_order.svg",
        report::chart_svg(studies::precision_order_chart(r))));
    result["files"] = files;
  }
  std::cout << dump_readable(result) << '\n';
}

}  // namespace

void register_study_precision(CLI::App* study) {
  auto o = std::make_shared<PrecisionCli>();
  CLI::App* cmd = study->add_subcommand(
      "precision",
      "trajectory error against wall time for each MuJoCo integrator and a "
      "ladder of physics steps, against an RK4 reference (quantisation off)");
  cmd->add_option("--case", o->case_name,
                  "1..6, case1..case6 or a scene file (default 1)");
  cmd->add_option("--duration", o->duration_s,
                  "simulated seconds from the start of the case's script "
                  "(default 3: the settle, the move off the path and the "
                  "hold there)");
  cmd->add_option("--steps", o->steps,
                  "physics steps h (s), comma-separated, each dividing the "
                  "servo period (default 1e-3,5e-4,2e-4,1e-4,5e-5,2e-5,1e-5)");
  cmd->add_option("--integrators", o->integrators,
                  "comma-separated subset of euler,implicit,rk4 (default all)");
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
  cmd->callback([o] { run(*o); });
}

}  // namespace vmh::cli
