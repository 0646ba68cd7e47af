// Errata of the seed thesis (Wickham 2010, eq. 2.1 and Appendix B), each shown
// with numbers, and the parts of Appendix B that the seed gets right.
//
// The printed equations come from tests/controller/thesis_equations.h, which
// transcribes them as printed. Each erratum test shows two things on random
// configurations (fixed seeds):
//   1. the printed form disagrees with an independent truth;
//   2. the corrected form (written here, in namespace `corrected`) agrees.
// The independent truths never reuse a printed equation:
//   - the Table B.1 chain, each link composed from elementary Eigen
//     transforms RotX(alpha) TransX(a) RotZ(theta) TransZ(d) (Craig's
//     definition of the modified-DH link, not eq. 2.1 typed out);
//   - central finite differences of that chain (Jacobian);
//   - the OpenHaptics closed form of docs/sources.md §4 (frame mapping);
//   - determinants and orthogonality (what any rotation must satisfy).
// docs/errata.md lists each erratum with the name of the test that shows it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"
#include "tests/controller/thesis_equations.h"
#include "tests/support/openhaptics_reference.h"

namespace vmh {
namespace {

namespace th = vmh::thesis;

using Mat4 = Eigen::Matrix4d;
using Vec4 = Eigen::Vector4d;
using Angles = th::Angles;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
constexpr int kSamples = 500;

// lengths in metres; L0 is non-zero so that every L0 term is exercised
constexpr double kL0 = 0.05;
constexpr double kL1 = 0.13335;
constexpr double kL2 = 0.13335;

// identities that hold to rounding (values of order 1 or 0.3 m)
constexpr double kExact = 1e-12;
// central finite differences, step kFdStep: truncation ~h^2, rounding ~eps/h
constexpr double kFdStep = 1e-6;
constexpr double kFdTol = 1e-8;
// angles out of atan2 (rounding grows near the singular directions)
constexpr double kAngle = 1e-9;
// a printed form "disagrees" when its worst error over the samples exceeds
// this (the errors found are of order 0.1-2, far above any rounding)
constexpr double kWrong = 1e-2;

// -- sampling --

class Sampler {
 public:
  explicit Sampler(unsigned seed) : rng_(seed) {}
  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  Angles angles() {
    Angles q;
    for (int i = 0; i < 6; ++i) q[i] = uniform(-kPi, kPi);
    return q;
  }

