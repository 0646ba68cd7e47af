// FirewireOmni (hw/firewire/firewire_omni.h) over a scripted transport:
// readings through the calibration, switches, encoder unwrap, lost packets,
// the transport's statuses as DeviceErrors, the command packet it sends,
// and no allocation on the servo path.
#include "hw/firewire/firewire_omni.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "tests/hw/firewire/fake_transport.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/constants.h"

namespace vmh::hw::fw {
namespace {

using testing::FakeTransport;
using testing::make_packet;

using vmh::testing::kPi;

OmniCalibration test_calibration() {
  OmniCalibration c;
  c.encoder_offset_rad = {0.1, -0.2, 0.3};
  c.pot_gain_rad = {0.002, 0.003, -0.0025};
  c.pot_offset_rad = {-1.0, -2.0, 1.5};
  return c;
}

FirewireOmniOptions test_options() {
  FirewireOmniOptions o;
  o.calibration = test_calibration();
  o.full_scale_Nm = {0.35, 0.2, 0.5};
  o.motor_sign = {+1, -1, +1};
  return o;
}

struct Rig {
  std::unique_ptr<FakeTransport> t = std::make_unique<FakeTransport>();
  FirewireOmni omni{t.get(), test_options()};
  DeviceState st;
  DeviceError read() { return omni.read_state(&st); }
};

TEST(FirewireOmni, AnglesAreTheCalibratedRawReadings) {
  Rig r;
  r.t->push_packet(make_packet(1, {1500, -3000, 7500}, {100, 1024, 2000}));
  ASSERT_EQ(r.read(), DeviceError::kOk);
  const OmniCalibration cal = test_calibration();
  const Joints expected =
      angles_from_raw({1500, -3000, 7500}, {100, 1024, 2000}, cal);
  for (int i = 0; i < 6; ++i) {
    EXPECT_DOUBLE_EQ(r.st.q_device_rad[i], expected[i]) << "t" << i + 1;
  }
  // and by hand: 1500 counts = 1/10 rev; with the drivers' signs t1 and
  // t2 count the other way (§9.2)
  EXPECT_NEAR(r.st.q_device_rad[0], 0.1 - 2 * kPi / 10, 1e-12);
  EXPECT_NEAR(r.st.q_device_rad[1], -0.2 + 2 * kPi / 5, 1e-12);  // -3000
  EXPECT_NEAR(r.st.q_device_rad[2], 0.3 + kPi, 1e-12);           // 7500
  EXPECT_NEAR(r.st.q_device_rad[3], 0.002 * 100 - 1.0, 1e-12);
  EXPECT_NEAR(r.st.q_device_rad[4], 0.003 * 1024 - 2.0, 1e-12);
  EXPECT_NEAR(r.st.q_device_rad[5], -0.0025 * 2000 + 1.5, 1e-12);
  EXPECT_EQ(r.st.encoder_counts[0], 1500);
  EXPECT_EQ(r.st.encoder_counts[1], -3000);
  EXPECT_EQ(r.st.encoder_counts[2], 7500);
  EXPECT_EQ(r.st.gimbal_pots[0], 100);
  EXPECT_EQ(r.st.gimbal_pots[1], 1024);
  EXPECT_EQ(r.st.gimbal_pots[2], 2000);
  EXPECT_EQ(r.st.present, kStateJoints | kStateButtons | kStateInkwell |
                              kStateTimestamp | kStateEncoders | kStatePots);
  EXPECT_GT(r.st.timestamp_s, 0.0);
  // read_joints is the same reading
  r.t->push_packet(make_packet(2, {1500, -3000, 7500}, {100, 1024, 2000}));
  Joints q;
  ASSERT_EQ(r.omni.read_joints(&q), DeviceError::kOk);
  EXPECT_DOUBLE_EQ(q[0], expected[0]);
  EXPECT_DOUBLE_EQ(q[5], expected[5]);
}

TEST(FirewireOmni, SetCalibrationChangesTheAngles) {
  Rig r;
  OmniCalibration c = test_calibration();
  c.encoder_offset_rad[0] = 1.0;
  r.omni.set_calibration(c);
  EXPECT_TRUE(r.omni.calibrated());
  r.t->push_packet(make_packet(1, {0, 0, 0}, {0, 0, 0}));
  ASSERT_EQ(r.read(), DeviceError::kOk);
  EXPECT_DOUBLE_EQ(r.st.q_device_rad[0], 1.0);
  c.pot_gain_rad[1] = 0.0;
  EXPECT_THROW(r.omni.set_calibration(c), std::invalid_argument);
}

TEST(FirewireOmni, ButtonsAndInkwell) {
  Rig r;
  StatePacket p = make_packet(1, {0, 0, 0}, {0, 0, 0});
  p.status = 0x05;  // button 1 up, button 2 down, out of the inkwell
  r.t->push_packet(p);
  p.counter = 2;
  p.status = 0x00;  // both down, docked
  r.t->push_packet(p);
  p.counter = 3;
  p.status = 0x07;  // none, out
  r.t->push_packet(p);
  ASSERT_EQ(r.read(), DeviceError::kOk);
  EXPECT_EQ(r.st.buttons, kButton2);
  EXPECT_FALSE(r.st.docked);
  ASSERT_EQ(r.read(), DeviceError::kOk);
  EXPECT_EQ(r.st.buttons, kButton1 | kButton2);
  EXPECT_TRUE(r.st.docked);
  ASSERT_EQ(r.read(), DeviceError::kOk);
  EXPECT_EQ(r.st.buttons, 0u);
  EXPECT_FALSE(r.st.docked);
}

TEST(FirewireOmni, EncoderUnwrapsAcrossTheInt16WrapOverPackets) {
  Rig r;
  // t1 climbs through +32767; t2 falls through -32768; t3 steps 0
  const std::int16_t up[] = {32000, 32700, -32736, -31736};   // raw
  const std::int32_t up_counts[] = {32000, 32700, 32800, 33800};
  const std::int16_t down[] = {-32000, -32700, 32736, 31736};
  const std::int32_t down_counts[] = {-32000, -32700, -32800, -33800};
  for (std::uint32_t k = 0; k < 4; ++k) {
    r.t->push_packet(make_packet(k + 1, {up[k], down[k], 0}, {0, 0, 0}));
  }
  for (std::size_t k = 0; k < 4; ++k) {
    ASSERT_EQ(r.read(), DeviceError::kOk);
    EXPECT_EQ(r.st.encoder_counts[0], up_counts[k]) << k;
    EXPECT_EQ(r.st.encoder_counts[1], down_counts[k]) << k;
  }
  // the angle follows the unwrapped count: 33800 counts on t1
  EXPECT_NEAR(r.st.q_device_rad[0], 0.1 - 2 * kPi * 33800 / 15000, 1e-12);
}

TEST(FirewireOmni, WhatArrivedTellsLostFromSupersededAndLate) {
  // The transport takes every packet that arrived and hands over the
  // newest. Two arrive each tick here (2000 packets a second read at 1 kHz):
  // a counter that steps by 2 loses nothing.
  Rig r;
  r.t->arrived_per_packet = 2;
  for (std::uint32_t c : {2u, 4u, 6u, 8u}) {
    r.t->push_packet(make_packet(c, {0, 0, 0}, {0, 0, 0}));
  }
  for (int k = 0; k < 4; ++k) ASSERT_EQ(r.read(), DeviceError::kOk);
  FirewireOmniStats s = r.omni.stats();
  EXPECT_EQ(s.packets, 4u);
  EXPECT_EQ(s.lost_packets, 0u);
  EXPECT_EQ(s.superseded_packets, 4u);
  EXPECT_EQ(s.late_packets, 0u);
  // a step of 5 with 2 arrived: 3 never came
  r.t->push_packet(make_packet(13, {0, 0, 0}, {0, 0, 0}));
  ASSERT_EQ(r.read(), DeviceError::kOk);
  EXPECT_EQ(r.omni.stats().lost_packets, 3u);
  // a tick that found two packets of which one had waited a period: late,
  // and not lost
  r.t->arrived_per_packet = 2;
  r.t->late_per_packet = 1;
  r.t->push_packet(make_packet(15, {0, 0, 0}, {0, 0, 0}));
  ASSERT_EQ(r.read(), DeviceError::kOk);
  s = r.omni.stats();
  EXPECT_EQ(s.lost_packets, 3u);
  EXPECT_EQ(s.late_packets, 1u);
  EXPECT_EQ(s.superseded_packets, 6u);
}

TEST(FirewireOmni, TheInkwellSetsTheEncoderOffsets) {
  // Re-homing as the drivers do it: a docked packet makes t1..t3 read the
  // calibration's inkwell pose, whatever the offsets were; out of the
  // inkwell the angles follow the counts from there.
  Rig r;
  OmniCalibration cal = test_calibration();
  cal.inkwell_t123_rad = {0.05, -0.6, -0.5};
  r.omni.set_calibration(cal);
  StatePacket p = make_packet(1, {1234, -4321, 777}, {0, 0, 0});
  p.status = kStateButton1Released | kStateButton2Released;  // docked
  r.t->push_packet(p);
  p.counter = 2;  // still docked, counts moved a little as it settles
  p.encoders = {1240, -4320, 770};
  r.t->push_packet(p);
  StatePacket out = make_packet(3, {1240 + 1500, -4320 - 1500, 770 + 1500},
                                {0, 0, 0});  // undocked, a tenth of a turn each
  r.t->push_packet(out);
  ASSERT_EQ(r.read(), DeviceError::kOk);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(r.st.q_device_rad[i], cal.inkwell_t123_rad[static_cast<std::size_t>(i)],
                1e-12) << "t" << i + 1;
  }
  ASSERT_EQ(r.read(), DeviceError::kOk);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(r.st.q_device_rad[i], cal.inkwell_t123_rad[static_cast<std::size_t>(i)],
                1e-12) << "t" << i + 1;
  }
  ASSERT_EQ(r.read(), DeviceError::kOk);
  // signs (-1, -1, +1): +1500 on t1 is -0.1 turn, -1500 on t2 +0.1 turn
  EXPECT_NEAR(r.st.q_device_rad[0], 0.05 - 2 * kPi / 10, 1e-12);
  EXPECT_NEAR(r.st.q_device_rad[1], -0.6 + 2 * kPi / 10, 1e-12);
  EXPECT_NEAR(r.st.q_device_rad[2], -0.5 + 2 * kPi / 10, 1e-12);
  const FirewireOmniStats s = r.omni.stats();
  EXPECT_EQ(s.rehomes, 1u);  // one stay in the inkwell
  // the calibration in use has the inkwell's offsets; pots untouched
  const OmniCalibration in_use = r.omni.calibration();
  const auto expected = docked_encoder_offsets({1240, -4320, 770}, cal);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(in_use.encoder_offset_rad[i], expected[i]) << i;
    EXPECT_EQ(in_use.pot_gain_rad[i], cal.pot_gain_rad[i]) << i;
  }
  // a calibration set afterwards is taken at the next tick
  OmniCalibration other = cal;
  other.encoder_offset_rad = {0.5, 0.5, 0.5};
  r.omni.set_calibration(other);
  EXPECT_EQ(r.omni.calibration().encoder_offset_rad, other.encoder_offset_rad);
  r.t->push_packet(make_packet(4, {0, 0, 0}, {0, 0, 0}));
  ASSERT_EQ(r.read(), DeviceError::kOk);
  EXPECT_DOUBLE_EQ(r.st.q_device_rad[0], 0.5);
}

