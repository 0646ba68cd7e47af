// vmhaptics study stability --mass m --damping b --servo-period T
//     [--virtual-damping B] [--delay-ticks n] [--physics-step h]
//     [--tolerance r] [--out DIR]
// vmhaptics study stability --map --out DIR --mass m --damping b
//     --servo-period T [--delay-ticks n] [--physics-step h]
//     [--map-b-max B] [--map-points P] [--jobs J]
//
// The critical stiffness of a virtual wall rendered at period T with a
// zero-order hold on a 1-DOF slider (models/slider/slider.xml) simulated in
// MuJoCo at h << T, found by bisection on whether the oscillation grows,
// against theory (studies/stability_study.h, docs/sources.md §11). Prints one JSON
// object. With --out DIR: DIR/stability_bisection.csv (every run of the
// bisection) and DIR/stability_bisection.svg (their growth rates against K
// with the theories' K marked); with --map: DIR/stability_map.csv and
// DIR/stability_map.svg, K_crit against B for each delay.
// Exit codes: 0 done; 2 bad usage or input; 1 anything else; 130 / 143
// stopped by SIGINT / SIGTERM (polled before each run of a bisection and
// before the files go in: --out as it was, or its files all written if the
// signal came as they went in).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/args.h"
#include "runtime/json_util.h"
#include "cli/study.h"
#include "cli/study_files.h"
#include "device/stop_signal.h"
#include "output/output_file.h"
#include "output/parallel.h"
#include "output/progress.h"
#include "thesis/run_case.h"
#include "studies/stability_study.h"

