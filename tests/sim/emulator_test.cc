// sim/emulator: the MuJoCo Omni behind HapticDevice.
//
// Every suite but EmulatorRealtime runs the emulator in lockstep
// (EmulatorOptions::lockstep): there is no physics thread, and the test runs
// each servo period itself with advance(). A servo tick here is "write a
// command, advance(), read": the command is held over the period, and the
// reading published at the period's end is read at once. The emulator's
// clock is (periods advanced) x period, so every reading, truth and fault
// falls on a known period: the tests assert exact counts and values, and
// their verdicts do not depend on how busy the machine is.
//
// A fault ends at the first period start at or past its end. The emulator
// compares times on its lockstep clock with a tolerance of a millionth of a
// period, so a duration of a whole number of periods (StallTimesOut-
// ThenRecovers' 0.3 s) ends exactly on its period; most tests give theirs
// half a period off the grid (0.3005 s), where no rounding could matter.
//
// EmulatorRealtime runs the physics thread on the wall clock, for what only
// it can show: it keeps its period beside a servo thread, stop() joins
// promptly, a starved thread is named by stall_cause(), the device watchdog
// counts wall time. Those tests are labelled realtime and run alone
// (tests/CMakeLists.txt), and assert only what holds on a loaded host.
#include "sim/emulator.h"

#include <gtest/gtest.h>
#include <time.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "device/tick_timer.h"
#include "sim/closed_loop.h"
#include "sim/sensor_model.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/wait.h"
#include "tests/support/constants.h"

