// vmhaptics hw capture --device usb[:BUS-ADDR] --duration s --out FILE [--detach]
// and the USB branch of hw probe and hw list (cli/hw.cc, cli/hw_backends.cc).
//
// Exit codes: 0 done; 2 bad usage, no such device, or a device that cannot
// be opened or claimed (nothing written); 1 the device failed during the
// capture (an unplug: the file keeps every transfer and ends with
// "# error: ...").
#include "cli/hw_usb.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "cli/args.h"
#include "cli/hw_common.h"
#include "hw/usb/touch_usb.h"

namespace vmh::cli {
namespace {

namespace usb = vmh::hw::usb;

const char* const kNotDecoded =
    "raw transfers only: the Touch's payload protocol is not public, so "
    "nothing is decoded and nothing is sent to the device (a guessed motor "
    "command on a force-feedback device is unsafe); drive a Touch through "
    "openhaptics";

// "usb" or "usb:1-5" → where; UsageError for anything else
std::optional<usb::BusAddress> usb_where(const std::string& device) {
  const auto colon = device.find(':');
  if (device.substr(0, colon) != "usb") {
    throw UsageError("--device " + device + ": this verb takes usb[:BUS-ADDR] only");
  }
  if (colon == std::string::npos) return std::nullopt;
  try {
    return usb::parse_bus_address(device.substr(colon + 1));
  } catch (const usb::UsbUsageError& e) {
    throw UsageError(e.what());
  }
}

std::string hex4(unsigned v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%04x", v & 0xffffu);
  return buf;
}
std::string hex2(unsigned v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02x", v & 0xffu);
  return buf;
}

Json listing_json(const usb::TouchListing& t) {
  Json j{{"id", t.id},
         {"bus", t.bus},
         {"address", t.address},
         {"port", t.port_path},
         {"accessible", t.accessible}};
  if (!t.accessible) j["why_not"] = t.why_not;
  return j;
}

Json string_json(const usb::UsbStringReport& s) {
  Json j{{"index", s.index}};
  if (s.value) {
    j["value"] = *s.value;
    j["source"] = s.source;
  } else {
    j["value"] = nullptr;
    j["why_not"] = s.why_not;
  }
  return j;
}

Json probe_json(const usb::TouchProbe& p) {
  const usb::UsbDeviceDescriptor& d = p.descriptors.device;
  Json configs = Json::array();
  for (const usb::UsbConfiguration& c : p.descriptors.configurations) {
    Json intfs = Json::array();
    for (const usb::UsbInterface& i : c.interfaces) {
      Json eps = Json::array();
      for (const usb::UsbEndpoint& e : i.endpoints) {
        eps.push_back(Json{{"address", hex2(e.address)},
                           {"direction", e.direction},
                           {"transfer_type", e.transfer_type},
                           {"max_packet_size", e.max_packet_size},
                           {"interval", e.interval}});
      }
      Json ij{{"number", i.number},
              {"alt_setting", i.alt_setting},
              {"class", hex2(i.interface_class)},
              {"subclass", hex2(i.interface_subclass)},
              {"protocol", hex2(i.interface_protocol)},
              {"endpoints", eps}};
      if (c.value == p.active_configuration && i.alt_setting == 0) {
        for (const usb::InterfaceDriver& drv : p.drivers) {
          if (drv.interface_number != i.number) continue;
          ij["kernel_driver"] = drv.sysfs_driver.empty() ? Json(nullptr) : Json(drv.sysfs_driver);
          ij["kernel_driver_active"] =
              drv.libusb_active ? Json(*drv.libusb_active) : Json(nullptr);
        }
      }
      intfs.push_back(ij);
    }
    configs.push_back(Json{{"value", c.value},
                           {"active", c.value == p.active_configuration},
                           {"attributes", hex2(c.attributes)},
                           {"max_power_mA", c.max_power_mA},
                           {"interfaces", intfs}});
  }
  return Json{
      {"backend", "usb_touch"},
      {"device", listing_json(p.device)},
      {"descriptor",
       Json{{"bcdUSB", usb::format_bcd(d.bcd_usb)},
            {"class", hex2(d.device_class)},
            {"subclass", hex2(d.device_subclass)},
            {"protocol", hex2(d.device_protocol)},
            {"max_packet_size0", d.max_packet_size0},
            {"vendor_id", hex4(d.vendor_id)},
            {"product_id", hex4(d.product_id)},
            {"bcdDevice", usb::format_bcd(d.bcd_device)},
            {"num_configurations", d.num_configurations}}},
      {"strings",
       Json{{"manufacturer", string_json(p.manufacturer)},
            {"product", string_json(p.product)},
            {"serial", string_json(p.serial)}}},
      {"configurations", configs},
      {"note", kNotDecoded},
      {"verified_on_hardware", false}};
}

struct CaptureArgs {
  std::string device = "usb";
  double duration_s = std::nan("");
  std::string out;
  bool detach = false;
};

void capture(const CaptureArgs& a) {
  usb::CaptureOptions o;
  o.where = usb_where(a.device);
  check_seconds("hw capture: --duration", a.duration_s, 0.0, 3600.0);
  o.duration_s = a.duration_s;
  o.out_path = a.out;
  o.detach = a.detach;
  usb::CaptureResult r;
  try {
    r = usb::capture_touch(o);
  } catch (const usb::UsbUsageError& e) {
    throw UsageError(std::string("hw capture: ") + e.what());
  } catch (const usb::UsbDeviceError& e) {
    throw UsageError(std::string("hw capture: ") + e.what());
  }
  Json eps = Json::array();
  for (std::uint8_t e : r.endpoints) eps.push_back(hex2(e));
  Json out{{"device", listing_json(r.device)},
           {"interface", r.interface_number},
           {"endpoints", eps},
           {"kernel_driver", r.kernel_driver.empty() ? Json(nullptr) : Json(r.kernel_driver)},
           {"detached", r.detached},
           {"transfers", r.transfers},
           {"bytes", r.bytes},
           {"timeouts", r.timeouts},
           {"elapsed_s", r.elapsed_s},
           {"out", r.out_path},
           {"error", r.error.empty() ? Json(nullptr) : Json(r.error)},
           {"note", kNotDecoded}};
  std::cout << dump_readable(out) << '\n';
  if (!r.error.empty()) {
    throw std::runtime_error("hw capture: " + r.error + "; " + std::to_string(r.transfers) +
                             " transfers kept in " + r.out_path);
  }
}

}  // namespace

Json usb_touch_backend_json() {
  const usb::TouchScan scan = usb::list_touch_devices();
  Json found = Json::array();
  bool any = false;
  for (const usb::TouchListing& t : scan.found) {
    found.push_back(listing_json(t));
    any = any || t.accessible;
  }
  Json j{{"name", "usb_touch"},
         {"device", "usb[:BUS-ADDR]"},
         {"available", any},
         {"found", found}};
  if (!any) {
    std::string why;
    if (!scan.why_none.empty()) {
      why = scan.why_none;
    } else if (scan.found.empty()) {
      why = "no USB Touch found (looked for 2988:0301, 2988:0302, 2988:0304 "
            "and 0301:2988)";
    } else {
      why = scan.found.front().why_not;
    }
    j["why_not"] = why;
  }
  j["verified_on_hardware"] = false;
  j["note"] = std::string("hw probe and hw capture only; ") + kNotDecoded;
  return j;
}

void usb_probe(const std::string& argument) {
  const std::optional<usb::BusAddress> where = usb_where(argument.empty() ? "usb" : "usb:" + argument);
  usb::TouchProbe p;
  try {
    p = usb::probe_touch(where);
  } catch (const usb::UsbUsageError& e) {
    throw UsageError(std::string("hw probe: ") + e.what());
  } catch (const usb::UsbDeviceError& e) {
    throw UsageError(std::string("hw probe: ") + e.what());
  }
  std::cout << dump_readable(probe_json(p)) << '\n';
}

void register_hw_capture(CLI::App* hw) {
  auto a = std::make_shared<CaptureArgs>();
  CLI::App* c = hw->add_subcommand(
      "capture",
      "the USB Touch's raw IN transfers, timestamped, to a text file; nothing "
      "decoded (hw/usb/README.md)");
  c->add_option("--device", a->device, "usb[:BUS-ADDR] (default: the first Touch)");
  c->add_option("--duration", a->duration_s, "seconds to capture, > 0 and <= 3600")->required();
  c->add_option("--out", a->out, "the capture file (hw/usb/README.md, capture format)")
      ->required();
  c->add_flag("--detach", a->detach,
              "detach the kernel driver (cdc_acm) from the data interface for "
              "the capture; it is re-attached afterwards");
  c->callback([a]() { capture(*a); });
}

}  // namespace vmh::cli
