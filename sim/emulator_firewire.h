// The emulator behind the FireWire Omni's packets: an hw::fw::Transport
// whose other end is the MuJoCo Omni (sim/emulator.h) instead of a bus, so
// that `--device emulator:firewire` runs the codec (hw/firewire/
// omni_packet.h), the device layer (FirewireOmni: unwrap, calibration,
// units, lost-packet and bus-reset handling) and the CLI on top exactly as
// they would run on a real Omni.
//
// receive(): the emulator's newest reading (Emulator::read_state: raw
// encoder counts and 11-bit pot codes, buttons, the inkwell switch) as one
// 44-byte state packet:
//   magic          kEmulatorStateMagic (the real one is not known)
//   encoders       the counts' low 16 bits as int16 (they wrap every 65536
//                  counts; the device layer unwraps them)
//   gimbal_a/_b    pot_words_from_code(code): a complementary pair
//   status         buttons active-low (bit 0 button 1, bit 1 button 2),
//                  bit 2 set when the stylus is out of the inkwell
//   counter        +1 for every packet the device sends (a lost or
//                  corrupted packet too, so the device layer sees the gap)
//   packet_number  the counter's low 8 bits
//   time           when the reading was taken, microseconds since start()
//                  (a late reading carries its old time), wrapping at 2^32
// It returns at once: the newest packet (ReceiveInfo: one packet, none
// late: the emulator publishes once a period and the call takes it), or
// kTimeout when the emulator has none fresh (its read_state's staleness
// rule: older than 3 periods), or a fault below. It never waits for
// timeout_s, so that the servo thread keeps its period as on the plain
// emulator.
//
// send(): decode_command(); motors off -> zero torque, else per motor
//   tau = factory_motor_sign * u * factory_full_scale_Nm,
// u = unit_from_motor_word(word), then Emulator::write_motor_torques (the
// emulator's clamps, delay line and device watchdog apply). The factory
// scale and sign are the emulated device's hidden truth: by default the
// device layer's estimate (kMotorFullScaleEstimate_Nm, +1), so that a torque
// written through FirewireOmni reaches the motors within one motor word.
//
// start()/stop() start and stop the emulator's physics thread. node():
// vendor kVendorSensable, the emulator's serial, a made-up GUID
// (kEmulatorGuidBase | 32 bits of the serial's hash), description
// "in-process (emulator)"; the generation counts bus resets.
//
// Packet-level faults, text form (parse_wire_faults), comma-separated,
// "kind@at_s[:...]" with at_s in emulator time from start(), in the one
// fault grammar (sim/fault_vocabulary.h):
//   loss@t:N          the next N state packets never arrive: N receives
//                     return kTimeout (the counter still advances)
//   late@t:dur:K      for dur s, every packet is K periods old (1..63;
//                     the emulator's own late fault)
//   length@t:N        the next N packets arrive 43 and 45 bytes long in
//                     turn: kBadPacket, *size the wrong length
//   reset@t           a bus reset: receive and send return kBusReset (the
//                     motors get zero) until recover(), which succeeds
//   unplug@t:dur      the device is gone for dur s: kDisconnected from
//                     receive, send and recover, zero torque held at the
//                     motors (the emulator's unplug); then back, the motors
//                     waiting for a fresh command
//   stall@t:dur       the device's physics freezes for dur s: no packets,
//                     receive returns kTimeout (the emulator's stall)
//
// Threads: receive, send and recover from one servo thread (noexcept, no
// allocation, no lock); inject, stats, node and emulator() from any.
#ifndef VMHAPTICS_SIM_EMULATOR_FIREWIRE_H_
#define VMHAPTICS_SIM_EMULATOR_FIREWIRE_H_

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "device/seqlock.h"
#include "hw/firewire/firewire_omni.h"
#include "hw/firewire/omni_packet.h"
#include "hw/firewire/transport.h"
#include "sim/emulator.h"

