// A scripted Transport for the FireWire Omni's tests: receive() plays a
// queue of packets and statuses written before the test (or, in `stream`
// mode, makes a fresh packet every call), send() records every packet. All
// storage is fixed-size, so receive and send allocate nothing.
#ifndef VMHAPTICS_TESTS_HW_FIREWIRE_FAKE_TRANSPORT_H_
#define VMHAPTICS_TESTS_HW_FIREWIRE_FAKE_TRANSPORT_H_

#include <array>
#include <atomic>
#include <cstring>

#include "hw/firewire/omni_packet.h"
#include "hw/firewire/transport.h"

namespace vmh::hw::fw::testing {

class FakeTransport final : public Transport {
 public:
  struct Item {
    TransportStatus status = TransportStatus::kOk;
    std::array<std::uint8_t, 64> bytes{};
    std::size_t size = 0;
  };
  static constexpr std::size_t kQueue = 512;
  static constexpr std::size_t kSent = 4096;

  // script
  void push_packet(const StatePacket& p) {
    Item it;
    encode_state(p, it.bytes.data());
    it.size = kStatePacketBytes;
    push(it);
  }
  void push_bytes(const std::uint8_t* data, std::size_t size) {
    Item it;
    std::memcpy(it.bytes.data(), data, size);
    it.size = size;
    push(it);
  }
  void push_status(TransportStatus s) {
    Item it;
    it.status = s;
    push(it);
  }
  void push(const Item& it) { queue_[tail_++ % kQueue] = it; }

  // stream mode: every receive() is a new packet, counter and t1's encoder
  // one up each time
  bool stream = false;
  StatePacket stream_packet;

  TransportStatus recover_result = TransportStatus::kOk;
  std::atomic<int> recover_calls{0};
  std::atomic<int> start_calls{0};
  std::atomic<int> stop_calls{0};
  std::atomic<long> receive_calls{0};
  // sent packets, in order (kSent at most; n_sent counts them all)
  std::array<std::array<std::uint8_t, kCommandPacketBytes>, kSent> sent{};
  std::atomic<std::size_t> n_sent{0};
  // the index of the last packet sent before stop() was first called, and
  // before the last recover()
  std::atomic<long> sent_at_stop{-1};
  std::atomic<long> sent_at_recover{-1};

  CommandPacket sent_command(std::size_t i) const {
    CommandPacket c;
    decode_command(sent[i % kSent].data(), kCommandPacketBytes, &c);
    return c;
  }
  CommandPacket last_command() const { return sent_command(n_sent - 1); }

  NodeInfo node() const override {
    NodeInfo n;
    n.guid = 0x000b990000001234ull;
    n.vendor = kVendorSensable;
    n.serial = "4660";
    n.description = "fake transport";
    return n;
  }
  void start() override { ++start_calls; }
  void stop() noexcept override {
    if (stop_calls++ == 0) sent_at_stop = static_cast<long>(n_sent) - 1;
  }
  // what each good receive() says arrived with its packet (ReceiveInfo)
  std::uint32_t arrived_per_packet = 1;
  std::uint32_t late_per_packet = 0;

  TransportStatus receive(std::uint8_t* buf, std::size_t capacity,
                          std::size_t* size, double,
                          ReceiveInfo* info) noexcept override {
    ++receive_calls;
    if (info != nullptr) *info = ReceiveInfo{};
    if (stream) {
      ++stream_packet.counter;
      stream_packet.encoders[0] =
          static_cast<std::int16_t>(stream_packet.encoders[0] + 1);
      if (capacity < kStatePacketBytes) return TransportStatus::kIo;
      encode_state(stream_packet, buf);
      *size = kStatePacketBytes;
      if (info != nullptr) *info = ReceiveInfo{arrived_per_packet, late_per_packet};
      return TransportStatus::kOk;
    }
    if (head_ == tail_) return TransportStatus::kTimeout;
    const Item& it = queue_[head_++ % kQueue];
    if (it.status != TransportStatus::kOk) return it.status;
    if (it.size > capacity) return TransportStatus::kIo;
    std::memcpy(buf, it.bytes.data(), it.size);
    *size = it.size;
    if (info != nullptr) *info = ReceiveInfo{arrived_per_packet, late_per_packet};
    return TransportStatus::kOk;
  }
  TransportStatus send(const std::uint8_t* data,
                       std::size_t size) noexcept override {
    if (size != kCommandPacketBytes) return TransportStatus::kBadPacket;
    const std::size_t i = n_sent.load();
    std::memcpy(sent[i % kSent].data(), data, kCommandPacketBytes);
    n_sent.store(i + 1);
    return TransportStatus::kOk;
  }
  TransportStatus recover() noexcept override {
    ++recover_calls;
    sent_at_recover = static_cast<long>(n_sent) - 1;
    return recover_result;
  }
  TransportStats stats() const noexcept override { return {}; }

 private:
  std::array<Item, kQueue> queue_{};
  std::size_t head_ = 0;
  std::size_t tail_ = 0;
};

// A packet with complementary pot words for the codes given, buttons up,
// out of the inkwell.
inline StatePacket make_packet(std::uint32_t counter,
                               std::array<std::int16_t, 3> enc,
                               std::array<std::int32_t, 3> pots) {
  StatePacket p;
  p.magic = 0x1;
  p.counter = counter;
  p.encoders = enc;
  for (std::size_t i = 0; i < 3; ++i) {
    pot_words_from_code(pots[i], &p.gimbal_a[i], &p.gimbal_b[i]);
  }
  p.status = kStateButton1Released | kStateButton2Released | kStateUndocked;
  return p;
}

}  // namespace vmh::hw::fw::testing

#endif  // VMHAPTICS_TESTS_HW_FIREWIRE_FAKE_TRANSPORT_H_
