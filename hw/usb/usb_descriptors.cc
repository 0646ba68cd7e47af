#include "hw/usb/usb_descriptors.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace vmh::hw::usb {
namespace {

// descriptor types, USB 2.0 table 9-5
constexpr std::uint8_t kDtDevice = 0x01;
constexpr std::uint8_t kDtConfig = 0x02;
constexpr std::uint8_t kDtInterface = 0x04;
constexpr std::uint8_t kDtEndpoint = 0x05;

std::uint16_t le16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}

std::string hex2(unsigned v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02x", v & 0xffu);
  return buf;
}

[[noreturn]] void bad(std::size_t offset, const std::string& what) {
  throw std::invalid_argument("USB descriptors: at byte " + std::to_string(offset) +
                              ": " + what);
}

// a decimal number in 1..255, all digits
bool parse_small(const std::string& s, int* out) {
  if (s.empty() || s.size() > 3) return false;
  for (char c : s) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  }
  *out = std::atoi(s.c_str());
  return *out >= 1 && *out <= 255;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

const std::vector<TouchId>& touch_ids() {
  // docs/sources.md §9.3: 0x0301:0x2988 on early units, 0x2988:0x0302 on
  // later ones, 0x2988:0x0304 in the udev rule of the 2023 driver; 0x0301
  // as a product of vendor 0x2988 is the project's brief (the swap of the
  // early pair) and is listed so that such a unit is not missed
  static const std::vector<TouchId> ids = {
      {0x2988, 0x0301, "3D Systems Touch (product 0x0301)"},
      {0x2988, 0x0302, "3D Systems Touch (later units)"},
      {0x2988, 0x0304, "3D Systems Touch (2023 driver's udev rule)"},
      {0x0301, 0x2988, "Touch, early units (vendor and product swapped)"},
  };
  return ids;
}

bool is_touch_id(std::uint16_t vendor_id, std::uint16_t product_id) {
  for (const TouchId& t : touch_ids()) {
    if (t.vendor_id == vendor_id && t.product_id == product_id) return true;
  }
  return false;
}

std::string format_usb_id(std::uint16_t vendor_id, std::uint16_t product_id) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%04x:%04x", static_cast<unsigned>(vendor_id),
                static_cast<unsigned>(product_id));
  return buf;
}

std::string format_port_path(int bus, const std::vector<std::uint8_t>& ports) {
  if (ports.empty()) return "usb" + std::to_string(bus);
  std::string s = std::to_string(bus) + "-";
  for (std::size_t i = 0; i < ports.size(); ++i) {
    if (i > 0) s += '.';
    s += std::to_string(static_cast<unsigned>(ports[i]));
  }
  return s;
}

BusAddress parse_bus_address(const std::string& text) {
  const auto dash = text.find('-');
  BusAddress w;
  if (dash == std::string::npos || !parse_small(text.substr(0, dash), &w.bus) ||
      !parse_small(text.substr(dash + 1), &w.address)) {
    throw UsbUsageError("--device usb:" + text +
                        ": expected BUS-ADDR, the bus number and device "
                        "address in 1..255 as in /dev/bus/usb/BBB/DDD "
                        "(e.g. usb:1-5; `vmhaptics hw list` shows them)");
  }
  return w;
}

std::string usbfs_path(const BusAddress& where) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "/dev/bus/usb/%03d/%03d", where.bus, where.address);
  return buf;
}

