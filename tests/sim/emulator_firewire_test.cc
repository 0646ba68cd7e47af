// sim/emulator_firewire: the emulator behind the FireWire Omni's packets,
// with the native driver's device layer (hw::fw::FirewireOmni) on top.
// The physics thread runs for real: the tests wait for what must happen
// (with generous limits) and compare what comes through the wire with what
// the emulator itself reports and holds.
#include "sim/emulator_firewire.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "device/tick_timer.h"
#include "hw/firewire/firewire_omni.h"
#include "hw/firewire/omni_packet.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/wait.h"

namespace vmh::sim {
namespace {

namespace fw = hw::fw;
using fw::TransportStatus;
using vmh::testing::sleep_s;
using vmh::testing::wait_for;

EmulatorFirewireOptions options(HandProgram p) {
  EmulatorFirewireOptions o;
  o.emulator.scene = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";
  o.emulator.hand = p;
  return o;
}

// the device layer over the transport, decoding with the emulator's
// factory calibration (what its raw values imply)
fw::FirewireOmniOptions omni_options(const EmulatorFirewireTransport& t) {
  fw::FirewireOmniOptions o;
  o.calibration = t.emulator()->factory_calibration();
  o.calibrated = true;
  return o;
}

// one packet, retried for up to a second past timeouts (a loaded machine can
// hold the physics thread back by the three periods after which it is stale)
TransportStatus receive_ok(EmulatorFirewireTransport* t, std::uint8_t* buf,
                           std::size_t* size) {
  const double end = monotonic_now_s() + 1.0;
  TransportStatus s = t->receive(buf, 64, size, 2e-3);
  while (s == TransportStatus::kTimeout && monotonic_now_s() < end) {
    sleep_s(2e-4);
    s = t->receive(buf, 64, size, 2e-3);
  }
  return s;
}

DeviceError read_ok(fw::FirewireOmni* omni, DeviceState* s) {
  const double end = monotonic_now_s() + 1.0;
  DeviceError e = omni->read_state(s);
  while (e == DeviceError::kTimeout && monotonic_now_s() < end) {
    sleep_s(2e-4);
    e = omni->read_state(s);
  }
  return e;
}

// a servo loop's worth of reads and writes through the device for `s`
// seconds (1 ms apart): the errors in order, each run of one error once
struct ErrorRun {
  DeviceError error;
  long ticks;
};
std::vector<ErrorRun> servo_for(fw::FirewireOmni* omni, const Vec3& tau, double s,
                           const std::function<void(double)>& each = nullptr) {
  std::vector<ErrorRun> runs;
  const double t0 = monotonic_now_s();
  while (monotonic_now_s() < t0 + s) {
    DeviceState st;
    const DeviceError e = omni->read_state(&st);
    if (runs.empty() || runs.back().error != e) runs.push_back({e, 0});
    ++runs.back().ticks;
    omni->write_motor_torques(tau);
    if (each) each(monotonic_now_s() - t0);
    sleep_s(1e-3);
  }
  return runs;
}

std::string runs_text(const std::vector<ErrorRun>& runs) {
  std::string s;
  for (const ErrorRun& r : runs) {
    s += std::string(device_error_name(r.error)) + "x" + std::to_string(r.ticks) + " ";
  }
  return s;
}

TEST(WireFaults, ParsesTheTextForm) {
  const auto f = parse_wire_faults(
      "loss@1:5, late@2:0.5:3,length@3:2,reset@4,unplug@5:1.5,stall@6:0.2");
  ASSERT_EQ(f.size(), 6u);
  EXPECT_EQ(f[0].kind, WireFaultKind::kLoss);
  EXPECT_EQ(f[0].at_s, 1.0);
  EXPECT_EQ(f[0].count, 5);
  EXPECT_EQ(f[1].kind, WireFaultKind::kLate);
  EXPECT_EQ(f[1].duration_s, 0.5);
  EXPECT_EQ(f[1].count, 3);
  EXPECT_EQ(f[2].kind, WireFaultKind::kLength);
  EXPECT_EQ(f[2].count, 2);
  EXPECT_EQ(f[3].kind, WireFaultKind::kReset);
  EXPECT_EQ(f[3].at_s, 4.0);
  EXPECT_EQ(f[4].kind, WireFaultKind::kUnplug);
  EXPECT_EQ(f[4].duration_s, 1.5);
  EXPECT_EQ(f[5].kind, WireFaultKind::kStall);
  EXPECT_TRUE(parse_wire_faults("").empty());
}

TEST(WireFaults, BadItemsAreNamed) {
  const auto message = [](const std::string& text) {
    try {
      parse_wire_faults(text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  // the emulator's own "drop" is not a packet fault: the kinds are listed
  EXPECT_NE(message("drop@1:5").find("unknown kind 'drop'"), std::string::npos);
  EXPECT_NE(message("drop@1:5").find("loss@t:N"), std::string::npos);
  EXPECT_NE(message("loss@1").find("loss@1"), std::string::npos);
  EXPECT_NE(message("loss@1:0").find("'0'"), std::string::npos);
  EXPECT_NE(message("length@x:2").find("'x'"), std::string::npos);
  EXPECT_NE(message("late@1:0.5:64").find("[1, 63]"), std::string::npos);
  EXPECT_NE(message("reset@1:2").find("reset@1:2"), std::string::npos);
  EXPECT_NE(message("unplug@1:-1").find("duration_s"), std::string::npos);
  EXPECT_NE(message("loss5").find("kind@at_s"), std::string::npos);
}

TEST(EmulatorFirewire, NodeIsTheEmulatorsSerialOnSensablesVendor) {
  EmulatorFirewireOptions o = options(HandProgram::kTour);
  o.emulator.serial = "EMU-0042";
  EmulatorFirewireTransport t(o);
  const fw::NodeInfo n = t.node();
  EXPECT_EQ(n.vendor, 0x000b99u);
  EXPECT_EQ(n.serial, "EMU-0042");
  EXPECT_EQ(n.description, "in-process (emulator)");
  EXPECT_EQ(n.guid >> 32, 0x000b99eeull);
  // another serial, another GUID
  o.emulator.serial = "EMU-0043";
  EXPECT_NE(EmulatorFirewireTransport(o).node().guid, n.guid);
  // not started: the device is not there
  std::uint8_t buf[64];
  std::size_t size = 0;
  EXPECT_EQ(t.receive(buf, sizeof buf, &size, 2e-3), TransportStatus::kDisconnected);
}

TEST(EmulatorFirewire, BadFactoryOptionsAreNamed) {
  EmulatorFirewireOptions o = options(HandProgram::kTour);
  o.factory_full_scale_Nm[1] = 0.0;
  EXPECT_THROW(
      {
        try {
          EmulatorFirewireTransport t(o);
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(std::string(e.what()).find("factory_full_scale_Nm[1]"),
                    std::string::npos);
          throw;
        }
      },
      std::invalid_argument);
  o = options(HandProgram::kTour);
  o.factory_motor_sign[2] = 0;
  EXPECT_THROW(EmulatorFirewireTransport t(o), std::invalid_argument);
}

// The packet's fields are the emulator's own raw readings: encoders as
// their low 16 bits, pots as a complementary pair, buttons active-low, the
// counter +1 a packet.
TEST(EmulatorFirewire, PacketsCarryTheEmulatorsRawReadings) {
  EmulatorFirewireTransport t(options(HandProgram::kTour));
  Emulator* emu = t.emulator();
  t.start();
  emu->press_buttons(kButton2);
  std::uint8_t buf[64];
  std::size_t size = 0;
  int matched = 0;
  std::uint32_t last_counter = 0;
  double last_time = -1.0;
  for (int i = 0; i < 300; ++i) {
    DeviceState a, b;
    const DeviceError ea = emu->read_state(&a);
    const TransportStatus s = t.receive(buf, sizeof buf, &size, 2e-3);
    const DeviceError eb = emu->read_state(&b);
    sleep_s(1e-3);
    if (s != TransportStatus::kOk) continue;
    ASSERT_EQ(size, fw::kStatePacketBytes);
    fw::StatePacket p;
    ASSERT_EQ(fw::decode_state(buf, size, &p), fw::PacketError::kOk);
    EXPECT_EQ(p.magic, kEmulatorStateMagic);
    if (last_counter != 0) {
      EXPECT_EQ(p.counter, last_counter + 1);
    }
    last_counter = p.counter;
    EXPECT_EQ(p.packet_number, p.counter & 0xffu);
    EXPECT_GE(static_cast<double>(p.time), last_time);
    last_time = p.time;
    // button 2 pressed (bit 1 clear), button 1 not (bit 0 set); the tour
    // keeps the stylus out of the inkwell (bit 2 set)
    EXPECT_EQ(p.status, 0x05) << int(p.status);
    if (ea != DeviceError::kOk || eb != DeviceError::kOk ||
        a.timestamp_s != b.timestamp_s) {
      continue;  // the physics published between the reads
    }
    ++matched;
    for (std::size_t j = 0; j < 3; ++j) {
      EXPECT_EQ(static_cast<std::int32_t>(p.encoders[j]), a.encoder_counts[j]);
      EXPECT_EQ(p.gimbal_a[j] >> 5, a.gimbal_pots[j]);
      EXPECT_EQ(p.gimbal_b[j] >> 5, 2047 - a.gimbal_pots[j]);
      EXPECT_EQ(p.gimbal_a[j] & 0x1f, 0);
    }
  }
  t.stop();
  EXPECT_GT(matched, 100);
  EXPECT_GT(last_counter, 200u);
}

// Through the wire and FirewireOmni the angles are the emulator's own (its
// factory calibration) to rounding, over a tour that moves every joint.
TEST(EmulatorFirewire, AnglesThroughTheWireEqualTheEmulators) {
  EmulatorFirewireTransport t(options(HandProgram::kTour));
  Emulator* emu = t.emulator();
  fw::FirewireOmni omni(&t, omni_options(t));
  t.start();
  Joints lo = Joints::Constant(1e9), hi = Joints::Constant(-1e9);
  int matched = 0;
  double worst = 0.0;
  const double end = monotonic_now_s() + 2.0;
  while (monotonic_now_s() < end) {
    if (monotonic_now_s() > end - 1.0) emu->press_buttons(kButton1);
    DeviceState a, w, b;
    const DeviceError ea = emu->read_state(&a);
    const DeviceError ew = omni.read_state(&w);
    const DeviceError eb = emu->read_state(&b);
    sleep_s(1e-3);
    if (ea != DeviceError::kOk || ew != DeviceError::kOk || eb != DeviceError::kOk ||
        a.timestamp_s != b.timestamp_s) {
      continue;
    }
    ++matched;
    worst = std::max(worst, (w.q_device_rad - a.q_device_rad).cwiseAbs().maxCoeff());
    EXPECT_EQ(w.encoder_counts, a.encoder_counts);
    EXPECT_EQ(w.gimbal_pots, a.gimbal_pots);
    EXPECT_EQ(w.buttons, a.buttons);
    EXPECT_EQ(w.docked, a.docked);
    EXPECT_TRUE(w.has(kStateJoints) && w.has(kStateEncoders) && w.has(kStatePots));
    lo = lo.cwiseMin(w.q_device_rad);
    hi = hi.cwiseMax(w.q_device_rad);
  }
  t.stop();
  EXPECT_GT(matched, 500);
  EXPECT_LE(worst, 1e-12);
  // the tour moved all six joints
  for (int j = 0; j < 6; ++j) EXPECT_GT(hi[j] - lo[j], 0.005) << "t" << j + 1;
  std::printf("%d matched readings, largest angle difference %.3g rad\n", matched,
              worst);
}

// A torque written through FirewireOmni reaches the emulator's motors
// with its sign and value, within one 12-bit motor word; motors off is
// zero.
TEST(EmulatorFirewire, TorqueThroughTheWireReachesTheMotors) {
  EmulatorFirewireTransport t(options(HandProgram::kTour));
  Emulator* emu = t.emulator();
  fw::FirewireOmni omni(&t, omni_options(t));
  t.start();
  // one word: the full scale over the 2047 words below zero
  const double step_Nm = fw::kMotorFullScaleEstimate_Nm / 2047.0;
  for (const Vec3& tau : {Vec3(0.1, -0.2, 0.05), Vec3(-0.15, 0.3, -0.012345)}) {
    Vec3 held = Vec3::Zero();
    const bool reached = wait_for(
        [&] {
          omni.write_motor_torques(tau);
          held = emu->truth().motor_torque_Nm;
          return (held - tau).cwiseAbs().maxCoeff() <= step_Nm;
        },
        2.0);
    EXPECT_TRUE(reached) << "asked " << tau.transpose() << ", held "
                         << held.transpose();
    for (int i = 0; i < 3; ++i) EXPECT_GT(held[i] * tau[i], 0.0) << i;
    EXPECT_TRUE(t.last_command().motors_on());
  }
  // motors off: zero words, bit 3 clear, no torque
  EXPECT_TRUE(wait_for(
      [&] {
        omni.send_zero();
        return emu->truth().motor_torque_Nm.isZero(0.0);
      },
      2.0));
  EXPECT_FALSE(t.last_command().motors_on());
  t.stop();
}

// The device's hidden motor scale and sign apply, whatever the host
// believes: motor 2 turns the other way, motor 1 is 20 % weaker than the
// estimate.
TEST(EmulatorFirewire, TheFactoryScaleAndSignAreTheDevicesOwn) {
  EmulatorFirewireOptions o = options(HandProgram::kTour);
  const double est = fw::kMotorFullScaleEstimate_Nm;  // what the host assumes
  o.factory_full_scale_Nm = {0.8 * est, est, est};
  o.factory_motor_sign = {+1, -1, +1};
  EmulatorFirewireTransport t(o);
  fw::FirewireOmni omni(&t, omni_options(t));
  t.start();
  const Vec3 tau(0.1, 0.2, 0.05);
  const Vec3 expected(0.1 * 0.8, -0.2, 0.05);
  const double step_Nm = est / 2047.0;
  Vec3 held = Vec3::Zero();
  EXPECT_TRUE(wait_for(
      [&] {
        omni.write_motor_torques(tau);
        held = t.emulator()->truth().motor_torque_Nm;
        return (held - expected).cwiseAbs().maxCoeff() <= step_Nm;
      },
      2.0))
      << "held " << held.transpose();
  t.stop();
}

TEST(EmulatorFirewire, LossTimesOutTheNextPacketsAndTheCounterShowsTheGap) {
  EmulatorFirewireTransport t(options(HandProgram::kTour));
  fw::FirewireOmni omni(&t, omni_options(t));
  t.start();
  DeviceState s;
  ASSERT_EQ(read_ok(&omni, &s), DeviceError::kOk);
  t.inject({WireFaultKind::kLoss, 0.0, 0.0, 5});
  // the fault is taken at the next packet: five timeouts in a row, then data
  int timeouts = 0;
  DeviceError e = DeviceError::kTimeout;
  for (int i = 0; i < 5; ++i) {
    e = omni.read_state(&s);
    if (e == DeviceError::kTimeout) ++timeouts;
  }
  EXPECT_EQ(timeouts, 5);
  EXPECT_EQ(read_ok(&omni, &s), DeviceError::kOk);
  // the five packets were sent and lost: the counter jumped by six
  EXPECT_EQ(omni.stats().lost_packets, 5u);
  EXPECT_GE(t.stats().timeouts, 5u);
  t.stop();
}

TEST(EmulatorFirewire, WrongLengthsAreBadPacketsThenDataAgain) {
  EmulatorFirewireTransport t(options(HandProgram::kTour));
  t.start();
  std::uint8_t buf[64];
  std::size_t size = 0;
  ASSERT_EQ(receive_ok(&t, buf, &size), TransportStatus::kOk);
  t.inject({WireFaultKind::kLength, 0.0, 0.0, 3});
  std::vector<std::size_t> sizes;
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(t.receive(buf, sizeof buf, &size, 2e-3), TransportStatus::kBadPacket);
    sizes.push_back(size);
  }
  EXPECT_EQ(sizes, (std::vector<std::size_t>{43, 45, 43}));
  EXPECT_EQ(receive_ok(&t, buf, &size), TransportStatus::kOk);
  EXPECT_EQ(size, 44u);
  EXPECT_EQ(t.stats().bad_packets, 3u);

  // through the device: kIo for each, then readings
  fw::FirewireOmni omni(&t, omni_options(t));
  DeviceState s;
  ASSERT_EQ(read_ok(&omni, &s), DeviceError::kOk);
  t.inject({WireFaultKind::kLength, 0.0, 0.0, 2});
  EXPECT_EQ(omni.read_state(&s), DeviceError::kIo);
  EXPECT_EQ(omni.read_state(&s), DeviceError::kIo);
  EXPECT_EQ(read_ok(&omni, &s), DeviceError::kOk);
  EXPECT_EQ(omni.stats().bad_packets, 2u);
  t.stop();
}

TEST(EmulatorFirewire, BusResetUntilRecoverWithTheMotorsAtZero) {
  EmulatorFirewireTransport t(options(HandProgram::kTour));
  Emulator* emu = t.emulator();
  fw::FirewireOmni omni(&t, omni_options(t));
  t.start();
  const Vec3 tau(0.1, 0.1, 0.1);
  ASSERT_TRUE(wait_for(
      [&] {
        omni.write_motor_torques(tau);
        return emu->truth().motor_torque_Nm.isApprox(tau, 1e-2);
      },
      2.0));
  const std::uint32_t generation = t.node().generation;
  t.inject({WireFaultKind::kReset, 0.0, 0.0, 0});
  std::uint8_t buf[64];
  std::size_t size = 0;
  // at the transport: reset on every call until recover()
  EXPECT_EQ(t.receive(buf, sizeof buf, &size, 2e-3), TransportStatus::kBusReset);
  EXPECT_EQ(t.receive(buf, sizeof buf, &size, 2e-3), TransportStatus::kBusReset);
  std::uint8_t cmd[fw::kCommandPacketBytes];
  fw::CommandPacket c;
  c.motor = {0x0fff, 0x0fff, 0x0fff};
  c.status = fw::kCommandStatusInitial | fw::kCommandMotorsOn;
  fw::encode_command(c, cmd);
  EXPECT_EQ(t.send(cmd, sizeof cmd), TransportStatus::kBusReset);
  EXPECT_EQ(t.node().generation, generation + 1);
  // nothing reaches the motors meanwhile
  EXPECT_TRUE(wait_for([&] { return emu->truth().motor_torque_Nm.isZero(0.0); }, 2.0));
  EXPECT_EQ(t.stats().bus_resets, 1u);
  EXPECT_EQ(t.recover(), TransportStatus::kOk);
  EXPECT_EQ(t.stats().recoveries, 1u);
  EXPECT_EQ(receive_ok(&t, buf, &size), TransportStatus::kOk);

  // through the device: one tick without a reading (it recovers), then data
  // and torque again
  t.inject({WireFaultKind::kReset, 0.0, 0.0, 0});
  DeviceState s;
  EXPECT_EQ(omni.read_state(&s), DeviceError::kNotConnected);
  EXPECT_EQ(read_ok(&omni, &s), DeviceError::kOk);
  EXPECT_EQ(t.stats().bus_resets, 2u);
  EXPECT_EQ(t.stats().recoveries, 2u);
  EXPECT_EQ(omni.stats().bus_resets, 1u);
  EXPECT_TRUE(wait_for(
      [&] {
        omni.write_motor_torques(tau);
        return emu->truth().motor_torque_Nm.isApprox(tau, 1e-2);
      },
      2.0));
  t.stop();
}

// Unplugged: kNotConnected and zero torque for the duration, however hard
// the host keeps writing; then back, readings and torque again.
TEST(EmulatorFirewire, UnplugIsDisconnectedWithZeroTorqueThenBack) {
  EmulatorFirewireTransport t(options(HandProgram::kTour));
  Emulator* emu = t.emulator();
  fw::FirewireOmni omni(&t, omni_options(t));
  t.start();
  const Vec3 tau(0.1, -0.1, 0.1);
  ASSERT_TRUE(wait_for(
      [&] {
        omni.write_motor_torques(tau);
        return emu->truth().motor_torque_Nm.isApprox(tau, 1e-2);
      },
      2.0));
  t.inject({WireFaultKind::kUnplug, 0.0, 0.4, 0});
  double torque_while_unplugged = 0.0;
  long unplugged_ticks = 0;
  const auto runs = servo_for(&omni, tau, 1.2, [&](double) {
    const EmulatorTruth truth = emu->truth();
    if (truth.unplugged) {
      ++unplugged_ticks;
      torque_while_unplugged =
          std::max(torque_while_unplugged, truth.motor_torque_Nm.cwiseAbs().maxCoeff());
    }
  });
  // ok ... not_connected ... ok (a timeout or two allowed around them on a
  // loaded machine)
  std::vector<ErrorRun> steady;
  for (const ErrorRun& r : runs) {
    if (r.error == DeviceError::kTimeout) continue;
    if (!steady.empty() && steady.back().error == r.error) {
      steady.back().ticks += r.ticks;
    } else {
      steady.push_back(r);
    }
  }
  ASSERT_GE(steady.size(), 3u) << runs_text(runs);
  EXPECT_EQ(steady.front().error, DeviceError::kOk) << runs_text(runs);
  EXPECT_EQ(steady[1].error, DeviceError::kNotConnected) << runs_text(runs);
  EXPECT_GE(steady[1].ticks, 100) << runs_text(runs);  // ~0.4 s of 1 ms ticks
  EXPECT_EQ(steady.back().error, DeviceError::kOk) << runs_text(runs);
  EXPECT_EQ(std::count_if(steady.begin(), steady.end(),
                          [](const ErrorRun& r) { return r.error == DeviceError::kNotConnected; }),
            1)
      << runs_text(runs);
  EXPECT_GT(unplugged_ticks, 100);
  EXPECT_EQ(torque_while_unplugged, 0.0);
  // and the torque is back
  EXPECT_TRUE(emu->truth().motor_torque_Nm.isApprox(tau, 1e-2))
      << emu->truth().motor_torque_Nm.transpose();
  t.stop();
}

// Late: every packet K periods old (its time field says so), then fresh.
TEST(EmulatorFirewire, LatePacketsAreOldThenFreshAgain) {
  EmulatorFirewireTransport t(options(HandProgram::kTour));
  t.start();
  std::uint8_t buf[64];
  std::size_t size = 0;
  fw::StatePacket p;
  ASSERT_EQ(receive_ok(&t, buf, &size), TransportStatus::kOk);
  fw::decode_state(buf, size, &p);
  // a packet's age, up to a constant: wall time now minus its time field
  const double w0 = monotonic_now_s();
  const double t0 = 1e-6 * p.time;
  const auto age = [&] { return (monotonic_now_s() - w0) - (1e-6 * p.time - t0); };
  const double fresh_age = age();
  t.inject({WireFaultKind::kLate, 0.0, 0.3, 20});
  ASSERT_TRUE(wait_for([&] { return t.emulator()->truth().late; }, 2.0));
  double late_age = 0.0;
  for (int i = 0; i < 50; ++i) {
    ASSERT_EQ(receive_ok(&t, buf, &size), TransportStatus::kOk);
    fw::decode_state(buf, size, &p);
    late_age = std::max(late_age, age());
    sleep_s(1e-3);
  }
  // 20 periods of 1 ms behind, give or take the ones dropped catching up
  EXPECT_GT(late_age - fresh_age, 0.010);
  ASSERT_TRUE(wait_for([&] { return !t.emulator()->truth().late; }, 2.0));
  double fresh_again = 1.0;
  for (int i = 0; i < 20; ++i) {
    ASSERT_EQ(receive_ok(&t, buf, &size), TransportStatus::kOk);
    fw::decode_state(buf, size, &p);
    fresh_again = std::min(fresh_again, age());
    sleep_s(1e-3);
  }
  EXPECT_LT(fresh_again - fresh_age, 0.005);
  t.stop();
}

// A stall: no packets at all (timeouts), and none counted as lost.
TEST(EmulatorFirewire, StallSendsNothing) {
  EmulatorFirewireTransport t(options(HandProgram::kTour));
  fw::FirewireOmni omni(&t, omni_options(t));
  t.start();
  DeviceState s;
  ASSERT_EQ(read_ok(&omni, &s), DeviceError::kOk);
  t.inject({WireFaultKind::kStall, 0.0, 0.3, 0});
  EXPECT_TRUE(wait_for([&] { return omni.read_state(&s) == DeviceError::kTimeout; }, 2.0));
  EXPECT_TRUE(wait_for([&] { return omni.read_state(&s) == DeviceError::kOk; }, 2.0));
  EXPECT_EQ(omni.stats().lost_packets, 0u);
  t.stop();
}

TEST(EmulatorFirewire, ReceiveAndSendAllocateNothing) {
  EmulatorFirewireTransport t(options(HandProgram::kTour));
  fw::FirewireOmni omni(&t, omni_options(t));
  t.start();
  DeviceState s;
  ASSERT_EQ(read_ok(&omni, &s), DeviceError::kOk);
  // faults scheduled ahead, so that taking them is counted too
  t.inject({WireFaultKind::kLoss, 0.0, 0.0, 2});
  t.inject({WireFaultKind::kLength, 0.0, 0.0, 2});
  t.inject({WireFaultKind::kReset, 0.0, 0.0, 0});
  std::size_t allocations = 0;
  long ok = 0;
  {
    vmh::testing::AllocationScope scope;
    for (int i = 0; i < 500; ++i) {
      if (omni.read_state(&s) == DeviceError::kOk) ++ok;
      omni.write_motor_torques(Vec3(0.01, -0.01, 0.01));
      const timespec pause{0, 500000};
      nanosleep(&pause, nullptr);
    }
    allocations = scope.count();
  }
  t.stop();
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(ok, 100);
  EXPECT_EQ(t.stats().bus_resets, 1u);
}

}  // namespace
}  // namespace vmh::sim
