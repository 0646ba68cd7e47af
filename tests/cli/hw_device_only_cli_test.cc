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
  EXPECT_EQ(names, (std::vector<std::string>{"openhaptics", "firewire", "usb"}));
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
