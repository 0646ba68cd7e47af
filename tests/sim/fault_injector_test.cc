// sim/fault_injector.h on its own, against a scripted device: the injector
// corrupts exactly the joint, from exactly the time, by exactly the amount
// it says; the guard refuses what no hand can do and passes what one can;
// neither allocates on the servo path.
#include "sim/fault_injector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "tests/support/alloc_counter.h"

namespace vmh::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kCount = 2.0 * kPi / 15000.0;  // one encoder count, rad

// A device whose readings the test sets, and which records what it was told.
class ScriptedDevice final : public HapticDevice {
 public:
  Joints q = Joints::Zero();
  DeviceError read_error = DeviceError::kOk;
  Vec3 written = Vec3::Constant(-1.0);
  int writes = 0;

  DeviceError read_joints(Joints* out) noexcept override {
    if (read_error != DeviceError::kOk) return read_error;
    *out = q;
    return DeviceError::kOk;
  }
  DeviceError write_motor_torques(const Vec3& tau) noexcept override {
    written = tau;
    ++writes;
    return DeviceError::kOk;
  }
};

Joints ramp(double t_s) {
  // every joint moving at a plausible 1 rad/s, from different offsets
  Joints q;
  for (int i = 0; i < 6; ++i) q[i] = 0.1 * i + t_s;
  return q;
}

TEST(FaultInjector, NoneAndBeforeOnsetPassTheReadingThrough) {
  ScriptedDevice dev;
  FaultSpec spec;
  spec.kind = SensorFaultKind::kNan;
  spec.joint = 2;
  spec.at_s = 0.5;
  FaultInjector inj(&dev, spec);
  FaultInjector none(&dev, FaultSpec{});
  for (double t : {0.0, 0.25, 0.499}) {
    dev.q = ramp(t);
    inj.set_time_s(t);
    none.set_time_s(t);
    Joints a, b;
    ASSERT_EQ(inj.read_joints(&a), DeviceError::kOk);
    ASSERT_EQ(none.read_joints(&b), DeviceError::kOk);
    EXPECT_EQ(a, dev.q) << "t = " << t;
    EXPECT_EQ(b, dev.q);
    EXPECT_FALSE(inj.active());
  }
}

TEST(FaultInjector, NanHitsOnlyItsJointFromItsTime) {
  ScriptedDevice dev;
  FaultSpec spec;
  spec.kind = SensorFaultKind::kNan;
  spec.joint = 1;
  spec.at_s = 0.5;
  FaultInjector inj(&dev, spec);
  for (double t : {0.5, 0.6, 3.0}) {
    dev.q = ramp(t);
    inj.set_time_s(t);
    Joints q;
    ASSERT_EQ(inj.read_joints(&q), DeviceError::kOk);
    EXPECT_TRUE(std::isnan(q[1]));
    for (int i : {0, 2, 3, 4, 5}) EXPECT_EQ(q[i], dev.q[i]) << "joint " << i;
    EXPECT_TRUE(inj.active());
    EXPECT_TRUE(std::isnan(inj.last_reading()[1]));
  }
}

TEST(FaultInjector, JumpIsAThousandCountsAndStays) {
  ScriptedDevice dev;
  FaultSpec spec;
  spec.kind = SensorFaultKind::kJump;
  spec.joint = 0;
  spec.at_s = 1.0;
  FaultInjector inj(&dev, spec);
  EXPECT_NEAR(spec.jump_rad, 1000.0 * kCount, 1e-15);
  for (double t : {1.0, 1.001, 2.0}) {
    dev.q = ramp(t);
    inj.set_time_s(t);
    Joints q;
    ASSERT_EQ(inj.read_joints(&q), DeviceError::kOk);
    EXPECT_NEAR(q[0] - dev.q[0], 1000.0 * kCount, 1e-12);
    EXPECT_EQ(q.tail<5>(), dev.q.tail<5>());
  }
}