UsbDescriptors parse_usb_descriptors(const std::uint8_t* d, std::size_t n) {
  UsbDescriptors out;
  if (n < 18) bad(0, "a device descriptor needs 18 bytes, got " + std::to_string(n));
  if (d[0] != 18 || d[1] != kDtDevice) {
    bad(0, "not a device descriptor (bLength " + std::to_string(d[0]) +
               ", bDescriptorType " + hex2(d[1]) + ")");
  }
  UsbDeviceDescriptor& dev = out.device;
  dev.bcd_usb = le16(d + 2);
  dev.device_class = d[4];
  dev.device_subclass = d[5];
  dev.device_protocol = d[6];
  dev.max_packet_size0 = d[7];
  dev.vendor_id = le16(d + 8);
  dev.product_id = le16(d + 10);
  dev.bcd_device = le16(d + 12);
  dev.manufacturer_index = d[14];
  dev.product_index = d[15];
  dev.serial_index = d[16];
  dev.num_configurations = d[17];

  std::size_t at = 18;
  while (at < n) {
    if (n - at < 9) bad(at, "a configuration descriptor needs 9 bytes");
    const std::uint8_t* c = d + at;
    if (c[0] < 9 || c[1] != kDtConfig) {
      bad(at, "not a configuration descriptor (bLength " + std::to_string(c[0]) +
                  ", bDescriptorType " + hex2(c[1]) + ")");
    }
    const std::size_t total = le16(c + 2);
    if (total < c[0] || total > n - at) {
      bad(at, "wTotalLength " + std::to_string(total) + " does not fit the " +
                  std::to_string(n - at) + " bytes left");
    }
    UsbConfiguration config;
    config.value = c[5];
    config.attributes = c[7];
    config.max_power_mA = 2 * c[8];
    UsbInterface* current = nullptr;
    std::size_t p = at + c[0];
    const std::size_t end = at + total;
    while (p < end) {
      const std::uint8_t len = d[p];
      if (len < 2 || len > end - p) {
        bad(p, "descriptor length " + std::to_string(len) + " runs past its configuration");
      }
      const std::uint8_t type = d[p + 1];
      if (type == kDtInterface) {
        if (len < 9) bad(p, "an interface descriptor needs 9 bytes");
        UsbInterface intf;
        intf.number = d[p + 2];
        intf.alt_setting = d[p + 3];
        intf.interface_class = d[p + 5];
        intf.interface_subclass = d[p + 6];
        intf.interface_protocol = d[p + 7];
        intf.string_index = d[p + 8];
        config.interfaces.push_back(intf);
        current = &config.interfaces.back();
      } else if (type == kDtEndpoint) {
        if (len < 7) bad(p, "an endpoint descriptor needs 7 bytes");
        if (current == nullptr) bad(p, "an endpoint descriptor before any interface");
        UsbEndpoint ep;
        ep.address = d[p + 2];
        ep.direction = (ep.address & 0x80) ? "in" : "out";
        static const char* const kTypes[] = {"control", "isochronous", "bulk",
                                             "interrupt"};
        ep.transfer_type = kTypes[d[p + 3] & 0x03];
        ep.max_packet_size = static_cast<std::uint16_t>(le16(d + p + 4) & 0x07ff);
        ep.interval = d[p + 6];
        current->endpoints.push_back(ep);
      }
      // class-specific (CDC functional descriptors, HID, ...) and
      // interface-association descriptors are skipped
      p += len;
    }
    out.configurations.push_back(std::move(config));
    at = end;
  }
  return out;
}

UsbDescriptors parse_usb_descriptors(const std::vector<std::uint8_t>& bytes) {
  return parse_usb_descriptors(bytes.data(), bytes.size());
}

std::string format_bcd(std::uint16_t bcd) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%x.%02x", static_cast<unsigned>(bcd >> 8),
                static_cast<unsigned>(bcd & 0xff));
  return buf;
}

const UsbInterface* find_data_interface(const UsbConfiguration& config) {
  for (const UsbInterface& i : config.interfaces) {
    if (i.interface_class == 0x0a && i.alt_setting == 0) return &i;
  }
  for (const UsbInterface& i : config.interfaces) {
    if (i.alt_setting == 0 && !capture_endpoints(i).empty()) return &i;
  }
  return nullptr;
}

std::vector<UsbEndpoint> capture_endpoints(const UsbInterface& interface) {
  std::vector<UsbEndpoint> out;
  for (const UsbEndpoint& e : interface.endpoints) {
    if (e.direction == "in" &&
        (e.transfer_type == "bulk" || e.transfer_type == "interrupt")) {
      out.push_back(e);
    }
  }
  return out;
}

