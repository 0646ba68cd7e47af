// The libraw1394 transport (hw/firewire/raw1394_transport.h) and the
// device on it, over the libraw1394 stand-in (fwsim/fwsim.h) on its
// virtual clock: every verdict is exact and independent of the machine's
// load. What the public drivers say an Omni does (docs/sources.md §9.2) is
// what the stand-in's Omni does; the tests check the bus code against it:
// the vendor test, the start sequence's bytes, addresses and order, the
// read-backs, EAGAIN retried, keeping up with 2000 packets a second, late
// packets apart from lost ones, a bus reset in the middle of a run, two
// Omnis on one bus, the stop, and no allocation on the servo path.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "device/device_backend.h"
#include "hw/firewire/firewire_omni.h"
#include "hw/firewire/raw1394_api.h"
#include "hw/firewire/raw1394_library.h"
#include "hw/firewire/raw1394_transport.h"
#include "tests/hw/firewire/fwsim/fwsim_client.h"
#include "tests/support/alloc_counter.h"

namespace vmh::hw::fw {
namespace {

using vmh::testing::Fwsim;

constexpr std::uint64_t kGuidA = 0x000b9900000a0a0aull;
constexpr std::uint64_t kGuidB = 0x000b9900000b0b0bull;
constexpr std::uint64_t kGuidCamera = 0x0000aa0000c0ffeeull;

const Fwsim& bus() {
  static const Fwsim f(VMH_FWSIM_LIBRARY);
  return f;
}

Raw1394Options options(std::uint64_t guid = 0) {
  Raw1394Options o;
  o.library = VMH_FWSIM_LIBRARY;
  o.guid = guid;
  o.eagain_delay_s = 0.0;  // the virtual bus does not need the time
  return o;
}

// the transactions with one node, in order
std::vector<fwsim_transaction> with(std::uint64_t guid) {
  std::vector<fwsim_transaction> out;
  for (const fwsim_transaction& t : bus().log()) {
    if (t.guid == guid) out.push_back(t);
  }
  return out;
}

std::string describe(const fwsim_transaction& t) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%c 0x%llx len %u data %02x %02x %02x %02x err %d",
                t.op, static_cast<unsigned long long>(t.addr), t.len, t.data[0],
                t.data[1], t.data[2], t.data[3], t.error);
  return buf;
}

// -- finding the Omni --

TEST(FirewireBus, TheVendorQuadletIsReadAsTheDriversReadIt) {
  // An Omni answers 0x000b9900 (big-endian: SensAble's OUI in bits
  // 31..8). A node answering 0x00000b99 (the OUI in bits 23..0, which the
  // transport once expected) and one answering 0x000b9901 are not Omnis.
  bus().setup("omni=000b9900000a0a0a;node=0000000000000b99,vendor=00000b99;"
              "node=000b990100000001,vendor=000b9901;node=0000aa0000c0ffee");
  std::string why = "unchanged";
  const std::vector<NodeInfo> found = list_omni_nodes(&why, options());
  ASSERT_EQ(found.size(), 1u) << why;
  EXPECT_EQ(why, "");
  EXPECT_EQ(found[0].guid, kGuidA);
  EXPECT_EQ(found[0].vendor, 0x000b99u);
  EXPECT_EQ(found[0].port, 0);
  EXPECT_EQ(found[0].node, 0);
  // the serial the stand-in packed as the drivers pack one: 11 digits
  EXPECT_EQ(found[0].serial.size(), 11u) << found[0].serial;
  EXPECT_EQ(found[0].serial, serial_text(found[0].serial_quadlet));
  EXPECT_NE(found[0].description.find("GUID 000b9900000a0a0a"), std::string::npos);

  // without it: why not, naming the SensAble node that is not an Omni
  bus().setup("node=0000000000000b99,vendor=00000b99;"
              "node=000b990100000001,vendor=000b9901;node=0000aa0000c0ffee");
  EXPECT_TRUE(list_omni_nodes(&why, options()).empty());
  EXPECT_NE(why.find("no PHANTOM Omni (vendor quadlet 0x000b9900) among 3 node(s) "
                     "on 1 port(s)"),
            std::string::npos) << why;
  EXPECT_NE(why.find("port 0 node 1: 0x000b9901"), std::string::npos) << why;
  EXPECT_EQ(why.find('\n'), std::string::npos);
  try {
    Raw1394Transport t(options());
    ADD_FAILURE() << "opened a node that is not an Omni";
  } catch (const DeviceOpenError& e) {
    EXPECT_EQ(std::string(e.what()), why);
  }
}