 private:
  std::mt19937 rng_;
};

// a NaN or infinity counts as a disagreement
bool close(double a, double b, double tol) { return std::abs(a - b) <= tol; }

double wrap(double a) { return std::remainder(a, 2.0 * kPi); }

// -- independent truth: the Table B.1 chain from elementary transforms --

Mat4 elementary_link(double a_prev, double alpha_prev, double d, double theta) {
  const Eigen::Affine3d T =
      Eigen::AngleAxisd(alpha_prev, Eigen::Vector3d::UnitX()) *
      Eigen::Translation3d(a_prev, 0.0, 0.0) *
      Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()) *
      Eigen::Translation3d(0.0, 0.0, d);
  return T.matrix();
}

// link i (1-based, as in Table B.1) at joint angle theta_i
Mat4 table_link(int i, double theta, double L0 = kL0) {
  th::TableB1Row rows[6];
  th::table_b1(L0, kL1, kL2, rows);
  const th::TableB1Row& r = rows[i - 1];
  return elementary_link(r.a_prev, r.alpha_prev_deg * kDeg, r.d,
                         theta + r.theta_offset_deg * kDeg);
}

// ^{first-1}_{last} T: product of Table B.1 links first..last (1-based)
Mat4 table_chain(const Angles& q, int first, int last, double L0 = kL0) {
  Mat4 T = Mat4::Identity();
  for (int i = first; i <= last; ++i) T = T * table_link(i, q[i - 1], L0);
  return T;
}

// geometric Jacobian of the wrist centre by central differences of the chain:
// linear rows from dP/dq, angular rows from (dR/dq) R^T = [w]x
th::Mat6 fd_jacobian(const Angles& q) {
  th::Mat6 J;
  const Mat4 T0 = table_chain(q, 1, 6);
  for (int j = 0; j < 6; ++j) {
    Angles qp = q, qm = q;
    qp[j] += kFdStep;
    qm[j] -= kFdStep;
    const Mat4 Tp = table_chain(qp, 1, 6), Tm = table_chain(qm, 1, 6);
    const Mat4 dT = (Tp - Tm) / (2.0 * kFdStep);
    J.block<3, 1>(0, j) = dT.block<3, 1>(0, 3);
    const Mat3 W = dT.block<3, 3>(0, 0) * T0.block<3, 3>(0, 0).transpose();
    J.block<3, 1>(3, j) =
        0.5 * Vec3(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
  }
  return J;
}

Mat3 rot_x(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
}

// Z'Y'X' Euler rotation RotZ(a) RotY(b) RotX(c), from Eigen's axis-angles
Mat3 zyx(double a, double b, double c) {
  return (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(b, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(c, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// ---------------------------------------------------------------------------
// The corrected forms, written for these tests.
namespace corrected {

// eq. 2.1 with Craig's (3,4) entry cos(alpha) d
Mat4 eq2_1(double a_prev, double alpha_prev, double d, double theta) {
  Mat4 T = th::eq2_1(a_prev, alpha_prev, d, theta);
  T(2, 3) = std::cos(alpha_prev) * d;
  return T;
}

// B.4 with -L2 in the second row (as eq. B.16 has it)
Mat4 eqB4(double th4, double L2) {
  Mat4 T = th::eqB4(th4, L2);
  T(1, 3) = -L2;
  T(2, 3) = 0.0;
  return T;
}

// B.5 from Table B.1 row 5: RotX(-90) RotZ(theta5 - 90)
Mat4 eqB5(double th5) {
  const double c = std::cos(th5), s = std::sin(th5);
  Mat4 T;
  T << s, c, 0, 0,  //
      0, 0, 1, 0,   //
      c, -s, 0, 0,  //
      0, 0, 0, 1;
  return T;
}

// B.6 with the sign of its second row flipped
Mat4 eqB6(double th6) {
  Mat4 T = th::eqB6(th6);
  T(1, 2) = 1.0;
  return T;
}

// B.8 with (3,2) = c2 c3 - s2 s3
Mat4 eqB8(double th1, double th2, double th3, double L0, double L1) {
  Mat4 T = th::eqB8(th1, th2, th3, L0, L1);
  T(2, 1) = std::cos(th2) * std::cos(th3) - std::sin(th2) * std::sin(th3);
  return T;
}

// B.14: the entries that are misprinted, as R_03 (B.11) times R_36 (B.12).
// With (a, b, c) the first and (d, e, f) the second column of B.12:
//   r11 = c1 (c23 a - s23 b) + s1 c     r12 = c1 (c23 d - s23 e) + s1 f
//   r21 = s1 (c23 a - s23 b) - c1 c     r22 = s1 (c23 d - s23 e) - c1 f
//   r31 = s23 a + c23 b (as printed)     r32 = s23 d + c23 e
th::EqB14 eqB14(const Angles& q, double L0, double L1, double L2) {
  th::EqB14 e = th::eqB14(q, L0, L1, L2);
  const double c1 = std::cos(q[0]), s1 = std::sin(q[0]);
  const double c23 = std::cos(q[1] + q[2]), s23 = std::sin(q[1] + q[2]);
  const double c4 = std::cos(q[3]), s4 = std::sin(q[3]);
  const double c5 = std::cos(q[4]), s5 = std::sin(q[4]);
  const double c6 = std::cos(q[5]), s6 = std::sin(q[5]);
  const double a = -c4 * s5 * s6 + s4 * c6, b = c5 * s6,
               c = -s4 * s5 * s6 - c4 * c6;
  const double d = -c4 * s5 * c6 - s4 * s6, ee = c5 * c6,
               f = -s4 * s5 * c6 + c4 * s6;
  e.r11 = c1 * (c23 * a - s23 * b) + s1 * c;
  e.r21 = s1 * (c23 * a - s23 * b) - c1 * c;
  e.r12 = c1 * (c23 * d - s23 * ee) + s1 * f;
  e.r22 = s1 * (c23 * d - s23 * ee) - c1 * f;
  e.r32 = s23 * d + c23 * ee;
  return e;
}

// B.13 with the first row r11 r12 r13
Mat4 eqB13(const th::EqB14& e) {
  Mat4 T = th::eqB13(e);
  T(0, 1) = e.r12;
  T(0, 2) = e.r13;
  return T;
}

// B.19, second row s1 c2 f1 - s1 s2 f2 - c1 f3
Vec3 eqB19_lhs(double th1, double th2, const th::EqB18& f, double L0) {
  Vec3 p = th::eqB19_lhs(th1, th2, f, L0);
  p.y() = std::sin(th1) * std::cos(th2) * f.f1 -
          std::sin(th1) * std::sin(th2) * f.f2 - std::cos(th1) * f.f3;
  return p;
}

// B.36 radicand as printed but with "-L0^2 + L2^2" read as
// "-2 r L0^2 + 2 r L2^2"
double eqB36_radicand(double r, double z, double L0, double L1, double L2) {
  const double L0s = L0 * L0, L1s = L1 * L1, L2s = L2 * L2;
  return 2.0 * L1s * L2s - 4.0 * L0 * z * L1s - r * r + 2.0 * r * L1s -
         2.0 * r * L0s + 2.0 * r * L2s - 4.0 * L0s * z * z +
         4.0 * L0s * L0 * z + 2.0 * L1s * L0s - 4.0 * L0 * z * L2s +
         4.0 * r * L0 * z - L1s * L1s - L0s * L0s - L2s * L2s + 2.0 * L0s * L2s;
}

double eqB36(double r, double z, double L0, double L1, double L2, double sign) {
  const double D = r - 2.0 * L0 * z - L1 * L1 + L0 * L0 - L2 * L2;
  return (2.0 * L1 * L2 + sign * std::sqrt(eqB36_radicand(r, z, L0, L1, L2))) /
         D;
}

// B.40 with the numerator L1 + s3 L2 (radicand and denominator as printed)
double eqB40(double th3, double z, double L0, double L1, double L2,
             double sign) {
  const double s3 = std::sin(th3), c3 = std::cos(th3);
  const double rad = L1 * L1 + 2.0 * L1 * s3 * L2 + s3 * s3 * L2 * L2 - z * z +
                     2.0 * z * L0 + L2 * L2 * c3 * c3 - L0 * L0;
  return (L1 + s3 * L2 + sign * std::sqrt(rad)) / (z - L2 * c3 - L0);
}

// B.43 with + s2 L2 c3
double eqB43(double th2, double th3, double L1, double L2) {
  return std::cos(th2) * (std::sin(th3) * L2 + L1) +
         std::sin(th2) * L2 * std::cos(th3);
}

// B.49 with row 2 = (sa cb, sa sb sg + ca cg, sa sb cg - ca sg)
Mat3 eqB49(double al, double be, double ga) {
  Mat3 R = th::eqB49(al, be, ga);
  const double ca = std::cos(al), sa = std::sin(al);
  const double sb = std::sin(be);
  const double cg = std::cos(ga), sg = std::sin(ga);
  R(1, 1) = sa * sb * sg + ca * cg;
  R(1, 2) = sa * sb * cg - ca * sg;
  return R;
}

// B.51 with r33 squared
double eqB51(const Mat3& R) {
  return -std::atan2(-R(2, 0),
                     std::sqrt(R(2, 1) * R(2, 1) + R(2, 2) * R(2, 2)));
}

// B.52 agreeing with its own label theta4 = -alpha
double eqB52(const Mat3& R, double beta) {
  const double cb = std::cos(beta);
  return -std::atan2(R(1, 0) / cb, R(0, 0) / cb);
}

// B.54 with j11 = -s1 (...) and j45 = -c1 s4 c23 + s1 c4
th::Mat6 eqB54(const Angles& q, double L1, double L2) {
  th::Mat6 J = th::eqB54(q, L1, L2);
  J(0, 0) = -J(0, 0);
  const double c1 = std::cos(q[0]), s1 = std::sin(q[0]);
  const double c2 = std::cos(q[1]), s2 = std::sin(q[1]);
  const double c3 = std::cos(q[2]), s3 = std::sin(q[2]);
  const double c4 = std::cos(q[3]), s4 = std::sin(q[3]);
  J(3, 4) = -c1 * s4 * c2 * c3 + c1 * s4 * s2 * s3 + s1 * c4;
  return J;
}

}  // namespace corrected

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

// ===========================================================================
// Errata.

// Eq. 2.1: the (3,4) entry is printed sin(alpha) d; Craig's link
// RotX(alpha) TransX(a) RotZ(theta) TransZ(d) has cos(alpha) d there. B.1
// (alpha0 = 0, d1 = L0 != 0) shows it: printed eq. 2.1 puts 0 where B.1 and
// the link have L0.
TEST(Errata, Eq2Dot1ThirdRowOffsetIsCosAlphaTimesD) {
  Sampler s(201);
  double worst_printed = 0, worst_corrected = 0;
  for (int k = 0; k < kSamples; ++k) {
    const double a = s.uniform(-0.2, 0.2), al = s.uniform(-kPi, kPi),
                 d = s.uniform(-0.2, 0.2), t = s.uniform(-kPi, kPi);
    const Mat4 truth = elementary_link(a, al, d, t);
    worst_printed =
        std::max(worst_printed, (th::eq2_1(a, al, d, t) - truth).norm());
    worst_corrected = std::max(worst_corrected,
                               (corrected::eq2_1(a, al, d, t) - truth).norm());
  }
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_corrected, kExact);

  // Table B.1 row 1 with L0 = 0.05: B.1 has L0 at (3,4), printed eq. 2.1 has 0
  const double th1 = 0.3;
  EXPECT_NEAR(th::eqB1(th1, kL0)(2, 3), kL0, kExact);
  EXPECT_NEAR(th::eq2_1(0.0, 0.0, kL0, th1)(2, 3), 0.0, kExact);
  EXPECT_NEAR(corrected::eq2_1(0.0, 0.0, kL0, th1)(2, 3), kL0, kExact);
  EXPECT_LE((corrected::eq2_1(0.0, 0.0, kL0, th1) - th::eqB1(th1, kL0)).norm(),
            kExact);
}

// Eq. B.4: -L2 is printed in the third row; it belongs in the second
// (-sin(90) d4 of eq. 2.1, and eq. B.16 uses (0, -L2, 0)). As printed, the
// wrist centre sits on the elbow axis z3, so the elbow angle theta3 no longer
// moves it, and the chain B.1 B.2 B.3 B.4 misses the B.14 position.
TEST(Errata, EqB4OffsetBelongsInSecondRow) {
  Sampler s(202);
  double worst_printed = 0, worst_corrected = 0;
  double worst_pos_printed = 0, worst_pos_corrected = 0;
  double largest_dp_dth3_printed = 0, smallest_dp_dth3_corrected = 1e9;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Mat4 truth = table_link(4, q[3]);
    worst_printed =
        std::max(worst_printed, (th::eqB4(q[3], kL2) - truth).norm());
    worst_corrected =
        std::max(worst_corrected, (corrected::eqB4(q[3], kL2) - truth).norm());

    // wrist centre from the printed links B.1-B.4 against B.14
    auto wrist = [](const Angles& a, bool use_printed) {
      const Mat4 T34 =
          use_printed ? th::eqB4(a[3], kL2) : corrected::eqB4(a[3], kL2);
      return Vec3(
          (th::eqB1(a[0], kL0) * th::eqB2(a[1]) * th::eqB3(a[2], kL1) * T34)
              .block<3, 1>(0, 3));
    };
    const th::EqB14 e = th::eqB14(q, kL0, kL1, kL2);
    const Vec3 p14(e.Px, e.Py, e.Pz);
    worst_pos_printed =
        std::max(worst_pos_printed, (wrist(q, true) - p14).norm());
    worst_pos_corrected =
        std::max(worst_pos_corrected, (wrist(q, false) - p14).norm());

    // finite check: d(wrist)/d(theta3), which must have length L2 (the
    // forearm turns about the elbow axis)
    Angles qp = q, qm = q;
    qp[2] += kFdStep;
    qm[2] -= kFdStep;
    const double dp_printed =
        ((wrist(qp, true) - wrist(qm, true)) / (2.0 * kFdStep)).norm();
    const double dp_corrected =
        ((wrist(qp, false) - wrist(qm, false)) / (2.0 * kFdStep)).norm();
    largest_dp_dth3_printed = std::max(largest_dp_dth3_printed, dp_printed);
    smallest_dp_dth3_corrected =
        std::min(smallest_dp_dth3_corrected, dp_corrected);
    EXPECT_NEAR(dp_corrected, kL2, kFdTol);
  }
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_corrected, kExact);
  EXPECT_GT(worst_pos_printed, kWrong);
  EXPECT_LE(worst_pos_corrected, kExact);
  EXPECT_LE(largest_dp_dth3_printed, kFdTol);  // the elbow does nothing
  EXPECT_GE(smallest_dp_dth3_corrected, kL2 - kFdTol);
  // B.16, the IK's own starting point, is the corrected column
  EXPECT_LE((th::eqB16(kL2) - corrected::eqB4(0.7, kL2).col(3)).norm(), kExact);
}

// Eq. B.5 is printed as RotX(+90) RotZ(90 deg - theta5); Table B.1 row 5
// gives RotX(-90) RotZ(theta5 - 90 deg). Only the table's link reproduces
// B.12 together with links 4 and 6.
TEST(Errata, EqB5DisagreesWithTableRow5) {
  Sampler s(203);
  double worst_printed = 0, worst_corrected = 0, worst_other_reading = 0;
  double worst_b12_printed = 0, worst_b12_corrected = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Mat4 truth = table_link(5, q[4]);
    const Mat4 printed = th::eqB5(q[4]);
    worst_printed = std::max(worst_printed, (printed - truth).norm());
    worst_corrected =
        std::max(worst_corrected, (corrected::eqB5(q[4]) - truth).norm());
    // what the printed matrix is
    worst_other_reading = std::max(
        worst_other_reading,
        (printed - elementary_link(0.0, kPi / 2, 0.0, kPi / 2 - q[4])).norm());
    const Mat4 b12 = th::eqB12(q[3], q[4], q[5], kL2);
    worst_b12_printed = std::max(
        worst_b12_printed,
        (table_link(4, q[3]) * printed * table_link(6, q[5]) - b12).norm());
    worst_b12_corrected = std::max(
        worst_b12_corrected,
        (table_link(4, q[3]) * corrected::eqB5(q[4]) * table_link(6, q[5]) -
         b12)
            .norm());
  }
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_corrected, kExact);
  EXPECT_LE(worst_other_reading, kExact);
  EXPECT_GT(worst_b12_printed, kWrong);
  EXPECT_LE(worst_b12_corrected, kExact);
}

// Eq. B.6: the printed rotation has determinant -1 (a reflection); flipping
// the sign of its second row gives Table B.1 row 6 (det +1).
TEST(Errata, EqB6IsAReflection) {
  Sampler s(204);
  double worst_det_printed = 0, worst_det_corrected = 0;
  double worst_printed = 0, worst_corrected = 0;
  for (int k = 0; k < kSamples; ++k) {
    const double th6 = s.uniform(-kPi, kPi);
    const Mat4 truth = table_link(6, th6);
    worst_det_printed =
        std::max(worst_det_printed,
                 std::abs(th::eqB6(th6).block<3, 3>(0, 0).determinant() + 1.0));
    worst_det_corrected = std::max(
        worst_det_corrected,
        std::abs(corrected::eqB6(th6).block<3, 3>(0, 0).determinant() - 1.0));
    worst_printed = std::max(worst_printed, (th::eqB6(th6) - truth).norm());
    worst_corrected =
        std::max(worst_corrected, (corrected::eqB6(th6) - truth).norm());
  }
  EXPECT_LE(worst_det_printed, kExact);  // det is -1 everywhere
  EXPECT_LE(worst_det_corrected, kExact);
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_corrected, kExact);
}

