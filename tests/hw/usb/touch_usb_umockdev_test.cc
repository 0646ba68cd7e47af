// hw/usb against described USB devices: umockdev fakes sysfs and usbfs for
// this process (it runs under umockdev-wrapper, which preloads
// libumockdev-preload; tests/hw/usb/CMakeLists.txt). Each test builds its
// own testbed from the hand-written descriptions in this folder
// (tests/hw/usb/README.md) and the recorded usbfs traffic replayed for the
// bulk IN reads of a capture. libusb enumerates and opens the described
// devices exactly as it would real ones; nothing here is a real Touch.
#include <gtest/gtest.h>
#include <libusb.h>
#include <umockdev.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "hw/usb/touch_usb.h"
#include "hw/usb/usb_transport.h"

namespace {

namespace fs = std::filesystem;
using namespace vmh::hw::usb;

const std::string kDir = VMH_USB_TEST_DIR;

class Testbed {
 public:
  Testbed() : tb_(umockdev_testbed_new()) {}
  ~Testbed() { g_object_unref(tb_); }
  Testbed(const Testbed&) = delete;
  Testbed& operator=(const Testbed&) = delete;

  void add(const std::string& file) {
    GError* e = nullptr;
    const bool ok = umockdev_testbed_add_from_file(tb_, (kDir + "/" + file).c_str(), &e);
    ASSERT_TRUE(ok) << file << ": " << (e ? e->message : "");
  }
  // a description from this folder with the lines starting `drop` removed
  void add_without(const std::string& file, const std::string& drop) {
    std::ifstream in(kDir + "/" + file);
    std::string line, text;
    while (std::getline(in, line)) {
      if (line.rfind(drop, 0) != 0) text += line + "\n";
    }
    GError* e = nullptr;
    const bool ok = umockdev_testbed_add_from_string(tb_, text.c_str(), &e);
    ASSERT_TRUE(ok) << file << ": " << (e ? e->message : "");
  }
  void replay(const std::string& devnode, const std::string& file) {
    GError* e = nullptr;
    const bool ok =
        umockdev_testbed_load_ioctl(tb_, devnode.c_str(), (kDir + "/" + file).c_str(), &e);
    ASSERT_TRUE(ok) << file << ": " << (e ? e->message : "");
  }

 private:
  UMockdevTestbed* tb_;
};

class TouchUsb : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* preload = std::getenv("LD_PRELOAD");
    ASSERT_TRUE(preload != nullptr && std::strstr(preload, "umockdev-preload") != nullptr)
        << "run this test under umockdev-wrapper (ctest does)";
  }
};

// the records the test's .ioctl files replay, in order: (length, hex)
struct Recorded {
  std::size_t length;
  std::string hex;
};

std::vector<Recorded> recorded_reads(const std::string& ioctl_file) {
  std::vector<Recorded> out;
  std::ifstream in(kDir + "/" + ioctl_file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("USBDEVFS_REAPURBNDELAY ", 0) != 0) continue;
    std::istringstream s(line.substr(23));
    int ret, type, ep, status, flags, buflen, actual, errors;
    std::string hex;
    s >> ret >> type >> ep >> status >> flags >> buflen >> actual >> errors >> hex;
    if (status != 0) continue;  // the unplug
    for (char& c : hex) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    out.push_back({static_cast<std::size_t>(actual), hex});
  }
  return out;
}