TEST(FirewireBus, AGuidPicksOneOfTwoAndAWrongOneIsNamed) {
  bus().setup("omni=000b9900000a0a0a;omni=000b9900000b0b0b");
  EXPECT_EQ(list_omni_nodes(nullptr, options()).size(), 2u);
  Raw1394Transport b(options(kGuidB));
  EXPECT_EQ(b.node().guid, kGuidB);
  EXPECT_EQ(b.node().node, 1);
  try {
    Raw1394Transport t(options(0x000b99000000dead));
    ADD_FAILURE() << "opened a GUID that is not on the bus";
  } catch (const DeviceOpenError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("no PHANTOM Omni with GUID 000b99000000dead"), std::string::npos) << m;
    EXPECT_NE(m.find("found 000b9900000a0a0a 000b9900000b0b0b"), std::string::npos) << m;
  }
}

// -- the start sequence --

TEST(FirewireBus, StartWritesTheDriversSequence) {
  bus().setup("omni=000b9900000a0a0a");
  Raw1394Transport t(options());
  bus().log_clear();
  t.start();
  const StartRecord r = t.start_record();
  ASSERT_EQ(r.tx_channel, 0);
  ASSERT_EQ(r.rx_channel, 1);
  // every transaction, in order: address, length, bytes on the bus
  struct Want {
    char op;
    std::uint64_t addr;
    std::uint32_t len;
    std::uint8_t data[4];
  };
  const Want want[] = {
      {'w', 0x1000, 1, {0x00}},                    // host -> device channel
      {'w', 0x1001, 1, {0x01}},                    // device -> host channel
      {'w', 0x20010, 4, {0x00, 0x00, 0x0f, 0xf8}}, // 0xf80f0000 from x86
      {'r', 0x1001, 1, {0x01}},                    // the channel reads back
      {'w', 0x1001, 1, {0x40}},                    // the register test
      {'r', 0x1001, 1, {0x40}},
      {'w', 0x1001, 1, {0x01}},                    // the channel again
      {'r', 0x1083, 1, {0xc0}},                    // ready
      {'r', 0x1082, 1, {0x00}},
      {'r', 0x1087, 1, {0x00}},                    // control, then bit 3 set
      {'w', 0x1087, 1, {0x08}},
  };
  const std::vector<fwsim_transaction> got = with(kGuidA);
  ASSERT_EQ(got.size(), std::size(want));
  for (std::size_t i = 0; i < got.size(); ++i) {
    SCOPED_TRACE(describe(got[i]));
    EXPECT_EQ(got[i].op, want[i].op) << i;
    EXPECT_EQ(got[i].addr, want[i].addr) << i;
    EXPECT_EQ(got[i].len, want[i].len) << i;
    EXPECT_EQ(std::memcmp(got[i].data, want[i].data, want[i].len), 0) << i;
    EXPECT_EQ(got[i].error, 0) << i;
  }
  const fwsim_node_info n = bus().info(kGuidA);
  EXPECT_TRUE(n.streaming);
  EXPECT_EQ(n.reg_tx_channel, 0);
  EXPECT_EQ(n.reg_rx_channel, 1);
  EXPECT_EQ(n.reg_control, 0x08);
  ASSERT_TRUE(n.wrote_20010);
  const std::uint8_t wire[4] = {0x00, 0x00, 0x0f, 0xf8};
  EXPECT_EQ(std::memcmp(n.reg_20010, wire, 4), 0);
  EXPECT_TRUE(r.wrote_20010);
  EXPECT_EQ(r.status1, 0xc0);
  EXPECT_EQ(r.status2, 0x00);
  EXPECT_EQ(r.control_before, 0x00);
  EXPECT_EQ(r.control_written, 0x08);
  EXPECT_EQ(r.starts, 1);
}

