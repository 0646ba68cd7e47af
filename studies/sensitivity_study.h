// The sensitivity study (issue 16, item 4): how far each thesis claim
// survives what is uncertain in the testbed's model.
//
// What is uncertain is one table, sweep_parameters(): the hand's stiffness,
// damping, mass and inertia (translational and rotational), the Omni's
// masses and joint friction, the motors' torque limits, the servo period
// and the delay, each with a low, a high and where the range comes from.
// The nominal value is the case's own (its scene or the case table's
// default), so the sweep follows the model as it is updated.
//
// A sweep is a deterministic list of points, per case:
//   - the nominal point (every parameter at the case's value);
//   - one at a time: each parameter over its levels, the others nominal
//     (quick: low and high; otherwise five levels, or every whole value or
//     choice);
//   - a sample of all parameters at once: a Latin hypercube, seeded, drawn
//     with the standard library's mt19937_64 alone so that every platform
//     draws the same points.
// Every point runs the case's closed loop to the end (run_point) and keeps
// each claim's value and verdict and the RMS path error.
//
// A sweep too large for one machine is cut into N shards: point i belongs to
// shard (i mod N) + 1. A shard writes sensitivity.partial.json, which names
// the sweep by a hash of its definition and points; merge_partials() joins
// shards of one sweep into the same files a single run writes.
#ifndef VMHAPTICS_STUDIES_SENSITIVITY_STUDY_H_
#define VMHAPTICS_STUDIES_SENSITIVITY_STUDY_H_

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "output/progress.h"
#include "output/svg_chart.h"
#include "sim/mujoco_util.h"
#include "runtime/stop.h"

