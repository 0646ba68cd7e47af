// The device layer's SafetyLayer (device/safety.h) over the Emulator, ticked
// by a plain 1 kHz servo thread of this test: each limit triggers AND
// recovers on the emulated device, and the torque the emulator's motors
// hold (EmulatorTruth::motor_torque_Nm) is checked, not only the flags.
// Every limit but the one under test is kept out of the way (quiet(), from
// tests/device/safety_rig.h). The tests wait for events with generous
// limits and never assert how long anything took.
#include <gtest/gtest.h>
#include <time.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <string>
#include <thread>

#include "controller/device_frame.h"
#include "device/safety.h"
#include "device/seqlock.h"
#include "device/tick_timer.h"
#include "sim/closed_loop.h"
#include "sim/emulator.h"
#include "tests/device/safety_rig.h"
#include "tests/support/wait.h"

namespace vmh::sim {
namespace {

using vmh::testing::fd_jacobian;
using vmh::testing::sleep_s;
using vmh::testing::wait_for;
using vmh::testing::quiet;

// the wrist-centre force (N, norm) that motor torques make at q (DH), by
// the finite-difference Jacobian: tau_dh = J^T F
double force_N(const Joints& q_dh, const Vec3& tau_motor_Nm) {
  const Mat3 J = fd_jacobian(q_dh);
  return (J.transpose().inverse() * motor_to_dh_torques(tau_motor_Nm)).norm();
}

// motor torques for a force of F_N newtons along device -y at q (DH)
Vec3 torque_for(const Joints& q_dh, double F_N) {
  return vmh::testing::torque_for_force(q_dh, Vec3(0.0, -F_N, 0.0));
}

// the emulator behind the safety layer, and a servo thread ticking it every
// millisecond (clock_nanosleep to absolute deadlines) with the torque the
// test commands
class Rig {
 public:
  // realtime_factor 0.5: the physics runs at half speed, so that a
  // physics thread delayed by a loaded machine (two periods: 4 ms) rarely
  // makes a read time out, which would cut the force (no_reading) and
  // restart the ramp under the limit being tested
  Rig(HandProgram hand, const SafetyParams& params,
      double realtime_factor = 0.5, double device_watchdog_s = 10.0)
      : emu_(make_options(hand, realtime_factor, device_watchdog_s)),
        safety_(&emu_, params, emu_.loop().controller_params().omni) {
    emu_.start();
    thread_ = std::thread([this] { loop(); });
  }
  ~Rig() {
    stop_.store(true);
    thread_.join();
    emu_.stop();
  }

  Emulator& emu() { return emu_; }
  SafetyLayer& safety() { return safety_; }  // only while paused
  void command(const Vec3& tau_Nm) { command_.write(tau_Nm); }
  SafetyStatus status() const { return status_.load(); }
  bool has(SafetyStatus f) const { return (status() & f) != 0; }
  Vec3 held() const { return emu_.truth().motor_torque_Nm; }
  Joints q_dh() const { return emu_.truth().q_end_dh; }
  bool wait_flag(SafetyStatus f, bool set, double limit_s) {
    return wait_for([&] { return has(f) == set; }, limit_s);
  }
  // stops ticking (after the tick under way) / ticks again
  void pause() {
    pause_.store(true);
    while (!paused_.load()) sleep_s(1e-4);
  }
  void resume() {
    pause_.store(false);
    while (paused_.load()) sleep_s(1e-4);
  }

 private:
  static EmulatorOptions make_options(HandProgram hand, double realtime_factor,
                                      double watchdog_s) {
    EmulatorOptions o;
    o.realtime_factor = realtime_factor;
    o.scene = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";
    o.hand = hand;
    o.device_watchdog_s = watchdog_s;
    return o;
  }
  void loop() {
    timespec next;
    clock_gettime(CLOCK_MONOTONIC, &next);
    while (!stop_.load()) {
      if (pause_.load()) {
        paused_.store(true);
      } else {
        paused_.store(false);
        DeviceState s;
        // the tick's time: the layer's watchdog is kicked with it
        safety_.set_read_time(monotonic_now_s());
        safety_.read_state(&s);
        safety_.write_motor_torques(command_.read());
        status_.store(safety_.status());
      }
      next.tv_nsec += 1000000;
      if (next.tv_nsec >= 1000000000) {
        next.tv_nsec -= 1000000000;
        ++next.tv_sec;
      }
      clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    }
  }

