// Runs a case from start to end and writes its outputs: DIR/<case>/trace.csv
// (one row per servo tick), DIR/<case>/summary.json (metrics and the
// thesis's claims), and the plots views.svg and history.svg (plot_svg.h).
// The four are written as one set (output::OutputSet): into a private
// temporary folder beside DIR/<case>, renamed into place once all are
// complete, so a failed or interrupted run leaves the previous set (or
// none) and nothing half-written. docs/outputs.md documents the formats.
#ifndef VMHAPTICS_THESIS_RUN_CASE_H_
#define VMHAPTICS_THESIS_RUN_CASE_H_

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "output/progress.h"
#include "sim/mujoco_messages.h"
#include "sim/cases/case_catalogue.h"
#include "sim/closed_loop.h"
#include "thesis/claims.h"
#include "thesis/summary_json.h"
#include "runtime/stop.h"

namespace vmh::thesis {

struct CaseResult {
  std::string name;
  std::string scene;
  nlohmann::json summary;  // what summary.json holds
  RunMetrics metrics;
  std::vector<Claim> claims;
  double wall_time_s = 0.0;
  double simulated_s = 0.0;
  // no claim fails on every side (a partial claim does not fail the run)
  bool all_claims_pass = true;
  int partial_claims = 0;  // claims that hold on some sides only
  // the claims, metrics and figures are measured on every kept_every-th
  // tick (1 up to 60,000 ticks; trace.csv has every tick)
  int kept_every = 1;
};

// runtime::StopFn and runtime::Interrupted (runtime/stop.h): polled between
// ticks and before the outputs are written (a signal, cli/run.cc).

// Throws SimError naming `dir`, the bytes needed and the bytes available
// when a trace of `ticks` rows (runtime::trace_bytes_bound, and a tenth more for the
// other files) does not fit in `available_B`. run_case calls it with the
// free space of --out's disk before any simulation.
void check_trace_fits(const std::string& dir, std::int64_t ticks,
                      std::size_t columns, std::uintmax_t available_B);

// The ticks run_case keeps in memory for the claims, metrics and figures,
// at most; a longer run keeps every k-th (CaseResult::kept_every) and
// streams every tick to trace.csv.
constexpr std::int64_t kMaxKeptTicks = 60000;

// How run_case() runs a case's other sides (thesis/side_runs.h).
enum class SideMode { kFitted, kFull };
struct CaseRunOptions {
  // fitted: each side simulates only what its claims read; full: the
  // whole script, as the main run (`run --sides`)
  SideMode sides = SideMode::kFitted;
  // each side also writes DIR/<case>/trace_side_<n>.csv (`run --trace-sides`)
  bool trace_sides = false;
};

// Runs `scene` (with `overrides`) for its duration and, if out_dir is not
// empty, writes out_dir/<name>/{trace.csv, summary.json, views.svg,
// history.svg}. `model_file` (not empty): a calibrated Omni MJCF whose
// parameters replace the scene's Omni's (sim::omni_model_hook; recorded in
// summary.json's "model"). Throws SimError on bad input (before anything is
// written), runtime::Interrupted when `stop` (if set) says so (nothing written,
// any previous set left as it was), std::runtime_error naming the file and the
// OS error when a file cannot be written (likewise).
CaseResult run_case(const std::string& name, const std::string& scene,
                    const std::vector<std::string>& overrides,
                    const std::string& out_dir,
                    const std::string& model_file = "",
                    const runtime::StopFn& stop = {},
                    const CaseRunOptions& options = {});

// One run of run_cases(): the case's name and scene, and what came of it.
struct CaseJob {
  std::string name;
  std::string scene;
  CaseResult result;   // filled when error is empty
  std::string error;   // the exception's message, if the run threw
  bool bad_input = false;  // the error was a SimError (bad scene or field)
  bool interrupted = false;  // stopped by `stop` (error says "interrupted")
};

// Runs every job through run_case() on `threads` threads (0: one per core,
// never more than there are jobs), each run in its own thread with its own
// model and data. Exceptions are caught per job and recorded in it.
// `model_file`: run_case's, for every job. `progress` (if set) is called
// from the worker threads with (jobs finished, jobs) as each one ends.
// `stop`: run_case's, for every job (polled from the worker threads).
void run_cases(std::vector<CaseJob>* jobs,
               const std::vector<std::string>& overrides,
               const std::string& out_dir, int threads,
               const std::string& model_file = "",
               const output::ProgressFn& progress = {},
               const runtime::StopFn& stop = {},
               const CaseRunOptions& options = {});

// trace.csv's column names for a loop, in order (runtime/trace_writer.h
// writes it, as it writes a session's)
std::vector<std::string> trace_columns(const sim::ClosedLoop& loop);

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_RUN_CASE_H_
