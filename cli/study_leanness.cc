// vmhaptics study leanness [--case N ...] [--duration S] [--repeats N]
//                          [--set name=value ...] [--out DIR]
//
// Steps per second of each case's scene as composed against the same scene
// with contacts, gravity and a viewer's scene update switched on, each alone
// and all together (studies/leanness_study.h). Prints one JSON object; with
// --out writes DIR/leanness.csv. Exit 2 on bad usage, naming the option;
// 130 / 143 stopped by SIGINT / SIGTERM (--out as it was, or leanness.csv
// written whole if the signal came as it went in).
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli/args.h"
#include "runtime/json_util.h"
#include "cli/study.h"
#include "cli/study_files.h"
#include "device/stop_signal.h"
#include "studies/leanness_study.h"
#include "sim/mujoco_util.h"
#include "thesis/run_case.h"

namespace vmh::cli {
namespace {

struct LeannessCli {
  std::vector<std::string> cases;  // empty: the seven
  double duration_s = studies::LeannessOptions{}.duration_s;
  int repeats = studies::LeannessOptions{}.repeats;
  std::vector<std::string> sets;
  std::string out;
};

void run(const LeannessCli& o) {
  // SIGINT / SIGTERM only set a flag for the whole run, which the study
  // polls (cli/study_files.h): exit 130 / 143, --out as it was
  StopSignals signals;
  studies::LeannessOptions p;
  if (o.cases.empty()) {
    for (const sim::CaseEntry& c : sim::case_catalogue()) {
      std::string name;
      const std::string scene = study_scene("--case", c.name, &name);
      p.scenes.emplace_back(name, scene);
    }
  } else {
    for (const std::string& c : o.cases) {
      std::string name;
      const std::string scene = study_scene("--case", c, &name);
      p.scenes.emplace_back(name, scene);
    }
  }
  if (!(o.duration_s > 0.0)) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", o.duration_s);
    throw UsageError(std::string("--duration: must be > 0 (s), got ") + buf);
  }
  if (o.repeats < 1 || o.repeats > 100) {
    throw UsageError("--repeats: must be in [1, 100], got " +
                     std::to_string(o.repeats));
  }
  p.duration_s = o.duration_s;
  p.repeats = o.repeats;
  for (const std::string& set : o.sets) {
    if (set.substr(0, set.find('=')) == "duration_s") {
      throw UsageError("--set duration_s: the study sets it; use --duration");
    }
  }
  p.overrides = o.sets;

  p.out_dir = o.out;
  p.should_stop = study_stop();

  studies::LeannessResult r;
  try {
    r = run_stoppable("study leanness",
                      [&] { return studies::run_leanness_study(p); });
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("study leanness: ") + e.what());
  }
  throw_if_stopped_after_writing("study leanness", o.out);
  std::cout << dump_readable(studies::leanness_json(r)) << '\n';
}

}  // namespace

void register_study_leanness(CLI::App* study, const char* name) {
  auto o = std::make_shared<LeannessCli>();
  CLI::App* cmd = study->add_subcommand(
      name,
      "steps per second of each case's scene as composed against the same "
      "scene with contacts, gravity and a viewer's scene update switched on");
  cmd->add_option("--case", o->cases,
                  "1..7, case1..case7 or a scene file; repeatable (default "
                  "the seven cases)")
      ->allow_extra_args(false);
  cmd->add_option("--duration", o->duration_s,
                  "simulated seconds per variant and repeat; the case's "
                  "script is compressed into them (default 2)");
  cmd->add_option("--repeats", o->repeats,
                  "runs per variant, interleaved; the fastest is kept "
                  "(default 5)");
  cmd->add_option("--set", o->sets,
                  "override a case parameter, name=value; repeatable")
      ->allow_extra_args(false);
  cmd->add_option("--out", o->out, "write DIR/leanness.csv");
  cmd->callback([o] { run(*o); });
}

}  // namespace vmh::cli