TEST(FirewireBus, No20010LeavesTheWriteOut) {
  bus().setup("omni=000b9900000a0a0a");
  Raw1394Options o = options();
  o.write_20010 = false;
  Raw1394Transport t(o);
  bus().log_clear();
  t.start();
  for (const fwsim_transaction& x : with(kGuidA)) {
    EXPECT_NE(x.addr, 0x20010u) << describe(x);
  }
  EXPECT_FALSE(bus().info(kGuidA).wrote_20010);
  EXPECT_FALSE(t.start_record().wrote_20010);
  EXPECT_TRUE(bus().info(kGuidA).streaming);
}

TEST(FirewireBus, ARegisterThatDoesNotReadBackStopsTheStart) {
  bus().setup("omni=000b9900000a0a0a,quirk=no-readback");
  {
    Raw1394Transport t(options());
    try {
      t.start();
      ADD_FAILURE() << "started a device whose 0x1001 does not read back";
    } catch (const DeviceOpenError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("0x1001 reads back 0x3f, not the channel 1 written"),
                std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos);
    }
    // nothing left streaming, the channels given back
    EXPECT_FALSE(bus().info(kGuidA).streaming);
  }
  bus().setup("omni=000b9900000a0a0a,quirk=not-ready");
  Raw1394Transport t(options());
  try {
    t.start();
    ADD_FAILURE() << "started a device whose 0x1083 is not 0xc0";
  } catch (const DeviceOpenError& e) {
    EXPECT_NE(std::string(e.what()).find("0x1083 reads 0x40, not 0xc0"), std::string::npos)
        << e.what();
  }
  // no stream bit was ever written
  for (const fwsim_transaction& x : with(kGuidA)) {
    EXPECT_FALSE(x.op == 'w' && x.addr == 0x1087) << describe(x);
  }
}

TEST(FirewireBus, EagainIsTriedAgainAndGivesUpNamingTheStep) {
  bus().setup("omni=000b9900000a0a0a");
  Raw1394Transport t(options());
  // the next three transactions are refused busy: tried again, started
  bus().eagain(0, 3);
  t.start();
  EXPECT_EQ(bus().eagain_count(), 3);
  EXPECT_EQ(t.stats().eagain_retries, 3u);
  EXPECT_TRUE(bus().info(kGuidA).streaming);
  t.stop();
  // a device that stays busy: ten tries, then the step is named
  Raw1394Options o = options();
  o.eagain_tries = 10;
  Raw1394Transport u(o);
  bus().eagain(0, 1000);
  const long before = bus().eagain_count();
  try {
    u.start();
    ADD_FAILURE() << "started through a bus that refused every transaction";
  } catch (const DeviceOpenError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("writing the host->device channel to 0x1000 failed"),
              std::string::npos) << m;
    EXPECT_NE(m.find(std::strerror(EAGAIN)), std::string::npos) << m;
  }
  EXPECT_EQ(bus().eagain_count() - before, 10);
  bus().eagain(0, 0);
}

TEST(FirewireBus, EveryNthTransactionBusyStillStarts) {
  // "now and then": every third transaction refused
  bus().setup("omni=000b9900000a0a0a;eagain=3");
  Raw1394Transport t(options());
  t.start();
  EXPECT_GT(t.stats().eagain_retries, 3u);
  EXPECT_TRUE(bus().info(kGuidA).streaming);
  EXPECT_EQ(bus().info(kGuidA).reg_rx_channel, 1);
}

// -- streaming --

