// `vmhaptics compare` against the emulator as a bring-up meets a device:
// for each fault the emulator can seed (--emulator-fault), a bring-up's
// recordings (the workspace tour, a pulse on each motor) are made in real
// time and compare must name that fault and nothing else; a clean set must
// pass every check. The answer is in meta.json only under the emulator's
// hidden key, which compare does not read (bringup/).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using vmh::testing::run;

struct FaultCase {
  const char* fault;              // "" for a clean device
  std::set<std::string> expect;   // what compare must name
};

std::string record_set(const std::string& fault, const fs::path& dir) {
  const std::string seeded = fault.empty() ? "" : " --emulator-fault " + fault;
  std::string dirs;
  const auto rec = run("hw record --quiet --duration 6" + seeded + " --out " +
                       (dir / "record").string());
  EXPECT_EQ(rec.exit_code, 0) << rec.err;
  dirs += (dir / "record").string();
  for (int m = 1; m <= 3; ++m) {
    const fs::path d = dir / ("motor" + std::to_string(m));
    const auto mt = run("hw motor-test --quiet --motor " + std::to_string(m) +
                        " --torque-mNm 60 --ms 50" + seeded + " --out " + d.string());
    EXPECT_EQ(mt.exit_code, 0) << mt.err;
    dirs += " " + d.string();
  }
  return dirs;
}

class CompareSeeded : public ::testing::TestWithParam<FaultCase> {};

TEST_P(CompareSeeded, NamesTheSeededFaultAndNothingElse) {
  const FaultCase& c = GetParam();
  const std::string tag = *c.fault ? c.fault : "clean";
  const fs::path dir = vmh::testing::fresh_dir("compare_", tag);
  const std::string dirs = record_set(c.fault, dir);
  const auto r = run("compare " + dirs + " --out " + (dir / "compare").string());
  ASSERT_FALSE(r.out.empty()) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  std::set<std::string> named;
  for (const auto& f : j["suspected_faults"]) named.insert(f.get<std::string>());
  if (std::string(c.fault).rfind("delay_", 0) == 0) {
    // the lag is found in whole servo periods, and which side of the half
    // a seeded 5 ms falls on depends on the phase of the host's loop
    // against the emulator's: 4 or 5 ms, measured (docs/bringup.md)
    ASSERT_EQ(named.size(), 1u) << "evidence: " << j["evidence"].dump(1);
    EXPECT_TRUE(*named.begin() == "delay_5ms" || *named.begin() == "delay_4ms")
        << *named.begin();
  } else {
    EXPECT_EQ(named, c.expect) << "evidence: " << j["evidence"].dump(1);
  }
  if (c.expect.empty()) {
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(j["pass"].get<bool>());
    for (const auto& check : j["checks"]) {
      EXPECT_TRUE(check["pass"].get<bool>()) << check.dump();
    }
  } else {
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find(*named.begin()), std::string::npos) << r.err;
  }
  // every check carries its number, threshold and unit
  for (const auto& check : j["checks"]) {
    EXPECT_TRUE(check.contains("threshold") && check.contains("unit")) << check.dump();
  }
  EXPECT_TRUE(fs::exists(dir / "compare" / "compare.json"));
}

INSTANTIATE_TEST_SUITE_P(
    Emulator, CompareSeeded,
    ::testing::Values(FaultCase{"", {}}, FaultCase{"joint1_sign", {"joint1_sign"}},
                      FaultCase{"gimbal_swap", {"gimbal_swap"}},
                      FaultCase{"link_length_2pct", {"link_length_2pct"}},
                      FaultCase{"delay_5ms", {"delay_5ms"}},
                      FaultCase{"motor3_relative", {"motor3_relative"}},
                      FaultCase{"torque_units_Nm", {"torque_units_Nm"}}),
    [](const ::testing::TestParamInfo<FaultCase>& i) {
      return std::string(*i.param.fault ? i.param.fault : "clean");
    });

TEST(Compare, ANonRecordingIsBadInput) {
  const fs::path dir = vmh::testing::fresh_dir("compare_", "bad");
  fs::create_directories(dir);
  const auto r = run("compare " + dir.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("meta.json"), std::string::npos) << r.err;
  const auto none = run("compare");
  EXPECT_EQ(none.exit_code, 2);
}

}  // namespace
