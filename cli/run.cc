// vmhaptics run <case1..case7|scene.xml> [--duration s] [--out DIR]
//                [--set name=value ...] [--json] [--model FILE]
// vmhaptics run --all [--out DIR] [--jobs N] [--sides fitted|full]
//                [--trace-sides]
//
// Prints a table of the error to the path against the run time (or, with
// --json, one JSON object holding every case's summary), and writes
// DIR/<case>/trace.csv and DIR/<case>/summary.json when --out is given.
// Each case's files are written as one set (thesis/run_case.h): a reader of
// DIR/<case> sees the previous whole set or the new one, never a mix.
// Exit codes: 0 every run finished and every claim passed; 1 a claim failed
// or a run failed (a set that could not be written included: it is not
// left half-written); 2 bad usage or bad input (nothing is written for it),
// an --out that cannot be created or written in included (found before any
// run); 130 / 143 SIGINT / SIGTERM (the sets not yet complete are removed,
// the complete ones kept).
#include "cli/run.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli/args.h"
#include "runtime/session.h"
#include "device/stop_signal.h"
#include "output/output_file.h"
#include "output/progress.h"
#include "sim/cases/case_params.h"
#include "thesis/run_case.h"

namespace vmh::cli {
namespace {

struct RunOptions {
  std::string target;
  bool all = false;
  std::string duration_s;  // not given: the scene's
  std::string out;
  std::vector<std::string> sets;
  int jobs = 0;  // 0: one per core
  bool json = false;
  bool duration_given = false;
  std::string model;  // a calibrated Omni MJCF; empty: the scene's own
  std::string sides = "fitted";  // thesis/side_runs.h
  bool trace_sides = false;
};

void print_table(const std::vector<thesis::CaseResult>& results) {
  std::printf("%-8s %10s %10s %10s %10s %9s %9s %8s  %s\n", "case",
              "sim_s", "wall_s", "rms_mm", "max_mm", "meanF_N", "maxF_N",
              "on_path", "claims");
  for (const thesis::CaseResult& r : results) {
    int pass = 0;
    for (const thesis::Claim& c : r.claims) pass += c.pass ? 1 : 0;
    char partial[32] = "";
    if (r.partial_claims > 0) {
      std::snprintf(partial, sizeof partial, " (%d partial)", r.partial_claims);
    }
    std::printf("%-8s %10.3f %10.3f %10.3f %10.3f %9.3f %9.3f %7.1f%%  %d/%zu%s%s\n",
                r.name.c_str(), r.simulated_s, r.wall_time_s,
                r.metrics.rms_path_error_mm, r.metrics.max_path_error_mm,
                r.metrics.mean_force_N, r.metrics.max_force_N,
                100.0 * r.metrics.time_on_path_s / std::max(r.simulated_s, 1e-9),
                pass, r.claims.size(), partial, r.all_claims_pass ? "" : "  FAIL");
    for (const thesis::Claim& c : r.claims) {
      std::printf("    %-4s %-36s %10.4g %s %-7.4g %-5s at %5.1f mm off",
                  c.pass ? "ok" : c.partial ? "part" : "FAIL", c.name.c_str(), c.value,
                  c.comparison.c_str(), c.threshold, c.unit.c_str(),
                  c.mean_path_distance_mm);
      if (c.prediction) {
        std::printf(", law %.4g%s, %s\n", *c.prediction,
                    c.matches_prediction.value_or(false) ? "" : " (differs)",
                    c.regime.c_str());
      } else {
        std::printf(", no prediction, %s\n", c.regime.c_str());
      }
      if (c.partial) std::printf("         holds only %s\n", c.holds_where.c_str());
    }
  }
}

// the options that need no scene: one target or --all, --jobs, --sides,
// --trace-sides; the runs' side options from them
thesis::CaseRunOptions check_run_options(const RunOptions& o) {
  if (o.all == !o.target.empty()) {
    throw UsageError("run: give one case or scene, or --all");
  }
  if (o.jobs < 0) {
    throw UsageError("--jobs: must be >= 0 (0: one per core), got " +
                     std::to_string(o.jobs));
  }
  thesis::CaseRunOptions run_options;
  if (o.sides == "full") {
    run_options.sides = thesis::SideMode::kFull;
  } else if (o.sides != "fitted") {
    throw UsageError("--sides: 'fitted' or 'full', got '" + o.sides + "'");
  }
  run_options.trace_sides = o.trace_sides;
  if (o.trace_sides && o.out.empty()) {
    throw UsageError("--trace-sides: needs --out DIR (the traces go to "
                     "DIR/<case>/trace_side_<n>.csv)");
  }
  return run_options;
}

// the --set overrides, with --duration as duration_s's
std::vector<std::string> overrides_of(const RunOptions& o) {
  std::vector<std::string> sets = o.sets;
  if (o.duration_given) {
    // checked here, before any scene is read, against duration_s's row of
    // the table; passed on exactly (%.17g round-trips)
    const double d = parse_number("--duration", o.duration_s);
    try {
      sim::check_param_number(*sim::find_param("duration_s"), d, "--duration");
    } catch (const sim::ParamError& e) {
      throw UsageError(e.what());
    }
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", d);
    sets.push_back(std::string("duration_s=") + text);
  }
  return sets;
}

// every run's case name and scene, resolved first, so that a bad name
// writes nothing
std::vector<thesis::CaseJob> resolve_runs(const RunOptions& o) {
  std::vector<std::pair<std::string, std::string>> jobs;
  try {
    if (o.all) {
      for (const sim::CaseEntry& c : sim::case_catalogue()) {
        std::string name;
        jobs.emplace_back(c.name, sim::resolve_scene(c.name, &name));
      }
    } else {
      std::string name;
      const std::string scene = sim::resolve_scene(o.target, &name);
      jobs.emplace_back(name, scene);
    }
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("run: ") + e.what());
  }
  std::vector<thesis::CaseJob> runs;
  for (const auto& [name, scene] : jobs) {
    runs.push_back(thesis::CaseJob{name, scene, {}, {}, false, false});
  }
  return runs;
}

// --model as an absolute path (empty: the scene's own Omni)
std::string model_of(const RunOptions& o) {
  std::string model;
  if (!o.model.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(o.model, ec)) {
      throw UsageError("--model: no such file '" + o.model + "'");
    }
    model = std::filesystem::absolute(o.model, ec).string();
  }
  return model;
}

