// The hw session's servo loop (cli/hw_loop.h) against a scripted device:
// what each mode sends, that every tick lands in the ring, and that a tick
// (safety layer, reading guard, controller, reference controller, ring)
// allocates nothing.
#include <gtest/gtest.h>

#include <cmath>

#include "cli/hw_loop.h"
#include "controller/device_frame.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/scripted_device.h"

namespace vmh::cli {
namespace {

using vmh::testing::AllocationScope;
using vmh::testing::ScriptedDevice;

// the wrist centre a few centimetres off a circle of L = 50 mm
const Joints kPose = (Joints() << -0.1, 0.4, 0.1, -0.2, 0.3, 0.1).finished();

ControllerParams circle() {
  ControllerParams p;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  return p;
}

SessionOptions options(HwMode mode) {
  SessionOptions o;
  o.mode = mode;
  o.duration_s = 10.0;
  o.safety.ramp_s = 0.05;
  return o;
}

TEST(HwLoop, RecordSendsZeroAndKeepsEveryTick) {
  ScriptedDevice dev;
  dev.q = kPose;
  const SessionOptions o = options(HwMode::kRecord);
  HwLoop loop(&dev, o, OmniParams(), nullptr);
  for (int k = 0; k < 100; ++k) ASSERT_TRUE(loop.tick(1e-3 * k));
  EXPECT_EQ(dev.written, Vec3::Zero());
  EXPECT_EQ(dev.writes, 100);
  HwSample s;
  int n = 0;
  while (loop.ring().pop(&s)) {
    EXPECT_NEAR(s.t_s, 1e-3 * n, 1e-12);
    EXPECT_TRUE(s.state.has(kStateJoints));
    EXPECT_EQ(s.state.q_device_rad, kPose);
    ++n;
  }
  EXPECT_EQ(n, 100);
  EXPECT_EQ(loop.ticks(), 100);
  // the latest state is the last tick's
  EXPECT_NEAR(loop.latest().t_s, 0.099, 1e-12);
}

TEST(HwLoop, RunSendsTheControllersTorqueOnceTheRampIsDone) {
  ScriptedDevice dev;
  dev.q = kPose;
  SessionOptions o = options(HwMode::kRun);
  o.controller = circle();
  o.safety.max_force_step_N = 10.0;  // no rate limit in the way
  HwLoop loop(&dev, o, OmniParams(), nullptr);
  for (int k = 0; k < 200; ++k) loop.tick(1e-3 * k);
  // an independent controller on the same reading
  Controller ref(circle());
  ControlOutput out;
  ref.tick(device_to_dh_joints(kPose), &out);
  ASSERT_GT(out.tau_motor_Nm.norm(), 1e-3);
  ASSERT_LT(out.force_device_N.norm(), SafetyParams().max_force_N);
  EXPECT_LT((dev.written - out.tau_motor_Nm).norm(), 1e-9);
}

TEST(HwLoop, MotorTestPulsesOneMotorForItsLength) {
  ScriptedDevice dev;
  dev.q = kPose;
  SessionOptions o = options(HwMode::kMotorTest);
  o.motor = 2;
  o.torque_Nm = 0.05;
  o.pulse_start_s = 0.1;
  o.pulse_s = 0.1;
  o.safety.max_force_step_N = 10.0;
  HwLoop loop(&dev, o, OmniParams(), nullptr);
  Vec3 during = Vec3::Zero();
  for (int k = 0; k <= 300; ++k) {
    loop.tick(1e-3 * k);
    if (k == 150) during = dev.written;
  }
  EXPECT_NEAR(during[1], 0.05, 1e-12);
  EXPECT_EQ(during[0], 0.0);
  EXPECT_EQ(during[2], 0.0);
  EXPECT_EQ(dev.written, Vec3::Zero());  // after the pulse
}

TEST(HwLoop, AFailedReadSendsZero) {
  ScriptedDevice dev;
  dev.q = kPose;
  SessionOptions o = options(HwMode::kRun);
  o.controller = circle();
  HwLoop loop(&dev, o, OmniParams(), nullptr);
  for (int k = 0; k < 100; ++k) loop.tick(1e-3 * k);
  ASSERT_NE(dev.written, Vec3::Zero());
  dev.read_error = DeviceError::kIo;
  loop.tick(0.1);
  EXPECT_EQ(dev.written, Vec3::Zero());
}

TEST(HwLoop, StopsAtItsDuration) {
  ScriptedDevice dev;
  SessionOptions o = options(HwMode::kRecord);
  o.duration_s = 0.01;
  HwLoop loop(&dev, o, OmniParams(), nullptr);
  EXPECT_TRUE(loop.tick(0.0));
  EXPECT_FALSE(loop.tick(0.02));
}

TEST(NoAlloc, HwLoopTick) {
  ScriptedDevice dev;
  SessionOptions o = options(HwMode::kRun);
  o.controller = circle();
  o.reference = circle();
  HwLoop loop(&dev, o, OmniParams(), nullptr);
  HwSample s;
  AllocationScope scope;
  for (int k = 0; k < 2000; ++k) {
    dev.q = kPose + vmh::testing::ramp(1e-4 * k) * 0.1;
    dev.read_error = k % 97 == 0 ? DeviceError::kTimeout : DeviceError::kOk;
    loop.tick(1e-3 * k);
    if (k % 50 == 0) {
      while (loop.ring().pop(&s)) {
      }
    }
  }
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace vmh::cli