// The stand-in's premise, libraw1394's on firewire-core: one receive
// interrupt (here one packet) per raw1394_loop_iterate. A reader that
// iterates once a tick falls behind a device that sends two a tick.
TEST(FirewireBus, TheStandInHandsOverOnePacketPerIterate) {
  bus().setup("omni=000b9900000a0a0a,rate=2000");
  Raw1394Transport t(options());  // configures the bus's Omni
  t.start();
  const auto lib = Raw1394Library::load(VMH_FWSIM_LIBRARY);
  const r1394::Api& a = lib->api();
  // a second receiver on the Omni's channel, iterated by hand
  static int packets = 0;
  packets = 0;
  r1394::Handle h = a.new_handle_on_port(0);
  ASSERT_NE(h, nullptr);
  ASSERT_EQ(a.iso_recv_init(
                h,
                [](r1394::Handle, unsigned char*, unsigned int, unsigned char,
                   unsigned char, unsigned char, unsigned int, unsigned int) {
                  ++packets;
                  return r1394::kIsoOk;
                },
                64, 64, 1, r1394::kDmaPacketPerBuffer, 1),
            0);
  ASSERT_EQ(a.iso_recv_start(h, -1, -1, 0), 0);
  bus().advance_ms(10);  // 20 packets
  int calls = 0;
  for (int k = 0; k < 10; ++k) {
    a.loop_iterate(h);
    ++calls;
  }
  EXPECT_EQ(packets, calls);  // one a call: half of what came
  while (a.loop_iterate(h) == 0) {
  }
  EXPECT_EQ(packets, 20);
  a.destroy_handle(h);
}

// What keeping up means: the reading moves at the device's speed. 2000
// packets a second read at 1 kHz for one second of bus time; each tick
// takes both packets that came and hands over the newer.
TEST(FirewireBus, KeepsUpWith2000PacketsASecond) {
  bus().setup("omni=000b9900000a0a0a,rate=2000,speed=3000/-1500/600");
  Raw1394Transport t(options());
  FirewireOmni omni(&t, FirewireOmniOptions{});
  t.start();
  DeviceState st;
  std::array<std::int32_t, 3> first{};
  std::int64_t first_ns = 0;
  const int ticks = 1000;
  for (int k = 0; k < ticks; ++k) {
    bus().advance_ms(1.0);
    ASSERT_EQ(omni.read_state(&st), DeviceError::kOk) << k;
    if (k == 9) {  // after the first packets settle the unwrap
      first = st.encoder_counts;
      first_ns = bus().info(kGuidA).last_packet_ns;
    }
  }
  const fwsim_node_info n = bus().info(kGuidA);
  const double dt_s = 1e-9 * static_cast<double>(n.last_packet_ns - first_ns);
  const double speed[3] = {3000, -1500, 600};
  for (int i = 0; i < 3; ++i) {
    const double moved = st.encoder_counts[static_cast<std::size_t>(i)] -
                         first[static_cast<std::size_t>(i)];
    // whole counts: within one of the device's own travel
    EXPECT_NEAR(moved, speed[i] * dt_s, 1.0) << "encoder " << i + 1;
    const double ratio = moved / (speed[i] * dt_s);
    EXPECT_NEAR(ratio, 1.0, 2e-3) << "encoder " << i + 1;
    if (i == 0) ::testing::Test::RecordProperty("speed_ratio_2000", std::to_string(ratio));
    // and the reading is the newest packet: no backlog at all
    EXPECT_EQ(st.encoder_counts[static_cast<std::size_t>(i)], n.encoder_counts[i]) << i;
  }
  const FirewireOmniStats s = omni.stats();
  EXPECT_EQ(s.packets, static_cast<std::uint64_t>(ticks));
  EXPECT_EQ(s.superseded_packets, static_cast<std::uint64_t>(ticks));  // one a tick
  EXPECT_EQ(s.lost_packets, 0u);
  EXPECT_EQ(s.late_packets, 0u);
  EXPECT_EQ(n.packets_dropped, 0u);
  EXPECT_EQ(t.stats().received, 2u * ticks);
}