std::vector<std::string> lines_of(const fs::path& p) {
  std::vector<std::string> out;
  std::ifstream in(p);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

fs::path out_file(const std::string& name) {
  const fs::path p = fs::path(::testing::TempDir()) / ("vmh_usb_" + name);
  fs::remove(p);
  return p;
}

TEST_F(TouchUsb, ListFindsExactlyTheTouchesWithTheirIdsBusAndAddress) {
  Testbed tb;
  tb.add("touch_0302.umockdev");
  tb.add("touch_0301_early.umockdev");
  tb.add("not_a_touch_mouse.umockdev");
  const TouchScan scan = list_touch_devices();
  EXPECT_TRUE(scan.why_none.empty()) << scan.why_none;
  ASSERT_EQ(scan.found.size(), 2u);
  const TouchListing* later = nullptr;
  const TouchListing* early = nullptr;
  for (const TouchListing& t : scan.found) {
    if (t.id == "2988:0302") later = &t;
    if (t.id == "0301:2988") early = &t;
  }
  ASSERT_NE(later, nullptr);
  ASSERT_NE(early, nullptr);
  EXPECT_EQ(later->bus, 1);
  EXPECT_EQ(later->address, 5);
  EXPECT_EQ(later->port_path, "1-2");
  EXPECT_TRUE(later->accessible) << later->why_not;
  EXPECT_EQ(early->bus, 2);
  EXPECT_EQ(early->address, 3);
  EXPECT_EQ(early->port_path, "2-1");
  EXPECT_TRUE(early->accessible) << early->why_not;
}

TEST_F(TouchUsb, ListIsEmptyWithOnlyAnotherDevice) {
  Testbed tb;
  tb.add("not_a_touch_mouse.umockdev");
  const TouchScan scan = list_touch_devices();
  EXPECT_TRUE(scan.found.empty());
  EXPECT_TRUE(scan.why_none.empty()) << scan.why_none;
}

// a Touch libusb lists but cannot open (its /dev node is missing): listed,
// not accessible, and why; the probe still describes it from sysfs
TEST_F(TouchUsb, ListSaysWhyATouchCannotBeOpened) {
  Testbed tb;
  tb.add_without("touch_0301_early.umockdev", "N:");
  const TouchScan scan = list_touch_devices();
  ASSERT_EQ(scan.found.size(), 1u);
  EXPECT_FALSE(scan.found[0].accessible);
  EXPECT_EQ(scan.found[0].why_not.rfind("could not open /dev/bus/usb/002/003: LIBUSB_ERROR_", 0), 0u)
      << scan.found[0].why_not;
  const TouchProbe p = probe_touch(std::nullopt);
  EXPECT_FALSE(p.device.accessible);
  EXPECT_EQ(p.descriptors.device.product_id, 0x2988);
  EXPECT_NE(p.serial.why_not.find("could not be opened"), std::string::npos) << p.serial.why_not;
  CaptureOptions o;
  o.duration_s = 0.1;
  o.out_path = out_file("noopen.txt").string();
  EXPECT_THROW(capture_touch(o), UsbDeviceError);
  EXPECT_FALSE(fs::exists(o.out_path));
}

// the text a user without the udev rule sees (the tests run as root, so
// libusb_open cannot be made to fail with EACCES here)
TEST(TouchUsbText, PermissionDeniedPointsAtTheUdevRule) {
  EXPECT_EQ(open_failure_text(LIBUSB_ERROR_ACCESS, BusAddress{1, 5}),
            "permission denied opening /dev/bus/usb/001/005: install "
            "hw/udev/60-vmhaptics.rules (hw/udev/README.md, docs/hardware.md)");
}

TEST_F(TouchUsb, ProbeGivesTheDescribedDescriptorsStringsAndDrivers) {
  Testbed tb;
  tb.add("touch_0302.umockdev");
  tb.add("not_a_touch_mouse.umockdev");
  const TouchProbe p = probe_touch(BusAddress{1, 5});
  EXPECT_EQ(p.device.id, "2988:0302");
  EXPECT_TRUE(p.device.accessible);
  const UsbDeviceDescriptor& d = p.descriptors.device;
  EXPECT_EQ(d.bcd_usb, 0x0200);
  EXPECT_EQ(d.device_class, 0x02);
  EXPECT_EQ(d.vendor_id, 0x2988);
  EXPECT_EQ(d.product_id, 0x0302);
  EXPECT_EQ(d.bcd_device, 0x0100);
  EXPECT_EQ(d.max_packet_size0, 64);
  ASSERT_TRUE(p.manufacturer.value);
  EXPECT_EQ(*p.manufacturer.value, "3D Systems");
  EXPECT_EQ(p.manufacturer.source, "sysfs");
  ASSERT_TRUE(p.product.value);
  EXPECT_EQ(*p.product.value, "3D Systems Touch 3D Stylus");
  ASSERT_TRUE(p.serial.value);
  EXPECT_EQ(*p.serial.value, "VMH-TEST-0302");
  EXPECT_EQ(p.active_configuration, 1);
  ASSERT_EQ(p.descriptors.configurations.size(), 1u);
  const UsbConfiguration& c = p.descriptors.configurations[0];
  EXPECT_EQ(c.max_power_mA, 100);
  ASSERT_EQ(c.interfaces.size(), 2u);
  const UsbInterface& comm = c.interfaces[0];
  EXPECT_EQ(comm.interface_class, 0x02);
  EXPECT_EQ(comm.interface_subclass, 0x02);
  EXPECT_EQ(comm.interface_protocol, 0x01);
  ASSERT_EQ(comm.endpoints.size(), 1u);
  EXPECT_EQ(comm.endpoints[0].address, 0x82);
  EXPECT_EQ(comm.endpoints[0].transfer_type, "interrupt");
  EXPECT_EQ(comm.endpoints[0].max_packet_size, 8);
  EXPECT_EQ(comm.endpoints[0].interval, 16);
  const UsbInterface& data = c.interfaces[1];
  EXPECT_EQ(data.interface_class, 0x0a);
  ASSERT_EQ(data.endpoints.size(), 2u);
  EXPECT_EQ(data.endpoints[0].address, 0x01);
  EXPECT_EQ(data.endpoints[0].direction, "out");
  EXPECT_EQ(data.endpoints[0].transfer_type, "bulk");
  EXPECT_EQ(data.endpoints[1].address, 0x81);
  EXPECT_EQ(data.endpoints[1].direction, "in");
  EXPECT_EQ(data.endpoints[1].max_packet_size, 64);
  ASSERT_EQ(p.drivers.size(), 2u);
  for (const InterfaceDriver& drv : p.drivers) {
    EXPECT_EQ(drv.sysfs_driver, "cdc_acm") << drv.interface_number;
    // umockdev answers USBDEVFS_GETDRIVER with ENODATA: libusb sees none
    ASSERT_TRUE(drv.libusb_active.has_value());
    EXPECT_FALSE(*drv.libusb_active);
  }
}

// the project's parse of the raw descriptors agrees with libusb's own
TEST_F(TouchUsb, ProbeParseAgreesWithLibusb) {
  Testbed tb;
  tb.add("touch_0302.umockdev");
  const TouchProbe p = probe_touch(std::nullopt);
  UsbContext ctx;
  UsbDeviceList list(ctx);
  ASSERT_EQ(list.devices().size(), 1u);
  libusb_config_descriptor* cfg = nullptr;
  ASSERT_EQ(libusb_get_active_config_descriptor(list.devices()[0].device, &cfg), 0);
  const UsbConfiguration& c = p.descriptors.configurations.at(0);
  ASSERT_EQ(cfg->bNumInterfaces, c.interfaces.size());
  for (int i = 0; i < cfg->bNumInterfaces; ++i) {
    const libusb_interface_descriptor& li = cfg->interface[i].altsetting[0];
    EXPECT_EQ(li.bInterfaceClass, c.interfaces[i].interface_class);
    ASSERT_EQ(li.bNumEndpoints, c.interfaces[i].endpoints.size());
    for (int e = 0; e < li.bNumEndpoints; ++e) {
      EXPECT_EQ(li.endpoint[e].bEndpointAddress, c.interfaces[i].endpoints[e].address);
      EXPECT_EQ(li.endpoint[e].wMaxPacketSize, c.interfaces[i].endpoints[e].max_packet_size);
      EXPECT_EQ(li.endpoint[e].bInterval, c.interfaces[i].endpoints[e].interval);
    }
  }
  libusb_free_config_descriptor(cfg);
}

TEST_F(TouchUsb, ProbeOfTheEarlyUnitReadsStringsAndSaysWhyNot) {
  Testbed tb;
  tb.add("touch_0301_early.umockdev");
  const TouchProbe p = probe_touch(BusAddress{2, 3});
  EXPECT_EQ(p.device.id, "0301:2988");
  EXPECT_EQ(p.descriptors.device.vendor_id, 0x0301);
  ASSERT_TRUE(p.product.value);
  EXPECT_EQ(*p.product.value, "PHANTOM Omni (USB)");
  // iSerialNumber is 3 but the description has no sysfs `serial`, and the
  // device answers no control transfer: it must say why, not invent one
  EXPECT_EQ(p.serial.index, 3);
  EXPECT_FALSE(p.serial.value);
  EXPECT_NE(p.serial.why_not.find("not in sysfs"), std::string::npos) << p.serial.why_not;
  for (const InterfaceDriver& drv : p.drivers) EXPECT_EQ(drv.sysfs_driver, "");
}

TEST_F(TouchUsb, ProbeErrorsNameTheValue) {
  Testbed tb;
  tb.add("touch_0302.umockdev");
  tb.add("not_a_touch_mouse.umockdev");
  try {
    probe_touch(BusAddress{1, 6});
    FAIL() << "a mouse probed as a Touch";
  } catch (const UsbUsageError& e) {
    EXPECT_NE(std::string(e.what()).find("046d:c077, not a Touch"), std::string::npos) << e.what();
  }
  try {
    probe_touch(BusAddress{3, 9});
    FAIL() << "no device at 3-9";
  } catch (const UsbUsageError& e) {
    EXPECT_NE(std::string(e.what()).find("usb:3-9"), std::string::npos) << e.what();
  }
}

TEST_F(TouchUsb, NoTouchPresentIsAUsageError) {
  Testbed tb;
  tb.add("not_a_touch_mouse.umockdev");
  EXPECT_THROW(probe_touch(std::nullopt), UsbUsageError);
  CaptureOptions o;
  o.duration_s = 0.1;
  o.out_path = out_file("none.txt").string();
  EXPECT_THROW(capture_touch(o), UsbUsageError);
  EXPECT_FALSE(fs::exists(o.out_path));
}

TEST_F(TouchUsb, CaptureRefusesWhileCdcAcmHoldsTheInterface) {
  Testbed tb;
  tb.add("touch_0302.umockdev");
  tb.replay("/dev/bus/usb/001/005", "touch_0302.ioctl");
  CaptureOptions o;
  o.duration_s = 0.1;
  o.out_path = out_file("held.txt").string();
  try {
    capture_touch(o);
    FAIL() << "captured without --detach";
  } catch (const UsbDeviceError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("held by cdc_acm"), std::string::npos) << m;
    EXPECT_NE(m.find("--detach"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(o.out_path)) << "nothing may be written";
}

TEST_F(TouchUsb, CaptureWritesTheRecordedTransfersWithTimestamps) {
  Testbed tb;
  tb.add("touch_0302.umockdev");
  tb.replay("/dev/bus/usb/001/005", "touch_0302.ioctl");
  CaptureOptions o;
  o.duration_s = 0.2;
  o.detach = true;
  o.out_path = out_file("capture.txt").string();
  const CaptureResult r = capture_touch(o);
  EXPECT_TRUE(r.error.empty()) << r.error;
  EXPECT_FALSE(r.device_lost);
  EXPECT_EQ(r.interface_number, 1);
  EXPECT_EQ(r.endpoints, std::vector<std::uint8_t>{0x81});
  EXPECT_EQ(r.kernel_driver, "cdc_acm");
  EXPECT_GE(r.elapsed_s, 0.2);

  const std::vector<Recorded> rec = recorded_reads("touch_0302.ioctl");
  ASSERT_EQ(rec.size(), 4u);
  const std::vector<std::string> lines = lines_of(o.out_path);
  ASSERT_GE(lines.size(), 3u);
  EXPECT_EQ(lines[0].rfind("# vmhaptics usb capture v1: device 2988:0302 bus 1 address 5", 0), 0u)
      << lines[0];
  EXPECT_EQ(lines[1].rfind("# t_s endpoint length hex", 0), 0u) << lines[1];
  EXPECT_EQ(lines.back().rfind("# end: " + std::to_string(r.transfers) + " transfers", 0), 0u)
      << lines.back();
  // the replay repeats the recording for as long as the capture reads, so
  // the records are the recorded reads, in order, over and over
  std::size_t n = 0, bytes = 0;
  double t_prev = 0.0;
  for (std::size_t i = 2; i + 1 < lines.size(); ++i, ++n) {
    const std::optional<CaptureRecord> c = parse_capture_record(lines[i]);
    ASSERT_TRUE(c) << lines[i];
    const Recorded& want = rec[n % rec.size()];
    EXPECT_EQ(c->endpoint, 0x81);
    ASSERT_EQ(c->data.size(), want.length) << lines[i];
    std::string hex;
    for (std::uint8_t b : c->data) {
      char buf[3];
      std::snprintf(buf, sizeof buf, "%02x", b);
      hex += buf;
    }
    EXPECT_EQ(hex, want.hex.substr(0, 2 * want.length)) << lines[i];
    EXPECT_GE(c->t_s, t_prev) << "timestamps must not go back: " << lines[i];
    EXPECT_LE(c->t_s, r.elapsed_s);
    t_prev = c->t_s;
    bytes += c->data.size();
  }
  EXPECT_EQ(n, r.transfers);
  EXPECT_EQ(bytes, r.bytes);
  EXPECT_GE(n, rec.size()) << "at least one pass over the recording";
}

TEST_F(TouchUsb, UnplugMidCaptureEndsCleanlyAndKeepsTheRecords) {
  Testbed tb;
  tb.add("touch_0302.umockdev");
  tb.replay("/dev/bus/usb/001/005", "touch_0302_unplug.ioctl");
  CaptureOptions o;
  o.duration_s = 5.0;
  o.detach = true;
  o.out_path = out_file("unplug.txt").string();
  const CaptureResult r = capture_touch(o);
  EXPECT_TRUE(r.device_lost);
  EXPECT_NE(r.error.find("unplugged"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("LIBUSB_ERROR_NO_DEVICE"), std::string::npos) << r.error;
  EXPECT_EQ(r.error.find('\n'), std::string::npos);
  EXPECT_LT(r.elapsed_s, 5.0);
  const std::vector<Recorded> rec = recorded_reads("touch_0302_unplug.ioctl");
  ASSERT_EQ(r.transfers, rec.size());
  const std::vector<std::string> lines = lines_of(o.out_path);
  ASSERT_EQ(lines.size(), 2 + rec.size() + 1);
  for (std::size_t i = 0; i < rec.size(); ++i) {
    const std::optional<CaptureRecord> c = parse_capture_record(lines[2 + i]);
    ASSERT_TRUE(c);
    EXPECT_EQ(c->data.size(), rec[i].length);
  }
  EXPECT_EQ(lines.back().rfind("# error: the Touch 2988:0302 at bus 1 address 5 was unplugged", 0), 0u)
      << lines.back();
  EXPECT_NE(lines.back().find("(3 transfers kept)"), std::string::npos) << lines.back();
}

TEST_F(TouchUsb, CaptureRejectsBadDurationsNamingTheValue) {
  Testbed tb;
  tb.add("touch_0302.umockdev");
  for (double d : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                   std::numeric_limits<double>::infinity()}) {
    CaptureOptions o;
    o.duration_s = d;
    o.detach = true;
    o.out_path = out_file("bad.txt").string();
    try {
      capture_touch(o);
      FAIL() << d;
    } catch (const UsbUsageError& e) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%g", d);
      EXPECT_NE(std::string(e.what()).find(std::string("--duration ") + buf), std::string::npos)
          << e.what();
    }
    EXPECT_FALSE(fs::exists(o.out_path));
  }
}

}  // namespace
