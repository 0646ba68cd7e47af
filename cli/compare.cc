// vmhaptics compare <recording-dir>... [--out DIR] [--scene S] [--model F]
//
// Each recording (from `hw record`, `hw motor-test`, `hw run`) goes through
// the analyses it holds the data for:
//   kinematics   the device reports its own transform (dev_p_*, dev_R_*)
//   jacobian     ... its Jacobian or velocity (dev_J_*, dev_v_*)
//   force_direction  a motor-test pulse
//   force_mapping, closed_loop  an `hw run`
// A sign or swap found in the readings (kinematics) is applied to every
// recording of the same device before the other analyses read it, so that
// one mistake is named once. Prints one JSON object: checks (each {name,
// pass, value, threshold, unit}), skipped checks, suspected_faults (names
// from docs/bringup.md's vocabulary) with their evidence, sections' detail
// and figures. Exit 0 when every check passes; 1 when one fails (the JSON
// is printed first); 2 on bad input (a directory that is not a recording).
#include "cli/compare.h"

#include <filesystem>
#include <iostream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "cli/args.h"
#include "cli/json_util.h"
#include "report/output_file.h"
#include "sim/mujoco_util.h"
#include "studies/bringup/compare_check.h"
#include "studies/bringup/compare_force.h"
#include "studies/bringup/compare_jacobian.h"
#include "studies/bringup/compare_kinematics.h"
#include "studies/bringup/compare_replay.h"
#include "studies/bringup/recording.h"

namespace vmh::cli {
namespace {

namespace fs = std::filesystem;
using bringup::CompareSection;
using bringup::Recording;

struct CompareOptions {
  std::vector<std::string> dirs;
  std::string out;
  std::string scene;  // to predict with when a recording does not name one
};

// where a recording's figures go: DIR/<recording's folder name>/
std::string figure_dir(const CompareOptions& o, const Recording& r) {
  if (o.out.empty()) return {};
  std::string name = fs::path(r.dir).filename().string();
  if (name.empty()) name = fs::path(r.dir).parent_path().filename().string();
  const fs::path d = fs::path(o.out) / name;
  fs::create_directories(d);
  return d.string();
}

void compare(const CompareOptions& o) {
  if (o.dirs.empty()) throw UsageError("compare: give at least one recording directory");
  std::vector<Recording> recs;
  try {
    for (const std::string& d : o.dirs) recs.push_back(bringup::load_recording(d));
  } catch (const bringup::RecordingError& e) {
    throw UsageError(std::string("compare: ") + e.what());
  }

  std::vector<CompareSection> sections;
  // the readings' map: from each recording that reports a transform; one
  // that does not takes the map the others agree on
  std::vector<bringup::ReadingMap> maps(recs.size());
  bringup::ReadingMap shared;
  for (std::size_t i = 0; i < recs.size(); ++i) {
    if (!recs[i].has_transform()) continue;
    maps[i] = bringup::diagnose_readings(recs[i]).map;
    if (!maps[i].is_identity()) shared = maps[i];
  }
  for (std::size_t i = 0; i < recs.size(); ++i) {
    if (!recs[i].has_transform()) maps[i] = shared;
  }

  try {
    for (std::size_t i = 0; i < recs.size(); ++i) {
      const Recording& r = recs[i];
      const std::string figs = figure_dir(o, r);
      sections.push_back(bringup::compare_kinematics(r, figs));
      sections.push_back(bringup::compare_jacobian(r, maps[i], figs));
      if (r.verb == "hw motor-test") {
        bringup::ForceOptions fo;
        if (!o.scene.empty()) fo.scene = o.scene;
        sections.push_back(bringup::compare_force_direction(r, maps[i], fo, figs));
      }
      if (r.verb == "hw run") {
        sections.push_back(bringup::compare_force_mapping(r));
        bringup::ReplayOptions ro;
        sections.push_back(bringup::compare_closed_loop(r, ro, figs));
      }
    }
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("compare: ") + e.what());
  } catch (const bringup::RecordingError& e) {
    throw UsageError(std::string("compare: ") + e.what());
  }

  Json checks = Json::array(), skipped = Json::array(), evidence = Json::array();
  Json figures = Json::array(), detail = Json::array();
  std::vector<std::string> faults;
  std::set<std::string> seen;
  long failed = 0;
  for (const CompareSection& s : sections) {
    for (const bringup::CompareCheck& c : s.checks) {
      checks.push_back(bringup::check_json(c));
      if (!c.pass) ++failed;
    }
    for (const bringup::SkippedCheck& k : s.skipped) {
      skipped.push_back({{"name", k.name}, {"reason", k.reason}, {"recording", k.recording}});
    }
    for (const bringup::SuspectedFault& f : s.faults) {
      evidence.push_back({{"name", f.name}, {"evidence", f.evidence}, {"recording", f.recording}});
      if (seen.insert(f.name).second) faults.push_back(f.name);
    }
    for (const std::string& f : s.figures) figures.push_back(f);
    if (!s.detail.empty()) detail.push_back({{"section", s.name}, {"detail", s.detail}});
  }
  Json recordings = Json::array();
  for (const Recording& r : recs) {
    recordings.push_back({{"dir", r.dir}, {"verb", r.verb}, {"rows", r.rows},
                          {"reports_transform", r.has_transform()},
                          {"reports_jacobian", r.has_jacobian()}});
  }
  Json out{{"recordings", recordings},
           {"pass", failed == 0},
           {"checks_failed", failed},
           {"suspected_faults", faults},
           {"checks", checks},
           {"skipped", skipped},
           {"evidence", evidence},
           {"figures", figures},
           {"detail", detail}};
  if (!o.out.empty()) {
    report::write_file_in(o.out, "compare.json", dump_readable(out) + "\n");
  }
  std::cout << dump_readable(out) << '\n';
  if (failed > 0) {
    std::string names;
    for (const std::string& f : faults) names += (names.empty() ? "" : ", ") + f;
    throw std::runtime_error("compare: " + std::to_string(failed) +
                             " check(s) failed; suspected faults: " +
                             (names.empty() ? "none named" : names));
  }
}

}  // namespace

void register_compare(CLI::App* app) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* cmd = app->add_subcommand(
      "compare",
      "device recordings (hw record, motor-test, run) against the project's "
      "kinematics and the MJCF Omni: checks, suspected faults, figures "
      "(docs/bringup.md)");
  cmd->add_option("recordings", o->dirs, "recording directories (DIR/meta.json, DIR/trace.csv)")
      ->required();
  cmd->add_option("--out", o->out, "write DIR/compare.json and the figures");
  cmd->add_option("--scene", o->scene,
                  "the scene to predict a motor test with when the recording "
                  "does not name one (default models/omni/scene.xml)");
  cmd->callback([o]() { compare(*o); });
}

}  // namespace vmh::cli