// Eq. B.8: the (3,2) entry is printed c2 c3 + s2 s3 (= cos(theta2 - theta3));
// the product B.1 B.2 B.3 and B.11 have c2 c3 - s2 s3 (= c_{2+3}).
TEST(Errata, EqB8Entry32Sign) {
  Sampler s(205);
  double worst_printed = 0, worst_corrected = 0, worst_other_entries = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Mat4 truth = table_chain(q, 1, 3);
    Mat4 diff = th::eqB8(q[0], q[1], q[2], kL0, kL1) - truth;
    worst_printed = std::max(worst_printed, std::abs(diff(2, 1)));
    diff(2, 1) = 0.0;
    worst_other_entries = std::max(worst_other_entries, diff.norm());
    worst_corrected =
        std::max(worst_corrected,
                 (corrected::eqB8(q[0], q[1], q[2], kL0, kL1) - truth).norm());
  }
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_other_entries, kExact);
  EXPECT_LE(worst_corrected, kExact);
}

// Eq. B.14: r11, r21, r12, r22 and r32 disagree with the Table B.1 product
// (and with B.11 * B.12, from which they are meant to come); the printed
// rotation is not even orthogonal. r31, the third column and P are right
// (see SeedConsistent). The corrected entries are R_03 (B.11) times R_36
// (B.12), and B.13 assembled with them (first row r11 r12 r13) is the table
// product.
TEST(Errata, EqB14FirstTwoColumnsDisagreeWithTableProduct) {
  Sampler s(206);
  double worst[9] = {0};
  double worst_corrected = 0, worst_orthogonality = 0, worst_b13 = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Mat3 R = table_chain(q, 1, 6).block<3, 3>(0, 0);
    const th::EqB14 e = th::eqB14(q, kL0, kL1, kL2);
    const double printed[9] = {e.r11, e.r12, e.r13, e.r21, e.r22,
                               e.r23, e.r31, e.r32, e.r33};
    Mat3 Rp;
    for (int i = 0; i < 9; ++i) {
      Rp(i / 3, i % 3) = printed[i];
      worst[i] = std::max(worst[i], std::abs(printed[i] - R(i / 3, i % 3)));
    }
    worst_orthogonality = std::max(
        worst_orthogonality, (Rp.transpose() * Rp - Mat3::Identity()).norm());
    const th::EqB14 c = corrected::eqB14(q, kL0, kL1, kL2);
    const Mat4 Tc = corrected::eqB13(c);
    worst_b13 = std::max(worst_b13, (Tc - table_chain(q, 1, 6)).norm());
    worst_corrected =
        std::max(worst_corrected, (Tc.block<3, 3>(0, 0) - R).norm());
  }
  // printed order: r11 r12 r13 / r21 r22 r23 / r31 r32 r33
  const bool misprinted[9] = {true,  true,  false, true, true,
                              false, false, true,  false};
  for (int i = 0; i < 9; ++i) {
    if (misprinted[i]) {
      EXPECT_GT(worst[i], kWrong) << "r" << i / 3 + 1 << i % 3 + 1;
    } else {
      EXPECT_LE(worst[i], kExact) << "r" << i / 3 + 1 << i % 3 + 1;
    }
  }
  EXPECT_GT(worst_orthogonality, kWrong);
  EXPECT_LE(worst_corrected, kExact);
  EXPECT_LE(worst_b13, kExact);
}