// the runs, in parallel; a SIGINT or SIGTERM stops them and is a
// SignalStop naming the sets kept
void run_jobs(std::vector<thesis::CaseJob>* runs,
              const std::vector<std::string>& sets, const std::string& model,
              const RunOptions& o, const thesis::CaseRunOptions& run_options) {
  // SIGINT / SIGTERM only set a flag (device/stop_signal.h); the runs poll
  // it between ticks and before each file, and a stopped run's temporary
  // set is removed by its own thread, outside the handler
  StopSignals signals;
  {
    // a bar on stderr (terminal only) for --all; one case is one item
    output::Progress bar("run", runs->size());
    thesis::run_cases(
        runs, sets, o.out, o.jobs, model,
        o.all ? bar.part(0) : output::ProgressFn{},
        [&signals] { return signals.requested(); }, run_options);
  }
  if (signals.requested()) {
    const int signo = signals.signal_number();
    std::string kept;
    for (const thesis::CaseJob& j : *runs) {
      if (j.error.empty() && !o.out.empty()) kept += " " + j.name;
    }
    throw runtime::SignalStop(std::string("interrupted: run stopped by ") +
                         (signo == SIGINT ? "SIGINT" : "SIGTERM") +
                         (o.out.empty() ? ""
                          : kept.empty() ? "; no set written"
                                         : "; complete sets kept:" + kept),
                     signo);
  }
}

// the runs' results; every failed run in one line, a UsageError if one
// failed on its input
std::vector<thesis::CaseResult> results_of(
    const std::vector<thesis::CaseJob>& runs) {
  std::vector<thesis::CaseResult> results;
  std::string errors;  // every failed run, in one line
  bool bad_input = false;
  for (const thesis::CaseJob& j : runs) {
    if (!j.error.empty()) {
      errors += (errors.empty() ? "run " : "; ") + j.name + ": " + j.error;
      bad_input |= j.bad_input;
    }
    results.push_back(j.result);
  }
  if (!errors.empty()) {
    if (bad_input) throw UsageError(errors);
    throw std::runtime_error(errors);
  }
  return results;
}

