// `vmhaptics run`, as a user runs it: the files it writes and their columns,
// the summary's fields, and the errors for bad input (named, exit 2, nothing
// written).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using vmh::testing::first_line;
using vmh::testing::run;

fs::path fresh_dir(const std::string& name) {
  return vmh::testing::fresh_dir("vmh_run_", name);
}


TEST(RunCli, WritesTraceAndSummary) {
  const fs::path out = fresh_dir("case1");
  const auto r = run("run case1 --duration 1.5 --out " + out.string());
  // a 1.5 s run has no settled windows for the claims: they fail, exit 1,
  // but the outputs are complete
  EXPECT_EQ(r.exit_code, 1) << r.err;
  ASSERT_TRUE(fs::exists(out / "case1" / "trace.csv"));
  ASSERT_TRUE(fs::exists(out / "case1" / "summary.json"));
  EXPECT_FALSE(fs::exists(out / "case1" / "trace.csv.tmp"));
  for (const char* svg : {"views.svg", "history.svg"}) {
    EXPECT_EQ(first_line(out / "case1" / svg).rfind("<svg", 0), 0u) << svg;
  }

  // the documented columns, in order (docs/outputs.md, "trace.csv")
  const std::string header = first_line(out / "case1" / "trace.csv");
  EXPECT_EQ(header.rfind("t_s,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,"
                         "p_x_mm,p_y_mm,p_z_mm,a_x,a_y,a_z,theta_v_1,"
                         "theta_r_1,xv_x_mm,xv_y_mm,xv_z_mm,xr_x_mm,",
                         0),
            0u)
      << header;
  for (const char* col : {"e_1_mm", "e_6_rad", "f_1_N", "f_6_Nmm", "F_x_N",
                          "F_z_N", "tau_1_Nm", "tau_3_Nm", "hand_x_mm",
                          "hand_z_mm", "d_path_mm", "status", "phase"}) {
    EXPECT_NE(header.find(col), std::string::npos) << col;
  }
  // one row per servo tick: 1.5 s at 1 kHz
  std::ifstream in(out / "case1" / "trace.csv");
  int lines = 0;
  std::string line;
  while (std::getline(in, line)) ++lines;
  EXPECT_EQ(lines, 1 + 1500);

  std::ifstream js(out / "case1" / "summary.json");
  const nlohmann::json s = nlohmann::json::parse(js);
  EXPECT_EQ(s.at("case"), "case1");
  EXPECT_EQ(s.at("thesis_case"), 1);
  EXPECT_EQ(s.at("metrics").at("ticks"), 1500);
  EXPECT_DOUBLE_EQ(s.at("simulated_s").get<double>(), 1.5);
  EXPECT_EQ(s.at("parameters").at("duration_s").at("source"), "set");
  EXPECT_EQ(s.at("parameters").at("vm_kind").at("value"), "circle");
  EXPECT_EQ(s.at("parameters").at("hand_k_pos_N_per_m").at("source"), "scene");
  // the hand's values, together, each with where its default comes from
  const auto& hand = s.at("parameters").at("hand");
  EXPECT_EQ(hand.size(), 6u);
  for (const auto& [name, v] : hand.items()) {
    EXPECT_EQ(name.rfind("hand_", 0), 0u) << name;
    ASSERT_TRUE(v.contains("reference")) << name;
    const std::string ref = v.at("reference");
    EXPECT_NE(ref.find("docs/sources.md"), std::string::npos) << name << ": " << ref;
  }
  // MuJoCo's warnings: none, in the documented shape
  EXPECT_EQ(s.at("mujoco_warnings"),
            nlohmann::json({{"count", 0},
                            {"kinds", nlohmann::json::object()},
                            {"messages", nlohmann::json::array()}}));
  EXPECT_FALSE(s.contains("mujoco_warning_kinds"));
  ASSERT_EQ(s.at("claims").size(), 2u);
  for (const auto& c : s.at("claims")) {
    for (const char* k : {"name", "value", "threshold", "comparison", "unit",
                          "samples", "pass", "prediction", "tolerance",
                          "matches_prediction", "prediction_note",
                          "saturated_fraction", "regime", "holds_where",
                          "sides"}) {
      EXPECT_TRUE(c.contains(k)) << k;
    }
    const std::string regime = c.at("regime");
    EXPECT_TRUE(regime == "linear" || regime == "saturated") << regime;
    // both sides of the pivot (and near the path for an off-path claim)
    ASSERT_GE(c.at("sides").size(), 2u) << c.dump();
    EXPECT_NE(c.at("sides")[0].at("where"), c.at("sides")[1].at("where"));
  }
}