std::string format_capture_header(const CaptureHeader& h) {
  std::ostringstream s;
  s << "# vmhaptics usb capture v1: device " << h.device_id << " bus " << h.where.bus
    << " address " << h.where.address << " port " << h.port_path << " interface "
    << h.interface_number << " endpoints";
  for (std::uint8_t e : h.endpoints) s << ' ' << hex2(e);
  char dur[32];
  std::snprintf(dur, sizeof dur, "%g", h.duration_s);
  s << " duration_s " << dur << " started " << h.started_utc << '\n'
    << "# t_s endpoint length hex  (payload not decoded: the Touch's protocol "
       "is not public)\n";
  return s.str();
}

std::string format_capture_record(double t_s, std::uint8_t endpoint,
                                  const std::uint8_t* data, std::size_t size) {
  // sized by snprintf itself: %.6f of a large t_s is hundreds of digits, and a
  // fixed buffer cut the endpoint and length off the line
  const int head = std::snprintf(nullptr, 0, "%.6f 0x%02x %zu", t_s,
                                 static_cast<unsigned>(endpoint), size);
  std::string s(static_cast<std::size_t>(head), '\0');
  std::snprintf(s.data(), s.size() + 1, "%.6f 0x%02x %zu", t_s,
                static_cast<unsigned>(endpoint), size);
  if (size > 0) {
    s += ' ';
    static const char* const kHex = "0123456789abcdef";
    for (std::size_t i = 0; i < size; ++i) {
      s += kHex[data[i] >> 4];
      s += kHex[data[i] & 0x0f];
    }
  }
  s += '\n';
  return s;
}

std::string format_capture_end(std::size_t transfers, std::size_t bytes,
                               std::size_t timeouts, double elapsed_s) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "# end: %zu transfers, %zu bytes, %zu timeouts in %.6f s\n",
                transfers, bytes, timeouts, elapsed_s);
  return buf;
}

std::string format_capture_error(const std::string& why, std::size_t transfers) {
  std::string one = why.substr(0, why.find('\n'));
  return "# error: " + one + " (" + std::to_string(transfers) + " transfers kept)\n";
}

std::optional<CaptureRecord> parse_capture_record(const std::string& line) {
  if (line.empty() || line[0] == '#') return std::nullopt;
  std::istringstream in(line);
  std::string t, ep, len, hex, extra;
  in >> t >> ep >> len >> hex >> extra;
  CaptureRecord r;
  char* end = nullptr;
  r.t_s = std::strtod(t.c_str(), &end);
  const bool t_ok = !t.empty() && end != nullptr && *end == '\0' && std::isfinite(r.t_s);
  const bool ep_ok = ep.size() == 4 && ep[0] == '0' && ep[1] == 'x' &&
                     hex_digit(ep[2]) >= 0 && hex_digit(ep[3]) >= 0;
  std::size_t n = 0;
  bool len_ok = !len.empty();
  for (char c : len) len_ok = len_ok && std::isdigit(static_cast<unsigned char>(c));
  if (len_ok) n = static_cast<std::size_t>(std::strtoull(len.c_str(), nullptr, 10));
  // n > hex.size() first: a 19-digit length near 2^63 wraps 2 * n round to
  // the hex's size, and the loop below then read past the hex
  if (!t_ok || !ep_ok || !len_ok || n > hex.size() || hex.size() != 2 * n ||
      !extra.empty()) {
    throw std::invalid_argument("not a capture record: '" + line + "'");
  }
  r.endpoint = static_cast<std::uint8_t>(hex_digit(ep[2]) * 16 + hex_digit(ep[3]));
  for (std::size_t i = 0; i < n; ++i) {
    const int hi = hex_digit(hex[2 * i]), lo = hex_digit(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) throw std::invalid_argument("not a capture record: '" + line + "'");
    r.data.push_back(static_cast<std::uint8_t>(hi * 16 + lo));
  }
  return r;
}

}  // namespace vmh::hw::usb
