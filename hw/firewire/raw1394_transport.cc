// The FireWire Omni's bus through libraw1394 (raw1394_transport.h says the
// sequences; docs/sources.md §9.2 where each step comes from): the
// transport opened on the Omni's port, libraw1394's callbacks, and the
// servo loop's receive and send. The start, stop and recovery sequences are
// in raw1394_sequences.cc, the finding of Omnis in raw1394_discovery.cc. The
// libraw1394 calls are as its header documents them (raw1394.h, 2.1.2).
#include "hw/firewire/raw1394_transport.h"

#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include "device/device_backend.h"
#include "hw/firewire/raw1394_library.h"
#include "hw/firewire/raw1394_transport_detail.h"

namespace vmh::hw::fw {

namespace {

using detail::errno_text;
using detail::now_s;
using detail::PortScan;
using r1394::Handle;

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

int Raw1394Callbacks::bus_reset(Handle h, unsigned int generation) {
  Raw1394Transport* t = owner_of(h);
  if (t != nullptr) {
    t->api_->update_generation(h, generation);
    t->reset_pending_ = true;
  }
  return 0;
}

r1394::Disposition Raw1394Callbacks::received(Handle h, unsigned char* data,
                                              unsigned int len, unsigned char,
                                              unsigned char, unsigned char,
                                              unsigned int cycle,
                                              unsigned int) {
  Raw1394Transport* t = owner_of(h);
  if (t != nullptr) t->on_packet(data, len, cycle);
  return r1394::kIsoOk;
}

r1394::Disposition Raw1394Callbacks::transmit(Handle h, unsigned char* data,
                                              unsigned int* len,
                                              unsigned char* tag,
                                              unsigned char* sy, int,
                                              unsigned int) {
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

  PortScan s = detail::scan(*api_, options_);
  if (s.ports <= 0) {
    throw DeviceOpenError(s.error.empty() || s.ports == 0
                              ? detail::no_adapter_message()
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
    throw DeviceOpenError(detail::not_found_message(s, options_.guid));
  }
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
  const TransportStatus s = await_batch(timeout_s, size);
  if (s != TransportStatus::kOk) return s;
  return hand_over(buf, capacity, size, info);
}

// Runs every waiting event's handler, waiting for more up to timeout_s,
// until a batch of packets is there (kOk), a bus reset or a wrong-size
// packet is seen, the adapter goes or the time is up.
TransportStatus Raw1394Transport::await_batch(double timeout_s,
                                              std::size_t* size) noexcept {
  const double deadline = now_s() + timeout_s;
  for (;;) {
    // every event waiting: bus resets first, then every packet
    if (!drain(h_->ctrl, 16) || !drain(h_->rx, 4 * kRxBufferPackets)) {
      return TransportStatus::kDisconnected;
    }
    if (reset_pending_) return take_bus_reset();
    if (batch_ >= kRxBufferPackets && fresh_start_) {
      discard_stale_batch();
      continue;
    }
    if (batch_ > 0) return TransportStatus::kOk;
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
}

// A bus reset seen: the device must be recovered before anything more is
// received.
TransportStatus Raw1394Transport::take_bus_reset() noexcept {
  // what arrived across the reset is from before it
  reset_pending_ = false;
  needs_recovery_ = true;
  receives_since_recovery_ = 0;
  batch_ = 0;
  rx_bad_ = false;
  resets_.fetch_add(1, std::memory_order_relaxed);
  return TransportStatus::kBusReset;
}

// The first receive after start() or recover() found the receive buffer
// full: the packets queued before the servo loop's first tick (setting up
// its thread can take tens of milliseconds), and the newest of them stale,
// as the ones after it did not fit. Discarded; the next packet is the
// loop's first.
void Raw1394Transport::discard_stale_batch() noexcept {
  stale_.fetch_add(batch_, std::memory_order_relaxed);
  batch_ = 0;
  rx_bad_ = false;
  fresh_start_ = false;
}

// How many of the batch's n packets are late: those beyond the record of
// arrival cycles, and those that arrived late_cycles_ or more before the
// newest.
std::uint32_t Raw1394Transport::count_late(std::uint32_t n) const noexcept {
  const std::size_t kept = n < batch_cycles_.size() ? n : batch_cycles_.size();
  const unsigned newest = batch_cycles_[kept - 1];
  auto late = static_cast<std::uint32_t>(n - kept);  // beyond the record
  for (std::size_t i = 0; i + 1 < kept; ++i) {
    const unsigned age = (newest + 8000u - batch_cycles_[i]) % 8000u;
    if (age >= late_cycles_) ++late;
  }
  return late;
}

// Hands over the batch's newest packet; the others of the batch are
// superseded, some late.
TransportStatus Raw1394Transport::hand_over(std::uint8_t* buf,
                                            std::size_t capacity,
                                            std::size_t* size,
                                            ReceiveInfo* info) noexcept {
  const std::uint32_t n = batch_;
  // (the first batch after a start came before any receive: none late)
  const std::uint32_t late = fresh_start_ ? 0 : count_late(n);
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
