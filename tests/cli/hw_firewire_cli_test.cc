// The FireWire Omni on the command line: `--device emulator:firewire` (the
// emulator behind the packets and the native driver), `--device firewire`
// and `--device usb` refused as they must be, `hw list`'s rows, and the
// packet verbs `hw decode` / `hw encode` against packets written out by
// hand from the layout of hw/firewire/omni_packet.h. The emulator runs in
// real time: `hw run` takes 20 s a case.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::run;

// a private calibration store, so that no test reads another's
const std::string kFirewireEnv =
    "XDG_CONFIG_HOME=" + ::testing::TempDir() + "vmh_hw_fw_cfg ";

fs::path firewire_dir(const std::string& name) {
  return vmh::testing::fresh_dir("vmh_hw_fw_", name);
}

long line_count(const std::string& s) { return std::count(s.begin(), s.end(), '\n'); }

// A state packet written out by hand, field by field (little-endian):
//   magic 0x31484d56                      56 4d 48 31
//   encoders -2, 300, -32768              fe ff  2c 01  00 80
//   gimbal_a codes 0, 1023, 2047 << 5     00 00  e0 7f  e0 ff
//   unknown16                             00 00
//   packet_number 2 (258's low byte)      02
//   status: button 1 pressed (bit 0       06
//     clear), button 2 not (bit 1 set),
//     out of the inkwell (bit 2 set)
//   unknown20                             00 00
//   gimbal_b (2047 - code) << 5           e0 ff  00 80  00 00
//   unknown28                             00 00 00 00
//   counter 258                           02 01 00 00
//   unknown36                             00 00 00 00
//   time 1000                             e8 03 00 00
const std::string kStateHex =
    "564d4831" "feff2c010080" "0000e07fe0ff" "0000" "02" "06" "0000"
    "e0ff00800000" "00000000" "02010000" "00000000" "e8030000";

TEST(HwFirewireCli, DecodeStateGivesTheHandWrittenFields) {
  ASSERT_EQ(kStateHex.size(), 88u);
  const auto r = run("hw decode firewire-state " + kStateHex);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("magic"), "0x31484d56");
  EXPECT_EQ(j.at("encoders"), json({-2, 300, -32768}));
  EXPECT_EQ(j.at("gimbal_a"), json({0, 0x7fe0, 0xffe0}));
  EXPECT_EQ(j.at("gimbal_b"), json({0xffe0, 0x8000, 0}));
  EXPECT_EQ(j.at("pot_codes"), json({0, 1023, 2047}));
  EXPECT_EQ(j.at("buttons_pressed"), json({true, false}));
  EXPECT_EQ(j.at("docked"), false);
  EXPECT_EQ(j.at("status"), 6);
  EXPECT_EQ(j.at("packet_number"), 2);
  EXPECT_EQ(j.at("counter"), 258);
  EXPECT_EQ(j.at("time"), 1000);
  EXPECT_EQ(j.at("hex"), kStateHex);
}

TEST(HwFirewireCli, DecodeTakesTheBytesInSeveralWords) {
  // as a capture tool prints them: a space every four bytes
  std::string spaced;
  for (std::size_t i = 0; i < kStateHex.size(); i += 8) {
    spaced += kStateHex.substr(i, 8) + " ";
  }
  const auto r = run("hw decode firewire-state " + spaced);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out).at("counter"), 258);
  // one quoted word with spaces and a tab inside, as pasted from a capture
  // tool's byte dump (issue 34: it was refused as a non-hex digit ' ')
  std::string pasted;
  for (std::size_t i = 0; i < kStateHex.size(); i += 2) {
    pasted += kStateHex.substr(i, 2) + (i % 16 == 14 ? "\t" : " ");
  }
  const auto q = run("hw decode firewire-state '" + pasted + "'");
  ASSERT_EQ(q.exit_code, 0) << q.err;
  EXPECT_EQ(json::parse(q.out).at("counter"), 258);
  EXPECT_EQ(json::parse(q.out).at("encoders"), json({-2, 300, -32768}));
}

