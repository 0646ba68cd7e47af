// libFuzzer harness: the USB Touch's pure parsers (hw/usb/usb_descriptors.h).
//
// The first byte picks the parser (modulo 3; the seeds use '\0', '1' and
// '2'), the rest is its input:
//  0  parse_usb_descriptors on the raw bytes. The harness walks the bytes
//     itself, independently, by the layouts of USB 2.0 chapter 9 as the
//     header describes them (an 18-byte device descriptor, then
//     configurations of wTotalLength bytes, each a chain of descriptors of
//     bLength >= 2; interfaces >= 9 bytes, endpoints >= 7 bytes and after an
//     interface; anything else skipped). Checks: the parser accepts exactly
//     the inputs the walk finds well-formed, and refuses the others with
//     std::invalid_argument "USB descriptors: at byte N: ..." with N within
//     the input; an accepted result has the walk's number of configurations,
//     interfaces and endpoints, every field equal to its bytes, direction
//     and transfer type from the documented sets and matching the bits,
//     wMaxPacketSize within 11 bits, max power 2 mA × bMaxPower;
//     find_data_interface returns one of the configuration's own alternate-0
//     interfaces, and capture_endpoints only bulk or interrupt IN endpoints.
//  1  parse_bus_address on the bytes as text (a leading "usb:" stripped, as
//     cli/hw_usb.cc does). Accepted: bus and address in 1..255, and
//     "BUS-ADDR" and usbfs_path's "/dev/bus/usb/BBB/DDD" spell them back to
//     the same value. Refused: UsbUsageError (nothing else) naming the text
//     (up to a NUL: what() is a C string).
//  2  parse_capture_record on the bytes as one line. nullopt exactly for an
//     empty line or a comment ('#' first). Accepted: finite t_s; the
//     endpoint and the byte count are the line's second and third fields;
//     format_capture_record writes the record back as a line that parses to
//     the same endpoint and bytes and to t_s within its 6 decimals.
//     Refused: std::invalid_argument (nothing else) quoting the line.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hw/usb/usb_descriptors.h"
#include "tests/fuzz/fuzz_check.h"