namespace vmh::sim {
namespace {

using vmh::testing::kPi;

// a fault's duration, s, and the whole servo periods (1 ms in case1) it
// lasts: taken at the start of a period, over from the first period start
// at or past its end, 300.5 periods later
constexpr double kFault_s = 0.3005;
constexpr long kFaultPeriods = 301;

// in lockstep
EmulatorOptions options(HandProgram p) {
  EmulatorOptions o;
  o.lockstep = true;
  o.scene = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";
  o.hand = p;
  return o;
}

// the physics thread on the wall clock (EmulatorRealtime only)
EmulatorOptions wall_options(HandProgram p) {
  EmulatorOptions o = options(p);
  o.lockstep = false;
  return o;
}

// n servo periods with no new command (the last one written stays held)
void run(Emulator* emu, long n) {
  for (long i = 0; i < n; ++i) emu->advance();
}

// n servo ticks writing tau before each period, as a servo loop does (which
// also keeps the device watchdog fed)
void hold(Emulator* emu, const Vec3& tau, long n) {
  for (long i = 0; i < n; ++i) {
    ASSERT_EQ(emu->write_motor_torques(tau), DeviceError::kOk) << i;
    emu->advance();
  }
}

// the emulator's clock after n periods, s: n x period, computed as the
// emulator computes it, so that times compare exactly
double clock_at(const Emulator& emu, long n) {
  return static_cast<double>(n) * emu.servo_period_s();
}

TEST(Emulator, LockstepClockCountsPeriods) {
  Emulator emu(options(HandProgram::kTour));
  EXPECT_TRUE(emu.lockstep());
  emu.advance();  // not started: nothing runs
  EXPECT_EQ(emu.clock_s(), 0.0);
  EXPECT_EQ(emu.truth().periods, 0);
  emu.start();
  EXPECT_EQ(emu.clock_s(), 0.0);
  // the start state is published at time 0, before any period
  DeviceState s;
  ASSERT_EQ(emu.read_state(&s), DeviceError::kOk);
  EXPECT_EQ(s.timestamp_s, 0.0);
  run(&emu, 7);
  EXPECT_EQ(emu.clock_s(), clock_at(emu, 7));
  const EmulatorTruth t = emu.truth();
  EXPECT_EQ(t.periods, 7);
  EXPECT_EQ(t.t_sim_s, clock_at(emu, 7));
  EXPECT_EQ(t.wall_s, clock_at(emu, 7));
  EXPECT_EQ(t.lag_periods, 0);
  EXPECT_THROW(emu.start(), DeviceOpenError);
  emu.stop();
  emu.advance();  // stopped: nothing runs
  EXPECT_EQ(emu.clock_s(), clock_at(emu, 7));
  // a restart is a fresh run from time 0
  emu.start();
  EXPECT_EQ(emu.clock_s(), 0.0);
  EXPECT_EQ(emu.truth().periods, 0);
}

TEST(Emulator, ReadsAdvanceWithIncreasingTimestamps) {
  Emulator emu(options(HandProgram::kTour));
  DeviceState s;
  EXPECT_EQ(emu.read_state(&s), DeviceError::kNotConnected);  // not started
  emu.start();
  for (long i = 1; i <= 5; ++i) {
    run(&emu, 10);
    // the reading of the period just run: no retry, no timeout. Its stamp
    // and the truth's period count are exactly 10 periods on from the last
    // read's (the old test, on the wall clock, could ask only that they grew)
    ASSERT_EQ(emu.read_state(&s), DeviceError::kOk) << i;
    EXPECT_EQ(s.timestamp_s, clock_at(emu, 10 * i));
    EXPECT_EQ(emu.truth().periods, 10 * i);
  }
  // the device's own kinematics too, as OpenHaptics reports them
  // (emulator_kinematics_test.cc checks their values); no safety switch
  for (DeviceStateField f : {kStateJoints, kStateButtons, kStateInkwell,
                             kStateTimestamp, kStateEncoders, kStatePots,
                             kStateTransform, kStateVelocity, kStateJacobian}) {
    EXPECT_TRUE(s.has(f)) << f;
  }
  EXPECT_FALSE(s.has(kStateSafetySwitch));
  // the buttons are sampled at the read: no period needs to pass
  emu.press_buttons(kButton1 | kButton2);
  ASSERT_EQ(emu.read_state(&s), DeviceError::kOk);
  EXPECT_EQ(s.buttons, kButton1 | kButton2);
  emu.stop();
  emu.stop();  // idempotent
  EXPECT_EQ(emu.read_state(&s), DeviceError::kNotConnected);
}

// The point of lockstep: the same settings and commands give the same
// readings and the same truth, to the last bit.
TEST(Emulator, LockstepRunsAreRepeatable) {
  Emulator a(options(HandProgram::kTour)), b(options(HandProgram::kTour));
  a.start();
  b.start();
  for (int k = 0; k < 500; ++k) {
    const Vec3 tau(0.02 * std::sin(0.01 * k), -0.01, 0.015 * std::cos(0.02 * k));
    ASSERT_EQ(a.write_motor_torques(tau), DeviceError::kOk);
    ASSERT_EQ(b.write_motor_torques(tau), DeviceError::kOk);
    a.advance();
    b.advance();
    DeviceState sa, sb;
    ASSERT_EQ(a.read_state(&sa), DeviceError::kOk);
    ASSERT_EQ(b.read_state(&sb), DeviceError::kOk);
    ASSERT_TRUE(sa.q_device_rad == sb.q_device_rad) << k;
    ASSERT_EQ(sa.encoder_counts, sb.encoder_counts) << k;
    ASSERT_EQ(sa.gimbal_pots, sb.gimbal_pots) << k;
    ASSERT_TRUE(sa.transform_mm == sb.transform_mm) << k;
    ASSERT_TRUE(sa.velocity_mm_s == sb.velocity_mm_s) << k;
    ASSERT_EQ(sa.timestamp_s, sb.timestamp_s) << k;
    const EmulatorTruth ta = a.truth(), tb = b.truth();
    ASSERT_TRUE(ta.q_end_dh == tb.q_end_dh) << k;
    ASSERT_TRUE(ta.motor_torque_Nm == tb.motor_torque_Nm) << k;
    ASSERT_EQ(ta.energy_motor_J, tb.energy_motor_J) << k;
  }
}

TEST(Emulator, TourMovesAllSixJoints) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  // 3 s of emulator time (the old test's 3 s of wall time), read every period
  const long n = 3000;
  long ok = 0;
  Joints lo = Joints::Constant(1e9), hi = Joints::Constant(-1e9);
  for (long k = 0; k < n; ++k) {
    emu.advance();
    Joints q;
    if (emu.read_joints(&q) == DeviceError::kOk) {
      ++ok;
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
  }
  const EmulatorTruth t = emu.truth();
  emu.stop();
  // every period stepped and read; none dropped to keep up with a clock
  EXPECT_EQ(ok, n);
  EXPECT_EQ(t.periods, n);
  EXPECT_EQ(t.lag_periods, 0);
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
  run(&emu, 50);
  Joints q0;
  ASSERT_EQ(emu.read_joints(&q0), DeviceError::kOk);
  const double q1_true0 = emu.truth().q_end_dh[0];  // the state q0 shows
  hold(&emu, Vec3(0.05, 0.0, 0.0), 300);  // 0.3 s
  Joints q1;
  ASSERT_EQ(emu.read_joints(&q1), DeviceError::kOk);
  const EmulatorTruth t = emu.truth();
  emu.stop();
  EXPECT_GT(q1[0] - q0[0], 0.02);
  EXPECT_LT(t.q_end_dh[0] - q1_true0, -0.02);
  EXPECT_NEAR(t.motor_torque_Nm[0], 0.05, 1e-12);
  // the hand let go: its spring and damper are zeroed at each step's start;
  // what is left is RK4's inner stages (the grip moved by part of a step)
  EXPECT_LT(t.hand_force_N.norm(), 0.05);
  std::printf("hand force while let go: %.2e N\n", t.hand_force_N.norm());
}

TEST(Emulator, NonFiniteWriteHoldsZeroTorque) {
  Emulator emu(options(HandProgram::kNone));
  emu.start();
  hold(&emu, Vec3(0.1, 0.0, 0.0), 20);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[0], 0.1, 1e-12);
  EXPECT_FALSE(emu.truth().invalid_command);
  EXPECT_EQ(emu.write_motor_torques(Vec3(0.1, std::nan(""), 0.0)),
            DeviceError::kInvalidCommand);
  // taken at the next period's start (the old test polled for up to 1 s):
  // that period holds zero
  emu.advance();
  EXPECT_TRUE(emu.truth().invalid_command);
  EXPECT_EQ(emu.truth().motor_torque_Nm, Vec3::Zero());
  // and a finite write is held from the period after it
  hold(&emu, Vec3(0.1, 0.0, 0.0), 1);
  EXPECT_FALSE(emu.truth().invalid_command);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[0], 0.1, 1e-12);
  emu.stop();
}