TEST(HwFirewireCli, EncodeStateWritesTheSamePacket) {
  const auto r = run("hw encode firewire-state --encoders -2,300,-32768 "
                     "--pot-codes 0,1023,2047 --buttons-pressed 1,0 "
                     "--counter 258 --time 1000 --magic 31484d56");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out).at("hex"), kStateHex);
  // docked and both buttons up: status 0x03
  const auto d = run("hw encode firewire-state --docked");
  ASSERT_EQ(d.exit_code, 0) << d.err;
  EXPECT_EQ(json::parse(d.out).at("status"), 3);
}

// A command written out by hand: motor words 0x09ff (u = 0.25: 0x07ff +
// 0.25 * 2048), 0x0000 (u = -1), 0x0fff (u = 2, saturated at +1); status
// 0x53c0 | 0x0008 (motors on); two zero quadlets.
const std::string kCommandHex = "ff090000ff0fc853" "0000000000000000";

TEST(HwFirewireCli, EncodeCommandGivesTheHandWrittenPacket) {
  const auto r = run("hw encode firewire-command --motor-unit 0.25,-1,2 --motors-on");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("hex"), kCommandHex);
  EXPECT_EQ(j.at("motor_words"), json({0x09ff, 0x0000, 0x0fff}));
  EXPECT_EQ(j.at("saturated"), json({false, false, true}));
  EXPECT_EQ(j.at("status"), 0x53c8);
  EXPECT_EQ(j.at("motors_on"), true);
  // motors off (as the drivers start), u = 0, 0.5, -0.25: 0x07ff, 0x07ff +
  // 1024, 0x07ff - 512; status 0x53c0
  const auto off = run("hw encode firewire-command --motor-unit 0,0.5,-0.25");
  ASSERT_EQ(off.exit_code, 0) << off.err;
  const json k = json::parse(off.out);
  EXPECT_EQ(k.at("hex"), "ff07ff0bff05c0530000000000000000");
  EXPECT_EQ(k.at("saturated"), json({false, false, false}));
  EXPECT_EQ(k.at("motors_on"), false);
}

TEST(HwFirewireCli, DecodeCommandGivesTheWordsAndBits) {
  const auto r = run("hw decode firewire-command " + kCommandHex);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("motor_words"), json({0x09ff, 0x0000, 0x0fff}));
  EXPECT_EQ(j.at("motor_unit"), json({0.25, -1.0, 1.0}));
  EXPECT_EQ(j.at("status"), 0x53c8);
  EXPECT_EQ(j.at("motors_on"), true);
  EXPECT_EQ(j.at("led_flash"), false);
}

TEST(HwFirewireCli, BadPacketsAndNumbersAreNamed) {
  struct Case {
    std::string args, names;
  };
  const std::string short_hex = kStateHex.substr(0, 86);  // 43 bytes
  const std::vector<Case> cases = {
      {"hw decode firewire-state " + short_hex, "43 bytes"},
      {"hw decode firewire-state " + kStateHex + "00", "45 bytes"},
      {"hw decode firewire-state " + kStateHex.substr(0, 87), "odd"},
      {"hw decode firewire-state " + kStateHex.substr(0, 86) + "zz", "'z'"},
      {"hw decode firewire-command " + kStateHex, "44 bytes"},
      {"hw encode firewire-command --motor-unit 0.1,abc,0", "'abc'"},
      {"hw encode firewire-command --motor-unit 0.1,0.2", "got 2"},
      {"hw encode firewire-command --motor-unit 0.1,nan,0", "'nan'"},
      {"hw encode firewire-state --pot-codes 0,2048,0", "'2048'"},
      {"hw encode firewire-state --encoders 0,40000,0", "'40000'"},
  };
  for (const Case& c : cases) {
    const auto r = run(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args;
    EXPECT_NE(r.err.find(c.names), std::string::npos) << c.args << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << c.args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << c.args;
  }
}

TEST(HwFirewireCli, ListHasTheFirewireRows) {
  const auto r = run("hw list");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  json fw, emu;
  for (const auto& b : j.at("backends")) {
    if (b.at("name") == "firewire") fw = b;
    if (b.at("name") == "emulator:firewire") emu = b;
  }
  ASSERT_FALSE(fw.is_null()) << r.out;
  ASSERT_FALSE(emu.is_null()) << r.out;
  EXPECT_EQ(fw.at("device"), "firewire[:GUID][?no-20010,no-rehome]");
  // this machine has no FireWire adapter: nothing found, and why
  EXPECT_TRUE(fw.at("found").empty()) << fw.dump();
  EXPECT_FALSE(fw.at("why_not").get<std::string>().empty()) << fw.dump();
  EXPECT_EQ(emu.at("available"), true);
  EXPECT_EQ(emu.at("device"), "emulator:firewire[:case|scene.xml]");
}

TEST(HwFirewireCli, FirewireWithoutAnAdapterIsOneLineAndExit2) {
  const fs::path out = firewire_dir("noadapter");
  const auto r = run("hw record --device firewire --out " + out.string(), kFirewireEnv);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("firewire"), std::string::npos) << r.err;
  EXPECT_EQ(line_count(r.err), 1) << r.err;
  EXPECT_FALSE(fs::exists(out / "trace.csv"));
}

