// `vmhaptics study sensitivity` and `study merge`, as a user runs them: the
// files, the summary on stdout, shards merged into what one run writes, and
// bad input refused with exit 2 and nothing written.
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
using vmh::testing::fresh_dir;
using vmh::testing::run;


// the quick sweep of case 2 on a 2 s script (the claims' windows scale with
// the script), so that the test takes seconds
const char* const kSweep = "study sensitivity --case 2 --quick --set duration_s=2";

TEST(StudySensitivityCli, QuickSweepAndItsShardsMerged) {
  const fs::path whole = fresh_dir("vmh_sens_", "whole");
  const auto r = run(std::string(kSweep) + " --jobs 2 --out " + whole.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json printed = nlohmann::json::parse(r.out);
  EXPECT_EQ(printed.at("study"), "sensitivity");
  for (const char* f : {"sensitivity.json", "sensitivity.csv", "sensitivity.svg"}) {
    EXPECT_TRUE(fs::exists(whole / f)) << f;
  }
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(whole / "sensitivity.json"));
  EXPECT_EQ(j.at("sweep_id"), printed.at("sweep_id"));
  ASSERT_FALSE(j.at("claims").empty());
  for (const auto& c : j.at("claims")) {
    EXPECT_EQ(c.at("case"), "case2");
    for (const char* key : {"name", "holds_fraction", "holds_at_nominal", "depends_on",
                            "by_parameter"}) {
      EXPECT_TRUE(c.contains(key)) << key;
    }
    const double f = c.at("holds_fraction").get<double>();
    EXPECT_GE(f, 0.0);
    EXPECT_LE(f, 1.0);
  }
  for (const char* key : {"min", "max", "spread", "nominal"}) {
    EXPECT_TRUE(j.at("modelling_spread")[0].at("rms_path_error_mm").contains(key)) << key;
  }
  for (const auto& p : j.at("parameters")) {
    EXPECT_FALSE(p.at("source").get<std::string>().empty()) << p.at("name");
  }
  const std::string header = first_line(whole / "sensitivity.csv");
  for (const char* col : {"point,case,kind,parameter,", ",hand_k_pos_N_per_m,",
                          ",hand_k_rot_Nm_per_rad,", ",servo_period_s,",
                          ",rms_path_error_mm,", ",claim_value,", ",holds,"}) {
    EXPECT_NE(header.find(col), std::string::npos) << col;
  }
  EXPECT_EQ(first_line(whole / "sensitivity.svg").rfind("<svg", 0), 0u);

  // three shards, then merged: the same files, byte for byte
  std::string parts;
  std::vector<fs::path> part_dirs;
  for (int k = 1; k <= 3; ++k) {
    const fs::path part = fresh_dir("vmh_sens_part", std::to_string(k));
    const auto s = run(std::string(kSweep) + " --jobs 1 --shard " + std::to_string(k) +
                       "/3 --out " + part.string());
    ASSERT_EQ(s.exit_code, 0) << s.err;
    EXPECT_TRUE(fs::exists(part / "sensitivity.partial.json"));
    EXPECT_FALSE(fs::exists(part / "sensitivity.json"));
    parts += " " + part.string();
    part_dirs.push_back(part);
  }
  const fs::path merged = fresh_dir("vmh_sens_", "merged");
  const auto m = run("study merge --out " + merged.string() + parts);
  ASSERT_EQ(m.exit_code, 0) << m.err;
  EXPECT_EQ(nlohmann::json::parse(m.out).at("claims"), printed.at("claims"));
  for (const char* f : {"sensitivity.json", "sensitivity.csv", "sensitivity.svg"}) {
    EXPECT_EQ(vmh::testing::read_file(merged / f), vmh::testing::read_file(whole / f)) << f;
  }

  // a shard missing, or one of another sweep: refused, nothing written
  const fs::path refused = fresh_dir("vmh_sens_", "refused");
  const auto missing = run("study merge --out " + refused.string() + " " +
                           part_dirs[0].string() + " " + part_dirs[2].string());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("missing"), std::string::npos) << missing.err;
  const fs::path p2 = part_dirs[1] / "sensitivity.partial.json";
  nlohmann::json other = nlohmann::json::parse(std::ifstream(p2));
  other["sweep_id"] = "0000000000000000";
  std::ofstream(p2) << other.dump();
  const auto mismatched = run("study merge --out " + refused.string() + parts);
  EXPECT_EQ(mismatched.exit_code, 2);
  EXPECT_NE(mismatched.err.find("sweep"), std::string::npos) << mismatched.err;
  EXPECT_FALSE(fs::exists(refused));
}

TEST(StudySensitivityCli, BadInputIsOneLineExit2NothingWritten) {
  const fs::path out = fresh_dir("vmh_sens_", "bad");
  const fs::path file = fs::path(::testing::TempDir()) / "vmh_sens_a_file";
  std::ofstream(file) << "x";
  const std::pair<std::string, std::string> cases[] = {
      {"--case 9", "--case"},
      {"--case 2 --shard 0/3", "--shard"},
      {"--case 2 --shard 4/3", "--shard"},
      {"--case 2 --shard two", "--shard"},
      {"--case 2 --set hand_mass_kg=1", "hand_mass_kg"},
      {"--case 2 --set no_such_field=1", "no_such_field"},
  };
  for (const auto& [args, named] : cases) {
    const auto r = run("study sensitivity " + args + " --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_NE(r.err.find(named), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
    EXPECT_EQ(r.out, "") << args;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
  const auto unwritable = run("study sensitivity --case 2 --out " +
                              (file / "sub").string());
  EXPECT_EQ(unwritable.exit_code, 2);
  EXPECT_NE(unwritable.err.find("--out"), std::string::npos) << unwritable.err;
  EXPECT_EQ(vmh::testing::read_file(file), "x");
}

}  // namespace