// Eq. B.13: the printed first row "r11 r22 r33" puts r22 and r33 where r12
// and r13 belong; so assembled, the matrix is not the FK.
TEST(Errata, EqB13FirstRowIndices) {
  Sampler s(207);
  double worst_printed = 0, worst_corrected = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Mat4 truth = table_chain(q, 1, 6);
    const th::EqB14 c = corrected::eqB14(q, kL0, kL1, kL2);
    worst_printed = std::max(worst_printed, (th::eqB13(c) - truth).norm());
    worst_corrected =
        std::max(worst_corrected, (corrected::eqB13(c) - truth).norm());
  }
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_corrected, kExact);
}

// Eq. B.19: the second row of the left-hand side, "s1 c2 - s1 s2 f2 - c1 f3",
// lacks f1 in its first term; with s1 c2 f1 it is P_y.
TEST(Errata, EqB19SecondRowMissesF1) {
  Sampler s(208);
  double worst_printed = 0, worst_corrected = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Vec3 p = table_chain(q, 1, 6).block<3, 1>(0, 3);
    const th::EqB18 f = th::eqB18(q[2], kL1, kL2);
    worst_printed =
        std::max(worst_printed, (th::eqB19_lhs(q[0], q[1], f, kL0) - p).norm());
    worst_corrected = std::max(
        worst_corrected, (corrected::eqB19_lhs(q[0], q[1], f, kL0) - p).norm());
  }
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_corrected, kExact);
}