TEST(RunCli, FullCasePassesItsClaims) {
  const auto r = run("run case2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j.at("case2").at("all_claims_pass").get<bool>());
  EXPECT_GE(j.at("case2").at("claims").size(), 4u);
}

TEST(RunCli, UnknownSetNameIsNamedAndWritesNothing) {
  const fs::path out = fresh_dir("badset");
  const auto r = run("run case1 --set k_pos=1 --out " + out.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown parameter 'k_pos'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(RunCli, BadValueIsNamed) {
  const auto r = run("run case1 --set vm_pivot_mm=1,2");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("vm_pivot_mm"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("expects 3"), std::string::npos) << r.err;
}

TEST(RunCli, MalformedSceneIsNamedAndWritesNothing) {
  const fs::path dir = fresh_dir("malformed");
  fs::create_directories(dir);
  const fs::path scene = dir / "broken.xml";
  std::ofstream(scene) << "<mujoco><worldbody><body>\n";
  const auto r = run("run " + scene.string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(scene.string()), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// case1.xml's text, to edit into another scene
std::string case1_xml() {
  std::ifstream in(std::string(VMH_MODELS_DIR) + "/cases/case1.xml");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// `xml` written as dir/cases/<name>. MuJoCo resolves includes relative to
// the scene's folder (even absolute ones), so the copy sits in a cases/
// folder beside links to the real omni/ and hand/ folders
fs::path scene_in(const fs::path& dir, const std::string& name,
                  const std::string& xml) {
  fs::create_directories(dir / "cases");
  for (const char* sub : {"omni", "hand"}) {
    fs::create_directory_symlink(fs::path(VMH_MODELS_DIR) / sub, dir / sub);
  }
  const fs::path scene = dir / "cases" / name;
  std::ofstream(scene) << xml;
  return scene;
}

TEST(RunCli, MissingFieldIsNamed) {
  const fs::path dir = fresh_dir("missing");
  // case1 without vm_kind
  std::string xml = case1_xml();
  const std::size_t at = xml.find("<text name=\"vm_kind\"");
  ASSERT_NE(at, std::string::npos);
  xml.erase(at, xml.find("/>", at) + 2 - at);
  const fs::path scene = scene_in(dir, "no_vm_kind.xml", xml);
  const auto r = run("run " + scene.string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("missing <custom> field 'vm_kind'"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(scene.string()), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(RunCli, UnknownCaseAndUsage) {
  auto r = run("run case7");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("'case7'"), std::string::npos) << r.err;
  r = run("run");
  EXPECT_EQ(r.exit_code, 2);
  r = run("run case1 --all");
  EXPECT_EQ(r.exit_code, 2);
}

// ---- bounds, checked before any work, and physics gone bad (issue 17) ----

// refused as bad input: exit 2, nothing on stdout, one line on stderr with
// every needle
void expect_refused(const std::string& args,
                    const std::vector<std::string>& needles) {
  const auto r = run(args);
  EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
  EXPECT_TRUE(r.out.empty()) << args << " printed " << r.out;
  for (const std::string& n : needles) {
    EXPECT_NE(r.err.find(n), std::string::npos)
        << args << ": '" << r.err << "' lacks '" << n << "'";
  }
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
}

// --duration was a double CLI11 read leniently: "", 0 and nan ran the
// scene's 20 s, 1e308 and 4294968 s wrapped the tick count and ran forever,
// 1e-7 was reported as "0.000000"
TEST(RunCli, DurationIsCheckedBeforeAnyWork) {
  const std::string range = "--duration: field 'duration_s' must be > 0 and "
                            "<= 3600, got ";
  expect_refused("run case1 --duration 1e308", {range + "1e+308"});
  expect_refused("run case1 --duration 4294968", {range + "4294968"});
  expect_refused("run case1 --duration 0", {range + "0"});
  expect_refused("run case1 --duration=-2", {range + "-2"});
  expect_refused("run case1 --duration nan",
                 {"--duration: value 'nan' is not a finite number"});
  expect_refused("run case1 --duration 1e999", {"not a finite number"});
  expect_refused("run case1 --duration ''", {"--duration", "empty"});
  expect_refused("run case1 --duration 1e-7",
                 {"duration_s (1e-07 s) must last from 1 to 1000000000 servo "
                  "periods"});
  // and the check comes before the scene is even looked for
  expect_refused("run case7 --duration 1e308", {"--duration"});
}

TEST(RunCli, TimingParametersAreBounded) {
  expect_refused("run case1 --set servo_period_s=3e6",
                 {"--set: field 'servo_period_s' must be in [1e-05, 1], got "
                  "3000000"});
  expect_refused("run case1 --set physics_step_s=1e-300",
                 {"servo_period_s / physics_step_s (0.001 s / 1e-300 s)",
                  "[1, 1000000], got 1e+297"});
  expect_refused("run case1 --set servo_jitter_s=0.0004,1e12",
                 {"field 'servo_jitter_s' must be >= 0 and <= 1, got 1e+12"});
  expect_refused("run case1 --set physics_step_s=1e-7 "
                 "--set servo_jitter_s=0.0004,0.9",
                 {"servo_jitter_s's longest period", "got 9000000"});
  expect_refused("run case1 --set delay_ticks=65",
                 {"field 'delay_ticks' must be a whole number in [0, 64], got "
                  "65"});
  expect_refused("run case1 --set duration_s=",
                 {"field 'duration_s' expects 1 value(s), got 0"});
  expect_refused("run case1 --jobs ''", {"--jobs", "empty"});
}

// a scene whose own step is 0 made the servo period an infinite number of
// physics steps
TEST(RunCli, ASceneStepOfZeroIsRefused) {
  const fs::path dir = fresh_dir("timestep0");
  std::string xml = case1_xml();
  const std::size_t at = xml.find("timestep=\"0.001\"");
  ASSERT_NE(at, std::string::npos);
  xml.replace(at, std::string("timestep=\"0.001\"").size(), "timestep=\"0\"");
  const fs::path scene = scene_in(dir, "timestep0.xml", xml);
  expect_refused("run " + scene.string(),
                 {scene.string(),
                  "the scene's <option timestep> must be finite and > 0, got "
                  "0 s"});
}

// Physics that goes non-finite at the first step: MuJoCo resets the state
// and warns (on stdout, into MUJOCO_LOG.TXT, 999 times over a run, by
// default); the run went on and exited 0. Now it stops with exit 1 and a
// named error, MuJoCo's warning on stderr before it, nothing on stdout and
// no log file in the working directory.
TEST(RunCli, NonFinitePhysicsStopsTheRunWithExitOne) {
  const fs::path dir = fresh_dir("nan_physics");
  fs::create_directories(dir);
  const auto r = run("run case1 --json --set hand_k_pos_N_per_m=1e30",
                     "cd " + dir.string() + " && ");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("vmhaptics: error: run case1: "), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("physics went non-finite at t=0.001 s (q"),
            std::string::npos)
      << r.err;
  // MuJoCo's warning, once, on stderr before the error line
  EXPECT_EQ(r.err.rfind("vmhaptics: warning: MuJoCo warning (bad", 0), 0u)
      << r.err;
  const std::size_t last = r.err.rfind('\n', r.err.size() - 2);
  EXPECT_EQ(r.err.compare(last + 1, 17, "vmhaptics: error:"), 0) << r.err;
  EXPECT_TRUE(fs::is_empty(dir)) << "left a file in the working directory";
}

}  // namespace
