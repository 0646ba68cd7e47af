// Work-precision study of the closed loop (issue 5, item 1): for each
// integrator MuJoCo 2.2.2 offers and a ladder of physics steps h, how far the
// stylus's trajectory is from a reference run, and what the run costs.
//
// Every run is the case's own closed loop (ClosedLoop: hand, controller,
// torque held over each servo tick), over the first `duration_s` of the
// case's script, with the sensor quantisation off (quantize=0) so that the
// readings are a smooth function of the state and the integrators' orders
// can show, and with MuJoCo's Newton constraint solver whatever the scene
// sets (the case scenes' PGS stops on a tolerance; over a fine rung's many
// steps its residual would hide the integrators' error). The trajectory is the true wrist centre (omni_fk of MuJoCo's
// joint angles, device frame, mm) and the stylus axis at the end of every
// servo tick; runs are compared tick by tick with the reference, RK4 at a
// step far below the ladder's smallest. A second reference, at a coarser
// step, bounds the reference's own error.
//
// The order fitted per integrator is the least-squares slope of
// log(rms error) against log(h) over the rungs whose error stands clear of
// the reference's own error (kFloorFactor times it) and whose run stayed
// finite; the rungs used are listed.
#ifndef VMHAPTICS_STUDIES_PRECISION_STUDY_H_
#define VMHAPTICS_STUDIES_PRECISION_STUDY_H_

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "controller/types.h"
#include "sim/hand_script.h"
#include "output/progress.h"
#include "output/svg_chart.h"
#include "studies/modelling_spread.h"
#include "runtime/stop.h"