// Eq. B.25, r = 2 L1 (k1 c2 + k2 s2) + k3, is Craig's general relation with
// a1 taken as L1; for the Omni a1 = 0 (Table B.1 row 2), and the squared
// distance r = x^2 + y^2 + z^2 is B.31 instead. B.25 misses r.
TEST(Errata, EqB25IsNotTheSquaredDistance) {
  Sampler s(209);
  double worst_printed = 0, worst_b31 = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Vec3 p = table_chain(q, 1, 6).block<3, 1>(0, 3);
    const double r = th::eqB21(p);
    const th::EqB18 f = th::eqB18(q[2], kL1, kL2);
    worst_printed =
        std::max(worst_printed, std::abs(th::eqB25(q[1], f, kL0, kL1) - r));
    worst_b31 = std::max(worst_b31,
                         std::abs(th::eqB32(q[2], p.z(), kL0, kL1, kL2) - r));
  }
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_b31, kExact);
}

// Eq. B.36: the radicand's "- L0^2 + L2^2" should read "- 2 r L0^2 + 2 r L2^2"
// (the two terms are not even of the right dimension). With them the radicand
// equals 4 L1^2 L2^2 - D^2 (D the printed denominator), and one root gives
// theta_3; as printed, neither root does. Run in mm (the thesis's units).
TEST(Errata, EqB36RadicandLacksTwoFactorsOfR) {
  Sampler s(210);
  const double L0 = 1e3 * kL0, L1 = 1e3 * kL1, L2 = 1e3 * kL2;
  int printed_hits = 0, corrected_hits = 0;
  double worst_radicand = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Vec3 p = 1e3 * table_chain(q, 1, 6).block<3, 1>(0, 3);
    const double r = th::eqB21(p), z = p.z();
    const double D = r - 2.0 * L0 * z - L1 * L1 + L0 * L0 - L2 * L2;
    const double exact = 4.0 * L1 * L1 * L2 * L2 - D * D;
    worst_radicand =
        std::max(worst_radicand,
                 std::abs(corrected::eqB36_radicand(r, z, L0, L1, L2) - exact) /
                     (L1 * L1 * L2 * L2));
    bool printed_ok = false, corrected_ok = false;
    for (double sign : {1.0, -1.0}) {
      printed_ok =
          printed_ok ||
          close(wrap(th::eqB37(th::eqB36(r, z, L0, L1, L2, sign)) - q[2]), 0.0,
                1e-6);
      corrected_ok =
          corrected_ok ||
          close(
              wrap(th::eqB37(corrected::eqB36(r, z, L0, L1, L2, sign)) - q[2]),
              0.0, 1e-6);
    }
    printed_hits += printed_ok ? 1 : 0;
    corrected_hits += corrected_ok ? 1 : 0;
  }
  EXPECT_LE(worst_radicand, 1e-9);  // relative to L1^2 L2^2
  EXPECT_EQ(printed_hits, 0);
  EXPECT_EQ(corrected_hits, kSamples);
}

