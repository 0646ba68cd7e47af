// Shared by the errata tests (errata_test.cc, thesis_consistency_test.cc):
// constants, a sampler of joint angles, the independent truths (the Table B.1
// chain from elementary transforms, its finite-difference Jacobian) and the
// corrected forms of the printed equations.
#ifndef VMHAPTICS_TESTS_CONTROLLER_ERRATA_SUPPORT_H_
#define VMHAPTICS_TESTS_CONTROLLER_ERRATA_SUPPORT_H_


#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"
#include "tests/controller/thesis_equations.h"
#include "tests/support/openhaptics_reference.h"


namespace vmh::errata {

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
inline bool close(double a, double b, double tol) { return std::abs(a - b) <= tol; }

inline double wrap(double a) { return std::remainder(a, 2.0 * kPi); }

// -- independent truth: the Table B.1 chain from elementary transforms --

inline Mat4 elementary_link(double a_prev, double alpha_prev, double d, double theta) {
  const Eigen::Affine3d T =
      Eigen::AngleAxisd(alpha_prev, Eigen::Vector3d::UnitX()) *
      Eigen::Translation3d(a_prev, 0.0, 0.0) *
      Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()) *
      Eigen::Translation3d(0.0, 0.0, d);
  return T.matrix();
}

// link i (1-based, as in Table B.1) at joint angle theta_i
inline Mat4 table_link(int i, double theta, double L0 = kL0) {
  th::TableB1Row rows[6];
  th::table_b1(L0, kL1, kL2, rows);
  const th::TableB1Row& r = rows[i - 1];
  return elementary_link(r.a_prev, r.alpha_prev_deg * kDeg, r.d,
                         theta + r.theta_offset_deg * kDeg);
}

// ^{first-1}_{last} T: product of Table B.1 links first..last (1-based)
inline Mat4 table_chain(const Angles& q, int first, int last, double L0 = kL0) {
  Mat4 T = Mat4::Identity();
  for (int i = first; i <= last; ++i) T = T * table_link(i, q[i - 1], L0);
  return T;
}