TEST(Emulator, DeviceWatchdogZeroesTorqueWithoutWrites) {
  EmulatorOptions o = options(HandProgram::kNone);
  // The watchdog fires in a period that starts more than this after the
  // last write: 50.5 periods, half a period off the grid, so that it fires
  // in the period after the 50th whatever the clock's last bits.
  o.device_watchdog_s = 0.0505;
  Emulator emu(o);
  emu.start();
  hold(&emu, Vec3(0.0, 0.1, 0.0), 20);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[1], 0.1, 1e-12);
  EXPECT_FALSE(emu.truth().device_watchdog_fired);
  // No more writes. The period just run was the last write's first; after
  // 49 more the write is 50 periods old: still within the watchdog ...
  run(&emu, 49);
  EXPECT_FALSE(emu.truth().device_watchdog_fired);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[1], 0.1, 1e-12);
  // ... and at 51 periods the device zeroes the motors by itself (the old
  // test polled for up to 1 s)
  emu.advance();
  EXPECT_TRUE(emu.truth().device_watchdog_fired);
  EXPECT_EQ(emu.truth().motor_torque_Nm, Vec3::Zero());
  // a write brings the torque back in the very next period
  hold(&emu, Vec3(0.0, 0.1, 0.0), 1);
  EXPECT_FALSE(emu.truth().device_watchdog_fired);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[1], 0.1, 1e-12);
  emu.stop();
}

TEST(Emulator, DropFaultTimesOutExactlyCountReads) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  run(&emu, 20);
  emu.inject({EmulatorFaultKind::kDrop, 0.0, 0.0, 5});
  // scheduled at the emulator's time now, taken at the next period's start
  EXPECT_EQ(emu.truth().drops_pending, 0);
  emu.advance();
  EXPECT_EQ(emu.truth().drops_pending, 5);
  // exactly five reads time out, whatever the time between them; every
  // read after them succeeds (the old test counted over 0.1 s on a slowed
  // physics, so that a loaded host did not add time-outs of its own)
  DeviceState s;
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(emu.read_state(&s), DeviceError::kTimeout) << i;
  }
  for (int i = 0; i < 100; ++i) {
    ASSERT_EQ(emu.read_state(&s), DeviceError::kOk) << i;  // recovered
    emu.advance();
  }
  EXPECT_EQ(emu.truth().drops_pending, 0);
  emu.stop();
}

TEST(Emulator, LateFaultDeliversOldReadings) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  run(&emu, 50);
  emu.inject({EmulatorFaultKind::kLate, 0.0, kFault_s, 40});
  // Taken at the next period's start: from that period on, for exactly
  // kFaultPeriods periods, each reading is the one published 40 periods
  // before, its timestamp with it (the old test could check only "older
  // than 20 periods" on the wall clock).
  long k = 50;  // periods run
  DeviceState s;
  for (long n = 0; n < kFaultPeriods; ++n) {
    emu.advance();
    ++k;
    ASSERT_TRUE(emu.truth().late) << n;
    ASSERT_EQ(emu.read_state(&s), DeviceError::kOk) << n;
    ASSERT_EQ(s.timestamp_s, clock_at(emu, k - 40)) << n;
  }
  // over: the next period's reading is fresh
  emu.advance();
  ++k;
  EXPECT_FALSE(emu.truth().late);
  ASSERT_EQ(emu.read_state(&s), DeviceError::kOk);
  EXPECT_EQ(s.timestamp_s, clock_at(emu, k));
  emu.stop();
}

