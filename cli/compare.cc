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
// is printed first); 2 on bad input (a directory that is not a recording,
// an --out that cannot be its output: see below); 130 / 143 SIGINT /
// SIGTERM (nothing written, --out left as it was, unless the signal came
// after the set was in place: then the set is whole).
//
// --out DIR is one output set (output/output_file.h): compare.json and each
// recording's figures, in DIR/<recording's name>/, are written into a
// private folder beside DIR which then replaces DIR whole; a reader sees
// the previous set or the new one, and of two runs at once the last to
// finish wins. A recording's name is its folder's last name reduced to
// [A-Za-z0-9._-], made unique by "-2", "-3", ... in the order given (a/rec
// and b/rec: rec and rec-2). Since DIR is replaced, compare refuses a DIR
// that holds one of its recordings, or a folder with files in it but no
// compare.json (not an earlier compare's output).
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
#include "device/stop_signal.h"
#include "runtime/json_util.h"
#include "runtime/stop.h"
#include "output/output_file.h"
#include "sim/mujoco_util.h"
#include "bringup/compare_check.h"
#include "bringup/compare_force.h"
#include "bringup/compare_jacobian.h"
#include "bringup/compare_kinematics.h"
#include "bringup/compare_replay.h"
#include "bringup/recording.h"

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

// A recording's name among the figure folders: its folder's last name with
// anything outside [A-Za-z0-9._-] as '_' (a leading '.' too, so that it is
// not hidden), "recording" if nothing is left, and "-2", "-3", ... after a
// name already taken (compare.json's name included).
std::string figure_folder_name(const std::string& dir,
                               std::set<std::string>* taken) {
  fs::path p = fs::path(dir).lexically_normal();
  if (!p.has_filename()) p = p.parent_path();
  std::string name = p.filename().string();
  if (name == "." || name == "..") {
    name = fs::weakly_canonical(fs::absolute(dir)).filename().string();
  }
  for (char& ch : name) {
    const auto u = static_cast<unsigned char>(ch);
    const bool safe = (u >= 'a' && u <= 'z') || (u >= 'A' && u <= 'Z') ||
                      (u >= '0' && u <= '9') || ch == '.' || ch == '_' ||
                      ch == '-';
    if (!safe) ch = '_';
  }
  if (!name.empty() && name[0] == '.') name[0] = '_';
  if (name.size() > 100) name.resize(100);
  if (name.empty()) name = "recording";
  std::string unique = name;
  for (int k = 2; taken->count(unique) > 0; ++k) {
    unique = name + "-" + std::to_string(k);
  }
  taken->insert(unique);
  return unique;
}

// --out as a path whose last name is the set's folder ("X/" is X), or a
// UsageError when it names none ("", ".", "/") or cannot be replaced by
// compare's set (a file, a folder holding one of `recs`, a folder with
// files but no compare.json)
std::string check_out(const std::string& out, const std::vector<Recording>& recs) {
  fs::path p = fs::path(out).lexically_normal();
  if (!p.has_filename() && p.has_parent_path() && p != p.root_path()) {
    p = p.parent_path();
  }
  const std::string last = p.filename().string();
  if (out.empty() || last.empty() || last == "." || last == "..") {
    throw UsageError("compare: --out '" + out +
                     "' names no folder of its own (compare replaces its "
                     "--out folder whole; give e.g. out/compare)");
  }
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(p, ec);
  if (!ec && fs::exists(st) && !fs::is_directory(st)) {
    throw UsageError("compare: --out '" + out + "' is not a folder (it is " +
                     (fs::is_symlink(st) ? "a symbolic link" : "a file") + ")");
  }
  const fs::path where = fs::weakly_canonical(fs::absolute(p), ec);
  for (const Recording& r : recs) {
    std::error_code rec_ec;
    const fs::path rec = fs::weakly_canonical(fs::absolute(r.dir), rec_ec);
    const auto [end, rest] =
        std::mismatch(where.begin(), where.end(), rec.begin(), rec.end());
    if (!ec && !rec_ec && end == where.end()) {
      throw UsageError("compare: --out '" + out + "' holds the recording " +
                       r.dir + " (compare replaces its --out folder whole)");
    }
  }
  if (fs::is_directory(st) && !fs::is_empty(p, ec) &&
      !fs::is_regular_file(p / "compare.json", ec)) {
    throw UsageError("compare: --out '" + out +
                     "' is a folder with files in it but no compare.json: not "
                     "an earlier compare's output, and compare replaces its "
                     "--out folder whole");
  }
  return p.string();
}

