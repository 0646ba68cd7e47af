// hw/usb's pure functions: the Touch ID table, the spellings of IDs, ports
// and BUS-ADDR, the descriptor parse (against bytes laid out by hand from
// the USB 2.0 specification, chapter 9), the capture file's lines, and that
// hw/udev/60-vmhaptics.rules grants access to every ID the table lists.
#include "hw/usb/usb_descriptors.h"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace vmh::hw::usb;

std::vector<std::uint8_t> from_hex(const std::string& hex) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2) {
    out.push_back(static_cast<std::uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  }
  return out;
}

// the device described in tests/hw/usb/touch_0302.umockdev: a CDC ACM
// function, interface 0 (communications, interrupt IN 0x82) and interface 1
// (data, bulk OUT 0x01 and bulk IN 0x81)
const std::string kTouchDescriptors =
    "12010002020000408829020300010102030109024300020100803209040000010202010005240010"
    "0105240100010424020205240600010705820308001009040100020A000000070501024000000705"
    "8102400000";

TEST(TouchIds, TableHasTheFourPairs) {
  std::set<std::pair<int, int>> got;
  for (const TouchId& t : touch_ids()) got.insert({t.vendor_id, t.product_id});
  const std::set<std::pair<int, int>> want = {
      {0x2988, 0x0301}, {0x2988, 0x0302}, {0x2988, 0x0304}, {0x0301, 0x2988}};
  EXPECT_EQ(got, want);
  EXPECT_TRUE(is_touch_id(0x0301, 0x2988));
  EXPECT_TRUE(is_touch_id(0x2988, 0x0302));
  EXPECT_FALSE(is_touch_id(0x2988, 0x2988));
  EXPECT_FALSE(is_touch_id(0x046d, 0xc077));
}

TEST(Format, IdsPortsAndNodes) {
  EXPECT_EQ(format_usb_id(0x2988, 0x0302), "2988:0302");
  EXPECT_EQ(format_usb_id(0x0301, 0x2988), "0301:2988");
  EXPECT_EQ(format_usb_id(0x046d, 0xc077), "046d:c077");
  EXPECT_EQ(format_port_path(1, {2}), "1-2");
  EXPECT_EQ(format_port_path(3, {1, 4, 2}), "3-1.4.2");
  EXPECT_EQ(format_port_path(2, {}), "usb2");
  EXPECT_EQ(usbfs_path({1, 5}), "/dev/bus/usb/001/005");
  EXPECT_EQ(format_bcd(0x0200), "2.00");
  EXPECT_EQ(format_bcd(0x0110), "1.10");
}

TEST(BusAddressArg, ParsesAndRejectsNamingTheText) {
  BusAddress w = parse_bus_address("1-5");
  EXPECT_EQ(w.bus, 1);
  EXPECT_EQ(w.address, 5);
  w = parse_bus_address("003-127");
  EXPECT_EQ(w.bus, 3);
  EXPECT_EQ(w.address, 127);
  for (const std::string bad : {"", "1", "1-", "-5", "1-5-2", "a-5", "0-5", "1-256",
                                "1:5", " 1-5"}) {
    try {
      parse_bus_address(bad);
      FAIL() << "accepted '" << bad << "'";
    } catch (const UsbUsageError& e) {
      EXPECT_NE(std::string(e.what()).find("usb:" + bad + ":"), std::string::npos) << e.what();
    }
  }
}

