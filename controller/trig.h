// The sine and cosine of one angle together, inline, for the servo tick's
// kinematics (the arm's one-pass FK and Jacobian, the VMs' poses).
//
// Why: after the one-pass kinematics, perf on controller_bench put glibc's
// __sincos at a quarter of the circle's tick: five to ten calls per tick, each
// a call through the PLT with its own range checks, one after the other. The
// angles here are joint angles and VM angles, a few radians at most, so the
// general-purpose argument reduction is not needed; inline, the independent
// evaluations of one tick also overlap in the pipeline.
//
// How: x = n pi/2 + r with n the nearest integer to x 2/pi and |r| <= ~pi/4,
// reduced in two steps as fdlibm's __ieee754_rem_pio2 does for medium
// arguments (pi/2's leading 33 bits, so that n times them is exact for
// |n| < 2^20, then the rest of pi/2), and sin r, cos r from fdlibm's
// __kernel_sin and __kernel_cos minimax polynomials (error below one ulp on
// [-pi/4, pi/4]). Outside |x| < 1e5 (and for NaN or infinities) it falls
// back to std::sin and std::cos. Checked against std::sin and std::cos in
// tests/controller/trig_test.cc (within 2.3e-16 absolute over the joint
// and VM ranges, which is about one ulp of 1).
#ifndef VMHAPTICS_CONTROLLER_TRIG_H_
#define VMHAPTICS_CONTROLLER_TRIG_H_

#include <cmath>

