// hd/hd_config: configuration names to device specs, and the errors a
// person can act on.
#include "hd/hd_config.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace vmh::hd {
namespace {

TEST(HdConfig, SplitsASpecIntoTheDeviceAndItsOptions) {
  const DeviceSpec d = parse_device_spec(" emulator:case2?hand=none&fault=drop@1 ");
  EXPECT_EQ(d.device, "emulator:case2");
  ASSERT_EQ(d.options.size(), 2u);
  EXPECT_EQ(d.options[0], (std::pair<std::string, std::string>{"hand", "none"}));
  EXPECT_EQ(d.options[1].first, "fault");
  EXPECT_EQ(d.options[1].second, "drop@1");
  const DeviceSpec f = parse_device_spec("firewire:0x1234?no-20010");
  EXPECT_EQ(f.device, "firewire:0x1234");
  ASSERT_EQ(f.options.size(), 1u);
  EXPECT_EQ(f.options[0].second, "");
  EXPECT_THROW(parse_device_spec("?hand=none"), HdConfigError);
  EXPECT_THROW(parse_device_spec("emulator?=x"), HdConfigError);
}

TEST(HdConfig, TheVendorsDefaultNamesOpenTheDefaultDevice) {
  for (const char* n : {"Default Device", "Default PHANToM", "default phantom",
                        "Phantom Omni", "PHANToM Omni", "Omni", ""}) {
    EXPECT_TRUE(is_default_name(n)) << n;
  }
  EXPECT_TRUE(is_default_name(nullptr));
  EXPECT_FALSE(is_default_name("Phantom2"));
  HdConfig c;
  EXPECT_EQ(resolve_device_name(c, nullptr), "emulator");
  EXPECT_EQ(resolve_device_name(c, "Default Device"), "emulator");
}

TEST(HdConfig, AFileNamesDevicesAndItsDefault) {
  const HdConfig c = parse_hd_config(
      "# two Omnis\n"
      "default = emulator:case1?hand=case\n"
      "  Phantom2 = emulator:case2   # the other one\n\n",
      "hd.conf");
  EXPECT_EQ(resolve_device_name(c, "Default Device"), "emulator:case1?hand=case");
  EXPECT_EQ(resolve_device_name(c, "phantom2"), "emulator:case2");
  EXPECT_EQ(c.default_from, "hd.conf:2");
}

TEST(HdConfig, AnUnknownNameSaysWhatIsConfiguredAndWhere) {
  const HdConfig c = parse_hd_config("Phantom2 = emulator:case2\n", "/x/hd.conf");
  try {
    resolve_device_name(c, "Phantom3");
    FAIL() << "no error";
  } catch (const HdConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'Phantom3'"), std::string::npos) << m;
    EXPECT_NE(m.find("Phantom2"), std::string::npos) << m;
    EXPECT_NE(m.find("/x/hd.conf"), std::string::npos) << m;
  }
  try {
    resolve_device_name(HdConfig{}, "Phantom3");
    FAIL() << "no error";
  } catch (const HdConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("hd.conf"), std::string::npos);
  }
}

TEST(HdConfig, AMalformedFileNamesItsLine) {
  try {
    parse_hd_config("default = emulator\nPhantom2 emulator\n", "f.conf");
    FAIL() << "no error";
  } catch (const HdConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("f.conf:2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_hd_config("A = emulator\na = emulator:case2\n", "f"),
               HdConfigError);
  EXPECT_THROW(parse_hd_config("A = ?x=1\n", "f"), HdConfigError);
}

TEST(HdConfig, TheEnvironmentOverridesTheFile) {
  const auto dir = std::filesystem::temp_directory_path() / "vmhd_config_test";
  std::filesystem::create_directories(dir);
  const auto file = dir / "hd.conf";
  std::ofstream(file) << "default = emulator:case3\nPhantom2 = emulator:case2\n";
  setenv("VMH_HD_CONFIG", file.c_str(), 1);
  unsetenv("VMH_HD_DEVICE");
  HdConfig c = load_hd_config();
  EXPECT_EQ(resolve_device_name(c, nullptr), "emulator:case3");
  setenv("VMH_HD_DEVICE", "emulator:case4", 1);
  c = load_hd_config();
  EXPECT_EQ(resolve_device_name(c, nullptr), "emulator:case4");
  EXPECT_EQ(resolve_device_name(c, "Phantom2"), "emulator:case2");
  setenv("VMH_HD_CONFIG", (dir / "missing.conf").c_str(), 1);
  EXPECT_THROW(load_hd_config(), HdConfigError);
  unsetenv("VMH_HD_CONFIG");
  unsetenv("VMH_HD_DEVICE");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace vmh::hd
