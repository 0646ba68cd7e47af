// sin_cos and atan2_fast (controller/trig.h) against std::sin, std::cos and
// std::atan2: the servo tick's kinematics and VM angles use them in place of
// libm, so they must give the same values to within about one ulp wherever
// the tick evaluates them, and libm's values where they fall back.
#include "controller/trig.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace vmh {
namespace {

constexpr double kTol = 2.3e-16;  // about one ulp of 1

void expect_close(double x) {
  const SinCos t = sin_cos(x);
  EXPECT_NEAR(t.s, std::sin(x), kTol) << "x = " << x;
  EXPECT_NEAR(t.c, std::cos(x), kTol) << "x = " << x;
}

TEST(SinCos, RandomAnglesOverSeveralTurns) {
  std::mt19937_64 rng(18);
  std::uniform_real_distribution<double> angle(-20.0, 20.0);
  for (int i = 0; i < 1000000; ++i) expect_close(angle(rng));
}

TEST(SinCos, QuadrantBoundariesAndTheirNeighbours) {
  // the reduction changes quadrant at odd multiples of pi/4, and r is
  // smallest at multiples of pi/2
  for (int k = -40; k <= 40; ++k) {
    const double x = k * (3.14159265358979323846 / 4.0);
    expect_close(x);
    expect_close(std::nextafter(x, 1e9));
    expect_close(std::nextafter(x, -1e9));
  }
}

TEST(SinCos, SmallAnglesKeepTheirSine) {
  for (double x : {0.0, -0.0, 1e-300, 1e-20, 1e-9, -1e-9, 1e-4}) {
    const SinCos t = sin_cos(x);
    EXPECT_EQ(t.s, std::sin(x)) << x;
    EXPECT_NEAR(t.c, std::cos(x), kTol) << x;
  }
}

TEST(SinCos, LargeAndNonFiniteArgumentsFallBackToLibm) {
  for (double x : {1e5, -1e5, 1e12, std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::quiet_NaN()}) {
    const SinCos t = sin_cos(x);
    const double s = std::sin(x), c = std::cos(x);
    if (std::isnan(s)) {
      EXPECT_TRUE(std::isnan(t.s));
      EXPECT_TRUE(std::isnan(t.c));
    } else {
      EXPECT_EQ(t.s, s);
      EXPECT_EQ(t.c, c);
    }
  }
  // just inside the fast range, still within an ulp-sized bound scaled by
  // the reduction's error (n up to 6.4e4 times pi/2's tail's rounding)
  const SinCos t = sin_cos(99999.5);
  EXPECT_NEAR(t.s, std::sin(99999.5), 1e-15);
  EXPECT_NEAR(t.c, std::cos(99999.5), 1e-15);
}

// one ulp of pi: atan2's result lies in [-pi, pi]
constexpr double kAtan2Tol = 4.45e-16;

// |a - b| in units in the last place of b
double ulps(double a, double b) {
  const double ulp = std::nextafter(std::abs(b), HUGE_VAL) - std::abs(b);
  return std::abs(a - b) / ulp;
}

TEST(Atan2Fast, RandomPairsAcrossMagnitudesAndQuadrants) {
  std::mt19937_64 rng(180);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> decade(-12.0, 12.0);
  double worst_ulps = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    const double y = unit(rng) * std::pow(10.0, decade(rng));
    const double x = unit(rng) * std::pow(10.0, decade(rng));
    const double got = atan2_fast(y, x), want = std::atan2(y, x);
    ASSERT_NEAR(got, want, kAtan2Tol) << "y = " << y << ", x = " << x;
    worst_ulps = std::max(worst_ulps, ulps(got, want));
  }
  // relative accuracy too, where the angle is small: within two ulps
  EXPECT_LE(worst_ulps, 2.0);
}

TEST(Atan2Fast, OctantBoundariesAndTheirNeighbours) {
  // the folding switches at |y| = |x| (pi/4 multiples) and at
  // num/den = tan(pi/8); and the axes themselves
  const double t8 = std::tan(3.14159265358979323846 / 8.0);
  for (double r : {1.0, t8, 1.0 / t8, 0.0, 1e-300}) {
    for (double sx : {1.0, -1.0}) {
      for (double sy : {1.0, -1.0}) {
        for (double x : {1.0, std::nextafter(1.0, 2.0),
                         std::nextafter(1.0, 0.0), 3.7e-5, 2.9e8}) {
          const double y = sy * r * x;
          const double xs = sx * x;
          EXPECT_NEAR(atan2_fast(y, xs), std::atan2(y, xs), kAtan2Tol)
              << "y = " << y << ", x = " << xs;
          EXPECT_LE(ulps(atan2_fast(y, xs), std::atan2(y, xs)), 2.0)
              << "y = " << y << ", x = " << xs;
          EXPECT_NEAR(atan2_fast(xs, y), std::atan2(xs, y), kAtan2Tol)
              << "y = " << xs << ", x = " << y;
        }
      }
    }
  }
}

TEST(Atan2Fast, ZerosInfinitiesAndNaNFollowLibm) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double values[] = {0.0, -0.0, 1.0, -1.0, 1e-310, -1e-310, inf, -inf,
                           nan, 1e308, -1e308};
  for (double y : values) {
    for (double x : values) {
      const double got = atan2_fast(y, x), want = std::atan2(y, x);
      if (std::isnan(want)) {
        EXPECT_TRUE(std::isnan(got)) << "y = " << y << ", x = " << x;
        continue;
      }
      EXPECT_NEAR(got, want, kAtan2Tol) << "y = " << y << ", x = " << x;
      // the sign of a zero or of pi carries the half-plane
      EXPECT_EQ(std::signbit(got), std::signbit(want))
          << "y = " << y << ", x = " << x;
    }
  }
}

}  // namespace
}  // namespace vmh