// Eq. B.40: the numerator begins "L1 + s3 + L2"; the radicand (the square of
// L1 + s3 L2 plus ...) shows it is L1 + s3 L2. Given the true theta_3 and z,
// one corrected root is theta_2; neither printed root is.
TEST(Errata, EqB40NumeratorIsL1PlusS3TimesL2) {
  Sampler s(211);
  int printed_hits = 0, corrected_hits = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const double z = table_chain(q, 1, 6)(2, 3);
    bool printed_ok = false, corrected_ok = false;
    for (double sign : {1.0, -1.0}) {
      printed_ok =
          printed_ok ||
          close(wrap(th::eqB37(th::eqB40(q[2], z, kL0, kL1, kL2, sign)) - q[1]),
                0.0, 1e-6);
      corrected_ok =
          corrected_ok ||
          close(wrap(th::eqB37(corrected::eqB40(q[2], z, kL0, kL1, kL2, sign)) -
                     q[1]),
                0.0, 1e-6);
    }
    printed_hits += printed_ok ? 1 : 0;
    corrected_hits += corrected_ok ? 1 : 0;
  }
  EXPECT_EQ(printed_hits, 0);
  EXPECT_EQ(corrected_hits, kSamples);
}

// Eq. B.43: g1 is printed c2 (s3 L2 + L1) - s2 L2 c3; B.20 with f2 = -c3 L2
// (B.18) gives + s2 L2 c3, and P_x = c1 g1 needs the plus. With the printed
// g1, B.48 returns theta_1 + 180 deg wherever the two g1 differ in sign.
TEST(Errata, EqB43SignOfS2C3Term) {
  Sampler s(220);
  double worst_printed = 0, worst_corrected = 0, worst_theta1_corrected = 0;
  int theta1_flipped = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const Vec3 p = table_chain(q, 1, 6).block<3, 1>(0, 3);
    // truth: the signed horizontal reach, P = (c1 g1, s1 g1, .)
    const double g1 = std::cos(q[0]) * p.x() + std::sin(q[0]) * p.y();
    const double printed = th::eqB43(q[1], q[2], kL1, kL2);
    const double fixed = corrected::eqB43(q[1], q[2], kL1, kL2);
    worst_printed = std::max(worst_printed, std::abs(printed - g1));
    worst_corrected = std::max(worst_corrected, std::abs(fixed - g1));
    worst_theta1_corrected =
        std::max(worst_theta1_corrected,
                 std::abs(wrap(th::eqB48(p.x(), p.y(), fixed) - q[0])));
    theta1_flipped +=
        close(std::abs(wrap(th::eqB48(p.x(), p.y(), printed) - q[0])), kPi,
              1e-9)
            ? 1
            : 0;
  }
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_corrected, kExact);
  EXPECT_LE(worst_theta1_corrected, kAngle);
  EXPECT_GT(theta1_flipped, kSamples / 20);
}

