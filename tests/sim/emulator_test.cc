// sim/emulator: the MuJoCo Omni in real time behind HapticDevice. These
// tests run the physics thread for real; they wait for what must happen
// (with generous limits) and assert what happened, never how long it took.
#include "sim/emulator.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "device/tick_timer.h"
#include "sim/closed_loop.h"
#include "sim/sensor_model.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/wait.h"

namespace vmh::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

EmulatorOptions options(HandProgram p) {
  EmulatorOptions o;
  o.scene = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";
  o.hand = p;
  return o;
}

using vmh::testing::sleep_s;
using vmh::testing::wait_for;

// a reading, retried for up to a second: a loaded machine can delay the
// physics thread by the three periods after which a read times out
DeviceError read_ok(Emulator* emu, DeviceState* s) {
  DeviceError e = emu->read_state(s);
  const double end = monotonic_now_s() + 1.0;
  while (e == DeviceError::kTimeout && monotonic_now_s() < end) {
    sleep_s(2e-4);
    e = emu->read_state(s);
  }
  return e;
}
DeviceError read_ok(Emulator* emu, Joints* q) {
  DeviceState s;
  const DeviceError e = read_ok(emu, &s);
  if (e == DeviceError::kOk) *q = s.q_device_rad;
  return e;
}

// keeps writing `tau` every millisecond for s seconds (feeds the device's
// watchdog as a servo loop would)
void hold_torque(Emulator* emu, const Vec3& tau, double s) {
  const double end = monotonic_now_s() + s;
  while (monotonic_now_s() < end) {
    emu->write_motor_torques(tau);
    sleep_s(1e-3);
  }
}

TEST(Emulator, ReadsAdvanceWithIncreasingTimestamps) {
  Emulator emu(options(HandProgram::kTour));
  DeviceState s;
  EXPECT_EQ(emu.read_state(&s), DeviceError::kNotConnected);  // not started
  emu.start();
  double last_stamp = -1.0;
  long last_periods = -1;
  for (int i = 0; i < 5; ++i) {
    sleep_s(0.01);
    ASSERT_EQ(read_ok(&emu, &s), DeviceError::kOk);
    EXPECT_GT(s.timestamp_s, last_stamp);
    last_stamp = s.timestamp_s;
    const long periods = emu.truth().periods;
    EXPECT_GT(periods, last_periods);
    last_periods = periods;
  }
  // the device's own kinematics too, as OpenHaptics reports them
  // (emulator_kinematics_test.cc checks their values); no safety switch
  for (DeviceStateField f : {kStateJoints, kStateButtons, kStateInkwell,
                             kStateTimestamp, kStateEncoders, kStatePots,
                             kStateTransform, kStateVelocity, kStateJacobian}) {
    EXPECT_TRUE(s.has(f)) << f;
  }
  EXPECT_FALSE(s.has(kStateSafetySwitch));
  emu.press_buttons(kButton1 | kButton2);
  ASSERT_EQ(read_ok(&emu, &s), DeviceError::kOk);
  EXPECT_EQ(s.buttons, kButton1 | kButton2);
  emu.stop();
  emu.stop();  // idempotent
  EXPECT_EQ(emu.read_state(&s), DeviceError::kNotConnected);
}

TEST(Emulator, TourMovesAllSixJoints) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  Joints lo = Joints::Constant(1e9), hi = Joints::Constant(-1e9);
  const double end = monotonic_now_s() + 3.0;
  while (monotonic_now_s() < end) {
    Joints q;
    if (emu.read_joints(&q) == DeviceError::kOk) {
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
    sleep_s(2e-3);
  }
  const EmulatorTruth t = emu.truth();
  emu.stop();
  std::printf("tour: %ld periods stepped, %ld dropped to stay in real time\n",
              t.periods, t.lag_periods);
  for (int i = 0; i < 6; ++i) {
    EXPECT_GT(hi[i] - lo[i], 0.05) << "t" << i + 1 << " barely moved";
  }
}

