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
#include "tests/controller/errata_support.h"
#include "tests/controller/thesis_equations.h"
#include "tests/support/openhaptics_reference.h"

namespace vmh {
namespace {

using namespace errata;  // NOLINT: the shared truths and corrected forms

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
