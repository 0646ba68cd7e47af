// Checks of the one-pass kinematics (omni_fk_jacobian, omni_arm_kinematics)
// against the chain of 4 x 4 products they replace in the servo tick
// (omni_frames, omni_fk, omni_jacobian_at: agreement within 1e-12) and
// against central finite differences of the chain's FK (within 1e-7, the
// bound of omni_kinematics_test), for the default Omni and for unequal
// links with a base offset, at the wrist centre and at a tool point.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "controller/omni_kinematics.h"
#include "tests/support/random_joints.h"

namespace vmh {
namespace {

using testing::JointSampler;

constexpr double kAgree = 1e-12;

// rotation vector of R_b R_a^T (the rotation taking a to b), base frame
Vec3 one_pass_rotation_between(const Mat3& Ra, const Mat3& Rb) {
  const Eigen::AngleAxisd aa(Rb * Ra.transpose());
  return aa.angle() * aa.axis();
}

OmniParams unequal_links() {
  OmniParams p;
  p.l0_m = 0.035;
  p.l1_m = 0.14;
  p.l2_m = 0.11;
  return p;
}

// identity with the chain: pose and Jacobian equal omni_fk and
// omni_jacobian_at, and the stylus frame equals omni_frames' frame 6
void check_against_chain(const OmniParams& p, double offset_m, unsigned seed) {
  JointSampler sample(seed);
  double worst_p = 0, worst_R = 0, worst_J = 0;
  for (int k = 0; k < 10000; ++k) {
    const Joints q = sample.next();
    OmniPose pose;
    Mat6 J;
    omni_fk_jacobian(p, q, &pose, &J, offset_m);
    const OmniPose ref = omni_fk(p, q);
    OmniFrames frames;
    omni_frames(p, q, &frames);
    worst_p = std::max(worst_p,
                       (pose.p_base_m - ref.p_base_m).cwiseAbs().maxCoeff());
    worst_R = std::max(worst_R,
                       (pose.R_base - ref.R_base).cwiseAbs().maxCoeff());
    worst_R = std::max(
        worst_R,
        (pose.R_base - frames.T_base[kOmniJoints].linear()).cwiseAbs().maxCoeff());
    worst_J = std::max(
        worst_J, (J - omni_jacobian_at(p, q, offset_m)).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst_p, kAgree);
  EXPECT_LE(worst_R, kAgree);
  EXPECT_LE(worst_J, kAgree) << "offset " << offset_m;
}

TEST(OmniFkJacobian, EqualsTheChainAtTheWristCentre) {
  check_against_chain(OmniParams{}, 0.0, 11);
}

TEST(OmniFkJacobian, EqualsTheChainAtAToolPoint) {
  check_against_chain(OmniParams{}, -0.0375, 12);
}

TEST(OmniFkJacobian, EqualsTheChainWithUnequalLinksAndBaseOffset) {
  check_against_chain(unequal_links(), 0.02, 13);
}

// identity: J(q) e_i equals central differences of the chain's FK (tool
// point in rows 1-3, the rotation vector of R(q + h e_i) R(q - h e_i)^T in
// rows 4-6)
void check_against_differences(const OmniParams& p, double offset_m,
                               unsigned seed) {
  JointSampler sample(seed);
  const double h = 1e-6;
  double worst = 0;
  for (int k = 0; k < 2000; ++k) {
    const Joints q = sample.next();
    Mat6 J;
    omni_fk_jacobian(p, q, nullptr, &J, offset_m);
    for (int i = 0; i < 6; ++i) {
      Joints qp = q, qm = q;
      qp[i] += h;
      qm[i] -= h;
      const OmniPose a = omni_fk(p, qp), b = omni_fk(p, qm);
      const Vec3 ta = a.p_base_m + offset_m * a.R_base.col(2);
      const Vec3 tb = b.p_base_m + offset_m * b.R_base.col(2);
      const Vec3 v = (ta - tb) / (2 * h);
      const Vec3 w = one_pass_rotation_between(b.R_base, a.R_base) / (2 * h);
      worst = std::max(worst, (J.block<3, 1>(0, i) - v).cwiseAbs().maxCoeff());
      worst = std::max(worst, (J.block<3, 1>(3, i) - w).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LE(worst, 1e-7) << "offset " << offset_m;
}

TEST(OmniFkJacobian, EqualsFiniteDifferencesAtTheWristCentre) {
  check_against_differences(OmniParams{}, 0.0, 14);
}

TEST(OmniFkJacobian, EqualsFiniteDifferencesAtAToolPoint) {
  check_against_differences(OmniParams{}, -0.04, 15);
}

TEST(OmniFkJacobian, EqualsFiniteDifferencesWithUnequalLinks) {
  check_against_differences(unequal_links(), 0.02, 16);
}

// identity: the servo tick's subset is the same numbers as the full pass
// and as the chain: wrist centre, z6, and the top-left 3 x 3 of J
TEST(OmniArmKinematics, EqualsTheFullPassAndTheChain) {
  for (const OmniParams& p : {OmniParams{}, unequal_links()}) {
    JointSampler sample(17);
    double worst = 0;
    for (int k = 0; k < 10000; ++k) {
      const Joints q = sample.next();
      const OmniArmKinematics arm = omni_arm_kinematics(p, q);
      OmniPose pose;
      Mat6 J;
      omni_fk_jacobian(p, q, &pose, &J);
      const OmniPose ref = omni_fk(p, q);
      const Mat6 Jref = omni_jacobian(p, q);
      EXPECT_EQ(arm.p_base_m, pose.p_base_m);
      const Mat3 J_arm = J.topLeftCorner<3, 3>();
      EXPECT_EQ(arm.Jv_arm, J_arm);
      worst = std::max(worst, (arm.z6_base - pose.R_base.col(2)).cwiseAbs().maxCoeff());
      worst = std::max(worst, (arm.p_base_m - ref.p_base_m).cwiseAbs().maxCoeff());
      worst = std::max(worst, (arm.z6_base - ref.R_base.col(2)).cwiseAbs().maxCoeff());
      worst = std::max(worst, (arm.Jv_arm - Jref.topLeftCorner<3, 3>())
                                  .cwiseAbs().maxCoeff());
    }
    EXPECT_LE(worst, kAgree);
  }
}

// either output may be left out
TEST(OmniFkJacobian, EitherOutputMayBeOmitted) {
  const OmniParams p;
  const Joints q = (Joints() << 0.3, -0.2, 0.4, 1.0, -0.5, 2.0).finished();
  OmniPose pose, pose_only;
  Mat6 J, J_only;
  omni_fk_jacobian(p, q, &pose, &J);
  omni_fk_jacobian(p, q, &pose_only, nullptr);
  omni_fk_jacobian(p, q, nullptr, &J_only);
  EXPECT_EQ(pose.p_base_m, pose_only.p_base_m);
  EXPECT_EQ(pose.R_base, pose_only.R_base);
  EXPECT_EQ(J, J_only);
}

}  // namespace
}  // namespace vmh
