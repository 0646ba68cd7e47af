// vmhaptics study extremes [--out DIR] [--only name ...] [--table] [--jobs N]
//
// The stiff and extreme cases of issue 5 (studies/extremes_study.h): gains x10
// and x100, hand stiffness from 10 to 5000 N/m, the RM at the pivot, the
// sphere's poles, the gimbal's singularity, the arm at full reach, the
// orientation error across +-pi, servo jitter and sensor faults. Prints one
// JSON object (or, with --table, a table) and, with --out, writes
// DIR/extremes.csv, DIR/extremes.json, DIR/extremes.svg and
// DIR/extremes/<scenario>.csv.
// Exit codes: 0 every scenario ended finite and bounded with its expected
// status; 1 one did not; 2 bad usage; 130 / 143 stopped by SIGINT / SIGTERM
// (--out as it was, or its files all written if the signal came as they
// went in).
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/args.h"
#include "cli/study.h"
#include "cli/study_files.h"
#include "device/stop_signal.h"
#include "output/parallel.h"
#include "output/progress.h"
#include "studies/extremes_study.h"

namespace vmh::cli {
namespace {

struct ExtremesCli {
  std::string out;
  std::vector<std::string> only;
  bool table = false;
  int jobs = 0;  // 0: one per core
};

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : " ") + x;
  return s.empty() ? "-" : s;
}

void print_table(const std::vector<studies::ExtremeResult>& results) {
  std::printf("%-24s %-34s %7s %8s %9s %9s %7s  %s\n", "scenario", "outcome",
              "maxF_N", "Emax_mJ", "Efinal_mJ", "rest_mJ", "wall_s",
              "statuses");
  for (const studies::ExtremeResult& r : results) {
    std::vector<std::string> named = r.statuses;
    named.insert(named.end(), r.device_errors.begin(), r.device_errors.end());
    named.insert(named.end(), r.guard_faults.begin(), r.guard_faults.end());
    std::printf("%-24s %-34s %7.3f %8.3f %9.3f %9.3f %7.3f  %s\n",
                r.scenario.name.c_str(), r.outcome.c_str(), r.max_force_N,
                1e3 * r.energy_motor_max_J, 1e3 * r.energy_motor_final_J,
                1e3 * r.rest_energy_rise_J, r.wall_time_s,
                joined(named).c_str());
  }
}

void run(const ExtremesCli& o) {
  // SIGINT / SIGTERM only set a flag for the whole run, which the study
  // polls (cli/study_files.h): exit 130 / 143, --out as it was
  StopSignals signals;
  // -5 ran on every core as if 0 had been given (issue 17)
  if (o.jobs < 0) {
    throw UsageError("--jobs: must be >= 0 (0: one per core), got " +
                     std::to_string(o.jobs));
  }
  studies::ExtremesOptions p;
  p.only = o.only;
  p.out_dir = o.out;
  p.jobs = o.jobs > 0 ? o.jobs : output::core_count();
  p.should_stop = study_stop();
  studies::ExtremesResult r;
  try {
    // the bar (on a terminal) is finished before the JSON or the table
    output::Progress bar("study extremes",
                         o.only.empty() ? studies::extreme_scenarios().size()
                                        : o.only.size());
    p.progress = bar.part(0);
    r = run_stoppable("study extremes",
                      [&] { return studies::run_extremes_study(p); });
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("study extremes: ") + e.what());
  }
  throw_if_stopped_after_writing("study extremes", o.out);
  if (o.table) {
    print_table(r.scenarios);
  } else {
    std::cout << studies::extremes_json(r).dump(2) << '\n';
  }
  std::cout.flush();
  std::string failed;
  for (const studies::ExtremeResult& s : r.scenarios) {
    if (!s.pass()) failed += " " + s.scenario.name + "(" + s.outcome + ")";
  }
  if (!failed.empty()) {
    throw std::runtime_error("study extremes: scenario(s) failed:" + failed);
  }
}

}  // namespace

void register_study_extremes(CLI::App* study, const char* name) {
  auto o = std::make_shared<ExtremesCli>();
  CLI::App* cmd = study->add_subcommand(
      name,
      "stiff and extreme cases (gains x10/x100, hand 10-5000 N/m, RM at the "
      "pivot, poles, gimbal singularity, full reach, +-pi, servo jitter, "
      "sensor faults): finite, |F| within the limit, bounded injected "
      "energy, a named status");
  cmd->add_option("--out", o->out,
                  "write DIR/extremes.csv, DIR/extremes.json, DIR/extremes.svg "
                  "and DIR/extremes/<scenario>.csv");
  cmd->add_option("--only", o->only, "run only these scenarios (repeatable)");
  cmd->add_flag("--table", o->table, "print a table instead of the JSON");
  cmd->add_option("--jobs", o->jobs,
                  "scenarios run in parallel (default: one per core)");
  cmd->callback([o] { run(*o); });
}

}  // namespace vmh::cli
