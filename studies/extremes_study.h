// The stiff and extreme cases (issue 5, item 3): the closed loop driven where
// the controller, the device layer or the simulation is most likely to break,
// each run short and judged on the same four counts:
//   finite   no NaN or inf in any output of the controller, the torques, the
//            hand's force, the observer, or MuJoCo's qpos, qvel, qacc, ctrl
//   |F|      the commanded force never above force_limit_N, and the motor
//            torques never above their clamps
//   energy   the passivity observer (Hannaford & Ryu 2002, IEEE TRA 18(1)):
//            E(t), the energy the motors put into the device, stops rising
//            once the hand is still (kRestEnergyRiseBoundJ below)
//   status   what the controller's flags, the device errors and the device
//            layer's guard named, against what the scenario should make
//            them name
// A scenario is a thesis case scene plus `--set` overrides; a few overrides
// (the stylus along the forearm, the start at full reach) are computed from
// the Omni's kinematics when the table is built.
#ifndef VMHAPTICS_STUDIES_EXTREMES_STUDY_H_
#define VMHAPTICS_STUDIES_EXTREMES_STUDY_H_

#include <nlohmann/json.hpp>

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "output/svg_chart.h"
#include "sim/closed_loop.h"
#include "runtime/stop.h"

namespace vmh::studies {

struct ExtremeScenario {
  std::string name;
  std::string base;  // a thesis case (case1..case6)
  std::vector<std::string> overrides;  // name=value, after the scene's own
  std::string stresses;  // what it pushes, in a few words
  // the sensor fault it injects: none, nan, jump, stuck (the scenario's name
  // for it, not a detection)
  std::string injected = "none";
  // a name that must appear among the statuses seen (controller flags,
  // device errors, guard faults); empty: none required. For an injected
  // fault, the detection expected; an injected fault with no expected
  // detection is one the device layer is known not to see.
  std::string expected;
  // what the energy must do: "bounded" (required), or "limit_cycle" (a
  // known instability, with the reason in energy_why and a test of its own
  // in tests/studies/extremes_study_test.cc). A "bounded" scenario whose
  // translational gain breaks Colgate & Schenkel's passivity bound is
  // relaxed to "either" when it runs (ExtremeResult::energy_expected):
  // sampled-data theory then allows a limit cycle without requiring one.
  std::string energy = "bounded";
  std::string energy_why;
};

// The scenario table, in order. Each runs its script for
// kExtremeDurationS (unless its overrides set duration_s), then
// kExtremeRestS more with the hand's target held still at its last pose,
// on RK4 (kExtremeIntegrator, unless its overrides set `integrator`): the
// case scenes step with Euler, whose numerical damping of the stiff
// wrist hides part of what a stability question asks about (in
// gains_x100_sphere the loop puts 0.47 mJ into the rest window under
// Euler, below the 1 mJ bound, an "ok"; and 2.2 mJ under RK4, a limit
// cycle; docs/numerics.md).
inline constexpr double kExtremeDurationS = 6.0;
inline constexpr double kExtremeRestS = 2.0;
inline constexpr const char* kExtremeIntegrator = "rk4";
std::vector<ExtremeScenario> extreme_scenarios();

// How energy is judged (stated once, here). Over the last kRestWindowS of
// the rest, the passivity observer may rise by at most
// kRestEnergyRiseBoundJ. A loop that comes to rest when the hand does stops
// exchanging energy; one that limit-cycles or goes unstable keeps pumping it
// in (into the hand's damping), however the script before it went. The
// first second of the rest lets the hand-device transient decay (the hand's
// 135 N/m on 0.6 kg at 36% damping: time constant 0.19 s). 1 mJ is an
// estimate: about five cycles of a one-count chatter at the saturated force
// (3.3 N x 0.056 mm = 0.18 mJ per count).
inline constexpr double kRestWindowS = 1.0;
inline constexpr double kRestEnergyRiseBoundJ = 1e-3;

// Hannaford & Ryu's passivity test, reported, not required: E(t) stays at
// or below kPassiveToleranceJ at every tick (the controller never gave out
// more than it had taken in). Rounding and the encoder's quantisation let a
// spring give back a little more than it took (Abbott & Okamura 2005): 1 mJ.
inline constexpr double kPassiveToleranceJ = 1e-3;

struct ExtremeResult {
  ExtremeScenario scenario;
  double simulated_s = 0.0;
  int ticks = 0;
  double wall_time_s = 0.0;

