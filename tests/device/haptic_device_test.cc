// controller/haptic_device: servo_tick(), the one servo tick shared by the
// simulator and the device, against a scripted fake device.
//
// On a good reading the device must receive exactly the torques a second
// Controller computes from the same angles converted to the DH convention
// by hand (q1 = -t1, q2 = t2, q3 = t3 - t2, q4 = -t4, q5 = t5, q6 = -t6).
// On a failed read or a controller fault the device must receive zero.
#include "device/servo_tick.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "controller/controller.h"

namespace vmh {

// gtest prints a DeviceError parameter by its name
void PrintTo(DeviceError e, std::ostream* os) { *os << device_error_name(e); }

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A device whose readings and errors the test sets, and which records what
// it was asked to write.
class FakeDevice final : public HapticDevice {
 public:
  DeviceError read_joints(Joints* q_device_rad) noexcept override {
    ++reads;
    if (read_error != DeviceError::kOk) {
      q_device_rad->setConstant(1e6);  // garbage: must not be used
      return read_error;
    }
    *q_device_rad = q_device;
    return DeviceError::kOk;
  }
  DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override {
    ++writes;
    written_Nm = tau_motor_Nm;
    return write_error;
  }

  Joints q_device = Joints::Zero();
  DeviceError read_error = DeviceError::kOk;
  DeviceError write_error = DeviceError::kOk;
  Vec3 written_Nm = Vec3::Constant(kNaN);
  int reads = 0;
  int writes = 0;
};

// the device convention to DH, by hand
Joints dh_of(const Joints& t) {
  Joints q;
  q << -t[0], t[1], t[2] - t[1], -t[3], t[4], -t[5];
  return q;
}

// a circle of L = 50 mm about the device origin, K_pos 0.5 N/mm, half the
// thesis's orientation gain, and some velocity gain so e_dot matters
ControllerParams params() {
  ControllerParams p;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  p.gains.k_vel_Ns_per_mm = 0.01;
  return p;
}

// device angles with the wrist centre a few centimetres off the circle
const Joints kPoseA = (Joints() << -0.1, 0.4, 0.1, -0.2, 0.3, 0.1).finished();
const Joints kPoseB =
    (Joints() << 0.15, 0.25, -0.05, 0.3, -0.2, 0.4).finished();

TEST(ServoTickTest, GoodReadWritesTheControllersTorques) {
  static_assert(noexcept(servo_tick(nullptr, nullptr, nullptr)),
                "servo_tick must be noexcept");
  FakeDevice dev;
  Controller c(params()), reference(params());
  ControlOutput out, ref_out;
  for (const Joints& t : {kPoseA, kPoseB, kPoseA}) {
    dev.q_device = t;
    const ServoTickResult r = servo_tick(&dev, &c, &out);
    const ControlStatus ref_status = reference.tick(dh_of(t), &ref_out);
    EXPECT_EQ(r.read, DeviceError::kOk);
    EXPECT_EQ(r.write, DeviceError::kOk);
    EXPECT_FALSE(r.zeroed);
    EXPECT_EQ(r.control, ref_status);
    EXPECT_FALSE(is_fault(r.control));
    for (int i = 0; i < 3; ++i) {
      EXPECT_DOUBLE_EQ(dev.written_Nm[i], ref_out.tau_motor_Nm[i]) << i;
      EXPECT_DOUBLE_EQ(out.tau_motor_Nm[i], ref_out.tau_motor_Nm[i]) << i;
    }
    // the pose is off the path: a real torque, not a trivial zero
    EXPECT_GT(dev.written_Nm.norm(), 1e-3);
  }
  EXPECT_EQ(dev.reads, 3);
  EXPECT_EQ(dev.writes, 3);
}

class FailedReadTest : public ::testing::TestWithParam<DeviceError> {};

// Any failed read: zero torque written once, zeroed set, *out untouched,
// and the controller reset, so the next good reading starts afresh (its
// torque equals that of a new controller; without the reset e_dot would
// carry the jump from the last reading).
TEST_P(FailedReadTest, WritesZeroAndResetsTheController) {
  FakeDevice dev;
  Controller c(params());
  ControlOutput out;
  dev.q_device = kPoseA;
  ASSERT_FALSE(servo_tick(&dev, &c, &out).zeroed);
  ASSERT_GT(dev.written_Nm.norm(), 1e-3);

  ControlOutput before = out;
  dev.read_error = GetParam();
  const ServoTickResult r = servo_tick(&dev, &c, &out);
  EXPECT_EQ(r.read, GetParam());
  EXPECT_EQ(r.write, DeviceError::kOk);
  EXPECT_EQ(r.control, kStatusOk);
  EXPECT_TRUE(r.zeroed);
  EXPECT_EQ(dev.writes, 2);
  EXPECT_EQ(dev.written_Nm, Vec3::Zero());
  EXPECT_EQ(out.tau_motor_Nm, before.tau_motor_Nm);
  EXPECT_EQ(out.status, before.status);
  EXPECT_EQ(out.e, before.e);

  // next good reading, at another pose
  dev.read_error = DeviceError::kOk;
  dev.q_device = kPoseB;
  servo_tick(&dev, &c, &out);
  Controller fresh(params());
  ControlOutput fresh_out;
  fresh.tick(dh_of(kPoseB), &fresh_out);
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(dev.written_Nm[i], fresh_out.tau_motor_Nm[i]) << i;
  }
  EXPECT_EQ(out.e_dot, Vec6::Zero());
}

