// The FireWire Omni's bus through libraw1394 (Linux firewire-core, the
// /dev/fw* character devices), loaded at run time (raw1394_library.h).
// Every register, value and order below is from the public drivers of
// docs/sources.md §9.2, which says which driver each comes from and where
// they differ; NOT VERIFIED ON A DEVICE.
//
// Finding the Omni: every node of every port (host adapter) whose quadlet
// at kRegVendorId, read big-endian, is kVendorQuadletOmni (0x000b9900:
// SensAble's OUI in bits 31..8, as all three drivers compare it); its GUID
// from the bus information block of its configuration ROM (quadlets 3 and
// 4); its serial from kRegSerial, printed as two of the drivers unpack it.
// An optional GUID picks one of several.
//
// Start (start()): two isochronous channels claimed at the bus's resource
// manager; the receive context (44-byte packets) and the transmit context
// (16-byte packets, S100, first filled with zero words and the motors off)
// started; then the registers, each transaction tried again on EAGAIN
// (Raw1394Options::eagain_tries):
//   1. the host->device channel to kRegTxChannel, one byte
//   2. the device->host channel to kRegRxChannel, one byte
//   3. the quadlet k20010Bytes (00 00 0f f8) to kReg20010, unless
//      Raw1394Options::write_20010 is false (`firewire:GUID?no-20010`: one
//      driver left it out because two Omnis on one bus stopped streaming
//      steadily with it)
//   4. kRegRxChannel read back: must be the channel
//   5. kRxChannelTestValue (0x40) written to kRegRxChannel and read back,
//      then the channel written again
//   6. kRegStatus1 must read 0xc0 and kRegStatus2 0x00
//   7. kRegControl read, kControlStream set, written back
// Any step that fails names itself in the DeviceOpenError. Stop: a few
// cycles of the last command (the caller's zero packet), kControlStream
// cleared in kRegControl, the contexts shut down, the channels freed.
//
// Three libraw1394 handles on the Omni's port, because one handle carries
// one isochronous context: control (register transactions, bus-reset
// events), receive and transmit.
//
// Receiving keeps up with the device. libraw1394 hands over one
// isochronous interrupt (here: one packet) per raw1394_loop_iterate, so
// receive() iterates the receive handle until nothing is left, keeps every
// packet's arrival cycle, hands over the newest and counts the others
// (ReceiveInfo): 2000 packets a second read at 1 kHz is two packets a
// call, not one packet a call and a backlog that never drains. The first
// receive() after start() or recover() counts none late (there was no
// earlier receive), and discards a full buffer (the newest packet in it is
// stale: the ones after it were dropped) to wait for the next packet. A packet
// that arrived late_after_s or more before the newest one is late: it was
// there for an earlier receive(). send() services the transmit context:
// every slot the device has consumed since is refilled with the newest
// command, which it then sends every cycle until another replaces it.
//
// Bus reset: the control handle's bus-reset handler takes the new
// generation and marks it; the next receive() and send() return kBusReset;
// the caller calls recover(): find the node again by its GUID (its node id
// may have changed), claim the channels again (other ones, and the
// contexts restarted on them, if they were taken meanwhile), repeat the
// register sequence. A recovery that fails is tried again from a later
// receive() (every kRecoverEveryReceives), which returns kDisconnected in
// between.
//
// No adapter, no permission, no library: the constructor throws
// vmh::DeviceOpenError with a one-line cause; list_omni_nodes() returns the
// same cause instead of throwing.
#ifndef VMHAPTICS_HW_FIREWIRE_RAW1394_TRANSPORT_H_
#define VMHAPTICS_HW_FIREWIRE_RAW1394_TRANSPORT_H_

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hw/firewire/omni_packet.h"
#include "hw/firewire/raw1394_api.h"
#include "hw/firewire/transport.h"

