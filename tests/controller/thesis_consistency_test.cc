// The parts of the seed thesis's Appendix B that are printed right, shown
// against the same independent truths as the errata (errata_support.h): the
// Table B.1 chain composed from elementary transforms, its finite-difference
// Jacobian, and the project's own kinematics. errata_test.cc shows the rest.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"
#include "tests/controller/errata_support.h"
#include "tests/controller/thesis_equations.h"
#include "tests/support/openhaptics_reference.h"

namespace vmh {
namespace {

using namespace errata;  // NOLINT: the shared truths and corrected forms

// ===========================================================================
// What the seed gets right.

// Eq. B.1-B.3 are the Table B.1 links 1-3 (B.1 keeps L0 in its (3,4) entry).
TEST(SeedConsistent, EqB1ToB3MatchTableLinks) {
  Sampler s(101);
  double worst = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    worst = std::max(worst, (th::eqB1(q[0], kL0) - table_link(1, q[0])).norm());
    worst = std::max(worst, (th::eqB2(q[1]) - table_link(2, q[1])).norm());
    worst = std::max(worst, (th::eqB3(q[2], kL1) - table_link(3, q[2])).norm());
  }
  EXPECT_LE(worst, kExact);
}

// Eq. B.11 is the product of Table B.1 links 1-3.
TEST(SeedConsistent, EqB11MatchesTableArmProduct) {
  Sampler s(102);
  double worst = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    worst = std::max(
        worst,
        (th::eqB11(q[0], q[1], q[2], kL0, kL1) - table_chain(q, 1, 3)).norm());
  }
  EXPECT_LE(worst, kExact);
}

// Eq. B.12 is R_34 R_45 R_56 of Table B.1 (with the wrist offset (0, -L2, 0)),
// although it is not the product of the printed B.4-B.6.
TEST(SeedConsistent, EqB12MatchesTableWristProduct) {
  Sampler s(103);
  double worst = 0, worst_printed_product = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Mat4 b12 = th::eqB12(q[3], q[4], q[5], kL2);
    worst = std::max(worst, (b12 - table_chain(q, 4, 6)).norm());
    worst_printed_product = std::max(
        worst_printed_product,
        (b12 - th::eqB4(q[3], kL2) * th::eqB5(q[4]) * th::eqB6(q[5])).norm());
  }
  EXPECT_LE(worst, kExact);
  EXPECT_GT(worst_printed_product, kWrong);
}

// Eq. B.14: the position (Px, Py, Pz) and the stylus axis (r13, r23, r33)
// equal the Table B.1 product, as do B.11 * B.12 as a whole.
TEST(SeedConsistent, EqB14PositionAndStylusAxisMatchTableProduct) {
  Sampler s(104);
  double worst_p = 0, worst_z = 0, worst_b11b12 = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Mat4 T = table_chain(q, 1, 6);
    const th::EqB14 e = th::eqB14(q, kL0, kL1, kL2);
    worst_p = std::max(worst_p,
                       (Vec3(e.Px, e.Py, e.Pz) - T.block<3, 1>(0, 3)).norm());
    worst_z = std::max(
        worst_z, (Vec3(e.r13, e.r23, e.r33) - T.block<3, 1>(0, 2)).norm());
    worst_b11b12 =
        std::max(worst_b11b12, (th::eqB11(q[0], q[1], q[2], kL0, kL1) *
                                    th::eqB12(q[3], q[4], q[5], kL2) -
                                T)
                                   .norm());
  }
  EXPECT_LE(worst_p, kExact);
  EXPECT_LE(worst_z, kExact);
  EXPECT_LE(worst_b11b12, kExact);
}

// Eq. B.54: every entry but j11 and j45 equals the geometric Jacobian of the
// wrist centre, found by central finite differences of the Table B.1 chain.
TEST(SeedConsistent, EqB54MatchesFiniteDifferencesExceptJ11AndJ45) {
  Sampler s(105);
  double worst = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const th::Mat6 printed = th::eqB54(q, kL1, kL2);
    const th::Mat6 fd = fd_jacobian(q);
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) {
        if ((i == 0 && j == 0) || (i == 3 && j == 4)) continue;
        worst = std::max(worst, std::abs(printed(i, j) - fd(i, j)));
      }
    }
  }
  EXPECT_LE(worst, kFdTol);
}

// The position IK relations that hold as printed: B.16-B.18 (wrist centre in
// frames 3 and 2), B.20 with the B.19 right-hand side, B.26 (z), B.31-B.32
// (squared distance), and B.48 (theta_1) with the g1 of B.20.
TEST(SeedConsistent, EqB16ToB48PositionRelationsHold) {
  Sampler s(106);
  double worst = 0, worst_angle = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Vec3 p = table_chain(q, 1, 6).block<3, 1>(0, 3);
    const th::EqB18 f = th::eqB18(q[2], kL1, kL2);
    const th::EqB20 g = th::eqB20(q[1], f, kL0);
    // B.16 is the translation of ^3_4 T; B.17 is ^2_3 T applied to it
    worst =
        std::max(worst, (th::eqB16(kL2) - table_link(4, q[3]).col(3)).norm());
    worst = std::max(worst, (Vec3(f.f1, f.f2, f.f3) -
                             (table_link(3, q[2]) * th::eqB16(kL2)).head<3>())
                                .norm());
    worst = std::max(worst, (th::eqB19_rhs(q[0], g) - p).norm());
    worst = std::max(worst, std::abs(th::eqB26(q[1], f, kL0) - p.z()));
    worst = std::max(
        worst, std::abs(th::eqB32(q[2], p.z(), kL0, kL1, kL2) - th::eqB21(p)));
    worst_angle = std::max(
        worst_angle, std::abs(wrap(th::eqB48(p.x(), p.y(), g.g1) - q[0])));
  }
  EXPECT_LE(worst, kExact);
  EXPECT_LE(worst_angle, kAngle);
}

// The project's FK and Jacobian equal the independent truths used here, so
// what these tests call "corrected" is what the project computes.
TEST(SeedConsistent, ProjectKinematicsMatchIndependentTruths) {
  Sampler s(107);
  OmniParams p;
  p.l0_m = kL0;
  p.l1_m = kL1;
  p.l2_m = kL2;
  double worst_fk = 0, worst_j = 0, worst_b54 = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Mat4 T = table_chain(q, 1, 6);
    const OmniPose pose = omni_fk(p, q);
    worst_fk =
        std::max(worst_fk, (pose.p_base_m - T.block<3, 1>(0, 3)).norm() +
                               (pose.R_base - T.block<3, 3>(0, 0)).norm());
    const Mat6 J = omni_jacobian(p, q);
    worst_j = std::max(worst_j, (J - fd_jacobian(q)).cwiseAbs().maxCoeff());
    worst_b54 = std::max(
        worst_b54, (J - corrected::eqB54(q, kL1, kL2)).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst_fk, kExact);
  EXPECT_LE(worst_j, kFdTol);
  EXPECT_LE(worst_b54, kExact);
}


}  // namespace
}  // namespace vmh
