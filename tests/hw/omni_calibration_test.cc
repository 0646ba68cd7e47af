// hw/omni_calibration: raw FireWire Omni readings <-> joint angles and the
// two calibration fits. Expected values are worked out here from the
// formulas of docs/sources.md §9.2 with hand-chosen numbers.
#include "hw/omni_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include "tests/support/constants.h"

namespace vmh::hw {
namespace {

using vmh::testing::kPi;

// a calibration chosen by hand: offsets of a few tenths of a radian, the
// nominal encoder signs and §9.2's theta = 5.48 r - 2.74 on a 10-bit ADC
OmniCalibration hand_cal() {
  OmniCalibration c;
  c.encoder_offset_rad = {-0.23, 0.37, 0.05};
  c.pot_gain_rad = {5.48 / 1023.0, -4.0 / 1023.0, 5.0 / 1023.0};
  c.pot_offset_rad = {-2.74, 1.9, -2.5};
  return c;
}

bool throws_naming(void (*f)(), const std::string& word) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return std::string(e.what()).find(word) != std::string::npos;
  }
  return false;
}

TEST(OmniCalibration, CountsFollowSection92) {
  // 15000 counts per revolution: a quarter turn is 3750 counts; with the
  // drivers' signs t1 and t2 count the other way from the device angle
  const OmniCalibration cal = hand_cal();
  EXPECT_EQ(cal.encoder_sign, (std::array<int, 3>{-1, -1, 1}));
  const Vec3 t(-0.23 + kPi / 2, 0.37 + kPi / 2, 0.05 - kPi / 2);
  const EncoderCounts c = encoder_counts_from_angles(t, cal);
  EXPECT_EQ(c[0], -3750);
  EXPECT_EQ(c[1], -3750);
  EXPECT_EQ(c[2], -3750);
  EXPECT_NEAR(encoder_step_rad(), 2 * kPi / 15000, 1e-15);
}

TEST(OmniCalibration, EncoderSignsAreCalibrationData) {
  // the same counts read the other way when a calibration says so
  OmniCalibration cal = hand_cal();
  const EncoderCounts c{1500, 1500, 1500};  // a tenth of a turn each
  const Joints nominal = angles_from_raw(c, {0, 0, 0}, cal);
  cal.encoder_sign = {1, 1, -1};
  const Joints flipped = angles_from_raw(c, {0, 0, 0}, cal);
  const double tenth = 2 * kPi / 10;
  EXPECT_NEAR(nominal[0], -0.23 - tenth, 1e-12);
  EXPECT_NEAR(flipped[0], -0.23 + tenth, 1e-12);
  EXPECT_NEAR(nominal[1], 0.37 - tenth, 1e-12);
  EXPECT_NEAR(flipped[1], 0.37 + tenth, 1e-12);
  EXPECT_NEAR(nominal[2], 0.05 + tenth, 1e-12);
  EXPECT_NEAR(flipped[2], 0.05 - tenth, 1e-12);
  // and the round trip holds with any signs
  EXPECT_EQ(encoder_counts_from_angles(flipped.head<3>(), cal), c);
}

TEST(OmniCalibration, PotsAreLinear) {
  // code 0 reads the offset, code 1023 offset + 1023 gain: -2.74 + 5.48
  const OmniCalibration cal = hand_cal();
  const Joints t = angles_from_raw({0, 0, 0}, {0, 1023, 512}, cal);
  EXPECT_NEAR(t[3], -2.74, 1e-12);
  EXPECT_NEAR(t[4], 1.9 - 4.0, 1e-12);
  EXPECT_NEAR(t[5], -2.5 + 5.0 * 512 / 1023.0, 1e-12);
  EXPECT_NEAR(t[0], -0.23, 1e-15);
}

TEST(OmniCalibration, RoundTripWithinHalfAStep) {
  const OmniCalibration cal = hand_cal();
  Joints t;
  t << 0.4, -0.6, 0.9, 1.3, -0.7, 2.1;
  const EncoderCounts c = encoder_counts_from_angles(t.head<3>(), cal);
  const PotCodes p = pot_codes_from_angles(t.tail<3>(), cal);
  const Joints back = angles_from_raw(c, p, cal);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(std::abs(back[i] - t[i]), 0.5 * 2 * kPi / 15000 + 1e-12) << i;
    EXPECT_LE(std::abs(back[i + 3] - t[i + 3]),
              0.5 * std::abs(cal.pot_gain_rad[static_cast<std::size_t>(i)]) +
                  1e-12)
        << i;
  }
  // and raw -> angles -> raw is exact
  EXPECT_EQ(encoder_counts_from_angles(back.head<3>(), cal), c);
  EXPECT_EQ(pot_codes_from_angles(back.tail<3>(), cal), p);
}

