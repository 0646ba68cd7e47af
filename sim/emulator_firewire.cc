// The emulator behind the FireWire Omni's packets (sim/emulator_firewire.h).
#include "sim/emulator_firewire.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "device/tick_timer.h"
#include "sim/fault_vocabulary.h"

namespace vmh::sim {
namespace {

using hw::fw::TransportStatus;

struct KindName {
  WireFaultKind kind;
  const char* name;
};
constexpr KindName kKinds[] = {
    {WireFaultKind::kLoss, "loss"},     {WireFaultKind::kLate, "late"},
    {WireFaultKind::kLength, "length"}, {WireFaultKind::kReset, "reset"},
    {WireFaultKind::kUnplug, "unplug"}, {WireFaultKind::kStall, "stall"},
};

// FNV-1a, for the made-up GUID
std::uint64_t text_hash(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

// the low 16 bits of a count as the int16 the packet carries
std::int16_t low16(std::int32_t count) noexcept {
  const int v = static_cast<int>(static_cast<std::uint32_t>(count) & 0xffffu);
  return static_cast<std::int16_t>(v >= 0x8000 ? v - 0x10000 : v);
}

EmulatorFault emulator_fault(const WireFault& w) {
  EmulatorFault f;
  f.at_s = w.at_s;
  f.duration_s = w.duration_s;
  f.count = w.count;
  switch (w.kind) {
    case WireFaultKind::kLate: f.kind = EmulatorFaultKind::kLate; break;
    case WireFaultKind::kUnplug: f.kind = EmulatorFaultKind::kUnplug; break;
    case WireFaultKind::kStall: f.kind = EmulatorFaultKind::kStall; break;
    default: break;
  }
  return f;
}

// the emulator's own faults carry these out; the others are the transport's
bool emulator_side(WireFaultKind k) {
  return k == WireFaultKind::kLate || k == WireFaultKind::kUnplug ||
         k == WireFaultKind::kStall;
}

}  // namespace

const char* wire_fault_name(WireFaultKind k) {
  for (const KindName& n : kKinds) {
    if (n.kind == k) return n.name;
  }
  return "unknown";
}

void validate_wire_fault(const WireFault& f) {
  const std::string name = wire_fault_name(f.kind);
  if (!std::isfinite(f.at_s) || f.at_s < 0.0) {
    throw std::invalid_argument("firewire fault " + name +
                                ": at_s must be finite and >= 0");
  }
  switch (f.kind) {
    case WireFaultKind::kLoss:
    case WireFaultKind::kLength:
      if (f.count < 1 || f.count > kMaxWireLengthFaultPackets) {
        throw std::invalid_argument("firewire fault " + name +
                                    ": count must be in [1, " +
                                    std::to_string(kMaxWireLengthFaultPackets) +
                                    "] packets");
      }
      return;
    case WireFaultKind::kReset:
      return;
    case WireFaultKind::kLate:
      if (f.count < 1 || f.count > kMaxLatePeriods) {
        throw std::invalid_argument("firewire fault late: count must be in [1, " +
                                    std::to_string(kMaxLatePeriods) + "] periods");
      }
      break;
    case WireFaultKind::kUnplug:
    case WireFaultKind::kStall:
      break;
  }
  if (!std::isfinite(f.duration_s) || f.duration_s <= 0.0) {
    throw std::invalid_argument("firewire fault " + name +
                                ": duration_s must be finite and > 0");
  }
}

std::vector<WireFault> parse_wire_faults(const std::string& text) {
  std::vector<WireFault> out;
  for (const FaultItem& it : parse_faults(text, kWireFaults)) {
    WireFault w;
    for (const KindName& n : kKinds) {
      if (n.name == std::string(it.kind->name)) w.kind = n.kind;
    }
    w.at_s = it.at_s;
    switch (w.kind) {
      case WireFaultKind::kLoss:
      case WireFaultKind::kLength: w.count = static_cast<int>(it.values[0]); break;
      case WireFaultKind::kLate:
        w.duration_s = it.values[0];
        w.count = static_cast<int>(it.values[1]);
        break;
      case WireFaultKind::kUnplug:
      case WireFaultKind::kStall: w.duration_s = it.values[0]; break;
      case WireFaultKind::kReset: break;
    }
    try {
      validate_wire_fault(w);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("firewire fault '" + it.text + "': " + e.what());
    }
    out.push_back(w);
  }
  return out;
}

EmulatorFirewireTransport::EmulatorFirewireTransport(
    const EmulatorFirewireOptions& options)
    : options_(options) {
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double fs = options_.factory_full_scale_Nm[k];
    if (!std::isfinite(fs) || fs <= 0.0) {
      throw std::invalid_argument("EmulatorFirewireOptions: factory_full_scale_Nm[" +
                                  std::to_string(i) + "] must be finite and > 0");
    }
    const int sg = options_.factory_motor_sign[k];
    if (sg != 1 && sg != -1) {
      throw std::invalid_argument("EmulatorFirewireOptions: factory_motor_sign[" +
                                  std::to_string(i) + "] must be +1 or -1");
    }
  }
  for (const WireFault& f : options_.faults) validate_wire_fault(f);
  emu_ = std::make_unique<Emulator>(options_.emulator);
  node_.guid = kEmulatorGuidBase | (text_hash(options_.emulator.serial) & 0xffffffffull);
  node_.vendor = hw::fw::kVendorSensable;
  node_.serial = options_.emulator.serial;
  node_.port = -1;
  node_.node = 0;
  node_.description = "in-process (emulator)";
  for (const WireFault& f : options_.faults) inject(f);
  publish_stats();
}

EmulatorFirewireTransport::~EmulatorFirewireTransport() { stop(); }

hw::fw::NodeInfo EmulatorFirewireTransport::node() const {
  hw::fw::NodeInfo n = node_;
  n.generation = generation_.load();
  return n;
}

void EmulatorFirewireTransport::inject(const WireFault& fault) {
  validate_wire_fault(fault);
  if (emulator_side(fault.kind)) {
    emu_->inject(emulator_fault(fault));  // the emulator keeps its own list
    return;
  }
  const int i = slot_count_.fetch_add(1);
  if (i >= kMaxFaults) {
    slot_count_.fetch_sub(1);
    throw std::length_error("EmulatorFirewireTransport::inject: more than " +
                            std::to_string(kMaxFaults) + " faults");
  }
  Slot& slot = slots_[i];
  slot.fault = fault;
  slot.fault.at_s = emu_->running() ? std::max(fault.at_s, emu_->truth().t_sim_s)
                                    : fault.at_s;
  slot.ready.store(true, std::memory_order_release);
}

void EmulatorFirewireTransport::start() {
  // a fresh stream: the device's counter starts again, as at power-on
  counter_ = 0;
  loss_pending_ = 0;
  length_pending_ = 0;
  length_parity_ = 0;
  taken_.fill(false);
  taken_count_ = 0;
  reset_pending_.store(false);
  // the arm stays where it was when the stream restarts (the emulator's
  // first start is fresh)
  emu_->start(/*resume=*/true);
  // the emulator's clock (lockstep: its periods) is the packets' time base
  start_wall_s_ = emu_->clock_s();
}

void EmulatorFirewireTransport::stop() noexcept {
  if (emu_) {
    (void)emu_->write_motor_torques(Vec3::Zero());
    emu_->stop();
  }
}

void EmulatorFirewireTransport::apply_due_faults() noexcept {
  const int n = std::min(slot_count_.load(std::memory_order_acquire), kMaxFaults);
  if (taken_count_ >= n) return;
  const double t_s = emu_->truth().t_sim_s;
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (taken_[k] || !slots_[i].ready.load(std::memory_order_acquire)) continue;
    const WireFault& f = slots_[i].fault;
    if (t_s + 1e-12 < f.at_s) continue;
    taken_[k] = true;
    ++taken_count_;
    switch (f.kind) {
      case WireFaultKind::kLoss: loss_pending_ += f.count; break;
      case WireFaultKind::kLength: length_pending_ += f.count; break;
      case WireFaultKind::kReset:
        if (!reset_pending_.load(std::memory_order_relaxed)) {
          reset_pending_.store(true, std::memory_order_release);
          generation_.fetch_add(1, std::memory_order_relaxed);
          ++s_.bus_resets;
          // the stream stops: no command reaches the motors
          (void)emu_->write_motor_torques(Vec3::Zero());
        }
        break;
      default: break;  // the emulator's own
    }
  }
}

