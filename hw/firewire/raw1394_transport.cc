// The FireWire Omni's bus through libraw1394 (raw1394_transport.h says the
// sequences; docs/sources.md §9.2 where each step comes from). The
// libraw1394 calls are as its header documents them (raw1394.h, 2.1.2).
#include "hw/firewire/raw1394_transport.h"

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include "device/device_backend.h"
#include "hw/firewire/raw1394_library.h"

namespace vmh::hw::fw {

namespace {

using r1394::Api;
using r1394::Handle;
using r1394::NodeAddr;
using r1394::NodeId;
using r1394::Quadlet;

std::string errno_text(int e) { return std::strerror(e); }

double now_s() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void sleep_s(double s) noexcept {
  if (!(s > 0.0)) return;
  timespec ts{};
  ts.tv_sec = static_cast<std::time_t>(s);
  ts.tv_nsec = static_cast<long>((s - static_cast<double>(ts.tv_sec)) * 1e9);
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

std::uint32_t from_bus(Quadlet q) noexcept {
  // bus data is big-endian: the first byte is the most significant
  unsigned char b[4];
  std::memcpy(b, &q, 4);
  return (static_cast<std::uint32_t>(b[0]) << 24) |
         (static_cast<std::uint32_t>(b[1]) << 16) |
         (static_cast<std::uint32_t>(b[2]) << 8) | b[3];
}

// One register transaction, tried again while it fails with EAGAIN (a busy
// node, a transaction cut by a bus reset, a generation that moved on), at
// most `tries` times in all. phantom-drivers' rev-eng/easy-com.c retries
// without bound; a node that has gone answers EAGAIN for ever, hence the
// bound.
template <typename F>
bool with_retries(const Raw1394Options& o, std::atomic<std::uint64_t>* retries,
                  F&& transaction) noexcept {
  for (int i = 0;; ++i) {
    errno = 0;
    if (transaction() == 0) return true;
    if (errno != EAGAIN || i + 1 >= o.eagain_tries) return false;
    if (retries != nullptr) retries->fetch_add(1, std::memory_order_relaxed);
    sleep_s(o.eagain_delay_s);
  }
}

bool read_quadlet_on(const Api& a, Handle h, const Raw1394Options& o,
                     std::atomic<std::uint64_t>* retries, NodeId node,
                     NodeAddr addr, std::uint32_t* out) noexcept {
  Quadlet q = 0;
  if (!with_retries(o, retries, [&] { return a.read(h, node, addr, 4, &q); })) {
    return false;
  }
  *out = from_bus(q);
  return true;
}

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

// no port: say why in one line
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

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", static_cast<unsigned>(v));
  return buf;
}

struct PortScan {
  int ports = 0;
  int nodes = 0;  // remote nodes looked at
  std::vector<NodeInfo> omnis;
  // SensAble's OUI in the vendor quadlet, but not the whole quadlet the
  // drivers know: "port 0 node 2: 0x000b9901"
  std::vector<std::string> other_sensable;
  std::string error;  // a port that could not be opened
};

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

}  // namespace

void Raw1394Options::validate() const {
  if (eagain_tries < 1 || eagain_tries > 1000) {
    throw std::invalid_argument("Raw1394Options: eagain_tries must be in "
                                "[1, 1000], is " + std::to_string(eagain_tries));
  }
  if (!std::isfinite(eagain_delay_s) || eagain_delay_s < 0.0 ||
      eagain_delay_s > 1.0) {
    throw std::invalid_argument("Raw1394Options: eagain_delay_s must be in "
                                "[0, 1] s, is " + std::to_string(eagain_delay_s));
  }
  if (!std::isfinite(late_after_s) || late_after_s <= 0.0 || late_after_s > 0.5) {
    throw std::invalid_argument("Raw1394Options: late_after_s must be in "
                                "(0, 0.5] s, is " + std::to_string(late_after_s));
  }
}

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
    PortScan s = scan(lib->api(), options);
    if (why_not != nullptr) {
      if (!s.omnis.empty()) {
        why_not->clear();
      } else if (!s.error.empty() && s.ports == 0) {
        *why_not = "firewire: " + s.error;
      } else if (s.ports <= 0) {
        *why_not = no_adapter_message();
      } else {
        *why_not = not_found_message(s, 0);
      }
    }
    return s.omnis;
  } catch (const std::exception& e) {  // bad_alloc and the like
    if (why_not != nullptr) *why_not = std::string("firewire: ") + e.what();
    return {};
  }
}