const char kNothing[] = "; nothing written";

// each directory's recording, in the order given, with the note on its
// analysis window on stderr; a directory that is not a recording is a
// UsageError
std::vector<Recording> load_recordings(const std::vector<std::string>& dirs) {
  std::vector<Recording> recs;
  try {
    for (const std::string& d : dirs) {
      runtime::throw_if_stopped("compare", kNothing);
      recs.push_back(bringup::load_recording(d));
      if (const std::string note = bringup::window_note(recs.back()); !note.empty()) {
        std::cerr << "compare: " << note << '\n';
      }
    }
  } catch (const bringup::RecordingError& e) {
    throw UsageError(std::string("compare: ") + e.what());
  }
  return recs;
}

// The set: each recording's figures in <its name>/ of a private folder,
// which replaces --out whole once compare.json is beside them. Without
// --out there is none, and nothing is written.
class CompareOutput {
 public:
  CompareOutput(const std::string& out, const std::vector<Recording>& recs) {
    if (out.empty()) return;
    out_dir_ = check_out(out, recs);
    try {
      set_ = std::make_unique<output::OutputSet>(out_dir_);
    } catch (const std::runtime_error& e) {
      throw UsageError("compare: --out '" + out + "': " + e.what());
    }
    std::set<std::string> taken{"compare.json"};
    for (const Recording& r : recs) {
      folder_names_.push_back(figure_folder_name(r.dir, &taken));
    }
  }

  bool active() const { return set_ != nullptr; }
  const std::string& dir() const { return out_dir_; }

  // where recording i's figures are written now (empty: none)
  std::string figure_dir(std::size_t i) const {
    if (!set_) return {};
    return (fs::path(set_->temp_dir()) / folder_names_[i]).string();
  }

  // the name a written file will have once the set is in place
  std::string shown(const std::string& written) const {
    if (!set_) return written;
    const std::string tmp = set_->temp_dir() + "/";
    return written.rfind(tmp, 0) == 0
               ? (fs::path(out_dir_) / written.substr(tmp.size())).string()
               : written;
  }

  // recording i's figure folder once the set is in place, or null
  Json figures_dir_json(std::size_t i) const {
    return set_ ? Json((fs::path(out_dir_) / folder_names_[i]).string())
                : Json(nullptr);
  }

  // compare.json beside the figures, and the set in place of --out
  void commit(const Json& out) {
    if (!set_) return;
    set_->write("compare.json", dump_readable(out) + "\n");
    set_->commit();
  }

 private:
  std::unique_ptr<output::OutputSet> set_;
  std::string out_dir_;
  std::vector<std::string> folder_names_;  // of each recording's figures
};

// The readings' map and the kinematics are judged on the recording that
// moves the joints most (the workspace tour): a motor test moves little,
// and a fit of the geometry to a few poses can explain a sign away as an
// offset. Recordings that move at least half as much are judged too; the
// map found applies to every recording (one device, one codec).
struct KinematicsPlan {
  std::vector<double> excitation;  // joint_excursion_rad of each recording
  std::size_t richest = 0;  // the one judged first; recs.size(): none
  bringup::ReadingMap shared;
  std::vector<bool> judge;  // whose kinematics are judged
};

