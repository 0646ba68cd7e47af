// Checks of controller/device_frame: the OpenHaptics frame and joint
// convention against the DH ones.
#include "controller/device_frame.h"

#include <gtest/gtest.h>

#include <cmath>

#include "controller/omni_kinematics.h"
#include "tests/support/random_joints.h"

namespace vmh {
namespace {

using testing::JointSampler;

TEST(DeviceJoints, RoundTripBothWays) {
  JointSampler sample(21);
  for (int k = 0; k < 1000; ++k) {
    const Joints q = sample.next();
    EXPECT_LE((device_to_dh_joints(dh_to_device_joints(q)) - q).norm(), 1e-15);
    EXPECT_LE((dh_to_device_joints(device_to_dh_joints(q)) - q).norm(), 1e-15);
  }
}

// joint 3 absolute on the device: t3 = q2 + q3; joints 1, 4 and 6 turn the
// other way
TEST(DeviceJoints, JointThreeIsAbsoluteAndJointsOneFourSixReversed) {
  Joints q;
  q << 0.1, 0.2, 0.3, 0.4, 0.5, 0.6;
  const Joints t = dh_to_device_joints(q);
  Joints expect;
  expect << -0.1, 0.2, 0.5, -0.4, 0.5, -0.6;
  EXPECT_LE((t - expect).norm(), 1e-15);
}

// the stylus frame at q = 0 is the device frame itself
// The torque map is the joint map's inverse transpose: for any joint motion
// dt (device convention) and its DH image dq = device_to_dh_joints(t + dt) -
// device_to_dh_joints(t), the motors' power equals the DH joints' power.
TEST(DeviceTorques, EqualPowerUnderTheJointMap) {
  JointSampler sample(22);
  for (int k = 0; k < 1000; ++k) {
    const Joints t = sample.next();
    const Joints dt = 1e-3 * sample.next();
    const Joints dq = device_to_dh_joints(t + dt) - device_to_dh_joints(t);
    const Vec3 tau_dh = sample.next().head<3>();
    const Vec3 tau_motor = dh_to_motor_torques(tau_dh);
    // dq is a difference of angles near 1 rad: rounding about 1e-16 each
    EXPECT_NEAR(tau_motor.dot(dt.head<3>()), tau_dh.dot(dq.head<3>()), 1e-14);
    EXPECT_LE((motor_to_dh_torques(tau_motor) - tau_dh).norm(), 1e-15);
  }
  // the third motor carries the absolute forearm torque: a pure q3 torque
  // loads motors 2 and 3 in opposite senses
  EXPECT_EQ(dh_to_motor_torques(Vec3(0, 0, 1)), Vec3(0, -1, 1));
  EXPECT_EQ(dh_to_motor_torques(Vec3(1, 0, 0)), Vec3(-1, 0, 0));
}

TEST(DeviceFrame, StylusFrameAtHomeIsTheDeviceFrame) {
  const OmniParams p;
  const Mat3 R = base_to_device_rotation(omni_fk(p, Joints::Zero()).R_base);
  EXPECT_LE((R - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(DeviceFrame, RotationIsProper) {
  const Mat3 R = R_device_base();
  EXPECT_LE((R.transpose() * R - Mat3::Identity()).norm(), 0.0);
  EXPECT_DOUBLE_EQ(R.determinant(), 1.0);
}

// device axes named in docs/sources.md §4: y up is base z; z toward the user is
// base x (the arm's direction at q1 = 0)
TEST(DeviceFrame, AxesPointWhereTheDocsSay) {
  EXPECT_EQ(base_to_device_vector(Vec3::UnitZ()), Vec3::UnitY());
  EXPECT_EQ(base_to_device_vector(Vec3::UnitX()), Vec3::UnitZ());
  EXPECT_EQ(base_to_device_vector(Vec3::UnitY()), Vec3::UnitX());
}

TEST(DeviceFrame, PointsRoundTripAndScaleToMm) {
  OmniParams p;
  p.l0_m = 0.02;
  JointSampler sample(22);
  for (int k = 0; k < 1000; ++k) {
    const Vec3 x = 0.1 * sample.next().head<3>();
    EXPECT_LE((device_mm_to_base(p, base_to_device_mm(p, x)) - x).norm(),
              1e-15);
  }
  // 1 cm along base z is 10 mm along device y
  const Vec3 a = base_to_device_mm(p, Vec3(0.1, 0, 0));
  const Vec3 b = base_to_device_mm(p, Vec3(0.1, 0, 0.01));
  EXPECT_NEAR((b - a - Vec3(0, 10, 0)).norm(), 0.0, 1e-12);
}

// the device origin is the wrist centre at q = 0, whatever l0
TEST(DeviceFrame, OriginIsWristCentreAtZeroPose) {
  OmniParams p;
  p.l0_m = 0.03;
  EXPECT_LE(base_to_device_mm(p, omni_fk(p, Joints::Zero()).p_base_m).norm(),
            1e-12);
}

// identity: velocities map by the same rotation; a finite difference of the
// device-frame wrist position over device joint angles equals
// R_device_base J_pos dq/dt with dq = d(device_to_dh)/dt
TEST(DeviceFrame, DeviceJacobianByChainRuleMatchesDifferences) {
  const OmniParams p;
  JointSampler sample(23);
  Mat3 dq_dt = Mat3::Identity();  // d(q1,q2,q3)/d(t1,t2,t3)
  dq_dt << -1, 0, 0,              //
      0, 1, 0,                    //
      0, -1, 1;
  const double h = 1e-6;
  for (int k = 0; k < 200; ++k) {
    const Joints t = sample.next();
    const Mat3 J_dev =
        1e3 * R_device_base() *
        omni_jacobian(p, device_to_dh_joints(t)).block<3, 3>(0, 0) * dq_dt;
    for (int i = 0; i < 3; ++i) {
      Joints tp = t, tm = t;
      tp[i] += h;
      tm[i] -= h;
      const Vec3 d =
          (base_to_device_mm(p, omni_fk(p, device_to_dh_joints(tp)).p_base_m) -
           base_to_device_mm(p, omni_fk(p, device_to_dh_joints(tm)).p_base_m)) /
          (2 * h);
      EXPECT_LE((J_dev.col(i) - d).norm(), 1e-4) << "mm/rad, joint " << i;
    }
  }
}

// OmniParams' DH ranges in the device convention, worked out by hand from
// the joint map (t1 = -q1, t3 = q2 + q3, t4 = -q4, t6 = -q6)
TEST(DeviceJointRanges, FollowTheJointMap) {
  const OmniParams p;
  Joints lo, hi;
  device_joint_ranges(p, &lo, &hi);
  EXPECT_DOUBLE_EQ(lo[0], -p.joint_upper_rad[0]);
  EXPECT_DOUBLE_EQ(hi[0], -p.joint_lower_rad[0]);
  EXPECT_DOUBLE_EQ(lo[1], p.joint_lower_rad[1]);
  EXPECT_DOUBLE_EQ(hi[1], p.joint_upper_rad[1]);
  EXPECT_DOUBLE_EQ(lo[2], p.joint_lower_rad[1] + p.joint_lower_rad[2]);
  EXPECT_DOUBLE_EQ(hi[2], p.joint_upper_rad[1] + p.joint_upper_rad[2]);
  EXPECT_DOUBLE_EQ(lo[3], -p.joint_upper_rad[3]);
  EXPECT_DOUBLE_EQ(hi[4], p.joint_upper_rad[4]);
  EXPECT_DOUBLE_EQ(lo[5], -p.joint_upper_rad[5]);
  EXPECT_DOUBLE_EQ(hi[5], -p.joint_lower_rad[5]);
}

}  // namespace
}  // namespace vmh
