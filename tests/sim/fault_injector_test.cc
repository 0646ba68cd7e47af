// sim/fault_injector.h on its own, against a scripted device: the injector
// corrupts exactly the joint, from exactly the time, by exactly the amount
// it says, and allocates nothing on the servo path, behind the device
// layer's guard (tested alone in tests/device/reading_guard_test.cc).
#include "sim/fault_injector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "device/reading_guard.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/scripted_device.h"

namespace vmh::sim {
namespace {

using testing::kCount;
using testing::ramp;
using testing::ScriptedDevice;

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
