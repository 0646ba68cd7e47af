// vmhaptics study leanness [--case N ...] [--duration S] [--repeats N]
//                          [--set name=value ...] [--out DIR]
//
// Steps per second of each case's scene as composed against the same scene
// with contacts, gravity and a viewer's scene update switched on, each alone
// and all together (sim/leanness_study.h). Prints one JSON object; with
// --out writes DIR/leanness.csv. Exit 2 on bad usage, naming the option.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli/args.h"
#include "cli/json_util.h"
#include "cli/study.h"
#include "cli/study_files.h"
#include "studies/leanness_study.h"
#include "sim/mujoco_util.h"
#include "studies/run_case.h"

namespace vmh::cli {
namespace {

struct LeannessCli {
  std::vector<std::string> cases;  // empty: the six
  double duration_s = studies::LeannessOptions{}.duration_s;
  int repeats = studies::LeannessOptions{}.repeats;
  std::vector<std::string> sets;
  std::string out;
};

Json ingredient_names(unsigned ingredients) {
  Json names = Json::array();
  if (ingredients & studies::kContacts) names.push_back("contacts");
  if (ingredients & studies::kGravity) names.push_back("gravity");
  if (ingredients & studies::kRendering) names.push_back("rendering");
  if (ingredients & studies::kNoFrictionloss) names.push_back("no_frictionloss");
  return names;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void run(const LeannessCli& o) {
  studies::LeannessOptions p;
  if (o.cases.empty()) {
    for (const studies::CaseEntry& c : studies::thesis_cases()) {
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

  studies::LeannessResult r;
  try {
    r = studies::run_leanness_study(p);
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("study leanness: ") + e.what());
  }

  Json cases = Json::array();
  std::vector<std::vector<double>> slowdowns(studies::leanness_variants().size());
  for (const studies::CaseLeanness& c : r.cases) {
    Json variants = Json::array();
    for (std::size_t i = 0; i < c.variants.size(); ++i) {
      const studies::VariantResult& v = c.variants[i];
      slowdowns[i].push_back(v.cpu_slowdown);
      variants.push_back({
          {"variant", v.variant.name},
          {"ingredients", ingredient_names(v.variant.ingredients)},
          {"wall_time_s", v.wall_time_s},
          {"cpu_time_s", v.cpu_time_s},
          {"steps_per_s", v.steps_per_s},
          {"cpu_steps_per_s", v.cpu_steps_per_s},
          {"realtime_factor", v.realtime_factor},
          {"slowdown", v.slowdown},
          {"cpu_slowdown", v.cpu_slowdown},
          {"physics_slowdown", v.physics_slowdown},
          {"contact_enabled", v.contact_enabled},
          {"colliding_geoms", v.colliding_geoms},
          {"gravity_enabled", v.gravity_enabled},
          {"frictionloss_enabled", v.frictionloss_enabled},
          {"mean_ncon", v.mean_ncon},
          {"max_ncon", v.max_ncon},
          {"mean_nefc", v.mean_nefc},
          {"max_nefc", v.max_nefc},
          {"scene_geoms", v.scene_geoms},
          {"render_us_per_tick", v.render_us_per_tick},
          {"max_deviation_mm", v.max_deviation_mm},
          {"mujoco_warnings", v.mujoco_warnings},
      });
    }
    cases.push_back({{"case", c.name},
                     {"scene", c.scene},
                     {"nv", c.nv},
                     {"ngeom", c.ngeom},
                     {"h_s", c.step_s},
                     {"substeps_per_tick", c.substeps},
                     {"ticks", c.ticks},
                     {"controller_cpu_time_s", c.controller_cpu_time_s},
                     {"variants", variants}});
  }
  Json summary = Json::object();
  for (std::size_t i = 0; i < studies::leanness_variants().size(); ++i) {
    summary[studies::leanness_variants()[i].name] = {
        {"median_cpu_slowdown", median(slowdowns[i])}};
  }

  Json result = {
      {"study", "leanness"},
      {"duration_s", r.duration_s},
      {"script", "each case's whole script, compressed into duration_s"},
      {"repeats", r.repeats},
      {"not_measured",
       {{"full_omni",
         "every case scene already holds the full Omni (nv = 6): the "
         "controller reads all six joints and the hand moves them, so no "
         "lighter model would run the same case"}}},
      {"median_over_cases", summary},
      {"cases", cases},
      {"study_wall_time_s", r.study_wall_time_s},
  };
  if (!o.out.empty()) {
    result["files"] = Json::array(
        {write_study_file(o.out, "leanness.csv", studies::leanness_csv(r))});
  }
  std::cout << dump_readable(result) << '\n';
}

}  // namespace

void register_study_leanness(CLI::App* study) {
  auto o = std::make_shared<LeannessCli>();
  CLI::App* cmd = study->add_subcommand(
      "leanness",
      "steps per second of each case's scene as composed against the same "
      "scene with contacts, gravity and a viewer's scene update switched on");
  cmd->add_option("--case", o->cases,
                  "1..6, case1..case6 or a scene file; repeatable (default "
                  "the six cases)")
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