// geometric Jacobian of the wrist centre by central differences of the chain:
// linear rows from dP/dq, angular rows from (dR/dq) R^T = [w]x
inline th::Mat6 fd_jacobian(const Angles& q) {
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

inline Mat3 rot_x(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
}

// Z'Y'X' Euler rotation RotZ(a) RotY(b) RotX(c), from Eigen's axis-angles
inline Mat3 zyx(double a, double b, double c) {
  return (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(b, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(c, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// ---------------------------------------------------------------------------
// The corrected forms, written for these tests.
namespace corrected {

// eq. 2.1 with Craig's (3,4) entry cos(alpha) d
inline Mat4 eq2_1(double a_prev, double alpha_prev, double d, double theta) {
  Mat4 T = th::eq2_1(a_prev, alpha_prev, d, theta);
  T(2, 3) = std::cos(alpha_prev) * d;
  return T;
}

// B.4 with -L2 in the second row (as eq. B.16 has it)
inline Mat4 eqB4(double th4, double L2) {
  Mat4 T = th::eqB4(th4, L2);
  T(1, 3) = -L2;
  T(2, 3) = 0.0;
  return T;
}

// B.5 from Table B.1 row 5: RotX(-90) RotZ(theta5 - 90)
inline Mat4 eqB5(double th5) {
  const double c = std::cos(th5), s = std::sin(th5);
  Mat4 T;
  T << s, c, 0, 0,  //
      0, 0, 1, 0,   //
      c, -s, 0, 0,  //
      0, 0, 0, 1;
  return T;
}

// B.6 with the sign of its second row flipped
inline Mat4 eqB6(double th6) {
  Mat4 T = th::eqB6(th6);
  T(1, 2) = 1.0;
  return T;
}

// B.8 with (3,2) = c2 c3 - s2 s3
inline Mat4 eqB8(double th1, double th2, double th3, double L0, double L1) {
  Mat4 T = th::eqB8(th1, th2, th3, L0, L1);
  T(2, 1) = std::cos(th2) * std::cos(th3) - std::sin(th2) * std::sin(th3);
  return T;
}

// B.14: the entries that are misprinted, as R_03 (B.11) times R_36 (B.12).
// With (a, b, c) the first and (d, e, f) the second column of B.12:
//   r11 = c1 (c23 a - s23 b) + s1 c     r12 = c1 (c23 d - s23 e) + s1 f
//   r21 = s1 (c23 a - s23 b) - c1 c     r22 = s1 (c23 d - s23 e) - c1 f
//   r31 = s23 a + c23 b (as printed)     r32 = s23 d + c23 e
inline th::EqB14 eqB14(const Angles& q, double L0, double L1, double L2) {
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
inline Mat4 eqB13(const th::EqB14& e) {
  Mat4 T = th::eqB13(e);
  T(0, 1) = e.r12;
  T(0, 2) = e.r13;
  return T;
}

// B.19, second row s1 c2 f1 - s1 s2 f2 - c1 f3
inline Vec3 eqB19_lhs(double th1, double th2, const th::EqB18& f, double L0) {
  Vec3 p = th::eqB19_lhs(th1, th2, f, L0);
  p.y() = std::sin(th1) * std::cos(th2) * f.f1 -
          std::sin(th1) * std::sin(th2) * f.f2 - std::cos(th1) * f.f3;
  return p;
}

// B.36 radicand as printed but with "-L0^2 + L2^2" read as
// "-2 r L0^2 + 2 r L2^2"
inline double eqB36_radicand(double r, double z, double L0, double L1, double L2) {
  const double L0s = L0 * L0, L1s = L1 * L1, L2s = L2 * L2;
  return 2.0 * L1s * L2s - 4.0 * L0 * z * L1s - r * r + 2.0 * r * L1s -
         2.0 * r * L0s + 2.0 * r * L2s - 4.0 * L0s * z * z +
         4.0 * L0s * L0 * z + 2.0 * L1s * L0s - 4.0 * L0 * z * L2s +
         4.0 * r * L0 * z - L1s * L1s - L0s * L0s - L2s * L2s + 2.0 * L0s * L2s;
}

inline double eqB36(double r, double z, double L0, double L1, double L2, double sign) {
  const double D = r - 2.0 * L0 * z - L1 * L1 + L0 * L0 - L2 * L2;
  return (2.0 * L1 * L2 + sign * std::sqrt(eqB36_radicand(r, z, L0, L1, L2))) /
         D;
}

// B.40 with the numerator L1 + s3 L2 (radicand and denominator as printed)
inline double eqB40(double th3, double z, double L0, double L1, double L2,
             double sign) {
  const double s3 = std::sin(th3), c3 = std::cos(th3);
  const double rad = L1 * L1 + 2.0 * L1 * s3 * L2 + s3 * s3 * L2 * L2 - z * z +
                     2.0 * z * L0 + L2 * L2 * c3 * c3 - L0 * L0;
  return (L1 + s3 * L2 + sign * std::sqrt(rad)) / (z - L2 * c3 - L0);
}

// B.43 with + s2 L2 c3
inline double eqB43(double th2, double th3, double L1, double L2) {
  return std::cos(th2) * (std::sin(th3) * L2 + L1) +
         std::sin(th2) * L2 * std::cos(th3);
}

// B.49 with row 2 = (sa cb, sa sb sg + ca cg, sa sb cg - ca sg)
inline Mat3 eqB49(double al, double be, double ga) {
  Mat3 R = th::eqB49(al, be, ga);
  const double ca = std::cos(al), sa = std::sin(al);
  const double sb = std::sin(be);
  const double cg = std::cos(ga), sg = std::sin(ga);
  R(1, 1) = sa * sb * sg + ca * cg;
  R(1, 2) = sa * sb * cg - ca * sg;
  return R;
}

// B.51 with r33 squared
inline double eqB51(const Mat3& R) {
  return -std::atan2(-R(2, 0),
                     std::sqrt(R(2, 1) * R(2, 1) + R(2, 2) * R(2, 2)));
}

// B.52 agreeing with its own label theta4 = -alpha
inline double eqB52(const Mat3& R, double beta) {
  const double cb = std::cos(beta);
  return -std::atan2(R(1, 0) / cb, R(0, 0) / cb);
}

// B.54 with j11 = -s1 (...) and j45 = -c1 s4 c23 + s1 c4
inline th::Mat6 eqB54(const Angles& q, double L1, double L2) {
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

}  // namespace vmh::errata

#endif  // VMHAPTICS_TESTS_CONTROLLER_ERRATA_SUPPORT_H_
