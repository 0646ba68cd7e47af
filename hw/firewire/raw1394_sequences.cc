// The FireWire Omni's start, stop and recovery sequences through libraw1394
// (raw1394_transport.h says each step; docs/sources.md §9.2 where each comes
// from): the register transactions, the isochronous channels and contexts,
// the node found again after a bus reset. The libraw1394 calls are as its
// header documents them (raw1394.h, 2.1.2).
#include <poll.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>

#include "device/device_backend.h"
#include "hw/firewire/raw1394_transport.h"
#include "hw/firewire/raw1394_transport_detail.h"

namespace vmh::hw::fw {

namespace {

using detail::now_s;
using detail::read_quadlet_on;
using detail::with_retries;
using r1394::NodeAddr;
using r1394::NodeId;
using r1394::Quadlet;

}  // namespace

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

}  // namespace vmh::hw::fw