// Eq. B.49: two signs of the second row are wrong; the printed matrix is not
// orthogonal. Corrected, it is RotZ(a) RotY(b) RotX(c).
TEST(Errata, EqB49SecondRowSigns) {
  Sampler s(212);
  double worst_orthogonality = 0, worst_printed = 0, worst_corrected = 0;
  for (int k = 0; k < kSamples; ++k) {
    const double a = s.uniform(-kPi, kPi), b = s.uniform(-kPi, kPi),
                 c = s.uniform(-kPi, kPi);
    const Mat3 printed = th::eqB49(a, b, c);
    worst_orthogonality =
        std::max(worst_orthogonality,
                 (printed * printed.transpose() - Mat3::Identity()).norm());
    worst_printed = std::max(worst_printed, (printed - zyx(a, b, c)).norm());
    worst_corrected = std::max(
        worst_corrected, (corrected::eqB49(a, b, c) - zyx(a, b, c)).norm());
  }
  EXPECT_GT(worst_orthogonality, kWrong);
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_corrected, kExact);
}

// Eq. B.51: sqrt(r32^2 + r33) lacks a square. On a Z'Y'X' matrix with
// |beta| < 90 deg the corrected Atan2 returns beta; the printed one does not
// (and is NaN where r33 < -r32^2).
TEST(Errata, EqB51RadicandMissesSquare) {
  Sampler s(213);
  int printed_hits = 0;
  double worst_corrected = 0;
  for (int k = 0; k < kSamples; ++k) {
    const double a = s.uniform(-kPi, kPi), b = s.uniform(-1.5, 1.5),
                 c = s.uniform(-kPi, kPi);
    const Mat3 R = zyx(a, b, c);
    printed_hits += close(th::eqB51_beta(R), b, 1e-6) ? 1 : 0;
    worst_corrected =
        std::max(worst_corrected, std::abs(-corrected::eqB51(R) - b));
  }
  // the printed form is right only where r33 = r33^2 (c = 0 or |b| = 90 deg)
  EXPECT_LE(printed_hits, kSamples / 100);
  EXPECT_LE(worst_corrected, kExact);
}

// Eq. B.52 reads "theta4 = -alpha = -Atan2(-r21/cb, r11/cb)", but on a
// Z'Y'X' matrix that Atan2 is -alpha, so the formula returns +alpha: it
// contradicts its own label. -Atan2(r21/cb, r11/cb) is -alpha.
TEST(Errata, EqB52FormulaContradictsItsLabel) {
  Sampler s(214);
  double worst_plus_alpha = 0, worst_label = 0, worst_corrected = 0;
  for (int k = 0; k < kSamples; ++k) {
    const double a = s.uniform(-kPi, kPi), b = s.uniform(-1.5, 1.5),
                 c = s.uniform(-kPi, kPi);
    const Mat3 R = zyx(a, b, c);
    const double printed = th::eqB52(R, b);
    worst_plus_alpha = std::max(worst_plus_alpha, std::abs(wrap(printed - a)));
    worst_label = std::max(worst_label, std::abs(wrap(printed + a)));
    worst_corrected =
        std::max(worst_corrected, std::abs(wrap(corrected::eqB52(R, b) + a)));
  }
  EXPECT_LE(worst_plus_alpha, kExact);
  EXPECT_GT(worst_label, kWrong);
  EXPECT_LE(worst_corrected, kExact);
}

// Eq. B.50-B.53 end to end, under one reading of the ambiguous B.50: the
// Z'Y'X' matrix is M = RotX(90) R_36 [z6 x6 y6] (frame 3 turned by RotX(90),
// the columns of frame 6 reordered). Up to negating both factors, this is the
// one reading (among signed axis permutations on either side, found by
// search) under which the labels theta4 = -alpha,
// theta5 = -beta, theta6 = gamma hold. With B.51 and B.52 corrected the wrist
// angles come back for |theta5| < 90 deg; printed B.52 gives -theta4 and
// printed B.51 misses theta5.
TEST(Errata, EqB50ToB53WristAnglesUnderOneReading) {
  Sampler s(215);
  Mat3 reorder;        // R_36 * reorder = [z6 x6 y6]
  reorder << 0, 1, 0,  //
      0, 0, 1,         //
      1, 0, 0;
  double worst_reading = 0, worst_corrected = 0;
  double worst_printed_b52 = 0, worst_printed_b52_minus = 0;
  int printed_b51_hits = 0;
  for (int k = 0; k < kSamples; ++k) {
    Angles q = s.angles();
    q[4] = s.uniform(-1.5, 1.5);
    const Mat3 R36 = table_chain(q, 4, 6).block<3, 3>(0, 0);
    const Mat3 M = rot_x(kPi / 2) * R36 * reorder;
    worst_reading =
        std::max(worst_reading, (M - zyx(-q[3], -q[4], q[5])).norm());
    const double th5 = corrected::eqB51(M);
    const double beta = -th5;
    const double th4 = corrected::eqB52(M, beta);
    const double th6 = th::eqB53(M, beta);
    worst_corrected =
        std::max({worst_corrected, std::abs(wrap(th4 - q[3])),
                  std::abs(wrap(th5 - q[4])), std::abs(wrap(th6 - q[5]))});
    worst_printed_b52 =
        std::max(worst_printed_b52, std::abs(wrap(th::eqB52(M, beta) - q[3])));
    worst_printed_b52_minus = std::max(
        worst_printed_b52_minus, std::abs(wrap(th::eqB52(M, beta) + q[3])));
    printed_b51_hits += close(th::eqB51(M), q[4], 1e-6) ? 1 : 0;
  }
  EXPECT_LE(worst_reading, kExact);
  EXPECT_LE(worst_corrected, kAngle);
  EXPECT_GT(worst_printed_b52, kWrong);
  EXPECT_LE(worst_printed_b52_minus, kExact);
  EXPECT_LE(printed_b51_hits, kSamples / 100);
}

