// The project's declarations of libraw1394 (hw/firewire/raw1394_api.h),
// which the transport calls through pointers resolved at run time, against
// libraw1394's own header: the same argument and return types for every
// function the API table holds, the same enumeration values and sizes, the
// same port-information layout and CSR addresses. Compiled only where the
// header is installed (libraw1394-dev); nothing is called.
#include <libraw1394/csr.h>
#include <libraw1394/raw1394.h>

#include <gtest/gtest.h>

#include <cstddef>
#include <type_traits>

#include "device/device_backend.h"
#include "hw/firewire/raw1394_api.h"
#include "hw/firewire/raw1394_library.h"

namespace vmh::hw::fw::r1394 {
namespace {

// the members of Api without an enumeration or a handler among their
// arguments have exactly libraw1394's types
#define VMH_SAME_TYPE(member)                                               \
  static_assert(std::is_same_v<decltype(Api::member),                      \
                               decltype(&::raw1394_##member)>,              \
                "raw1394_" #member " is not declared as libraw1394 does")
VMH_SAME_TYPE(new_handle);
VMH_SAME_TYPE(new_handle_on_port);
VMH_SAME_TYPE(destroy_handle);
VMH_SAME_TYPE(get_nodecount);
VMH_SAME_TYPE(get_local_id);
VMH_SAME_TYPE(get_generation);
VMH_SAME_TYPE(update_generation);
VMH_SAME_TYPE(set_userdata);
VMH_SAME_TYPE(get_userdata);
VMH_SAME_TYPE(get_fd);
VMH_SAME_TYPE(loop_iterate);
VMH_SAME_TYPE(busreset_notify);
VMH_SAME_TYPE(read);
VMH_SAME_TYPE(write);
VMH_SAME_TYPE(iso_recv_start);
VMH_SAME_TYPE(iso_xmit_start);
VMH_SAME_TYPE(iso_stop);
VMH_SAME_TYPE(iso_shutdown);
VMH_SAME_TYPE(set_bus_reset_handler);
#undef VMH_SAME_TYPE

// the types underneath
static_assert(std::is_same_v<Handle, raw1394handle_t>);
static_assert(std::is_same_v<NodeId, nodeid_t>);
static_assert(std::is_same_v<NodeAddr, nodeaddr_t>);
static_assert(std::is_same_v<Quadlet, quadlet_t>);
static_assert(std::is_same_v<BusResetHandler, bus_reset_handler_t>);

// get_port_info differs only in the struct's name: the same layout
static_assert(sizeof(PortInfo) == sizeof(raw1394_portinfo));
static_assert(offsetof(PortInfo, nodes) == offsetof(raw1394_portinfo, nodes));
static_assert(offsetof(PortInfo, name) == offsetof(raw1394_portinfo, name));
static_assert(sizeof(PortInfo::name) == sizeof(raw1394_portinfo::name));
static_assert(std::is_same_v<decltype(&::raw1394_get_port_info),
                             int (*)(raw1394handle_t, raw1394_portinfo*, int)>);

// the enumerations: values, and a size the calling convention passes alike
#define VMH_SAME_VALUE(ours, theirs) \
  static_assert(static_cast<int>(ours) == static_cast<int>(theirs), #ours)
VMH_SAME_VALUE(kIsoOk, RAW1394_ISO_OK);
VMH_SAME_VALUE(kIsoDefer, RAW1394_ISO_DEFER);
VMH_SAME_VALUE(kIsoError, RAW1394_ISO_ERROR);
VMH_SAME_VALUE(kIsoStop, RAW1394_ISO_STOP);
VMH_SAME_VALUE(kSpeed100, RAW1394_ISO_SPEED_100);
VMH_SAME_VALUE(kSpeed200, RAW1394_ISO_SPEED_200);
VMH_SAME_VALUE(kSpeed400, RAW1394_ISO_SPEED_400);
VMH_SAME_VALUE(kDmaDefault, RAW1394_DMA_DEFAULT);
VMH_SAME_VALUE(kDmaBufferFill, RAW1394_DMA_BUFFERFILL);
VMH_SAME_VALUE(kDmaPacketPerBuffer, RAW1394_DMA_PACKET_PER_BUFFER);
VMH_SAME_VALUE(kModifyAlloc, RAW1394_MODIFY_ALLOC);
VMH_SAME_VALUE(kModifyFree, RAW1394_MODIFY_FREE);
VMH_SAME_VALUE(kNotifyOn, RAW1394_NOTIFY_ON);
VMH_SAME_VALUE(kNotifyOff, RAW1394_NOTIFY_OFF);
#undef VMH_SAME_VALUE
static_assert(sizeof(Disposition) == sizeof(enum raw1394_iso_disposition));
static_assert(sizeof(Speed) == sizeof(enum raw1394_iso_speed));
static_assert(sizeof(DmaRecvMode) == sizeof(enum raw1394_iso_dma_recv_mode));
static_assert(sizeof(ModifyMode) == sizeof(enum raw1394_modify_mode));

// the functions whose arguments hold those enumerations or the handlers:
// the same arguments, with the project's enumerations in place of
// libraw1394's (checked above to be alike)
static_assert(std::is_same_v<decltype(&::raw1394_channel_modify),
                             int (*)(raw1394handle_t, unsigned int,
                                     enum raw1394_modify_mode)>);
static_assert(std::is_same_v<decltype(Api::channel_modify),
                             int (*)(Handle, unsigned int, ModifyMode)>);
static_assert(std::is_same_v<
              decltype(&::raw1394_iso_recv_init),
              int (*)(raw1394handle_t, raw1394_iso_recv_handler_t, unsigned int,
                      unsigned int, unsigned char,
                      enum raw1394_iso_dma_recv_mode, int)>);
static_assert(std::is_same_v<decltype(Api::iso_recv_init),
                             int (*)(Handle, IsoRecvHandler, unsigned int,
                                     unsigned int, unsigned char, DmaRecvMode,
                                     int)>);
static_assert(std::is_same_v<
              decltype(&::raw1394_iso_xmit_init),
              int (*)(raw1394handle_t, raw1394_iso_xmit_handler_t, unsigned int,
                      unsigned int, unsigned char, enum raw1394_iso_speed, int)>);
static_assert(std::is_same_v<decltype(Api::iso_xmit_init),
                             int (*)(Handle, IsoXmitHandler, unsigned int,
                                     unsigned int, unsigned char, Speed, int)>);
// the handlers: the same arguments, the disposition as the enum above
static_assert(std::is_same_v<raw1394_iso_recv_handler_t,
                             enum raw1394_iso_disposition (*)(
                                 raw1394handle_t, unsigned char*, unsigned int,
                                 unsigned char, unsigned char, unsigned char,
                                 unsigned int, unsigned int)>);
static_assert(std::is_same_v<IsoRecvHandler,
                             Disposition (*)(Handle, unsigned char*, unsigned int,
                                             unsigned char, unsigned char,
                                             unsigned char, unsigned int,
                                             unsigned int)>);
static_assert(std::is_same_v<raw1394_iso_xmit_handler_t,
                             enum raw1394_iso_disposition (*)(
                                 raw1394handle_t, unsigned char*, unsigned int*,
                                 unsigned char*, unsigned char*, int, unsigned int)>);
static_assert(std::is_same_v<IsoXmitHandler,
                             Disposition (*)(Handle, unsigned char*, unsigned int*,
                                             unsigned char*, unsigned char*, int,
                                             unsigned int)>);

// the CSR space
static_assert(kCsrRegisterBase == CSR_REGISTER_BASE);
static_assert(kCsrConfigRom == CSR_CONFIG_ROM);

// The declarations are checked at compile time above. At run time: the
// installed libraw1394 has every function the transport resolves.
TEST(FirewireRaw1394Abi, TheInstalledLibraryHasEveryFunction) {
  std::shared_ptr<const vmh::hw::fw::Raw1394Library> lib;
  try {
    lib = vmh::hw::fw::Raw1394Library::load(
        vmh::hw::fw::Raw1394Library::kDefaultName);
  } catch (const vmh::DeviceOpenError& e) {
    GTEST_SKIP() << "libraw1394 is not installed as a library here: " << e.what();
  }
  const Api& a = lib->api();
  const void* fns[] = {
      reinterpret_cast<const void*>(a.new_handle),
      reinterpret_cast<const void*>(a.new_handle_on_port),
      reinterpret_cast<const void*>(a.destroy_handle),
      reinterpret_cast<const void*>(a.get_port_info),
      reinterpret_cast<const void*>(a.read),
      reinterpret_cast<const void*>(a.write),
      reinterpret_cast<const void*>(a.loop_iterate),
      reinterpret_cast<const void*>(a.iso_recv_init),
      reinterpret_cast<const void*>(a.iso_xmit_init),
      reinterpret_cast<const void*>(a.iso_shutdown)};
  for (const void* f : fns) EXPECT_NE(f, nullptr);
  // and they are libraw1394's: the library's own raw1394_read
  EXPECT_EQ(reinterpret_cast<const void*>(a.read), lib->symbol("raw1394_read"));
}

}  // namespace
}  // namespace vmh::hw::fw::r1394
