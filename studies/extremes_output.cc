// The extreme-cases study's outputs: the JSON the command line prints and
// extremes.json holds, the tables (CSV, units in the column names) and the
// figure of the passivity observer, one panel per scenario (output/'s chart).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "output/output_file.h"
#include "output/svg_chart.h"
#include "studies/extremes_study.h"

namespace vmh::studies {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace fs = std::filesystem;
namespace {

// a CSV cell: quoted (quotes doubled) when it holds a comma, quote or newline
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// names as one CSV cell, space-separated
std::string csv_list(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : " ") + n;
  return csv_field(s);
}

// the outcome's colour in the figure: green ok, orange a limit cycle, blue
// a detected fault, purple an undetected one, red a failure
const char* outcome_colour(const std::string& outcome) {
  if (outcome == "ok") return "#2e7d32";
  if (outcome == "limit_cycle") return "#e65100";
  if (outcome.rfind("fault_detected", 0) == 0) return "#1565c0";
  if (outcome.rfind("fault_undetected", 0) == 0) return "#6a1b9a";
  return "#c62828";
}

// one scenario's panel: E(t) in mJ, zero and the end of the script dashed,
// the judged window shaded
output::Chart energy_panel(const ExtremeResult& r, const EnergyCurve& e) {
  const double t_end_s = r.simulated_s > 0.0 ? r.simulated_s : 1.0;
  const double script_end_s = t_end_s - kExtremeRestS;
  output::Chart c;
  c.title = r.scenario.name;
  c.subtitle = r.outcome;
  c.subtitle_color = outcome_colour(r.outcome);
  c.width_px = 300;
  c.height_px = 210;
  c.x = {"t (s)", false, 0.0, t_end_s};
  c.y = {"E (mJ)", false};
  output::ChartSeries curve;
  curve.color = "#1565c0";
  curve.markers = false;
  double lo_mJ = 0.0, hi_mJ = 0.0;  // zero always shows
  for (std::size_t k = 0; k < e.t_s.size(); ++k) {
    curve.x.push_back(e.t_s[k]);
    curve.y.push_back(1e3 * e.energy_J[k]);
    lo_mJ = std::min(lo_mJ, curve.y.back());
    hi_mJ = std::max(hi_mJ, curve.y.back());
  }
  output::ChartSeries zero, script_end;
  for (output::ChartSeries* s : {&zero, &script_end}) {
    s->color = "#999999";
    s->markers = false;
    s->dashed = true;
  }
  zero.x = {0.0, t_end_s};
  zero.y = {0.0, 0.0};
  script_end.x = {script_end_s, script_end_s};
  script_end.y = {lo_mJ, hi_mJ};
  c.series = {zero, script_end, curve};
  c.bands.push_back({t_end_s - kRestWindowS, t_end_s});
  return c;
}

}  // namespace