// -- the transport --

struct Raw1394Transport::Handles {
  Handle ctrl = nullptr;  // registers, bus-reset events
  Handle rx = nullptr;    // iso receive
  Handle tx = nullptr;    // iso transmit
};

// libraw1394's callbacks are plain C functions that get only the handle:
// they find their transport in this table (three handles a transport, a
// few transports a process), which is written when a transport opens or
// closes its handles and read without a lock.
namespace {
struct HandleSlot {
  std::atomic<Handle> handle{nullptr};
  std::atomic<Raw1394Transport*> owner{nullptr};
};
constexpr int kHandleSlots = 48;
HandleSlot g_handles[kHandleSlots];

void register_handle(Handle h, Raw1394Transport* t) {
  for (HandleSlot& s : g_handles) {
    Handle expected = nullptr;
    if (s.handle.compare_exchange_strong(expected, h)) {
      s.owner.store(t, std::memory_order_release);
      return;
    }
  }
  throw DeviceOpenError("firewire: more than 16 FireWire transports open in "
                        "one process");
}
void unregister_handle(Handle h) noexcept {
  for (HandleSlot& s : g_handles) {
    if (s.handle.load(std::memory_order_acquire) == h) {
      s.owner.store(nullptr, std::memory_order_release);
      s.handle.store(nullptr, std::memory_order_release);
    }
  }
}
Raw1394Transport* owner_of(Handle h) noexcept {
  for (HandleSlot& s : g_handles) {
    if (s.handle.load(std::memory_order_acquire) == h) {
      return s.owner.load(std::memory_order_acquire);
    }
  }
  return nullptr;
}
}  // namespace

struct Raw1394Callbacks {
  static int bus_reset(Handle h, unsigned int generation) {
    Raw1394Transport* t = owner_of(h);
    if (t != nullptr) {
      t->api_->update_generation(h, generation);
      t->reset_pending_ = true;
    }
    return 0;
  }
  static r1394::Disposition received(Handle h, unsigned char* data,
                                     unsigned int len, unsigned char,
                                     unsigned char, unsigned char,
                                     unsigned int cycle, unsigned int) {
    Raw1394Transport* t = owner_of(h);
    if (t != nullptr) t->on_packet(data, len, cycle);
    return r1394::kIsoOk;
  }
  static r1394::Disposition transmit(Handle h, unsigned char* data,
                                     unsigned int* len, unsigned char* tag,
                                     unsigned char* sy, int, unsigned int) {
    Raw1394Transport* t = owner_of(h);
    if (t != nullptr) {
      std::memcpy(data, t->tx_packet_.data(), kCommandPacketBytes);
      ++t->tx_refills_;
    } else {
      CommandPacket zero;  // motors off
      encode_command(zero, data);
    }
    *len = static_cast<unsigned int>(kCommandPacketBytes);
    *tag = 0;
    *sy = 0;
    return r1394::kIsoOk;
  }
};

