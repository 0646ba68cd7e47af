// `vmhaptics run`, as a user runs it: the files it writes and their columns,
// the summary's fields, and the errors for bad input (named, exit 2, nothing
// written).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

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
  EXPECT_EQ(s.at("mujoco_warnings"), 0);
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

TEST(RunCli, MissingFieldIsNamed) {
  const fs::path dir = fresh_dir("missing");
  fs::create_directories(dir);
  // case1 without vm_kind. MuJoCo resolves includes relative to the scene's
  // folder (even absolute ones), so the copy sits in a cases/ folder beside
  // links to the real omni/ and hand/ folders
  std::ifstream in(std::string(VMH_MODELS_DIR) + "/cases/case1.xml");
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  const std::size_t at = xml.find("<text name=\"vm_kind\"");
  ASSERT_NE(at, std::string::npos);
  xml.erase(at, xml.find("/>", at) + 2 - at);
  for (const char* sub : {"omni", "hand"}) {
    fs::create_directory_symlink(fs::path(VMH_MODELS_DIR) / sub, dir / sub);
  }
  fs::create_directories(dir / "cases");
  const fs::path scene = dir / "cases" / "no_vm_kind.xml";
  std::ofstream(scene) << xml;
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

}  // namespace
