// vmhaptics study sensitivity [--case N ...] [--quick] [--samples S]
//                             [--seed N] [--set name=value ...] [--jobs J]
//                             [--shard K/N] [--out DIR]
// vmhaptics study merge --out DIR PART...
//
// How far each thesis claim survives what is uncertain in the model
// (studies/sensitivity_study.h): one parameter at a time over its range and
// a Latin-hypercube sample of all at once. Writes DIR/sensitivity.json,
// sensitivity.csv and sensitivity.svg (default DIR: out/sensitivity) and
// prints a summary as JSON. With --shard K/N it runs only the points
// i mod N == K - 1 and writes DIR/sensitivity.partial.json; `study merge`
// joins the N partial files into the files one run writes.
// Exit codes: 0 done (claims that fail are results, not errors); 2 bad
// usage or input, nothing written; 1 anything else; 130 / 143 stopped by
// SIGINT / SIGTERM (polled between points, every tick and before the files
// go in: --out as it was, or its files all written if the signal came as
// they went in).
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/args.h"
#include "runtime/json_util.h"
#include "cli/study.h"
#include "cli/study_files.h"
#include "device/stop_signal.h"
#include "output/parallel.h"
#include "output/progress.h"
#include "sim/mujoco_util.h"
#include "thesis/run_case.h"
#include "studies/sensitivity_study.h"

