// The part of libraw1394's C interface the FireWire Omni's transport calls,
// declared by the project so that the library can be loaded at run time
// (raw1394_library.h) and a build needs neither libraw1394-dev nor the
// library itself. The declarations follow libraw1394 2.1.2's public header
// (<libraw1394/raw1394.h>, <libraw1394/csr.h>): the same C names, argument
// types and enumeration values. tests/hw/firewire/raw1394_abi_test.cc
// compares them with that header where it is installed; the test library
// of tests/hw/firewire/fwsim/ implements exactly these functions.
//
// Everything here is C: types and function pointers only, no definitions.
#ifndef VMHAPTICS_HW_FIREWIRE_RAW1394_API_H_
#define VMHAPTICS_HW_FIREWIRE_RAW1394_API_H_

#include <cstddef>
#include <cstdint>

// libraw1394's handle is a pointer to an opaque struct of this name; the
// name is the library's, so that a pointer declared here and one declared
// by <libraw1394/raw1394.h> are the same type.
extern "C" {
struct raw1394_handle;
}

namespace vmh::hw::fw::r1394 {

using Handle = ::raw1394_handle*;  // raw1394handle_t
using NodeId = std::uint16_t;      // nodeid_t: bus (10 bits), node (6 bits)
using NodeAddr = std::uint64_t;    // nodeaddr_t: a 48-bit address
using Quadlet = std::uint32_t;     // quadlet_t

// enum raw1394_iso_disposition (returned by the iso handlers)
enum Disposition : int { kIsoOk = 0, kIsoDefer = 1, kIsoError = 2, kIsoStop = 3 };
// enum raw1394_iso_speed
enum Speed : int { kSpeed100 = 0, kSpeed200 = 1, kSpeed400 = 2 };
// enum raw1394_iso_dma_recv_mode
enum DmaRecvMode : int {
  kDmaDefault = -1,
  kDmaBufferFill = 1,
  kDmaPacketPerBuffer = 2
};
// enum raw1394_modify_mode
enum ModifyMode : int { kModifyAlloc = 0, kModifyFree = 1 };
// raw1394_busreset_notify's switch
inline constexpr int kNotifyOff = 0;
inline constexpr int kNotifyOn = 1;

// the CSR space (IEEE 1212) and the bus information block of a node's
// configuration ROM: quadlet 0 the lengths, 1 "1394", 2 the capabilities,
// 3 node vendor id (bits 31..8) and chip id high (7..0), 4 chip id low;
// quadlets 3 and 4 are the node's EUI-64 (its GUID)
inline constexpr NodeAddr kCsrRegisterBase = 0xfffff0000000ull;
inline constexpr NodeAddr kCsrConfigRom = 0x400;
inline constexpr NodeAddr kConfigRomBase = kCsrRegisterBase + kCsrConfigRom;
inline constexpr NodeAddr kConfigRomGuidHi = kConfigRomBase + 0x0c;
inline constexpr NodeAddr kConfigRomGuidLo = kConfigRomBase + 0x10;
// node ids on the local bus: bus number 0x3ff, node 0..62 in the low 6 bits
inline constexpr NodeId kLocalBus = 0xffc0;

// struct raw1394_portinfo
struct PortInfo {
  int nodes;
  char name[32];
};

// raw1394_iso_recv_handler_t: one received packet (len bytes at data)
using IsoRecvHandler = Disposition (*)(Handle handle, unsigned char* data,
                                       unsigned int len, unsigned char channel,
                                       unsigned char tag, unsigned char sy,
                                       unsigned int cycle,
                                       unsigned int dropped);
// raw1394_iso_xmit_handler_t: fill one packet (at most the max packet size)
using IsoXmitHandler = Disposition (*)(Handle handle, unsigned char* data,
                                       unsigned int* len, unsigned char* tag,
                                       unsigned char* sy, int cycle,
                                       unsigned int dropped);
// bus_reset_handler_t
using BusResetHandler = int (*)(Handle handle, unsigned int generation);

// The functions, as pointers (raw1394_library.h resolves each by its C
// name, which is the member's name with the raw1394_ prefix).
struct Api {
  Handle (*new_handle)();
  Handle (*new_handle_on_port)(int port);
  void (*destroy_handle)(Handle handle);
  int (*get_port_info)(Handle handle, PortInfo* info, int max_ports);
  int (*get_nodecount)(Handle handle);
  NodeId (*get_local_id)(Handle handle);
  unsigned int (*get_generation)(Handle handle);
  void (*update_generation)(Handle handle, unsigned int generation);
  void (*set_userdata)(Handle handle, void* data);
  void* (*get_userdata)(Handle handle);
  int (*get_fd)(Handle handle);
  int (*loop_iterate)(Handle handle);
  BusResetHandler (*set_bus_reset_handler)(Handle handle, BusResetHandler h);
  int (*busreset_notify)(Handle handle, int off_on_switch);
  int (*read)(Handle handle, NodeId node, NodeAddr addr, std::size_t length,
              Quadlet* buffer);
  int (*write)(Handle handle, NodeId node, NodeAddr addr, std::size_t length,
               Quadlet* data);
  int (*channel_modify)(Handle handle, unsigned int channel, ModifyMode mode);
  int (*iso_recv_init)(Handle handle, IsoRecvHandler handler,
                       unsigned int buf_packets, unsigned int max_packet_size,
                       unsigned char channel, DmaRecvMode mode,
                       int irq_interval);
  int (*iso_recv_start)(Handle handle, int start_on_cycle, int tag_mask,
                        int sync);
  int (*iso_xmit_init)(Handle handle, IsoXmitHandler handler,
                       unsigned int buf_packets, unsigned int max_packet_size,
                       unsigned char channel, Speed speed, int irq_interval);
  int (*iso_xmit_start)(Handle handle, int start_on_cycle,
                        int prebuffer_packets);
  void (*iso_stop)(Handle handle);
  void (*iso_shutdown)(Handle handle);
};

}  // namespace vmh::hw::fw::r1394

#endif  // VMHAPTICS_HW_FIREWIRE_RAW1394_API_H_