void Raw1394Transport::on_packet(const unsigned char* data, unsigned int len,
                                 unsigned int cycle) noexcept {
  received_.fetch_add(1, std::memory_order_relaxed);
  if (len != kStatePacketBytes) {
    rx_bad_ = true;
    rx_bad_size_ = len;
    bad_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  std::memcpy(rx_packet_.data(), data, kStatePacketBytes);
  if (batch_ < batch_cycles_.size()) {
    batch_cycles_[batch_] = static_cast<std::uint16_t>(cycle % 8000u);
  }
  ++batch_;
}

Raw1394Transport::Raw1394Transport(const Raw1394Options& options)
    : options_(options) {
  options_.validate();
  lib_ = Raw1394Library::load(options_.library);  // DeviceOpenError
  api_ = &lib_->api();
  late_cycles_ = static_cast<unsigned>(
      std::max(1.0, std::round(options_.late_after_s * kIsoCyclesPerSecond)));

  PortScan s = scan(*api_, options_);
  if (s.ports <= 0) {
    throw DeviceOpenError(s.error.empty() || s.ports == 0
                              ? no_adapter_message()
                              : "firewire: " + s.error);
  }
  const NodeInfo* pick = nullptr;
  for (const auto& n : s.omnis) {
    if (options_.guid == 0 || n.guid == options_.guid) {
      pick = &n;
      break;
    }
  }
  if (pick == nullptr) throw DeviceOpenError(not_found_message(s, options_.guid));
  node_ = *pick;
  if (const auto paren = node_.description.find(" ("); paren != std::string::npos) {
    port_name_ = node_.description.substr(paren);
  }

  h_ = new Handles;
  Handle* all[3] = {&h_->ctrl, &h_->rx, &h_->tx};
  for (Handle* p : all) {
    *p = api_->new_handle_on_port(node_.port);
    if (*p == nullptr) {
      const int e = errno;
      close_handles();
      throw DeviceOpenError("firewire: cannot open a libraw1394 handle on "
                            "port " + std::to_string(node_.port) + " (" +
                            errno_text(e) + ")");
    }
    try {
      register_handle(*p, this);
    } catch (...) {
      api_->destroy_handle(*p);
      *p = nullptr;
      close_handles();
      throw;
    }
    api_->set_userdata(*p, this);
  }
  api_->set_bus_reset_handler(h_->ctrl, &Raw1394Callbacks::bus_reset);
  api_->busreset_notify(h_->ctrl, r1394::kNotifyOn);
  // the first packet the transmit context sends: zero words, motors off
  encode_command(CommandPacket{}, tx_packet_.data());
}

Raw1394Transport::~Raw1394Transport() {
  stop();
  close_handles();
}

NodeInfo Raw1394Transport::node() const {
  NodeInfo n = node_;
  n.description = "port " + std::to_string(n.port) + ", node " +
                  std::to_string(n.node) + ", GUID " + guid_text(n.guid) +
                  port_name_;
  return n;
}

const std::string& Raw1394Transport::library_file() const noexcept {
  return lib_->file();
}

void Raw1394Transport::close_handles() noexcept {
  if (h_ == nullptr) return;
  for (Handle h : {h_->tx, h_->rx, h_->ctrl}) {
    if (h == nullptr) continue;
    api_->destroy_handle(h);
    unregister_handle(h);
  }
  delete h_;
  h_ = nullptr;
}

bool Raw1394Transport::read_quadlet(NodeId node, NodeAddr addr,
                                    std::uint32_t* out) noexcept {
  return read_quadlet_on(*api_, h_->ctrl, options_, &eagain_, node, addr, out);
}

// The Omni's registers at 0x1000..0x1087 are read and written one byte at
// a time (block transactions of length 1, as all three drivers do); the
// byte is the first of the buffer.
bool Raw1394Transport::read_byte(NodeAddr addr, std::uint8_t* out) noexcept {
  const auto id = static_cast<NodeId>(r1394::kLocalBus | node_.node);
  Quadlet q = 0;
  if (!with_retries(options_, &eagain_,
                    [&] { return api_->read(h_->ctrl, id, addr, 1, &q); })) {
    return false;
  }
  std::memcpy(out, &q, 1);
  return true;
}

bool Raw1394Transport::write_bytes(NodeAddr addr, const std::uint8_t* v,
                                   std::size_t n) noexcept {
  const auto id = static_cast<NodeId>(r1394::kLocalBus | node_.node);
  Quadlet q = 0;
  std::memcpy(&q, v, n);
  return with_retries(options_, &eagain_,
                      [&] { return api_->write(h_->ctrl, id, addr, n, &q); });
}

bool Raw1394Transport::write_byte(NodeAddr addr, std::uint8_t v) noexcept {
  return write_bytes(addr, &v, 1);
}

const char* Raw1394Transport::claim_channels() noexcept {
  // two free channels at the isochronous resource manager; after a bus
  // reset (which frees every allocation) the same ones again if free
  if (channels_claimed_) {
    bool same = true;
    for (const int ch : {tx_channel_, rx_channel_}) {
      if (api_->channel_modify(h_->ctrl, static_cast<unsigned>(ch),
                               r1394::kModifyAlloc) != 0) {
        same = false;
      }
    }
    if (same) return nullptr;
    // taken meanwhile: new channels, and the contexts restarted on them
    release_channels();
    shutdown_iso();
    if (const char* e = claim_channels()) return e;
    return start_iso();
  }
  tx_channel_ = rx_channel_ = -1;
  for (int ch = 0; ch < 64 && rx_channel_ < 0; ++ch) {
    if (api_->channel_modify(h_->ctrl, static_cast<unsigned>(ch),
                             r1394::kModifyAlloc) != 0) {
      continue;
    }
    (tx_channel_ < 0 ? tx_channel_ : rx_channel_) = ch;
  }
  if (rx_channel_ < 0) {
    release_channels();
    return "no two free isochronous channels at the bus's resource manager "
           "(raw1394_channel_modify)";
  }
  channels_claimed_ = true;
  record_.tx_channel = tx_channel_;
  record_.rx_channel = rx_channel_;
  return nullptr;
}

void Raw1394Transport::release_channels() noexcept {
  for (const int ch : {tx_channel_, rx_channel_}) {
    if (ch >= 0) {
      api_->channel_modify(h_->ctrl, static_cast<unsigned>(ch),
                           r1394::kModifyFree);
    }
  }
  tx_channel_ = rx_channel_ = -1;
  channels_claimed_ = false;
}

const char* Raw1394Transport::start_iso() noexcept {
  if (api_->iso_recv_init(h_->rx, &Raw1394Callbacks::received,
                          kRxBufferPackets, kRxMaxPacket,
                          static_cast<unsigned char>(rx_channel_),
                          r1394::kDmaPacketPerBuffer, kIsoIrqInterval) != 0) {
    std::snprintf(error_, sizeof error_,
                  "isochronous receive on channel %d (raw1394_iso_recv_init): %s",
                  rx_channel_, std::strerror(errno));
    return error_;
  }
  rx_iso_ = true;
  if (api_->iso_recv_start(h_->rx, -1, -1, 0) != 0) {
    std::snprintf(error_, sizeof error_,
                  "isochronous receive on channel %d (raw1394_iso_recv_start): %s",
                  rx_channel_, std::strerror(errno));
    return error_;
  }
  if (api_->iso_xmit_init(h_->tx, &Raw1394Callbacks::transmit, kTxBufferPackets,
                          static_cast<unsigned>(kCommandPacketBytes),
                          static_cast<unsigned char>(tx_channel_),
                          r1394::kSpeed100, kIsoIrqInterval) != 0) {
    std::snprintf(error_, sizeof error_,
                  "isochronous transmit on channel %d (raw1394_iso_xmit_init): %s",
                  tx_channel_, std::strerror(errno));
    return error_;
  }
  tx_iso_ = true;
  if (api_->iso_xmit_start(h_->tx, -1, -1) != 0) {
    std::snprintf(error_, sizeof error_,
                  "isochronous transmit on channel %d (raw1394_iso_xmit_start): %s",
                  tx_channel_, std::strerror(errno));
    return error_;
  }
  return nullptr;
}

const char* Raw1394Transport::start_registers() noexcept {
  const auto fail = [&](const char* what) {
    std::snprintf(error_, sizeof error_, "%s (%s)", what,
                  errno != 0 ? std::strerror(errno) : "no error code");
    return error_;
  };
  // 1, 2: the channels, one byte each
  if (!write_byte(kRegTxChannel, static_cast<std::uint8_t>(tx_channel_))) {
    return fail("writing the host->device channel to 0x1000 failed");
  }
  if (!write_byte(kRegRxChannel, static_cast<std::uint8_t>(rx_channel_))) {
    return fail("writing the device->host channel to 0x1001 failed");
  }
  // 3: the quadlet of unknown meaning, unless left out
  record_.wrote_20010 = false;
  if (options_.write_20010) {
    if (!write_bytes(kReg20010, k20010Bytes, 4)) {
      return fail("writing 00 00 0f f8 to 0x20010 failed (leave it out with "
                  "firewire:GUID?no-20010)");
    }
    record_.wrote_20010 = true;
  }
  // 4: the channel reads back
  std::uint8_t v = 0;
  if (!read_byte(kRegRxChannel, &v)) return fail("reading 0x1001 back failed");
  if (v != rx_channel_) {
    std::snprintf(error_, sizeof error_,
                  "0x1001 reads back 0x%02x, not the channel %d written (the "
                  "Omni did not take it)",
                  static_cast<unsigned>(v), rx_channel_);
    return error_;
  }
  // 5: the write/read test, then the channel again
  if (!write_byte(kRegRxChannel, kRxChannelTestValue)) {
    return fail("writing the test value 0x40 to 0x1001 failed");
  }
  if (!read_byte(kRegRxChannel, &v)) return fail("reading the test value back failed");
  if (v != kRxChannelTestValue) {
    std::snprintf(error_, sizeof error_,
                  "0x1001 reads 0x%02x after 0x40 was written (the Omni's "
                  "register test failed)",
                  static_cast<unsigned>(v));
    return error_;
  }
  if (!write_byte(kRegRxChannel, static_cast<std::uint8_t>(rx_channel_))) {
    return fail("writing the device->host channel to 0x1001 again failed");
  }
  // 6: ready
  if (!read_byte(kRegStatus1, &v)) return fail("reading 0x1083 failed");
  record_.status1 = v;
  if (v != kStatus1Ready) {
    std::snprintf(error_, sizeof error_,
                  "0x1083 reads 0x%02x, not 0xc0 (the Omni is not ready)",
                  static_cast<unsigned>(v));
    return error_;
  }
  if (!read_byte(kRegStatus2, &v)) return fail("reading 0x1082 failed");
  record_.status2 = v;
  if (v != kStatus2Ready) {
    std::snprintf(error_, sizeof error_,
                  "0x1082 reads 0x%02x, not 0x00 (the Omni is not ready)",
                  static_cast<unsigned>(v));
    return error_;
  }
  // 7: stream, keeping the control register's other bits
  if (!read_byte(kRegControl, &v)) return fail("reading 0x1087 failed");
  record_.control_before = v;
  const auto c = static_cast<std::uint8_t>(v | kControlStream);
  if (!write_byte(kRegControl, c)) return fail("setting bit 3 of 0x1087 (start) failed");
  record_.control_written = c;
  return nullptr;
}

void Raw1394Transport::start() {
  if (started_) return;
  const auto fail = [&](const std::string& what) {
    shutdown_iso();
    release_channels();
    return DeviceOpenError("firewire: start of " + node().description + ": " +
                           what);
  };
  if (const char* e = claim_channels()) throw fail(e);
  batch_ = 0;
  rx_bad_ = reset_pending_ = needs_recovery_ = false;
  encode_command(CommandPacket{}, tx_packet_.data());
  if (const char* e = start_iso()) throw fail(e);
  if (const char* e = start_registers()) throw fail(e);
  ++record_.starts;
  started_ = true;
  fresh_start_ = true;
}

void Raw1394Transport::stop() noexcept {
  if (!started_ || h_ == nullptr) return;
  // The last command (the caller's zero packet) must reach the device
  // before it stops listening: wait until every transmit slot has been
  // refilled with it and one more has gone out, 50 ms at most.
  const std::uint64_t goal = tx_refills_ + kTxBufferPackets + 1;
  const double deadline = now_s() + 0.05;
  while (tx_refills_ < goal && now_s() < deadline) {
    pollfd fd{api_->get_fd(h_->tx), POLLIN, 0};
    timespec ts{0, 1000000};
    if (ppoll(&fd, 1, &ts, nullptr) > 0) drain(h_->tx, 2 * kTxBufferPackets);
  }
  std::uint8_t c = 0;
  if (!needs_recovery_ && read_byte(kRegControl, &c)) {
    write_byte(kRegControl, static_cast<std::uint8_t>(c & ~kControlStream));
  } else {
    write_byte(kRegControl, 0x00);
  }
  shutdown_iso();
  release_channels();
  started_ = false;
  needs_recovery_ = false;
}

void Raw1394Transport::shutdown_iso() noexcept {
  if (h_ == nullptr) return;
  if (rx_iso_) {
    api_->iso_stop(h_->rx);
    api_->iso_shutdown(h_->rx);
    rx_iso_ = false;
  }
  if (tx_iso_) {
    api_->iso_stop(h_->tx);
    api_->iso_shutdown(h_->tx);
    tx_iso_ = false;
  }
}

bool Raw1394Transport::drain(Handle h, int limit) noexcept {
  for (int i = 0; i < limit; ++i) {
    pollfd fd{api_->get_fd(h), POLLIN, 0};
    const timespec zero{0, 0};
    const int n = ppoll(&fd, 1, &zero, nullptr);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if ((fd.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) return false;
    if ((fd.revents & POLLIN) == 0) return true;
    errno = 0;
    if (api_->loop_iterate(h) < 0 && errno != EAGAIN && errno != EINTR) {
      return false;
    }
  }
  return true;
}

TransportStatus Raw1394Transport::wait(double timeout_s) noexcept {
  pollfd fds[2] = {{api_->get_fd(h_->ctrl), POLLIN, 0},
                   {api_->get_fd(h_->rx), POLLIN, 0}};
  timespec ts{0, 0};
  if (timeout_s > 0.0) {
    const auto whole = static_cast<std::time_t>(timeout_s);
    ts.tv_sec = whole;
    ts.tv_nsec = static_cast<long>((timeout_s - static_cast<double>(whole)) * 1e9);
    if (ts.tv_nsec >= 1000000000L) ts.tv_nsec = 999999999L;
  }
  const int n = ppoll(fds, 2, &ts, nullptr);
  if (n < 0) return errno == EINTR ? TransportStatus::kOk : TransportStatus::kIo;
  for (const pollfd& f : fds) {
    if ((f.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
      return TransportStatus::kDisconnected;  // the adapter went away
    }
  }
  return TransportStatus::kOk;
}

TransportStatus Raw1394Transport::receive(std::uint8_t* buf,
                                          std::size_t capacity,
                                          std::size_t* size, double timeout_s,
                                          ReceiveInfo* info) noexcept {
  if (info != nullptr) *info = ReceiveInfo{};
  *size = 0;
  if (!started_) return TransportStatus::kDisconnected;
  if (needs_recovery_) {
    // a recovery failed: try again every so often, quiet in between
    if (++receives_since_recovery_ >= kRecoverEveryReceives) {
      receives_since_recovery_ = 0;
      return TransportStatus::kBusReset;
    }
    return TransportStatus::kDisconnected;
  }
  const double deadline = now_s() + timeout_s;
  for (;;) {
    // every event waiting: bus resets first, then every packet
    if (!drain(h_->ctrl, 16) || !drain(h_->rx, 4 * kRxBufferPackets)) {
      return TransportStatus::kDisconnected;
    }
    if (reset_pending_) {
      // what arrived across the reset is from before it
      reset_pending_ = false;
      needs_recovery_ = true;
      receives_since_recovery_ = 0;
      batch_ = 0;
      rx_bad_ = false;
      resets_.fetch_add(1, std::memory_order_relaxed);
      return TransportStatus::kBusReset;
    }
    if (batch_ >= kRxBufferPackets && fresh_start_) {
      // The first receive after start() or recover() found the receive
      // buffer full: the packets queued before the servo loop's first tick
      // (setting up its thread can take tens of milliseconds), and the
      // newest of them stale, as the ones after it did not fit. Discarded;
      // the next packet is the loop's first.
      stale_.fetch_add(batch_, std::memory_order_relaxed);
      batch_ = 0;
      rx_bad_ = false;
      fresh_start_ = false;
      continue;
    }
    if (batch_ > 0) break;
    if (rx_bad_) {
      rx_bad_ = false;
      *size = rx_bad_size_;
      return TransportStatus::kBadPacket;
    }
    const double left = deadline - now_s();
    if (left <= 0.0) {
      timeouts_.fetch_add(1, std::memory_order_relaxed);
      return TransportStatus::kTimeout;
    }
    const TransportStatus s = wait(left);
    if (s != TransportStatus::kOk) return s;
  }

  // the newest packet; the others of the batch superseded, some late
  const std::uint32_t n = batch_;
  const std::size_t kept = n < batch_cycles_.size() ? n : batch_cycles_.size();
  const unsigned newest = batch_cycles_[kept - 1];
  std::uint32_t late = 0;
  if (!fresh_start_) {
    // (the first batch after a start came before any receive: none late)
    late = static_cast<std::uint32_t>(n - kept);  // beyond the record
    for (std::size_t i = 0; i + 1 < kept; ++i) {
      const unsigned age = (newest + 8000u - batch_cycles_[i]) % 8000u;
      if (age >= late_cycles_) ++late;
    }
  }
  fresh_start_ = false;
  batch_ = 0;
  rx_bad_ = false;
  if (capacity < kStatePacketBytes) return TransportStatus::kIo;
  std::memcpy(buf, rx_packet_.data(), kStatePacketBytes);
  *size = kStatePacketBytes;
  delivered_.fetch_add(1, std::memory_order_relaxed);
  superseded_.fetch_add(n - 1, std::memory_order_relaxed);
  late_.fetch_add(late, std::memory_order_relaxed);
  if (info != nullptr) {
    info->packets = n;
    info->late = late;
  }
  return TransportStatus::kOk;
}

TransportStatus Raw1394Transport::send(const std::uint8_t* data,
                                       std::size_t size) noexcept {
  if (!started_) return TransportStatus::kDisconnected;
  if (data == nullptr || size != kCommandPacketBytes) {
    return TransportStatus::kBadPacket;
  }
  std::memcpy(tx_packet_.data(), data, kCommandPacketBytes);
  sent_.fetch_add(1, std::memory_order_relaxed);
  // every slot the device has used since is refilled with this command
  if (!drain(h_->tx, 4 * kTxBufferPackets)) return TransportStatus::kDisconnected;
  if (needs_recovery_) return TransportStatus::kDisconnected;
  return TransportStatus::kOk;
}

bool Raw1394Transport::find_node_again() noexcept {
  const int count = api_->get_nodecount(h_->ctrl);
  const int local = api_->get_local_id(h_->ctrl) & 0x3f;
  for (int n = 0; n < count; ++n) {
    if (n == local) continue;
    const auto id = static_cast<NodeId>(r1394::kLocalBus | n);
    std::uint32_t hi = 0, lo = 0, vendor = 0;
    if (!read_quadlet(id, r1394::kConfigRomGuidHi, &hi) ||
        !read_quadlet(id, r1394::kConfigRomGuidLo, &lo)) {
      continue;
    }
    if (((static_cast<std::uint64_t>(hi) << 32) | lo) != node_.guid) continue;
    if (!read_quadlet(id, kRegVendorId, &vendor) || vendor != kVendorQuadletOmni) {
      return false;  // the GUID, but not an Omni's answer
    }
    node_.node = n;  // node() writes the description again
    node_.generation = api_->get_generation(h_->ctrl);
    return true;
  }
  return false;
}

TransportStatus Raw1394Transport::recover() noexcept {
  if (h_ == nullptr || !started_) return TransportStatus::kDisconnected;
  reset_pending_ = false;
  needs_recovery_ = true;
  receives_since_recovery_ = 0;
  batch_ = 0;
  rx_bad_ = false;
  // a further reset may be waiting: take its generation first
  if (!drain(h_->ctrl, 16)) return TransportStatus::kDisconnected;
  reset_pending_ = false;
  if (!find_node_again()) return TransportStatus::kDisconnected;
  if (claim_channels() != nullptr) return TransportStatus::kIo;
  if (start_registers() != nullptr) return TransportStatus::kIo;
  // packets that came before the device was set up again are not its new
  // stream's
  drain(h_->rx, 4 * kRxBufferPackets);
  batch_ = 0;
  rx_bad_ = false;
  needs_recovery_ = false;
  fresh_start_ = true;
  ++record_.starts;
  recoveries_.fetch_add(1, std::memory_order_relaxed);
  return TransportStatus::kOk;
}

TransportStats Raw1394Transport::stats() const noexcept {
  TransportStats s;
  s.received = received_.load(std::memory_order_relaxed);
  s.delivered = delivered_.load(std::memory_order_relaxed);
  s.superseded = superseded_.load(std::memory_order_relaxed);
  s.late = late_.load(std::memory_order_relaxed);
  s.sent = sent_.load(std::memory_order_relaxed);
  s.bad_packets = bad_.load(std::memory_order_relaxed);
  s.timeouts = timeouts_.load(std::memory_order_relaxed);
  s.bus_resets = resets_.load(std::memory_order_relaxed);
  s.recoveries = recoveries_.load(std::memory_order_relaxed);
  s.eagain_retries = eagain_.load(std::memory_order_relaxed);
  s.stale_at_start = stale_.load(std::memory_order_relaxed);
  return s;
}

}  // namespace vmh::hw::fw