TEST(FirewireOmni, WithoutRehomingTheInkwellChangesNothing) {
  auto t = std::make_unique<FakeTransport>();
  FirewireOmniOptions o = test_options();
  o.rehome_in_inkwell = false;
  FirewireOmni omni(t.get(), o);
  StatePacket p = make_packet(1, {1234, -4321, 777}, {0, 0, 0});
  p.status = kStateButton1Released | kStateButton2Released;  // docked
  t->push_packet(p);
  DeviceState st;
  ASSERT_EQ(omni.read_state(&st), DeviceError::kOk);
  EXPECT_TRUE(st.docked);
  const Joints expected = angles_from_raw({1234, -4321, 777}, {0, 0, 0},
                                          test_calibration());
  EXPECT_DOUBLE_EQ(st.q_device_rad[0], expected[0]);
  EXPECT_EQ(omni.stats().rehomes, 0u);
  EXPECT_EQ(omni.calibration().encoder_offset_rad,
            test_calibration().encoder_offset_rad);
}

TEST(FirewireOmni, CounterGapsAreLostPackets) {
  Rig r;
  for (std::uint32_t c : {10u, 11u, 14u, 15u, 20u}) {
    r.t->push_packet(make_packet(c, {0, 0, 0}, {0, 0, 0}));
  }
  for (int k = 0; k < 5; ++k) ASSERT_EQ(r.read(), DeviceError::kOk);
  FirewireOmniStats s = r.omni.stats();
  EXPECT_EQ(s.packets, 5u);
  EXPECT_EQ(s.lost_packets, 2u + 4u);  // 12, 13 and 16..19
  EXPECT_EQ(s.last_counter, 20u);
  // the counter's own wrap is no loss: ..., 0xffffffff, 0, then 2 (one lost)
  for (std::uint32_t c : {0xfffffffeu, 0xffffffffu, 0u, 2u}) {
    r.t->push_packet(make_packet(c, {0, 0, 0}, {0, 0, 0}));
  }
  for (int k = 0; k < 4; ++k) ASSERT_EQ(r.read(), DeviceError::kOk);
  s = r.omni.stats();
  // 20 -> 0xfffffffe is 12 back modulo 2^32: not counted (next case)
  EXPECT_EQ(s.lost_packets, 6u + 1u);
  EXPECT_EQ(s.last_counter, 2u);
  // 2 -> 100 loses 97; a counter that went back (a restarted device) is
  // not counted as loss
  r.t->push_packet(make_packet(100u, {0, 0, 0}, {0, 0, 0}));
  r.t->push_packet(make_packet(50u, {0, 0, 0}, {0, 0, 0}));
  ASSERT_EQ(r.read(), DeviceError::kOk);
  EXPECT_EQ(r.omni.stats().lost_packets, 7u + 97u);
  ASSERT_EQ(r.read(), DeviceError::kOk);
  EXPECT_EQ(r.omni.stats().lost_packets, 7u + 97u);
  // the last packet is there for `hw probe`
  EXPECT_EQ(r.omni.last_packet().counter, 50u);
}

