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

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "cli/args.h"
#include "runtime/json_util.h"
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

// how far the recording moves the joints: the sum over t1..t6 of each
// angle's 5th-95th percentile spread, rad
double joint_excursion_rad(const Recording& r) {
  const std::vector<std::size_t> rows = r.good_rows();
  if (rows.size() < 2) return 0.0;
  double sum = 0.0;
  for (int j = 1; j <= 6; ++j) {
    const std::vector<double>& q = r.col("q" + std::to_string(j) + "_rad");
    std::vector<double> v;
    v.reserve(rows.size());
    for (std::size_t k : rows) v.push_back(q[k]);
    std::sort(v.begin(), v.end());
    sum += v[v.size() * 95 / 100] - v[v.size() * 5 / 100];
  }
  return sum;
}

// A delay is the device's, not one pulse's: the motor tests' delay_<M>ms
// are merged into one with M their median (each lag is found to the
// millisecond, so one test of three may land a step off)
void merge_delays(std::vector<bringup::SuspectedFault>* faults) {
  std::vector<long> ms;
  for (const bringup::SuspectedFault& f : *faults) {
    long m = 0;
    if (std::sscanf(f.name.c_str(), "delay_%ldms", &m) == 1) ms.push_back(m);
  }
  if (ms.size() < 2) return;
  std::sort(ms.begin(), ms.end());
  const std::string name = "delay_" + std::to_string(ms[ms.size() / 2]) + "ms";
  for (bringup::SuspectedFault& f : *faults) {
    long m = 0;
    if (std::sscanf(f.name.c_str(), "delay_%ldms", &m) == 1 && f.name != name) {
      f.evidence += " (merged: the median of the motor tests' delays is " + name + ")";
      f.name = name;
    }
  }
}

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
  // The readings' map and the kinematics are judged on the recording that
  // moves the joints most (the workspace tour): a motor test moves little,
  // and a fit of the geometry to a few poses can explain a sign away as an
  // offset. Recordings that move at least half as much are judged too; the
  // map found applies to every recording (one device, one codec).
  std::vector<double> excitation(recs.size(), 0.0);
  std::size_t richest = recs.size();
  for (std::size_t i = 0; i < recs.size(); ++i) {
    excitation[i] = joint_excursion_rad(recs[i]);
    if (recs[i].has_transform() &&
        (richest == recs.size() || excitation[i] > excitation[richest])) {
      richest = i;
    }
  }
  bringup::ReadingMap shared;
  if (richest < recs.size()) shared = bringup::diagnose_readings(recs[richest]).map;
  std::vector<bool> judge_kinematics(recs.size(), true);
  for (std::size_t i = 0; i < recs.size(); ++i) {
    if (richest < recs.size() && i != richest &&
        excitation[i] < 0.5 * excitation[richest]) {
      judge_kinematics[i] = false;
    }
  }

  try {
    for (std::size_t i = 0; i < recs.size(); ++i) {
      const Recording& r = recs[i];
      const std::string figs = figure_dir(o, r);
      if (judge_kinematics[i]) {
        sections.push_back(bringup::compare_kinematics(r, figs));
      } else {
        CompareSection k;
        k.name = "kinematics";
        k.skipped.push_back({"kinematics.*",
                             "judged on " + recs[richest].dir +
                                 ", which moves the joints more",
                             r.dir});
        sections.push_back(k);
      }
      sections.push_back(bringup::compare_jacobian(r, shared, figs));
      if (r.verb == "hw motor-test") {
        bringup::ForceOptions fo;
        if (!o.scene.empty()) fo.scene = o.scene;
        sections.push_back(bringup::compare_force_direction(r, shared, fo, figs));
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

  std::vector<bringup::SuspectedFault> all_faults;
  for (const CompareSection& s : sections) {
    all_faults.insert(all_faults.end(), s.faults.begin(), s.faults.end());
  }
  merge_delays(&all_faults);

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
    for (const std::string& f : s.figures) figures.push_back(f);
    if (!s.detail.empty()) detail.push_back({{"section", s.name}, {"detail", s.detail}});
  }
  for (const bringup::SuspectedFault& f : all_faults) {
    evidence.push_back({{"name", f.name}, {"evidence", f.evidence}, {"recording", f.recording}});
    if (seen.insert(f.name).second) faults.push_back(f.name);
  }
  Json recordings = Json::array();
  for (const Recording& r : recs) {
    recordings.push_back({{"dir", r.dir}, {"verb", r.verb}, {"rows", r.rows},
                          {"joint_excursion_rad", excitation[&r - recs.data()]},
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
                  "does not name one (default models/cases/case1.xml, the emulator's)");
  cmd->callback([o]() { compare(*o); });
}

}  // namespace vmh::cli