// Eq. B.54, j11: printed +s1 (c2 L1 + s23 L2); dPx/dtheta1 is -s1 (...).
TEST(Errata, EqB54J11Sign) {
  Sampler s(216);
  double worst_printed = 0, worst_negated = 0, worst_corrected = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const double fd = fd_jacobian(q)(0, 0);
    const double printed = th::eqB54(q, kL1, kL2)(0, 0);
    worst_printed = std::max(worst_printed, std::abs(printed - fd));
    worst_negated = std::max(worst_negated, std::abs(printed + fd));
    worst_corrected = std::max(
        worst_corrected, std::abs(corrected::eqB54(q, kL1, kL2)(0, 0) - fd));
  }
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_negated, kFdTol);  // exactly the negative
  EXPECT_LE(worst_corrected, kFdTol);
}

// Eq. B.54, j45 (x of the joint-5 axis z5): printed
// c1 s4 c2 c3 + c1 s4 s2 s3 + s1 c4 = c1 s4 cos(theta2 - theta3) + s1 c4;
// the axis is -s4 x3 + c4 z3, whose x is -c1 s4 c23 + s1 c4 (j55 and j65,
// its y and z, are printed right).
TEST(Errata, EqB54J45Sign) {
  Sampler s(217);
  double worst_printed = 0, worst_corrected = 0, worst_axis = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Angles q = s.angles();
    const th::Mat6 fd = fd_jacobian(q);
    worst_printed = std::max(worst_printed,
                             std::abs(th::eqB54(q, kL1, kL2)(3, 4) - fd(3, 4)));
    worst_corrected =
        std::max(worst_corrected,
                 std::abs(corrected::eqB54(q, kL1, kL2)(3, 4) - fd(3, 4)));
    // z5 read off the chain directly
    const Vec3 z5 = table_chain(q, 1, 5).block<3, 1>(0, 2);
    worst_axis =
        std::max(worst_axis,
                 (corrected::eqB54(q, kL1, kL2).block<3, 1>(3, 4) - z5).norm());
  }
  EXPECT_GT(worst_printed, kWrong);
  EXPECT_LE(worst_corrected, kFdTol);
  EXPECT_LE(worst_axis, kExact);
}

// ===========================================================================
// first derived frame mapping (docs/sources.md §4): x_HD = -y_DH, y_HD = z_DH + l2,
// z_HD = x_DH - l1 with q1 = t1 fits the OpenHaptics positions, but its
// rotation has det -1; the project's R_device_base() (x_HD = +y_DH with
// q1 = -t1) has det +1 and fits them too.
TEST(FrameMapping, ReferenceMappingIsAReflectionProjectsIsARotation) {
  OmniParams p;  // L0 = 0, as docs/sources.md §4 assumes
  const double l1 = 1e3 * p.l1_m, l2 = 1e3 * p.l2_m;
  Mat3 R_ref;
  R_ref << 0, -1, 0,  //
      0, 0, 1,        //
      1, 0, 0;
  const Vec3 origin_ref_mm(l1, 0.0, -l2);  // DH point that maps to HD (0,0,0)
  EXPECT_NEAR(R_ref.determinant(), -1.0, kExact);
  EXPECT_NEAR(R_device_base().determinant(), 1.0, kExact);
  EXPECT_LE(
      (R_device_base() * R_device_base().transpose() - Mat3::Identity()).norm(),
      kExact);

  Sampler s(301);
  double worst_ref = 0, worst_project = 0;
  double worst_det_stylus_ref = 0, worst_det_stylus_project = 0;
  for (int k = 0; k < kSamples; ++k) {
    const Joints t = s.angles();  // OpenHaptics joint angles, t3 absolute
    const Vec3 hd = testing::openhaptics_wrist_mm(t, l1, l2);

    // first derivation: q1 = t1, q2 = t2, q3 = t3 - t2
    Joints q_ref = t;
    q_ref[2] = t[2] - t[1];
    const OmniPose pose_ref = omni_fk(p, q_ref);
    const Vec3 hd_ref = R_ref * (1e3 * pose_ref.p_base_m - origin_ref_mm);
    worst_ref = std::max(worst_ref, (hd_ref - hd).norm());
    worst_det_stylus_ref =
        std::max(worst_det_stylus_ref,
                 std::abs((R_ref * pose_ref.R_base).determinant() + 1.0));

    // the project: q = device_to_dh_joints(t), then base_to_device_mm
    const OmniPose pose = omni_fk(p, device_to_dh_joints(t));
    worst_project = std::max(worst_project,
                             (base_to_device_mm(p, pose.p_base_m) - hd).norm());
    worst_det_stylus_project = std::max(
        worst_det_stylus_project,
        std::abs(base_to_device_rotation(pose.R_base).determinant() - 1.0));
  }
  EXPECT_LE(worst_ref, 1e-9);      // mm
  EXPECT_LE(worst_project, 1e-9);  // mm
  // the first derived mapping turns the stylus frame left-handed; the project's not
  EXPECT_LE(worst_det_stylus_ref, kExact);
  EXPECT_LE(worst_det_stylus_project, kExact);
}

}  // namespace
}  // namespace vmh
