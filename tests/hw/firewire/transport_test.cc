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
  EXPECT_EQ(kRegStart, 0x1087u);
  EXPECT_EQ(kRegStatus1, 0x1083u);
  EXPECT_EQ(kStartValue, 0x08);
  EXPECT_EQ(kStopValue, 0x00);
  EXPECT_EQ(kVendorSensable, 0x000b99u);
}

}  // namespace
}  // namespace vmh::hw::fw
