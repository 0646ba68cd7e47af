// `vmhaptics study precision` and `vmhaptics study leanness`, as a user runs
// them: the JSON keys, the files under --out, and one-line errors (exit 2)
// that name the option, with nothing written.
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

fs::path precision_dir(const std::string& name) {
  return vmh::testing::fresh_dir("vmh_study_", name);
}


// a precision study small enough for a test: 0.2 s of the script
// compressed into 2 s, two rungs, a coarse reference
const char* const kQuick =
    "study precision --case 1 --duration 0.2 --set duration_s=2 "
    "--steps 1e-3,5e-4 --reference-step 5e-5 --reference-check-step 1e-4 "
    "--integrators euler,rk4";

TEST(StudyPrecisionCli, PrintsJsonAndWritesTableAndCharts) {
  const fs::path out = precision_dir("precision");
  const auto r = run(std::string(kQuick) + " --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  for (const char* k :
       {"study", "case", "scene", "duration_s", "servo_period_s", "ticks",
        "quantize", "segments", "reference", "fit_floor_mm", "orders",
        "default", "front", "rows", "study_wall_time_s", "files"}) {
    EXPECT_TRUE(j.contains(k)) << k;
  }
  EXPECT_EQ(j.at("study"), "precision");
  EXPECT_EQ(j.at("case"), "case1");
  EXPECT_EQ(j.at("quantize"), 0);
  EXPECT_EQ(j.at("ticks"), 200);
  // euler: 1 ms (the default), 0.5 ms; rk4: 1 ms, 0.5 ms
  EXPECT_EQ(j.at("rows").size(), 4u);
  EXPECT_EQ(j.at("orders").size(), 2u);
  EXPECT_EQ(j.at("default").at("integrator"), "euler");
  EXPECT_DOUBLE_EQ(j.at("default").at("h_s").get<double>(), 1e-3);
  EXPECT_TRUE(j.at("default").at("on_front").is_boolean());
  EXPECT_EQ(j.at("reference").at("integrator"), "rk4");
  for (const char* k : {"rms_error_mm", "max_error_mm", "wall_time_s",
                        "steps_per_s", "on_front", "local_order"}) {
    EXPECT_TRUE(j.at("rows").at(0).contains(k)) << k;
  }

  EXPECT_EQ(first_line(out / "precision.csv")
                .rfind("integrator,h_s,substeps_per_tick,rms_error_mm,", 0),
            0u);
  for (const char* svg : {"precision.svg", "precision_order.svg"}) {
    ASSERT_TRUE(fs::exists(out / svg)) << svg;
    const std::string text = vmh::testing::read_file(out / svg);
    EXPECT_NE(text.find("<svg"), std::string::npos) << svg;
    EXPECT_NE(text.find("series-1"), std::string::npos) << svg;
  }
  EXPECT_FALSE(fs::exists(out / "precision.csv.tmp"));
}

TEST(StudyPrecisionCli, BadOptionsAreNamedAndWriteNothing) {
  struct Bad {
    const char* args;
    const char* names;
  };
  const Bad bad[] = {
      {"--case 9", "--case"},
      {"--case nowhere.xml", "--case"},
      {"--steps 3e-4", "--steps"},
      {"--steps 1e-3,abc", "--steps"},
      {"--steps 1e-6", "--steps"},
      // issue 17: an empty list ran the default ladder
      {"--steps ''", "--steps"},
      {"--integrators ''", "--integrators"},
      {"--reference-step 1e-12", "--reference-step"},
      {"--integrators euler,verlet", "--integrators"},
      {"--duration 0", "--duration"},
      {"--duration 21", "--duration"},
      {"--reference-step 3e-6", "--reference-step"},
      {"--reference-check-step 1e-6", "--reference-check-step"},
      {"--set no_such_field=1", "--set"},
      {"--set quantize=1", "--set quantize"},
      {"--set integrator=euler", "--set integrator"},
  };
  const fs::path out = precision_dir("precision_bad");
  for (const Bad& b : bad) {
    const auto r = run(std::string("study precision ") + b.args + " --out " +
                       out.string());
    EXPECT_EQ(r.exit_code, 2) << b.args << ": " << r.err;
    EXPECT_NE(r.err.find(b.names), std::string::npos) << b.args << ": " << r.err;
    // one line
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << b.args;
  }
  EXPECT_FALSE(fs::exists(out));
}

TEST(StudyLeannessCli, PrintsJsonAndWritesTable) {
  const fs::path out = precision_dir("leanness");
  const auto r = run("study leanness --case 2 --duration 0.1 --repeats 1 --out " +
                     out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  for (const char* k : {"study", "duration_s", "repeats", "not_measured",
                        "median_over_cases", "cases", "files"}) {
    EXPECT_TRUE(j.contains(k)) << k;
  }
  ASSERT_EQ(j.at("cases").size(), 1u);
  const auto& c = j.at("cases").at(0);
  EXPECT_EQ(c.at("case"), "case2");
  EXPECT_EQ(c.at("variants").size(), 6u);
  EXPECT_EQ(c.at("variants").at(0).at("variant"), "composed");
  EXPECT_EQ(first_line(out / "leanness.csv").rfind("case,variant,", 0), 0u);
}

TEST(StudyLeannessCli, BadOptionsAreNamed) {
  const struct {
    const char* args;
    const char* names;
  } bad[] = {
      {"--case 8", "--case"},
      {"--duration -2", "--duration"},
      {"--repeats 0", "--repeats"},
      {"--set quantize=2", "quantize"},
      {"--set duration_s=3", "--duration"},
  };
  for (const auto& b : bad) {
    const auto r = run(std::string("study leanness ") + b.args);
    EXPECT_EQ(r.exit_code, 2) << b.args << ": " << r.err;
    EXPECT_NE(r.err.find(b.names), std::string::npos) << b.args << ": " << r.err;
  }
}

}  // namespace
