// transport_status_name and the register constants of hw/firewire/transport.h
#include "hw/firewire/transport.h"

#include <gtest/gtest.h>

namespace vmh::hw::fw {
namespace {

TEST(FirewireTransport, StatusNames) {
  EXPECT_STREQ(transport_status_name(TransportStatus::kOk), "ok");
  EXPECT_STREQ(transport_status_name(TransportStatus::kTimeout), "timeout");
  EXPECT_STREQ(transport_status_name(TransportStatus::kBusReset), "bus_reset");
  EXPECT_STREQ(transport_status_name(TransportStatus::kDisconnected),
               "disconnected");
  EXPECT_STREQ(transport_status_name(TransportStatus::kIo), "io");
  EXPECT_STREQ(transport_status_name(TransportStatus::kBadPacket),
               "bad_packet");
  EXPECT_STREQ(transport_status_name(static_cast<TransportStatus>(99)),
               "unknown");
}

TEST(FirewireTransport, RegistersAsDocsSourcesSection92) {
  EXPECT_EQ(kRegVendorId, 0x1006000cu);
  EXPECT_EQ(kRegSerial, 0x10060010u);
  EXPECT_EQ(kRegTxChannel, 0x1000u);
  EXPECT_EQ(kRegRxChannel, 0x1001u);
  EXPECT_EQ(kRegControl, 0x1087u);
  EXPECT_EQ(kRegStatus1, 0x1083u);
  EXPECT_EQ(kRegStatus2, 0x1082u);
  EXPECT_EQ(kReg20010, 0x20010u);
  EXPECT_EQ(kControlStream, 0x08);
  EXPECT_EQ(kStatus1Ready, 0xc0);
  EXPECT_EQ(kStatus2Ready, 0x00);
  EXPECT_EQ(kRxChannelTestValue, 0x40);
  EXPECT_EQ(kVendorSensable, 0x000b99u);
  // the whole vendor quadlet, big-endian: the OUI in bits 31..8
  EXPECT_EQ(kVendorQuadletOmni, 0x000b9900u);
  // 0xf80f0000 as x86 memory holds it, first byte first
  const std::uint32_t host = 0xf80f0000u;
  std::uint8_t bytes[4];
  for (int i = 0; i < 4; ++i) bytes[i] = static_cast<std::uint8_t>(host >> (8 * i));
  for (int i = 0; i < 4; ++i) EXPECT_EQ(k20010Bytes[i], bytes[i]) << i;
}

}  // namespace
}  // namespace vmh::hw::fw