TEST(Emulator, StallTimesOutThenRecovers) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  run(&emu, 20);
  emu.inject({EmulatorFaultKind::kStall, 0.0, 0.3, 0});
  // The stall is taken at the next period's start, which therefore does not
  // step; nor do the following ones until 0.3 s of the clock have passed in
  // all, as on the wall clock: 300 periods without a step, the reading of
  // period 20 ageing meanwhile (the emulator compares times on its clock
  // with a tolerance far below a period, so a whole number of periods is
  // exact).
  const long frozen = 300;
  long timeouts = 0;
  DeviceState s;
  for (long age = 1; age <= frozen; ++age) {
    emu.advance();
    ASSERT_EQ(emu.truth().periods, 20) << age;  // nothing stepped
    const DeviceError e = emu.read_state(&s);
    // a reading times out once more than 3 periods old
    if (age <= 3) {
      EXPECT_EQ(e, DeviceError::kOk) << age;
    } else {
      EXPECT_EQ(e, DeviceError::kTimeout) << age;
      timeouts += e == DeviceError::kTimeout ? 1 : 0;
    }
  }
  EXPECT_EQ(timeouts, frozen - 3);  // the old test asked for more than 10
  // the physics runs again from the next period, and its first says a
  // stall came before it
  emu.advance();
  EXPECT_EQ(emu.truth().periods, 21);
  EXPECT_TRUE(emu.truth().stalled);
  ASSERT_EQ(emu.read_state(&s), DeviceError::kOk);
  EXPECT_EQ(s.timestamp_s, clock_at(emu, 20 + frozen + 1));
  emu.advance();
  EXPECT_EQ(emu.truth().periods, 22);
  EXPECT_FALSE(emu.truth().stalled);
  emu.stop();
}

TEST(Emulator, UnplugCutsReadsAndMotorsThenReplugs) {
  Emulator emu(options(HandProgram::kNone));
  emu.start();
  const Vec3 tau(0.05, 0.0, 0.0);
  hold(&emu, tau, 20);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[0], 0.05, 1e-12);
  emu.inject({EmulatorFaultKind::kUnplug, 0.0, kFault_s, 0});
  // Each tick writes, runs a period and reads, as a servo loop that keeps
  // trying. The unplug is taken at the next period's start (this tick's
  // write got in before it); for exactly kFaultPeriods periods the motors
  // hold zero and reads and writes say the device is gone.
  DeviceState s;
  EXPECT_EQ(emu.write_motor_torques(tau), DeviceError::kOk);
  for (long n = 0; n < kFaultPeriods; ++n) {
    if (n > 0) {
      EXPECT_EQ(emu.write_motor_torques(tau), DeviceError::kNotConnected) << n;
    }
    emu.advance();
    const EmulatorTruth t = emu.truth();
    ASSERT_TRUE(t.unplugged) << n;
    EXPECT_EQ(t.motor_torque_Nm, Vec3::Zero()) << n;
    EXPECT_EQ(emu.read_state(&s), DeviceError::kNotConnected) << n;
  }
  // replugged at the next period's start: readings again at once, but the
  // motors wait for a write made after the replug
  EXPECT_EQ(emu.write_motor_torques(tau), DeviceError::kNotConnected);
  emu.advance();
  EXPECT_FALSE(emu.truth().unplugged);
  EXPECT_EQ(emu.truth().motor_torque_Nm, Vec3::Zero());
  EXPECT_EQ(emu.read_state(&s), DeviceError::kOk);
  hold(&emu, tau, 1);
  EXPECT_NEAR(emu.truth().motor_torque_Nm[0], 0.05, 1e-12);
  emu.stop();
}

TEST(Emulator, DockProgramReachesTheInkwell) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  run(&emu, 200);
  DeviceState s;
  ASSERT_EQ(emu.read_state(&s), DeviceError::kOk);
  EXPECT_FALSE(s.docked);
  emu.set_hand_program(HandProgram::kDock);
  // The program takes the stylus to the inkwell in kDockMove_s = 1.5 s and
  // then corrects what error is left. In lockstep the period it docks in is
  // the same on every run (printed; 1353 when this was written); the
  // bound, 2.5 s of emulator time where the old test allowed 4.5 s of wall
  // time, leaves room for changes to the hand or the model, not for timing.
  const long limit = 2500;
  long n = 0;
  while (!emu.truth().docked && n < limit) {
    emu.advance();
    ++n;
  }
  ASSERT_TRUE(emu.truth().docked) << "not docked after " << n << " periods";
  std::printf("docked %ld periods after the dock program started\n", n);
  // the reading of that same period has the inkwell switch closed
  ASSERT_EQ(emu.read_state(&s), DeviceError::kOk);
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
  // and the program holds it there: docked in every period of the next 0.5 s
  for (long k = 0; k < 500; ++k) {
    emu.advance();
    ASSERT_EQ(emu.read_state(&s), DeviceError::kOk);
    ASSERT_TRUE(s.docked) << k;
  }
  emu.stop();
}