TEST(FirewireBus, AMissedTickIsLateNotLag) {
  // 1000 packets a second at 1 kHz: one a tick. A tick that does not run
  // leaves two for the next; the older one is late, the reading is the
  // newer, and the tick after is back to one: no lag left behind.
  bus().setup("omni=000b9900000a0a0a,rate=1000,speed=1000/0/0");
  Raw1394Transport t(options());
  FirewireOmni omni(&t, FirewireOmniOptions{});
  t.start();
  DeviceState st;
  for (int k = 0; k < 50; ++k) {
    bus().advance_ms(1.0);
    ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
  }
  EXPECT_EQ(omni.stats().late_packets, 0u);
  bus().advance_ms(2.0);  // the missed tick
  ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
  EXPECT_EQ(omni.stats().late_packets, 1u);
  EXPECT_EQ(omni.stats().superseded_packets, 1u);
  EXPECT_EQ(st.encoder_counts[0], bus().info(kGuidA).encoder_counts[0]);
  for (int k = 0; k < 50; ++k) {
    bus().advance_ms(1.0);
    ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
  }
  // the reading is the device's newest count, not one packet behind
  EXPECT_EQ(st.encoder_counts[0], bus().info(kGuidA).encoder_counts[0]);
  EXPECT_EQ(t.stats().late, 1u);
  EXPECT_EQ(omni.stats().lost_packets, 0u);
  // three missed ticks: three late (every packet a period or more older
  // than the newest), none lost
  bus().advance_ms(4.0);
  ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
  const FirewireOmniStats s = omni.stats();
  EXPECT_EQ(s.late_packets, 1u + 3u);
  EXPECT_EQ(s.lost_packets, 0u);
  EXPECT_EQ(st.encoder_counts[0], bus().info(kGuidA).encoder_counts[0]);
}

TEST(FirewireBus, PacketsTheHostBufferCouldNotHoldAreLost) {
  // 100 ms without a tick at 1000 a second: the receive buffer holds 64,
  // the other 36 are dropped; the counter says 36 lost, the other 63 of
  // the batch late.
  bus().setup("omni=000b9900000a0a0a,rate=1000");
  Raw1394Transport t(options());
  FirewireOmni omni(&t, FirewireOmniOptions{});
  t.start();
  DeviceState st;
  bus().advance_ms(1.0);
  ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
  bus().advance_ms(100.0);
  // the buffer kept the first 64; the newest of them is handed over
  ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
  const fwsim_node_info n = bus().info(kGuidA);
  EXPECT_EQ(n.packets_dropped, 100u - kRxBufferPackets);
  FirewireOmniStats s = omni.stats();
  EXPECT_EQ(s.late_packets, kRxBufferPackets - 1u);
  EXPECT_EQ(s.superseded_packets, kRxBufferPackets - 1u);
  EXPECT_EQ(s.lost_packets, 0u);  // not yet: the counter has not moved past them
  // the next packet's counter has: the 36 dropped are lost
  bus().advance_ms(1.0);
  ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
  s = omni.stats();
  EXPECT_EQ(s.lost_packets, n.packets_dropped);
  EXPECT_EQ(s.late_packets, kRxBufferPackets - 1u);
}

TEST(FirewireBus, WhatQueuedBeforeTheFirstTickIsNeitherLateNorLost) {
  // The stream starts in start(); the servo loop's first tick comes when
  // its thread is set up. What queued meanwhile came before any receive:
  // none of it is late.
  bus().setup("omni=000b9900000a0a0a,rate=1000,speed=1000/0/0");
  {
    Raw1394Transport t(options());
    FirewireOmni omni(&t, FirewireOmniOptions{});
    t.start();
    DeviceState st;
    bus().advance_ms(10.0);
    ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
    EXPECT_EQ(omni.stats().superseded_packets, 9u);
    EXPECT_EQ(omni.stats().late_packets, 0u);
    EXPECT_EQ(st.encoder_counts[0], bus().info(kGuidA).encoder_counts[0]);
    EXPECT_EQ(t.stats().stale_at_start, 0u);
  }
  // A first tick 100 ms late found the buffer full (64 of 100 kept): the
  // newest it holds is 36 ms old and the ones after it were dropped. It is
  // discarded, and the next packet is the loop's first: nothing stale
  // handed over, nothing counted lost or late.
  bus().setup("omni=000b9900000a0a0a,rate=1000,speed=1000/0/0");
  Raw1394Transport t(options());
  FirewireOmni omni(&t, FirewireOmniOptions{});
  t.start();
  DeviceState st;
  bus().advance_ms(100.0);
  EXPECT_EQ(omni.read_state(&st), DeviceError::kTimeout);  // nothing fresh
  EXPECT_EQ(t.stats().stale_at_start, kRxBufferPackets);
  EXPECT_EQ(bus().info(kGuidA).packets_dropped, 100u - kRxBufferPackets);
  for (int k = 0; k < 10; ++k) {
    bus().advance_ms(1.0);
    ASSERT_EQ(omni.read_state(&st), DeviceError::kOk) << k;
    EXPECT_EQ(st.encoder_counts[0], bus().info(kGuidA).encoder_counts[0]) << k;
  }
  const FirewireOmniStats s = omni.stats();
  EXPECT_EQ(s.lost_packets, 0u);
  EXPECT_EQ(s.late_packets, 0u);
  EXPECT_EQ(s.superseded_packets, 0u);
  EXPECT_EQ(s.packets, 10u);
}