TEST(Emulator, PositiveMotorOneTorqueTurnsT1Positively) {
  // physics: a positive generalised force on a hinge accelerates it
  // positively. Motor t1 drives t1, and t1 = -q1 (docs/sources.md §5), so
  // from rest with the hand let go, +0.05 N m on motor 1 must raise t1
  // and lower MuJoCo's q1.
  Emulator emu(options(HandProgram::kNone));
  emu.start();
  sleep_s(0.05);
  Joints q0;
  ASSERT_EQ(read_ok(&emu, &q0), DeviceError::kOk);
  const double q1_true0 = emu.truth().q_true_dh[0];
  hold_torque(&emu, Vec3(0.05, 0.0, 0.0), 0.3);
  Joints q1;
  ASSERT_EQ(read_ok(&emu, &q1), DeviceError::kOk);
  const EmulatorTruth t = emu.truth();
  emu.stop();
  EXPECT_GT(q1[0] - q0[0], 0.02);
  EXPECT_LT(t.q_true_dh[0] - q1_true0, -0.02);
  EXPECT_NEAR(t.motor_torque_Nm[0], 0.05, 1e-12);
  // the hand let go: its spring and damper are zeroed at each step's start;
  // what is left is RK4's inner stages (the grip moved by part of a step)
  EXPECT_LT(t.hand_force_N.norm(), 0.05);
  std::printf("hand force while let go: %.2e N\n", t.hand_force_N.norm());
}

TEST(Emulator, NonFiniteWriteHoldsZeroTorque) {
  Emulator emu(options(HandProgram::kNone));
  emu.start();
  hold_torque(&emu, Vec3(0.1, 0.0, 0.0), 0.02);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[0], 0.1, 1e-12);
  EXPECT_EQ(emu.write_motor_torques(Vec3(0.1, std::nan(""), 0.0)),
            DeviceError::kInvalidCommand);
  ASSERT_TRUE(wait_for([&] { return emu.truth().invalid_command; }, 1.0));
  EXPECT_EQ(emu.truth().motor_torque_Nm, Vec3::Zero());
  emu.stop();
}

TEST(Emulator, DeviceWatchdogZeroesTorqueWithoutWrites) {
  EmulatorOptions o = options(HandProgram::kNone);
  o.device_watchdog_s = 0.05;
  Emulator emu(o);
  emu.start();
  hold_torque(&emu, Vec3(0.0, 0.1, 0.0), 0.02);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[1], 0.1, 1e-12);
  EXPECT_FALSE(emu.truth().device_watchdog_fired);
  // no more writes: the device zeroes the motors by itself
  ASSERT_TRUE(wait_for([&] { return emu.truth().device_watchdog_fired; }, 1.0));
  EXPECT_EQ(emu.truth().motor_torque_Nm, Vec3::Zero());
  // a write brings the torque back
  hold_torque(&emu, Vec3(0.0, 0.1, 0.0), 0.02);
  EXPECT_FALSE(emu.truth().device_watchdog_fired);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[1], 0.1, 1e-12);
  emu.stop();
}

// counts read results over s seconds, reading every 0.5 ms
struct ReadCounts {
  int ok = 0, timeout = 0, not_connected = 0, other = 0;
};
ReadCounts read_for(Emulator* emu, double s) {
  ReadCounts c;
  const double end = monotonic_now_s() + s;
  while (monotonic_now_s() < end) {
    DeviceState st;
    switch (emu->read_state(&st)) {
      case DeviceError::kOk: ++c.ok; break;
      case DeviceError::kTimeout: ++c.timeout; break;
      case DeviceError::kNotConnected: ++c.not_connected; break;
      default: ++c.other; break;
    }
    sleep_s(5e-4);
  }
  return c;
}

TEST(Emulator, DropFaultTimesOutExactlyCountReads) {
  // a slow physics (10 ms periods): a loaded machine does not delay it the
  // three periods that would make a read time out by itself
  EmulatorOptions o = options(HandProgram::kTour);
  o.realtime_factor = 0.1;
  Emulator emu(o);
  emu.start();
  sleep_s(0.02);
  emu.inject({EmulatorFaultKind::kDrop, 0.0, 0.0, 5});
  ASSERT_TRUE(wait_for([&] { return emu.truth().drops_pending == 5; }, 1.0));
  const ReadCounts c = read_for(&emu, 0.1);
  emu.stop();
  EXPECT_EQ(c.timeout, 5);
  EXPECT_GT(c.ok, 0);  // recovered
}