TEST(HwFirewireCli, UsbIsListProbeAndCaptureOnly) {
  const auto r = run("hw record --device usb", kFirewireEnv);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("payload protocol is not public"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("hw capture"), std::string::npos) << r.err;
  EXPECT_EQ(line_count(r.err), 1) << r.err;
}

TEST(HwFirewireCli, BadOptionsForTheWireAreNamed) {
  // the emulator's own fault names are not packet faults
  const auto f = run("hw probe --device emulator:firewire --fault drop@1:5", kFirewireEnv);
  EXPECT_EQ(f.exit_code, 2);
  EXPECT_NE(f.err.find("'drop'"), std::string::npos) << f.err;
  EXPECT_EQ(line_count(f.err), 1) << f.err;
  // a host decoding mistake seeded into the emulator would never be seen
  const auto s = run("hw probe --device emulator:firewire --emulator-fault joint2_sign",
                     kFirewireEnv);
  EXPECT_EQ(s.exit_code, 2);
  EXPECT_NE(s.err.find("joint2_sign"), std::string::npos) << s.err;
  const auto c = run("hw probe --device emulator:firewire:nosuch_case", kFirewireEnv);
  EXPECT_EQ(c.exit_code, 2);
  EXPECT_NE(c.err.find("nosuch_case"), std::string::npos) << c.err;
  const auto t = run("hw run --device emulator:firewire:case2 case1", kFirewireEnv);
  EXPECT_EQ(t.exit_code, 2);
  EXPECT_NE(t.err.find("emulator:firewire:case2"), std::string::npos) << t.err;
}

TEST(HwFirewireCli, ProbeReadsThroughThePackets) {
  const auto r = run("hw probe --device emulator:firewire --seconds 1", kFirewireEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("device").at("backend"), "emulator:firewire");
  EXPECT_EQ(j.at("device").at("serial"), "EMU-0001");
  EXPECT_EQ(j.at("calibration").at("state"), "ok");
  EXPECT_GT(j.at("rate_Hz").get<double>(), 100.0);
  const auto reports = j.at("reports").get<std::vector<std::string>>();
  for (const char* f : {"joints", "buttons", "inkwell", "encoders", "gimbal_pots"}) {
    EXPECT_NE(std::find(reports.begin(), reports.end(), f), reports.end()) << f;
  }
  // pot codes are 11-bit
  for (const auto& c : j.at("gimbal_pots")) {
    EXPECT_GE(c.get<int>(), 0);
    EXPECT_LE(c.get<int>(), 2047);
  }
}

