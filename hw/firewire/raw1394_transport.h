// The FireWire Omni's bus through libraw1394 (Linux firewire-core, the
// /dev/fw* character devices). Built only where pkg-config finds libraw1394
// (VMH_HAVE_RAW1394; Debian: libraw1394-dev).
//
// Finding the Omni: every node of every port (host adapter) whose quadlet
// at kRegVendorId reads kVendorSensable in its low 24 bits; its GUID from
// the bus information block of its configuration ROM (IEEE 1212: quadlets 3
// and 4, at 0xfffff000040c and 0xfffff0000410); its serial from kRegSerial.
// An optional GUID picks one of several.
//
// Start sequence (transport.h, docs/sources.md §9.2): two isochronous
// channels are claimed at the bus's isochronous resource manager, the
// receive (44-byte packets) and transmit (16-byte packets, S100) contexts
// started on them, the channel numbers written to kRegTxChannel and
// kRegRxChannel (one byte each, as the drivers of §9.2 write them),
// kRegStatus1 checked to read 0xc0, and kStartValue written to kRegStart.
//
// Three libraw1394 handles on the Omni's port, because one handle carries
// one isochronous context: control (register reads and writes, bus-reset
// events), receive and transmit. receive() polls all three: a bus-reset
// event makes it return kBusReset; the receive handler copies the newest
// 44-byte packet into a buffer the transport owns; the transmit handler
// sends the newest packet given to send(), again every iso cycle until
// another replaces it (zero-order hold).
//
// NOT VERIFIED ON A DEVICE: every register, value and width above, the
// channel directions, the vendor quadlet's format, the serial's format.
#ifndef VMHAPTICS_HW_FIREWIRE_RAW1394_TRANSPORT_H_
#define VMHAPTICS_HW_FIREWIRE_RAW1394_TRANSPORT_H_

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hw/firewire/omni_packet.h"
#include "hw/firewire/transport.h"

namespace vmh::hw::fw {

// The udev rules that give the user's group access to /dev/fw* (named in
// error messages; the file is hw/udev/60-vmhaptics.rules).
inline constexpr const char* kUdevRulesFile = "hw/udev/60-vmhaptics.rules";

struct Raw1394Options {
  std::uint64_t guid = 0;  // 0: the first Omni found
  int port = -1;           // -1: search every port
};

// "0x000b990012345678" or "000b990012345678" (hex, up to 16 digits) ->
// GUID. Throws std::invalid_argument naming the text. For
// `--device firewire:GUID`.
std::uint64_t parse_guid(const std::string& text);
// 16 hex digits, lower case, no prefix
std::string guid_text(std::uint64_t guid);

// Every Omni on every port, for `hw list`. Never throws. When none is
// found, *why_not (if given) says why in one line: no adapter (0 ports),
// /dev/fw* present but not accessible (permissions: kUdevRulesFile), or
// N ports with M nodes and no SensAble vendor quadlet among them. Empty
// when nodes were found.
std::vector<NodeInfo> list_omni_nodes(std::string* why_not);

class Raw1394Transport final : public Transport {
 public:
  // Finds the Omni (options.guid if non-zero) and opens the handles. Throws
  // vmh::DeviceOpenError with a one-line cause (no adapter, no permission on
  // /dev/fw*, no Omni, no Omni with that GUID, a handle not opened).
  explicit Raw1394Transport(const Raw1394Options& options = {});
  ~Raw1394Transport() override;  // stop(), handles closed, channels freed

  Raw1394Transport(const Raw1394Transport&) = delete;
  Raw1394Transport& operator=(const Raw1394Transport&) = delete;

  // the node found (call it outside the servo loop: recover() updates it)
  NodeInfo node() const override { return node_; }
  void start() override;
  void stop() noexcept override;
  TransportStatus receive(std::uint8_t* buf, std::size_t capacity,
                          std::size_t* size, double timeout_s) noexcept override;
  TransportStatus send(const std::uint8_t* data,
                       std::size_t size) noexcept override;
  // Re-finds the node by its GUID on the same port, claims the channels
  // again and repeats the register sequence. The isochronous contexts run
  // on the local adapter and are kept across the reset, so nothing is
  // allocated here by this class (libraw1394's own transactions may).
  TransportStatus recover() noexcept override;
  TransportStats stats() const noexcept override;

 private:
  struct Handles;
  // the register sequence; nullptr on success, else the step that failed
  const char* start_registers() noexcept;
  const char* claim_channels() noexcept;
  void release_channels() noexcept;
  void shutdown_iso() noexcept;
  void close_handles() noexcept;
  bool find_node_again() noexcept;
  TransportStatus pump(double timeout_s) noexcept;

  friend struct Raw1394Callbacks;

  Raw1394Options options_;
  NodeInfo node_;
  Handles* h_ = nullptr;  // libraw1394 handles (kept out of this header)
  bool started_ = false;
  int tx_channel_ = -1;   // host -> device
  int rx_channel_ = -1;   // device -> host
  bool channels_claimed_ = false;
  bool rx_iso_ = false;  // an iso context was initialised on the handle
  bool tx_iso_ = false;

  // written by the receive handler (on the servo thread, inside receive())
  std::array<std::uint8_t, kStatePacketBytes> rx_packet_{};
  std::size_t rx_size_ = 0;
  bool rx_fresh_ = false;
  bool rx_bad_ = false;
  // read by the transmit handler
  std::array<std::uint8_t, kCommandPacketBytes> tx_packet_{};
  bool reset_pending_ = false;

  char error_[128] = {};  // the last failed step, for recover()/start()
  std::atomic<std::uint64_t> received_{0}, sent_{0}, bad_{0}, timeouts_{0},
      resets_{0}, recoveries_{0};
};

}  // namespace vmh::hw::fw

#endif  // VMHAPTICS_HW_FIREWIRE_RAW1394_TRANSPORT_H_