namespace {

using namespace vmh::hw::usb;

// ---- descriptors ----

struct WalkEp {
  std::size_t at;  // offset of the endpoint descriptor
};
struct WalkIntf {
  std::size_t at;
  std::vector<WalkEp> endpoints;
};
struct WalkConfig {
  std::size_t at;
  std::vector<WalkIntf> interfaces;
};

// the independent walk: nullopt when the bytes are not well-formed
std::optional<std::vector<WalkConfig>> walk(const std::uint8_t* d,
                                            std::size_t n) {
  if (n < 18 || d[0] != 18 || d[1] != 0x01) return std::nullopt;
  std::vector<WalkConfig> configs;
  std::size_t at = 18;
  while (at < n) {
    if (at + 9 > n) return std::nullopt;
    const std::size_t blen = d[at];
    const std::size_t total = d[at + 2] | (d[at + 3] << 8);
    if (blen < 9 || d[at + 1] != 0x02) return std::nullopt;
    if (total < blen || at + total > n) return std::nullopt;
    WalkConfig c{at, {}};
    for (std::size_t p = at + blen; p < at + total;) {
      const std::size_t len = d[p];
      if (len < 2 || p + len > at + total) return std::nullopt;
      const std::uint8_t type = d[p + 1];
      if (type == 0x04) {
        if (len < 9) return std::nullopt;
        c.interfaces.push_back(WalkIntf{p, {}});
      } else if (type == 0x05) {
        if (len < 7 || c.interfaces.empty()) return std::nullopt;
        c.interfaces.back().endpoints.push_back(WalkEp{p});
      }
      p += len;
    }
    configs.push_back(std::move(c));
    at += total;
  }
  return configs;
}

std::size_t le16(const std::uint8_t* p) { return p[0] | (p[1] << 8); }

void check_descriptors(const std::uint8_t* d, std::size_t n) {
  const auto want = walk(d, n);
  UsbDescriptors got;
  try {
    got = parse_usb_descriptors(d, n);
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    FUZZ_CHECK(!want, "well-formed descriptors refused: " + msg);
    const std::string prefix = "USB descriptors: at byte ";
    FUZZ_CHECK(msg.rfind(prefix, 0) == 0, "refusal without the prefix: " + msg);
    const std::size_t offset =
        std::strtoull(msg.c_str() + prefix.size(), nullptr, 10);
    FUZZ_CHECK(offset <= n, "refusal names byte " + std::to_string(offset) +
                                " of " + std::to_string(n));
    return;
  }
  FUZZ_CHECK(want.has_value(),
             "malformed descriptors accepted (" + std::to_string(n) + " bytes)");

  const UsbDeviceDescriptor& dev = got.device;
  FUZZ_CHECK(dev.bcd_usb == le16(d + 2) && dev.device_class == d[4] &&
                 dev.device_subclass == d[5] && dev.device_protocol == d[6] &&
                 dev.max_packet_size0 == d[7] && dev.vendor_id == le16(d + 8) &&
                 dev.product_id == le16(d + 10) &&
                 dev.bcd_device == le16(d + 12) &&
                 dev.manufacturer_index == d[14] && dev.product_index == d[15] &&
                 dev.serial_index == d[16] && dev.num_configurations == d[17],
             "device descriptor fields differ from its bytes");

  FUZZ_CHECK(got.configurations.size() == want->size(),
             "configurations: parsed " +
                 std::to_string(got.configurations.size()) + ", walked " +
                 std::to_string(want->size()));
  for (std::size_t ci = 0; ci < want->size(); ++ci) {
    const UsbConfiguration& gc = got.configurations[ci];
    const WalkConfig& wc = (*want)[ci];
    const std::uint8_t* c = d + wc.at;
    const std::string where = "configuration " + std::to_string(ci);
    FUZZ_CHECK(gc.value == c[5] && gc.attributes == c[7] &&
                   gc.max_power_mA == 2 * c[8] && gc.max_power_mA <= 510,
               where + ": fields differ from its bytes");
    FUZZ_CHECK(gc.interfaces.size() == wc.interfaces.size(),
               where + ": interface count");
    for (std::size_t ii = 0; ii < wc.interfaces.size(); ++ii) {
      const UsbInterface& gi = gc.interfaces[ii];
      const WalkIntf& wi = wc.interfaces[ii];
      const std::uint8_t* q = d + wi.at;
      const std::string iwhere = where + " interface " + std::to_string(ii);
      FUZZ_CHECK(gi.number == q[2] && gi.alt_setting == q[3] &&
                     gi.interface_class == q[5] &&
                     gi.interface_subclass == q[6] &&
                     gi.interface_protocol == q[7] && gi.string_index == q[8],
                 iwhere + ": fields differ from its bytes");
      FUZZ_CHECK(gi.endpoints.size() == wi.endpoints.size(),
                 iwhere + ": endpoint count");
      for (std::size_t ei = 0; ei < wi.endpoints.size(); ++ei) {
        const UsbEndpoint& ge = gi.endpoints[ei];
        const std::uint8_t* e = d + wi.endpoints[ei].at;
        static const char* const kTypes[] = {"control", "isochronous", "bulk",
                                             "interrupt"};
        FUZZ_CHECK(ge.address == e[2] &&
                       ge.direction == ((e[2] & 0x80) ? "in" : "out") &&
                       ge.transfer_type == kTypes[e[3] & 0x03] &&
                       ge.max_packet_size == (le16(e + 4) & 0x07ff) &&
                       ge.max_packet_size <= 0x07ff && ge.interval == e[6],
                   iwhere + " endpoint " + std::to_string(ei) +
                       ": fields differ from its bytes");
      }
      for (const UsbEndpoint& ce : capture_endpoints(gi)) {
        FUZZ_CHECK(ce.direction == "in" && (ce.transfer_type == "bulk" ||
                                            ce.transfer_type == "interrupt"),
                   iwhere + ": capture endpoint not bulk or interrupt IN");
      }
    }
    const UsbInterface* data = find_data_interface(gc);
    if (data != nullptr) {
      FUZZ_CHECK(data >= gc.interfaces.data() &&
                     data < gc.interfaces.data() + gc.interfaces.size(),
                 where + ": data interface not one of its own");
      FUZZ_CHECK(data->alt_setting == 0,
                 where + ": data interface not alternate setting 0");
    }
  }
}

// ---- bus address ----

// what() is a C string: a message quoting text with a NUL in it ends there
// (argv cannot hold one; a capture file could)
std::string until_nul(const std::string& s) { return s.substr(0, s.find('\0')); }

void check_bus_address(const std::string& arg) {
  // as cli/hw_usb.cc: the text after "usb:"
  const std::string text = arg.rfind("usb:", 0) == 0 ? arg.substr(4) : arg;
  BusAddress w;
  try {
    w = parse_bus_address(text);
  } catch (const UsbUsageError& e) {
    const std::string msg = e.what();
    FUZZ_CHECK(msg.find(until_nul("usb:" + text)) != std::string::npos,
               "refusal does not name the text: " + msg);
    return;
  }
  FUZZ_CHECK(w.bus >= 1 && w.bus <= 255 && w.address >= 1 && w.address <= 255,
             "'" + text + "' accepted as bus " + std::to_string(w.bus) +
                 " address " + std::to_string(w.address));
  const BusAddress again = parse_bus_address(std::to_string(w.bus) + "-" +
                                             std::to_string(w.address));
  FUZZ_CHECK(again.bus == w.bus && again.address == w.address,
             "BUS-ADDR does not read back: '" + text + "'");
  char want[40];
  std::snprintf(want, sizeof want, "/dev/bus/usb/%03d/%03d", w.bus, w.address);
  const std::string path = usbfs_path(w);
  FUZZ_CHECK(path == want, "usbfs path " + path);
  // its last two folders are BBB and DDD, which parse_bus_address takes too
  const BusAddress from_path =
      parse_bus_address(path.substr(13, 3) + "-" + path.substr(17, 3));
  FUZZ_CHECK(from_path.bus == w.bus && from_path.address == w.address,
             "usbfs path does not read back: " + path);
}

// ---- capture record ----

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (std::isspace(static_cast<unsigned char>(c))) {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

void check_capture_record(const std::string& line) {
  std::optional<CaptureRecord> r;
  try {
    r = parse_capture_record(line);
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    FUZZ_CHECK(!line.empty() && line[0] != '#', "comment line refused");
    FUZZ_CHECK(msg.find(until_nul(line)) != std::string::npos,
               "refusal does not quote the line: " + msg);
    return;
  }
  const bool comment = line.empty() || line[0] == '#';
  FUZZ_CHECK(comment == !r.has_value(),
             comment ? "comment read as a record" : "record read as nothing");
  if (!r) return;

  FUZZ_CHECK(std::isfinite(r->t_s), "non-finite t_s accepted");
  const std::vector<std::string> f = fields(line);
  FUZZ_CHECK(f.size() == 3 || f.size() == 4, "record of " +
                                                 std::to_string(f.size()) +
                                                 " fields accepted");
  FUZZ_CHECK(f[1].size() == 4 &&
                 std::strtoul(f[1].c_str() + 2, nullptr, 16) == r->endpoint,
             "endpoint is not the second field");
  // leading zeros are read (strtoull), the digits after them fit 64 bits
  const std::size_t lead = std::min(f[2].find_first_not_of('0'), f[2].size());
  FUZZ_CHECK(!f[2].empty() && f[2].size() - lead <= 20 &&
                 f[2].find_first_not_of("0123456789") == std::string::npos &&
                 std::strtoull(f[2].c_str(), nullptr, 10) == r->data.size(),
             "byte count is not the third field");
  FUZZ_CHECK(r->data.size() * 2 == (f.size() == 4 ? f[3].size() : 0),
             "byte count does not match the hex");

  std::string out =
      format_capture_record(r->t_s, r->endpoint, r->data.data(), r->data.size());
  FUZZ_CHECK(!out.empty() && out.back() == '\n', "written record not a line");
  out.pop_back();
  std::optional<CaptureRecord> back;
  try {
    back = parse_capture_record(out);
  } catch (const std::invalid_argument& e) {
    FUZZ_CHECK(false, "written record refused: " + std::string(e.what()));
  }
  FUZZ_CHECK(back.has_value(), "written record read as a comment: " + out);
  FUZZ_CHECK(back->endpoint == r->endpoint && back->data == r->data,
             "written record does not read back: " + out);
  FUZZ_CHECK(std::fabs(back->t_s - r->t_s) <=
                 5.0000001e-7 + 1e-15 * std::fabs(r->t_s),
             "t_s does not read back within 6 decimals: " + out);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data,
                                      std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t* rest = data + 1;
  const std::size_t n = size - 1;
  switch (data[0] % 3) {
    case 0: check_descriptors(rest, n); break;
    case 1:
      check_bus_address(std::string(reinterpret_cast<const char*>(rest), n));
      break;
    default:
      check_capture_record(std::string(reinterpret_cast<const char*>(rest), n));
      break;
  }
  return 0;
}