namespace vmh::hw::fw {

class Raw1394Library;

// The udev rules that give the user's group access to /dev/fw* (named in
// error messages; the file is hw/udev/60-vmhaptics.rules).
inline constexpr const char* kUdevRulesFile = "hw/udev/60-vmhaptics.rules";

// the isochronous contexts: the receive buffer holds 32 ms of packets at
// 2000 a second, so that a servo loop held up that long loses none; the
// transmit buffer one servo period of cycles (8 at 8000 cycles a second),
// refilled by send(), so that a command waits at most that long
inline constexpr unsigned kRxBufferPackets = 64;
inline constexpr unsigned kRxMaxPacket = 64;  // > 44: a long packet is seen
inline constexpr unsigned kTxBufferPackets = 8;
inline constexpr int kIsoIrqInterval = 1;     // one wake-up per packet
inline constexpr double kIsoCyclesPerSecond = 8000.0;
// a failed recovery is tried again every this many receive() calls
inline constexpr int kRecoverEveryReceives = 100;

struct Raw1394Options {
  std::uint64_t guid = 0;  // 0: the first Omni found
  int port = -1;           // -1: search every port
  // write k20010Bytes to kReg20010 in the start sequence
  bool write_20010 = true;
  // a register transaction that fails with EAGAIN is tried up to this
  // many times in all (>= 1), eagain_delay_s apart
  int eagain_tries = 10;
  double eagain_delay_s = 0.01;
  // ReceiveInfo::late: how long before the newest packet a packet must
  // have arrived to count as late (> 0; the servo period)
  double late_after_s = 1e-3;
  // the libraw1394 to load (empty: Raw1394Library's default)
  std::string library;
  // throws std::invalid_argument naming the bad field
  void validate() const;
};

// "0x000b990012345678" or "000b990012345678" (hex, up to 16 digits) ->
// GUID. Throws std::invalid_argument naming the text. For
// `--device firewire:GUID`.
std::uint64_t parse_guid(const std::string& text);
// 16 hex digits, lower case, no prefix
std::string guid_text(std::uint64_t guid);
// The serial quadlet as two of the drivers print it: 11 digits from the
// fields a (bits 25..23), b (22..19), c (18..14), d (13..11), e (10..1),
// when bits 31 and 0 are set and bits 30..26 clear as their packing makes
// them; otherwise "0x" and the quadlet's 8 hex digits.
std::string serial_text(std::uint32_t serial_quadlet);

// Every Omni on every port, for `hw list`. Never throws. When none is
// found, *why_not (if given) says why in one line: no library, no adapter
// (0 ports), /dev/fw* present but not accessible (permissions:
// kUdevRulesFile), or N ports with M nodes and no Omni's vendor quadlet
// among them (naming SensAble nodes whose quadlet differs). Empty when
// Omnis were found.
std::vector<NodeInfo> list_omni_nodes(std::string* why_not,
                                      const Raw1394Options& options = {});

// What the start sequence did and read, for meta.json and `hw probe`.
struct StartRecord {
  int tx_channel = -1;  // host -> device
  int rx_channel = -1;  // device -> host
  bool wrote_20010 = false;
  int status1 = -1;     // kRegStatus1 as read (-1: not read)
  int status2 = -1;
  int control_before = -1;  // kRegControl before the stream bit was set
  int control_written = -1;
  int starts = 0;       // start() plus successful recoveries
};

class Raw1394Transport final : public Transport {
 public:
  // Loads libraw1394, finds the Omni (options.guid if non-zero) and opens
  // the handles. Throws vmh::DeviceOpenError with a one-line cause (no
  // library, no adapter, no permission on /dev/fw*, no Omni, no Omni with
  // that GUID, a handle not opened), std::invalid_argument for bad options.
  explicit Raw1394Transport(const Raw1394Options& options = {});
  ~Raw1394Transport() override;  // stop(), handles closed

  Raw1394Transport(const Raw1394Transport&) = delete;
  Raw1394Transport& operator=(const Raw1394Transport&) = delete;

  // the node found (call it outside the servo loop: recover() updates it)
  NodeInfo node() const override;
  void start() override;
  void stop() noexcept override;
  TransportStatus receive(std::uint8_t* buf, std::size_t capacity,
                          std::size_t* size, double timeout_s,
                          ReceiveInfo* info) noexcept override;
  TransportStatus send(const std::uint8_t* data,
                       std::size_t size) noexcept override;
  TransportStatus recover() noexcept override;
  TransportStats stats() const noexcept override;