TEST(FirewireOmni, TransportStatusesAsDeviceErrors) {
  Rig r;
  r.t->push_status(TransportStatus::kTimeout);
  r.t->push_status(TransportStatus::kDisconnected);
  r.t->push_status(TransportStatus::kIo);
  r.t->push_status(TransportStatus::kBadPacket);
  EXPECT_EQ(r.read(), DeviceError::kTimeout);
  EXPECT_EQ(r.st.present, 0u);
  EXPECT_EQ(r.read(), DeviceError::kNotConnected);
  EXPECT_EQ(r.read(), DeviceError::kIo);
  EXPECT_EQ(r.read(), DeviceError::kIo);
  EXPECT_EQ(r.st.present, 0u);
  // an empty queue is a timeout too
  EXPECT_EQ(r.read(), DeviceError::kTimeout);
  const FirewireOmniStats s = r.omni.stats();
  EXPECT_EQ(s.timeouts, 2u);
  EXPECT_EQ(s.bad_packets, 1u);
  EXPECT_EQ(s.packets, 0u);
  EXPECT_EQ(r.t->recover_calls.load(), 0);
}

TEST(FirewireOmni, WrongSizedPacketsAreIoErrors) {
  Rig r;
  std::uint8_t bytes[64] = {};
  r.t->push_bytes(bytes, 43);
  r.t->push_bytes(bytes, 45);
  EXPECT_EQ(r.read(), DeviceError::kIo);
  EXPECT_EQ(r.read(), DeviceError::kIo);
  EXPECT_EQ(r.omni.stats().bad_packets, 2u);
  EXPECT_EQ(r.omni.stats().packets, 0u);
}