TEST(Emulator, CaseProgramPlaysTheScenesScript) {
  Emulator emu(options(HandProgram::kCase));
  emu.start();
  // just past 4 s of the script, as the old test waited for t_sim > 4 s
  // (it ran the physics 4 times faster than the wall clock to get there)
  const long n = 4001;
  run(&emu, n);
  const EmulatorTruth t = emu.truth();
  emu.stop();
  EXPECT_EQ(t.periods, n);
  EXPECT_EQ(t.t_sim_s, clock_at(emu, n));
  // the target of the period that ended at t_sim_s was set at its start
  const double t0 = clock_at(emu, n - 1);
  const ScriptPose want = emu.loop().script().at(t0);
  EXPECT_LT((t.hand_target.p_mm - want.p_mm).norm(), 1e-9);
  EXPECT_EQ(t.segment, emu.loop().script().segment_at(t0));
  EXPECT_GE(t.segment, 1);
  EXPECT_TRUE(t.state_finite);
}

TEST(Emulator, GimbalSweepReachesBothEndsOfEachGimbalJoint) {
  Emulator emu(options(HandProgram::kGimbalSweep));
  emu.start();
  // the 9 s sweep and a little more, every period's reading (the old test
  // ran the physics 3 times faster than the wall clock and sampled it)
  const long n = 9500;
  long ok = 0;
  Joints lo = Joints::Constant(1e9), hi = Joints::Constant(-1e9);
  for (long k = 0; k < n; ++k) {
    emu.advance();
    DeviceState s;
    if (emu.read_state(&s) == DeviceError::kOk) {
      ++ok;
      lo = lo.cwiseMin(s.q_device_rad);
      hi = hi.cwiseMax(s.q_device_rad);
    }
  }
  emu.stop();
  EXPECT_EQ(ok, n);
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
  run(&emu, 50);
  DeviceState s;
  ASSERT_EQ(emu.read_state(&s), DeviceError::kOk);
  const EmulatorTruth t = emu.truth();
  ASSERT_EQ(s.timestamp_s, t.wall_s);  // the same period's reading and truth
  const hw::OmniCalibration f = emu.factory_calibration();
  // §9.2 by hand: t_i = offset_i + sign_i 2 pi count / 15000, with the
  // drivers' signs (-1, -1, +1), which the emulator's Omni has
  const double sign[3] = {-1, -1, 1};
  EXPECT_EQ(f.encoder_sign, (std::array<int, 3>{-1, -1, 1}));
  EXPECT_LT(f.pot_gain_rad[1], 0.0);  // and t5's pot turns the other way
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
  // another calibration moves the reading by its offset; readings are
  // decoded when published, so from the next period's on
  hw::OmniCalibration c = f;
  c.encoder_offset_rad[1] += 0.01;
  emu.set_calibration(c);
  emu.advance();
  DeviceState s2;
  ASSERT_EQ(emu.read_state(&s2), DeviceError::kOk);
  EXPECT_NEAR(s2.q_device_rad[1] - s.q_device_rad[1], 0.01, 1e-9);
  c.pot_gain_rad[0] = 0.0;
  EXPECT_THROW(emu.set_calibration(c), std::invalid_argument);
  emu.stop();
}

// In lockstep stall_cause() has nothing to report: there is no wall clock
// for the physics to fall behind, and a time-out is the device's own (here
// an injected stall), never the emulator's.
// In lockstep a reading's age is counted in the emulator's own periods,
// whatever the real-time factor (which scales only the wall clock): one to
// three periods old it is fresh, four it is stale.
TEST(Emulator, LockstepStalenessIgnoresTheRealtimeFactor) {
  EmulatorOptions o = options(HandProgram::kTour);
  o.realtime_factor = 4.0;
  Emulator emu(o);
  emu.start();
  run(&emu, 10);
  emu.inject({EmulatorFaultKind::kStall, 0.0, 0.1, 0});
  DeviceState s;
  for (int age = 1; age <= 6; ++age) {
    emu.advance();
    EXPECT_EQ(emu.read_state(&s),
              age <= 3 ? DeviceError::kOk : DeviceError::kTimeout)
        << "a reading " << age << " periods old";
  }
  emu.stop();
}

TEST(Emulator, StallCauseIsEmptyInLockstep) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  run(&emu, 10);
  EXPECT_EQ(emu.stall_cause(), "");
  emu.inject({EmulatorFaultKind::kStall, 0.0, 0.05, 0});
  run(&emu, 20);  // the reading is 20 periods old
  DeviceState s;
  EXPECT_EQ(emu.read_state(&s), DeviceError::kTimeout);
  EXPECT_EQ(emu.read_state(&s), DeviceError::kTimeout);
  EXPECT_EQ(emu.stall_cause(), "");
  EXPECT_EQ(emu.truth().lag_periods, 0);
  run(&emu, 40);  // past the stall
  EXPECT_EQ(emu.read_state(&s), DeviceError::kOk);
  EXPECT_EQ(emu.stall_cause(), "");
  emu.stop();
}

