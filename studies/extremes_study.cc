#include "studies/extremes_study.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <set>
#include <sstream>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "output/output_file.h"
#include "output/parallel.h"
#include "thesis/run_case.h"

namespace vmh::studies {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace fs = std::filesystem;
namespace {

using constants::kPi;

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

// every output of a tick that must stay finite (the reading itself may be
// NaN by injection and is checked apart)
const char* nonfinite_part(const TickRecord& r) {
  const ControlOutput& o = r.out;
  if (!o.force_device_N.allFinite()) return "force_device_N";
  if (!o.tau_motor_Nm.allFinite()) return "tau_motor_Nm";
  if (!o.f_motion.allFinite()) return "f_motion";
  if (!o.e.allFinite()) return "e";
  if (!o.e_dot.allFinite()) return "e_dot";
  if (!o.x_v_mm.allFinite()) return "x_v_mm";
  if (!o.x_r_mm.allFinite()) return "x_r_mm";
  if (!o.p_rm_mm.allFinite()) return "p_rm_mm";
  if (!o.axis_rm.allFinite()) return "axis_rm";
  if (!o.theta_v.allFinite()) return "theta_v";
  if (!o.theta_r.allFinite()) return "theta_r";
  if (!r.motor_torque_Nm.allFinite()) return "motor_torque_Nm";
  if (!r.hand_force_N.allFinite()) return "hand_force_N";
  if (!r.p_true_mm.allFinite()) return "p_true_mm";
  if (!std::isfinite(r.energy_motor_J) || !std::isfinite(r.energy_hand_J) ||
      !std::isfinite(r.kinetic_J)) {
    return "energy";
  }
  if (!r.state_finite) return "mujoco_state";
  return nullptr;
}

}  // namespace

namespace {

// The force limit and the motors' torque clamps (ctrlrange of m1..m3).
void read_limits(const ClosedLoop& loop, ExtremeResult* r) {
  const mjModel* m = loop.model();
  r->force_limit_N = loop.controller_params().force_limit_N;
  for (int i = 0; i < 3; ++i) {
    const int a = mj_name2id(m, mjOBJ_ACTUATOR, ("m" + std::to_string(i + 1)).c_str());
    r->motor_limit_Nm[i] = m->actuator_ctrlrange[2 * a + 1];
  }
}

// Ticks the loop until end_s, a row per tick; the wall time and the ticks
// go in r.
void run_ticks(ClosedLoop* loop, double end_s, std::vector<TickRecord>* rows,
               ExtremeResult* r, const runtime::StopFn& stop) {
  const mjModel* m = loop->model();
  rows->clear();
  rows->reserve(static_cast<std::size_t>(loop->ticks_per_run()));
  const auto start = std::chrono::steady_clock::now();
  while (loop->time_s() < end_s - 0.5 * m->opt.timestep) {
    runtime::throw_if_stop_asked(stop);
    rows->emplace_back();
    loop->tick(&rows->back());
  }
  r->wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r->simulated_s = loop->time_s();
  r->ticks = static_cast<int>(rows->size());
}

// What every tick adds to the result: the four counts' raw material, and
// what the scenario reached.
class TickScan {
 public:
  TickScan(const ClosedLoop& loop, double end_s, ExtremeResult* r)
      : params_(loop.controller_params()),
        r_(r),
        shoulder_mm_(base_to_device_mm(params_.omni, Vec3::Zero())),
        reach_mm_(1000.0 * (params_.omni.l1_m + params_.omni.l2_m)),
        window_from_s_(end_s - kRestWindowS),
        pole_axis_(params_.vm.R_pivot.col(2)) {
    r_->energy_motor_max_J = r_->energy_motor_min_J = 0.0;
    r_->min_pivot_distance_mm = 1e300;
    r_->min_q5_to_singular_rad = 1e300;
    r_->min_period_s = 1e300;
    r_->min_pole_angle_rad = 1e300;
  }

  void add(const std::vector<TickRecord>& rows, std::size_t k) {
    const TickRecord& row = rows[k];
    finite(row);
    command(row);
    statuses(row, static_cast<int>(k));
    energy(row);
    reached(row, k > 0 ? &rows[k - 1] : nullptr);
  }

  // the mean period, and the names seen, sorted
  void finish(std::size_t ticks) {
    r_->mean_period_s = ticks == 0 ? 0.0 : period_sum_ / static_cast<double>(ticks);
    for (int b = 0; b < kStatusFlagCount; ++b) {
      if (seen_ & (1u << b)) statuses_.insert(status_flag_name(1u << b));
    }
    r_->statuses.assign(statuses_.begin(), statuses_.end());
    r_->device_errors.assign(device_errors_.begin(), device_errors_.end());
    r_->guard_faults.assign(guard_faults_.begin(), guard_faults_.end());
  }