KinematicsPlan plan_kinematics(const std::vector<Recording>& recs) {
  KinematicsPlan p;
  p.excitation.assign(recs.size(), 0.0);
  p.richest = recs.size();
  for (std::size_t i = 0; i < recs.size(); ++i) {
    p.excitation[i] = joint_excursion_rad(recs[i]);
    if (recs[i].has_transform() &&
        (p.richest == recs.size() || p.excitation[i] > p.excitation[p.richest])) {
      p.richest = i;
    }
  }
  if (p.richest < recs.size()) {
    p.shared = bringup::diagnose_readings(recs[p.richest]).map;
  }
  p.judge.assign(recs.size(), true);
  for (std::size_t i = 0; i < recs.size(); ++i) {
    if (p.richest < recs.size() && i != p.richest &&
        p.excitation[i] < 0.5 * p.excitation[p.richest]) {
      p.judge[i] = false;
    }
  }
  return p;
}

// Recording i's sections, appended in order: its kinematics (or why they
// are judged on another), its Jacobian, a motor test's force direction, an
// hw run's force mapping and closed loop; figures into `figs` (empty: none)
void recording_sections(const std::vector<Recording>& recs, std::size_t i,
                        const KinematicsPlan& plan, const std::string& scene,
                        const std::string& figs,
                        std::vector<CompareSection>* sections) {
  const Recording& r = recs[i];
  runtime::throw_if_stopped("compare", kNothing);
  if (plan.judge[i]) {
    sections->push_back(bringup::compare_kinematics(r, figs));
  } else {
    CompareSection k;
    k.name = "kinematics";
    k.skipped.push_back({"kinematics.*",
                         "judged on " + recs[plan.richest].dir +
                             ", which moves the joints more",
                         r.dir});
    sections->push_back(k);
  }
  runtime::throw_if_stopped("compare", kNothing);
  sections->push_back(bringup::compare_jacobian(r, plan.shared, figs));
  if (r.verb == "hw motor-test") {
    bringup::ForceOptions fo;
    if (!scene.empty()) fo.scene = scene;
    runtime::throw_if_stopped("compare", kNothing);
    sections->push_back(
        bringup::compare_force_direction(r, plan.shared, fo, figs));
  }
  if (r.verb == "hw run") {
    sections->push_back(bringup::compare_force_mapping(r));
    bringup::ReplayOptions ro;
    runtime::throw_if_stopped("compare", kNothing);
    sections->push_back(bringup::compare_closed_loop(r, ro, figs));
  }
}

// every recording's sections, in the order given; a scene or recording
// that cannot be read is a UsageError
std::vector<CompareSection> compare_sections(const std::vector<Recording>& recs,
                                             const KinematicsPlan& plan,
                                             const std::string& scene,
                                             const CompareOutput& output) {
  std::vector<CompareSection> sections;
  try {
    for (std::size_t i = 0; i < recs.size(); ++i) {
      recording_sections(recs, i, plan, scene, output.figure_dir(i),
                         &sections);
    }
  } catch (const sim::SimError& e) {
    throw UsageError(std::string("compare: ") + e.what());
  } catch (const bringup::RecordingError& e) {
    throw UsageError(std::string("compare: ") + e.what());
  }
  return sections;
}

// What the sections found, as compare.json's arrays: every check (and how
// many failed), skipped check, figure (by its name once in place) and
// detail; the suspected faults with their evidence, the delays merged, and
// their names once each in the order found.
struct CompareFindings {
  Json checks = Json::array(), skipped = Json::array(), evidence = Json::array();
  Json figures = Json::array(), detail = Json::array();
  std::vector<std::string> faults;
  long failed = 0;
};

