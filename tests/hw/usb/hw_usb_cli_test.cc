// `vmhaptics hw list`, `hw probe --device usb` and `hw capture`, run as a
// user runs them, inside umockdev-run with the hand-written device
// descriptions of this folder (and the replayed bulk reads for capture):
// the JSON, the capture file and the exit codes (0 done, 2 bad usage or no
// such device with nothing written, 1 an unplug with the records kept).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::run;

const std::string kDir = VMH_USB_TEST_DIR;

// `umockdev-run` with these descriptions (and ioctl replays), then the CLI
std::string under(const std::vector<std::string>& devices, const std::string& ioctl = "") {
  std::string s = VMH_UMOCKDEV_RUN;
  for (const std::string& d : devices) s += " --device " + kDir + "/" + d;
  if (!ioctl.empty()) s += " --ioctl /dev/bus/usb/001/005=" + kDir + "/" + ioctl;
  return s + " -- ";
}

const std::vector<std::string> kAll = {"touch_0302.umockdev", "touch_0301_early.umockdev",
                                       "not_a_touch_mouse.umockdev"};

json usb_entry(const json& list) {
  for (const json& b : list.at("backends")) {
    if (b.at("name") == "usb") return b;
  }
  ADD_FAILURE() << "no usb entry";
  return json::object();
}