  // -- finite --
  bool finite = true;
  std::string first_nonfinite;  // what and when, if not finite
  int nonfinite_reading_ticks = 0;  // readings that were NaN (injected)

  // -- limits --
  double force_limit_N = 0.0;
  double max_force_N = 0.0;  // largest commanded |F|, device frame
  Vec3 motor_limit_Nm = Vec3::Zero();
  Vec3 max_motor_torque_Nm = Vec3::Zero();  // largest held |tau| per motor
  bool force_within_limit = true;
  bool torque_within_limit = true;

  // -- energy (passivity observer, J) --
  double energy_motor_max_J = 0.0;    // max over t of E(t)
  double energy_motor_min_J = 0.0;    // min over t (energy taken out)
  double energy_motor_final_J = 0.0;
  double energy_hand_final_J = 0.0;   // what the hand put in
  double kinetic_max_J = 0.0;         // the mechanism's kinetic energy
  // over the rest's last kRestWindowS: the most E rose above its value at
  // the window's start, and the largest kinetic energy
  double rest_energy_rise_J = 0.0;
  double rest_kinetic_max_J = 0.0;
  // rest_energy_rise_J <= kRestEnergyRiseBoundJ
  bool energy_bounded = true;
  // Hannaford & Ryu's test: E(t) <= kPassiveToleranceJ at every tick
  bool passive = true;
  // Colgate & Schenkel (1997): a virtual spring K and damper B sampled at T
  // with a zero-order hold is passive if b > K T / 2 + |B|. Here K =
  // k_pos_N_per_mm, B = k_vel_Ns_per_mm (both per m), T the longest servo
  // period, and b the hand's translational damping hand_b_pos_Ns_per_m
  // (the Omni's own joint damping adds about 0.03 N s/m at the wrist
  // centre and is left out). Translation only: the orientation term has no
  // such bound.
  double colgate_demand_Ns_per_m = 0.0;   // K T / 2 + |B|
  double colgate_b_Ns_per_m = 0.0;        // b
  bool colgate_passive = true;
  std::string energy_expected;  // bounded, limit_cycle or either

  // -- statuses --
  std::vector<std::string> statuses;       // controller flags seen
  std::vector<std::string> device_errors;  // read or write errors seen
  std::vector<std::string> guard_faults;   // the guard's findings
  int zeroed_ticks = 0;                    // ticks that sent zero torque
  int mujoco_warnings = 0;                 // sum of d->warning counters
  // the injected fault: its first tick, and the first tick at or after it
  // whose status named a fault (-1: none)
  int fault_tick = -1;
  int detection_tick = -1;
  // the torque after detection: largest |tau| commanded from the detection
  // on, N m (0 when the fault zeroed every later tick)
  double max_torque_after_detection_Nm = 0.0;

  // -- what the scenario reached (to show it did) --
  double min_pivot_distance_mm = 0.0;  // true wrist centre to the VM pivot
  int orientation_wraps = 0;  // ticks where an orientation error row jumped by > pi
  double min_q5_to_singular_rad = 0.0;  // |pi/2 - |q5||, true angles
  // smallest angle between (wrist centre - pivot) and the pivot frame's z
  // axis, either way: the sphere's poles
  double min_pole_angle_rad = 0.0;
  double max_reach_fraction = 0.0;  // |wrist - shoulder| / (l1 + l2)
  double max_encoder_speed_rad_s = 0.0;  // true t1..t3 speeds
  double min_period_s = 0.0, max_period_s = 0.0, mean_period_s = 0.0;

