// The one servo chain (device/servo_chain.h) against a scripted device,
// checked by an independent route: the chain without a safety layer sends
// exactly what servo_tick on a hand-built guard and controller sends; with
// it, what a hand-built SafetyLayer sends; the record's pose is omni_fk's;
// a failed read zeroes; a tick allocates nothing.
#include <gtest/gtest.h>

#include <cmath>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "device/servo_chain.h"
#include "device/servo_tick.h"
#include "tests/support/alloc_counter.h"
#include "tests/support/scripted_device.h"

namespace vmh {
namespace {

using testing::ScriptedDevice;

const Joints kPose = (Joints() << -0.1, 0.4, 0.1, -0.2, 0.3, 0.1).finished();

ControllerParams circle() {
  ControllerParams p;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  return p;
}

TEST(ServoChain, WithoutSafetyItSendsWhatServoTickSends) {
  ScriptedDevice a, b;
  ChainOptions o;
  o.controller = circle();
  o.safety = false;
  ServoChain chain(&a, o);
  // the independent route: the guard and the controller by hand
  ReadingGuard guard(&b, GuardParams());
  Controller c(circle());
  ControlOutput out;
  TickRecord rec;
  for (int k = 0; k < 50; ++k) {
    a.q = b.q = kPose + testing::ramp(1e-3 * k) * 0.05;
    chain.tick(1e-3 * k, 1e-3 * k, &rec);
    servo_tick(&guard, &c, &out);
    ASSERT_EQ(a.written, b.written) << "tick " << k;
    EXPECT_EQ(rec.tau_cmd_Nm, out.tau_motor_Nm);
    EXPECT_EQ(rec.tau_sent_Nm, out.tau_motor_Nm);
    EXPECT_EQ(rec.safety, kSafetyOk);
    EXPECT_EQ(rec.ramp_scale, 1.0);
  }
  ASSERT_GT(a.written.norm(), 1e-4);
}

TEST(ServoChain, WithSafetyItSendsWhatTheSafetyLayerSends) {
  ScriptedDevice a, b;
  ChainOptions o;
  o.controller = circle();
  o.safety = true;
  o.safety_params.ramp_s = 0.02;
  ServoChain chain(&a, o);
  ReadingGuard guard(&b, GuardParams());
  SafetyLayer safety(&guard, o.safety_params, circle().omni);
  Controller c(circle());
  ControlOutput out;
  TickRecord rec;
  for (int k = 0; k < 100; ++k) {
    a.q = b.q = kPose;
    chain.tick(1e-3 * k, 1e-3 * k, &rec);
    safety.set_read_time(1e-3 * k);
    servo_tick(&safety, &c, &out);
    ASSERT_EQ(a.written, b.written) << "tick " << k;
    EXPECT_EQ(rec.tau_sent_Nm, safety.last_torque_Nm());
    EXPECT_EQ(rec.safety, safety.status());
  }
  // the ramp ran: the first ticks flagged it, the last did not
  EXPECT_EQ(rec.ramp_scale, 1.0);
}

TEST(ServoChain, TheRecordsPoseIsTheReadingsForwardKinematics) {
  ScriptedDevice dev;
  dev.q = kPose;
  for (const ChainMode mode : {ChainMode::kRun, ChainMode::kRecord}) {
    ChainOptions o;
    o.mode = mode;
    o.controller = circle();
    ServoChain chain(&dev, o);
    TickRecord rec;
    chain.tick(0.0, 0.0, &rec);
    const Joints q_dh = device_to_dh_joints(kPose);
    EXPECT_EQ(rec.q_dh, q_dh);
    const OmniPose pose = omni_fk(circle().omni, q_dh);
    EXPECT_LT((rec.p_mm - base_to_device_mm(circle().omni, pose.p_base_m)).norm(), 1e-9);
    EXPECT_LT((rec.axis - base_to_device_vector(pose.R_base.col(2))).norm(), 1e-12);
    EXPECT_EQ(rec.has_controller, mode == ChainMode::kRun);
    EXPECT_EQ(std::isfinite(rec.d_path_mm), mode == ChainMode::kRun);
  }
}

TEST(ServoChain, AFailedReadZeroesAndLeavesNoReading) {
  ScriptedDevice dev;
  dev.q = kPose;
  ChainOptions o;
  o.controller = circle();
  o.safety = false;
  ServoChain chain(&dev, o);
  TickRecord rec;
  chain.tick(0.0, 0.0, &rec);
  ASSERT_NE(dev.written, Vec3::Zero());
  dev.read_error = DeviceError::kIo;
  chain.tick(1e-3, 1e-3, &rec);
  EXPECT_EQ(dev.written, Vec3::Zero());
  EXPECT_TRUE(rec.servo.zeroed);
  EXPECT_EQ(rec.servo.read, DeviceError::kIo);
  EXPECT_EQ(rec.state.present, 0u);
  EXPECT_TRUE(std::isnan(rec.q_dh[0]));
  EXPECT_EQ(rec.tau_cmd_Nm, Vec3::Zero());
  EXPECT_EQ(rec.tau_sent_Nm, Vec3::Zero());
}

TEST(ServoChain, RefusesWhatCannotBeRun) {
  ScriptedDevice dev;
  ChainOptions run;  // kRun without a controller
  EXPECT_THROW(ServoChain(&dev, run), std::invalid_argument);
  ChainOptions pulse;
  pulse.mode = ChainMode::kMotorTest;
  pulse.pulse.motor = 4;
  EXPECT_THROW(ServoChain(&dev, pulse), std::invalid_argument);
  EXPECT_THROW(ServoChain(nullptr, ChainOptions{}), std::invalid_argument);
}

TEST(ServoChain, TheReferenceAsksAtTheSameReadingWithoutActing) {
  ScriptedDevice dev;
  dev.q = kPose;
  ChainOptions o;
  o.controller = circle();
  o.safety = false;
  ControllerParams stiff = circle();
  stiff.gains.k_pos_N_per_mm *= 2.0;
  o.reference = stiff;
  ServoChain chain(&dev, o);
  TickRecord rec;
  chain.tick(0.0, 0.0, &rec);
  Controller c(stiff);
  ControlOutput out;
  c.tick(device_to_dh_joints(kPose), &out);
  EXPECT_EQ(rec.force_reference_N, out.force_device_N);
  EXPECT_NE(rec.force_reference_N, rec.out.force_device_N);
}

TEST(NoAlloc, ServoChainTick) {
  ScriptedDevice dev;
  ChainOptions o;
  o.controller = circle();
  o.reference = circle();
  ServoChain chain(&dev, o);
  TickRecord rec;
  testing::AllocationScope scope;
  for (int k = 0; k < 2000; ++k) {
    dev.q = kPose + testing::ramp(1e-4 * k) * 0.1;
    dev.read_error = k % 97 == 0 ? DeviceError::kTimeout : DeviceError::kOk;
    chain.tick(1e-3 * k, 1e-3 * k, &rec);
  }
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace vmh