namespace vmh::cli {
namespace {

namespace fs = std::filesystem;

struct StabilityCli {
  double mass_kg = 0.0;
  double damping_Ns_per_m = 0.0;
  double servo_period_s = 0.0;
  double virtual_damping_Ns_per_m = 0.0;
  int delay_ticks = 0;
  double physics_step_s = 0.0;  // not given: T / kDefaultStepsPerTick
  double tolerance = 2e-3;
  std::string out;
  bool map = false;
  double map_b_max_Ns_per_m = 0.0;  // not given: 0.1 m/T
  int map_points = 11;
  int jobs = 0;  // 0: one per core
  // whether the option was given
  bool virtual_damping_given = false;
  bool delay_given = false;
  bool physics_step_given = false;
  bool map_b_max_given = false;
};

// h = T/1000 by default: MuJoCo's semi-implicit Euler shortens the hold's
// effective delay by h/2, which raises K_crit by about h/((1 + 2n) T), 0.1%
constexpr int kDefaultStepsPerTick = 1000;
// B up to 0.1 m/T by default, where the backward difference's correction to
// Gil et al.'s bound reaches about -10%: the map shows the line part from
// the points
constexpr double kDefaultMapBMaxTimesMOverT = 0.1;

// --out checked before the study (created and removed again: a study
// stopped by a signal leaves no folder of its own; the writers create it)
void make_out_dir(const std::string& out) {
  try {
    output::check_writable_dir(out);
  } catch (const std::runtime_error& e) {
    throw UsageError("--out: cannot create directory '" + out + "' (" +
                     e.what() + ")");
  }
}

// The parameters, checked. For --map, B is the sweep's and is checked per
// point; here it stands at 1 N s/m so that b = 0 passes.
studies::StabilityParams params_from(const StabilityCli& o) {
  studies::StabilityParams p;
  p.mass_kg = o.mass_kg;
  p.damping_Ns_per_m = o.damping_Ns_per_m;
  p.servo_period_s = o.servo_period_s;
  p.virtual_damping_Ns_per_m = o.map ? 1.0 : o.virtual_damping_Ns_per_m;
  p.delay_ticks = o.delay_ticks;
  p.physics_step_s = o.physics_step_s;
  if (!o.physics_step_given && std::isfinite(o.servo_period_s)) {
    p.physics_step_s = o.servo_period_s / kDefaultStepsPerTick;
  }
  try {
    studies::validate(p);
  } catch (const sim::SimError& e) {
    throw UsageError(e.what());
  }
  if (o.map) p.virtual_damping_Ns_per_m = 0.0;
  return p;
}

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// the study, its bad input as bad usage, and its JSON on stdout
// `bar` (if any) is finished before the JSON, so that a terminal shows it
// whole above it
void run_study(const studies::StabilityOptions& p,
               output::Progress* bar = nullptr) {
  studies::StabilityResult r;
  studies::StabilityOptions stoppable = p;
  stoppable.should_stop = study_stop();
  try {
    r = run_stoppable("study stability",
                      [&] { return studies::run_stability_study(stoppable); });
  } catch (const sim::SimError& e) {
    throw UsageError(e.what());
  }
  if (bar != nullptr) bar->finish();
  throw_if_stopped_after_writing("study stability", p.out_dir);
  std::cout << dump_readable(studies::stability_json(r)) << '\n';
}

void run_single(const StabilityCli& o, const studies::StabilityParams& p) {
  studies::StabilityOptions so;
  so.model_path = studies::slider_model_path(sim::models_dir());
  so.params = p;
  so.rel_tol = o.tolerance;
  so.out_dir = o.out;
  if (!o.out.empty()) make_out_dir(o.out);
  run_study(so);
}

void run_map(const StabilityCli& o, const studies::StabilityParams& base) {
  if (o.out.empty()) {
    throw UsageError("--map: give --out DIR for stability_map.csv and .svg");
  }
  if (o.virtual_damping_given) {
    throw UsageError(
        "--virtual-damping: not with --map, which sweeps B from 0 to "
        "--map-b-max");
  }
  if (o.map_points < 2 || o.map_points > 200) {
    throw UsageError("--map-points: must be 2..200 (got " +
                     std::to_string(o.map_points) + ")");
  }
  const double T = base.servo_period_s;
  const double b_max = o.map_b_max_given
                           ? o.map_b_max_Ns_per_m
                           : kDefaultMapBMaxTimesMOverT * base.mass_kg / T;
  if (!(b_max > 0.0) || !std::isfinite(b_max)) {
    throw UsageError("--map-b-max: the largest B must be > 0 N s/m (got " +
                     number_text(o.map_b_max_Ns_per_m) + ")");
  }
  studies::StabilityOptions so;
  so.model_path = studies::slider_model_path(sim::models_dir());
  so.params = base;
  so.rel_tol = o.tolerance;
  so.jobs = o.jobs > 0 ? o.jobs : output::core_count();
  // with b = 0 the sweep starts one step above B = 0, where nothing is
  // stable
  const int first = base.damping_Ns_per_m > 0.0 ? 0 : 1;
  for (int i = first; i < o.map_points + first; ++i) {
    so.map_virtual_damping_Ns_per_m.push_back(b_max * i / (o.map_points - 1));
  }
  if (o.delay_given) {
    so.map_delay_ticks = {o.delay_ticks};
  } else {
    so.map_delay_ticks = {0, 1, 2};
  }
  so.out_dir = o.out;
  make_out_dir(o.out);
  output::Progress bar("study stability --map",
                       so.map_virtual_damping_Ns_per_m.size() *
                           so.map_delay_ticks.size());
  so.progress = bar.part(0);
  run_study(so, &bar);
}

void run(const StabilityCli& o) {
  // SIGINT / SIGTERM only set a flag for the whole run, which the study
  // polls (cli/study_files.h): exit 130 / 143, --out as it was
  StopSignals signals;
  if (!(o.tolerance >= 1e-5 && o.tolerance <= 0.1)) {
    throw UsageError("--tolerance: the relative bracket width must be in "
                     "[1e-5, 0.1] (got " + number_text(o.tolerance) + ")");
  }
  if (o.jobs < 0) throw UsageError("--jobs: must be >= 1");
  const studies::StabilityParams p = params_from(o);
  if (o.map) {
    run_map(o, p);
  } else {
    run_single(o, p);
  }
}

}  // namespace

void register_study_stability(CLI::App* study, const char* name) {
  auto o = std::make_shared<StabilityCli>();
  CLI::App* cmd = study->add_subcommand(
      name,
      "critical stiffness K_crit of a sampled-data virtual wall on a 1-DOF "
      "slider (MuJoCo, zero-order hold at T, physics at h << T), by "
      "bisection on the growth of the oscillation, against Gil et al.'s "
      "bound (b+B)/(T/2+nT), the exact discrete-time loop and passivity");
  cmd->add_option("--mass", o->mass_kg, "slider mass m, kg")->required();
  cmd->add_option("--damping", o->damping_Ns_per_m,
                  "physical damping b, N s/m")
      ->required();
  cmd->add_option("--servo-period", o->servo_period_s,
                  "controller period T, s (e.g. 0.001)")
      ->required();
  cmd->add_option("--virtual-damping", o->virtual_damping_Ns_per_m,
                  "the wall's damper B, N s/m (default 0)");
  cmd->add_option("--delay-ticks", o->delay_ticks,
                  "ticks between sampling and applying the force, t_d = n T "
                  "(default 0; with --map, 0, 1 and 2)");
  cmd->add_option("--physics-step", o->physics_step_s,
                  "MuJoCo time step h, s; T must be a whole multiple "
                  "(default T/1000)");
  cmd->add_option("--tolerance", o->tolerance,
                  "relative width of the final K bracket (default 0.002)");
  cmd->add_option("--out", o->out,
                  "write DIR/stability_bisection.csv and .svg, or with --map "
                  "DIR/stability_map.csv and .svg");
  cmd->add_flag("--map", o->map,
                "sweep B from 0 to --map-b-max (and n over 0..2 unless "
                "--delay-ticks) and write the stability map; needs --out");
  cmd->add_option("--map-b-max", o->map_b_max_Ns_per_m,
                  "largest B of the map, N s/m (default 0.1 m/T)");
  cmd->add_option("--map-points", o->map_points,
                  "B values per delay in the map (default 11)");
  cmd->add_option("--jobs", o->jobs,
                  "map points simulated in parallel (default: one per core)");
  CLI::Option* vd = cmd->get_option("--virtual-damping");
  CLI::Option* dt = cmd->get_option("--delay-ticks");
  CLI::Option* h = cmd->get_option("--physics-step");
  CLI::Option* bm = cmd->get_option("--map-b-max");
  cmd->callback([o, vd, dt, h, bm] {
    o->virtual_damping_given = vd->count() > 0;
    o->delay_given = dt->count() > 0;
    o->physics_step_given = h->count() > 0;
    o->map_b_max_given = bm->count() > 0;
    run(*o);
  });
}

}  // namespace vmh::cli
