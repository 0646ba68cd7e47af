// The stability study (`vmhaptics study stability`): the critical stiffness
// of a sampled-data virtual wall, found by simulation in MuJoCo and checked
// against theory (docs/sources.md §11).
//
// The scene is models/slider/slider.xml: a 1-DOF slider of mass m with
// viscous damping b (joint damping), pushed by a motor. A controller sampled
// every servo period T renders a virtual wall at x = 0, a spring K and a
// damper B:
//   - it reads the position x_k at t = kT (no quantisation, no noise),
//   - estimates the velocity by the backward difference (x_k - x_{k-1}) / T,
//   - computes F_k = -K x_k - B (x_k - x_{k-1}) / T,
//   - applies it n ticks later (a computation/communication delay of
//     t_d = n T) and holds it (zero-order hold) over one period,
// while MuJoCo steps the slider at h << T.
//
// The wall is bilateral: the spring and damper act on both sides of x = 0,
// as if the slider were coupled to the wall, so that the loop is linear and
// its stability a property of (m, b, T, B, K, n) alone, which is what the
// theories below are about. (A one-sided wall makes the loop piecewise
// linear; it is not studied here.)
////
// The theory it is compared with (Gil et al. 2004, Colgate and Schenkel
// 1997, the exact discrete loop) is in studies/stability_theory.h.
#ifndef VMHAPTICS_STUDIES_STABILITY_STUDY_H_
#define VMHAPTICS_STUDIES_STABILITY_STUDY_H_

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "output/progress.h"
#include "output/svg_chart.h"
#include "sim/mujoco_util.h"
#include "studies/stability_theory.h"
#include "runtime/stop.h"

namespace vmh::studies {

// ---------------------------------------------------------------- simulation

// What one simulated run says about the envelope of the oscillation.
struct WallRun {
  double k_N_per_m = 0.0;
  bool stable = false;   // the envelope decays
  bool diverged = false;  // |x| passed kDivergedFactor x0: stopped early
  int ticks = 0;          // servo ticks simulated
  // the envelope's growth rate, 1/s (< 0: decays), from the windows below
  double growth_rate_per_s = 0.0;
  // largest |x| in the early and the late window, m
  double early_peak_m = 0.0;
  double late_peak_m = 0.0;
};

inline constexpr double kInitialDisplacement_m = 1e-3;
inline constexpr double kDivergedFactor = 1e4;

// The slider model with m, b and h set from the parameters, and one
// mjData; runs the wall at any K and n = p.delay_ticks.
class SliderWall {
 public:
  // Loads `model_path` (models/slider/slider.xml) and sets body_mass (and
  // the inertia, scaled alike), dof_damping and opt.timestep, then
  // mj_setConst. Throws SimError for bad parameters (validate) or a model
  // that is not a slider.
  SliderWall(const std::string& model_path, const StabilityParams& p);

  const StabilityParams& params() const { return p_; }
  const mjModel* model() const { return m_.get(); }

  // The number of servo ticks run() simulates at stiffness K: enough for
  // kHorizonPeriods periods of the undamped oscillation sqrt(K/m) and at
  // least kMinHorizonTicks.
  //
  // Why that is enough near the boundary, where the envelope changes by
  // only ~1e-4 over the run: run() does not compare peaks (sampled once a
  // tick, a peak is off by up to (pi/ticks per period)²/2, 0.05% at 100
  // ticks a period, larger than the signal) but the window sums of
  // Q_k = x_k² - x_{k-1} x_{k+1}, which for the dominant mode grow as
  // rho^{2k} with no ripple. What limits it is the other modes (the
  // backward difference's and the delay line's), which must have died out
  // before the early window: |z| <= 0.7 in the sets tried, so 0.7^100 ~
  // 3e-16 at the window's start a third into 300 ticks. Three periods keep
  // each window a whole period long. The test checks the result against
  // the discrete loop's spectral radius to 1e-4; it agrees to ~1e-6.
  int horizon_ticks(double k_N_per_m) const;