namespace vmh::studies {

// MuJoCo 2.2.2's integrators: mjINT_EULER (semi-implicit, joint damping
// implicit), mjINT_RK4 (needs mj_step: mj_step2 falls back to Euler), and
// mjINT_IMPLICIT (implicit in velocity). docs/sources.md §12.
enum class Integrator { kEuler, kImplicit, kRk4 };

// "euler", "implicit", "rk4": the case field `integrator`'s values
const char* integrator_name(Integrator i);
// false for anything else
bool parse_integrator(const std::string& name, Integrator* out);

struct PrecisionOptions {
  std::string name;                     // the case's name, for the JSON
  std::string scene;                    // scene file (resolve_scene)
  std::vector<std::string> overrides;   // further name=value settings
  double duration_s = 3.0;              // simulated, from the script's start
  std::vector<Integrator> integrators = {Integrator::kEuler,
                                         Integrator::kImplicit,
                                         Integrator::kRk4};
  // the ladder; each must divide the servo period. The scene's own step is
  // added for its own integrator if missing, so the default is always a row.
  std::vector<double> steps_s = {1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5};
  double reference_step_s = 2e-6;        // RK4
  double reference_check_step_s = 4e-6;  // RK4, bounds the reference's error
  // a run is repeated while the repeats took less than this, up to
  // max_repeats, and the fastest is reported (the machine is shared; the
  // thread's CPU time is reported beside the wall time for the same reason)
  double min_timing_s = 0.3;
  int max_repeats = 5;
  // where precision.csv, precision.svg and precision_order.svg go; empty:
  // nothing is written
  std::string out_dir;
  // called with (runs done, runs) after the references (one item) and after
  // each rung of the ladder; not set: nothing
  output::ProgressFn progress;
  // polled between the runs and every 64 ticks of each (both references'
  // threads too), and last before the files are written (runtime/stop.h);
  // not set: never stops
  runtime::StopFn should_stop;
  // the sensitivity study's spread of the RMS path error, shown beside the
  // errors (precision.svg, the JSON's modelling_spread); not present: none
  ModellingSpread modelling_spread;
};

// How one run differs from the reference, tick by tick.
struct TrajectoryError {
  double rms_mm = 0.0;       // wrist centre, RMS over ticks of |p - p_ref|
  double max_mm = 0.0;
  double rms_axis_rad = 0.0;  // stylus axis, angle to the reference's
  double max_axis_rad = 0.0;
  // the commanded motor torques, RMS over ticks of |tau - tau_ref| (mN m):
  // how far the controller's commands drifted apart
  double rms_torque_mNm = 0.0;
  // ticks where a discrete decision of the controller differed from the
  // reference's: its status, or the number of placement iterations
  int status_mismatch_ticks = 0;
  int iteration_mismatch_ticks = 0;
  bool finite = true;  // false: the run blew up (NaN or a MuJoCo warning)
};

struct PrecisionRow {
  Integrator integrator = Integrator::kEuler;
  double step_s = 0.0;
  int substeps = 0;            // physics steps per servo tick
  TrajectoryError error;
  double wall_time_s = 0.0;    // the fastest repeat of the tick loop
  double cpu_time_s = 0.0;     // its thread CPU time, least of the repeats
  int repeats = 0;
  double steps_per_s = 0.0;    // physics steps per wall second
  double realtime_factor = 0.0;  // simulated s per wall s
  bool is_default = false;     // the scene's own integrator and step
  bool used_in_fit = false;
  // log(e_prev / e) / log(h_prev / h) against the next larger step of the
  // same integrator (NaN for the largest)
  double local_order = 0.0;
  bool on_front = false;       // Pareto front of (wall time, rms error)
  bool on_front_cpu = false;   // the same with the CPU time
  int mujoco_warnings = 0;
};

struct OrderFit {
  Integrator integrator = Integrator::kEuler;
  double order = 0.0;          // slope of log(rms error) vs log(h)
  double log10_coefficient = 0.0;  // rms_mm ~ 10^c * h_s^order
  int points = 0;              // rungs used (NaN order if fewer than 2)
  std::vector<double> steps_used_s;
};

struct ReferenceInfo {
  double step_s = 0.0;
  double check_step_s = 0.0;
  double wall_time_s = 0.0;
  double check_wall_time_s = 0.0;
  // the check reference against the reference: an upper estimate of the
  // reference's own error (for an order p, the reference's error is about
  // this over 2^p - 1)
  TrajectoryError self_error;
};

struct PrecisionResult {
  std::string name;
  std::string scene;
  double duration_s = 0.0;
  double servo_period_s = 0.0;
  int ticks = 0;
  std::vector<sim::ScriptSegment> segments;  // the script's, as far as the runs go
  Integrator default_integrator = Integrator::kEuler;
  double default_step_s = 0.0;
  ReferenceInfo reference;
  std::vector<PrecisionRow> rows;  // by integrator, then by decreasing h
  std::vector<OrderFit> fits;      // one per integrator
  double floor_mm = 0.0;           // rungs below this are not fitted
  double study_wall_time_s = 0.0;
  std::vector<std::string> files;  // the paths written (out_dir)
  ModellingSpread modelling_spread;  // the options', if present
};

// a rung is fitted when its rms error is above this many times the
// reference's own error
inline constexpr double kFloorFactor = 10.0;

// Runs the study and, with out_dir, writes its files (write_precision_files).
// Throws SimError on bad input (a step that does not divide the servo
// period or is not above the reference step, a bad scene or override, a
// duration beyond the case's), before any run; runtime::Interrupted when
// should_stop says so, before any file is written.
PrecisionResult run_precision_study(const PrecisionOptions& options);

// The least-squares slope and intercept of log10(e) against log10(h).
OrderFit fit_order(const std::vector<double>& steps_s,
                   const std::vector<double>& errors);

// Which of the points (x, y) no other point dominates (x' <= x and y' <= y,
// one strictly); non-finite points are never on the front.
std::vector<bool> pareto_front(const std::vector<double>& x,
                               const std::vector<double>& y);

// The table, one row per run, units in the column names.
std::string precision_csv(const PrecisionResult& r);
// error (RMS, mm) against wall time (s), log-log, one line per integrator,
// the default setting and the reference marked
output::Chart precision_chart(const PrecisionResult& r);
// error (RMS, mm) against h (s), log-log, with the fitted slopes
output::Chart precision_order_chart(const PrecisionResult& r);

// (precision_output.cc) What the command line prints: the setting, the
// reference, the fitted orders, the default setting against the others,
// the Pareto front, every row, and the files written. NaN errors are null.
nlohmann::ordered_json precision_json(const PrecisionResult& r);
// out_dir/precision.csv, precision.svg (error against wall time) and
// precision_order.svg (error against h); returns their paths
std::vector<std::string> write_precision_files(const PrecisionResult& r,
                                               const std::string& out_dir);

}  // namespace vmh::studies

#endif  // VMHAPTICS_STUDIES_PRECISION_STUDY_H_