TEST(Descriptors, ParsesTheTouchDescription) {
  const UsbDescriptors d = parse_usb_descriptors(from_hex(kTouchDescriptors));
  EXPECT_EQ(d.device.bcd_usb, 0x0200);
  EXPECT_EQ(d.device.device_class, 0x02);
  EXPECT_EQ(d.device.max_packet_size0, 64);
  EXPECT_EQ(d.device.vendor_id, 0x2988);
  EXPECT_EQ(d.device.product_id, 0x0302);
  EXPECT_EQ(d.device.bcd_device, 0x0100);
  EXPECT_EQ(d.device.manufacturer_index, 1);
  EXPECT_EQ(d.device.product_index, 2);
  EXPECT_EQ(d.device.serial_index, 3);
  EXPECT_EQ(d.device.num_configurations, 1);
  ASSERT_EQ(d.configurations.size(), 1u);
  const UsbConfiguration& c = d.configurations[0];
  EXPECT_EQ(c.value, 1);
  EXPECT_EQ(c.attributes, 0x80);
  EXPECT_EQ(c.max_power_mA, 100);
  ASSERT_EQ(c.interfaces.size(), 2u);
  EXPECT_EQ(c.interfaces[0].interface_class, 0x02);
  ASSERT_EQ(c.interfaces[0].endpoints.size(), 1u);  // CDC functional descriptors skipped
  EXPECT_EQ(c.interfaces[0].endpoints[0].transfer_type, "interrupt");
  EXPECT_EQ(c.interfaces[0].endpoints[0].interval, 16);
  const UsbInterface* data = find_data_interface(c);
  ASSERT_NE(data, nullptr);
  EXPECT_EQ(data->number, 1);
  const std::vector<UsbEndpoint> in = capture_endpoints(*data);
  ASSERT_EQ(in.size(), 1u);
  EXPECT_EQ(in[0].address, 0x81);
  EXPECT_EQ(in[0].direction, "in");
  EXPECT_EQ(in[0].transfer_type, "bulk");
  EXPECT_EQ(in[0].max_packet_size, 64);
}

TEST(Descriptors, WithoutACdcDataInterfaceTheFirstWithAnInEndpointIsUsed) {
  // a HID mouse: one interface, interrupt IN 0x81
  const UsbDescriptors d = parse_usb_descriptors(from_hex(
      "12010002000000086D0477C000720102000109022200010100A0320904000001030102000921110100"
      "012243000705810304000A"));
  const UsbInterface* i = find_data_interface(d.configurations.at(0));
  ASSERT_NE(i, nullptr);
  EXPECT_EQ(i->interface_class, 0x03);
  EXPECT_EQ(capture_endpoints(*i).at(0).transfer_type, "interrupt");
}

TEST(Descriptors, MalformedBytesNameTheOffset) {
  std::vector<std::uint8_t> b = from_hex(kTouchDescriptors);
  EXPECT_THROW(parse_usb_descriptors(std::vector<std::uint8_t>(b.begin(), b.begin() + 10)),
               std::invalid_argument);
  // wTotalLength beyond the bytes there are
  std::vector<std::uint8_t> cut(b.begin(), b.end() - 5);
  try {
    parse_usb_descriptors(cut);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("at byte 18"), std::string::npos) << e.what();
  }
  // a zero-length descriptor inside the configuration
  std::vector<std::uint8_t> zero = b;
  zero[18 + 9] = 0;
  EXPECT_THROW(parse_usb_descriptors(zero), std::invalid_argument);
  std::vector<std::uint8_t> notdev = b;
  notdev[1] = 0x02;
  EXPECT_THROW(parse_usb_descriptors(notdev), std::invalid_argument);
}

TEST(CaptureFormat, LinesRoundTrip) {
  CaptureHeader h;
  h.device_id = "2988:0302";
  h.where = {1, 5};
  h.port_path = "1-2";
  h.interface_number = 1;
  h.endpoints = {0x81};
  h.duration_s = 0.5;
  h.started_utc = "2026-01-01T00:00:00Z";
  EXPECT_EQ(format_capture_header(h),
            "# vmhaptics usb capture v1: device 2988:0302 bus 1 address 5 port 1-2 "
            "interface 1 endpoints 0x81 duration_s 0.5 started 2026-01-01T00:00:00Z\n"
            "# t_s endpoint length hex  (payload not decoded: the Touch's protocol is "
            "not public)\n");
  const std::uint8_t bytes[] = {0x00, 0xab, 0x10};
  const std::string line = format_capture_record(1.25, 0x81, bytes, 3);
  EXPECT_EQ(line, "1.250000 0x81 3 00ab10\n");
  const auto r = parse_capture_record(line.substr(0, line.size() - 1));
  ASSERT_TRUE(r);
  EXPECT_DOUBLE_EQ(r->t_s, 1.25);
  EXPECT_EQ(r->endpoint, 0x81);
  EXPECT_EQ(r->data, std::vector<std::uint8_t>(bytes, bytes + 3));
  EXPECT_EQ(format_capture_record(0.0, 0x82, nullptr, 0), "0.000000 0x82 0\n");
  EXPECT_TRUE(parse_capture_record("0.000000 0x82 0")->data.empty());
  EXPECT_FALSE(parse_capture_record("# end: 0 transfers"));
  EXPECT_THROW(parse_capture_record("1.0 0x81 2 00"), std::invalid_argument);
  EXPECT_THROW(parse_capture_record("x 0x81 0"), std::invalid_argument);
  EXPECT_EQ(format_capture_end(3, 12, 1, 0.5),
            "# end: 3 transfers, 12 bytes, 1 timeouts in 0.500000 s\n");
  EXPECT_EQ(format_capture_error("unplugged\nsecond line", 2),
            "# error: unplugged (2 transfers kept)\n");
}