TransportStatus EmulatorFirewireTransport::receive(std::uint8_t* buf,
                                                   std::size_t capacity,
                                                   std::size_t* size,
                                                   double /*timeout_s*/,
                                                   hw::fw::ReceiveInfo* info) noexcept {
  *size = 0;
  if (info != nullptr) *info = hw::fw::ReceiveInfo{};
  apply_due_faults();
  if (reset_pending_.load(std::memory_order_acquire)) {
    publish_stats();
    return TransportStatus::kBusReset;
  }
  if (loss_pending_ > 0) {
    // sent by the device, never arrived
    --loss_pending_;
    ++counter_;
    ++s_.timeouts;
    publish_stats();
    return TransportStatus::kTimeout;
  }
  DeviceState s;
  const DeviceError e = emu_->read_state(&s);
  if (e == DeviceError::kNotConnected) return TransportStatus::kDisconnected;
  if (e == DeviceError::kTimeout) {
    ++s_.timeouts;
    publish_stats();
    return TransportStatus::kTimeout;
  }
  if (e != DeviceError::kOk) return TransportStatus::kIo;

  hw::fw::StatePacket p;
  p.magic = kEmulatorStateMagic;
  for (std::size_t i = 0; i < 3; ++i) {
    p.encoders[i] = low16(s.encoder_counts[i]);
    hw::fw::pot_words_from_code(s.gimbal_pots[i], &p.gimbal_a[i], &p.gimbal_b[i]);
  }
  std::uint8_t status = 0;
  if ((s.buttons & kButton1) == 0) status |= hw::fw::kStateButton1Released;
  if ((s.buttons & kButton2) == 0) status |= hw::fw::kStateButton2Released;
  if (!s.docked) status |= hw::fw::kStateUndocked;
  p.status = status;
  ++counter_;
  p.counter = counter_;
  p.packet_number = static_cast<std::uint8_t>(counter_ & 0xffu);
  const double us = std::max(0.0, 1e6 * (s.timestamp_s - start_wall_s_));
  // rounded, not truncated: 1.025 s is 1025000 us, not 1024999
  p.time = static_cast<std::uint32_t>(static_cast<std::uint64_t>(std::llround(us)) &
                                      0xffffffffull);

  std::uint8_t bytes[hw::fw::kStatePacketBytes + 1] = {};
  hw::fw::encode_state(p, bytes);
  if (length_pending_ > 0) {
    // corrupted on the way: one byte short or one too many
    --length_pending_;
    const std::size_t n = length_parity_++ % 2 == 0 ? hw::fw::kStatePacketBytes - 1
                                                    : hw::fw::kStatePacketBytes + 1;
    std::memcpy(buf, bytes, std::min(n, capacity));
    *size = n;
    ++s_.bad_packets;
    publish_stats();
    return TransportStatus::kBadPacket;
  }
  *size = hw::fw::kStatePacketBytes;
  if (capacity < hw::fw::kStatePacketBytes) {
    publish_stats();
    return TransportStatus::kIo;
  }
  std::memcpy(buf, bytes, hw::fw::kStatePacketBytes);
  ++s_.received;
  ++s_.delivered;
  if (info != nullptr) info->packets = 1;
  publish_stats();
  return TransportStatus::kOk;
}

