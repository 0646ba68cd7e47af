// `vmhaptics hw ... --device openhaptics`, through the test libHD.so
// (tests/hw/fake_libhd/, over the MuJoCo emulator) reached with VMH_LIBHD:
// probe, record and run work, and a device that stops answering
// (comm_error) ends the session with its trace kept.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::first_line;
using vmh::testing::run;

const std::string kLibhdEnv = std::string("VMH_LIBHD=") + VMH_FAKE_LIBHD + " ";

int count_lines(const fs::path& p) {
  std::ifstream in(p);
  int n = 0;
  std::string line;
  while (std::getline(in, line)) ++n;
  return n;
}

TEST(HwOpenHapticsCli, ListFindsTheLibrary) {
  const auto r = run("hw list", kLibhdEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  json oh;
  const json list = json::parse(r.out);
  for (const json& b : list.at("backends")) {
    if (b.at("name") == "openhaptics") oh = b;
  }
  ASSERT_FALSE(oh.is_null()) << r.out;
  EXPECT_TRUE(oh.at("available").get<bool>()) << oh.dump();
  EXPECT_EQ(oh.at("found"), VMH_FAKE_LIBHD);
}

TEST(HwOpenHapticsCli, ProbeIdentifiesAndReads) {
  const auto r = run("hw probe --device openhaptics --seconds 0.5", kLibhdEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("device").at("backend"), "openhaptics");
  EXPECT_FALSE(j.at("device").at("model").get<std::string>().empty());
  EXPECT_FALSE(j.at("device").at("serial").get<std::string>().empty());
  EXPECT_EQ(j.at("q_device_rad").size(), 6u);
  const auto reports = j.at("reports").get<std::vector<std::string>>();
  for (const char* f : {"joints", "buttons", "inkwell", "transform", "velocity",
                        "jacobian"}) {
    EXPECT_NE(std::find(reports.begin(), reports.end(), f), reports.end()) << f;
  }
}

TEST(HwOpenHapticsCli, RecordHasTheDevicesOwnKinematics) {
  const fs::path out = vmh::testing::fresh_dir("vmh_hwoh_", "record");
  const auto r = run("hw record --device openhaptics --duration 1 --quiet --out " +
                         out.string(), kLibhdEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string header = first_line(out / "trace.csv");
  for (const char* col : {"q1_rad", "dev_p_x_mm", "dev_R_33", "dev_v_z_mm_s",
                          "dev_J_66", "buttons", "docked"}) {
    EXPECT_NE(header.find(col), std::string::npos) << col;
  }
  EXPECT_GT(count_lines(out / "trace.csv"), 500);
  std::ifstream in(out / "meta.json");
  EXPECT_EQ(json::parse(in).at("device").at("backend"), "openhaptics");
}

TEST(HwOpenHapticsCli, RunDrivesTheControllerInBothCommandModes) {
  for (const char* mode : {"joint_torque", "force"}) {
    const fs::path out = vmh::testing::fresh_dir("vmh_hwoh_run_", mode);
    const auto r = run(std::string("hw run --device openhaptics --hd-command ") +
                           mode + " case1 --duration 1.5 --quiet --out " +
                           out.string(), kLibhdEnv);
    ASSERT_EQ(r.exit_code, 0) << mode << ": " << r.err;
    const json j = json::parse(r.out);
    // no ground truth on a device: no claims, and it says so
    EXPECT_TRUE(j.at("claims").empty());
    const long ticks = j.at("session").at("ticks").get<long>();
    EXPECT_GT(ticks, 1000);
    EXPECT_TRUE(fs::exists(out / "summary.json"));
  }
}

TEST(HwOpenHapticsCli, DeviceThatStopsAnsweringKeepsTheTrace) {
  const fs::path out = vmh::testing::fresh_dir("vmh_hwoh_", "comm");
  const auto r = run("hw record --device openhaptics:comm_error@800 "
                     "--duration 10 --quiet --out " + out.string(), kLibhdEnv);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("device_gone"), std::string::npos) << r.err;
  // the 800 frames before the fault are all in the trace
  EXPECT_GE(count_lines(out / "trace.csv"), 1 + 700);
}

TEST(HwOpenHapticsCli, UnknownConfigurationIsNamed) {
  const auto r = run("hw probe --device openhaptics:missing", kLibhdEnv);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("missing"), std::string::npos) << r.err;
}

}  // namespace