TEST(OmniCalibration, InkwellFitRecoversOffsets) {
  // a device with offsets `truth` docked at a known pose reads counts
  // (computed here by hand); the fit must return `truth`
  OmniCalibration truth = hand_cal();
  truth.encoder_sign = {-1, 1, -1};  // any signs: the fit uses the ones given
  const Vec3 inkwell(0.0, -0.647, 0.3);
  EncoderCounts docked{};
  const double step = 2 * kPi / 15000;
  const int sign[3] = {-1, 1, -1};
  for (int i = 0; i < 3; ++i) {
    docked[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(std::lround(
        sign[i] * (inkwell[i] - truth.encoder_offset_rad[static_cast<std::size_t>(i)]) /
        step));
  }
  const auto off = fit_encoder_offsets(docked, inkwell, truth.encoder_sign);
  for (int i = 0; i < 3; ++i) {
    // the counts are whole, so the offset is recovered to half a count
    EXPECT_NEAR(off[static_cast<std::size_t>(i)],
                truth.encoder_offset_rad[static_cast<std::size_t>(i)],
                0.5 * step + 1e-12)
        << i;
  }
  // and with the fitted offsets the docked reading is the inkwell pose
  OmniCalibration fitted = truth;
  fitted.encoder_offset_rad = off;
  const Joints t = angles_from_raw(docked, {0, 0, 0}, fitted);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(t[i], inkwell[i], 1e-12) << i;
  // the servo path's version with the calibration's own pose agrees
  OmniCalibration own = truth;
  own.inkwell_t123_rad = {inkwell[0], inkwell[1], inkwell[2]};
  const auto again = docked_encoder_offsets(docked, own);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(again[i], off[i], 1e-15) << i;
}

TEST(OmniCalibration, TwoPointPotFitRecoversLine) {
  // theta = 5.48/1023 r - 2.74 read at codes 100 and 900
  const double g = 5.48 / 1023.0, o = -2.74;
  const PotFit f = fit_pot_two_point(100, g * 100 + o, 900, g * 900 + o, 4);
  EXPECT_NEAR(f.gain_rad, g, 1e-15);
  EXPECT_NEAR(f.offset_rad, o, 1e-12);
  // order of the points does not matter
  const PotFit f2 = fit_pot_two_point(900, g * 900 + o, 100, g * 100 + o, 4);
  EXPECT_NEAR(f2.gain_rad, g, 1e-15);
}

TEST(OmniCalibration, BadInputNamesTheField) {
  EXPECT_TRUE(throws_naming(
      [] { fit_pot_two_point(300, 0.1, 300, 0.5, 5); }, "t5"));
  EXPECT_TRUE(throws_naming(
      [] {
        fit_pot_two_point(1, std::numeric_limits<double>::quiet_NaN(), 2, 0, 6);
      },
      "t6"));
  EXPECT_TRUE(throws_naming(
      [] {
        OmniCalibration c = hand_cal();
        c.pot_gain_rad[1] = 0.0;
        c.validate();
      },
      "pot_gain_rad[1]"));
  EXPECT_TRUE(throws_naming(
      [] {
        OmniCalibration c = hand_cal();
        c.encoder_offset_rad[2] = std::numeric_limits<double>::infinity();
        c.validate();
      },
      "encoder_offset_rad[2]"));
  EXPECT_TRUE(throws_naming(
      [] {
        fit_encoder_offsets({0, 0, 0},
                            Vec3(0, std::numeric_limits<double>::quiet_NaN(), 0),
                            kNominalEncoderSign);
      },
      "inkwell_t123_rad[1]"));
  EXPECT_TRUE(throws_naming(
      [] { fit_encoder_offsets({0, 0, 0}, Vec3(0, 0, 0), {-1, 0, 1}); },
      "encoder_sign[1]"));
  EXPECT_TRUE(throws_naming(
      [] {
        OmniCalibration c = hand_cal();
        c.encoder_sign[2] = 2;
        c.validate();
      },
      "encoder_sign[2] (t3) is 2"));
  EXPECT_TRUE(throws_naming(
      [] {
        OmniCalibration c = hand_cal();
        c.inkwell_t123_rad[0] = std::numeric_limits<double>::infinity();
        c.validate();
      },
      "inkwell_t123_rad[0]"));
  EXPECT_NO_THROW(hand_cal().validate());
}

}  // namespace
}  // namespace vmh::hw