TransportStatus EmulatorFirewireTransport::send(const std::uint8_t* data,
                                                std::size_t size) noexcept {
  if (reset_pending_.load(std::memory_order_acquire)) return TransportStatus::kBusReset;
  hw::fw::CommandPacket c;
  if (hw::fw::decode_command(data, size, &c) != hw::fw::PacketError::kOk) {
    return TransportStatus::kBadPacket;
  }
  Vec3 tau_Nm = Vec3::Zero();
  if (c.motors_on()) {
    for (int i = 0; i < 3; ++i) {
      const auto k = static_cast<std::size_t>(i);
      tau_Nm[i] = options_.factory_motor_sign[k] * options_.factory_full_scale_Nm[k] *
                  hw::fw::unit_from_motor_word(c.motor[k]);
    }
  }
  const DeviceError e = emu_->write_motor_torques(tau_Nm);
  if (e == DeviceError::kNotConnected) return TransportStatus::kDisconnected;
  last_command_.write(c);
  ++s_.sent;
  publish_stats();
  return e == DeviceError::kOk ? TransportStatus::kOk : TransportStatus::kIo;
}

TransportStatus EmulatorFirewireTransport::recover() noexcept {
  if (!emu_->running() || emu_->truth().unplugged) {
    return TransportStatus::kDisconnected;
  }
  if (reset_pending_.exchange(false, std::memory_order_acq_rel)) {
    ++s_.recoveries;
    publish_stats();
  }
  return TransportStatus::kOk;
}

}  // namespace vmh::sim
