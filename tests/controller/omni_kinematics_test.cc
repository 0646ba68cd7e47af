// Checks of controller/omni_kinematics against routes that do not share its
// code: the OpenHaptics closed form (docs/sources.md §4), central finite
// differences, and forward kinematics of the inverse solutions.
// (MuJoCo's own kinematics are compared in omni_kinematics_mujoco_test.cc.)
#include "controller/omni_kinematics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "controller/device_frame.h"
#include "tests/support/openhaptics_reference.h"
#include "tests/support/random_joints.h"
#include "tests/support/constants.h"

namespace vmh {
namespace {

using testing::JointSampler;
using testing::openhaptics_stylus_rotation;
using testing::openhaptics_wrist_mm;

using vmh::testing::kPi;

// rotation vector of R_b R_a^T (the rotation taking a to b), base frame
Vec3 rotation_between(const Mat3& Ra, const Mat3& Rb) {
  const Eigen::AngleAxisd aa(Rb * Ra.transpose());
  return aa.angle() * aa.axis();
}

double angle_distance(const Joints& a, const Joints& b) {
  double d = 0;
  for (int i = 0; i < 6; ++i)
    d = std::max(d, std::abs(wrap_angle(a[i] - b[i])));
  return d;
}

// identity: omni_fk(device_to_dh(t)) mapped to the device frame equals the
// OpenHaptics wrist-centre closed form and stylus rotation, for 10,000 random
// device configurations
TEST(OmniFk, DeviceFrameEqualsOpenHapticsClosedForm) {
  const OmniParams p;
  JointSampler sample(1);
  double worst_mm = 0, worst_rot = 0;
  for (int k = 0; k < 10000; ++k) {
    const Joints t = sample.next();
    const OmniPose pose = omni_fk(p, device_to_dh_joints(t));
    const Vec3 ref_mm =
        openhaptics_wrist_mm(t, p.l1_m * kMmPerM, p.l2_m * kMmPerM);
    worst_mm = std::max(worst_mm,
                        (base_to_device_mm(p, pose.p_base_m) - ref_mm).norm());
    worst_rot = std::max(worst_rot, (base_to_device_rotation(pose.R_base) -
                                     openhaptics_stylus_rotation(t))
                                        .cwiseAbs()
                                        .maxCoeff());
  }
  EXPECT_LE(worst_mm, 1e-6);  // 1e-9 m
  EXPECT_LE(worst_rot, 1e-12);
}

// identity: the home pose q = 0 is the device-frame origin, stylus toward the
// user (+z device)
TEST(OmniFk, HomePoseIsDeviceOrigin) {
  const OmniParams p;
  const OmniPose pose = omni_fk(p, Joints::Zero());
  EXPECT_LE(base_to_device_mm(p, pose.p_base_m).norm(), 1e-12);
  EXPECT_LE((base_to_device_vector(pose.R_base.col(2)) - Vec3::UnitZ()).norm(),
            1e-12);
}

// identity: R^T R = I and det R = +1 for every frame
TEST(OmniFk, EveryFrameIsAProperRotation) {
  const OmniParams p;
  JointSampler sample(2);
  for (int k = 0; k < 1000; ++k) {
    OmniFrames f;
    omni_frames(p, sample.next(), &f);
    for (const auto& T : f.T_base) {
      const Mat3 R = T.linear();
      EXPECT_LE((R.transpose() * R - Mat3::Identity()).norm(), 1e-12);
      EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    }
  }
}

// identity: the wrist centre does not move with the gimbal joints 4-6
TEST(OmniFk, WristCentreIndependentOfGimbal) {
  const OmniParams p;
  JointSampler sample(3);
  for (int k = 0; k < 1000; ++k) {
    Joints a = sample.next(), b = sample.next();
    b.head<3>() = a.head<3>();
    EXPECT_LE((omni_fk(p, a).p_base_m - omni_fk(p, b).p_base_m).norm(), 1e-15);
  }
}

// identity: the tool point lies tool_offset_m along z6 from the wrist centre
TEST(OmniFk, ToolPointOnStylusAxis) {
  OmniParams p;
  p.tool_offset_m = -0.0375;
  JointSampler sample(4);
  for (int k = 0; k < 100; ++k) {
    const OmniPose pose = omni_fk(p, sample.next());
    const Vec3 d = omni_tool_point(p, pose) - pose.p_base_m;
    EXPECT_NEAR(d.norm(), 0.0375, 1e-15);
    EXPECT_NEAR(d.dot(pose.R_base.col(2)), -0.0375, 1e-15);
  }
}

// identity: J(q) dq = (p(q + h e_i) - p(q - h e_i)) / 2h in rows 1-3, and the
// rotation vector of R(q + h e_i) R(q - h e_i)^T / 2h in rows 4-6
void check_jacobian_by_differences(const OmniParams& p, double offset_m,
                                   unsigned seed) {
  OmniParams po = p;
  po.tool_offset_m = offset_m;
  JointSampler sample(seed);
  const double h = 1e-6;
  double worst = 0;
  for (int k = 0; k < 2000; ++k) {
    const Joints q = sample.next();
    const Mat6 J = omni_jacobian_at(p, q, offset_m);
    for (int i = 0; i < 6; ++i) {
      Joints qp = q, qm = q;
      qp[i] += h;
      qm[i] -= h;
      const OmniPose a = omni_fk(po, qp), b = omni_fk(po, qm);
      const Vec3 v =
          (omni_tool_point(po, a) - omni_tool_point(po, b)) / (2 * h);
      const Vec3 w = rotation_between(b.R_base, a.R_base) / (2 * h);
      worst = std::max(worst, (J.block<3, 1>(0, i) - v).cwiseAbs().maxCoeff());
      worst = std::max(worst, (J.block<3, 1>(3, i) - w).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LE(worst, 1e-7) << "offset " << offset_m;
}

TEST(OmniJacobian, WristCentreEqualsFiniteDifferences) {
  check_jacobian_by_differences(OmniParams{}, 0.0, 5);
}

TEST(OmniJacobian, ToolPointEqualsFiniteDifferences) {
  check_jacobian_by_differences(OmniParams{}, -0.04, 6);
}

TEST(OmniJacobian, UnequalLinksAndBaseOffsetEqualFiniteDifferences) {
  OmniParams p;
  p.l0_m = 0.035;
  p.l1_m = 0.14;
  p.l2_m = 0.11;
  check_jacobian_by_differences(p, 0.02, 7);
}

// identity: omni_jacobian is omni_jacobian_at with zero offset, and the
// gimbal columns have no linear part there (their axes meet at the wrist)
TEST(OmniJacobian, GimbalColumnsHaveNoLinearPartAtTheWristCentre) {
  const OmniParams p;
  JointSampler sample(8);
  for (int k = 0; k < 100; ++k) {
    const Joints q = sample.next();
    const Mat6 J = omni_jacobian(p, q);
    EXPECT_LE((J.block<3, 3>(0, 3).cwiseAbs().maxCoeff()), 1e-15);
    EXPECT_EQ(J, omni_jacobian_at(p, q, 0.0));
  }
}

// FK(IK(x)) = x for every solution, and the nearest solution to the
// configuration FK came from is that configuration
TEST(OmniIk, PositionSolutionsReproduceTargetAndNearestIsSource) {
  const OmniParams p;
  JointSampler sample(9);
  double worst_m = 0, worst_rad = 0;
  int total = 0;
  for (int k = 0; k < 10000; ++k) {
    const Joints q = sample.next();
    const Vec3 target = omni_fk(p, q).p_base_m;
    const IkSolutions s = omni_ik_position(p, target, q);
    ASSERT_EQ(s.status, IkStatus::kOk);
    ASSERT_GE(s.count, 1);
    total += s.count;
    for (int j = 0; j < s.count; ++j) {
      worst_m =
          std::max(worst_m, (omni_fk(p, s.q_dh[j]).p_base_m - target).norm());
    }
    const int best = omni_ik_nearest(s, q);
    ASSERT_GE(best, 0);
    worst_rad = std::max(worst_rad, angle_distance(s.q_dh[best], q));
  }
  EXPECT_LE(worst_m, 1e-9);
  EXPECT_LE(worst_rad, 1e-9);
  // generic targets have two shoulder and two elbow branches
  EXPECT_EQ(total, 4 * 10000);
}

TEST(OmniIk, PoseSolutionsReproducePositionAndRotation) {
  const OmniParams p;
  JointSampler sample(10);
  double worst_m = 0, worst_rot = 0, worst_rad_scaled = 0;
  for (int k = 0; k < 5000; ++k) {
    const Joints q = sample.next();
    const OmniPose pose = omni_fk(p, q);
    const IkSolutions s = omni_ik_pose(p, pose.p_base_m, pose.R_base, q);
    ASSERT_EQ(s.status, IkStatus::kOk);
    EXPECT_EQ(s.count, 8);
    for (int j = 0; j < s.count; ++j) {
      const OmniPose got = omni_fk(p, s.q_dh[j]);
      worst_m = std::max(worst_m, (got.p_base_m - pose.p_base_m).norm());
      worst_rot = std::max(worst_rot, (got.R_base - pose.R_base).norm());
    }
    // q4 and q6 are recovered from R with an error that grows as 1/|cos q5|
    // toward the gimbal singularity, so the angle check is scaled by it
    worst_rad_scaled = std::max(
        worst_rad_scaled, angle_distance(s.q_dh[omni_ik_nearest(s, q)], q) *
                              std::abs(std::cos(q[4])));
  }
  EXPECT_LE(worst_m, 1e-9);
  EXPECT_LE(worst_rot, 1e-9);
  EXPECT_LE(worst_rad_scaled, 1e-9);
}

// solutions are returned within pi of `near`, whole turns included
TEST(OmniIk, SolutionsUnwrapTowardNear) {
  const OmniParams p;
  Joints q;
  q << 0.3, 0.4, 0.2, 0.1, -0.2, 0.5;
  Joints near = q;
  near.array() += 2 * kPi;
  const IkSolutions s =
      omni_ik_pose(p, omni_fk(p, q).p_base_m, omni_fk(p, q).R_base, near);
  const int best = omni_ik_nearest(s, near);
  ASSERT_GE(best, 0);
  EXPECT_LE((s.q_dh[best] - near).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(OmniIk, BeyondReachIsReportedNotNaN) {
  const OmniParams p;
  const Vec3 far(0.0, 0.0, 0.3);  // 0.3 m > l1 + l2 = 0.2667 m
  const IkSolutions s = omni_ik_position(p, far, Joints::Zero());
  EXPECT_EQ(s.status, IkStatus::kUnreachable);
  EXPECT_EQ(s.count, 0);
  EXPECT_NEAR(s.reach_excess_m, 0.3 - 0.2667, 1e-12);
  EXPECT_EQ(omni_ik_nearest(s, Joints::Zero()), -1);
}

TEST(OmniIk, InsideTheInnerHoleIsUnreachable) {
  OmniParams p;
  p.l1_m = 0.14;
  p.l2_m = 0.10;  // nothing closer than 0.04 m to the shoulder is reachable
  const IkSolutions s =
      omni_ik_position(p, Vec3(0.01, 0.01, 0.0), Joints::Zero());
  EXPECT_EQ(s.status, IkStatus::kUnreachable);
  EXPECT_NEAR(s.reach_excess_m, 0.04 - std::sqrt(2) * 0.01, 1e-12);
}

TEST(OmniIk, NonFiniteInputIsRejected) {
  const OmniParams p;
  const double nan = std::nan("");
  EXPECT_EQ(omni_ik_position(p, Vec3(nan, 0, 0), Joints::Zero()).status,
            IkStatus::kInvalidInput);
  Joints near = Joints::Zero();
  near[4] = INFINITY;
  EXPECT_EQ(omni_ik_position(p, Vec3(0.1, 0, 0), near).status,
            IkStatus::kInvalidInput);
  // a finite hint too large to unwrap toward (1e17 rad has no angle left)
  near = Joints::Zero();
  near[0] = 1e17;
  EXPECT_EQ(omni_ik_position(p, Vec3(0.1, 0, 0), near).status,
            IkStatus::kInvalidInput);
  near[0] = kIkMaxHintRad;  // the largest accepted
  const IkSolutions big = omni_ik_position(p, Vec3(0.1, 0, -0.1), near);
  ASSERT_EQ(big.status, IkStatus::kOk);
  for (int k = 0; k < big.count; ++k) {
    const OmniPose fk = omni_fk(p, big.q_dh[k]);
    EXPECT_LT((fk.p_base_m - Vec3(0.1, 0, -0.1)).norm(), 1e-9) << k;
  }
  Mat3 R = Mat3::Identity();
  R(1, 1) = nan;
  const IkSolutions s = omni_ik_pose(p, Vec3(0.1, 0, -0.1), R, Joints::Zero());
  EXPECT_EQ(s.status, IkStatus::kInvalidInput);
  EXPECT_EQ(s.count, 0);
}

// the wrist centre on the joint-1 axis: q1 is free, taken from `near`
TEST(OmniIk, ShoulderSingularityTakesQ1FromNear) {
  const OmniParams p;
  const Vec3 target(0.0, 0.0, -0.2);
  Joints near = Joints::Zero();
  near[0] = 0.42;
  const IkSolutions s = omni_ik_position(p, target, near);
  ASSERT_EQ(s.status, IkStatus::kOk);
  EXPECT_TRUE(s.shoulder_singular);
  ASSERT_GE(s.count, 1);
  for (int j = 0; j < s.count; ++j) {
    EXPECT_TRUE(s.q_dh[j].allFinite());
    EXPECT_DOUBLE_EQ(s.q_dh[j][0], 0.42);
    EXPECT_LE((omni_fk(p, s.q_dh[j]).p_base_m - target).norm(), 1e-9);
  }
}

// the arm fully stretched: both elbow branches are q3 = pi/2, merged
TEST(OmniIk, FullyStretchedArmHasOneElbowBranch) {
  const OmniParams p;
  Joints q = Joints::Zero();
  q[1] = 0.3;
  q[2] = kPi / 2;
  const Vec3 target = omni_fk(p, q).p_base_m;
  const IkSolutions s = omni_ik_position(p, target, q);
  ASSERT_EQ(s.status, IkStatus::kOk);
  EXPECT_TRUE(s.elbow_singular);
  EXPECT_EQ(s.count, 2);  // two shoulder branches, one elbow branch each
  for (int j = 0; j < s.count; ++j) {
    EXPECT_LE((omni_fk(p, s.q_dh[j]).p_base_m - target).norm(), 1e-9);
  }
}

// q5 = +-pi/2 aligns the q4 and q6 axes: q4 comes from `near`
TEST(OmniIk, GimbalSingularityGivesFiniteExactSolutions) {
  const OmniParams p;
  for (double q5 : {kPi / 2, -kPi / 2}) {
    Joints q;
    q << 0.2, 0.5, 0.1, 0.7, q5, -0.4;
    const OmniPose pose = omni_fk(p, q);
    Joints near = q;
    near[3] = -0.25;
    const IkSolutions s = omni_ik_pose(p, pose.p_base_m, pose.R_base, near);
    ASSERT_EQ(s.status, IkStatus::kOk);
    EXPECT_TRUE(s.wrist_singular) << "q5 " << q5;
    for (int j = 0; j < s.count; ++j) {
      EXPECT_TRUE(s.q_dh[j].allFinite());
      const OmniPose got = omni_fk(p, s.q_dh[j]);
      EXPECT_LE((got.R_base - pose.R_base).norm(), 1e-9);
      EXPECT_LE((got.p_base_m - pose.p_base_m).norm(), 1e-9);
    }
  }
}

// the docked pose reported by OpenHaptics is reachable inside the joint ranges
TEST(OmniIk, InkwellPoseIsReachableWithinLimits) {
  const OmniParams p;
  const Vec3 inkwell = device_mm_to_base(p, Vec3(0.0, -65.51, -88.11));
  const IkSolutions s = omni_ik_position(p, inkwell, Joints::Zero());
  ASSERT_EQ(s.status, IkStatus::kOk);
  const int best = omni_ik_nearest(s, Joints::Zero());
  ASSERT_GE(best, 0);
  EXPECT_TRUE(s.within_limits[best]);
  // the arm points down and forward, elbow bent: q2 < 0 < q3
  EXPECT_LT(s.q_dh[best][1], 0.0);
  EXPECT_GT(s.q_dh[best][2], 0.0);
}

TEST(OmniLimits, InsideEdgesOutsideWrappedAndNaN) {
  const OmniParams p;
  EXPECT_TRUE(omni_within_limits(p, Joints::Zero()));
  Joints q = Joints::Zero();
  q[1] = p.joint_upper_rad[1];  // the edge counts as inside
  EXPECT_TRUE(omni_within_limits(p, q));
  q[1] = p.joint_upper_rad[1] + 1e-9;
  EXPECT_FALSE(omni_within_limits(p, q));
  q[1] = 0.2 + 2 * kPi;  // a whole turn away from an inside angle
  EXPECT_TRUE(omni_within_limits(p, q));
  q[1] = std::nan("");
  EXPECT_FALSE(omni_within_limits(p, q));
}

TEST(WrapAngle, HalfOpenInterval) {
  EXPECT_DOUBLE_EQ(wrap_angle(kPi), kPi);
  EXPECT_DOUBLE_EQ(wrap_angle(-kPi), kPi);
  EXPECT_NEAR(wrap_angle(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_angle(2 * kPi + 0.1), 0.1, 1e-12);
  EXPECT_NEAR(wrap_angle(-2 * kPi - 0.1), -0.1, 1e-12);
  EXPECT_DOUBLE_EQ(wrap_angle(0.0), 0.0);
  EXPECT_TRUE(std::isnan(wrap_angle(std::nan(""))));
}

}  // namespace
}  // namespace vmh
