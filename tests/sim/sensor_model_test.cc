// sim/sensor_model: what the Omni's sensors report of the true joint angles
// (device convention, rad). Joints t1..t3: optical encoders of 15000 counts
// per revolution, so a reading is a whole number of counts of 2 pi / 15000
// rad. Joints t4..t6: potentiometers read with 11 bits across the joint's
// range, so a reading is one of the 2^11 levels lower + k range / (2^11 - 1),
// k = 0 .. 2047, both ends of the range included.
//
// The step sizes are worked out here from OmniParams' fields (and once by
// hand from the numbers in omni_params.h), and the device-convention range
// of each gimbal joint from the sign of its mapping (t4 = -q4, t5 = q5,
// t6 = -q6, controller/device_frame.h).
#include "sim/sensor_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "controller/omni_params.h"
#include "tests/support/constants.h"

namespace vmh::sim {
namespace {

using vmh::testing::kPi;
constexpr double kEncoderQuantum_rad = 2.0 * kPi / 15000.0;

// how far x is from the nearest whole number
double off_whole(double x) { return std::abs(x - std::round(x)); }

// the lower end of gimbal joint i (3..5) in the device convention: the DH
// range negated and swapped for t4 and t6, as it is for t5
double device_lower_rad(const OmniParams& p, int i) {
  const auto k = static_cast<std::size_t>(i);
  return (i == 4) ? p.joint_lower_rad[k] : -p.joint_upper_rad[k];
}

double pot_step_rad(const OmniParams& p, int i) {
  const auto k = static_cast<std::size_t>(i);
  return (p.joint_upper_rad[k] - p.joint_lower_rad[k]) /
         (std::pow(2.0, p.gimbal_pot_bits) - 1.0);
}

TEST(SensorModelTest, StepSizes) {
  const OmniParams p;
  const SensorModel s(p, true);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(s.resolution_rad()[static_cast<std::size_t>(i)],
                kEncoderQuantum_rad, 1e-18)
        << "t" << i + 1;
  }
  // 2 pi / 15000 = 4.18879e-4 rad
  EXPECT_NEAR(s.resolution_rad()[0], 4.1887902047863906e-4, 1e-15);
  for (int i = 3; i < 6; ++i) {
    EXPECT_NEAR(s.resolution_rad()[static_cast<std::size_t>(i)],
                pot_step_rad(p, i), 1e-15)
        << "t" << i + 1;
  }
  // by hand from omni_params.h: ranges 4.90, 2.26, 5.16 rad in 2047 steps
  EXPECT_NEAR(s.resolution_rad()[3], 4.90 / 2047.0, 1e-15);
  EXPECT_NEAR(s.resolution_rad()[4], 2.26 / 2047.0, 1e-15);
  EXPECT_NEAR(s.resolution_rad()[5], 5.16 / 2047.0, 1e-15);
}

// Readings over the whole range: encoder readings are whole counts, pot
// readings whole levels within [0, 2^11 - 1], and every reading is within half
// a step of the truth.
TEST(SensorModelTest, ReadingsAreWholeStepsWithinHalfAStep) {
  const OmniParams p;
  const SensorModel s(p, true);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst_encoder_rad = 0.0;
  for (int n = 0; n < 2000; ++n) {
    Joints t;
    // encoders: any angle in (-3, 3); pots: anywhere in the joint's span
    for (int i = 0; i < 3; ++i) t[i] = -3.0 + 6.0 * unit(rng);
    for (int i = 3; i < 6; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double span = p.joint_upper_rad[k] - p.joint_lower_rad[k];
      t[i] = device_lower_rad(p, i) + span * unit(rng);
    }
    const Joints m = s.measure(t);
    for (int i = 0; i < 3; ++i) {
      EXPECT_LT(off_whole(m[i] / kEncoderQuantum_rad), 1e-6) << m[i];
      EXPECT_LE(std::abs(m[i] - t[i]), 0.5 * kEncoderQuantum_rad * (1 + 1e-9));
      worst_encoder_rad = std::max(worst_encoder_rad, std::abs(m[i] - t[i]));
    }
    for (int i = 3; i < 6; ++i) {
      const double step = pot_step_rad(p, i);
      const double level = (m[i] - device_lower_rad(p, i)) / step;
      EXPECT_LT(off_whole(level), 1e-6) << "t" << i + 1;
      EXPECT_GE(level, -1e-9);
      EXPECT_LE(level, 2047.0 + 1e-9);
      EXPECT_LE(std::abs(m[i] - t[i]), 0.5 * step * (1 + 1e-9));
    }
  }
  // the error does use the half step: quantisation is not a no-op
  EXPECT_GT(worst_encoder_rad, 0.45 * kEncoderQuantum_rad);
}

// Rounding goes to the nearest count, on both sides of zero.
TEST(SensorModelTest, RoundsToTheNearestCount) {
  const SensorModel s(OmniParams(), true);
  const double q = kEncoderQuantum_rad;
  Joints t = Joints::Zero();
  t[0] = 0.4 * q;
  t[1] = 0.6 * q;
  t[2] = -7.3 * q;
  const Joints m = s.measure(t);
  EXPECT_EQ(m[0], 0.0);
  EXPECT_NEAR(m[1], q, 1e-18);
  EXPECT_NEAR(m[2], -7.0 * q, 1e-17);
}

// An asymmetric gimbal range: the levels start at the device-convention
// lower end, which for t4 is minus the DH upper end.
TEST(SensorModelTest, PotLevelsStartAtTheDeviceLowerEnd) {
  OmniParams p;
  p.joint_lower_rad[3] = -1.0;  // q4 in [-1, 2], so t4 = -q4 in [-2, 1]
  p.joint_upper_rad[3] = 2.0;
  const SensorModel s(p, true);
  const double step = 3.0 / 2047.0;
  EXPECT_NEAR(s.resolution_rad()[3], step, 1e-15);
  Joints t = Joints::Zero();
  for (const double level : {0.0, 1.0, 700.0, 2046.0}) {
    t[3] = -2.0 + level * step + 0.3 * step;  // a little above the level
    EXPECT_NEAR(s.measure(t)[3], -2.0 + level * step, 1e-12) << level;
  }
  // the top level is the range's upper end, t4 = 1
  t[3] = 1.0 - 0.3 * step;
  EXPECT_NEAR(s.measure(t)[3], 1.0, 1e-12);
}

// A potentiometer reads no further than the ends of its track: angles past
// the joint's range read as the nearest end. Encoders have no such end.
TEST(SensorModelTest, PotReadingsClampToTheRangeEnds) {
  OmniParams p;
  p.joint_lower_rad[3] = -1.0;  // t4 in [-2, 1]
  p.joint_upper_rad[3] = 2.0;
  const SensorModel s(p, true);
  Joints t = Joints::Zero();
  t[3] = 1.4;
  EXPECT_NEAR(s.measure(t)[3], 1.0, 1e-12);
  t[3] = -2.7;
  EXPECT_NEAR(s.measure(t)[3], -2.0, 1e-12);
  t[0] = 40.0;  // an encoder keeps counting past any range
  EXPECT_NEAR(s.measure(t)[0], 40.0, 0.5 * kEncoderQuantum_rad);
}

TEST(SensorModelTest, DisabledPassesTheAnglesThrough) {
  const SensorModel s(OmniParams(), false);
  Joints t;
  t << 0.123456789, -1.0e-7, 2.5, -2.4, 1.1, 0.3333;
  const Joints m = s.measure(t);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(m[i], t[i]) << i;
  for (double r : s.resolution_rad()) EXPECT_EQ(r, 0.0);
}

// A NaN stays NaN in its own joint (so the device can see the fault) and
// does not spoil the others.
TEST(SensorModelTest, NanStaysNanAndStaysPut) {
  const SensorModel s(OmniParams(), true);
  Joints t = Joints::Constant(0.1);
  t[1] = std::numeric_limits<double>::quiet_NaN();
  t[4] = std::numeric_limits<double>::quiet_NaN();
  const Joints m = s.measure(t);
  EXPECT_TRUE(std::isnan(m[1]));
  EXPECT_TRUE(std::isnan(m[4]));
  for (int i : {0, 2, 3, 5}) {
    EXPECT_TRUE(std::isfinite(m[i])) << i;
    EXPECT_NEAR(m[i], 0.1,
                0.5 * s.resolution_rad()[static_cast<std::size_t>(i)])
        << i;
  }
}

// Reading a reading gives the same reading.
TEST(SensorModelTest, MeasuringTwiceChangesNothing) {
  const OmniParams p;
  const SensorModel s(p, true);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.9, 0.9);
  for (int n = 0; n < 200; ++n) {
    Joints t;
    for (int i = 0; i < 6; ++i) t[i] = u(rng);
    const Joints once = s.measure(t);
    EXPECT_EQ(s.measure(once), once);
  }
}

}  // namespace
}  // namespace vmh::sim