TEST(FirewireBus, NothingArrivedIsATimeout) {
  bus().setup("omni=000b9900000a0a0a");
  Raw1394Transport t(options());
  t.start();
  std::uint8_t buf[64];
  std::size_t size = 0;
  ReceiveInfo info;
  EXPECT_EQ(t.receive(buf, sizeof buf, &size, 1e-4, &info), TransportStatus::kTimeout);
  EXPECT_EQ(info.packets, 0u);
  EXPECT_EQ(t.stats().timeouts, 1u);
}

// -- commands --

TEST(FirewireBus, TheNewestCommandGoesOutEveryCycle) {
  bus().setup("omni=000b9900000a0a0a");
  Raw1394Transport t(options());
  FirewireOmniOptions fo;
  fo.full_scale_Nm = {1.0, 1.0, 1.0};
  FirewireOmni omni(&t, fo);
  t.start();
  // before any command: zero words, motors off (the transmit buffer's
  // first fill)
  bus().advance_ms(1.0);
  CommandPacket c;
  fwsim_node_info n = bus().info(kGuidA);
  ASSERT_GT(n.commands, 0u);
  ASSERT_EQ(decode_command(n.last_command, 16, &c), PacketError::kOk);
  EXPECT_FALSE(c.motors_on());
  EXPECT_EQ(c.motor[0], kMotorWordZero);
  // a torque: in the slots the device has used since, so within a period
  DeviceState st;
  ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
  ASSERT_EQ(omni.write_motor_torques(Vec3(0.5, -0.25, 0.0)), DeviceError::kOk);
  const std::uint64_t before = bus().info(kGuidA).commands;
  bus().advance_ms(1.0);
  n = bus().info(kGuidA);
  EXPECT_EQ(n.commands - before, 8u);  // 8000 cycles a second
  ASSERT_EQ(decode_command(n.last_command, 16, &c), PacketError::kOk);
  EXPECT_TRUE(c.motors_on());
  EXPECT_EQ(c.motor[0], motor_word_from_unit(0.5));
  EXPECT_EQ(c.motor[1], motor_word_from_unit(-0.25));
  EXPECT_EQ(c.motor[2], kMotorWordZero);
  EXPECT_EQ(bus().underruns(), 0);
}