// the summaries as one JSON object (--json), or the table and where the
// files went
void print_results(const RunOptions& o,
                   const std::vector<thesis::CaseResult>& results) {
  if (o.json) {
    nlohmann::json all = nlohmann::json::object();
    for (const thesis::CaseResult& r : results) all[r.name] = r.summary;
    std::cout << all.dump(2) << '\n';
  } else {
    print_table(results);
    if (!o.out.empty()) {
      std::printf("outputs: %s/<case>/trace.csv and summary.json\n",
                  o.out.c_str());
    }
  }
  std::cout.flush();
  std::fflush(stdout);
}

// exit 1 naming every claim that failed (a partial one is not a failure)
void throw_if_claims_failed(const std::vector<thesis::CaseResult>& results) {
  std::string failed;
  for (const thesis::CaseResult& r : results) {
    for (const thesis::Claim& c : r.claims) {
      if (!c.pass && !c.partial) failed += " " + r.name + ":" + c.name;
    }
  }
  if (!failed.empty()) {
    throw std::runtime_error("run: thesis claim(s) not met:" + failed);
  }
}

void run(const RunOptions& o) {
  const thesis::CaseRunOptions run_options = check_run_options(o);
  const std::vector<std::string> sets = overrides_of(o);
  std::vector<thesis::CaseJob> runs = resolve_runs(o);
  const std::string model = model_of(o);
  // an --out that cannot hold the sets is found before any run
  if (!o.out.empty()) {
    try {
      output::check_writable_dir(o.out);
    } catch (const std::exception& e) {
      throw UsageError(std::string("run: --out ") + e.what());
    }
  }
  run_jobs(&runs, sets, model, o, run_options);
  const std::vector<thesis::CaseResult> results = results_of(runs);
  print_results(o, results);
  throw_if_claims_failed(results);
}

}  // namespace

void register_run(CLI::App* app) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* cmd = app->add_subcommand(
      "run",
      "closed-loop simulation of a case (case1..case6 the thesis's, case7 "
      "the line slider) or a scene file: the Omni held by a simulated hand, "
      "headless; prints the error against run time and checks the case's "
      "claims");
  cmd->add_option("target", o->target,
                  "case1..case7, or the path of a scene .xml");
  cmd->add_flag("--all", o->all,
                "run the seven cases: the thesis's six and the line slider");
  cmd->add_option_function<std::string>(
      "--duration",
      [o](const std::string& text) {
        o->duration_s = text;
        o->duration_given = true;
      },
      "simulated seconds, > 0 and <= 3600 (default: the scene's duration_s, "
      "20)")
      ->type_name("FLOAT");
  cmd->add_option("--out", o->out,
                  "write DIR/<case>/trace.csv and DIR/<case>/summary.json");
  cmd->add_option("--set", o->sets,
                  "override a case parameter, name=value (vectors "
                  "comma-separated); repeatable. docs/cli.md lists the names")
      ->allow_extra_args(false);
  cmd->add_option("--jobs", o->jobs,
                  "cases run in parallel (default: one per core)");
  cmd->add_option("--model", o->model,
                  "a calibrated Omni MJCF (e.g. models/omni/calibrated/"
                  "<serial>.xml, any MJCF with models/omni/omni.xml's names) "
                  "whose parameters replace the scene's Omni's");
  cmd->add_option("--sides", o->sides,
                  "how the claims' other sides run: fitted (each simulates "
                  "only the script segments its claims read, settled holds "
                  "cut short; docs/testbed.md) or full (the whole script, "
                  "as the main run)")
      ->type_name("fitted|full")
      ->default_str("fitted");
  cmd->add_flag("--trace-sides", o->trace_sides,
                "also write each side's trace, DIR/<case>/trace_side_<n>.csv "
                "(summary.json's sides.runs name them)");
  cmd->add_flag("--json", o->json,
                "print every case's summary as one JSON object instead of "
                "the table");
  cmd->callback([o] { run(*o); });
}

}  // namespace vmh::cli