  // whether the rest's last window was reached
  bool in_window() const { return in_window_; }

 private:
  void finite(const TickRecord& row) {
    if (r_->finite) {
      if (const char* part = nonfinite_part(row)) {
        r_->finite = false;
        char buf[96];
        std::snprintf(buf, sizeof buf, "%s at t = %.4f s", part, row.t_s);
        r_->first_nonfinite = buf;
      }
    }
    if (!row.q_dh.allFinite()) ++r_->nonfinite_reading_ticks;
  }

  // the command as the controller computed it and as the motors held it
  void command(const TickRecord& row) {
    r_->max_force_N = std::max(r_->max_force_N, row.out.force_device_N.norm());
    for (int i = 0; i < 3; ++i) {
      r_->max_motor_torque_Nm[i] =
          std::max(r_->max_motor_torque_Nm[i], std::abs(row.motor_torque_Nm[i]));
    }
  }

  void statuses(const TickRecord& row, int tick) {
    if (row.servo.read == DeviceError::kOk) seen_ |= row.out.status;
    if (row.servo.read != DeviceError::kOk) device_errors_.insert(device_error_name(row.servo.read));
    if (row.servo.write != DeviceError::kOk) device_errors_.insert(device_error_name(row.servo.write));
    if (row.guard != GuardFault::kNone) guard_faults_.insert(guard_fault_name(row.guard));
    if (row.servo.zeroed) ++r_->zeroed_ticks;
    const bool fault_named = row.servo.read != DeviceError::kOk ||
                             (row.servo.read == DeviceError::kOk && is_fault(row.out.status));
    if (row.fault_injected && r_->fault_tick < 0) r_->fault_tick = tick;
    if (r_->fault_tick >= 0 && r_->detection_tick < 0 && fault_named) r_->detection_tick = tick;
    if (r_->detection_tick >= 0 && tick >= r_->detection_tick) {
      r_->max_torque_after_detection_Nm =
          std::max(r_->max_torque_after_detection_Nm, row.motor_torque_Nm.cwiseAbs().maxCoeff());
    }
  }

  void energy(const TickRecord& row) {
    const double E = row.energy_motor_J;
    r_->energy_motor_max_J = std::max(r_->energy_motor_max_J, E);
    r_->energy_motor_min_J = std::min(r_->energy_motor_min_J, E);
    r_->kinetic_max_J = std::max(r_->kinetic_max_J, row.kinetic_J);
    if (row.t_s >= window_from_s_) {
      if (!in_window_) {
        in_window_ = true;
        window_start_J_ = prev_end_J_;
      }
      r_->rest_energy_rise_J = std::max(r_->rest_energy_rise_J, E - window_start_J_);
      r_->rest_kinetic_max_J = std::max(r_->rest_kinetic_max_J, row.kinetic_J);
    }
    prev_end_J_ = E;
    r_->energy_motor_final_J = E;
    r_->energy_hand_final_J = row.energy_hand_J;
  }

  // what the scenario reached, from MuJoCo's true angles
  void reached(const TickRecord& row, const TickRecord* prev) {
    const Vec3 from_pivot = row.p_true_mm - params_.vm.pivot_mm;
    r_->min_pivot_distance_mm = std::min(r_->min_pivot_distance_mm, from_pivot.norm());
    if (from_pivot.norm() > 1e-9) {
      const double c = std::abs(from_pivot.normalized().dot(pole_axis_));
      r_->min_pole_angle_rad = std::min(r_->min_pole_angle_rad, std::acos(std::min(1.0, c)));
    }
    r_->max_reach_fraction =
        std::max(r_->max_reach_fraction, (row.p_true_mm - shoulder_mm_).norm() / reach_mm_);
    r_->min_q5_to_singular_rad = std::min(
        r_->min_q5_to_singular_rad, std::abs(0.5 * kPi - std::abs(wrap_angle(row.q_true_dh[4]))));
    if (prev != nullptr) {
      // encoder speeds over the previous tick, device joints t1..t3
      const Joints dq = dh_to_device_joints(row.q_true_dh) - dh_to_device_joints(prev->q_true_dh);
      r_->max_encoder_speed_rad_s = std::max(
          r_->max_encoder_speed_rad_s, dq.head<3>().cwiseAbs().maxCoeff() / prev->period_s);
      const Vec6 de = row.out.e - prev->out.e;
      for (int i = 3; i < 6; ++i) {
        if (std::abs(de[i]) > kPi) {
          ++r_->orientation_wraps;
          break;
        }
      }
    }
    r_->min_period_s = std::min(r_->min_period_s, row.period_s);
    r_->max_period_s = std::max(r_->max_period_s, row.period_s);
    period_sum_ += row.period_s;
  }

