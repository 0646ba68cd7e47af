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

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_TRIG_H_