TEST(FaultInjector, StuckKeepsTheValueAtOnsetUntilReset) {
  ScriptedDevice dev;
  FaultSpec spec;
  spec.kind = SensorFaultKind::kStuck;
  spec.joint = 2;
  spec.at_s = 0.2;
  FaultInjector inj(&dev, spec);
  dev.q = ramp(0.2);
  const double frozen = dev.q[2];
  inj.set_time_s(0.2);
  Joints q;
  ASSERT_EQ(inj.read_joints(&q), DeviceError::kOk);
  for (double t : {0.3, 0.7, 1.5}) {
    dev.q = ramp(t);
    inj.set_time_s(t);
    ASSERT_EQ(inj.read_joints(&q), DeviceError::kOk);
    EXPECT_EQ(q[2], frozen) << "t = " << t;
    EXPECT_EQ(q[1], dev.q[1]);
  }
  inj.reset();
  dev.q = ramp(2.0);
  inj.set_time_s(2.0);
  ASSERT_EQ(inj.read_joints(&q), DeviceError::kOk);
  EXPECT_EQ(q[2], dev.q[2]);  // a new onset, at the new reading
}

TEST(FaultInjector, PassesErrorsAndWritesThrough) {
  ScriptedDevice dev;
  FaultInjector inj(&dev, FaultSpec{});
  dev.read_error = DeviceError::kTimeout;
  Joints q;
  EXPECT_EQ(inj.read_joints(&q), DeviceError::kTimeout);
  EXPECT_TRUE(std::isnan(inj.last_reading()[0]));
  EXPECT_EQ(inj.write_motor_torques(Vec3(0.1, -0.2, 0.3)), DeviceError::kOk);
  EXPECT_EQ(dev.written, Vec3(0.1, -0.2, 0.3));
}

TEST(FaultInjector, RejectsABadSpec) {
  ScriptedDevice dev;
  FaultSpec spec;
  spec.joint = 6;
  EXPECT_THROW(FaultInjector(&dev, spec), std::invalid_argument);
  EXPECT_THROW(FaultInjector(nullptr, FaultSpec{}), std::invalid_argument);
  SensorFaultKind k;
  EXPECT_TRUE(parse_sensor_fault_kind("stuck", &k));
  EXPECT_EQ(k, SensorFaultKind::kStuck);
  EXPECT_FALSE(parse_sensor_fault_kind("glitch", &k));
}

GuardParams guard_params() {
  GuardParams p;
  p.max_speed_rad_s = 50.0;
  p.max_period_s = 1e-3;
  return p;
}

TEST(ReadingGuard, PassesWhatAHandCanDo) {
  ScriptedDevice dev;
  ReadingGuard guard(&dev, guard_params());
  // 40 rad/s on every encoder, 1 ms apart: inside the 50 rad/s bound
  for (int k = 0; k < 100; ++k) {
    dev.q.setZero();
    dev.q.head<3>().setConstant(0.04 * k);
    Joints q;
    ASSERT_EQ(guard.read_joints(&q), DeviceError::kOk) << "tick " << k;
    EXPECT_EQ(q, dev.q);
    EXPECT_EQ(guard.last_fault(), GuardFault::kNone);
  }
  EXPECT_NEAR(guard.max_step_rad(), 0.05, 1e-15);
}

TEST(ReadingGuard, NanIsRefusedWhileItLasts) {
  ScriptedDevice dev;
  ReadingGuard guard(&dev, guard_params());
  Joints q;
  dev.q = ramp(0.0);
  ASSERT_EQ(guard.read_joints(&q), DeviceError::kOk);
  dev.q[4] = std::nan("");
  EXPECT_EQ(guard.read_joints(&q), DeviceError::kSensorFault);
  EXPECT_EQ(guard.last_fault(), GuardFault::kNonFinite);
  EXPECT_STREQ(guard_fault_name(guard.last_fault()), "sensor_nan");
  EXPECT_FALSE(guard.latched());
  // the reading recovers, far from the last good one: after a gap that is
  // not a jump
  dev.q = ramp(0.0);
  dev.q[0] += 1.0;
  EXPECT_EQ(guard.read_joints(&q), DeviceError::kOk);
}

