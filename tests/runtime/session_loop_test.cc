// The session's servo loop (runtime/session_loop.h) against a scripted
// device: what each mode sends, that every tick lands in the ring, one tick
// late with the truth of its own period, and that a tick (safety layer,
// reading guard, controller, reference controller, ring) allocates
// nothing.
#include <gtest/gtest.h>

#include <cmath>

#include "controller/device_frame.h"
#include "runtime/session_loop.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/scripted_device.h"

namespace vmh::runtime {
namespace {

using vmh::testing::AllocationScope;
using vmh::testing::ScriptedDevice;

// the wrist centre a few centimetres off a circle of L = 50 mm
const Joints kPose = (Joints() << -0.1, 0.4, 0.1, -0.2, 0.3, 0.1).finished();
constexpr double kT = 1e-3;

ControllerParams circle() {
  ControllerParams p;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  return p;
}

ChainOptions chain(ChainMode mode) {
  ChainOptions o;
  o.mode = mode;
  o.safety_params.ramp_s = 0.05;
  if (mode == ChainMode::kRun) o.controller = circle();
  return o;
}

// a truth that names the tick it was published after: the plant "ran"
// period k when its counter says k
class CountingTruth final : public TruthSource {
 public:
  int period = -1;
  void read_truth(PlantTruth* t) const noexcept override {
    *t = PlantTruth{};
    t->segment = period;
  }
};

TEST(SessionLoop, RecordSendsZeroAndKeepsEveryTickInOrder) {
  ScriptedDevice dev;
  dev.q = kPose;
  SessionLoop loop(&dev, chain(ChainMode::kRecord), kT, 10.0, nullptr);
  for (int k = 0; k < 100; ++k) ASSERT_TRUE(loop.tick(kT * k));
  loop.flush();
  EXPECT_EQ(dev.written, Vec3::Zero());
  EXPECT_EQ(dev.writes, 100);
  TickRecord s;
  int n = 0;
  while (loop.ring().pop(&s)) {
    EXPECT_NEAR(s.t_s, kT * n, 1e-12);
    EXPECT_NEAR(s.period_s, kT, 1e-12);  // the tick's own length
    EXPECT_TRUE(s.state.has(kStateJoints));
    EXPECT_EQ(s.state.q_device_rad, kPose);
    EXPECT_FALSE(s.has_truth);
    EXPECT_FALSE(s.has_controller);
    ++n;
  }
  EXPECT_EQ(n, 100);
  EXPECT_EQ(loop.ticks(), 100);
  EXPECT_NEAR(loop.latest().t_s, 0.099, 1e-12);
}

TEST(SessionLoop, EachRecordCarriesTheTruthOfItsOwnPeriod) {
  ScriptedDevice dev;
  dev.q = kPose;
  CountingTruth truth;
  SessionLoop loop(&dev, chain(ChainMode::kRecord), kT, 10.0, &truth);
  for (int k = 0; k < 20; ++k) {
    ASSERT_TRUE(loop.tick(kT * k));
    truth.period = k;  // the plant runs period k after tick k
  }
  loop.flush();
  TickRecord s;
  int n = 0;
  while (loop.ring().pop(&s)) {
    ASSERT_TRUE(s.has_truth);
    EXPECT_EQ(s.segment, n) << "record " << n;
    ++n;
  }
  EXPECT_EQ(n, 20);
}

TEST(SessionLoop, RunSendsTheControllersTorqueOnceTheRampIsDone) {
  ScriptedDevice dev;
  dev.q = kPose;
  ChainOptions o = chain(ChainMode::kRun);
  o.safety_params.max_force_step_N = 10.0;  // no rate limit in the way
  SessionLoop loop(&dev, o, kT, 10.0, nullptr);
  for (int k = 0; k < 200; ++k) loop.tick(kT * k);
  // an independent controller on the same reading
  Controller ref(circle());
  ControlOutput out;
  ref.tick(device_to_dh_joints(kPose), &out);
  ASSERT_GT(out.tau_motor_Nm.norm(), 1e-3);
  ASSERT_LT(out.force_device_N.norm(), SafetyParams().max_force_N);
  EXPECT_LT((dev.written - out.tau_motor_Nm).norm(), 1e-9);
}

TEST(SessionLoop, MotorTestPulsesOneMotorForItsLength) {
  ScriptedDevice dev;
  dev.q = kPose;
  ChainOptions o = chain(ChainMode::kMotorTest);
  o.pulse.motor = 2;
  o.pulse.torque_Nm = 0.05;
  o.pulse.start_s = 0.1;
  o.pulse.length_s = 0.1;
  o.safety_params.max_force_step_N = 10.0;
  SessionLoop loop(&dev, o, kT, 10.0, nullptr);
  Vec3 during = Vec3::Zero();
  for (int k = 0; k <= 300; ++k) {
    loop.tick(kT * k);
    if (k == 150) during = dev.written;
  }
  EXPECT_NEAR(during[1], 0.05, 1e-12);
  EXPECT_EQ(during[0], 0.0);
  EXPECT_EQ(during[2], 0.0);
  EXPECT_EQ(dev.written, Vec3::Zero());  // after the pulse
}

TEST(SessionLoop, AFailedReadSendsZero) {
  ScriptedDevice dev;
  dev.q = kPose;
  SessionLoop loop(&dev, chain(ChainMode::kRun), kT, 10.0, nullptr);
  for (int k = 0; k < 100; ++k) loop.tick(kT * k);
  ASSERT_NE(dev.written, Vec3::Zero());
  dev.read_error = DeviceError::kIo;
  loop.tick(0.1);
  EXPECT_EQ(dev.written, Vec3::Zero());
}

// a loop of duration D at period T runs round(D / T) ticks, as the
// simulated loop does (its last at D - T), and ends at the next
TEST(SessionLoop, RunsItsDurationsWholeNumberOfTicks) {
  ScriptedDevice dev;
  SessionLoop loop(&dev, chain(ChainMode::kRecord), kT, 0.01, nullptr);
  int ticks = 0;
  for (int k = 0; k < 100 && loop.tick(kT * k); ++k) ++ticks;
  EXPECT_EQ(ticks, 10);
  EXPECT_EQ(loop.ticks(), 10);
}

TEST(NoAlloc, SessionLoopTick) {
  ScriptedDevice dev;
  ChainOptions o = chain(ChainMode::kRun);
  o.reference = circle();
  CountingTruth truth;
  SessionLoop loop(&dev, o, kT, 1e9, &truth);
  TickRecord s;
  AllocationScope scope;
  for (int k = 0; k < 2000; ++k) {
    dev.q = kPose + vmh::testing::ramp(1e-4 * k) * 0.1;
    dev.read_error = k % 97 == 0 ? DeviceError::kTimeout : DeviceError::kOk;
    loop.tick(kT * k);
    if (k % 50 == 0) {
      while (loop.ring().pop(&s)) {
      }
    }
  }
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace vmh::runtime