namespace vmh::sim {

// "VMH1" read as a little-endian u32: marks the emulator's packets
inline constexpr std::uint32_t kEmulatorStateMagic = 0x31484d56u;
// the emulator's GUIDs: SensAble's OUI, then 0xee and 32 bits of the serial
inline constexpr std::uint64_t kEmulatorGuidBase = 0x000b99ee00000000ull;
inline constexpr int kMaxWireLengthFaultPackets = 1000000;

enum class WireFaultKind { kLoss, kLate, kLength, kReset, kUnplug, kStall };
const char* wire_fault_name(WireFaultKind k);  // "loss", "late", ...

struct WireFault {
  WireFaultKind kind = WireFaultKind::kLoss;
  double at_s = 0.0;        // emulator time from start()
  double duration_s = 0.0;  // late, unplug, stall
  int count = 0;            // loss, length: packets; late: periods (1..63)
};
// Empty text: no faults. Throws std::invalid_argument naming the bad item
// (an unknown kind names the kinds there are).
std::vector<WireFault> parse_wire_faults(const std::string& text);
// Throws std::invalid_argument naming the fault's bad field.
void validate_wire_fault(const WireFault& fault);

struct EmulatorFirewireOptions {
  EmulatorOptions emulator;       // the emulated Omni (its own faults too)
  std::vector<WireFault> faults;  // packet-level faults
  // the emulated device's hidden motor scale and sign (torque at u = +1,
  // N m, > 0; +1 or -1)
  std::array<double, 3> factory_full_scale_Nm{
      hw::fw::kMotorFullScaleEstimate_Nm, hw::fw::kMotorFullScaleEstimate_Nm,
      hw::fw::kMotorFullScaleEstimate_Nm};
  std::array<int, 3> factory_motor_sign{+1, +1, +1};
};

class EmulatorFirewireTransport final : public hw::fw::Transport {
 public:
  // Builds the emulator (throws as Emulator's constructor does) and checks
  // the options (std::invalid_argument naming the field).
  explicit EmulatorFirewireTransport(const EmulatorFirewireOptions& options);
  ~EmulatorFirewireTransport() override;

  hw::fw::NodeInfo node() const override;
  void start() override;
  void stop() noexcept override;
  hw::fw::TransportStatus receive(std::uint8_t* buf, std::size_t capacity,
                                  std::size_t* size, double timeout_s,
                                  hw::fw::ReceiveInfo* info) noexcept override;
  hw::fw::TransportStatus send(const std::uint8_t* data,
                               std::size_t size) noexcept override;
  hw::fw::TransportStatus recover() noexcept override;
  hw::fw::TransportStats stats() const noexcept override { return stats_.read(); }

  // Schedules a packet-level fault (at max(at_s, now)); any thread. Throws
  // std::invalid_argument for a bad fault, std::length_error past
  // kMaxFaults in all.
  void inject(const WireFault& fault);
  static constexpr int kMaxFaults = 64;

  // the device on the other end (ground truth, hand programs, its faults)
  Emulator* emulator() noexcept { return emu_.get(); }
  const Emulator* emulator() const noexcept { return emu_.get(); }

  // the command the emulated device last decoded (for tests)
  hw::fw::CommandPacket last_command() const noexcept { return last_command_.read(); }

 private:
  struct Slot {
    std::atomic<bool> ready{false};
    WireFault fault;
  };
  void apply_due_faults() noexcept;
  void publish_stats() noexcept { stats_.write(s_); }

  EmulatorFirewireOptions options_;
  std::unique_ptr<Emulator> emu_;
  hw::fw::NodeInfo node_;
  std::atomic<std::uint32_t> generation_{0};

  Slot slots_[kMaxFaults];
  std::atomic<int> slot_count_{0};
  Seqlock<hw::fw::TransportStats> stats_;
  Seqlock<hw::fw::CommandPacket> last_command_;

  // the servo thread's own
  std::array<bool, kMaxFaults> taken_{};
  int taken_count_ = 0;
  hw::fw::TransportStats s_;
  std::uint32_t counter_ = 0;
  int loss_pending_ = 0;
  int length_pending_ = 0;
  int length_parity_ = 0;
  std::atomic<bool> reset_pending_{false};
  double start_wall_s_ = 0.0;
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_EMULATOR_FIREWIRE_H_