TEST(Emulator, LateFaultDeliversOldReadings) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  sleep_s(0.05);
  emu.inject({EmulatorFaultKind::kLate, 0.0, 0.3, 40});
  ASSERT_TRUE(wait_for([&] { return emu.truth().late; }, 1.0));
  sleep_s(0.01);
  DeviceState s;
  ASSERT_EQ(read_ok(&emu, &s), DeviceError::kOk);
  // 40 periods old: older than 20 periods by any measure
  EXPECT_LT(s.timestamp_s, monotonic_now_s() - 20 * emu.servo_period_s());
  ASSERT_TRUE(wait_for([&] { return !emu.truth().late; }, 2.0));
  sleep_s(0.01);
  ASSERT_EQ(read_ok(&emu, &s), DeviceError::kOk);
  EXPECT_GT(s.timestamp_s, monotonic_now_s() - 20 * emu.servo_period_s());
  emu.stop();
}

TEST(Emulator, StallTimesOutThenRecovers) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  sleep_s(0.02);
  emu.inject({EmulatorFaultKind::kStall, 0.0, 0.3, 0});
  const ReadCounts c = read_for(&emu, 0.6);
  const long periods_a = emu.truth().periods;
  sleep_s(0.02);
  const long periods_b = emu.truth().periods;
  emu.stop();
  EXPECT_GT(c.timeout, 10);
  EXPECT_GT(c.ok, 10);
  EXPECT_GT(periods_b, periods_a);  // the physics runs again
}

TEST(Emulator, UnplugCutsReadsAndMotorsThenReplugs) {
  Emulator emu(options(HandProgram::kNone));
  emu.start();
  hold_torque(&emu, Vec3(0.05, 0.0, 0.0), 0.02);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[0], 0.05, 1e-12);
  emu.inject({EmulatorFaultKind::kUnplug, 0.0, 0.3, 0});
  ASSERT_TRUE(wait_for([&] { return emu.truth().unplugged; }, 1.0));
  DeviceState s;
  EXPECT_EQ(emu.read_state(&s), DeviceError::kNotConnected);
  EXPECT_EQ(emu.write_motor_torques(Vec3(0.05, 0, 0)), DeviceError::kNotConnected);
  sleep_s(0.01);
  EXPECT_EQ(emu.truth().motor_torque_Nm, Vec3::Zero());
  ASSERT_TRUE(wait_for([&] { return !emu.truth().unplugged; }, 2.0));
  EXPECT_EQ(read_ok(&emu, &s), DeviceError::kOk);
  hold_torque(&emu, Vec3(0.05, 0.0, 0.0), 0.02);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[0], 0.05, 1e-12);
  emu.stop();
}

TEST(Emulator, DockProgramReachesTheInkwell) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  sleep_s(0.2);
  DeviceState s;
  ASSERT_EQ(read_ok(&emu, &s), DeviceError::kOk);
  EXPECT_FALSE(s.docked);
  emu.set_hand_program(HandProgram::kDock);
  ASSERT_TRUE(wait_for([&] { return emu.truth().docked; }, 4.5));
  sleep_s(0.01);
  ASSERT_EQ(read_ok(&emu, &s), DeviceError::kOk);
  EXPECT_TRUE(s.docked);
  // independently: the wrist centre is within 5 mm of the inkwell's, by
  // omni_fk of the inkwell joint angles
  const OmniParams omni = emu.loop().controller_params().omni;
  Joints ink;
  for (int i = 0; i < 6; ++i) ink[i] = kInkwellDevice_rad[i];
  const Vec3 ink_mm =
      base_to_device_mm(omni, omni_fk(omni, device_to_dh_joints(ink)).p_base_m);
  EXPECT_LT((emu.truth().p_end_mm - ink_mm).norm(), kDockRadius_mm);
  // the inkwell is where docs/omni.md puts it (OpenHaptics's dock point)
  EXPECT_NEAR(ink_mm.y(), -65.51, 1.0);
  EXPECT_NEAR(ink_mm.z(), -88.11, 1.0);
  emu.stop();
}

TEST(Emulator, CaseProgramPlaysTheScenesScript) {
  EmulatorOptions o = options(HandProgram::kCase);
  o.realtime_factor = 4.0;  // 4 s of the script in 1 s
  Emulator emu(o);
  emu.start();
  ASSERT_TRUE(wait_for([&] { return emu.truth().t_sim_s > 4.0; }, 3.0));
  const EmulatorTruth t = emu.truth();
  emu.stop();
  // the target of the period that ended at t_sim_s was set at its start
  const double t0 = t.t_sim_s - emu.servo_period_s();
  const ScriptPose want = emu.loop().script().at(t0);
  EXPECT_LT((t.hand_target.p_mm - want.p_mm).norm(), 1e-9);
  EXPECT_EQ(t.segment, emu.loop().script().segment_at(t0));
  EXPECT_GE(t.segment, 1);
  EXPECT_TRUE(t.state_finite);
}

