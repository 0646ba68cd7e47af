// `vmhaptics study extremes`, as a user runs it: the JSON on stdout, the
// files under --out with their units in the column names, the exit codes.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using vmh::testing::first_line;
using vmh::testing::run;


TEST(StudyExtremesCli, WritesTablesAndPrintsJson) {
  const fs::path out = fs::path(::testing::TempDir()) / "vmh_study_extremes";
  fs::remove_all(out);
  const auto r = run("study extremes --only fault_jump --only baseline --out " +
                     out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("study"), "extremes");
  ASSERT_EQ(j.at("scenarios").size(), 2u);
  EXPECT_EQ(j.at("scenarios")[0].at("name"), "fault_jump");
  EXPECT_EQ(j.at("scenarios")[0].at("outcome"), "fault_detected:sensor_jump");
  EXPECT_TRUE(j.at("all_pass").get<bool>());

  for (const char* f : {"extremes.csv", "extremes.json", "extremes.svg",
                        "extremes/fault_jump.csv", "extremes/baseline.csv"}) {
    EXPECT_TRUE(fs::exists(out / f)) << f;
  }
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(out / "extremes.json")), j);
  const std::string header = first_line(out / "extremes.csv");
  for (const char* col : {"name,", ",outcome,", ",max_force_N,",
                          ",energy_motor_max_J,", ",rest_energy_rise_J,",
                          ",wall_time_s"}) {
    EXPECT_NE(header.find(col), std::string::npos) << col;
  }
  EXPECT_EQ(first_line(out / "extremes/baseline.csv").rfind("t_s,period_s,F_N,", 0), 0u);
  EXPECT_EQ(first_line(out / "extremes.svg").rfind("<svg", 0), 0u);
}

TEST(StudyExtremesCli, UnknownScenarioIsBadUsage) {
  const auto r = run("study extremes --only no_such_case");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no_such_case"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("gains_x100"), std::string::npos) << "lists the known names";
  EXPECT_EQ(r.out, "");
}

// issue 17: --jobs=-5 ran the study on every core
TEST(StudyExtremesCli, NegativeJobsIsBadUsage) {
  const auto r = run("study extremes --jobs=-5");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--jobs"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  EXPECT_EQ(r.out, "");
}

}  // namespace
