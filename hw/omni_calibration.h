// The FireWire Omni's raw sensors and their calibration (docs/sources.md
// §9.2): pure functions between raw readings (encoder counts of motors
// t1..t3, potentiometer ADC codes of gimbal joints t4..t6) and joint angles
// in the device convention (t1..t6, rad, t3 the absolute forearm angle).
//
//   encoders: t_i = encoder_offset_rad[i] + sign_i * 2 pi * count_i / 15000,
//             sign = (-1, +1, +1): joint 1 counts the other way (§9.2)
//   pots:     t_j = pot_gain_rad[j] * code_j + pot_offset_rad[j]
//             (§9.2's theta = gain * r + offset with r the ADC ratio; here
//             r is kept as the integer code, so the gain is rad per code)
//
// The offsets of the encoders come from the inkwell (the dock pose is known,
// so the docked counts fix them); the pot constants differ per unit and
// come from two known angles per joint (e.g. both ends of its range).
// Eigen and the standard library only: no MuJoCo, no I/O.
#ifndef VMHAPTICS_HW_OMNI_CALIBRATION_H_
#define VMHAPTICS_HW_OMNI_CALIBRATION_H_

#include <array>
#include <cstdint>

#include "controller/types.h"

namespace vmh::hw {

// counts per revolution of each motor encoder (docs/sources.md §9.2, §6)
inline constexpr int kEncoderCountsPerRev = 15000;
// direction each encoder counts in, relative to the device angle (§9.2)
inline constexpr std::array<int, 3> kEncoderSign = {-1, +1, +1};

// The inkwell (dock) pose, device convention, rad: an ESTIMATE. t1..t3 put
// the wrist centre at OpenHaptics's inkwell position (0, -65.5, -88.1) mm
// (docs/omni.md), t5 tilts the stylus 36 deg below horizontal, tip forward;
// nobody has measured it on a device. Within the ranges of docs/sources.md
// §5 (OmniParams).
inline constexpr double kInkwellDevice_rad[6] = {0.0,  -0.647, -0.477,
                                                 0.0,  1.0,    0.0};

using EncoderCounts = std::array<std::int32_t, 3>;  // motors t1..t3
using PotCodes = std::array<std::int32_t, 3>;       // gimbal t4..t6

// One device's calibration, device convention. Index 0..2 is t1..t3 for
// the encoders and t4..t6 for the pots.
struct OmniCalibration {
  // device angle at count zero, rad
  std::array<double, 3> encoder_offset_rad{};
  // rad per ADC code, and the angle at code zero, rad
  std::array<double, 3> pot_gain_rad{};
  std::array<double, 3> pot_offset_rad{};

  // Throws std::invalid_argument naming the first bad field (non-finite,
  // or a zero pot gain, e.g. "pot_gain_rad[1] (t5) is 0").
  void validate() const;
};

// rad per encoder count
double encoder_step_rad();

// The counts that read as t1..t3 (rounded to whole counts).
EncoderCounts encoder_counts_from_angles(const Vec3& t123_device_rad,
                                         const OmniCalibration& cal);
// The pot codes that read as t4..t6 (rounded to whole codes; not clamped).
PotCodes pot_codes_from_angles(const Vec3& t456_device_rad,
                               const OmniCalibration& cal);

// The six joint angles, device convention, from raw readings.
Joints angles_from_raw(const EncoderCounts& counts, const PotCodes& pots,
                       const OmniCalibration& cal);

// Inkwell calibration: the encoder offsets that make the counts read while
// docked equal the inkwell pose's t1..t3 (device convention, rad).
std::array<double, 3> fit_encoder_offsets(const EncoderCounts& counts_docked,
                                          const Vec3& inkwell_t123_rad);

// Two-point fit of one potentiometer: the line through (r_a, theta_a) and
// (r_b, theta_b), r in ADC codes, theta in rad. `joint` (4..6) names the
// joint in errors. Throws std::invalid_argument when r_a == r_b or a value
// is not finite.
struct PotFit {
  double gain_rad = 0.0;    // rad per code
  double offset_rad = 0.0;  // rad at code zero
};
PotFit fit_pot_two_point(double r_a, double theta_a, double r_b,
                         double theta_b, int joint);

}  // namespace vmh::hw

#endif  // VMHAPTICS_HW_OMNI_CALIBRATION_H_