  // what the last start or recovery did (outside the servo loop)
  StartRecord start_record() const { return record_; }
  const Raw1394Options& options() const noexcept { return options_; }
  const std::string& library_file() const noexcept;

 private:
  struct Handles;
  friend struct Raw1394Callbacks;

  // the register sequence; nullptr on success, else the step that failed
  const char* start_registers() noexcept;
  const char* claim_channels() noexcept;
  const char* start_iso() noexcept;
  void release_channels() noexcept;
  void shutdown_iso() noexcept;
  void close_handles() noexcept;
  bool find_node_again() noexcept;
  // register transactions, tried again on EAGAIN; false with errno set
  bool read_quadlet(r1394::NodeId node, r1394::NodeAddr addr,
                    std::uint32_t* out) noexcept;
  bool read_byte(r1394::NodeAddr addr, std::uint8_t* out) noexcept;
  bool write_byte(r1394::NodeAddr addr, std::uint8_t v) noexcept;
  bool write_bytes(r1394::NodeAddr addr, const std::uint8_t* v,
                   std::size_t n) noexcept;
  // runs the handlers of every event waiting on `h` (at most `limit`);
  // false when the handle's file descriptor reports an error
  bool drain(r1394::Handle h, int limit) noexcept;
  // waits up to timeout_s for the control or receive handle
  TransportStatus wait(double timeout_s) noexcept;
  // receive()'s steps (raw1394_transport.cc says each)
  TransportStatus await_batch(double timeout_s, std::size_t* size) noexcept;
  TransportStatus take_bus_reset() noexcept;
  void discard_stale_batch() noexcept;
  std::uint32_t count_late(std::uint32_t n) const noexcept;
  TransportStatus hand_over(std::uint8_t* buf, std::size_t capacity,
                            std::size_t* size, ReceiveInfo* info) noexcept;
  void on_packet(const unsigned char* data, unsigned int len,
                 unsigned int cycle) noexcept;

  Raw1394Options options_;
  std::shared_ptr<const Raw1394Library> lib_;
  const r1394::Api* api_ = nullptr;
  NodeInfo node_;
  std::string port_name_;  // " (name)" of the adapter, or empty
  StartRecord record_;
  Handles* h_ = nullptr;  // libraw1394 handles (kept out of this header)
  bool started_ = false;
  int tx_channel_ = -1;
  int rx_channel_ = -1;
  bool channels_claimed_ = false;
  bool rx_iso_ = false;  // an iso context was initialised on the handle
  bool tx_iso_ = false;

  // the receive handler's batch since the last receive() (servo thread)
  std::array<std::uint8_t, kStatePacketBytes> rx_packet_{};
  std::uint32_t batch_ = 0;       // good packets in this batch
  std::array<std::uint16_t, 256> batch_cycles_{};  // their arrival cycles
  bool rx_bad_ = false;           // the batch had a wrong-size packet
  std::size_t rx_bad_size_ = 0;
  unsigned late_cycles_ = 8;      // options_.late_after_s in bus cycles
  // the newest command, copied into each transmit slot
  std::array<std::uint8_t, kCommandPacketBytes> tx_packet_{};
  std::uint64_t tx_refills_ = 0;  // transmit slots filled
  bool reset_pending_ = false;    // a bus reset not yet returned
  bool needs_recovery_ = false;   // recover() failed: try again later
  bool fresh_start_ = false;      // no packet handed over since (re)start
  int receives_since_recovery_ = 0;

  char error_[160] = {};  // the last failed step, for start()
  std::atomic<std::uint64_t> received_{0}, delivered_{0}, superseded_{0},
      late_{0}, sent_{0}, bad_{0}, timeouts_{0}, resets_{0}, recoveries_{0},
      eagain_{0}, stale_{0};
};

}  // namespace vmh::hw::fw

#endif  // VMHAPTICS_HW_FIREWIRE_RAW1394_TRANSPORT_H_
