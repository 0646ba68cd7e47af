// The FireWire Omni's bus through libraw1394 (raw1394_transport.h). The
// libraw1394 calls are as its header documents them (raw1394.h, 2.1.2);
// the Omni's registers are from docs/sources.md §9.2.
#include "hw/firewire/raw1394_transport.h"

#include <arpa/inet.h>  // ntohl: bus data is big-endian
#include <dirent.h>
#include <fcntl.h>
#include <libraw1394/csr.h>
#include <libraw1394/raw1394.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include "device/device_backend.h"

namespace vmh::hw::fw {

namespace {

// IEEE 1394 node ids on the local bus: bus 0x3ff ("this bus"), node 0..62
constexpr nodeid_t kLocalBus = 0xffc0;
// the bus information block of the configuration ROM (IEEE 1212): the
// GUID is its quadlets 3 (high) and 4 (low)
constexpr nodeaddr_t kGuidHi = CSR_REGISTER_BASE + CSR_CONFIG_ROM + 0x0c;
constexpr nodeaddr_t kGuidLo = CSR_REGISTER_BASE + CSR_CONFIG_ROM + 0x10;

constexpr unsigned kIsoBufferPackets = 64;  // 8 ms of 8 kHz iso cycles
constexpr unsigned kRxMaxPacket = 64;       // > 44: long packets are seen
constexpr int kIrqInterval = 1;             // wake per packet: latency

std::string errno_text(int e) { return std::strerror(e); }

bool read_quadlet(raw1394handle_t h, nodeid_t node, nodeaddr_t addr,
                  std::uint32_t* out) noexcept {
  quadlet_t q = 0;
  if (raw1394_read(h, node, addr, 4, &q) != 0) return false;
  *out = ntohl(q);
  return true;
}

// The Omni's registers are read and written one byte at a time (§9.2's
// drivers do so); the byte is the first of the buffer.
bool read_byte(raw1394handle_t h, nodeid_t node, nodeaddr_t addr,
               std::uint8_t* out) noexcept {
  quadlet_t q = 0;
  if (raw1394_read(h, node, addr, 1, &q) != 0) return false;
  std::memcpy(out, &q, 1);
  return true;
}
bool write_byte(raw1394handle_t h, nodeid_t node, nodeaddr_t addr,
                std::uint8_t v) noexcept {
  quadlet_t q = 0;
  std::memcpy(&q, &v, 1);
  return raw1394_write(h, node, addr, 1, &q) == 0;
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

std::string port_name(raw1394handle_t h, int port) {
  raw1394_portinfo info[16];
  const int n = raw1394_get_port_info(h, info, 16);
  if (port >= 0 && port < n && port < 16) {
    info[port].name[sizeof info[port].name - 1] = '\0';
    return info[port].name;
  }
  return {};
}

// The node's identity if it is an Omni (the vendor quadlet), else false.
bool probe_node(raw1394handle_t h, int port, int node, NodeInfo* out) {
  const auto id = static_cast<nodeid_t>(kLocalBus | node);
  std::uint32_t vendor = 0;
  if (!read_quadlet(h, id, kRegVendorId, &vendor)) return false;
  if ((vendor & 0x00ffffffu) != kVendorSensable) return false;
  NodeInfo n;
  n.vendor = vendor & 0x00ffffffu;
  std::uint32_t hi = 0, lo = 0;
  if (read_quadlet(h, id, kGuidHi, &hi) && read_quadlet(h, id, kGuidLo, &lo)) {
    n.guid = (static_cast<std::uint64_t>(hi) << 32) | lo;
  }
  std::uint32_t serial = 0;
  if (read_quadlet(h, id, kRegSerial, &serial)) {
    n.serial = std::to_string(serial);  // format unverified (§9.2)
  }
  n.port = port;
  n.node = node;
  n.generation = raw1394_get_generation(h);
  n.description = "port " + std::to_string(port) + ", node " +
                  std::to_string(node) + ", GUID " + guid_text(n.guid);
  *out = n;
  return true;
}

struct PortScan {
  int ports = 0;
  int nodes = 0;  // remote nodes looked at
  std::vector<NodeInfo> omnis;
  std::string error;  // a port that could not be opened
};

PortScan scan(int only_port) {
  PortScan s;
  raw1394handle_t h = raw1394_new_handle();
  if (h == nullptr) {
    s.error = "raw1394_new_handle failed (" + errno_text(errno) + ")";
    return s;
  }
  s.ports = raw1394_get_port_info(h, nullptr, 0);
  raw1394_destroy_handle(h);
  for (int p = 0; p < s.ports; ++p) {
    if (only_port >= 0 && p != only_port) continue;
    raw1394handle_t hp = raw1394_new_handle_on_port(p);
    if (hp == nullptr) {
      s.error = "port " + std::to_string(p) + " cannot be opened (" +
                errno_text(errno) + ")";
      continue;
    }
    const int count = raw1394_get_nodecount(hp);
    const int local = raw1394_get_local_id(hp) & 0x3f;
    const std::string name = port_name(hp, p);
    for (int n = 0; n < count; ++n) {
      if (n == local) continue;
      ++s.nodes;
      NodeInfo info;
      if (probe_node(hp, p, n, &info)) {
        if (!name.empty()) info.description += " (" + name + ")";
        s.omnis.push_back(info);
      }
    }
    raw1394_destroy_handle(hp);
  }
  return s;
}

double now_s() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

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

std::vector<NodeInfo> list_omni_nodes(std::string* why_not) {
  try {
    PortScan s = scan(-1);
    if (why_not != nullptr) {
      if (!s.omnis.empty()) {
        why_not->clear();
      } else if (!s.error.empty() && s.ports == 0) {
        *why_not = "firewire: " + s.error;
      } else if (s.ports <= 0) {
        *why_not = no_adapter_message();
      } else {
        std::string w = "firewire: no PHANTOM Omni (vendor 0x000b99) among " +
                        std::to_string(s.nodes) + " node(s) on " +
                        std::to_string(s.ports) + " port(s)";
        const DevFwAccess a = dev_fw_access();
        if (!a.denied.empty()) w += "; " + permission_hint(a);
        if (!s.error.empty()) w += "; " + s.error;
        *why_not = w;
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
  raw1394handle_t ctrl = nullptr;  // registers, bus-reset events
  raw1394handle_t rx = nullptr;    // iso receive
  raw1394handle_t tx = nullptr;    // iso transmit
};

// libraw1394's callbacks, with access to the transport (its userdata)
struct Raw1394Callbacks {
  static Raw1394Transport* self(raw1394handle_t h) noexcept {
    return static_cast<Raw1394Transport*>(raw1394_get_userdata(h));
  }
  static int bus_reset(raw1394handle_t h, unsigned int generation) {
    raw1394_update_generation(h, generation);
    self(h)->reset_pending_ = true;
    return 0;
  }
  static raw1394_iso_disposition received(raw1394handle_t h,
                                          unsigned char* data,
                                          unsigned int len, unsigned char,
                                          unsigned char, unsigned char,
                                          unsigned int, unsigned int) {
    Raw1394Transport* t = self(h);
    if (len == kStatePacketBytes) {
      std::memcpy(t->rx_packet_.data(), data, kStatePacketBytes);
      t->rx_fresh_ = true;
      t->rx_bad_ = false;
    } else {
      t->rx_bad_ = true;
      t->rx_size_ = len;
    }
    return RAW1394_ISO_OK;
  }
  static raw1394_iso_disposition transmit(raw1394handle_t h,
                                          unsigned char* data,
                                          unsigned int* len,
                                          unsigned char* tag,
                                          unsigned char* sy, int,
                                          unsigned int) {
    Raw1394Transport* t = self(h);
    std::memcpy(data, t->tx_packet_.data(), kCommandPacketBytes);
    *len = static_cast<unsigned int>(kCommandPacketBytes);
    *tag = 0;
    *sy = 0;
    return RAW1394_ISO_OK;
  }
};

Raw1394Transport::Raw1394Transport(const Raw1394Options& options)
    : options_(options) {
  PortScan s = scan(options_.port);
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
  if (pick == nullptr) {
    std::string what =
        options_.guid != 0
            ? "firewire: no PHANTOM Omni with GUID " + guid_text(options_.guid)
            : std::string("firewire: no PHANTOM Omni (vendor 0x000b99)");
    what += " among " + std::to_string(s.nodes) + " node(s) on " +
            std::to_string(s.ports) + " port(s)";
    if (options_.guid != 0 && !s.omnis.empty()) {
      what += "; found";
      for (const auto& n : s.omnis) what += " " + guid_text(n.guid);
    }
    const DevFwAccess a = dev_fw_access();
    if (!a.denied.empty()) what += "; " + permission_hint(a);
    throw DeviceOpenError(what);
  }
  node_ = *pick;

  h_ = new Handles;
  raw1394handle_t* all[3] = {&h_->ctrl, &h_->rx, &h_->tx};
  for (raw1394handle_t* p : all) {
    *p = raw1394_new_handle_on_port(node_.port);
    if (*p == nullptr) {
      const int e = errno;
      close_handles();
      throw DeviceOpenError("firewire: cannot open a libraw1394 handle on "
                            "port " + std::to_string(node_.port) + " (" +
                            errno_text(e) + ")");
    }
    raw1394_set_userdata(*p, this);
  }
  raw1394_set_bus_reset_handler(h_->ctrl, &Raw1394Callbacks::bus_reset);
  raw1394_busreset_notify(h_->ctrl, RAW1394_NOTIFY_ON);
  // the first packet the transmit context sends: zero words, motors off
  encode_command(CommandPacket{}, tx_packet_.data());
}

Raw1394Transport::~Raw1394Transport() {
  stop();
  close_handles();
}

void Raw1394Transport::close_handles() noexcept {
  if (h_ == nullptr) return;
  raw1394_destroy_handle(h_->tx);
  raw1394_destroy_handle(h_->rx);
  raw1394_destroy_handle(h_->ctrl);
  delete h_;
  h_ = nullptr;
}

const char* Raw1394Transport::claim_channels() noexcept {
  // two free channels at the isochronous resource manager, the same ones
  // again after a bus reset (which frees every allocation)
  if (!channels_claimed_) {
    tx_channel_ = rx_channel_ = -1;
    for (int ch = 0; ch < 64 && rx_channel_ < 0; ++ch) {
      if (raw1394_channel_modify(h_->ctrl, static_cast<unsigned>(ch),
                                 RAW1394_MODIFY_ALLOC) != 0) {
        continue;
      }
      (tx_channel_ < 0 ? tx_channel_ : rx_channel_) = ch;
    }
    if (rx_channel_ < 0) {
      release_channels();
      return "no two free isochronous channels at the bus's resource "
             "manager (raw1394_channel_modify)";
    }
    channels_claimed_ = true;
    return nullptr;
  }
  for (const int ch : {tx_channel_, rx_channel_}) {
    if (raw1394_channel_modify(h_->ctrl, static_cast<unsigned>(ch),
                               RAW1394_MODIFY_ALLOC) != 0) {
      return "isochronous channel taken by another node after the bus reset";
    }
  }
  return nullptr;
}

void Raw1394Transport::release_channels() noexcept {
  for (const int ch : {tx_channel_, rx_channel_}) {
    if (ch >= 0) {
      raw1394_channel_modify(h_->ctrl, static_cast<unsigned>(ch),
                             RAW1394_MODIFY_FREE);
    }
  }
  tx_channel_ = rx_channel_ = -1;
  channels_claimed_ = false;
}

const char* Raw1394Transport::start_registers() noexcept {
  const auto id = static_cast<nodeid_t>(kLocalBus | node_.node);
  if (!write_byte(h_->ctrl, id, kRegTxChannel,
                  static_cast<std::uint8_t>(tx_channel_))) {
    return "writing the host->device channel to 0x1000 failed";
  }
  if (!write_byte(h_->ctrl, id, kRegRxChannel,
                  static_cast<std::uint8_t>(rx_channel_))) {
    return "writing the device->host channel to 0x1001 failed";
  }
  std::uint8_t status = 0;
  if (!read_byte(h_->ctrl, id, kRegStatus1, &status)) {
    return "reading 0x1083 failed";
  }
  if (status != 0xc0) {
    std::snprintf(error_, sizeof error_,
                  "0x1083 reads 0x%02x, not 0xc0 (the Omni is not ready)",
                  static_cast<unsigned>(status));
    return error_;
  }
  if (!write_byte(h_->ctrl, id, kRegStart, kStartValue)) {
    return "writing 0x08 to 0x1087 (start) failed";
  }
  return nullptr;
}

void Raw1394Transport::start() {
  if (started_) return;
  const auto fail = [&](const std::string& what) {
    shutdown_iso();
    release_channels();
    return DeviceOpenError("firewire: start of " + node_.description +
                           ": " + what);
  };
  if (const char* e = claim_channels()) throw fail(e);
  rx_fresh_ = rx_bad_ = reset_pending_ = false;
  const auto rx_failed = [&](const char* call) {
    return fail("isochronous receive on channel " +
                std::to_string(rx_channel_) + " (" + call +
                "): " + errno_text(errno));
  };
  if (raw1394_iso_recv_init(h_->rx, &Raw1394Callbacks::received,
                            kIsoBufferPackets, kRxMaxPacket,
                            static_cast<unsigned char>(rx_channel_),
                            RAW1394_DMA_PACKET_PER_BUFFER,
                            kIrqInterval) != 0) {
    throw rx_failed("raw1394_iso_recv_init");
  }
  rx_iso_ = true;
  if (raw1394_iso_recv_start(h_->rx, -1, -1, 0) != 0) {
    throw rx_failed("raw1394_iso_recv_start");
  }
  encode_command(CommandPacket{}, tx_packet_.data());
  const auto tx_failed = [&](const char* call) {
    return fail("isochronous transmit on channel " +
                std::to_string(tx_channel_) + " (" + call +
                "): " + errno_text(errno));
  };
  if (raw1394_iso_xmit_init(h_->tx, &Raw1394Callbacks::transmit,
                            kIsoBufferPackets,
                            static_cast<unsigned>(kCommandPacketBytes),
                            static_cast<unsigned char>(tx_channel_),
                            RAW1394_ISO_SPEED_100, kIrqInterval) != 0) {
    throw tx_failed("raw1394_iso_xmit_init");
  }
  tx_iso_ = true;
  if (raw1394_iso_xmit_start(h_->tx, -1, -1) != 0) {
    throw tx_failed("raw1394_iso_xmit_start");
  }
  if (const char* e = start_registers()) throw fail(e);
  started_ = true;
}

void Raw1394Transport::stop() noexcept {
  if (!started_ || h_ == nullptr) return;
  // let the last command (the caller's zero packet) go out for a few cycles
  for (int i = 0; i < 5; ++i) pump(1e-3);
  const auto id = static_cast<nodeid_t>(kLocalBus | node_.node);
  write_byte(h_->ctrl, id, kRegStart, kStopValue);
  shutdown_iso();
  release_channels();
  started_ = false;
}

void Raw1394Transport::shutdown_iso() noexcept {
  if (rx_iso_) {
    raw1394_iso_stop(h_->rx);
    raw1394_iso_shutdown(h_->rx);
    rx_iso_ = false;
  }
  if (tx_iso_) {
    raw1394_iso_stop(h_->tx);
    raw1394_iso_shutdown(h_->tx);
    tx_iso_ = false;
  }
}

// Waits up to timeout_s for any of the three handles and lets libraw1394
// run the handlers of what arrived. kOk also when nothing did.
TransportStatus Raw1394Transport::pump(double timeout_s) noexcept {
  pollfd fds[3] = {{raw1394_get_fd(h_->ctrl), POLLIN, 0},
                   {raw1394_get_fd(h_->rx), POLLIN, 0},
                   {raw1394_get_fd(h_->tx), POLLIN, 0}};
  timespec ts{0, 0};
  if (timeout_s > 0.0) {
    const auto whole = static_cast<std::time_t>(timeout_s);
    ts.tv_sec = whole;
    ts.tv_nsec = static_cast<long>((timeout_s - static_cast<double>(whole)) * 1e9);
    if (ts.tv_nsec >= 1000000000L) ts.tv_nsec = 999999999L;
  }
  const int n = ppoll(fds, 3, &ts, nullptr);
  if (n < 0) return errno == EINTR ? TransportStatus::kOk : TransportStatus::kIo;
  raw1394handle_t hs[3] = {h_->ctrl, h_->rx, h_->tx};
  for (int i = 0; i < 3; ++i) {
    if ((fds[i].revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
      return TransportStatus::kDisconnected;  // the adapter went away
    }
    if ((fds[i].revents & POLLIN) != 0 && raw1394_loop_iterate(hs[i]) < 0) {
      return TransportStatus::kIo;
    }
  }
  return TransportStatus::kOk;
}

TransportStatus Raw1394Transport::receive(std::uint8_t* buf,
                                          std::size_t capacity,
                                          std::size_t* size,
                                          double timeout_s) noexcept {
  if (!started_) return TransportStatus::kDisconnected;
  const double deadline = now_s() + timeout_s;
  for (;;) {
    if (reset_pending_) {
      resets_.fetch_add(1, std::memory_order_relaxed);
      return TransportStatus::kBusReset;
    }
    if (rx_fresh_) {
      rx_fresh_ = false;
      if (capacity < kStatePacketBytes) return TransportStatus::kIo;
      std::memcpy(buf, rx_packet_.data(), kStatePacketBytes);
      *size = kStatePacketBytes;
      received_.fetch_add(1, std::memory_order_relaxed);
      return TransportStatus::kOk;
    }
    if (rx_bad_) {
      rx_bad_ = false;
      *size = rx_size_;
      bad_.fetch_add(1, std::memory_order_relaxed);
      return TransportStatus::kBadPacket;
    }
    const double left = deadline - now_s();
    if (left <= 0.0) {
      timeouts_.fetch_add(1, std::memory_order_relaxed);
      return TransportStatus::kTimeout;
    }
    const TransportStatus s = pump(left);
    if (s != TransportStatus::kOk) return s;
  }
}

TransportStatus Raw1394Transport::send(const std::uint8_t* data,
                                       std::size_t size) noexcept {
  if (!started_) return TransportStatus::kDisconnected;
  if (data == nullptr || size != kCommandPacketBytes) {
    return TransportStatus::kBadPacket;
  }
  std::memcpy(tx_packet_.data(), data, kCommandPacketBytes);
  sent_.fetch_add(1, std::memory_order_relaxed);
  return pump(0.0);  // keeps the transmit context fed between receives
}

bool Raw1394Transport::find_node_again() noexcept {
  const int count = raw1394_get_nodecount(h_->ctrl);
  const int local = raw1394_get_local_id(h_->ctrl) & 0x3f;
  for (int n = 0; n < count; ++n) {
    if (n == local) continue;
    const auto id = static_cast<nodeid_t>(kLocalBus | n);
    std::uint32_t hi = 0, lo = 0;
    if (!read_quadlet(h_->ctrl, id, kGuidHi, &hi) ||
        !read_quadlet(h_->ctrl, id, kGuidLo, &lo)) {
      continue;
    }
    if (((static_cast<std::uint64_t>(hi) << 32) | lo) == node_.guid) {
      node_.node = n;
      node_.generation = raw1394_get_generation(h_->ctrl);
      return true;
    }
  }
  return false;
}

TransportStatus Raw1394Transport::recover() noexcept {
  if (h_ == nullptr || !started_) return TransportStatus::kDisconnected;
  reset_pending_ = false;
  rx_fresh_ = rx_bad_ = false;
  if (!find_node_again()) return TransportStatus::kDisconnected;
  if (claim_channels() != nullptr) return TransportStatus::kIo;
  if (start_registers() != nullptr) return TransportStatus::kIo;
  recoveries_.fetch_add(1, std::memory_order_relaxed);
  return TransportStatus::kOk;
}

TransportStats Raw1394Transport::stats() const noexcept {
  TransportStats s;
  s.received = received_.load(std::memory_order_relaxed);
  s.sent = sent_.load(std::memory_order_relaxed);
  s.bad_packets = bad_.load(std::memory_order_relaxed);
  s.timeouts = timeouts_.load(std::memory_order_relaxed);
  s.bus_resets = resets_.load(std::memory_order_relaxed);
  s.recoveries = recoveries_.load(std::memory_order_relaxed);
  return s;
}

}  // namespace vmh::hw::fw