  Emulator emu_;
  SafetyLayer safety_;
  Seqlock<Vec3> command_{Vec3::Zero()};
  std::atomic<SafetyStatus> status_{0};
  std::atomic<bool> stop_{false}, pause_{false}, paused_{false};
  std::thread thread_;
};

// a small command (a few tenths of a newton) every limit lets through
const Vec3 kSmall(0.02, 0.03, 0.02);

bool holds(const Vec3& held, const Vec3& want) {
  return (held - want).norm() < 1e-9;
}

TEST(EmulatorSafety, ForceClampTriggersAndRecovers) {
  Rig rig(HandProgram::kCase, quiet());
  sleep_s(0.05);
  rig.command(torque_for(rig.q_dh(), 5.0));  // 5 N asked; 3.3 N is the limit
  ASSERT_TRUE(rig.wait_flag(kSafetyForceClamped | kSafetyTorqueClamped, true, 1.0));
  // the clamped torque reaches the motors: a force near the limit, not a
  // cut and not more
  double F = 0.0;
  EXPECT_TRUE(wait_for([&] {
    F = force_N(rig.q_dh(), rig.held());
    return F > 2.0;
  }, 0.5));
  EXPECT_LE(F, SafetyParams().max_force_N * 1.05);
  rig.command(kSmall);
  ASSERT_TRUE(rig.wait_flag(kSafetyForceClamped | kSafetyTorqueClamped, false, 1.0));
  ASSERT_TRUE(wait_for([&] { return holds(rig.held(), kSmall); }, 1.0));
}

TEST(EmulatorSafety, RampAfterForceOutputOn) {
  SafetyParams p = quiet();
  p.ramp_s = 0.3;
  Rig rig(HandProgram::kCase, p);
  rig.command(kSmall);
  sleep_s(0.02);
  rig.pause();
  rig.safety().set_force_output(false);
  rig.resume();
  ASSERT_TRUE(rig.wait_flag(kSafetyForceOutputOff, true, 1.0));
  ASSERT_TRUE(wait_for([&] { return rig.held().isZero(); }, 1.0));
  rig.pause();
  rig.safety().set_force_output(true);
  rig.resume();
  ASSERT_TRUE(rig.wait_flag(kSafetyForceRamping, true, 1.0));
  // part way up the ramp: less than asked, more than nothing, the same
  // direction
  Vec3 mid = Vec3::Zero();
  ASSERT_TRUE(wait_for(
      [&] {
        mid = rig.held();
        return mid.norm() > 0.1 * kSmall.norm() && mid.norm() < 0.9 * kSmall.norm();
      },
      2.0));
  EXPECT_NEAR(mid.normalized().dot(kSmall.normalized()), 1.0, 1e-9);
  ASSERT_TRUE(rig.wait_flag(kSafetyForceRamping, false, 2.0));
  ASSERT_TRUE(wait_for([&] { return holds(rig.held(), kSmall); }, 1.0));
}

TEST(EmulatorSafety, ImpulseLimitSmoothsAStep) {
  SafetyParams p = quiet();
  p.max_force_step_N = 0.05;  // 1 N takes at least 20 ticks
  Rig rig(HandProgram::kCase, p);
  sleep_s(0.05);
  const Vec3 step = torque_for(rig.q_dh(), 1.0);
  rig.command(step);
  ASSERT_TRUE(rig.wait_flag(kSafetyForceImpulseLimited, true, 1.0));
  const Vec3 early = rig.held();
  EXPECT_LT(early.norm(), 0.9 * step.norm());
  ASSERT_TRUE(rig.wait_flag(kSafetyForceImpulseLimited, false, 2.0));
  ASSERT_TRUE(wait_for([&] { return holds(rig.held(), step); }, 1.0));
}

TEST(EmulatorSafety, VelocityCutOnAFlingResumesWhenCaught) {
  // The emulator's hand cannot fling the stylus to the default 12 rad/s,
  // so the joint-speed limit is lowered to 2 rad/s (resume below 1 rad/s):
  // the hand lets go and motor 1 spins t1 up; then the hand catches it.
  SafetyParams p = quiet();
  p.max_joint_speed_rad_s = 2.0;
  p.resume_joint_speed_rad_s = 1.0;
  Rig rig(HandProgram::kNone, p, 1.0);  // real time: speeds as simulated
  sleep_s(0.05);
  EXPECT_FALSE(rig.has(kSafetyVelocityExceeded));  // at rest
  const double q1_rest = rig.q_dh()[0];
  rig.command(Vec3(0.1, 0.0, 0.0));
  ASSERT_TRUE(rig.wait_flag(kSafetyVelocityExceeded, true, 2.0));
  // it was the fling: from rest to 2 rad/s under a bounded torque takes
  // some travel
  EXPECT_GT(std::abs(rig.q_dh()[0] - q1_rest), 0.005);
  rig.command(kSmall);
  // while the cut lasts the motors come to hold nothing (the emulator
  // applies a command from its next period, after its delay line)
  if (rig.has(kSafetyVelocityExceeded)) {
    EXPECT_TRUE(wait_for([&] { return rig.held().isZero(); }, 0.1));
  }
  rig.emu().set_hand_program(HandProgram::kCase);
  ASSERT_TRUE(wait_for(
      [&] { return !rig.has(kSafetyVelocityExceeded) && holds(rig.held(), kSmall); },
      3.0));
}

TEST(EmulatorSafety, ThermalWarmHotCoolRecover) {
  // a fast thermal model, and a lower continuous force so that the motors'
  // torque limits reach the cut level through the derating (with 0.88 N
  // the derated equilibrium stays below it)
  SafetyParams p = quiet();
  p.thermal_time_constant_s = 0.2;
  p.continuous_force_N = 0.3;
  Rig rig(HandProgram::kCase, p);
  const Vec3 big(0.0, 0.3, 0.0);  // many times motor 2's continuous torque
  rig.command(big);
  ASSERT_TRUE(rig.wait_flag(kSafetyMotorWarm, true, 2.0));
  ASSERT_TRUE(rig.wait_flag(kSafetyMotorHot, true, 2.0));
  // the cut reaches the motors within the emulator's next periods
  EXPECT_TRUE(wait_for([&] { return rig.held().isZero(); }, 0.1));
  // cooled below the resume level: the torque comes back
  rig.command(kSmall);
  ASSERT_TRUE(rig.wait_flag(kSafetyMotorHot, false, 3.0));
  ASSERT_TRUE(wait_for([&] { return holds(rig.held(), kSmall); }, 3.0));
}

TEST(EmulatorSafety, WatchdogZeroesTorqueWhenTheLoopStops) {
  // the emulator's own watchdog is set long (10 s), so that only the
  // safety layer's can zero the motors here
  Rig rig(HandProgram::kCase, quiet());
  rig.command(kSmall);
  ASSERT_TRUE(wait_for([&] { return holds(rig.held(), kSmall); }, 1.0));
  rig.pause();
  sleep_s(0.03);  // more than watchdog_periods (10) periods without a tick
  EXPECT_TRUE(rig.safety().service_watchdog(monotonic_now_s()));
  EXPECT_TRUE((rig.safety().status() & kSafetyWatchdogExpired) != 0);
  ASSERT_TRUE(wait_for([&] { return rig.held().isZero(); }, 1.0));
  rig.resume();
  ASSERT_TRUE(wait_for([&] { return holds(rig.held(), kSmall); }, 1.0));
  EXPECT_FALSE(rig.has(kSafetyWatchdogExpired));
}

TEST(EmulatorSafety, CommLossOnUnplugRecoversAfterReplug) {
  SafetyParams p = quiet();
  p.comm_resume_reads = 50;
  Rig rig(HandProgram::kCase, p);
  rig.command(kSmall);
  ASSERT_TRUE(wait_for([&] { return holds(rig.held(), kSmall); }, 1.0));
  rig.emu().inject({EmulatorFaultKind::kUnplug, 0.0, 0.3, 0});
  ASSERT_TRUE(rig.wait_flag(kSafetyCommLost, true, 1.0));
  EXPECT_TRUE(rig.held().isZero());
  ASSERT_TRUE(wait_for([&] { return !rig.emu().truth().unplugged; }, 2.0));
  // replugged, but still cut until comm_resume_reads good reads
  EXPECT_TRUE(rig.has(kSafetyCommLost));
  ASSERT_TRUE(rig.wait_flag(kSafetyCommLost, false, 2.0));
  ASSERT_TRUE(wait_for([&] { return holds(rig.held(), kSmall); }, 1.0));
}

TEST(EmulatorSafety, DockedCutsUndockedRestores) {
  Rig rig(HandProgram::kCase, quiet());
  rig.command(kSmall);
  ASSERT_TRUE(wait_for([&] { return holds(rig.held(), kSmall); }, 1.0));
  rig.emu().set_hand_program(HandProgram::kDock);
  ASSERT_TRUE(rig.wait_flag(kSafetyDocked, true, 8.0));
  // the cut reaches the motors within the emulator's next periods
  EXPECT_TRUE(wait_for([&] { return rig.held().isZero(); }, 0.1));
  EXPECT_TRUE(rig.emu().truth().docked);
  rig.emu().set_hand_program(HandProgram::kTour);  // out of the inkwell
  ASSERT_TRUE(rig.wait_flag(kSafetyDocked, false, 3.0));
  ASSERT_TRUE(wait_for([&] { return holds(rig.held(), kSmall); }, 1.0));
}

TEST(EmulatorSafety, DeadmanButtonGatesForce) {
  SafetyParams p = quiet();
  p.require_deadman = true;
  Rig rig(HandProgram::kCase, p);
  rig.command(kSmall);
  ASSERT_TRUE(rig.wait_flag(kSafetyDeadmanReleased, true, 1.0));
  // the cut reaches the motors within the emulator's next periods
  EXPECT_TRUE(wait_for([&] { return rig.held().isZero(); }, 0.1));
  rig.emu().press_buttons(kButton1);
  ASSERT_TRUE(rig.wait_flag(kSafetyDeadmanReleased, false, 1.0));
  ASSERT_TRUE(wait_for([&] { return holds(rig.held(), kSmall); }, 1.0));
  rig.emu().press_buttons(0);
  ASSERT_TRUE(rig.wait_flag(kSafetyDeadmanReleased, true, 1.0));
  ASSERT_TRUE(wait_for([&] { return rig.held().isZero(); }, 1.0));
}

}  // namespace
}  // namespace vmh::sim