TEST(FirewireOmni, OpenPotIsASensorFault) {
  Rig r;
  StatePacket p = make_packet(1, {0, 0, 0}, {10, 10, 10});
  p.gimbal_a[1] = 0;
  p.gimbal_b[1] = 0;
  r.t->push_packet(p);
  EXPECT_EQ(r.read(), DeviceError::kSensorFault);
  EXPECT_EQ(r.st.present, 0u);
}

TEST(FirewireOmni, BusResetRecoversAndReseedsTheUnwrap) {
  Rig r;
  // counts driven to 40000 (raw int16 -25536) before the reset
  r.t->push_packet(make_packet(1, {30000, 0, 0}, {0, 0, 0}));
  r.t->push_packet(make_packet(2, {-25536, 0, 0}, {0, 0, 0}));
  r.t->push_status(TransportStatus::kBusReset);
  // after the reset the device counts from 5 (its counter restarted too)
  r.t->push_packet(make_packet(7, {5, 0, 0}, {0, 0, 0}));
  ASSERT_EQ(r.read(), DeviceError::kOk);
  ASSERT_EQ(r.read(), DeviceError::kOk);
  EXPECT_EQ(r.st.encoder_counts[0], 40000);
  EXPECT_EQ(r.read(), DeviceError::kNotConnected);
  EXPECT_EQ(r.st.present, 0u);
  EXPECT_EQ(r.t->recover_calls.load(), 1);
  // zero words with the motors off went out before the recovery
  ASSERT_GE(r.t->sent_at_recover.load(), 0);
  const CommandPacket before = r.t->sent_command(
      static_cast<std::size_t>(r.t->sent_at_recover.load()));
  EXPECT_FALSE(before.motors_on());
  EXPECT_EQ(before.motor[0], kMotorWordZero);
  ASSERT_EQ(r.read(), DeviceError::kOk);
  // re-seeded: 5, not unwrap_encoder(40000, 5) = 65541
  EXPECT_EQ(r.st.encoder_counts[0], 5);
  const FirewireOmniStats s = r.omni.stats();
  EXPECT_EQ(s.bus_resets, 1u);
  EXPECT_EQ(s.recoveries_failed, 0u);
  EXPECT_EQ(s.lost_packets, 0u);  // counter 2 -> 7 across a reset: no loss
}

