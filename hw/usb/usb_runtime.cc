#include "hw/usb/usb_runtime.h"

#include <cstdio>

namespace vmh::hw::usb {

const char* const kNotDecoded =
    "raw transfers only: the Touch's payload protocol is not public, so "
    "nothing is decoded and nothing is sent to the device (a guessed motor "
    "command on a force-feedback device is unsafe); drive a Touch through "
    "openhaptics";

namespace {

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

Json string_json(const UsbStringReport& s) {
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

}  // namespace

std::optional<BusAddress> parse_where(const std::string& argument) {
  if (argument.empty()) return std::nullopt;
  try {
    return parse_bus_address(argument);
  } catch (const UsbUsageError& e) {
    throw runtime::RequestError(e.what());
  }
}

Json listing_json(const TouchListing& t) {
  Json j{{"id", t.id},
         {"bus", t.bus},
         {"address", t.address},
         {"port", t.port_path},
         {"accessible", t.accessible}};
  if (!t.accessible) j["why_not"] = t.why_not;
  return j;
}

Json probe_json(const TouchProbe& p) {
  const UsbDeviceDescriptor& d = p.descriptors.device;
  Json configs = Json::array();
  for (const UsbConfiguration& c : p.descriptors.configurations) {
    Json intfs = Json::array();
    for (const UsbInterface& i : c.interfaces) {
      Json eps = Json::array();
      for (const UsbEndpoint& e : i.endpoints) {
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
        for (const InterfaceDriver& drv : p.drivers) {
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
      {"backend", "usb"},
      {"device", listing_json(p.device)},
      {"descriptor",
       Json{{"bcdUSB", format_bcd(d.bcd_usb)},
            {"class", hex2(d.device_class)},
            {"subclass", hex2(d.device_subclass)},
            {"protocol", hex2(d.device_protocol)},
            {"max_packet_size0", d.max_packet_size0},
            {"vendor_id", hex4(d.vendor_id)},
            {"product_id", hex4(d.product_id)},
            {"bcdDevice", format_bcd(d.bcd_device)},
            {"num_configurations", d.num_configurations}}},
      {"strings",
       Json{{"manufacturer", string_json(p.manufacturer)},
            {"product", string_json(p.product)},
            {"serial", string_json(p.serial)}}},
      {"configurations", configs},
      {"note", kNotDecoded},
      {"verified_on_hardware", false}};
}


Json capture_json(const CaptureResult& r) {
  Json eps = Json::array();
  for (std::uint8_t e : r.endpoints) eps.push_back(hex2(e));
  return Json{{"device", listing_json(r.device)},
              {"interface", r.interface_number},
              {"endpoints", eps},
              {"kernel_driver",
               r.kernel_driver.empty() ? Json(nullptr) : Json(r.kernel_driver)},
              {"detached", r.detached},
              {"transfers", r.transfers},
              {"bytes", r.bytes},
              {"timeouts", r.timeouts},
              {"elapsed_s", r.elapsed_s},
              {"out", r.out_path},
              {"error", r.error.empty() ? Json(nullptr) : Json(r.error)},
              {"note", kNotDecoded}};
}

namespace {

Json list_usb() {
  const TouchScan scan = list_touch_devices();
  Json found = Json::array();
  bool any = false;
  for (const TouchListing& t : scan.found) {
    found.push_back(listing_json(t));
    any = any || t.accessible;
  }
  Json j{{"available", any},
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


Json probe_usb(const std::string& argument) {
  const std::optional<BusAddress> where = parse_where(argument);
  try {
    return probe_json(probe_touch(where));
  } catch (const UsbUsageError& e) {
    throw runtime::RequestError(std::string("hw probe: ") + e.what());
  } catch (const UsbDeviceError& e) {
    throw runtime::RequestError(std::string("hw probe: ") + e.what());
  }
}

}  // namespace

void register_usb_backend(runtime::BackendRegistry* registry) {
  runtime::BackendInfo b;
  b.name = "usb";
  b.grammar = "usb[:BUS-ADDR]";
  b.summary = "the USB Touch through libusb: listed, probed and captured "
              "only (its payload protocol is not public)";
  b.servo = false;
  b.list = list_usb;
  b.probe = probe_usb;
  registry->add(std::move(b));
}

}  // namespace vmh::hw::usb