TEST(Emulator, GimbalSweepReachesBothEndsOfEachGimbalJoint) {
  EmulatorOptions o = options(HandProgram::kGimbalSweep);
  o.realtime_factor = 3.0;  // the 9 s sweep in 3 s
  Emulator emu(o);
  emu.start();
  Joints lo = Joints::Constant(1e9), hi = Joints::Constant(-1e9);
  const double end = monotonic_now_s() + 4.0;
  while (monotonic_now_s() < end && emu.truth().t_sim_s < 9.5) {
    DeviceState s;
    if (emu.read_state(&s) == DeviceError::kOk) {
      lo = lo.cwiseMin(s.q_device_rad);
      hi = hi.cwiseMax(s.q_device_rad);
    }
    sleep_s(5e-4);
  }
  emu.stop();
  // each gimbal joint within 0.15 rad of both ends of its range (the
  // device convention's range is the DH one, symmetric, docs/sources.md §5)
  const OmniParams omni = emu.loop().controller_params().omni;
  for (int i = 3; i < 6; ++i) {
    const double top = omni.joint_upper_rad[static_cast<std::size_t>(i)];
    EXPECT_GT(hi[i], top - 0.15) << "t" << i + 1;
    EXPECT_LT(lo[i], -top + 0.15) << "t" << i + 1;
  }
}

TEST(Emulator, RawReadingsDecodeToTheReportedAngles) {
  Emulator emu(options(HandProgram::kNone));  // at rest: truth and reading agree
  emu.start();
  sleep_s(0.05);
  DeviceState s;
  ASSERT_EQ(read_ok(&emu, &s), DeviceError::kOk);
  const EmulatorTruth t = emu.truth();
  const hw::OmniCalibration f = emu.factory_calibration();
  // §9.2 by hand: t_i = offset_i + sign_i 2 pi count / 15000, sign (-1,1,1)
  const double sign[3] = {-1, 1, 1};
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    EXPECT_NEAR(f.encoder_offset_rad[k] + sign[i] * 2 * kPi * s.encoder_counts[k] / 15000,
                s.q_device_rad[i], 1e-12);
    EXPECT_NEAR(f.pot_gain_rad[k] * s.gimbal_pots[k] + f.pot_offset_rad[k],
                s.q_device_rad[i + 3], 1e-12);
  }
  // and the angles are SimDevice's: the sensor model on the true angles
  const SensorModel sensor(emu.loop().controller_params().omni, true);
  const Joints expect = sensor.measure(dh_to_device_joints(t.q_end_dh));
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(s.q_device_rad[i], expect[i], 1e-12) << i;
  // the factory calibration has offsets (it is not the identity)
  EXPECT_GT(std::abs(f.encoder_offset_rad[0]), 0.1);
  // another calibration moves the reading by its offset
  hw::OmniCalibration c = f;
  c.encoder_offset_rad[1] += 0.01;
  emu.set_calibration(c);
  sleep_s(0.01);
  DeviceState s2;
  ASSERT_EQ(read_ok(&emu, &s2), DeviceError::kOk);
  EXPECT_NEAR(s2.q_device_rad[1] - s.q_device_rad[1], 0.01, 1e-9);
  c.pot_gain_rad[0] = 0.0;
  EXPECT_THROW(emu.set_calibration(c), std::invalid_argument);
  emu.stop();
}

