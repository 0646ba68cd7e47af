// The command line of a build without the testbed (VMH_BUILD_SIM=OFF: a
// machine that only drives a device), as a user runs it: the hw verbs that
// need no simulation list the backends, and probe, record and calibrate a
// device through OpenHaptics (the test libHD.so's rigid device model); the
// default device, the emulator, is not there and says so.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::first_line;
using vmh::testing::run;

const std::string kEnv = std::string("VMH_LIBHD=") + VMH_FAKE_LIBHD +
                         " XDG_CONFIG_HOME=" + ::testing::TempDir() +
                         "vmh_device_only_cfg ";

TEST(DeviceOnlyCli, ListHasTheDeviceBackendsAndNoEmulator) {
  const auto r = run("hw list", kEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  std::vector<std::string> names;
  for (const json& b : j.at("backends")) names.push_back(b.at("name"));
  EXPECT_EQ(names,
            (std::vector<std::string>{"openhaptics", "firewire", "usb", "served",
                                      "replay"}));
  EXPECT_TRUE(j["backends"][0]["available"].get<bool>()) << r.out;
  EXPECT_EQ(j["backends"][0]["found"], VMH_FAKE_LIBHD);
}

TEST(DeviceOnlyCli, ProbeReadsTheDeviceThroughOpenHaptics) {
  const auto r = run("hw probe --device openhaptics --seconds 0.3", kEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("device").at("backend"), "openhaptics");
  EXPECT_EQ(j.at("device").at("serial"), "TEST-00001");
  ASSERT_EQ(j.at("q_device_rad").size(), 6u);
  EXPECT_EQ(j.at("session").at("clock"), "realtime");
  EXPECT_GT(j.at("session").at("ticks").get<long>(), 1);
}

TEST(DeviceOnlyCli, RecordWritesTheSet) {
  const fs::path out = vmh::testing::fresh_dir("vmh_device_only_", "record");
  const auto r = run("hw record --device openhaptics --duration 0.3 --quiet --out " +
                         out.string(), kEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(first_line(out / "trace.csv").rfind("t_s,period_s,q1_rad", 0), 0u);
  std::ifstream in(out / "meta.json");
  EXPECT_EQ(json::parse(in).at("device").at("backend"), "openhaptics");
}

// a case's controller on the device, its parameters read from the scene
// without MuJoCo: no ground truth, so no claims, and it says so
TEST(DeviceOnlyCli, RunDrivesAScenesControllerOnTheDevice) {
  const fs::path out = vmh::testing::fresh_dir("vmh_device_only_", "run");
  const auto r = run(std::string("hw run --device openhaptics ") + VMH_MODELS_DIR +
                         "/cases/case5.xml --duration 0.5 --gain-scale 0.2 --quiet "
                         "--out " + out.string(), kEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("thesis_case"), 5);
  EXPECT_EQ(j.at("gain_scale"), 0.2);
  EXPECT_TRUE(j.at("claims").empty());
  EXPECT_GT(j.at("session").at("ticks").get<long>(), 1);
  // the controller's columns: theta_v_* for the sphere's three angles
  const std::string header = first_line(out / "trace.csv");
  EXPECT_NE(header.find("theta_v_3"), std::string::npos) << header;
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  // a case name needs the testbed's catalogue: a path is asked for
  const auto c = run("hw run --device openhaptics case2", kEnv);
  EXPECT_EQ(c.exit_code, 2);
  EXPECT_NE(c.err.find("give the scene's path"), std::string::npos) << c.err;
  // a bad parameter is refused before the device opens, naming the field
  const auto bad = run(std::string("hw run --device openhaptics ") + VMH_MODELS_DIR +
                           "/cases/case2.xml --set k_pos_N_per_mm=-1", kEnv);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("k_pos_N_per_mm"), std::string::npos) << bad.err;
}

TEST(DeviceOnlyCli, TheMissingEmulatorIsNamed) {
  const auto r = run("hw probe", kEnv);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no emulator"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("VMH_BUILD_SIM=OFF"), std::string::npos) << r.err;
  const auto s = run("hw probe --device emulator:firewire", kEnv);
  EXPECT_EQ(s.exit_code, 2);
  EXPECT_NE(s.err.find("unknown backend 'emulator'"), std::string::npos) << s.err;
}

TEST(DeviceOnlyCli, LockstepIsRefusedForADevice) {
  const auto r = run("hw probe --device openhaptics --clock lockstep", kEnv);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("lockstep"), std::string::npos) << r.err;
}

}  // namespace
