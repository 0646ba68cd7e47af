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
// against theory (sim/stability_study.h, REFERENCE.md §6). Prints one JSON
// object. With --out DIR: DIR/stability_bisection.csv (every run of the
// bisection) and DIR/stability_bisection.svg (their growth rates against K
// with the theories' K marked); with --map: DIR/stability_map.csv and
// DIR/stability_map.svg, K_crit against B for each delay.
// Exit codes: 0 done; 2 bad usage or input; 1 anything else.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/args.h"
#include "cli/json_util.h"
#include "cli/study.h"
#include "report/output_file.h"
#include "report/parallel.h"
#include "studies/run_case.h"
#include "studies/stability_study.h"
#include "report/svg_chart.h"

namespace vmh::cli {
namespace {

namespace fs = std::filesystem;

struct StabilityOptions {
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

void write_file(const fs::path& path, const std::string& text) {
  report::write_file_atomically(path.string(), text);
}

void make_out_dir(const std::string& out) {
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec || !fs::is_directory(out)) {
    throw UsageError("--out: cannot create directory '" + out + "'");
  }
}

// The parameters, checked. For --map, B is the sweep's and is checked per
// point; here it stands at 1 N s/m so that b = 0 passes.
studies::StabilityParams params_from(const StabilityOptions& o) {
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

double rel(double value, double reference) {
  return reference != 0.0 ? value / reference - 1.0 : std::nan("");
}

Json inputs_json(const studies::StabilityParams& p, bool with_controller) {
  Json j = Json::object();
  j["mass_kg"] = p.mass_kg;
  j["damping_Ns_per_m"] = p.damping_Ns_per_m;
  j["servo_period_s"] = p.servo_period_s;
  if (with_controller) {
    j["virtual_damping_Ns_per_m"] = p.virtual_damping_Ns_per_m;
    j["delay_ticks"] = p.delay_ticks;
    j["delay_s"] = p.delay_ticks * p.servo_period_s;
  }
  j["physics_step_s"] = p.physics_step_s;
  j["steps_per_tick"] = studies::steps_per_tick(p);
  j["velocity_estimate"] = "backward difference (x_k - x_{k-1})/T";
  j["initial_displacement_m"] = studies::kInitialDisplacement_m;
  return j;
}

// the bisection's runs: growth rate against K, the theories' K as vertical
// lines
std::string bisection_svg(const studies::StabilityReport& r) {
  report::Chart c;
  char title[200];
  std::snprintf(title, sizeof title,
                "Bisection on K: m = %g kg, b = %g N s/m, T = %g ms, B = %g "
                "N s/m, n = %d",
                r.params.mass_kg, r.params.damping_Ns_per_m,
                1e3 * r.params.servo_period_s,
                r.params.virtual_damping_Ns_per_m, r.params.delay_ticks);
  c.title = title;
  c.x.label = "stiffness K (N/m)";
  c.y.label = "envelope growth rate (1/s)";
  c.width_px = 820;
  report::ChartSeries runs;
  runs.label = "simulated runs";
  runs.line = false;
  double lo = 0.0, hi = 0.0;
  for (const studies::WallRun& w : r.sim.history) {
    if (w.diverged) continue;  // off the scale
    runs.x.push_back(w.k_N_per_m);
    runs.y.push_back(w.growth_rate_per_s);
    lo = std::min(lo, w.growth_rate_per_s);
    hi = std::max(hi, w.growth_rate_per_s);
  }
  c.series.push_back(runs);
  auto vertical = [&](const std::string& label, double k, const char* color,
                      bool dashed) {
    report::ChartSeries s;
    s.label = label;
    s.x = {k, k};
    s.y = {lo, hi};
    s.markers = false;
    s.dashed = dashed;
    s.color = color;
    c.series.push_back(s);
  };
  vertical("K_crit simulated", r.sim.k_crit_N_per_m, "#1f77b4", false);
  vertical("exact discrete", r.exact.k_crit_N_per_m, "#2ca02c", true);
  vertical("Gil et al. (b+B)/(T/2+nT)", r.k_bound_gil_N_per_m, "#d62728",
           true);
  return report::chart_svg(c);
}

std::string bisection_csv(const studies::StabilityReport& r) {
  std::string s =
      "run,k_N_per_m,stable,diverged,growth_rate_per_s,early_peak_m,"
      "late_peak_m,ticks\n";
  char buf[256];
  int i = 0;
  for (const studies::WallRun& w : r.sim.history) {
    std::snprintf(buf, sizeof buf, "%d,%.10g,%d,%d,%.6g,%.9g,%.9g,%d\n", i++,
                  w.k_N_per_m, w.stable ? 1 : 0, w.diverged ? 1 : 0,
                  w.growth_rate_per_s, w.early_peak_m, w.late_peak_m,
                  w.ticks);
    s += buf;
  }
  return s;
}

void run_single(const StabilityOptions& o, const studies::StabilityParams& p) {
  const std::string model = studies::slider_model_path(studies::models_dir());
  if (!o.out.empty()) make_out_dir(o.out);
  studies::StabilityReport r;
  try {
    r = studies::study_stability(model, p, o.tolerance);
  } catch (const sim::SimError& e) {
    throw UsageError(e.what());
  }
  studies::SliderWall probe(model, p);
  const double k = r.sim.k_crit_N_per_m;
  const double bT_m = p.damping_Ns_per_m * p.servo_period_s / p.mass_kg;
  const double BT_m =
      p.virtual_damping_Ns_per_m * p.servo_period_s / p.mass_kg;

  Json j = Json::object();
  j["study"] = "stability";
  j["model"] = model;
  j["inputs"] = inputs_json(p, true);
  j["k_crit_N_per_m"] = k;
  j["k_stable_N_per_m"] = r.sim.k_stable_N_per_m;
  j["k_unstable_N_per_m"] = r.sim.k_unstable_N_per_m;
  j["tolerance"] = o.tolerance;
  j["bound"] = Json{{"source", "Gil, Avello, Rubio and Florez 2004"},
                    {"formula", "(b + B) / (T/2 + n T)"},
                    {"k_N_per_m", r.k_bound_gil_N_per_m}};
  j["k_bound_gil_N_per_m"] = r.k_bound_gil_N_per_m;
  j["k_crit_exact_discrete_N_per_m"] = r.exact.k_crit_N_per_m;
  j["k_crit_mujoco_euler_discrete_N_per_m"] = r.euler.k_crit_N_per_m;
  j["k_passivity_N_per_m"] = r.k_passivity_N_per_m;
  j["rel_error_vs_gil"] = rel(k, r.k_bound_gil_N_per_m);
  j["rel_error_vs_exact_discrete"] = rel(k, r.exact.k_crit_N_per_m);
  j["rel_error_vs_mujoco_euler_discrete"] = rel(k, r.euler.k_crit_N_per_m);
  j["rel_error_gil_vs_exact_discrete"] =
      rel(r.k_bound_gil_N_per_m, r.exact.k_crit_N_per_m);
  // Gil et al.'s first-order bound holds while these are small
  j["bT_over_m"] = bT_m;
  j["BT_over_m"] = BT_m;
  j["iterations"] = Json{{"sim_runs", r.sim.runs},
                         {"physics_steps", r.sim.physics_steps},
                         {"eigen_evaluations_exact", r.exact.iterations},
                         {"eigen_evaluations_euler", r.euler.iterations}};
  j["horizon_ticks_at_k_crit"] = probe.horizon_ticks(k);
  j["wall_time_s"] = r.wall_time_s;
  if (!o.out.empty()) {
    const fs::path dir(o.out);
    write_file(dir / "stability_bisection.csv", bisection_csv(r));
    write_file(dir / "stability_bisection.svg", bisection_svg(r));
    j["outputs"] = Json{(dir / "stability_bisection.csv").string(),
                        (dir / "stability_bisection.svg").string()};
  }
  std::cout << dump_readable(j) << '\n';
}

void run_map(const StabilityOptions& o, const studies::StabilityParams& base) {
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
  studies::MapSpec spec;
  spec.base = base;
  spec.rel_tol = o.tolerance;
  spec.jobs = o.jobs > 0 ? o.jobs : report::core_count();
  // with b = 0 the sweep starts one step above B = 0, where nothing is
  // stable
  const int first = base.damping_Ns_per_m > 0.0 ? 0 : 1;
  for (int i = first; i < o.map_points + first; ++i) {
    spec.virtual_damping_Ns_per_m.push_back(b_max * i / (o.map_points - 1));
  }
  if (o.delay_given) {
    spec.delay_ticks = {o.delay_ticks};
  } else {
    spec.delay_ticks = {0, 1, 2};
  }
  make_out_dir(o.out);
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<studies::MapPoint> points;
  try {
    points = studies::stability_map(studies::slider_model_path(studies::models_dir()),
                                spec);
  } catch (const sim::SimError& e) {
    throw UsageError(e.what());
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
          .count();
  const fs::path dir(o.out);
  write_file(dir / "stability_map.csv", studies::stability_map_csv(points));
  write_file(dir / "stability_map.svg",
             studies::stability_map_svg(points, base));

  double worst_exact = 0.0, worst_euler = 0.0, worst_gil = 0.0;
  int runs = 0;
  Json rows = Json::array();
  for (const studies::MapPoint& p : points) {
    const double k = p.sim.k_crit_N_per_m;
    worst_exact = std::max(worst_exact, std::abs(rel(k, p.k_crit_exact_N_per_m)));
    worst_euler =
        std::max(worst_euler, std::abs(rel(k, p.k_crit_mujoco_euler_N_per_m)));
    worst_gil = std::max(worst_gil, std::abs(rel(k, p.k_bound_gil_N_per_m)));
    runs += p.sim.runs;
    rows.push_back(Json{p.virtual_damping_Ns_per_m, p.delay_ticks, k,
                        p.k_crit_exact_N_per_m, p.k_bound_gil_N_per_m});
  }
  Json j = Json::object();
  j["study"] = "stability";
  j["mode"] = "map";
  j["inputs"] = inputs_json(base, false);
  j["virtual_damping_Ns_per_m"] = spec.virtual_damping_Ns_per_m;
  j["delay_ticks"] = spec.delay_ticks;
  j["tolerance"] = o.tolerance;
  j["points"] = points.size();
  j["columns"] = Json{"virtual_damping_Ns_per_m", "delay_ticks",
                      "k_crit_sim_N_per_m", "k_crit_exact_N_per_m",
                      "k_bound_gil_N_per_m"};
  j["rows"] = rows;
  j["max_abs_rel_error_sim_vs_exact"] = worst_exact;
  j["max_abs_rel_error_sim_vs_mujoco_euler"] = worst_euler;
  j["max_abs_rel_error_sim_vs_gil"] = worst_gil;
  j["sim_runs"] = runs;
  j["jobs"] = spec.jobs;
  j["wall_time_s"] = wall_s;
  j["outputs"] = Json{(dir / "stability_map.csv").string(),
                      (dir / "stability_map.svg").string()};
  std::cout << dump_readable(j) << '\n';
}

void run(const StabilityOptions& o) {
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

void register_study_stability(CLI::App* study) {
  auto o = std::make_shared<StabilityOptions>();
  CLI::App* cmd = study->add_subcommand(
      "stability",
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
