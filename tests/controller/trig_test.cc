// sin_cos (controller/trig.h) against std::sin and std::cos: the servo
// tick's kinematics use it in place of libm, so it must give the same values
// to within about one ulp of 1 wherever the tick evaluates it, and libm's
// values where it falls back.
#include "controller/trig.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace vmh