// A servo thread's calls and the emulator's periods, in lockstep on this
// thread, allocate nothing: every hand program, and each fault taken and
// read through (drop, late, stall, unplug).
TEST(NoAlloc, EmulatorAdvanceReadWrite) {
  Emulator emu(options(HandProgram::kTour));
  emu.start();
  run(&emu, 20);
  // scheduled ahead (inject is not a servo call), taken inside the scope
  // (durations half a period off the grid, as kFault_s)
  emu.inject({EmulatorFaultKind::kDrop, 0.05, 0.0, 3});
  emu.inject({EmulatorFaultKind::kLate, 0.1, 0.0505, 10});
  emu.inject({EmulatorFaultKind::kStall, 0.3, 0.02, 0});
  emu.inject({EmulatorFaultKind::kUnplug, 0.5, 0.0205, 0});
  long ok = 0, timeouts = 0, not_connected = 0, other = 0, late = 0;
  std::size_t allocations = 0;
  {
    vmh::testing::AllocationScope scope;
    for (HandProgram p : {HandProgram::kCase, HandProgram::kNone,
                          HandProgram::kDock, HandProgram::kGimbalSweep,
                          HandProgram::kTour}) {
      emu.set_hand_program(p);
      for (int i = 0; i < 150; ++i) {
        DeviceState s;
        switch (emu.read_state(&s)) {
          case DeviceError::kOk: ++ok; break;
          case DeviceError::kTimeout: ++timeouts; break;
          case DeviceError::kNotConnected: ++not_connected; break;
          default: ++other; break;
        }
        Joints q;
        (void)emu.read_joints(&q);
        (void)emu.write_motor_torques(Vec3(0.01, -0.01, 0.01));
        emu.advance();
        late += emu.truth().late ? 1 : 0;
      }
    }
    allocations = scope.count();
  }
  emu.stop();
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(other, 0);
  // every fault was taken and read through inside the scope
  // the 3 drops go to the next 3 reads, and each tick reads twice
  // (read_state, then read_joints): 2 of them land on read_state. The
  // stall: 20 periods without a step (its own and 19 more), the reading 1
  // to 20 periods old, a time-out from 4 periods: 17
  EXPECT_EQ(timeouts, 2 + 17);
  EXPECT_EQ(not_connected, 21);  // the unplug: 21 periods
  EXPECT_EQ(late, 51);           // the late fault: 51 periods
  EXPECT_EQ(ok + timeouts + not_connected, 5 * 150);
}

// the grip site's pose in a copy of the physics (world frame, SI)
HandTargetState grip_of(const mjModel* m, const mjData* d, int grip) {
  HandTargetState t;
  t.p_m = Vec3(d->site_xpos + 3 * grip);
  t.R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
      d->site_xmat + 9 * grip);
  (void)m;
  return t;
}

TEST(Emulator, MirrorCopiesThePhysicsOfItsLastCopiedPeriod) {
  Emulator emu(options(HandProgram::kTour));
  emu.enable_mirror();
  const mjModel* m = emu.loop().model();
  mjData* d = mj_makeData(m);
  emu.start();
  EXPECT_FALSE(emu.copy_mirror(d));  // nothing copied yet
  run(&emu, 10 * Emulator::kMirrorPeriods);  // ends on a copied period
  ASSERT_TRUE(emu.copy_mirror(d));
  // the copy is the state the truth describes at the period's end
  const EmulatorTruth t = emu.truth();
  for (int i = 0; i < 6; ++i) {
    const std::string name = "q" + std::to_string(i + 1);
    const int j = mj_name2id(m, mjOBJ_JOINT, name.c_str());
    ASSERT_GE(j, 0);
    EXPECT_EQ(d->qpos[m->jnt_qposadr[j]], t.q_end_dh[i]) << name;
  }
  EXPECT_NEAR(d->time, t.t_sim_s, 1e-12);
  mj_deleteData(d);
  emu.stop();
  EXPECT_THROW(
      {
        Emulator started(options(HandProgram::kTour));
        started.start();
        started.enable_mirror();
      },
      std::logic_error);
}

