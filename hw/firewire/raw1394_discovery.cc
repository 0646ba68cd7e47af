// Finding the FireWire Omnis (raw1394_transport.h says how): every node of
// every port asked for its vendor quadlet, an Omni's GUID and serial read,
// and when none is found the one-line cause (no adapter, no permission on
// /dev/fw*, no Omni, no Omni with that GUID); the GUID and the serial as
// text. The libraw1394 calls are as its header documents them (raw1394.h,
// 2.1.2).
#include <dirent.h>
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "device/device_backend.h"
#include "hw/firewire/raw1394_library.h"
#include "hw/firewire/raw1394_transport.h"
#include "hw/firewire/raw1394_transport_detail.h"

namespace vmh::hw::fw {

namespace {

using detail::errno_text;
using detail::PortScan;
using detail::read_quadlet_on;
using r1394::Api;
using r1394::Handle;
using r1394::NodeId;

// What /dev/fw* says about access, for the messages: how many device nodes
// exist and which of them cannot be opened for lack of permission.
struct DevFwAccess {
  int present = 0;
  std::vector<std::string> denied;
};
DevFwAccess dev_fw_access() {
  DevFwAccess a;
  DIR* d = opendir("/dev");
  if (d == nullptr) return a;
  while (dirent* e = readdir(d)) {
    const char* n = e->d_name;
    if (std::strncmp(n, "fw", 2) != 0 || n[2] < '0' || n[2] > '9') continue;
    ++a.present;
    const std::string path = std::string("/dev/") + n;
    const int fd = open(path.c_str(), O_RDWR | O_CLOEXEC);
    if (fd >= 0) {
      close(fd);
    } else if (errno == EACCES || errno == EPERM) {
      a.denied.push_back(path);
    }
  }
  closedir(d);
  return a;
}

std::string permission_hint(const DevFwAccess& a) {
  std::string list;
  for (const auto& p : a.denied) list += (list.empty() ? "" : ", ") + p;
  return list + " cannot be opened (permission denied): install " +
         kUdevRulesFile +
         " (copy it to /etc/udev/rules.d/, reload udev, join its group)";
}

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", static_cast<unsigned>(v));
  return buf;
}

// The node's identity if its vendor quadlet is an Omni's, else false.
bool probe_node(const Api& a, Handle h, const Raw1394Options& o, int port,
                int node, PortScan* s, NodeInfo* out) {
  const auto id = static_cast<NodeId>(r1394::kLocalBus | node);
  std::uint32_t vendor = 0;
  if (!read_quadlet_on(a, h, o, nullptr, id, kRegVendorId, &vendor)) return false;
  if (vendor != kVendorQuadletOmni) {
    if ((vendor >> 8) == kVendorSensable) {
      s->other_sensable.push_back("port " + std::to_string(port) + " node " +
                                  std::to_string(node) + ": " + hex32(vendor));
    }
    return false;
  }
  NodeInfo n;
  n.vendor = vendor >> 8;
  std::uint32_t hi = 0, lo = 0;
  if (read_quadlet_on(a, h, o, nullptr, id, r1394::kConfigRomGuidHi, &hi) &&
      read_quadlet_on(a, h, o, nullptr, id, r1394::kConfigRomGuidLo, &lo)) {
    n.guid = (static_cast<std::uint64_t>(hi) << 32) | lo;
  }
  std::uint32_t serial = 0;
  if (read_quadlet_on(a, h, o, nullptr, id, kRegSerial, &serial)) {
    n.serial_quadlet = serial;
    n.serial = serial_text(serial);
  }
  n.port = port;
  n.node = node;
  n.generation = a.get_generation(h);
  n.description = "port " + std::to_string(port) + ", node " +
                  std::to_string(node) + ", GUID " + guid_text(n.guid);
  *out = n;
  return true;
}

}  // namespace