INSTANTIATE_TEST_SUITE_P(
    EveryError, FailedReadTest,
    ::testing::Values(DeviceError::kNotConnected, DeviceError::kIo,
                      DeviceError::kTimeout, DeviceError::kSensorFault,
                      DeviceError::kInvalidCommand),
    [](const ::testing::TestParamInfo<DeviceError>& param_info) {
      return std::string(device_error_name(param_info.param));
    });

// The control for the test above: without a failed read in between, the
// second reading's torque differs from a fresh controller's (e_dot), so
// the equality above does show the reset.
TEST(ServoTickTest, WithoutAResetTheHistoryShows) {
  FakeDevice dev;
  Controller c(params());
  ControlOutput out;
  dev.q_device = kPoseA;
  servo_tick(&dev, &c, &out);
  dev.q_device = kPoseB;
  servo_tick(&dev, &c, &out);
  Controller fresh(params());
  ControlOutput fresh_out;
  fresh.tick(dh_of(kPoseB), &fresh_out);
  EXPECT_GT((dev.written_Nm - fresh_out.tau_motor_Nm).norm(), 1e-6);
  EXPECT_GT(out.e_dot.norm(), 0.0);
}

// A reading that is not a joint angle is the controller's fault to find:
// invalid input, zero torque.
TEST(ServoTickTest, NanAnglesFaultTheControllerAndWriteZero) {
  for (int joint = 0; joint < 6; ++joint) {
    FakeDevice dev;
    Controller c(params());
    ControlOutput out;
    dev.q_device = kPoseA;
    servo_tick(&dev, &c, &out);
    ASSERT_GT(dev.written_Nm.norm(), 1e-3);
    dev.q_device[joint] = kNaN;
    const ServoTickResult r = servo_tick(&dev, &c, &out);
    EXPECT_EQ(r.read, DeviceError::kOk);
    EXPECT_TRUE(r.control & kStatusInvalidInput) << joint;
    EXPECT_TRUE(is_fault(r.control));
    EXPECT_TRUE(r.zeroed);
    EXPECT_EQ(dev.written_Nm, Vec3::Zero()) << joint;
    EXPECT_EQ(dev.writes, 2);
  }
}

// A write that fails is reported; the torque it tried to send was the
// controller's.
TEST(ServoTickTest, WriteErrorIsReported) {
  for (const DeviceError e : {DeviceError::kIo, DeviceError::kNotConnected,
                              DeviceError::kInvalidCommand}) {
    FakeDevice dev;
    Controller c(params()), reference(params());
    ControlOutput out, ref_out;
    dev.q_device = kPoseA;
    dev.write_error = e;
    const ServoTickResult r = servo_tick(&dev, &c, &out);
    reference.tick(dh_of(kPoseA), &ref_out);
    EXPECT_EQ(r.read, DeviceError::kOk);
    EXPECT_EQ(r.write, e);
    EXPECT_FALSE(is_fault(r.control));
    // "zeroed: any device error or controller fault" (haptic_device.h)
    EXPECT_TRUE(r.zeroed);
    EXPECT_EQ(dev.written_Nm, ref_out.tau_motor_Nm);
  }
}

// A failed read whose zero write also fails reports both.
TEST(ServoTickTest, FailedReadAndFailedWriteAreBothReported) {
  FakeDevice dev;
  Controller c(params());
  ControlOutput out;
  dev.read_error = DeviceError::kTimeout;
  dev.write_error = DeviceError::kIo;
  const ServoTickResult r = servo_tick(&dev, &c, &out);
  EXPECT_EQ(r.read, DeviceError::kTimeout);
  EXPECT_EQ(r.write, DeviceError::kIo);
  EXPECT_TRUE(r.zeroed);
  EXPECT_EQ(dev.written_Nm, Vec3::Zero());
}

TEST(DeviceErrorNameTest, NamesEveryValue) {
  const std::vector<std::pair<DeviceError, const char*>> names = {
      {DeviceError::kOk, "ok"},
      {DeviceError::kNotConnected, "not_connected"},
      {DeviceError::kIo, "io"},
      {DeviceError::kTimeout, "timeout"},
      {DeviceError::kSensorFault, "sensor_fault"},
      {DeviceError::kInvalidCommand, "invalid_command"},
  };
  for (const auto& [e, name] : names) {
    EXPECT_STREQ(device_error_name(e), name) << static_cast<int>(e);
  }
  // the enum is numbered from 0 without gaps; one past the end is unknown
  EXPECT_EQ(static_cast<int>(DeviceError::kInvalidCommand), 5);
  EXPECT_STREQ(device_error_name(static_cast<DeviceError>(6)), "unknown");
}

}  // namespace
}  // namespace vmh
