#include "hw/omni_calibration.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace vmh::hw {
namespace {

constexpr double kTwoPi = 6.28318530717958647692;

void require_finite(double v, const char* field, int i) {
  if (!std::isfinite(v)) {
    throw std::invalid_argument(std::string(field) + "[" + std::to_string(i) +
                                "] is not finite");
  }
}

std::int32_t to_code(double x, const char* what, int joint) {
  const double r = std::round(x);
  if (!(std::abs(r) < 2147483647.0)) {
    throw std::invalid_argument(std::string(what) + " of t" +
                                std::to_string(joint) +
                                " is out of range or not finite");
  }
  return static_cast<std::int32_t>(r);
}

}  // namespace

void OmniCalibration::validate() const {
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    require_finite(encoder_offset_rad[k], "encoder_offset_rad", i);
    require_finite(pot_gain_rad[k], "pot_gain_rad", i);
    require_finite(pot_offset_rad[k], "pot_offset_rad", i);
    if (pot_gain_rad[k] == 0.0) {
      throw std::invalid_argument("pot_gain_rad[" + std::to_string(i) +
                                  "] (t" + std::to_string(i + 4) + ") is 0");
    }
    if (encoder_sign[k] != 1 && encoder_sign[k] != -1) {
      throw std::invalid_argument("encoder_sign[" + std::to_string(i) + "] (t" +
                                  std::to_string(i + 1) + ") is " +
                                  std::to_string(encoder_sign[k]) +
                                  ", not +1 or -1");
    }
    require_finite(inkwell_t123_rad[k], "inkwell_t123_rad", i);
  }
}

double encoder_step_rad() { return kTwoPi / kEncoderCountsPerRev; }

EncoderCounts encoder_counts_from_angles(const Vec3& t123_device_rad,
                                         const OmniCalibration& cal) {
  EncoderCounts c{};
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double rel = t123_device_rad[i] - cal.encoder_offset_rad[k];
    c[k] = to_code(cal.encoder_sign[k] * rel / encoder_step_rad(), "encoder count",
                   i + 1);
  }
  return c;
}

PotCodes pot_codes_from_angles(const Vec3& t456_device_rad,
                               const OmniCalibration& cal) {
  PotCodes c{};
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    c[k] = to_code((t456_device_rad[i] - cal.pot_offset_rad[k]) /
                       cal.pot_gain_rad[k],
                   "pot code", i + 4);
  }
  return c;
}

Joints angles_from_raw(const EncoderCounts& counts, const PotCodes& pots,
                       const OmniCalibration& cal) {
  Joints t;
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    t[i] = cal.encoder_offset_rad[k] +
           cal.encoder_sign[k] * encoder_step_rad() * counts[k];
    t[i + 3] = cal.pot_gain_rad[k] * pots[k] + cal.pot_offset_rad[k];
  }
  return t;
}

std::array<double, 3> fit_encoder_offsets(const EncoderCounts& counts_docked,
                                          const Vec3& inkwell_t123_rad,
                                          const std::array<int, 3>& sign) {
  std::array<double, 3> off{};
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    require_finite(inkwell_t123_rad[i], "inkwell_t123_rad", i);
    if (sign[k] != 1 && sign[k] != -1) {
      throw std::invalid_argument("encoder_sign[" + std::to_string(i) +
                                  "] is " + std::to_string(sign[k]) +
                                  ", not +1 or -1");
    }
    off[k] = inkwell_t123_rad[i] - sign[k] * encoder_step_rad() * counts_docked[k];
  }
  return off;
}

std::array<double, 3> docked_encoder_offsets(const EncoderCounts& counts_docked,
                                             const OmniCalibration& cal) noexcept {
  constexpr double kStep = kTwoPi / kEncoderCountsPerRev;
  std::array<double, 3> off{};
  for (std::size_t k = 0; k < 3; ++k) {
    off[k] = cal.inkwell_t123_rad[k] - cal.encoder_sign[k] * kStep * counts_docked[k];
  }
  return off;
}

PotFit fit_pot_two_point(double r_a, double theta_a, double r_b,
                         double theta_b, int joint) {
  const std::string name = "t" + std::to_string(joint);
  if (!std::isfinite(r_a) || !std::isfinite(theta_a) || !std::isfinite(r_b) ||
      !std::isfinite(theta_b)) {
    throw std::invalid_argument("fit_pot_two_point: a reading of " + name +
                                " is not finite");
  }
  if (r_a == r_b) {
    throw std::invalid_argument("fit_pot_two_point: both readings of " + name +
                                " are " + std::to_string(r_a) +
                                "; the two points must differ");
  }
  PotFit f;
  f.gain_rad = (theta_b - theta_a) / (r_b - r_a);
  f.offset_rad = theta_a - f.gain_rad * r_a;
  return f;
}

}  // namespace vmh::hw