namespace detail {

std::string no_adapter_message() {
  const DevFwAccess a = dev_fw_access();
  if (a.present == 0) {
    return "firewire: no IEEE 1394 adapter found (libraw1394 sees 0 ports and "
           "there is no /dev/fw*; is firewire-ohci loaded?)";
  }
  if (!a.denied.empty()) return "firewire: " + permission_hint(a);
  return "firewire: libraw1394 sees 0 ports although /dev/fw* exists (" +
         std::to_string(a.present) + " node(s)); is firewire-ohci loaded?";
}

PortScan scan(const Api& a, const Raw1394Options& o) {
  PortScan s;
  Handle h = a.new_handle();
  if (h == nullptr) {
    s.error = "raw1394_new_handle failed (" + errno_text(errno) + ")";
    return s;
  }
  s.ports = a.get_port_info(h, nullptr, 0);
  r1394::PortInfo info[16] = {};
  const int named = a.get_port_info(h, info, 16);
  a.destroy_handle(h);
  for (int p = 0; p < s.ports; ++p) {
    if (o.port >= 0 && p != o.port) continue;
    Handle hp = a.new_handle_on_port(p);
    if (hp == nullptr) {
      s.error = "port " + std::to_string(p) + " cannot be opened (" +
                errno_text(errno) + ")";
      continue;
    }
    const int count = a.get_nodecount(hp);
    const int local = a.get_local_id(hp) & 0x3f;
    std::string name;
    if (p < named && p < 16) {
      info[p].name[sizeof info[p].name - 1] = '\0';
      name = info[p].name;
    }
    for (int n = 0; n < count; ++n) {
      if (n == local) continue;
      ++s.nodes;
      NodeInfo found;
      if (probe_node(a, hp, o, p, n, &s, &found)) {
        if (!name.empty()) found.description += " (" + name + ")";
        s.omnis.push_back(found);
      }
    }
    a.destroy_handle(hp);
  }
  return s;
}

std::string not_found_message(const PortScan& s, std::uint64_t guid) {
  std::string what =
      guid != 0 ? "firewire: no PHANTOM Omni with GUID " + guid_text(guid)
                : std::string("firewire: no PHANTOM Omni (vendor quadlet "
                              "0x000b9900)");
  what += " among " + std::to_string(s.nodes) + " node(s) on " +
          std::to_string(s.ports) + " port(s)";
  if (guid != 0 && !s.omnis.empty()) {
    what += "; found";
    for (const auto& n : s.omnis) what += " " + guid_text(n.guid);
  }
  if (!s.other_sensable.empty()) {
    what += "; SensAble nodes whose vendor quadlet is not an Omni's:";
    for (const auto& n : s.other_sensable) what += " " + n;
  }
  const DevFwAccess acc = dev_fw_access();
  if (!acc.denied.empty()) what += "; " + permission_hint(acc);
  if (!s.error.empty()) what += "; " + s.error;
  return what;
}

}  // namespace detail

std::uint64_t parse_guid(const std::string& text) {
  std::string t = text;
  if (t.size() > 2 && t[0] == '0' && (t[1] == 'x' || t[1] == 'X')) {
    t = t.substr(2);
  }
  if (t.empty() || t.size() > 16) {
    throw std::invalid_argument("firewire: GUID \"" + text +
                                "\" is not 1 to 16 hex digits");
  }
  std::uint64_t v = 0;
  for (const char c : t) {
    int d = -1;
    if (c >= '0' && c <= '9') d = c - '0';
    if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
    if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
    if (d < 0) {
      throw std::invalid_argument("firewire: GUID \"" + text +
                                  "\" is not hexadecimal");
    }
    v = (v << 4) | static_cast<std::uint64_t>(d);
  }
  return v;
}

std::string guid_text(std::uint64_t guid) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx",
                static_cast<unsigned long long>(guid));
  return buf;
}

std::string serial_text(std::uint32_t q) {
  // bit 31 and bit 0 set, bits 30..26 clear: the drivers' packing
  if ((q & 0xfc000001u) != 0x80000001u) return hex32(q);
  const unsigned a = (q >> 23) & 0x7u, b = (q >> 19) & 0xfu,
                 c = (q >> 14) & 0x1fu, d = (q >> 11) & 0x7u,
                 e = (q >> 1) & 0x3ffu;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%01u%02u%02u%01u%05u", a, b, c, d, e);
  return buf;
}

std::vector<NodeInfo> list_omni_nodes(std::string* why_not,
                                      const Raw1394Options& options) {
  try {
    std::shared_ptr<const Raw1394Library> lib;
    try {
      lib = Raw1394Library::load(options.library);
    } catch (const DeviceOpenError& e) {
      if (why_not != nullptr) *why_not = e.what();
      return {};
    }
    PortScan s = detail::scan(lib->api(), options);
    if (why_not != nullptr) {
      if (!s.omnis.empty()) {
        why_not->clear();
      } else if (!s.error.empty() && s.ports == 0) {
        *why_not = "firewire: " + s.error;
      } else if (s.ports <= 0) {
        *why_not = detail::no_adapter_message();
      } else {
        *why_not = detail::not_found_message(s, 0);
      }
    }
    return s.omnis;
  } catch (const std::exception& e) {  // bad_alloc and the like
    if (why_not != nullptr) *why_not = std::string("firewire: ") + e.what();
    return {};
  }
}

}  // namespace vmh::hw::fw
