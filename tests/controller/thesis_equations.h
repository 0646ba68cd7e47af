// The seed thesis's equations transcribed EXACTLY AS PRINTED, typos included.
//
// Source: Wickham, "A study of haptic interactions with an under actuated
// robot in three dimensions", MS thesis, Iowa State University, 2010:
// eq. 2.1 (chapter 2) and Appendix B (Table B.1, eq. B.1-B.54).
//
// Purpose: tests/controller/errata_test.cc compares these printed forms with
// independent truths (finite differences, the Table B.1 product, the
// OpenHaptics closed form, determinants). Nothing here is used by the
// project's code, and nothing here should be "fixed": a corrected form belongs
// in the test that shows the erratum (docs/errata.md lists them all).
//
// Conventions of this file:
//   - angles in radians; the thesis prints Table B.1 offsets in degrees.
//   - theta[0..5] is theta_1..theta_6 of the thesis (DH convention, theta_3
//     relative to theta_2). L0, L1, L2, Lt are the thesis's lengths, any unit.
//   - matrices are returned with the thesis's row/column layout: entry (i, j)
//     of the printed matrix is M(i-1, j-1).
//   - cX, sX abbreviate cos(theta_X), sin(theta_X); c23 = cos(theta_2 +
//     theta_3), as eq. B.9-B.10 define c_{2+3}, s_{2+3}.
//   - each function is named after its equation number; where the printing is
//     ambiguous (in the text transcription of the seed) a comment says so and
//     states which reading is implemented.
#ifndef VMHAPTICS_TESTS_CONTROLLER_THESIS_EQUATIONS_H_
#define VMHAPTICS_TESTS_CONTROLLER_THESIS_EQUATIONS_H_

#include <Eigen/Core>
#include <cmath>