CompareFindings gather_findings(const std::vector<CompareSection>& sections,
                                const CompareOutput& output) {
  std::vector<bringup::SuspectedFault> all_faults;
  for (const CompareSection& s : sections) {
    all_faults.insert(all_faults.end(), s.faults.begin(), s.faults.end());
  }
  merge_delays(&all_faults);

  CompareFindings f;
  for (const CompareSection& s : sections) {
    for (const bringup::CompareCheck& c : s.checks) {
      f.checks.push_back(bringup::check_json(c));
      if (!c.pass) ++f.failed;
    }
    for (const bringup::SkippedCheck& k : s.skipped) {
      f.skipped.push_back({{"name", k.name}, {"reason", k.reason}, {"recording", k.recording}});
    }
    for (const std::string& fig : s.figures) f.figures.push_back(output.shown(fig));
    if (!s.detail.empty()) f.detail.push_back({{"section", s.name}, {"detail", s.detail}});
  }
  std::set<std::string> seen;
  for (const bringup::SuspectedFault& sf : all_faults) {
    f.evidence.push_back({{"name", sf.name}, {"evidence", sf.evidence}, {"recording", sf.recording}});
    if (seen.insert(sf.name).second) f.faults.push_back(sf.name);
  }
  return f;
}

// compare.json's recordings: what each holds and where its figures went
Json recordings_json(const std::vector<Recording>& recs,
                     const KinematicsPlan& plan, const CompareOutput& output) {
  Json recordings = Json::array();
  for (std::size_t i = 0; i < recs.size(); ++i) {
    const Recording& r = recs[i];
    recordings.push_back({{"dir", r.dir}, {"verb", r.verb}, {"rows", r.rows},
                          {"rows_in_trace", r.rows_in_trace},
                          {"joint_excursion_rad", plan.excitation[i]},
                          {"reports_transform", r.has_transform()},
                          {"reports_jacobian", r.has_jacobian()},
                          {"figures_dir", output.figures_dir_json(i)}});
  }
  return recordings;
}

// exit 1 when a check failed (the JSON is out first), naming the faults
void throw_if_failed(const CompareFindings& f) {
  if (f.failed == 0) return;
  std::string names;
  for (const std::string& n : f.faults) names += (names.empty() ? "" : ", ") + n;
  throw std::runtime_error("compare: " + std::to_string(f.failed) +
                           " check(s) failed; suspected faults: " +
                           (names.empty() ? "none named" : names));
}

void compare(const CompareOptions& o) {
  if (o.dirs.empty()) throw UsageError("compare: give at least one recording directory");
  // SIGINT / SIGTERM only set a flag from here on (device/stop_signal.h),
  // polled between recordings and sections and before the set is put in
  // place: a stopped compare leaves --out as it was
  StopSignals signals;
  const std::vector<Recording> recs = load_recordings(o.dirs);
  runtime::throw_if_stopped("compare", kNothing);
  CompareOutput output(o.out, recs);
  const KinematicsPlan plan = plan_kinematics(recs);
  const std::vector<CompareSection> sections =
      compare_sections(recs, plan, o.scene, output);
  const CompareFindings f = gather_findings(sections, output);
  Json out{{"recordings", recordings_json(recs, plan, output)},
           {"pass", f.failed == 0},
           {"checks_failed", f.failed},
           {"suspected_faults", f.faults},
           {"checks", f.checks},
           {"skipped", f.skipped},
           {"evidence", f.evidence},
           {"figures", f.figures},
           {"detail", f.detail}};
  runtime::throw_if_stopped("compare", kNothing);
  output.commit(out);
  // a signal while the set went in: it is whole, and the exit says so
  runtime::throw_if_stopped(
      "compare", output.active()
                     ? "; " + output.dir() + " was already written whole"
                     : kNothing);
  std::cout << dump_readable(out) << '\n';
  throw_if_failed(f);
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
  cmd->add_option("--out", o->out,
                  "write DIR/compare.json and the figures, DIR/<recording>/*.svg, "
                  "as one set that replaces DIR whole (a new or empty folder, "
                  "or an earlier compare's)");
  cmd->add_option("--scene", o->scene,
                  "the scene to predict a motor test with when the recording "
                  "does not name one (default models/cases/case1.xml, the emulator's)");
  cmd->callback([o]() { compare(*o); });
}

}  // namespace vmh::cli