TEST(Emulator, ManualHandLetsGoUntilHeldThenCarriesTheGrip) {
  Emulator emu(options(HandProgram::kManual));
  emu.enable_mirror();
  const mjModel* m = emu.loop().model();
  const int grip = emu.loop().hand().grip_site();
  mjData* d = mj_makeData(m);
  emu.start();
  run(&emu, 100);
  // not held: like "none", the hand exerts (almost) nothing
  EXPECT_FALSE(emu.truth().manual_held);
  EXPECT_LT(emu.truth().hand_force_N.norm(), 0.05);
  ASSERT_TRUE(emu.copy_mirror(d));
  const HandTargetState start = grip_of(m, d, grip);
  // held 20 mm along the world x from where the grip is
  HandTargetState target = start;
  target.p_m += Vec3(0.02, 0.0, 0.0);
  emu.set_manual_hand(target, true);
  run(&emu, 1500);
  EXPECT_TRUE(emu.truth().manual_held);
  ASSERT_TRUE(emu.copy_mirror(d));
  const Vec3 moved = grip_of(m, d, grip).p_m - start.p_m;
  std::printf("grip moved %.2f mm toward a target 20 mm away (x %.2f, "
              "off-axis %.2f mm)\n",
              1e3 * moved.norm(), 1e3 * moved.x(),
              1e3 * Vec3(0.0, moved.y(), moved.z()).norm());
  // nothing but the arm's inertia, damping and friction resists the hand
  EXPECT_GT(moved.x(), 0.015);
  EXPECT_LT(moved.x(), 0.0205);
  // the truth's hand target is the wrist pose the grip target asks for:
  // with the grip nearly there, the true wrist centre is nearly there too
  const EmulatorTruth t = emu.truth();
  EXPECT_LT((t.hand_target.p_mm - t.p_end_mm).norm(), 5.0);
  EXPECT_GT(t.hand_target.axis.dot(t.stylus_axis), 0.99);
  // let go: the hand's force vanishes again
  emu.set_manual_hand(target, false);
  run(&emu, 20);
  EXPECT_FALSE(emu.truth().manual_held);
  EXPECT_LT(emu.truth().hand_force_N.norm(), 0.05);
  mj_deleteData(d);
  emu.stop();
  EXPECT_EQ(parse_hand_program("manual"), HandProgram::kManual);
}