namespace vmh {
namespace thesis {

using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Angles = Eigen::Matrix<double, 6, 1>;  // theta_1..theta_6

// ---------------------------------------------------------------------------
// Eq. 2.1: the general link transform {i-1} -> {i} from the modified (Craig)
// DH parameters a_{i-1}, alpha_{i-1}, d_i, theta_i, AS PRINTED. Its (3,4)
// entry reads sin(alpha_{i-1}) d_i (Craig's is cos(alpha_{i-1}) d_i).
// (The printed left-hand side is "^i_j T"; it means ^{i-1}_i T.)
inline Mat4 eq2_1(double a_prev, double alpha_prev, double d, double theta) {
  const double ct = std::cos(theta), st = std::sin(theta);
  const double ca = std::cos(alpha_prev), sa = std::sin(alpha_prev);
  Mat4 T;
  T << ct, -st, 0.0, a_prev,           //
      st * ca, ct * ca, -sa, -sa * d,  //
      st * sa, ct * sa, ca, sa * d,    //  <- printed sin(alpha) d
      0.0, 0.0, 0.0, 1.0;
  return T;
}

// ---------------------------------------------------------------------------
// Table B.1 as printed: a_{i-1}, alpha_{i-1} (deg), d_i, theta_i offset (deg).
// Row 5 prints theta_5 as "-90 + theta_5", row 6 "90 + theta_6".
struct TableB1Row {
  double a_prev;
  double alpha_prev_deg;
  double d;
  double theta_offset_deg;
};

// lengths of row 1 (d_1 = L0), row 3 (a_2 = L1) and row 4 (d_4 = L2)
inline void table_b1(double L0, double L1, double L2, TableB1Row rows[6]) {
  rows[0] = {0.0, 0.0, L0, 0.0};
  rows[1] = {0.0, 90.0, 0.0, 0.0};
  rows[2] = {L1, 0.0, 0.0, 0.0};
  rows[3] = {0.0, 90.0, L2, 0.0};
  rows[4] = {0.0, -90.0, 0.0, -90.0};
  rows[5] = {0.0, -90.0, 0.0, 90.0};
}

// ---------------------------------------------------------------------------
// Eq. B.1-B.7: the link transforms, as printed.

// B.1, ^0_1 T
inline Mat4 eqB1(double th1, double L0) {
  const double c = std::cos(th1), s = std::sin(th1);
  Mat4 T;
  T << c, -s, 0, 0,  //
      s, c, 0, 0,    //
      0, 0, 1, L0,   //
      0, 0, 0, 1;
  return T;
}

// B.2, ^1_2 T
inline Mat4 eqB2(double th2) {
  const double c = std::cos(th2), s = std::sin(th2);
  Mat4 T;
  T << c, -s, 0, 0,  //
      0, 0, -1, 0,   //
      s, c, 0, 0,    //
      0, 0, 0, 1;
  return T;
}

// B.3, ^2_3 T
inline Mat4 eqB3(double th3, double L1) {
  const double c = std::cos(th3), s = std::sin(th3);
  Mat4 T;
  T << c, -s, 0, L1,  //
      s, c, 0, 0,     //
      0, 0, 1, 0,     //
      0, 0, 0, 1;
  return T;
}

// B.4, ^3_4 T, as printed: -L2 in the THIRD row (eq. B.16 puts it second)
inline Mat4 eqB4(double th4, double L2) {
  const double c = std::cos(th4), s = std::sin(th4);
  Mat4 T;
  T << c, -s, 0, 0,  //
      0, 0, -1, 0,   //
      s, c, 0, -L2,  //
      0, 0, 0, 1;
  return T;
}

// B.5, ^4_5 T, as printed
inline Mat4 eqB5(double th5) {
  const double c = std::cos(th5), s = std::sin(th5);
  Mat4 T;
  T << s, -c, 0, 0,  //
      0, 0, -1, 0,   //
      c, s, 0, 0,    //
      0, 0, 0, 1;
  return T;
}

// B.6, ^5_6 T, as printed
inline Mat4 eqB6(double th6) {
  const double c = std::cos(th6), s = std::sin(th6);
  Mat4 T;
  T << -s, -c, 0, 0,  //
      0, 0, -1, 0,    //
      -c, s, 0, 0,    //
      0, 0, 0, 1;
  return T;
}

// B.7, ^6_t T: tool offset along z6 by -Lt
inline Mat4 eqB7(double Lt) {
  Mat4 T = Mat4::Identity();
  T(2, 3) = -Lt;
  return T;
}

// ---------------------------------------------------------------------------
// Eq. B.8 and B.11: ^0_3 T, as printed.

// B.8. Its (3,2) entry prints c2 c3 + s2 s3.
inline Mat4 eqB8(double th1, double th2, double th3, double L0, double L1) {
  const double c1 = std::cos(th1), s1 = std::sin(th1);
  const double c2 = std::cos(th2), s2 = std::sin(th2);
  const double c3 = std::cos(th3), s3 = std::sin(th3);
  Mat4 T;
  // clang-format off
  T << c1 * (c2 * c3 - s2 * s3), -c1 * (s2 * c3 + c2 * s3),  s1, c1 * c2 * L1,
       s1 * (c2 * c3 - s2 * s3), -s1 * (s2 * c3 + c2 * s3), -c1, s1 * c2 * L1,
       s2 * c3 + c2 * s3,         c2 * c3 + s2 * s3,          0, s2 * L1 + L0,
       0, 0, 0, 1;
  // clang-format on
  return T;
}

// B.11 (B.8 with c_{2+3}, s_{2+3})
inline Mat4 eqB11(double th1, double th2, double th3, double L0, double L1) {
  const double c1 = std::cos(th1), s1 = std::sin(th1);
  const double c2 = std::cos(th2), s2 = std::sin(th2);
  const double c23 = std::cos(th2 + th3), s23 = std::sin(th2 + th3);
  Mat4 T;
  T << c1 * c23, -c1 * s23, s1, c1 * c2 * L1,  //
      s1 * c23, -s1 * s23, -c1, s1 * c2 * L1,  //
      s23, c23, 0, s2 * L1 + L0,               //
      0, 0, 0, 1;
  return T;
}

// ---------------------------------------------------------------------------
// Eq. B.12: ^3_6 T = ^3_4 T ^4_5 T ^5_6 T, as printed (the closed form; it is
// not the product of the printed B.4-B.6).
inline Mat4 eqB12(double th4, double th5, double th6, double L2) {
  const double c4 = std::cos(th4), s4 = std::sin(th4);
  const double c5 = std::cos(th5), s5 = std::sin(th5);
  const double c6 = std::cos(th6), s6 = std::sin(th6);
  Mat4 T;
  T << -c4 * s5 * s6 + s4 * c6, -c4 * s5 * c6 - s4 * s6, c4 * c5, 0,  //
      c5 * s6, c5 * c6, s5, -L2,                                      //
      -s4 * s5 * s6 - c4 * c6, -s4 * s5 * c6 + c4 * s6, s4 * c5, 0,   //
      0, 0, 0, 1;
  return T;
}

// ---------------------------------------------------------------------------
// Eq. B.14: the entries of ^0_6 T, as printed. (As printed, r11, r21, r12,
// r22 and r32 are not those of B.11 * B.12; see docs/errata.md.)
struct EqB14 {
  double r11, r12, r13;
  double r21, r22, r23;
  double r31, r32, r33;
  double Px, Py, Pz;
};

inline EqB14 eqB14(const Angles& th, double L0, double L1, double L2) {
  const double c1 = std::cos(th[0]), s1 = std::sin(th[0]);
  const double c2 = std::cos(th[1]), s2 = std::sin(th[1]);
  const double c23 = std::cos(th[1] + th[2]), s23 = std::sin(th[1] + th[2]);
  const double c4 = std::cos(th[3]), s4 = std::sin(th[3]);
  const double c5 = std::cos(th[4]), s5 = std::sin(th[4]);
  const double c6 = std::cos(th[5]), s6 = std::sin(th[5]);
  EqB14 e{};
  e.r11 = c1 * (-c23 * (-c4 * s5 * s6 + s4 * c6) - s23 * c5 * s6) +
          s1 * (-s4 * s5 * s6 - c4 * c6);
  e.r21 = s1 * (-c23 * (-c4 * s5 * s6 + s4 * c6) - s23 * c5 * s6) +
          c1 * (-s4 * s5 * s6 - c4 * c6);
  e.r31 = s23 * (-c4 * s5 * s6 + s4 * c6) + c23 * c5 * s6;
  e.r12 = c1 * (-c23 * (-c4 * s5 * c6 + s4 * s6) - s23 * c5 * c6) +
          s1 * (-s4 * s5 * c6 - c4 * s6);
  e.r22 = s1 * (-c23 * (-c4 * s5 * c6 + s4 * s6) - s23 * c5 * c6) +
          c1 * (-s4 * s5 * c6 - c4 * s6);
  e.r32 = s23 * (-c4 * s5 * c6 + s4 * s6) + c23 * c5 * c6;
  e.r13 = c1 * (c23 * c4 * c5 - s23 * s5) + s1 * s4 * c5;
  e.r23 = s1 * (c23 * c4 * c5 - s23 * s5) - c1 * s4 * c5;
  e.r33 = s23 * c4 * c5 + c23 * s5;
  e.Px = c1 * s23 * L2 + c1 * c2 * L1;
  e.Py = s1 * s23 * L2 + s1 * c2 * L1;
  e.Pz = -c23 * L2 + s2 * L1 + L0;
  return e;
}

// Eq. B.13: ^0_6 T assembled as printed. The printed first row is
// "r11 r22 r33 Px" (a typo for r11 r12 r13); this assembles it that way.
inline Mat4 eqB13(const EqB14& e) {
  Mat4 T;
  T << e.r11, e.r22, e.r33, e.Px,  //
      e.r21, e.r22, e.r23, e.Py,   //
      e.r31, e.r32, e.r33, e.Pz,   //
      0, 0, 0, 1;
  return T;
}

// ---------------------------------------------------------------------------
// Eq. B.15-B.48: inverse kinematics of the wrist centre (Pieper), as printed.

// B.16: ^3 P_{4ORG}
inline Vec4 eqB16(double L2) { return Vec4(0.0, -L2, 0.0, 1.0); }

// B.18: f1, f2, f3
struct EqB18 {
  double f1, f2, f3;
};
inline EqB18 eqB18(double th3, double L1, double L2) {
  return {std::sin(th3) * L2 + L1, -std::cos(th3) * L2, 0.0};
}

// B.19, left-hand side, as printed. The second row reads
// "s1 c2 - s1 s2 f2 - c1 f3": f1 is missing from its first term.
inline Vec3 eqB19_lhs(double th1, double th2, const EqB18& f, double L0) {
  const double c1 = std::cos(th1), s1 = std::sin(th1);
  const double c2 = std::cos(th2), s2 = std::sin(th2);
  // clang-format off
  return Vec3(c1 * c2 * f.f1 - c1 * s2 * f.f2 + s1 * f.f3,
              s1 * c2        - s1 * s2 * f.f2 - c1 * f.f3,
              s2 * f.f1 + c2 * f.f2 + L0);
  // clang-format on
}

// B.20: g1, g2, g3
struct EqB20 {
  double g1, g2, g3;
};
inline EqB20 eqB20(double th2, const EqB18& f, double L0) {
  const double c2 = std::cos(th2), s2 = std::sin(th2);
  return {c2 * f.f1 - s2 * f.f2, -f.f3, s2 * f.f1 + c2 * f.f2 + L0};
}

// B.19, right-hand side: (c1 g1 - s1 g2, s1 g1 + c1 g2, g3)
inline Vec3 eqB19_rhs(double th1, const EqB20& g) {
  const double c1 = std::cos(th1), s1 = std::sin(th1);
  return Vec3(c1 * g.g1 - s1 * g.g2, s1 * g.g1 + c1 * g.g2, g.g3);
}

// B.42, left: (c1 g1 - s1 g2, s1 g1 - c1 g2, g3). The sign of c1 g2 differs
// from B.19; harmless for the Omni, where g2 = 0 (B.43).
inline Vec3 eqB42(double th1, const EqB20& g) {
  const double c1 = std::cos(th1), s1 = std::sin(th1);
  return Vec3(c1 * g.g1 - s1 * g.g2, s1 * g.g1 - c1 * g.g2, g.g3);
}

// B.21: r = x^2 + y^2 + z^2 (r is a squared distance throughout B.21-B.36)
inline double eqB21(const Vec3& p) { return p.squaredNorm(); }

// B.25 as printed: r = 2 L1 (k1 c2 + k2 s2) + k3, with k1..k3 of B.27
// (k1 = f1, k2 = -f2, k3 = f1^2 + f2^2 + L0^2).
inline double eqB25(double th2, const EqB18& f, double L0, double L1) {
  const double k1 = f.f1, k2 = -f.f2;
  const double k3 = f.f1 * f.f1 + f.f2 * f.f2 + L0 * L0;
  return 2.0 * L1 * (k1 * std::cos(th2) + k2 * std::sin(th2)) + k3;
}

// B.26: z = (k1 s2 - k2 c2) + L0
inline double eqB26(double th2, const EqB18& f, double L0) {
  const double k1 = f.f1, k2 = -f.f2;
  return (k1 * std::sin(th2) - k2 * std::cos(th2)) + L0;
}

// B.32: r = (s3 L2 + L1)^2 + (c3 L2)^2 - L0^2 + 2 L0 z
inline double eqB32(double th3, double z, double L0, double L1, double L2) {
  const double a = std::sin(th3) * L2 + L1, b = std::cos(th3) * L2;
  return a * a + b * b - L0 * L0 + 2.0 * L0 * z;
}

// B.36: u3 = tan(theta_3 / 2), both roots (sign = +1 or -1), as printed.
// AMBIGUOUS PRINTING: the numerator runs over two lines joined by "...", each
// drawn over the same denominator. Read here as ONE square root over the whole
// continued radicand, all over the denominator D:
//   u3 = (2 L1 L2 +- sqrt(S)) / D,  D = r - 2 L0 z - L1^2 + L0^2 - L2^2,
//   S  = 2L1^2L2^2 - 4L0zL1^2 - r^2 + 2rL1^2 - L0^2 + L2^2 - 4L0^2z^2
//        + 4L0^3z + 2L1^2L0^2 - 4L0zL2^2 + 4rL0z - L1^4 - L0^4 - L2^4
//        + 2L0^2L2^2.
// The "- L0^2 + L2^2" terms are as they stand in the text; they are not of
// the dimension of the others (length^2 against length^4).
inline double eqB36(double r, double z, double L0, double L1, double L2,
                    double sign) {
  const double D = r - 2.0 * L0 * z - L1 * L1 + L0 * L0 - L2 * L2;
  const double L0s = L0 * L0, L1s = L1 * L1, L2s = L2 * L2;
  const double S = 2.0 * L1s * L2s - 4.0 * L0 * z * L1s - r * r +
                   2.0 * r * L1s - L0s + L2s - 4.0 * L0s * z * z +
                   4.0 * L0s * L0 * z + 2.0 * L1s * L0s - 4.0 * L0 * z * L2s +
                   4.0 * r * L0 * z - L1s * L1s - L0s * L0s - L2s * L2s +
                   2.0 * L0s * L2s;
  return (2.0 * L1 * L2 + sign * std::sqrt(S)) / D;
}

// B.37 / B.41: theta = 2 atan(u)
inline double eqB37(double u) { return 2.0 * std::atan(u); }

// B.40: u2 = tan(theta_2 / 2), both roots, as printed. The numerator starts
// "L1 + s(theta3) + L2" (a plus where a product s3 L2 belongs, as the radicand
// L1^2 + 2 L1 s3 L2 + s3^2 L2^2 ... shows).
inline double eqB40(double th3, double z, double L0, double L1, double L2,
                    double sign) {
  const double s3 = std::sin(th3), c3 = std::cos(th3);
  const double rad = L1 * L1 + 2.0 * L1 * s3 * L2 + s3 * s3 * L2 * L2 - z * z +
                     2.0 * z * L0 + L2 * L2 * c3 * c3 - L0 * L0;
  return (L1 + s3 + L2 + sign * std::sqrt(rad)) / (z - L2 * c3 - L0);
}

// B.43: g1 = c2 (s3 L2 + L1) - s2 L2 c3 (and g2 = 0), as printed; B.20
// with f2 = -c3 L2 gives + s2 L2 c3.
inline double eqB43(double th2, double th3, double L1, double L2) {
  return std::cos(th2) * (std::sin(th3) * L2 + L1) -
         std::sin(th2) * L2 * std::cos(th3);
}

// B.48: theta_1 = Atan2(y / g1, x / g1)
inline double eqB48(double x, double y, double g1) {
  return std::atan2(y / g1, x / g1);
}

// ---------------------------------------------------------------------------
// Eq. B.49-B.53: the wrist angles via a Z'Y'X' Euler matrix, as printed.

// B.49, R_{Z'Y'X'}(alpha, beta, gamma) as printed. Row 2 prints
// "-sa sb sg + ca cg" and "-sa sb cg - ca sg".
inline Mat3 eqB49(double al, double be, double ga) {
  const double ca = std::cos(al), sa = std::sin(al);
  const double cb = std::cos(be), sb = std::sin(be);
  const double cg = std::cos(ga), sg = std::sin(ga);
  Mat3 R;
  R << ca * cb, ca * sb * sg - sa * cg, ca * sb * cg + sa * sg,   //
      sa * cb, -sa * sb * sg + ca * cg, -sa * sb * cg - ca * sg,  //
      -sb, cb * sg, cb * cg;
  return R;
}

// B.50 ("^6_4 R^{-1}|_{theta4=0} ^0_6 R = R_{Z'Y'X'}") is not transcribed:
// AMBIGUOUS, it names neither a well-defined product of Table B.1 rotations
// nor the frame in which the Euler angles are taken.

// B.51: theta_5 = -beta = -Atan2(-r31, sqrt(r32^2 + r33)), as printed (r33
// is not squared). R is the matrix of B.50.
inline double eqB51(const Mat3& R) {
  return -std::atan2(-R(2, 0), std::sqrt(R(2, 1) * R(2, 1) + R(2, 2)));
}

// B.51's beta itself (the printed Atan2, before the leading minus)
inline double eqB51_beta(const Mat3& R) { return -eqB51(R); }

// B.52: theta_4 = -alpha = -Atan2(-r21 / c(beta), r11 / c(beta)), as printed
inline double eqB52(const Mat3& R, double beta) {
  const double cb = std::cos(beta);
  return -std::atan2(-R(1, 0) / cb, R(0, 0) / cb);
}

// B.53: theta_6 = gamma = Atan2(r32 / c(beta), r33 / c(beta))
inline double eqB53(const Mat3& R, double beta) {
  const double cb = std::cos(beta);
  return std::atan2(R(2, 1) / cb, R(2, 2) / cb);
}

// ---------------------------------------------------------------------------
// Eq. B.54: ^0_6 J, all 36 entries as printed. Rows 1-3 are linear velocity
// of the wrist centre, rows 4-6 angular velocity, both in frame {0}.
// j11 prints "+s(theta1) * (...)"; j45 prints "+c1 s4 c2 c3 + c1 s4 s2 s3".
inline Mat6 eqB54(const Angles& th, double L1, double L2) {
  const double c1 = std::cos(th[0]), s1 = std::sin(th[0]);
  const double c2 = std::cos(th[1]), s2 = std::sin(th[1]);
  const double c3 = std::cos(th[2]), s3 = std::sin(th[2]);
  const double c4 = std::cos(th[3]), s4 = std::sin(th[3]);
  const double c5 = std::cos(th[4]), s5 = std::sin(th[4]);
  Mat6 J;
  // row 1
  J(0, 0) = s1 * (c2 * L1 + L2 * s2 * c3 + L2 * c2 * s3);
  J(0, 1) = c1 * (-s2 * s3 * L2 + c2 * c3 * L2 - s2 * L1);
  J(0, 2) = L2 * c1 * (c2 * c3 - s2 * s3);
  J(0, 3) = 0.0;
  J(0, 4) = 0.0;
  J(0, 5) = 0.0;
  // row 2
  J(1, 0) = c1 * (c2 * L1 + L2 * s2 * c3 + L2 * c2 * s3);
  J(1, 1) = s1 * (-s2 * s3 * L2 + c2 * c3 * L2 - s2 * L1);
  J(1, 2) = L2 * s1 * (c2 * c3 - s2 * s3);
  J(1, 3) = 0.0;
  J(1, 4) = 0.0;
  J(1, 5) = 0.0;
  // row 3
  J(2, 0) = 0.0;
  J(2, 1) = c2 * L1 + L2 * s2 * c3 + L2 * c2 * s3;
  J(2, 2) = (s2 * c3 + c2 * s3) * L2;
  J(2, 3) = 0.0;
  J(2, 4) = 0.0;
  J(2, 5) = 0.0;
  // row 4
  J(3, 0) = 0.0;
  J(3, 1) = s1;
  J(3, 2) = s1;
  J(3, 3) = c1 * (s2 * c3 + c2 * s3);
  J(3, 4) = c1 * s4 * c2 * c3 + c1 * s4 * s2 * s3 + s1 * c4;
  J(3, 5) = c5 * c4 * c1 * c2 * c3 - c5 * c4 * c1 * s2 * s3 + c5 * s1 * s4 -
            s5 * c1 * c2 * s3 - s5 * c1 * s2 * c3;
  // row 5
  J(4, 0) = 0.0;
  J(4, 1) = -c1;
  J(4, 2) = -c1;
  J(4, 3) = s1 * (s2 * c3 + c2 * s3);
  J(4, 4) = s1 * s4 * s2 * s3 - s1 * s4 * c2 * c3 - c1 * c4;
  J(4, 5) = -c5 * c4 * s1 * s2 * s3 + c5 * c4 * s1 * c2 * c3 - c5 * c1 * s4 -
            s5 * s1 * c2 * s3 - s5 * s1 * s2 * c3;
  // row 6
  J(5, 0) = 1.0;
  J(5, 1) = 0.0;
  J(5, 2) = 0.0;
  J(5, 3) = s2 * s3 - c2 * c3;
  J(5, 4) = -s4 * (s2 * c3 + c2 * s3);
  J(5, 5) = c5 * c4 * s2 * c3 + c5 * c4 * c2 * s3 - s5 * s2 * s3 + s5 * c2 * c3;
  return J;
}

}  // namespace thesis
}  // namespace vmh

#endif  // VMHAPTICS_TESTS_CONTROLLER_THESIS_EQUATIONS_H_