  // One run from x = kInitialDisplacement_m at rest, the controller's
  // previous sample equal to it and no force in the delay line. `ticks` 0:
  // horizon_ticks(K). If `x_per_tick` is given it receives x_k, m.
  WallRun run(double k_N_per_m, int ticks = 0,
              std::vector<double>* x_per_tick = nullptr);

 private:
  // From x = kInitialDisplacement_m at rest, `ticks` servo ticks of the
  // wall at stiffness K (or until |x| passes kDivergedFactor x0, when
  // r->diverged is set): x_k appended to *xs each tick, and the last x after
  // the last tick unless diverged; r->ticks counts them.
  void run_ticks(double k_N_per_m, int ticks, std::vector<double>* xs,
                 WallRun* r);
  // std::runtime_error naming the warning and K if MuJoCo warned in the run
  void throw_if_warned(double k_N_per_m) const;

  StabilityParams p_;
  sim::ModelPtr m_;
  sim::DataPtr d_;
  int steps_per_tick_ = 1;
};

inline constexpr double kHorizonPeriods = 3.0;
inline constexpr int kMinHorizonTicks = 300;

struct SimKcrit {
  // the zero of the measured growth rate, interpolated linearly between
  // the bracket's two runs (or its middle, if not interpolated)
  double k_crit_N_per_m = 0.0;
  bool interpolated = false;
  double k_stable_N_per_m = 0.0;    // largest K seen to decay
  double k_unstable_N_per_m = 0.0;  // smallest K seen to grow
  int runs = 0;                     // simulated runs, bracketing included
  long long physics_steps = 0;
  std::vector<WallRun> history;     // every run, in order
};

// K_crit by simulation: a bracket [K_stable, K_unstable] found around
// `k_guess_N_per_m` (K_guess x 1.03^-1 and x 1.03, widened geometrically
// until one run decays and the other grows), then bisected until
// (K_unstable - K_stable) / K_stable <= rel_tol. The guess only says where
// to look; every K is judged by a run. `stop` (if set) is polled before
// each run: runtime::Interrupted once it says so.
SimKcrit k_crit_simulated(SliderWall& wall, double k_guess_N_per_m,
                          double rel_tol = 2e-3,
                          const runtime::StopFn& stop = {});

// The whole comparison for one setting.
struct StabilityReport {
  StabilityParams params;
  SimKcrit sim;
  DiscreteKcrit exact;        // exact ZOH plant
  DiscreteKcrit euler;        // MuJoCo's Euler plant at the same h
  double k_bound_gil_N_per_m = 0.0;
  double k_passivity_N_per_m = 0.0;
  double wall_time_s = 0.0;
};

StabilityReport study_stability(const std::string& model_path,
                                const StabilityParams& p, double rel_tol = 2e-3,
                                const runtime::StopFn& stop = {});

// ---------------------------------------------------------------- map

// K_crit against the virtual damping B, for each delay n: the boundary of
// the stable region in the (B, K) plane.
struct MapSpec {
  StabilityParams base;  // m, b, T, h; B and n are swept
  std::vector<double> virtual_damping_Ns_per_m;
  std::vector<int> delay_ticks;
  double rel_tol = 2e-3;
  int jobs = 1;  // threads, each with its own model and data
  // called from the workers with (points done, points); not set: nothing
  output::ProgressFn progress;
  // polled from the workers before each point and each run of its
  // bisection; once it says so no point starts and runtime::Interrupted is
  // thrown
  runtime::StopFn should_stop;
};

struct MapPoint {
  double virtual_damping_Ns_per_m = 0.0;
  int delay_ticks = 0;
  SimKcrit sim;
  double k_crit_exact_N_per_m = 0.0;
  double k_crit_mujoco_euler_N_per_m = 0.0;
  double k_bound_gil_N_per_m = 0.0;
  double k_passivity_N_per_m = 0.0;
};

// One point per (B, n), ordered by n then B. Throws SimError (validate) for
// a bad point before simulating any.
std::vector<MapPoint> stability_map(const std::string& model_path,
                                    const MapSpec& spec);

// ---------------------------------------------------------------- the study

// What `vmhaptics study stability` runs: one setting's K_crit by bisection,
// or, when the sweep is given, the map.
struct StabilityOptions {
  std::string model_path;  // the slider (slider_model_path)
  StabilityParams params;  // validated; for a map, B and n are swept
  double rel_tol = 2e-3;   // relative width of the final K bracket
  // a map when not empty: K_crit for every (B, n) (stability_map)
  std::vector<double> map_virtual_damping_Ns_per_m;
  std::vector<int> map_delay_ticks;
  int jobs = 1;  // map points simulated at once
  output::ProgressFn progress;  // the map's (MapSpec::progress)
  // polled before each run of a bisection (each point's, for a map) and
  // last before the files are written: runtime::Interrupted, nothing written
  runtime::StopFn should_stop;
  // where the CSV and the chart go (write_stability_files); empty: nothing
  std::string out_dir;
};

struct StabilityResult {
  StabilityOptions options;
  StabilityReport bisection;         // one setting (not a map)
  int horizon_ticks_at_k_crit = 0;   // the run length at the K found
  std::vector<MapPoint> map;         // a map: by n, then B
  double wall_time_s = 0.0;          // the bisection's, or the whole map's
  std::vector<std::string> files;    // the paths written (out_dir)
  bool is_map() const { return !options.map_virtual_damping_Ns_per_m.empty(); }
};

// Runs the bisection (study_stability) or the map (stability_map) and, with
// out_dir, writes the files (write_stability_files). Throws SimError on bad
// parameters; runtime::Interrupted when should_stop says so, before any
// file is written.
StabilityResult run_stability_study(const StabilityOptions& options);

// ---------------------------------------------------------------- output
// (stability_output.cc)

// What the command line prints: for one setting, K_crit against the
// theories and the relative errors; for a map, a row per (B, n) and the
// worst relative errors. "outputs" lists the files written.
nlohmann::ordered_json stability_json(const StabilityResult& r);

// The bisection's runs, one row each: run, k_N_per_m, stable, diverged,
// growth_rate_per_s, early_peak_m, late_peak_m, ticks.
std::string bisection_csv(const StabilityReport& r);
// their growth rates against K, the theories' K as vertical lines
output::Chart bisection_chart(const StabilityReport& r);

// The map as CSV, units in the column names: virtual_damping_Ns_per_m,
// delay_ticks, k_crit_sim_N_per_m, k_stable_sim_N_per_m,
// k_unstable_sim_N_per_m, k_crit_exact_N_per_m, k_crit_mujoco_euler_N_per_m,
// k_bound_gil_N_per_m, k_passivity_N_per_m, rel_error_sim_vs_exact,
// rel_error_sim_vs_gil, sim_runs.
std::string stability_map_csv(const std::vector<MapPoint>& points);

// The map as an SVG chart (output/svg_chart.h): K_crit against B, for each
// delay the simulated points as markers, the exact discrete boundary as a
// line and Gil et al.'s bound dashed, with Colgate and Schenkel's passivity
// bound dashed in grey (where it is > 0).
std::string stability_map_svg(const std::vector<MapPoint>& points,
                              const StabilityParams& base);

// out_dir/stability_bisection.csv and .svg, or for a map
// out_dir/stability_map.csv and .svg; returns their paths
std::vector<std::string> write_stability_files(const StabilityResult& r,
                                               const std::string& out_dir);

// The slider's model file under `models_dir`.
std::string slider_model_path(const std::string& models_dir);

}  // namespace vmh::studies

#endif  // VMHAPTICS_STUDIES_STABILITY_STUDY_H_