TEST(FirewireOmni, FailedRecoveryIsCounted) {
  Rig r;
  r.t->recover_result = TransportStatus::kDisconnected;
  r.t->push_status(TransportStatus::kBusReset);
  EXPECT_EQ(r.read(), DeviceError::kNotConnected);
  EXPECT_EQ(r.t->recover_calls.load(), 1);
  EXPECT_EQ(r.omni.stats().recoveries_failed, 1u);
}

TEST(FirewireOmni, TorqueSignAndFullScale) {
  Rig r;
  // full scales 0.35, 0.2, 0.5 N m; signs +1, -1, +1 (test_options)
  // t1: 0.175 = half of 0.35 -> u = +0.5 -> 0x0bff
  // t2: 0.1 = half of 0.2 with the sign reversed -> u = -0.5 -> 0x03ff
  // t3: 0 -> 0x07ff
  ASSERT_EQ(r.omni.write_motor_torques(Vec3(0.175, 0.1, 0.0)), DeviceError::kOk);
  ASSERT_EQ(r.t->n_sent.load(), 1u);
  const std::uint8_t expected[16] = {0xff, 0x0b, 0xff, 0x03, 0xff, 0x07,
                                     0xc8, 0x53,  // 0x53c0 | motors on
                                     0, 0, 0, 0, 0, 0, 0, 0};
  for (std::size_t i = 0; i < 16; ++i) {
    EXPECT_EQ(r.t->sent[0][i], expected[i]) << "byte " << i;
  }
  // an arbitrary torque decodes back to itself within one word
  const Vec3 tau(0.123, -0.0777, 0.31);
  const std::array<double, 3> fs = {0.35, 0.2, 0.5};
  const std::array<int, 3> sign = {+1, -1, +1};
  ASSERT_EQ(r.omni.write_motor_torques(tau), DeviceError::kOk);
  const CommandPacket c = r.t->last_command();
  EXPECT_TRUE(c.motors_on());
  for (std::size_t i = 0; i < 3; ++i) {
    const double u = unit_from_motor_word(c.motor[i]);
    EXPECT_NEAR(sign[i] * u * fs[i], tau[static_cast<int>(i)], fs[i] / 2047)
        << "t" << i + 1;
  }
  EXPECT_EQ(r.omni.stats().commands, 2u);
  EXPECT_EQ(r.omni.stats().saturated_commands, 0u);
}

