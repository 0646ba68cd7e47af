// The stability study's outputs: the bisection's runs and the map as
// tables (CSV, units in the column names) and charts (output/'s chart), and
// the JSON the command line prints (keys in the order a reader meets them).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "output/output_file.h"
#include "output/svg_chart.h"
#include "studies/stability_study.h"

namespace vmh::studies {
namespace {

using Json = nlohmann::ordered_json;

// value / reference - 1; NaN against 0
double rel(double value, double reference) {
  return reference != 0.0 ? value / reference - 1.0 : std::nan("");
}

Json inputs_json(const StabilityParams& p, bool with_controller) {
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
  j["steps_per_tick"] = steps_per_tick(p);
  j["velocity_estimate"] = "backward difference (x_k - x_{k-1})/T";
  j["initial_displacement_m"] = kInitialDisplacement_m;
  return j;
}

// one setting: K_crit simulated against the theories
Json bisection_json(const StabilityResult& res) {
  const StabilityReport& r = res.bisection;
  const StabilityParams& p = res.options.params;
  const double k = r.sim.k_crit_N_per_m;
  Json j = Json::object();
  j["study"] = "stability";
  j["model"] = res.options.model_path;
  j["inputs"] = inputs_json(p, true);
  j["k_crit_N_per_m"] = k;
  j["k_stable_N_per_m"] = r.sim.k_stable_N_per_m;
  j["k_unstable_N_per_m"] = r.sim.k_unstable_N_per_m;
  j["tolerance"] = res.options.rel_tol;
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
  j["bT_over_m"] = p.damping_Ns_per_m * p.servo_period_s / p.mass_kg;
  j["BT_over_m"] = p.virtual_damping_Ns_per_m * p.servo_period_s / p.mass_kg;
  j["iterations"] = Json{{"sim_runs", r.sim.runs},
                         {"physics_steps", r.sim.physics_steps},
                         {"eigen_evaluations_exact", r.exact.iterations},
                         {"eigen_evaluations_euler", r.euler.iterations}};
  j["horizon_ticks_at_k_crit"] = res.horizon_ticks_at_k_crit;
  j["wall_time_s"] = res.wall_time_s;
  if (!res.files.empty()) j["outputs"] = res.files;
  return j;
}

// the map: a row per (B, n), and the worst relative errors over it
Json map_json(const StabilityResult& res) {
  const StabilityOptions& o = res.options;
  double worst_exact = 0.0, worst_euler = 0.0, worst_gil = 0.0;
  int runs = 0;
  Json rows = Json::array();
  for (const MapPoint& p : res.map) {
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
  j["inputs"] = inputs_json(o.params, false);
  j["virtual_damping_Ns_per_m"] = o.map_virtual_damping_Ns_per_m;
  j["delay_ticks"] = o.map_delay_ticks;
  j["tolerance"] = o.rel_tol;
  j["points"] = res.map.size();
  j["columns"] = Json{"virtual_damping_Ns_per_m", "delay_ticks",
                      "k_crit_sim_N_per_m", "k_crit_exact_N_per_m",
                      "k_bound_gil_N_per_m"};
  j["rows"] = rows;
  j["max_abs_rel_error_sim_vs_exact"] = worst_exact;
  j["max_abs_rel_error_sim_vs_mujoco_euler"] = worst_euler;
  j["max_abs_rel_error_sim_vs_gil"] = worst_gil;
  j["sim_runs"] = runs;
  j["jobs"] = o.jobs;
  j["wall_time_s"] = res.wall_time_s;
  if (!res.files.empty()) j["outputs"] = res.files;
  return j;
}

}  // namespace

std::string bisection_csv(const StabilityReport& r) {
  std::string s =
      "run,k_N_per_m,stable,diverged,growth_rate_per_s,early_peak_m,"
      "late_peak_m,ticks\n";
  char buf[256];
  int i = 0;
  for (const WallRun& w : r.sim.history) {
    std::snprintf(buf, sizeof buf, "%d,%.10g,%d,%d,%.6g,%.9g,%.9g,%d\n", i++,
                  w.k_N_per_m, w.stable ? 1 : 0, w.diverged ? 1 : 0,
                  w.growth_rate_per_s, w.early_peak_m, w.late_peak_m,
                  w.ticks);
    s += buf;
  }
  return s;
}

output::Chart bisection_chart(const StabilityReport& r) {
  output::Chart c;
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
  output::ChartSeries runs;
  runs.label = "simulated runs";
  runs.line = false;
  double lo = 0.0, hi = 0.0;
  for (const WallRun& w : r.sim.history) {
    if (w.diverged) continue;  // off the scale
    runs.x.push_back(w.k_N_per_m);
    runs.y.push_back(w.growth_rate_per_s);
    lo = std::min(lo, w.growth_rate_per_s);
    hi = std::max(hi, w.growth_rate_per_s);
  }
  c.series.push_back(runs);
  auto vertical = [&](const std::string& label, double k, const char* color,
                      bool dashed) {
    output::ChartSeries s;
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
  return c;
}

std::string stability_map_csv(const std::vector<MapPoint>& points) {
  std::string out =
      "virtual_damping_Ns_per_m,delay_ticks,k_crit_sim_N_per_m,"
      "k_stable_sim_N_per_m,k_unstable_sim_N_per_m,k_crit_exact_N_per_m,"
      "k_crit_mujoco_euler_N_per_m,k_bound_gil_N_per_m,k_passivity_N_per_m,"
      "rel_error_sim_vs_exact,rel_error_sim_vs_gil,sim_runs\n";
  char buf[512];
  for (const MapPoint& p : points) {
    std::snprintf(
        buf, sizeof buf, "%.10g,%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.6g,%.6g,%d\n",
        p.virtual_damping_Ns_per_m, p.delay_ticks, p.sim.k_crit_N_per_m,
        p.sim.k_stable_N_per_m, p.sim.k_unstable_N_per_m,
        p.k_crit_exact_N_per_m, p.k_crit_mujoco_euler_N_per_m,
        p.k_bound_gil_N_per_m, p.k_passivity_N_per_m,
        p.sim.k_crit_N_per_m / p.k_crit_exact_N_per_m - 1.0,
        p.sim.k_crit_N_per_m / p.k_bound_gil_N_per_m - 1.0, p.sim.runs);
    out += buf;
  }
  return out;
}

namespace {

// the delays of the map, in the order its points first give them
std::vector<int> map_delays(const std::vector<MapPoint>& points) {
  std::vector<int> delays;
  for (const MapPoint& p : points) {
    if (std::find(delays.begin(), delays.end(), p.delay_ticks) ==
        delays.end()) {
      delays.push_back(p.delay_ticks);
    }
  }
  return delays;
}

// For delay n, in `color`: the simulated K_crit as markers, the exact
// discrete boundary as a line and Gil et al.'s bound dashed, against B.
void add_delay_series(const std::vector<MapPoint>& points, int n,
                      const std::string& color, output::Chart* c) {
  const std::string tag = "n = " + std::to_string(n);
  output::ChartSeries sim, exact, gil;
  sim.label = "simulated, " + tag;
  sim.line = false;
  exact.label = "exact discrete, " + tag;
  exact.markers = false;
  gil.label = "Gil et al. (b+B)/(T/2+nT), " + tag;
  gil.markers = false;
  gil.dashed = true;
  sim.color = exact.color = gil.color = color;
  for (const MapPoint& p : points) {
    if (p.delay_ticks != n) continue;
    const double B = p.virtual_damping_Ns_per_m;
    sim.x.push_back(B);
    sim.y.push_back(p.sim.k_crit_N_per_m);
    exact.x.push_back(B);
    exact.y.push_back(p.k_crit_exact_N_per_m);
    gil.x.push_back(B);
    gil.y.push_back(p.k_bound_gil_N_per_m);
  }
  c->series.push_back(sim);
  c->series.push_back(exact);
  c->series.push_back(gil);
}

// Colgate and Schenkel's passivity bound 2(b-B)/T where it is >= 0, from
// the points of delay n (it does not depend on the delay), closed at B = b
// where it reaches 0 if the map goes that far. *B_max: the map's largest B.
output::ChartSeries passivity_series(const std::vector<MapPoint>& points,
                                     int n, double b, double* B_max) {
  output::ChartSeries passive;
  passive.label = "passivity 2(b-B)/T (Colgate & Schenkel)";
  passive.markers = false;
  passive.dashed = true;
  passive.color = "#888888";
  *B_max = 0.0;
  for (const MapPoint& p : points) {
    *B_max = std::max(*B_max, p.virtual_damping_Ns_per_m);
    if (p.delay_ticks != n || p.k_passivity_N_per_m < 0.0) {
      continue;
    }
    passive.x.push_back(p.virtual_damping_Ns_per_m);
    passive.y.push_back(p.k_passivity_N_per_m);
  }
  if (b <= *B_max && (passive.x.empty() || passive.x.back() < b)) {
    passive.x.push_back(b);
    passive.y.push_back(0.0);
  }
  return passive;
}

// The passivity line, drawn when it reaches a visible length: with b small
// against the map's B range (the Omni's 0.028 of 8 N s/m, or 2 of 100 for
// 1 kg) the whole line (B from 0 to b) is 2% of both axes or less, a few
// pixels hidden under the first markers, so a legend entry would name a
// line no one can see. Then the subtitle gives its end points instead.
void add_passivity(const output::ChartSeries& passive, double B_max,
                   const StabilityParams& base, output::Chart* c) {
  const double b = base.damping_Ns_per_m;
  double K_max = 0.0;
  for (const output::ChartSeries& s : c->series) {
    for (double k : s.y) K_max = std::max(K_max, k);
  }
  double x_span = 0.0, y_span = 0.0;
  if (!passive.x.empty()) {
    const auto [x_lo, x_hi] =
        std::minmax_element(passive.x.begin(), passive.x.end());
    const auto [y_lo, y_hi] =
        std::minmax_element(passive.y.begin(), passive.y.end());
    x_span = *x_hi - *x_lo;
    y_span = *y_hi - *y_lo;
  }
  constexpr double kVisible = 0.05;  // of an axis' data range, ~20 px
  if (x_span >= kVisible * B_max || y_span >= kVisible * K_max) {
    c->series.push_back(passive);
  } else if (!passive.x.empty()) {
    char note[200];
    std::snprintf(note, sizeof note,
                  "passivity bound 2(b-B)/T: %.4g N/m at B = 0, 0 at B = b = "
                  "%.3g N s/m (too short to draw)",
                  2.0 * b / base.servo_period_s, b);
    c->subtitle = note;
  }
}

}  // namespace

std::string stability_map_svg(const std::vector<MapPoint>& points,
                              const StabilityParams& base) {
  // one colour per delay; the three series of a delay share it
  static const char* const kColors[] = {"#1f77b4", "#d62728", "#2ca02c",
                                        "#9467bd", "#ff7f0e", "#8c564b"};
  const std::vector<int> delays = map_delays(points);
  output::Chart c;
  char title[256];
  std::snprintf(title, sizeof title,
                "K_crit of the sampled wall: m = %g kg, b = %g N s/m, "
                "T = %g ms, h = %g us",
                base.mass_kg, base.damping_Ns_per_m,
                1e3 * base.servo_period_s, 1e6 * base.physics_step_s);
  c.title = title;
  c.x.label = "virtual damping B (N s/m)";
  c.y.label = "critical stiffness K_crit (N/m)";
  c.y.min = 0.0;  // the passivity bound goes negative for B > b
  c.width_px = 860;
  c.height_px = 500;
  for (std::size_t i = 0; i < delays.size(); ++i) {
    add_delay_series(points, delays[i],
                     kColors[i % (sizeof kColors / sizeof *kColors)], &c);
  }
  // the bound from the first delay's points (any n: without points, none)
  double B_max = 0.0;
  const output::ChartSeries passive =
      passivity_series(points, delays.empty() ? 0 : delays.front(),
                       base.damping_Ns_per_m, &B_max);
  add_passivity(passive, B_max, base, &c);
  return output::chart_svg(c);
}

nlohmann::ordered_json stability_json(const StabilityResult& r) {
  return r.is_map() ? map_json(r) : bisection_json(r);
}

std::vector<std::string> write_stability_files(const StabilityResult& r,
                                               const std::string& out_dir) {
  if (r.is_map()) {
    return {output::write_file_in(out_dir, "stability_map.csv",
                                  stability_map_csv(r.map)),
            output::write_file_in(out_dir, "stability_map.svg",
                                  stability_map_svg(r.map, r.options.params))};
  }
  return {output::write_file_in(out_dir, "stability_bisection.csv",
                                bisection_csv(r.bisection)),
          output::write_file_in(out_dir, "stability_bisection.svg",
                                output::chart_svg(bisection_chart(r.bisection)))};
}

}  // namespace vmh::studies