TEST(FirewireBus, StopSendsZeroWithTheMotorsOffThenClearsTheStreamBit) {
  bus().setup("omni=000b9900000a0a0a");
  Raw1394Transport t(options());
  FirewireOmniOptions fo;
  fo.full_scale_Nm = {1.0, 1.0, 1.0};
  FirewireOmni omni(&t, fo);
  t.start();
  DeviceState st;
  bus().advance_ms(1.0);
  ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
  ASSERT_EQ(omni.write_motor_torques(Vec3(0.5, 0.5, 0.5)), DeviceError::kOk);
  bus().advance_ms(1.0);
  CommandPacket c;
  decode_command(bus().info(kGuidA).last_command, 16, &c);
  ASSERT_TRUE(c.motors_on());
  // as FirewireBackend::stop does it, with the bus running beside it
  omni.send_zero();
  std::atomic<bool> done{false};
  std::thread stopper([&] {
    t.stop();
    done = true;
  });
  while (!done) {
    bus().advance_ms(0.125);
    std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
  stopper.join();
  const fwsim_node_info n = bus().info(kGuidA);
  EXPECT_FALSE(n.streaming);
  EXPECT_EQ(n.reg_control & 0x08, 0);
  ASSERT_EQ(decode_command(n.last_command, 16, &c), PacketError::kOk);
  EXPECT_FALSE(c.motors_on()) << "the last command the device took";
  for (int i = 0; i < 3; ++i) EXPECT_EQ(c.motor[static_cast<std::size_t>(i)], kMotorWordZero);
  // the stream bit was cleared after that command was taken
  const std::vector<fwsim_transaction> log = with(kGuidA);
  ASSERT_FALSE(log.empty());
  const fwsim_transaction& last = log.back();
  EXPECT_EQ(last.op, 'w');
  EXPECT_EQ(last.addr, 0x1087u);
  EXPECT_EQ(last.data[0], 0x00);
  EXPECT_GE(last.t_ns, n.last_command_ns);
}

// -- bus resets --

TEST(FirewireBus, ABusResetMidRunIsRecovered) {
  // Two nodes, renumbered by the reset: the Omni is found again by its
  // GUID at its new node number, its channels claimed again and the start
  // sequence repeated; the tick of the reset reads nothing and sends zero.
  bus().setup("omni=000b9900000a0a0a,rate=1000,speed=500/0/0;"
              "node=0000aa0000c0ffee;renumber=1");
  Raw1394Transport t(options());
  FirewireOmniOptions fo;
  fo.full_scale_Nm = {1.0, 1.0, 1.0};
  FirewireOmni omni(&t, fo);
  t.start();
  DeviceState st;
  for (int k = 0; k < 20; ++k) {
    bus().advance_ms(1.0);
    ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
    omni.write_motor_torques(Vec3(0.2, 0, 0));
  }
  EXPECT_EQ(bus().info(kGuidA).phy, 0);
  bus().log_clear();
  ASSERT_EQ(bus().bus_reset(0), 0);
  EXPECT_EQ(bus().info(kGuidA).phy, 1);  // renumbered
  EXPECT_FALSE(bus().info(kGuidA).streaming);
  bus().advance_ms(1.0);
  EXPECT_EQ(omni.read_state(&st), DeviceError::kNotConnected);
  EXPECT_EQ(st.present, 0u);
  // the start sequence again, at the new node number
  std::vector<std::uint64_t> writes;
  for (const fwsim_transaction& x : with(kGuidA)) {
    EXPECT_EQ(x.phy, 1) << describe(x);
    if (x.op == 'w') writes.push_back(x.addr);
  }
  const std::vector<std::uint64_t> want = {0x1000, 0x1001, 0x20010, 0x1001, 0x1001,
                                           0x1087};
  EXPECT_EQ(writes, want);
  EXPECT_TRUE(bus().info(kGuidA).streaming);
  EXPECT_EQ(t.node().node, 1);
  // and the stream goes on
  for (int k = 0; k < 20; ++k) {
    bus().advance_ms(1.0);
    ASSERT_EQ(omni.read_state(&st), DeviceError::kOk) << k;
  }
  EXPECT_EQ(st.encoder_counts[0], bus().info(kGuidA).encoder_counts[0]);
  const FirewireOmniStats s = omni.stats();
  EXPECT_EQ(s.bus_resets, 1u);
  EXPECT_EQ(s.recoveries_failed, 0u);
  EXPECT_EQ(t.stats().bus_resets, 1u);
  EXPECT_EQ(t.stats().recoveries, 1u);
  EXPECT_EQ(t.start_record().starts, 2);
}

TEST(FirewireBus, AFailedRecoveryIsTriedAgain) {
  bus().setup("omni=000b9900000a0a0a,rate=1000");
  Raw1394Options o = options();
  o.eagain_tries = 5;
  Raw1394Transport t(o);
  FirewireOmni omni(&t, FirewireOmniOptions{});
  t.start();
  DeviceState st;
  bus().advance_ms(1.0);
  ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
  bus().bus_reset(0);
  bus().eagain(0, 5);  // the node answers busy to the first GUID read
  bus().advance_ms(1.0);
  EXPECT_EQ(omni.read_state(&st), DeviceError::kNotConnected);
  EXPECT_EQ(omni.stats().recoveries_failed, 1u);
  // quiet until the next attempt, then streaming again
  int ticks = 0;
  while (omni.read_state(&st) != DeviceError::kOk && ticks < 2 * kRecoverEveryReceives) {
    bus().advance_ms(1.0);
    ++ticks;
  }
  EXPECT_LE(ticks, kRecoverEveryReceives + 1);
  EXPECT_EQ(st.present & kStateJoints, kStateJoints);
  EXPECT_EQ(omni.stats().bus_resets, 2u);  // two attempts
  EXPECT_EQ(t.stats().recoveries, 1u);
}

// -- two Omnis --

TEST(FirewireBus, TwoOmnisOnOneBus) {
  // The drivers' two-device case: 0x20010 left out, each Omni on its own
  // pair of channels, each reading its own device.
  bus().setup("omni=000b9900000a0a0a,rate=1000,speed=1000/0/0;"
              "omni=000b9900000b0b0b,rate=1000,speed=-2000/0/0");
  Raw1394Options oa = options(kGuidA), ob = options(kGuidB);
  oa.write_20010 = ob.write_20010 = false;
  Raw1394Transport ta(oa), tb(ob);
  FirewireOmni a(&ta, FirewireOmniOptions{}), b(&tb, FirewireOmniOptions{});
  ta.start();
  tb.start();
  EXPECT_EQ(ta.start_record().tx_channel, 0);
  EXPECT_EQ(ta.start_record().rx_channel, 1);
  EXPECT_EQ(tb.start_record().tx_channel, 2);
  EXPECT_EQ(tb.start_record().rx_channel, 3);
  DeviceState sa, sb;
  for (int k = 0; k < 200; ++k) {
    bus().advance_ms(1.0);
    ASSERT_EQ(a.read_state(&sa), DeviceError::kOk);
    ASSERT_EQ(b.read_state(&sb), DeviceError::kOk);
  }
  EXPECT_EQ(sa.encoder_counts[0], bus().info(kGuidA).encoder_counts[0]);
  EXPECT_EQ(sb.encoder_counts[0], bus().info(kGuidB).encoder_counts[0]);
  EXPECT_GT(sa.encoder_counts[0], 150);
  EXPECT_LT(sb.encoder_counts[0], -300);
  EXPECT_FALSE(bus().info(kGuidA).wrote_20010);
  EXPECT_FALSE(bus().info(kGuidB).wrote_20010);
  EXPECT_EQ(a.stats().lost_packets + b.stats().lost_packets, 0u);
}

// -- the servo path --

TEST(FirewireBus, ServoPathAllocatesNothing) {
  bus().setup("omni=000b9900000a0a0a,rate=2000,speed=100/200/300");
  Raw1394Transport t(options());
  FirewireOmniOptions fo;
  fo.full_scale_Nm = {1.0, 1.0, 1.0};
  FirewireOmni omni(&t, fo);
  t.start();
  DeviceState st;
  std::size_t allocations = 0;
  int ok = 0;
  for (int k = 0; k < 2000; ++k) {
    bus().advance_ms(k % 97 == 0 ? 3.0 : 1.0);  // the bus: outside the count
    vmh::testing::AllocationScope scope;
    if (omni.read_state(&st) == DeviceError::kOk) ++ok;
    omni.write_motor_torques(Vec3(0.1, -0.1, 0.05));
    if (k % 500 == 0) omni.send_zero();
    (void)omni.stats();
    (void)t.stats();
    allocations += scope.count();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(ok, 2000);
  EXPECT_GT(omni.stats().late_packets, 0u);  // the long ticks were there
}

}  // namespace
}  // namespace vmh::hw::fw
