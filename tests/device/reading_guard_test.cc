// device/reading_guard.h against a scripted device: the guard refuses what
// no hand can do (a non-finite angle, an encoder step faster than a hand can
// turn it) and passes what one can, and allocates nothing on the servo path.
#include "device/reading_guard.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/alloc_counter.h"
#include "tests/support/scripted_device.h"

namespace vmh {
namespace {

using testing::kCount;
using testing::ramp;
using testing::ScriptedDevice;

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

// a device whose readings say when it set its encoder offsets again (a
// FireWire Omni re-homed in its inkwell)
class RehomingDevice final : public HapticDevice {
 public:
  Joints q = Joints::Zero();
  bool rehomed = false;
  DeviceError read_joints(Joints* out) noexcept override {
    *out = q;
    return DeviceError::kOk;
  }
  DeviceError read_state(DeviceState* s) noexcept override {
    s->q_device_rad = q;
    s->rehomed = rehomed;
    s->present = kStateJoints;
    return DeviceError::kOk;
  }
  DeviceError write_motor_torques(const Vec3&) noexcept override {
    return DeviceError::kOk;
  }
};

TEST(ReadingGuard, AReHomedReadingMayStepAndEndsTheLatch) {
  RehomingDevice dev;
  ReadingGuard guard(&dev, guard_params());
  DeviceState s;
  dev.q = ramp(0.0);
  ASSERT_EQ(guard.read_state(&s), DeviceError::kOk);
  // a slip: latched
  dev.q[0] += 1000.0 * kCount;
  EXPECT_EQ(guard.read_state(&s), DeviceError::kSensorFault);
  EXPECT_TRUE(guard.latched());
  EXPECT_EQ(guard.read_state(&s), DeviceError::kSensorFault);
  // docked: the device sets its offsets, the reading steps to the inkwell
  // pose; the angle is right again
  dev.q = ramp(0.0);
  dev.q[2] -= 0.6;
  dev.rehomed = true;
  EXPECT_EQ(guard.read_state(&s), DeviceError::kOk);
  EXPECT_FALSE(guard.latched());
  EXPECT_EQ(s.q_device_rad, dev.q);
  // and the next readings are compared with it again: a slip still latches
  dev.rehomed = false;
  EXPECT_EQ(guard.read_state(&s), DeviceError::kOk);
  dev.q[1] += 1000.0 * kCount;
  EXPECT_EQ(guard.read_state(&s), DeviceError::kSensorFault);
  EXPECT_TRUE(guard.latched());
  // a re-homed reading that steps with no latch is passed too
  guard.reset();
  dev.q = ramp(0.0);
  ASSERT_EQ(guard.read_state(&s), DeviceError::kOk);
  dev.q[0] += 0.5;
  dev.rehomed = true;
  EXPECT_EQ(guard.read_state(&s), DeviceError::kOk);
  EXPECT_EQ(guard.last_fault(), GuardFault::kNone);
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

TEST(ReadingGuardNoAlloc, ReadAndWriteAllocateNothing) {
  ScriptedDevice dev;
  ReadingGuard guard(&dev, guard_params());
  std::size_t allocations = 0;
  {
    testing::AllocationScope scope;
    for (int k = 0; k < 100; ++k) {
      dev.q = ramp(1e-3 * k);
      if (k == 50) dev.q[0] = std::nan("");     // refused, sensor_nan
      if (k == 70) dev.q[1] += 1000.0 * kCount;  // latched, sensor_jump
      Joints q;
      (void)guard.read_joints(&q);
      (void)guard.write_motor_torques(Vec3(0.01 * k, 0.0, -0.01));
    }
    allocations = scope.count();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_TRUE(guard.latched());
}

}  // namespace
}  // namespace vmh