TEST(NoAlloc, EmulatorManualHandAndMirror) {
  Emulator emu(options(HandProgram::kManual));
  emu.enable_mirror();
  emu.start();
  run(&emu, 10);
  HandTargetState target;
  target.p_m = Vec3(0.0, 0.1, 0.1);
  std::size_t allocations = 0;
  {
    vmh::testing::AllocationScope scope;
    for (int i = 0; i < 200; ++i) {
      emu.set_manual_hand(target, i % 50 < 25);
      (void)emu.write_motor_torques(Vec3(0.01, 0.0, 0.0));
      emu.advance();
    }
    allocations = scope.count();
  }
  emu.stop();
  EXPECT_EQ(allocations, 0u);
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

// --- The physics thread on the wall clock (label realtime, run alone) ---

// The physics thread steps one period per period of wall time beside a
// servo thread (this one: a read and a write every millisecond for 0.3 s).
// On any host: it stepped, never ahead of the wall clock (it sleeps to
// absolute deadlines); every read is a reading or a time-out, never a
// vanished device; readings never go back in time or tear; nothing
// allocates. Keeping its period holds only on a host that gives it the
// CPU: on a busier one stall_cause() must say why instead.
TEST(EmulatorRealtime, PhysicsThreadRunsBesideAServoThread) {
  Emulator emu(wall_options(HandProgram::kTour));
  const double w0_s = monotonic_now_s();
  emu.start();
  long ok = 0, timeouts = 0, bad = 0, backwards = 0;
  std::size_t allocations = 0;
  {
    vmh::testing::AllocationScope scope;  // counts every thread's new
    const double end_s = monotonic_now_s() + 0.3;
    double last_stamp_s = 0.0;
    DeviceState s;
    while (monotonic_now_s() < end_s) {
      const DeviceError e = emu.read_state(&s);
      if (e == DeviceError::kOk) {
        ++ok;
        if (s.timestamp_s < last_stamp_s || !s.q_device_rad.allFinite()) ++backwards;
        last_stamp_s = s.timestamp_s;
      } else if (e == DeviceError::kTimeout) {
        ++timeouts;
      } else {
        ++bad;
      }
      if (emu.write_motor_torques(Vec3(0.01, -0.01, 0.01)) != DeviceError::kOk) ++bad;
      const timespec pause{0, 1000000};
      nanosleep(&pause, nullptr);
    }
    allocations = scope.count();
  }
  // the truth first, then the time: the periods it counts were stepped
  // before that time
  const EmulatorTruth t = emu.truth();
  const double w1_s = monotonic_now_s();
  const std::string cause = emu.stall_cause();
  const double stop0_s = monotonic_now_s();
  emu.stop();
  const double stop_s = monotonic_now_s() - stop0_s;
  const double wall_periods = (w1_s - w0_s) / emu.servo_period_s();
  std::printf("%ld periods stepped in %.0f periods of wall time (%ld dropped); "
              "%ld readings, %ld time-outs; stop() took %.2g s%s%s\n",
              t.periods, wall_periods, t.lag_periods, ok, timeouts, stop_s,
              cause.empty() ? "" : "; ", cause.c_str());
  EXPECT_GT(t.periods, 0);
  EXPECT_EQ(t.t_sim_s, static_cast<double>(t.periods) * emu.servo_period_s());
  EXPECT_LE(static_cast<double>(t.periods), wall_periods + 1.0);
  EXPECT_GT(ok, 0);
  EXPECT_EQ(bad, 0);
  EXPECT_EQ(backwards, 0);
  EXPECT_EQ(allocations, 0u);
  // kept its period (an idle host loses a few at most; half is a loaded
  // host's margin), or named why not
  EXPECT_TRUE(static_cast<double>(t.periods) >= 0.5 * wall_periods || !cause.empty())
      << t.periods << " periods in " << wall_periods << " and no cause named";
  // stop() joins: the thread sleeps at most one period at a time
  EXPECT_FALSE(emu.running());
  EXPECT_LT(stop_s, 1.0);
}

// A stall freezes the physics thread for its duration, in short sleeps:
// stop() does not wait for a 10 s stall to end.
TEST(EmulatorRealtime, StopDuringAStallJoinsPromptly) {
  EmulatorOptions o = wall_options(HandProgram::kTour);
  o.faults = {{EmulatorFaultKind::kStall, 0.0, 10.0, 0}};  // from the first period
  Emulator emu(o);
  emu.start();
  // reads time out once the start state is older than 3 periods
  ASSERT_TRUE(vmh::testing::wait_for(
      [&] {
        DeviceState s;
        return emu.read_state(&s) == DeviceError::kTimeout;
      },
      2.0));
  EXPECT_EQ(emu.truth().periods, 0);  // frozen before its first step
  const double t0_s = monotonic_now_s();
  emu.stop();
  const double stop_s = monotonic_now_s() - t0_s;
  EXPECT_FALSE(emu.running());
  EXPECT_LT(stop_s, 1.0) << "stop() waited for the stall";
}

// A physics thread that cannot keep up with the wall clock (here by
// construction: 10^4 simulated seconds per wall second make a period
// 0.1 us, far less than one physics step takes on any machine, so this
// holds on an idle host as on a busy one) is the emulator's problem, not
// the device's: reads time out, the device stays connected, and
// stall_cause() names the reason and the remedy.
TEST(EmulatorRealtime, StarvedPhysicsIsNamedNotUnplugged) {
  EmulatorOptions o = wall_options(HandProgram::kTour);
  o.realtime_factor = 1e4;
  o.realtime_priority = 0;  // it never sleeps: keep it off SCHED_FIFO
  Emulator emu(o);
  emu.start();
  long timeouts = 0, bad = 0;
  const bool starved = vmh::testing::wait_for(
      [&] {
        DeviceState s;
        const DeviceError e = emu.read_state(&s);
        if (e == DeviceError::kTimeout) ++timeouts;
        if (e != DeviceError::kTimeout && e != DeviceError::kOk) ++bad;
        return timeouts > 0 && emu.truth().lag_periods > 0;
      },
      2.0);
  const std::string cause = emu.stall_cause();
  const bool running = emu.running();
  emu.stop();
  ASSERT_TRUE(starved) << timeouts << " time-outs";
  EXPECT_TRUE(running);
  EXPECT_EQ(bad, 0);  // never kNotConnected: the device did not vanish
  EXPECT_NE(cause.find("fell behind the wall clock"), std::string::npos) << cause;
  EXPECT_NE(cause.find("--clock lockstep"), std::string::npos) << cause;
}

// On the wall clock the device watchdog counts wall time, as a device's
// firmware does. At 0.02 simulated s per wall s a 1 ms period takes 50 ms of
// wall time, so the watchdog's 50 ms of wall time pass within a period or
// two of emulator time, where in lockstep (DeviceWatchdogZeroesTorque-
// WithoutWrites) they are 50 periods.
TEST(EmulatorRealtime, DeviceWatchdogCountsWallTime) {
  EmulatorOptions o = wall_options(HandProgram::kNone);
  o.realtime_factor = 0.02;
  o.device_watchdog_s = 0.05;
  Emulator emu(o);
  emu.start();
  const double t_sim_before_s = emu.truth().t_sim_s;
  const double wall_before_s = monotonic_now_s();
  ASSERT_EQ(emu.write_motor_torques(Vec3(0.0, 0.1, 0.0)), DeviceError::kOk);
  EmulatorTruth fired;
  const bool zeroed = vmh::testing::wait_for(
      [&] {
        fired = emu.truth();
        return fired.device_watchdog_fired;
      },
      2.0);
  emu.stop();
  ASSERT_TRUE(zeroed);
  EXPECT_EQ(fired.motor_torque_Nm, Vec3::Zero());
  // more than 50 ms of wall time after the write ...
  EXPECT_GT(fired.wall_s - wall_before_s, o.device_watchdog_s);
  // ... and long before 50 ms of emulator time
  EXPECT_LT(fired.t_sim_s - t_sim_before_s, o.device_watchdog_s);
}

}  // namespace
}  // namespace vmh::sim