nlohmann::json extreme_result_json(const ExtremeResult& r) {
  const ExtremeScenario& s = r.scenario;
  auto v3 = [](const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  return {
      {"name", s.name},
      {"base", s.base},
      {"overrides", s.overrides},
      {"stresses", s.stresses},
      {"injected_fault", s.injected},
      {"expected_status", s.expected},
      {"outcome", r.outcome},
      {"pass", r.pass()},
      {"simulated_s", r.simulated_s},
      {"ticks", r.ticks},
      {"wall_time_s", r.wall_time_s},
      {"finite", r.finite},
      {"first_nonfinite", r.first_nonfinite},
      {"nonfinite_reading_ticks", r.nonfinite_reading_ticks},
      {"force_limit_N", r.force_limit_N},
      {"max_force_N", r.max_force_N},
      {"motor_limit_Nm", v3(r.motor_limit_Nm)},
      {"max_motor_torque_Nm", v3(r.max_motor_torque_Nm)},
      {"force_within_limit", r.force_within_limit},
      {"torque_within_limit", r.torque_within_limit},
      {"energy",
       {{"motor_max_J", r.energy_motor_max_J},
        {"motor_min_J", r.energy_motor_min_J},
        {"motor_final_J", r.energy_motor_final_J},
        {"hand_final_J", r.energy_hand_final_J},
        {"kinetic_max_J", r.kinetic_max_J},
        {"rest_rise_J", r.rest_energy_rise_J},
        {"rest_rise_bound_J", kRestEnergyRiseBoundJ},
        {"rest_kinetic_max_J", r.rest_kinetic_max_J},
        {"bounded", r.energy_bounded},
        {"passive", r.passive},
        {"passive_tolerance_J", kPassiveToleranceJ},
        {"expected", r.energy_expected},
        {"expected_why", s.energy_why}}},
      {"colgate",
       {{"demand_Ns_per_m", r.colgate_demand_Ns_per_m},
        {"b_Ns_per_m", r.colgate_b_Ns_per_m},
        {"passive", r.colgate_passive}}},
      {"statuses", r.statuses},
      {"device_errors", r.device_errors},
      {"guard_faults", r.guard_faults},
      {"zeroed_ticks", r.zeroed_ticks},
      {"mujoco_warnings", r.mujoco_warnings},
      {"fault_tick", r.fault_tick},
      {"detection_tick", r.detection_tick},
      {"detection_latency_ticks",
       r.fault_tick >= 0 && r.detection_tick >= 0 ? r.detection_tick - r.fault_tick : -1},
      {"max_torque_after_detection_Nm", r.max_torque_after_detection_Nm},
      {"reached",
       {{"min_pivot_distance_mm", r.min_pivot_distance_mm},
        {"orientation_wraps", r.orientation_wraps},
        {"min_q5_to_singular_rad", r.min_q5_to_singular_rad},
        {"min_pole_angle_rad", r.min_pole_angle_rad},
        {"max_reach_fraction", r.max_reach_fraction},
        {"max_encoder_speed_rad_s", r.max_encoder_speed_rad_s},
        {"min_period_s", r.min_period_s},
        {"max_period_s", r.max_period_s},
        {"mean_period_s", r.mean_period_s}}},
  };
}

std::string extremes_csv(const std::vector<ExtremeResult>& results) {
  std::string s =
      "name,base,injected_fault,expected_status,outcome,finite,max_force_N,"
      "force_limit_N,max_tau_1_Nm,max_tau_2_Nm,max_tau_3_Nm,"
      "energy_motor_max_J,energy_motor_min_J,energy_motor_final_J,"
      "rest_energy_rise_J,energy_hand_final_J,kinetic_max_J,"
      "rest_kinetic_max_J,energy_bounded,passive,energy_expected,"
      "colgate_demand_Ns_per_m,colgate_b_Ns_per_m,statuses,device_errors,guard_faults,zeroed_ticks,"
      "mujoco_warnings,detection_latency_ticks,min_pivot_distance_mm,"
      "min_pole_angle_rad,orientation_wraps,min_q5_to_singular_rad,"
      "max_reach_fraction,max_encoder_speed_rad_s,min_period_s,max_period_s,"
      "simulated_s,ticks,wall_time_s\n";
  char buf[640];
  for (const ExtremeResult& r : results) {
    s += csv_field(r.scenario.name) + "," + r.scenario.base + "," +
         r.scenario.injected + "," + r.scenario.expected + "," +
         csv_field(r.outcome) + "," + (r.finite ? "1" : "0") + ",";
    std::snprintf(buf, sizeof buf,
                  "%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,"
                  "%.6g,%d,%d,",
                  r.max_force_N, r.force_limit_N, r.max_motor_torque_Nm[0],
                  r.max_motor_torque_Nm[1], r.max_motor_torque_Nm[2],
                  r.energy_motor_max_J, r.energy_motor_min_J,
                  r.energy_motor_final_J, r.rest_energy_rise_J,
                  r.energy_hand_final_J, r.kinetic_max_J, r.rest_kinetic_max_J,
                  r.energy_bounded ? 1 : 0, r.passive ? 1 : 0);
    s += buf;
    s += r.energy_expected + ",";
    std::snprintf(buf, sizeof buf, "%.6g,%.6g,", r.colgate_demand_Ns_per_m,
                  r.colgate_b_Ns_per_m);
    s += buf;
    s += csv_list(r.statuses) + "," +
         csv_list(r.device_errors) + "," +
         csv_list(r.guard_faults) + ",";
    std::snprintf(buf, sizeof buf,
                  "%d,%d,%d,%.6g,%.6g,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%.6g\n",
                  r.zeroed_ticks, r.mujoco_warnings,
                  r.fault_tick >= 0 && r.detection_tick >= 0
                      ? r.detection_tick - r.fault_tick
                      : -1,
                  r.min_pivot_distance_mm, r.min_pole_angle_rad,
                  r.orientation_wraps, r.min_q5_to_singular_rad,
                  r.max_reach_fraction, r.max_encoder_speed_rad_s,
                  r.min_period_s, r.max_period_s, r.simulated_s, r.ticks,
                  r.wall_time_s);
    s += buf;
  }
  return s;
}

std::string extreme_series_csv(const std::vector<TickRecord>& rows) {
  std::string s =
      "t_s,period_s,F_N,tau_1_Nm,tau_2_Nm,tau_3_Nm,energy_motor_J,"
      "energy_hand_J,kinetic_J,d_pivot_mm,status,read,guard\n";
  s.reserve(rows.size() * 160);
  char buf[320];
  for (const TickRecord& r : rows) {
    std::snprintf(buf, sizeof buf,
                  "%.6f,%.6g,%.6g,%.6g,%.6g,%.6g,%.9g,%.9g,%.9g,%.6g,%u,%s,%s\n",
                  r.t_s, r.period_s, r.out.force_device_N.norm(),
                  r.motor_torque_Nm[0], r.motor_torque_Nm[1], r.motor_torque_Nm[2],
                  r.energy_motor_J, r.energy_hand_J, r.kinetic_J,
                  r.p_true_mm.norm(), static_cast<unsigned>(r.out.status),
                  device_error_name(r.servo.read), guard_fault_name(r.guard));
    s += buf;
  }
  return s;
}

EnergyCurve thin_energy(const std::vector<TickRecord>& rows, std::size_t buckets) {
  EnergyCurve e;
  const std::size_t stride =
      std::max<std::size_t>(1, rows.size() / std::max<std::size_t>(1, buckets));
  for (std::size_t k0 = 0; k0 < rows.size(); k0 += stride) {
    const std::size_t k1 = std::min(rows.size(), k0 + stride);
    std::size_t lo = k0, hi = k0;
    for (std::size_t k = k0; k < k1; ++k) {
      if (rows[k].energy_motor_J < rows[lo].energy_motor_J) lo = k;
      if (rows[k].energy_motor_J > rows[hi].energy_motor_J) hi = k;
    }
    // one point where the lowest and highest are the same row (a flat
    // bucket, or a bucket of one row)
    const std::size_t first = std::min(lo, hi), last = std::max(lo, hi);
    e.t_s.push_back(rows[first].t_s);
    e.energy_J.push_back(rows[first].energy_motor_J);
    if (last != first) {
      e.t_s.push_back(rows[last].t_s);
      e.energy_J.push_back(rows[last].energy_motor_J);
    }
  }
  return e;
}

output::ChartGrid extremes_figure(const ExtremesResult& r) {
  output::ChartGrid g;
  g.title = "Extreme cases: the passivity observer E(t), energy the motors "
            "put into the device (mJ)";
  char note[240];
  std::snprintf(note, sizeof note,
                "t from 0 to the end of the rest; dashed vertical: end of the "
                "script; grey: the window judged (E may rise at most %.3g mJ "
                "there); under each name: its outcome",
                1e3 * kRestEnergyRiseBoundJ);
  g.notes = {note};
  g.columns = 5;
  for (std::size_t i = 0; i < r.scenarios.size(); ++i) {
    g.panels.push_back(energy_panel(r.scenarios[i], r.energy[i]));
  }
  return g;
}

nlohmann::json extremes_json(const ExtremesResult& r) {
  nlohmann::json scenarios = nlohmann::json::array();
  for (const ExtremeResult& s : r.scenarios) {
    scenarios.push_back(extreme_result_json(s));
  }
  return {
      {"study", "extremes"},
      {"duration_s", kExtremeDurationS},
      {"rest_s", kExtremeRestS},
      {"bounds",
       {{"rest_s", kExtremeRestS},
        {"rest_window_s", kRestWindowS},
        {"rest_energy_rise_bound_J", kRestEnergyRiseBoundJ},
        {"passive_tolerance_J", kPassiveToleranceJ}}},
      {"scenarios", scenarios},
      {"all_pass", r.all_pass()},
      {"wall_time_s", r.wall_time_s},
  };
}

std::vector<std::string> write_extremes_files(const ExtremesResult& r,
                                              const std::string& out_dir) {
  const fs::path dir(out_dir);
  const std::vector<std::string> files = {(dir / "extremes.csv").string(),
                                          (dir / "extremes.json").string(),
                                          (dir / "extremes.svg").string()};
  output::write_file_atomically(files[0], extremes_csv(r.scenarios));
  output::write_file_atomically(files[1], extremes_json(r).dump(2) + "\n");
  output::write_file_atomically(files[2],
                                output::chart_grid_svg(extremes_figure(r)));
  return files;
}

}  // namespace vmh::studies