std::vector<std::string> lines_of(const fs::path& p) {
  std::vector<std::string> out;
  std::ifstream in(p);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

fs::path out_file(const std::string& name) {
  const fs::path p = fs::path(::testing::TempDir()) / ("vmh_usb_cli_" + name);
  fs::remove(p);
  return p;
}

TEST(HwUsbCli, ListShowsExactlyTheTouches) {
  const auto r = run("hw list", under(kAll));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json u = usb_entry(json::parse(r.out));
  EXPECT_EQ(u.at("device"), "usb[:BUS-ADDR]");
  EXPECT_TRUE(u.at("available").get<bool>());
  EXPECT_FALSE(u.at("verified_on_hardware").get<bool>());
  EXPECT_NE(u.at("note").get<std::string>().find("not public"), std::string::npos);
  const json& found = u.at("found");
  ASSERT_EQ(found.size(), 2u) << found.dump();
  json later, early;
  for (const json& f : found) {
    if (f.at("id") == "2988:0302") later = f;
    if (f.at("id") == "0301:2988") early = f;
  }
  ASSERT_FALSE(later.is_null()) << found.dump();
  ASSERT_FALSE(early.is_null()) << found.dump();
  EXPECT_EQ(later.at("bus"), 1);
  EXPECT_EQ(later.at("address"), 5);
  EXPECT_EQ(later.at("port"), "1-2");
  EXPECT_TRUE(later.at("accessible").get<bool>());
  EXPECT_EQ(early.at("bus"), 2);
  EXPECT_EQ(early.at("address"), 3);
}

TEST(HwUsbCli, ListWithoutATouchSaysWhyNot) {
  const auto r = run("hw list", under({"not_a_touch_mouse.umockdev"}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json u = usb_entry(json::parse(r.out));
  EXPECT_FALSE(u.at("available").get<bool>());
  EXPECT_TRUE(u.at("found").empty());
  EXPECT_NE(u.at("why_not").get<std::string>().find("no USB Touch found"), std::string::npos);
}

TEST(HwUsbCli, ProbeGivesTheDescriptors) {
  const auto r = run("hw probe --device usb", under(kAll));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("descriptor").at("bcdUSB"), "2.00");
  EXPECT_EQ(j.at("descriptor").at("class"), "0x02");
  EXPECT_EQ(j.at("strings").at("product").at("value"), "3D Systems Touch 3D Stylus");
  const json& intf = j.at("configurations").at(0).at("interfaces");
  ASSERT_EQ(intf.size(), 2u);
  EXPECT_EQ(intf[1].at("class"), "0x0a");
  EXPECT_EQ(intf[1].at("kernel_driver"), "cdc_acm");
  const json& in = intf[1].at("endpoints").at(1);
  EXPECT_EQ(in.at("address"), "0x81");
  EXPECT_EQ(in.at("direction"), "in");
  EXPECT_EQ(in.at("transfer_type"), "bulk");
  EXPECT_EQ(in.at("max_packet_size"), 64);
  EXPECT_FALSE(j.at("verified_on_hardware").get<bool>());

  const auto early = run("hw probe --device usb:2-3", under(kAll));
  ASSERT_EQ(early.exit_code, 0) << early.err;
  EXPECT_EQ(json::parse(early.out).at("descriptor").at("vendor_id"), "0x0301");
}

TEST(HwUsbCli, ProbeOfNoTouchIsExit2) {
  auto r = run("hw probe --device usb:1-6", under(kAll));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("046d:c077, not a Touch"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  r = run("hw probe --device usb:9-9", under(kAll));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("usb:9-9"), std::string::npos) << r.err;
  r = run("hw probe --device usb:nine", under(kAll));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("usb:nine"), std::string::npos) << r.err;
  r = run("hw probe --device usb", under({"not_a_touch_mouse.umockdev"}));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no USB Touch found"), std::string::npos) << r.err;
}

TEST(HwUsbCli, CaptureWritesTheTransfers) {
  const fs::path held = out_file("held.txt");
  auto r = run("hw capture --device usb --duration 0.2 --out " + held.string(),
               under({"touch_0302.umockdev"}, "touch_0302.ioctl"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("held by cdc_acm"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(held)) << "nothing may be written";

  const fs::path f = out_file("capture.txt");
  r = run("hw capture --device usb --duration 0.2 --detach --out " + f.string(),
          under({"touch_0302.umockdev"}, "touch_0302.ioctl"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_TRUE(j.at("error").is_null());
  EXPECT_EQ(j.at("endpoints"), json::array({"0x81"}));
  EXPECT_EQ(j.at("kernel_driver"), "cdc_acm");
  EXPECT_GE(j.at("elapsed_s").get<double>(), 0.2);
  const std::vector<std::string> lines = lines_of(f);
  ASSERT_GE(lines.size(), 3u);
  EXPECT_EQ(lines.size(), j.at("transfers").get<std::size_t>() + 3);
  EXPECT_EQ(lines[0].rfind("# vmhaptics usb capture v1: device 2988:0302", 0), 0u) << lines[0];
  // the first pass of the replayed recording, in its order
  EXPECT_NE(lines[2].find(" 0x81 16 00112233445566778899aabbccddeeff"), std::string::npos)
      << lines[2];
  EXPECT_NE(lines[3].find(" 0x81 8 0102030405060708"), std::string::npos) << lines[3];
  EXPECT_EQ(lines.back().rfind("# end: ", 0), 0u) << lines.back();
}

TEST(HwUsbCli, UnplugMidCaptureIsExit1WithTheRecordsKept) {
  const fs::path f = out_file("unplug.txt");
  const auto r = run("hw capture --device usb:1-5 --duration 3 --detach --out " + f.string(),
                     under({"touch_0302.umockdev"}, "touch_0302_unplug.ioctl"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("unplugged"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("transfers"), 3);
  EXPECT_NE(j.at("error").get<std::string>().find("LIBUSB_ERROR_NO_DEVICE"), std::string::npos);
  const std::vector<std::string> lines = lines_of(f);
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_NE(lines[2].find(" 0x81 4 deadbeef"), std::string::npos) << lines[2];
  EXPECT_EQ(lines[5].rfind("# error: ", 0), 0u) << lines[5];
}

TEST(HwUsbCli, CaptureBadInputIsExit2WithNothingWritten) {
  const fs::path f = out_file("bad.txt");
  for (const std::string d : {"0", "-1", "nan", "inf"}) {
    const auto r = run("hw capture --device usb --duration " + d + " --detach --out " + f.string(),
                       under({"touch_0302.umockdev"}, "touch_0302.ioctl"));
    EXPECT_EQ(r.exit_code, 2) << d << ": " << r.err;
    EXPECT_NE(r.err.find("--duration"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(f));
  }
  const auto r = run("hw capture --device usb:1-9 --duration 1 --out " + f.string(),
                     under({"touch_0302.umockdev"}));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("usb:1-9"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(f));
}

}  // namespace