TEST(ReadingGuard, AJumpLatchesUntilReset) {
  ScriptedDevice dev;
  ReadingGuard guard(&dev, guard_params());
  Joints q;
  dev.q = ramp(0.0);
  ASSERT_EQ(guard.read_joints(&q), DeviceError::kOk);
  dev.q[1] += 1000.0 * kCount;
  EXPECT_EQ(guard.read_joints(&q), DeviceError::kSensorFault);
  EXPECT_EQ(guard.last_fault(), GuardFault::kJump);
  EXPECT_STREQ(guard_fault_name(guard.last_fault()), "sensor_jump");
  // the angle is wrong for good: every later reading is refused
  for (int k = 0; k < 10; ++k) {
    EXPECT_EQ(guard.read_joints(&q), DeviceError::kSensorFault);
    EXPECT_TRUE(guard.latched());
  }
  guard.reset();
  EXPECT_EQ(guard.read_joints(&q), DeviceError::kOk);
}

TEST(ReadingGuard, ThresholdIsTheSpeedTimesTheLongestPeriod) {
  ScriptedDevice dev;
  GuardParams p = guard_params();
  p.max_period_s = 2.8e-3;  // the jittered loop's longest period
  ReadingGuard guard(&dev, p);
  Joints q;
  dev.q.setZero();
  ASSERT_EQ(guard.read_joints(&q), DeviceError::kOk);
  dev.q[2] = 0.99 * 50.0 * 2.8e-3;
  EXPECT_EQ(guard.read_joints(&q), DeviceError::kOk);
  dev.q[2] += 1.01 * 50.0 * 2.8e-3;
  EXPECT_EQ(guard.read_joints(&q), DeviceError::kSensorFault);
}

TEST(ReadingGuard, GimbalAndDisabledAreNotChecked) {
  ScriptedDevice dev;
  ReadingGuard guard(&dev, guard_params());
  Joints q;
  dev.q.setZero();
  ASSERT_EQ(guard.read_joints(&q), DeviceError::kOk);
  dev.q[3] = 2.0;  // a potentiometer swings far: absolute, not checked
  EXPECT_EQ(guard.read_joints(&q), DeviceError::kOk);

  GuardParams off = guard_params();
  off.enabled = false;
  ReadingGuard open(&dev, off);
  dev.q[0] = std::nan("");
  EXPECT_EQ(open.read_joints(&q), DeviceError::kOk);
  EXPECT_TRUE(std::isnan(q[0]));
}

// The servo path allocates nothing (the controller's own promise, extended
// to the device layer): read and write through guard and injector, with
// every fault kind firing.
TEST(FaultInjectorNoAlloc, ReadAndWriteAllocateNothing) {
  for (SensorFaultKind kind : {SensorFaultKind::kNone, SensorFaultKind::kNan,
                               SensorFaultKind::kJump, SensorFaultKind::kStuck}) {
    ScriptedDevice dev;
    FaultSpec spec;
    spec.kind = kind;
    spec.at_s = 0.05;
    FaultInjector inj(&dev, spec);
    ReadingGuard guard(&inj, guard_params());
    std::size_t allocations = 0;
    {
      testing::AllocationScope scope;
      for (int k = 0; k < 100; ++k) {
        dev.q = ramp(1e-3 * k);
        inj.set_time_s(1e-3 * k);
        Joints q;
        (void)guard.read_joints(&q);
        (void)guard.write_motor_torques(Vec3(0.01 * k, 0.0, -0.01));
      }
      allocations = scope.count();
    }
    EXPECT_EQ(allocations, 0u) << sensor_fault_kind_name(kind);
  }
}

}  // namespace
}  // namespace vmh::sim