// every ID pair of the table has a usbfs rule in the shipped udev file
TEST(UdevRules, EveryTouchIdHasAUsbRule) {
  std::ifstream in(std::string(VMH_SOURCE_DIR) + "/hw/udev/60-vmhaptics.rules");
  ASSERT_TRUE(in) << "hw/udev/60-vmhaptics.rules";
  std::set<std::pair<int, int>> usb, tty;
  bool firewire = false;
  const std::regex vid(R"re(ATTRS?\{idVendor\}=="([0-9a-f]{4})")re");
  const std::regex pid(R"re(ATTRS?\{idProduct\}=="([0-9a-f]{4})")re");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::smatch v, p;
    const bool grants = line.find("MODE=\"0660\"") != std::string::npos &&
                        line.find("GROUP=\"plugdev\"") != std::string::npos &&
                        line.find("TAG+=\"uaccess\"") != std::string::npos;
    EXPECT_TRUE(grants) << line;
    if (line.find("SUBSYSTEM==\"firewire\"") != std::string::npos &&
        line.find("ATTR{vendor}==\"0x000b99\"") != std::string::npos) {
      firewire = true;
    }
    if (!std::regex_search(line, v, vid) || !std::regex_search(line, p, pid)) continue;
    const std::pair<int, int> id{std::stoi(v[1], nullptr, 16), std::stoi(p[1], nullptr, 16)};
    if (line.find("SUBSYSTEM==\"usb\"") != std::string::npos) usb.insert(id);
    if (line.find("SUBSYSTEM==\"tty\"") != std::string::npos) tty.insert(id);
  }
  std::set<std::pair<int, int>> table;
  for (const TouchId& t : touch_ids()) table.insert({t.vendor_id, t.product_id});
  EXPECT_EQ(usb, table) << "the usb rules and touch_ids() have drifted apart";
  EXPECT_EQ(tty, table) << "the tty rules and touch_ids() have drifted apart";
  EXPECT_TRUE(firewire) << "no rule for the FireWire Omni (vendor 0x000b99)";
}

}  // namespace

// usb_codec_fuzz's first finding: a large t_s (%.6f prints every digit) was
// written into a 64-byte buffer, which cut the endpoint and the length off,
// and the line did not read back
TEST(CaptureFormat, ALargeTimeIsWrittenWhole) {
  const std::uint8_t bytes[] = {0xff};
  const std::string line = format_capture_record(1e300, 0x81, bytes, 1);
  ASSERT_GT(line.size(), 300u);
  EXPECT_EQ(line.compare(line.size() - 18, 18, ".000000 0x81 1 ff\n"), 0);
  const auto r = parse_capture_record(line.substr(0, line.size() - 1));
  ASSERT_TRUE(r);
  EXPECT_EQ(r->t_s, 1e300);
  EXPECT_EQ(r->endpoint, 0x81);
  EXPECT_EQ(r->data, std::vector<std::uint8_t>(bytes, bytes + 1));
}

// a length near 2^63 made 2 × length wrap round to the hex's size, so the
// line passed the length check and the loop read the hex past its end (the
// line was still refused, at the terminating NUL, which is why this passed
// before the fix too: it keeps the check in front of the loop)
TEST(CaptureFormat, ALengthThatWrapsIsRefused) {
  EXPECT_THROW(parse_capture_record("0 0x81 9223372036854775816 "
                                    "00112233445566778899aabbccddeeff"),
               std::invalid_argument);
  EXPECT_THROW(parse_capture_record("0 0x81 9223372036854775808"),
               std::invalid_argument);
}
