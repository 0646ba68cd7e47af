// The bus under the FireWire Omni: what the device layer (firewire_omni.h)
// needs from IEEE 1394, whoever provides it. Two implementations:
//   Raw1394Transport  (raw1394_transport.h)  the real bus through libraw1394
//   the emulator's in-process transport (sim/emulator_firewire.h), which
//   runs the MuJoCo Omni behind the same packets, so that the codec, the
//   device, calibration, safety and the servo thread run in CI exactly as
//   they would on the bus.
//
// Lifetime: construct (finds the node; throws DeviceOpenError naming what
// is missing) -> start() -> receive()/send() from ONE servo thread ->
// stop(). After kBusReset the caller calls recover() (which re-finds the
// node by its GUID and repeats the start sequence) before anything else.
//
// Real time: receive, send, recover and stop are noexcept and must not
// allocate; they return a TransportStatus.
#ifndef VMHAPTICS_HW_FIREWIRE_TRANSPORT_H_
#define VMHAPTICS_HW_FIREWIRE_TRANSPORT_H_

#include <cstddef>
#include <cstdint>
#include <string>

namespace vmh::hw::fw {

// The Omni's registers and constants on the bus (docs/sources.md §9.2;
// unverified on a device by this project).
inline constexpr std::uint64_t kRegVendorId = 0x1006000c;  // quadlet: vendor
inline constexpr std::uint64_t kRegSerial = 0x10060010;    // serial number
inline constexpr std::uint64_t kRegTxChannel = 0x1000;     // host -> device iso channel
inline constexpr std::uint64_t kRegRxChannel = 0x1001;     // device -> host iso channel
inline constexpr std::uint64_t kRegStart = 0x1087;         // 0x08 start, 0x00 stop
inline constexpr std::uint64_t kRegStatus1 = 0x1083;       // reads 0xc0 once started
inline constexpr std::uint64_t kRegStatus2 = 0x1082;       // reads 0x00 once started
inline constexpr std::uint8_t kStartValue = 0x08;
inline constexpr std::uint8_t kStopValue = 0x00;
inline constexpr std::uint32_t kVendorSensable = 0x000b99;

enum class TransportStatus : int {
  kOk = 0,
  kTimeout,        // no packet within the timeout
  kBusReset,       // the bus was reset: call recover()
  kDisconnected,   // the node is gone (unplugged, powered off)
  kIo,             // a transfer failed
  kBadPacket,      // a packet of the wrong size arrived (it is dropped)
};
// "ok", "timeout", "bus_reset", "disconnected", "io", "bad_packet"
const char* transport_status_name(TransportStatus s) noexcept;

// Where the node is and what it says it is.
struct NodeInfo {
  std::uint64_t guid = 0;      // EUI-64 from the config ROM
  std::uint32_t vendor = 0;    // from kRegVendorId (kVendorSensable)
  std::string serial;          // from kRegSerial, as text
  int port = -1;               // host adapter (card) index
  int node = -1;               // node id on that bus, -1: none
  std::uint32_t generation = 0;  // bus generation it was found in
  std::string description;     // e.g. "/dev/fw1 (port 0, node 1)"
};

// Counters a transport keeps (for the run's metadata and tests).
struct TransportStats {
  std::uint64_t received = 0;     // state packets delivered
  std::uint64_t sent = 0;         // command packets sent
  std::uint64_t bad_packets = 0;  // wrong-size packets dropped
  std::uint64_t timeouts = 0;
  std::uint64_t bus_resets = 0;
  std::uint64_t recoveries = 0;   // successful recover() calls
};

class Transport {
 public:
  virtual ~Transport() = default;

  virtual NodeInfo node() const = 0;

  // The start sequence: iso channels to kRegTxChannel / kRegRxChannel, the
  // iso receive and transmit set up, kStartValue to kRegStart. Throws
  // DeviceOpenError naming the register or call that failed.
  virtual void start() = 0;
  // kStopValue to kRegStart, iso stopped; idempotent.
  virtual void stop() noexcept = 0;

  // The newest device -> host packet since the last call (older ones are
  // dropped: the servo wants the latest state), waiting at most timeout_s.
  // On kOk, *size bytes were written to buf (capacity `capacity`); a
  // packet of the wrong size is reported as kBadPacket with *size its size.
  virtual TransportStatus receive(std::uint8_t* buf, std::size_t capacity,
                                  std::size_t* size,
                                  double timeout_s) noexcept = 0;
  // Queues one host -> device packet for the next iso cycle.
  virtual TransportStatus send(const std::uint8_t* data,
                               std::size_t size) noexcept = 0;
  // After kBusReset: find the node again (same GUID) and repeat the start
  // sequence. kOk when streaming again; kDisconnected when it is gone.
  virtual TransportStatus recover() noexcept = 0;

  virtual TransportStats stats() const noexcept = 0;
};

}  // namespace vmh::hw::fw

#endif  // VMHAPTICS_HW_FIREWIRE_TRANSPORT_H_