TEST(Emulator, ServoCallsAllocateNothingAlongsidePhysics) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  sleep_s(0.02);
  // a servo thread for 1 s (created before counting starts: creating a
  // thread allocates), reading and writing every 0.25 ms while the physics
  // thread steps; a timeout is allowed (a loaded machine can delay the
  // physics by three periods), any other error or a step back in time is not
  std::atomic<bool> go{false};
  std::atomic<long> ok{0}, timeouts{0}, bad{0}, backwards{0};
  std::thread servo([&] {
    while (!go.load()) std::this_thread::yield();
    const double end = monotonic_now_s() + 1.0;
    DeviceState s;
    double last_stamp = 0.0;
    while (monotonic_now_s() < end) {
      const DeviceError e = emu.read_state(&s);
      if (e == DeviceError::kOk) {
        ok.fetch_add(1);
        if (s.timestamp_s < last_stamp || !s.q_device_rad.allFinite()) {
          backwards.fetch_add(1);
        }
        last_stamp = s.timestamp_s;
      } else if (e == DeviceError::kTimeout) {
        timeouts.fetch_add(1);
      } else {
        bad.fetch_add(1);
      }
      Joints q;
      const DeviceError e2 = emu.read_joints(&q);
      if (e2 != DeviceError::kOk && e2 != DeviceError::kTimeout) bad.fetch_add(1);
      if (emu.write_motor_torques(Vec3(0.01, -0.01, 0.01)) != DeviceError::kOk) {
        bad.fetch_add(1);
      }
      const timespec pause{0, 250000};
      nanosleep(&pause, nullptr);
    }
  });
  std::size_t allocations = 0;
  {
    vmh::testing::AllocationScope scope;  // counts every thread's new
    go.store(true);
    // every hand program runs in the physics thread meanwhile
    for (HandProgram p : {HandProgram::kCase, HandProgram::kNone,
                          HandProgram::kDock, HandProgram::kGimbalSweep,
                          HandProgram::kTour}) {
      emu.set_hand_program(p);
      sleep_s(0.15);
    }
    while (ok.load() + timeouts.load() + bad.load() < 1000) sleep_s(0.01);
    allocations = scope.count();
  }
  servo.join();
  emu.stop();
  EXPECT_EQ(allocations, 0u);
  EXPECT_GT(ok.load(), 500);
  EXPECT_EQ(bad.load(), 0);
  EXPECT_EQ(backwards.load(), 0);
  std::printf("servo thread: %ld good reads, %ld timeouts\n", ok.load(),
              timeouts.load());
}

TEST(Emulator, IdentityNamesTheEmulator) {
  EmulatorOptions o = options(HandProgram::kTour);
  o.serial = "EMU-0042";
  Emulator emu(o);
  const DeviceIdentity id = emu.identity();
  EXPECT_EQ(id.backend, "emulator");
  EXPECT_EQ(id.serial, "EMU-0042");
  EXPECT_EQ(id.input_dof, 6);
  EXPECT_EQ(id.output_dof, 3);
  EXPECT_EQ(id.api_version.rfind("MuJoCo 2.", 0), 0u);
  // a different serial, a different hidden calibration
  Emulator other(options(HandProgram::kTour));
  EXPECT_NE(other.factory_calibration().encoder_offset_rad,
            emu.factory_calibration().encoder_offset_rad);
}

TEST(EmulatorFaults, ParseTheExample) {
  const auto f = parse_emulator_faults("drop@1.0:5,late@2.0:0.5:3,stall@3:0.2,unplug@4:1");
  ASSERT_EQ(f.size(), 4u);
  EXPECT_EQ(f[0].kind, EmulatorFaultKind::kDrop);
  EXPECT_EQ(f[0].at_s, 1.0);
  EXPECT_EQ(f[0].count, 5);
  EXPECT_EQ(f[1].kind, EmulatorFaultKind::kLate);
  EXPECT_EQ(f[1].duration_s, 0.5);
  EXPECT_EQ(f[1].count, 3);
  EXPECT_EQ(f[2].kind, EmulatorFaultKind::kStall);
  EXPECT_EQ(f[2].duration_s, 0.2);
  EXPECT_EQ(f[3].kind, EmulatorFaultKind::kUnplug);
  EXPECT_EQ(f[3].at_s, 4.0);
  EXPECT_TRUE(parse_emulator_faults("").empty());
}

TEST(EmulatorFaults, BadItemIsNamed) {
  for (const char* bad : {"drop@1", "fizz@1:2", "late@1:0.5:0", "stall@x:1",
                          "unplug@1:-1", "drop@-1:3", "stall1:2"}) {
    try {
      parse_emulator_faults(std::string("drop@0:1,") + bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(parse_hand_program("juggle"), std::invalid_argument);
  EXPECT_EQ(parse_hand_program(hand_program_name(HandProgram::kGimbalSweep)),
            HandProgram::kGimbalSweep);
}

}  // namespace
}  // namespace vmh::sim