namespace vmh::studies {

// How a parameter reaches the model.
enum class SweepKind {
  kField,         // a case field, set to the value (run --set name=value)
  kFieldScale,    // a vector case field, every item times the value
  kOmniMass,      // every Omni body's mass and inertia times the value
  kOmniFriction,  // the Omni's joint dry friction times the value
  kChoice,        // a text case field, one of `choices`
};

// How levels and samples spread over [low, high].
enum class SweepScale {
  kLinear,
  kLog,      // geometric: low > 0
  kInteger,  // every whole value from low to high
  kChoice,   // the choices
};

struct SweepParameter {
  std::string name;    // the name in the outputs
  SweepKind kind = SweepKind::kField;
  std::string field;   // the case field it sets (kField, kFieldScale, kChoice)
  SweepScale scale = SweepScale::kLinear;
  double low = 0.0;
  double high = 0.0;
  std::vector<std::string> choices;  // kChoice
  std::string unit;
  std::string source;  // where the range comes from
  // left out, with a note, when the case table has no such field (a field
  // another change adds); a missing required field is an error
  bool optional = false;
};

// The table of what is uncertain, with ranges and sources
// (docs/numerics.md §5 prints it).
const std::vector<SweepParameter>& sweep_parameters();

// One parameter's value at a point: a number, or a choice's text.
struct SweepValue {
  double number = 0.0;
  std::string text;  // kChoice only
};

enum class PointKind { kNominal, kOneAtATime, kSample };
const char* point_kind_name(PointKind k);

struct SweepPoint {
  std::size_t index = 0;   // in the whole sweep
  std::size_t case_index = 0;
  PointKind kind = PointKind::kNominal;
  int parameter = -1;      // kOneAtATime: which one moves
  std::vector<SweepValue> values;        // one per parameter of the plan
  std::vector<std::string> overrides;    // the case fields set (name=value)
  double omni_mass_scale = 1.0;
  double omni_friction_scale = 1.0;
};

struct SweepCase {
  std::string name;   // case2
  std::string scene;
  double physics_step_s = 0.0;           // the scene's, with the base overrides
  std::vector<SweepValue> nominal;       // one per parameter of the plan
};

// What the sweep is: the plan's definition, which a partial file keeps
// (partial_options) so that its merge can plan the sweep again.
struct SweepOptions {
  std::vector<std::string> cases;        // case names (resolve_scene)
  bool quick = false;
  int samples = -1;                      // -1: 16 with quick, 64 otherwise
  std::uint64_t seed = 1;
  std::vector<std::string> overrides;    // applied to every point first
  // the table swept; empty: sweep_parameters()
  std::vector<SweepParameter> parameters;
  // one-at-a-time levels per parameter; 0: 2 with quick, 5 otherwise
  int levels = 0;
  std::string software;                  // "vmhaptics <version>", in the id
};

// The sweep as planned: its cases, parameters, points and identity.
struct SweepPlan {
  SweepOptions options;  // levels and samples as planned
  std::vector<SweepParameter> parameters;  // those swept
  std::vector<std::string> omitted;        // optional ones left out, and why
  std::vector<SweepCase> cases;
  std::vector<SweepPoint> points;
  std::string id;                          // 16 hex digits
  nlohmann::ordered_json definition;       // what id hashes
};

// Plans the sweep. Throws SimError on an unknown case, a bad override, a
// missing required field or a bad table row, before anything runs.
SweepPlan plan_sweep(const SweepOptions& options);

// Shard k of n (1 <= k <= n): the points i with i mod n == k - 1.
std::vector<std::size_t> shard_points(std::size_t points, int k, int n);

// "K/N" with 1 <= K <= N; false otherwise.
bool parse_shard(const std::string& text, int* k, int* n);

struct ClaimOutcome {
  std::string name;
  double value = 0.0;
  double threshold = 0.0;
  std::string comparison;  // "<=" or ">="
  std::string unit;
  bool pass = false;
};

struct PointResult {
  std::size_t index = 0;
  std::string error;  // the run threw: its message (every claim fails)
  double rms_path_error_mm = 0.0;
  std::vector<ClaimOutcome> claims;
};

// Runs one point: the case's closed loop to its end, its claims and RMS
// path error. A failed run is recorded in `error`; it throws only
// runtime::Interrupted, when `stop` (if set, polled every tick) says so.
PointResult run_point(const SweepPlan& plan, std::size_t index,
                      const runtime::StopFn& stop = {});

// Every point of the plan, in index order (what an unsharded run runs).
std::vector<std::size_t> all_points(const SweepPlan& plan);

// Runs the points `which` (none: an empty list; all: all_points(plan)) on
// `jobs` threads, in index order.
// `stop` (if set) is polled from the workers between points and every
// tick: once it says so, no point starts, those running end at their next
// tick, and runtime::Interrupted is thrown (nothing is written here either
// way).
std::vector<PointResult> run_points(const SweepPlan& plan,
                                    const std::vector<std::size_t>& which,
                                    int jobs,
                                    const output::ProgressFn& progress = {},
                                    const runtime::StopFn& stop = {});

// The claim's margin: value - threshold for ">=", threshold - value for
// "<=" (>= 0 where it holds), over |threshold| when that is not 0.
double claim_margin(const ClaimOutcome& c);

// ---------------------------------------------------------------- the study

// What `vmhaptics study sensitivity` runs: the sweep, or one shard of it.
struct SensitivityOptions {
  SweepOptions sweep;
  int jobs = 1;  // points run at once (run_points; <= 0: one per core)
  // shard k of n (shard_points): only its points run, and the partial file
  // is written; 0 of 0: the whole sweep
  int shard_k = 0, shard_n = 0;
  // where the files go (write_sensitivity_files); empty: nothing written
  std::string out_dir;
  // called from the workers with (points done, points), and once with
  // (0, points) before the first starts; not set: nothing
  output::ProgressFn progress;
  // polled from the workers between points and every tick, and last before
  // the files are written: runtime::Interrupted, nothing written
  runtime::StopFn should_stop;
};

struct SensitivityResult {
  SweepPlan plan;
  int shard_k = 0, shard_n = 0;      // the options', 0 of 0: the whole sweep
  std::vector<PointResult> results;  // the points run, by index
  std::vector<std::string> files;    // the paths written (out_dir)
  bool is_shard() const { return shard_n > 0; }
};

// Plans the sweep (plan_sweep), runs its points or the shard's (run_points)
// and, with out_dir, writes the files (write_sensitivity_files). Throws
// SimError on bad input (plan_sweep's), before any point runs;
// runtime::Interrupted when should_stop says so, before any file is
// written. A point whose run failed is a result (PointResult::error).
SensitivityResult run_sensitivity_study(const SensitivityOptions& options);

// What the command line prints. The whole sweep: per claim its holds
// fractions and the parameters that flip it, each case's spread of the RMS
// path error, and the files. A shard: the sweep's id, the shard, how many
// points it ran, and its file.
nlohmann::ordered_json sensitivity_json(const SensitivityResult& r);

// The whole sweep: out_dir/sensitivity.json, .csv and .svg; a shard:
// out_dir/sensitivity.partial.json. Returns their paths.
std::vector<std::string> write_sensitivity_files(const SensitivityResult& r,
                                                 const std::string& out_dir);

// ---------------------------------------------------------------- output
// (sensitivity_output.cc)

// sensitivity.json: the sweep, the points, per claim its holds fraction and
// what it depends on, and the modelling spread of the RMS path error.
// `results` must hold every point once.
nlohmann::ordered_json sensitivity_file_json(
    const SweepPlan& plan, const std::vector<PointResult>& results);
// one row per point and claim, units in the column names
std::string sensitivity_csv(const SweepPlan& plan,
                            const std::vector<PointResult>& results);
// per claim, the span of its margin over each parameter's one-at-a-time
// sweep, zero where it stops holding
output::ChartGrid sensitivity_chart(const SweepPlan& plan,
                                    const std::vector<PointResult>& results);

// ---------------------------------------------------------------- shards
// (sensitivity_shards.cc)

// A shard's results and the sweep's identity (sensitivity.partial.json).
nlohmann::ordered_json partial_json(const SweepPlan& plan, int k, int n,
                                    const std::vector<PointResult>& results);
// out_dir/sensitivity.partial.json; returns its path
std::string write_partial_file(const SweepPlan& plan, int k, int n,
                               const std::vector<PointResult>& results,
                               const std::string& out_dir);

// The options a partial file was planned from (to plan the sweep again).
// Throws SimError naming the file on a file that is not one.
SweepOptions partial_options(const nlohmann::json& partial,
                             const std::string& where);
std::vector<PointResult> partial_results(const nlohmann::json& partial,
                                         const std::string& where);

// Joins partial files (paths of sensitivity.partial.json or of folders
// holding one) of one sweep: plans it again from the first one's options,
// and checks that every file names that plan's id and that every point is
// there exactly once. Throws SimError naming the file or the points
// otherwise. `software`: the running program's, which must plan the same
// sweep. The result is the whole sweep's, every point by index, as if one
// run had made it, with no files yet (write_sensitivity_files).
SensitivityResult merge_partials(const std::vector<std::string>& paths,
                                 const std::string& software);

}  // namespace vmh::studies

#endif  // VMHAPTICS_STUDIES_SENSITIVITY_STUDY_H_