TEST(FirewireOmni, SaturationIsCountedAndNeverWraps) {
  Rig r;
  ASSERT_EQ(r.omni.write_motor_torques(Vec3(1.0, 0.0, -2.0)), DeviceError::kOk);
  CommandPacket c = r.t->last_command();
  EXPECT_EQ(c.motor[0], 0x0fff);
  EXPECT_EQ(c.motor[1], 0x07ff);
  EXPECT_EQ(c.motor[2], 0x0000);
  // t2's sign is -1: a large positive torque is the bottom word
  ASSERT_EQ(r.omni.write_motor_torques(Vec3(0.0, 5.0, 0.0)), DeviceError::kOk);
  c = r.t->last_command();
  EXPECT_EQ(c.motor[1], 0x0000);
  // exactly full scale is not saturation
  ASSERT_EQ(r.omni.write_motor_torques(Vec3(0.35, -0.2, 0.5)),
            DeviceError::kOk);
  c = r.t->last_command();
  EXPECT_EQ(c.motor[0], 0x0fff);
  EXPECT_EQ(c.motor[1], 0x0fff);
  EXPECT_EQ(c.motor[2], 0x0fff);
  EXPECT_EQ(r.omni.stats().saturated_commands, 2u);
  EXPECT_EQ(r.omni.stats().commands, 3u);
}

TEST(FirewireOmni, NonFiniteTorqueSendsZeroWithMotorsOff) {
  Rig r;
  ASSERT_EQ(r.omni.write_motor_torques(Vec3(0.1, 0.1, 0.1)), DeviceError::kOk);
  EXPECT_TRUE(r.t->last_command().motors_on());
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  for (const Vec3& bad : {Vec3(nan, 0.1, 0.1), Vec3(0.1, inf, 0.1),
                          Vec3(0.1, 0.1, -inf)}) {
    EXPECT_EQ(r.omni.write_motor_torques(bad), DeviceError::kInvalidCommand);
    const std::size_t i = r.t->n_sent.load() - 1;
    const std::uint8_t expected[16] = {0xff, 0x07, 0xff, 0x07, 0xff, 0x07,
                                       0xc0, 0x53,  // motors-on bit clear
                                       0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t b = 0; b < 16; ++b) {
      EXPECT_EQ(r.t->sent[i][b], expected[b]) << "byte " << b;
    }
  }
  // the next finite torque turns the motors on again
  ASSERT_EQ(r.omni.write_motor_torques(Vec3(0.0, 0.0, 0.0)), DeviceError::kOk);
  EXPECT_TRUE(r.t->last_command().motors_on());
  // send_zero: zero words, motors off
  ASSERT_EQ(r.omni.send_zero(), DeviceError::kOk);
  const CommandPacket z = r.t->last_command();
  EXPECT_FALSE(z.motors_on());
  EXPECT_EQ(z.motor[0], 0x07ff);
  EXPECT_EQ(z.motor[1], 0x07ff);
  EXPECT_EQ(z.motor[2], 0x07ff);
}

TEST(FirewireOmni, OptionsAreValidated) {
  FakeTransport t;
  FirewireOmniOptions o = test_options();
  EXPECT_NO_THROW(FirewireOmni(&t, o));
  EXPECT_THROW(FirewireOmni(nullptr, o), std::invalid_argument);
  o.full_scale_Nm[1] = 0.0;
  EXPECT_THROW(FirewireOmni(&t, o), std::invalid_argument);
  o = test_options();
  o.full_scale_Nm[2] = std::nan("");
  EXPECT_THROW(FirewireOmni(&t, o), std::invalid_argument);
  o = test_options();
  o.motor_sign[0] = 0;
  try {
    FirewireOmni omni(&t, o);
    ADD_FAILURE() << "a motor sign of 0 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("motor_sign[0]"), std::string::npos)
        << e.what();
  }
  o = test_options();
  o.receive_timeout_s = 0.0;
  EXPECT_THROW(FirewireOmni(&t, o), std::invalid_argument);
  o = test_options();
  o.calibration.pot_gain_rad[2] = 0.0;
  EXPECT_THROW(FirewireOmni(&t, o), std::invalid_argument);
  // the default options are usable (nominal calibration), not calibrated
  FirewireOmni d(&t, FirewireOmniOptions{});
  EXPECT_FALSE(d.calibrated());
}