  const ControllerParams& params_;
  ExtremeResult* r_;
  const Vec3 shoulder_mm_;
  const double reach_mm_;
  const double window_from_s_;  // the rest's last window starts here
  const Vec3 pole_axis_;
  std::set<std::string> statuses_, device_errors_, guard_faults_;
  ControlStatus seen_ = kStatusOk;
  double period_sum_ = 0.0;
  bool in_window_ = false;
  double window_start_J_ = 0.0;
  double prev_end_J_ = 0.0;  // the observer at the end of the last tick
};

// The limits, the energy (the observer, and Colgate & Schenkel's bound for
// this scenario's translational gains) and what it is expected to do.
void judge(const ClosedLoop& loop, bool in_window, ExtremeResult* r) {
  r->force_within_limit = r->max_force_N <= r->force_limit_N * (1.0 + 1e-12);
  r->torque_within_limit = true;
  for (int i = 0; i < 3; ++i) {
    r->torque_within_limit &= r->max_motor_torque_Nm[i] <= r->motor_limit_Nm[i] * (1.0 + 1e-12);
  }
  r->passive = r->energy_motor_max_J <= kPassiveToleranceJ;
  r->energy_bounded = in_window && r->rest_energy_rise_J <= kRestEnergyRiseBoundJ;

  // Colgate & Schenkel's bound for this scenario's translational gains
  const CaseConfig& c = loop.config();
  const double T_max_s = loop.substeps_max() * loop.model()->opt.timestep;
  r->colgate_demand_Ns_per_m = 1000.0 * c.controller.k_pos_N_per_mm * T_max_s / 2.0 +
                              1000.0 * std::abs(c.controller.k_vel_Ns_per_mm);
  // an anisotropic hand: its least damped axis
  r->colgate_b_Ns_per_m = c.hand.b_pos_axes_Ns_per_m.isZero(0.0)
                              ? c.hand.b_pos_Ns_per_m
                              : c.hand.b_pos_axes_Ns_per_m.minCoeff();
  r->colgate_passive = r->colgate_b_Ns_per_m > r->colgate_demand_Ns_per_m;
  r->energy_expected = r->scenario.energy;
  if (r->energy_expected == "bounded" && !r->colgate_passive) r->energy_expected = "either";
}

// ok, limit_cycle, fault_detected:<name>, fault_undetected:<fault> or
// failed:<reasons> (ExtremeResult::outcome)
std::string outcome_of(const ExtremeResult& r) {
  const ExtremeScenario& s = r.scenario;
  std::vector<std::string> failures;
  if (!r.finite) failures.push_back("nonfinite");
  if (!r.force_within_limit) failures.push_back("force_above_limit");
  if (!r.torque_within_limit) failures.push_back("torque_above_limit");
  if (!r.energy_bounded && r.energy_expected == "bounded") {
    failures.push_back("energy_unbounded");
  }
  if (r.mujoco_warnings > 0) failures.push_back("mujoco_warning");
  std::vector<std::string> named = r.statuses;
  named.insert(named.end(), r.device_errors.begin(), r.device_errors.end());
  named.insert(named.end(), r.guard_faults.begin(), r.guard_faults.end());
  const auto has = [&named](const std::string& n) {
    return std::find(named.begin(), named.end(), n) != named.end();
  };
  if (!s.expected.empty() && !has(s.expected)) failures.push_back("missing_status:" + s.expected);
  // a fault named where none was injected is a false alarm
  const bool any_fault_named = !r.device_errors.empty() || !r.guard_faults.empty() ||
                               has("invalid_input") || has("numerical_fault");
  if (s.injected == "none" && any_fault_named) failures.push_back("false_alarm");

  if (!failures.empty()) return "failed:" + join(failures, "+");
  if (s.injected != "none") {
    if (r.detection_tick < 0) return "fault_undetected:" + s.injected;
    const std::string what = !r.guard_faults.empty() ? r.guard_faults.front()
                             : has("invalid_input") ? "invalid_input"
                             : !r.device_errors.empty() ? r.device_errors.front()
                                                        : "fault";
    return "fault_detected:" + what;
  }
  return r.energy_bounded ? "ok" : "limit_cycle";
}

// the table, or the scenarios named in `only` in that order; SimError for
// an unknown name, listing the known ones
std::vector<ExtremeScenario> pick_scenarios(const std::vector<std::string>& only) {
  const std::vector<ExtremeScenario> table = extreme_scenarios();
  if (only.empty()) return table;
  std::vector<ExtremeScenario> picked;
  for (const std::string& n : only) {
    auto it = std::find_if(table.begin(), table.end(),
                           [&n](const ExtremeScenario& s) { return s.name == n; });
    if (it == table.end()) {
      std::string names;
      for (const ExtremeScenario& s : table) names += (names.empty() ? "" : ", ") + s.name;
      throw SimError("unknown extreme scenario '" + n + "' (known: " + names + ")");
    }
    picked.push_back(*it);
  }
  return picked;
}

}  // namespace

ExtremeResult run_extreme(const ExtremeScenario& s,
                          std::vector<TickRecord>* trace,
                          const runtime::StopFn& stop) {
  ExtremeResult r;
  r.scenario = s;
  std::string name;
  const std::string scene = sim::resolve_scene(s.base, &name);
  std::vector<std::string> sets = {
      "duration_s=" + std::to_string(kExtremeDurationS),
      std::string("integrator=") + kExtremeIntegrator};
  sets.insert(sets.end(), s.overrides.begin(), s.overrides.end());
  ClosedLoop loop(scene, sets);
  read_limits(loop, &r);
  const double script_end_s = loop.config().sim.duration_s;
  const double end_s = script_end_s + kExtremeRestS;

  std::vector<TickRecord> local;
  std::vector<TickRecord>& rows = trace != nullptr ? *trace : local;
  run_ticks(&loop, end_s, &rows, &r, stop);

  TickScan scan(loop, end_s, &r);
  for (std::size_t k = 0; k < rows.size(); ++k) scan.add(rows, k);
  scan.finish(rows.size());
  for (int i = 0; i < mjNWARNING; ++i) r.mujoco_warnings += loop.data()->warning[i].number;

  judge(loop, scan.in_window(), &r);
  r.outcome = outcome_of(r);
  return r;
}

ExtremesResult run_extremes_study(const ExtremesOptions& o) {
  const std::vector<ExtremeScenario> table = pick_scenarios(o.only);
  // the series' set (out_dir/extremes, made beside it and put in place at
  // the end); out_dir itself, if this run makes it, is removed again (if
  // still empty) when the study stops or fails before writing
  struct RemoveIfMadeHere {
    std::string dir;
    bool keep = false;
    ~RemoveIfMadeHere() {
      std::error_code ignored;
      if (!keep && !dir.empty()) fs::remove(dir, ignored);  // only if empty
    }
  } made_here;
  std::unique_ptr<output::OutputSet> series;
  if (!o.out_dir.empty()) {
    std::error_code ec;
    if (!fs::exists(o.out_dir, ec)) made_here.dir = o.out_dir;
    try {
      series = std::make_unique<output::OutputSet>(
          (fs::path(o.out_dir) / "extremes").string());
    } catch (const std::runtime_error& e) {
      throw SimError(o.out_dir + ": " + e.what());
    }
  }
  // the scenarios are independent: run them on `jobs` threads (each loop's
  // hand is registered for its own mjData, and model loading is
  // serialised), each keeping its time series only as long as it needs it
  ExtremesResult result;
  result.scenarios.assign(table.size(), ExtremeResult{});
  result.energy.assign(table.size(), EnergyCurve{});
  std::vector<std::string> errors(table.size());
  const auto start = std::chrono::steady_clock::now();
  std::atomic<std::size_t> finished{0};
  std::atomic<bool> stopped{false};
  output::parallel_for(table.size(), o.jobs, [&](std::size_t i) {
    // once stopped, the scenarios not begun are skipped
    if (stopped || runtime::stop_asked(o.should_stop)) {
      stopped = true;
      return;
    }
    std::vector<TickRecord> rows;
    try {
      result.scenarios[i] = run_extreme(table[i], &rows, o.should_stop);
      result.energy[i] = thin_energy(rows);
      if (series) series->write(table[i].name + ".csv", extreme_series_csv(rows));
    } catch (const runtime::Interrupted&) {
      stopped = true;
      return;
    } catch (const std::exception& e) {
      errors[i] = table[i].name + ": " + e.what();
    }
    if (o.progress) o.progress(++finished, table.size());
  });
  if (stopped) throw runtime::Interrupted();
  for (const std::string& e : errors) {
    if (!e.empty()) throw SimError(e);
  }
  result.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // the last poll: from here the series' folder and the three files go in
  runtime::throw_if_stop_asked(o.should_stop);
  if (series) {
    made_here.keep = true;
    series->commit();
    result.files = write_extremes_files(result, o.out_dir);
  }
  return result;
}

bool ExtremesResult::all_pass() const {
  return std::all_of(scenarios.begin(), scenarios.end(),
                     [](const ExtremeResult& r) { return r.pass(); });
}

}  // namespace vmh::studies
