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
// Receiving keeps up: every receive() takes every packet that has arrived
// since the last one and hands over the newest, saying in ReceiveInfo how
// many arrived (so that the device layer tells packets the bus lost from
// packets it merely superseded) and how many of them were late.
//
// Real time: receive, send, recover and stop are noexcept and must not
// allocate; they return a TransportStatus.
#ifndef VMHAPTICS_HW_FIREWIRE_TRANSPORT_H_
#define VMHAPTICS_HW_FIREWIRE_TRANSPORT_H_

#include <cstddef>
#include <cstdint>
#include <string>

namespace vmh::hw::fw {

// The Omni's registers and constants on the bus (docs/sources.md §9.2 says
// which public driver each comes from; none is verified on a device by
// this project).
inline constexpr std::uint64_t kRegVendorId = 0x1006000c;  // quadlet: vendor
inline constexpr std::uint64_t kRegSerial = 0x10060010;    // quadlet: serial
inline constexpr std::uint64_t kRegTxChannel = 0x1000;     // host -> device iso channel
inline constexpr std::uint64_t kRegRxChannel = 0x1001;     // device -> host iso channel
inline constexpr std::uint64_t kRegControl = 0x1087;       // bit 3: stream
inline constexpr std::uint64_t kRegStatus1 = 0x1083;       // reads 0xc0 before start
inline constexpr std::uint64_t kRegStatus2 = 0x1082;       // reads 0x00 before start
inline constexpr std::uint64_t kReg20010 = 0x20010;        // quadlet, meaning unknown
inline constexpr std::uint8_t kControlStream = 0x08;       // bit 3 of kRegControl
inline constexpr std::uint8_t kStatus1Ready = 0xc0;
inline constexpr std::uint8_t kStatus2Ready = 0x00;
// the read-back test on kRegRxChannel (phantom-drivers): write this, read
// it back, then write the channel again
inline constexpr std::uint8_t kRxChannelTestValue = 0x40;
// The quadlet two drivers write to kReg20010, as it travels on the bus
// (big-endian, first byte first): they write the host-order value
// 0xf80f0000 from x86 memory, so the bytes are 00 00 0f f8.
inline constexpr std::uint8_t k20010Bytes[4] = {0x00, 0x00, 0x0f, 0xf8};
// The vendor quadlet at kRegVendorId read big-endian: SensAble's OUI
// 0x000b99 in bits 31..8, bits 7..0 zero (all three drivers compare the
// whole quadlet).
inline constexpr std::uint32_t kVendorSensable = 0x000b99;
inline constexpr std::uint32_t kVendorQuadletOmni = kVendorSensable << 8;

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
  std::uint32_t vendor = 0;    // from kRegVendorId: the OUI (kVendorSensable)
  std::uint32_t serial_quadlet = 0;  // kRegSerial as read (big-endian)
  std::string serial;          // the serial as the drivers print it
  int port = -1;               // host adapter (card) index
  int node = -1;               // node id on that bus, -1: none
  std::uint32_t generation = 0;  // bus generation it was found in
  std::string description;     // e.g. "port 0, node 1, GUID ..."
};

// Counters a transport keeps (for the run's metadata and tests).
struct TransportStats {
  std::uint64_t received = 0;     // state packets that arrived
  std::uint64_t delivered = 0;    // handed over by receive() (the newest)
  std::uint64_t superseded = 0;   // arrived, but a newer one was handed over
  std::uint64_t late = 0;         // arrived a receive late (ReceiveInfo)
  std::uint64_t sent = 0;         // command packets given to send()
  std::uint64_t bad_packets = 0;  // wrong-size packets dropped
  std::uint64_t timeouts = 0;
  std::uint64_t bus_resets = 0;
  std::uint64_t recoveries = 0;   // successful recover() calls
  std::uint64_t eagain_retries = 0;  // register transactions retried
  // packets queued before the first receive() after a start or recovery
  // that filled the receive buffer, discarded as stale
  std::uint64_t stale_at_start = 0;
};

// What one receive() took from the bus besides the packet it hands over.
struct ReceiveInfo {
  // packets that arrived since the last receive(), the one handed over
  // included (1 when the transport keeps pace with the device; 0 when it
  // returns no packet). A gap in the device's counter larger than this is
  // packets the bus lost.
  std::uint32_t packets = 0;
  // of those, packets that had arrived a servo period or more before the
  // newest one: they were there for an earlier receive() that did not run
  // or did not get them
  std::uint32_t late = 0;
};

class Transport {
 public:
  virtual ~Transport() = default;

  virtual NodeInfo node() const = 0;

  // The start sequence: iso channels to kRegTxChannel / kRegRxChannel, the
  // iso receive and transmit set up, kControlStream set in kRegControl
  // (Raw1394Transport says every step). Throws DeviceOpenError naming the
  // register or call that failed.
  virtual void start() = 0;
  // kControlStream cleared in kRegControl, iso stopped; idempotent.
  virtual void stop() noexcept = 0;

  // Takes every device -> host packet that has arrived since the last call
  // and writes the newest to buf (the servo wants the latest state; the
  // older ones are counted in *info, which may be null), waiting at most
  // timeout_s for one when none has. On kOk, *size bytes were written to
  // buf (capacity `capacity`); a packet of the wrong size is reported as
  // kBadPacket with *size its size.
  virtual TransportStatus receive(std::uint8_t* buf, std::size_t capacity,
                                  std::size_t* size, double timeout_s,
                                  ReceiveInfo* info) noexcept = 0;
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