namespace vmh {

struct SinCos {
  double s;
  double c;
};

inline SinCos sin_cos(double x) {
  // fdlibm's split of pi/2 (e_rem_pio2.c) and its kernels (k_sin.c, k_cos.c)
  constexpr double kInvPio2 = 6.36619772367581382433e-01;  // 0x3FE45F306DC9C883
  constexpr double kPio2Hi = 1.57079632673412561417e+00;   // 0x3FF921FB54400000
  constexpr double kPio2Lo = 6.07710050650619224932e-11;   // 0x3DD0B4611A626331
  constexpr double kS1 = -1.66666666666666324348e-01;
  constexpr double kS2 = 8.33333333332248946124e-03;
  constexpr double kS3 = -1.98412698298579493134e-04;
  constexpr double kS4 = 2.75573137070700676789e-06;
  constexpr double kS5 = -2.50507602534068634195e-08;
  constexpr double kS6 = 1.58969099521155010221e-10;
  constexpr double kC1 = 4.16666666666666019037e-02;
  constexpr double kC2 = -1.38888888888741095749e-03;
  constexpr double kC3 = 2.48015872894767294178e-05;
  constexpr double kC4 = -2.75573143513906633035e-07;
  constexpr double kC5 = 2.08757232129817482790e-09;
  constexpr double kC6 = -1.13596475577881948265e-11;
  // 1.5 * 2^52: adding and subtracting it rounds to the nearest integer
  // (round-to-nearest-even, the default mode) without a libm call
  constexpr double kRound = 6755399441055744.0;

  if (!(std::abs(x) < 1e5)) return SinCos{std::sin(x), std::cos(x)};
  const double n = (x * kInvPio2 + kRound) - kRound;
  const double r = (x - n * kPio2Hi) - n * kPio2Lo;
  const double z = r * r;
  const double v = z * r;
  const double sr =
      r + v * (kS1 + z * (kS2 + z * (kS3 + z * (kS4 + z * (kS5 + z * kS6)))));
  const double hz = 0.5 * z;
  const double w = 1.0 - hz;
  const double cr =
      w + (((1.0 - w) - hz) +
           z * (z * (kC1 + z * (kC2 + z * (kC3 + z * (kC4 + z * (kC5 +
                                                              z * kC6)))))));
  switch (static_cast<int>(n) & 3) {
    case 0:
      return SinCos{sr, cr};
    case 1:
      return SinCos{cr, -sr};
    case 2:
      return SinCos{-sr, -cr};
    default:
      return SinCos{-cr, sr};
  }
}

// atan2(y, x) inline, for the VMs' angles (theta_V and theta_R from a
// direction: four calls per sphere tick, two per circle tick).
//
// Why: perf on controller_bench/sphere/closed put glibc's __ieee754_acos and
// __ieee754_atan2 at 18% of the tick (four calls through the PLT, one after
// the other); the polar angle now comes from atan2 too (acos(-d_z) =
// atan2(|d_xy|, -d_z) for a unit d, and better conditioned at the poles).
//
// How: fold (y, x) into the first octant, num = min(|x|, |y|) <= den =
// max(|x|, |y|); above tan(pi/8) take atan(num/den) = pi/4 + atan((num -
// den)/(num + den)), so one division leaves an argument u with |u| <=
// tan(pi/8) < 7/16, where fdlibm's s_atan.c polynomial (11 coefficients) is
// accurate to below one ulp. Then unfold: pi/2 - a where |y| > |x|, pi - a
// where x < 0, the sign of y. The pi/4 and pi/2 constants carry their
// low-order parts (fdlibm's atanhi/atanlo). Both arguments zero, or either
// not finite, go to std::atan2 (signed zeros, infinities, NaN). Checked
// against std::atan2 in tests/controller/trig_test.cc (within 4.5e-16
// absolute, two ulps of pi, over random and edge arguments).
inline double atan2_fast(double y, double x) {
  constexpr double kAT0 = 3.33333333333329318027e-01;
  constexpr double kAT1 = -1.99999999998764832476e-01;
  constexpr double kAT2 = 1.42857142725034663711e-01;
  constexpr double kAT3 = -1.11111104054623557880e-01;
  constexpr double kAT4 = 9.09088713343650656196e-02;
  constexpr double kAT5 = -7.69187620504482999495e-02;
  constexpr double kAT6 = 6.66107313738753120669e-02;
  constexpr double kAT7 = -5.83357013379057348645e-02;
  constexpr double kAT8 = 4.97687799461593236017e-02;
  constexpr double kAT9 = -3.65315727442169155270e-02;
  constexpr double kAT10 = 1.62858201153657823623e-02;
  constexpr double kPio4Hi = 7.85398163397448278999e-01;
  constexpr double kPio4Lo = 3.06161699786838301793e-17;
  constexpr double kPio2Hi = 1.57079632679489655800e+00;
  constexpr double kPio2Lo = 6.12323399573676603587e-17;
  constexpr double kPiHi = 3.14159265358979311600e+00;
  constexpr double kPiLo = 1.22464679914735317720e-16;
  constexpr double kTanPio8 = 0.41421356237309503;

  const double ax = std::abs(x), ay = std::abs(y);
  // both zero, or a NaN or infinity: libm's conventions
  if (!(ax + ay > 0.0) || !(ax + ay < HUGE_VAL)) return std::atan2(y, x);
  const bool steep = ay > ax;
  const double num = steep ? ax : ay;
  const double den = steep ? ay : ax;
  const bool upper = num > kTanPio8 * den;
  const double u = upper ? (num - den) / (num + den) : num / den;
  const double z = u * u;
  const double w = z * z;
  const double s1 =
      z * (kAT0 + w * (kAT2 + w * (kAT4 + w * (kAT6 + w * (kAT8 + w * kAT10)))));
  const double s2 = w * (kAT1 + w * (kAT3 + w * (kAT5 + w * (kAT7 + w * kAT9))));
  // atan(num / den) in [0, pi/4], with pi/4's low part where it was added
  double a = upper ? kPio4Hi - ((u * (s1 + s2) - kPio4Lo) - u)
                   : u - u * (s1 + s2);
  if (steep) a = (kPio2Hi - a) + kPio2Lo;
  if (x < 0.0) a = (kPiHi - a) + kPiLo;
  return std::signbit(y) ? -a : a;
}

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_TRIG_H_