namespace vmh::cli {
namespace {

namespace fs = std::filesystem;

const char* const kSoftware = "vmhaptics " VMH_VERSION;

struct SensitivityCli {
  std::vector<std::string> cases;
  bool quick = false;
  int samples = -1;
  unsigned long long seed = 1;
  std::vector<std::string> sets;
  int jobs = 0;
  std::string shard;
  std::string out = "out/sensitivity";
};

struct MergeCli {
  std::string out;
  std::vector<std::string> parts;
};

// --out as a folder that can be written: an existing writable folder, or
// one whose nearest existing parent is. Nothing is created here.
void check_out(const std::string& out) {
  if (out.empty()) throw UsageError("--out: empty path");
  std::error_code ec;
  fs::path p = fs::absolute(out, ec);
  if (fs::exists(p, ec) && !fs::is_directory(p, ec)) {
    throw UsageError("--out: '" + out + "' exists and is not a directory");
  }
  while (!fs::exists(p, ec)) {
    if (!p.has_parent_path() || p.parent_path() == p) break;
    p = p.parent_path();
  }
  if (!fs::is_directory(p, ec) || access(p.c_str(), W_OK | X_OK) != 0) {
    throw UsageError("--out: cannot write under '" + out + "' (" + p.string() +
                     " is not a writable directory)");
  }
}

// --case items: "2", "case2", "2,6" or a scene path; every case if none
std::vector<std::string> case_names(const std::vector<std::string>& given) {
  std::vector<std::string> items;
  for (const std::string& g : given) {
    std::string::size_type start = 0;
    while (true) {
      const auto comma = g.find(',', start);
      items.push_back(g.substr(start, comma - start));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  std::vector<std::string> out;
  if (items.empty()) {
    for (const auto& c : sim::case_catalogue()) out.push_back(c.name);
    return out;
  }
  for (const std::string& item : items) {
    std::string name;
    const std::string scene = study_scene("--case", item, &name);
    // a thesis case by its name, so that the plan names it the same way
    // whichever spelling was given; a scene file by its path
    bool known = false;
    for (const auto& c : sim::case_catalogue()) known |= name == c.name;
    out.push_back(known ? name : scene);
  }
  return out;
}

void run(const SensitivityCli& o) {
  // SIGINT / SIGTERM only set a flag for the whole run, which the sweep
  // polls (cli/study_files.h): exit 130 / 143, --out as it was
  StopSignals signals;
  int k = 0, n = 0;
  if (!o.shard.empty() && !studies::parse_shard(o.shard, &k, &n)) {
    throw UsageError("--shard: '" + o.shard + "' is not K/N with 1 <= K <= N");
  }
  if (o.jobs < 0) throw UsageError("--jobs: must be >= 1");
  if (o.samples < -1 || o.samples > 100000) {
    throw UsageError("--samples: must be 0..100000");
  }
  for (const std::string& set : o.sets) {
    const std::string field = set.substr(0, set.find('='));
    for (const studies::SweepParameter& p : studies::sweep_parameters()) {
      if (field == p.field) {
        throw UsageError("--set " + field + ": the study sweeps it (" + p.name + ")");
      }
    }
  }
  studies::SensitivityOptions opt;
  opt.sweep.cases = case_names(o.cases);
  opt.sweep.quick = o.quick;
  opt.sweep.samples = o.samples;
  opt.sweep.seed = o.seed;
  opt.sweep.overrides = o.sets;
  opt.sweep.software = kSoftware;
  opt.jobs = o.jobs > 0 ? o.jobs : output::core_count();
  opt.shard_k = k;
  opt.shard_n = n;
  opt.out_dir = o.out;
  opt.should_stop = study_stop();
  check_out(o.out);
  studies::SensitivityResult r;
  try {
    // the bar (on a terminal) is finished before the JSON
    output::Progress bar("study sensitivity", 0);
    opt.progress = bar.part(0);
    r = run_stoppable("study sensitivity",
                      [&] { return studies::run_sensitivity_study(opt); });
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("study sensitivity: ") + e.what());
  }
  throw_if_stopped_after_writing("study sensitivity", o.out);
  std::cout << dump_readable(studies::sensitivity_json(r)) << '\n';
}

void merge(const MergeCli& o) {
  // SIGINT / SIGTERM only set a flag for the whole run: polled before the
  // files go in and after (exit 130 / 143)
  StopSignals signals;
  if (o.parts.empty()) throw UsageError("study merge: give the shards' folders or files");
  check_out(o.out);
  studies::SensitivityResult m;
  try {
    m = studies::merge_partials(o.parts, kSoftware);
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("study merge: ") + e.what());
  }
  runtime::throw_if_stopped("study merge", "; nothing written");
  m.files = studies::write_sensitivity_files(m, o.out);
  throw_if_stopped_after_writing("study merge", o.out);
  std::cout << dump_readable(studies::sensitivity_json(m)) << '\n';
}

}  // namespace

void register_study_sensitivity(CLI::App* study, const char* name) {
  auto o = std::make_shared<SensitivityCli>();
  CLI::App* cmd = study->add_subcommand(
      name,
      "how far each thesis claim survives what is uncertain (the hand's "
      "stiffness, damping, mass and inertia, the Omni's masses and friction, "
      "torque limits, servo period, delay): one parameter at a time and a "
      "Latin-hypercube sample; per claim its holds fraction and the "
      "parameters that flip it");
  cmd->add_option("--case", o->cases,
                  "1..7, case1..case7, a comma list or a scene file; "
                  "repeatable (default: all seven)");
  cmd->add_flag("--quick", o->quick,
                "each parameter at its low and high only, and 16 samples "
                "(about a minute a case on 2 cores)");
  cmd->add_option("--samples", o->samples,
                  "points of the Latin-hypercube sample per case (default 64, "
                  "16 with --quick; 0: none)");
  cmd->add_option("--seed", o->seed, "the sample's seed (default 1)");
  cmd->add_option("--set", o->sets,
                  "override a case parameter for every point, name=value; "
                  "repeatable (not a swept one)")
      ->allow_extra_args(false);
  cmd->add_option("--jobs", o->jobs, "points run in parallel (default: one per core)");
  cmd->add_option("--shard", o->shard,
                  "run only slice K of N (points i with i mod N = K-1) and "
                  "write DIR/sensitivity.partial.json for `study merge`");
  cmd->add_option("--out", o->out,
                  "write DIR/sensitivity.json, .csv and .svg (default "
                  "out/sensitivity)");
  cmd->callback([o] { run(*o); });
}

void register_study_merge(CLI::App* study, const char* name) {
  auto m = std::make_shared<MergeCli>();
  CLI::App* mc = study->add_subcommand(
      name,
      "join the partial files of `study sensitivity --shard K/N` into the "
      "files one unsharded run writes (refused unless they are one sweep, "
      "every point once)");
  mc->add_option("--out", m->out,
                 "write DIR/sensitivity.json, .csv and .svg")
      ->required();
  mc->add_option("parts", m->parts,
                 "the shards' --out folders (or their sensitivity.partial.json)")
      ->required();
  mc->callback([m] { merge(*m); });
}

}  // namespace vmh::cli