// Packet faults in a recording: losses time out, wrong lengths are I/O
// errors, a bus reset costs a tick; the session goes on to the end.
TEST(HwFirewireCli, PacketFaultsShowInTheSessionAndItCarriesOn) {
  const fs::path out = firewire_dir("faults");
  const auto r = run("hw record --device emulator:firewire --duration 3 --quiet "
                     "--fault loss@0.8:5,length@1.4:3,reset@2 --out " +
                         out.string(),
                     kFirewireEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(out / "meta.json");
  const json m = json::parse(in);
  EXPECT_EQ(m.at("session").at("stop_reason"), "duration");
  const json e = m.at("session").at("read_errors");
  EXPECT_GE(e.value("timeout", 0L), 5) << e.dump();
  EXPECT_EQ(e.value("io", 0L), 3) << e.dump();
  EXPECT_GE(e.value("not_connected", 0L), 1) << e.dump();
  EXPECT_EQ(m.at("device").at("backend"), "emulator:firewire");
  // the packets' own account: three of the wrong length, one bus reset
  // recovered from; the counter's gaps are the five lost packets and the
  // three refused ones, whose counters the device never decoded
  const json fw = m.at("firewire");
  EXPECT_EQ(fw.at("device").at("lost_packets"), 5 + 3) << fw.dump();
  EXPECT_EQ(fw.at("device").at("bad_packets"), 3) << fw.dump();
  EXPECT_EQ(fw.at("transport").at("bus_resets"), 1) << fw.dump();
  EXPECT_EQ(fw.at("transport").at("recoveries"), 1) << fw.dump();
  EXPECT_EQ(fw.at("node").at("vendor"), 0x000b99) << fw.dump();
}

TEST(HwFirewireCli, UnpluggedForGoodIsDeviceGone) {
  const fs::path out = firewire_dir("unplug");
  const auto r = run("hw record --device emulator:firewire --fault unplug@1.0:60 "
                     "--duration 10 --quiet --out " + out.string(), kFirewireEnv);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("not_connected"), std::string::npos) << r.err;
  EXPECT_EQ(line_count(r.err), 1) << r.err;
  EXPECT_TRUE(fs::exists(out / "trace.csv"));
}

// hw calibrate through the packets: the fit of the raw values that came
// over the wire lands near the emulator's hidden calibration, is stored,
// and the next probe decodes with it.
TEST(HwFirewireCli, CalibrateThroughThePackets) {
  const std::string cfg = ::testing::TempDir() + "vmh_hw_fw_cfg_cal";
  fs::remove_all(cfg);
  const std::string env = "XDG_CONFIG_HOME=" + cfg + " ";
  const auto r = run("hw calibrate --device emulator:firewire --quiet", env);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("device").at("backend"), "emulator:firewire");
  const std::string stored = j.at("stored");
  EXPECT_TRUE(fs::exists(stored));
  const auto err = j.at("error_vs_truth_rad").get<std::vector<double>>();
  ASSERT_EQ(err.size(), 6u);
  for (int i = 0; i < 3; ++i) EXPECT_LT(err[i], 0.02) << "t" << i + 1;
  for (int i = 3; i < 6; ++i) EXPECT_LT(err[i], 0.1) << "t" << i + 1;
  const auto p = run("hw probe --device emulator:firewire --seconds 0.5", env);
  ASSERT_EQ(p.exit_code, 0) << p.err;
  EXPECT_EQ(json::parse(p.out).at("calibration").at("source"), stored);
}

// `hw run --device emulator:firewire caseN` reproduces `run caseN`'s claims
// through the packets and the native driver, in real time (20 s each).
class HwFirewireRunCase : public ::testing::TestWithParam<int> {};

TEST_P(HwFirewireRunCase, ReproducesTheThesisClaims) {
  const std::string name = "case" + std::to_string(GetParam());
  const fs::path out = firewire_dir("run_" + name);
  const auto r = run("hw run --device emulator:firewire " + name +
                         " --quiet --out " + out.string(),
                     kFirewireEnv);
  const json j = json::parse(r.out);
  ASSERT_TRUE(j.contains("claims")) << r.out << r.err;
  ASSERT_FALSE(j.at("claims").empty());
  for (const auto& c : j.at("claims")) {
    EXPECT_TRUE(c.at("pass").get<bool>()) << c.dump();
  }
  EXPECT_EQ(j.at("all_claims_pass"), true);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(out / "meta.json");
  const json m = json::parse(in);
  EXPECT_EQ(m.at("device").at("backend"), "emulator:firewire");
  EXPECT_TRUE(m.contains("emulator"));
  EXPECT_TRUE(fs::exists(out / "trace.csv"));
  EXPECT_TRUE(fs::exists(out / "summary.json"));
}

INSTANTIATE_TEST_SUITE_P(Cases, HwFirewireRunCase, ::testing::Range(1, 7));

}  // namespace