  // ok, limit_cycle (energy unbounded where energy_expected allows it:
  // finite, |F| bounded, but the observer shows energy pumped in at rest),
  // fault_detected:<name>, fault_undetected:<fault>, or
  // failed:<reason>[+<reason>...]
  std::string outcome;
  bool pass() const { return outcome.rfind("failed", 0) != 0; }
};

// Runs one scenario. With `trace` non-null, fills it with every tick's row.
// Throws SimError on bad input (a bad override, an unreachable start pose),
// runtime::Interrupted when `stop` (if set, polled every tick) says so.
ExtremeResult run_extreme(const ExtremeScenario& s,
                          std::vector<TickRecord>* trace = nullptr,
                          const runtime::StopFn& stop = {});

struct ExtremesOptions {
  std::vector<std::string> only;  // scenario names, in this order; empty: all
  // where the files go (below); empty: nothing is written
  std::string out_dir;
  int jobs = 1;  // scenarios run at once, each on its own thread
  // called from the workers with (scenarios done, scenarios); not set:
  // nothing
  std::function<void(std::size_t, std::size_t)> progress;
  // polled from the workers between scenarios and every tick (studies/
  // stop.h); not set: never stops
  runtime::StopFn should_stop;
};

// The passivity observer E(t) of one scenario, thinned for the figure
// (thin_energy).
struct EnergyCurve {
  std::vector<double> t_s;
  std::vector<double> energy_J;
};

struct ExtremesResult {
  std::vector<ExtremeResult> scenarios;  // in the order run
  std::vector<EnergyCurve> energy;       // one per scenario, same order
  double wall_time_s = 0.0;              // the whole study
  // the three files written (write_extremes_files; out_dir), not the
  // series' folder beside them; extremes_json leaves them out
  std::vector<std::string> files;
  bool all_pass() const;
};

// Runs every scenario of extreme_scenarios() (or those named in `only`) on
// `jobs` threads, and, if out_dir is not empty, writes out_dir/extremes/
// <name>.csv (a time series per scenario) and the study's files
// (write_extremes_files): out_dir/extremes.csv, out_dir/extremes.json
// (extremes_json) and out_dir/extremes.svg (the observer's E(t), one panel
// per scenario), keeping the three files' paths in `files`. Throws SimError
// naming the scenario on bad input. The series go into a private folder
// beside out_dir/extremes as they are made (output::OutputSet) and replace
// that folder whole at the end, just before the three files: should_stop
// (polled last before that) throws runtime::Interrupted with nothing
// written and no folder of its own left, and out_dir/extremes then holds
// only the series of the scenarios run.
ExtremesResult run_extremes_study(const ExtremesOptions& options);

// ---------------------------------------------------------------- output
// (extremes_output.cc)

// what extremes.json holds: the bounds, every scenario, all_pass
nlohmann::json extremes_json(const ExtremesResult& r);
nlohmann::json extreme_result_json(const ExtremeResult& r);
// the CSV's header and one row per result
std::string extremes_csv(const std::vector<ExtremeResult>& results);
// one scenario's time series, a row per tick: what the observer and the
// command did (extremes/<name>.csv)
std::string extreme_series_csv(const std::vector<TickRecord>& rows);
// E(t) thinned to about `buckets` buckets, each drawn by its lowest and
// highest point in time order, so that no peak or dip is lost to the
// thinning (the table's max and min are the curve's)
EnergyCurve thin_energy(const std::vector<TickRecord>& rows,
                        std::size_t buckets = 400);
// the figure: one panel per scenario, E(t) in mJ over the whole run, the
// end of the script dashed, the rest window the study judges shaded, the
// outcome under the name in its colour
output::ChartGrid extremes_figure(const ExtremesResult& r);
// out_dir/extremes.csv, extremes.json and extremes.svg, each replaced
// whole (not the per-scenario series, which run_extremes_study puts in);
// returns their paths
std::vector<std::string> write_extremes_files(const ExtremesResult& r,
                                              const std::string& out_dir);

}  // namespace vmh::studies

#endif  // VMHAPTICS_STUDIES_EXTREMES_STUDY_H_