TEST(FirewireOmni, NominalCalibrationIsTheDriversLines) {
  // §9.2: t4 = 5.48 r - 2.74, t5 = -5.28 r + 2.64, t6 = 4.76 r - 2.38 with
  // r = a / (a + b); encoders (-1, -1, +1)
  const OmniCalibration c = nominal_calibration();
  EXPECT_NO_THROW(c.validate());
  const double at_one[3] = {5.48 - 2.74, -5.28 + 2.64, 4.76 - 2.38};
  const double at_zero[3] = {-2.74, 2.64, -2.38};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(c.pot_gain_rad[i] * kPotCodeMax + c.pot_offset_rad[i], at_one[i],
                1e-12) << i;  // r = 1
    EXPECT_DOUBLE_EQ(c.pot_offset_rad[i], at_zero[i]) << i;  // r = 0
    EXPECT_DOUBLE_EQ(c.encoder_offset_rad[i], 0.0) << i;
  }
  EXPECT_LT(c.pot_gain_rad[1], 0.0);  // t5's pot turns the other way
  EXPECT_EQ(c.encoder_sign, (std::array<int, 3>{-1, -1, 1}));
  // the half-way code of a pot reads the middle of its line
  const Joints mid = angles_from_raw({0, 0, 0}, {1024, 1024, 1024}, c);
  EXPECT_NEAR(mid[3], 5.48 * 1024 / 2047 - 2.74, 1e-12);
  EXPECT_NEAR(mid[4], -5.28 * 1024 / 2047 + 2.64, 1e-12);
}

TEST(FirewireOmni, ServoPathAllocatesNothing) {
  Rig r;
  // a script of every path: packets, wrap, gaps, each status, bad sizes,
  // an open pot, a bus reset
  std::uint8_t junk[64] = {};
  for (int round = 0; round < 20; ++round) {
    const auto c = static_cast<std::uint32_t>(round * 10);
    r.t->push_packet(make_packet(c + 1, {32760, -32760, 0}, {5, 6, 7}));
    r.t->push_packet(make_packet(c + 3, {-32760, 32760, 1}, {5, 6, 7}));
    r.t->push_status(TransportStatus::kTimeout);
    r.t->push_status(TransportStatus::kBusReset);
    r.t->push_status(TransportStatus::kBadPacket);
    r.t->push_status(TransportStatus::kDisconnected);
    r.t->push_status(TransportStatus::kIo);
    r.t->push_bytes(junk, 43);
    StatePacket open = make_packet(c + 4, {0, 0, 0}, {1, 1, 1});
    open.gimbal_a[0] = open.gimbal_b[0] = 0;
    r.t->push_packet(open);
  }
  const double nan = std::nan("");
  int ok = 0;
  std::size_t allocations = 0;
  {
    vmh::testing::AllocationScope scope;
    for (int k = 0; k < 9 * 20 + 5; ++k) {
      if (r.read() == DeviceError::kOk) ++ok;
      r.omni.write_motor_torques(k % 7 == 0 ? Vec3(nan, 0, 0)
                                            : Vec3(0.1 * (k % 5), -2.0, 0.0));
      r.omni.send_zero();
      (void)r.omni.stats();
      (void)r.omni.last_packet();
      (void)r.omni.calibration();
    }
    allocations = scope.count();
  }
  EXPECT_EQ(allocations, 0u);
  // the script really went through every path
  EXPECT_EQ(ok, 40);
  const FirewireOmniStats s = r.omni.stats();
  EXPECT_EQ(s.bus_resets, 20u);
  EXPECT_EQ(s.timeouts, 20u + 5u);  // and 5 on the empty queue
  EXPECT_EQ(s.bad_packets, 40u);
  EXPECT_GT(s.saturated_commands, 0u);
}

TEST(FirewireOmni, AllocationCounterWorks) {
  // the counter the test above relies on does count
  vmh::testing::AllocationScope scope;
  auto p = std::make_unique<int>(3);
  EXPECT_GE(scope.count(), 1u);
  EXPECT_EQ(*p, 3);
}

}  // namespace
}  // namespace vmh::hw::fw
