// The FireWire Omni's raw sensors and their calibration (docs/sources.md
// §9.2): pure functions between raw readings (encoder counts of motors
// t1..t3, potentiometer ADC codes of gimbal joints t4..t6) and joint angles
// in the device convention (t1..t6, rad, t3 the absolute forearm angle).
//
//   encoders: t_i = encoder_offset_rad[i]
//                   + encoder_sign[i] * 2 pi * count_i / 15000
//   pots:     t_j = pot_gain_rad[j] * code_j + pot_offset_rad[j]
//             (§9.2's theta = gain * r + offset with r the ADC ratio; here
//             r is kept as the integer code, so the gain is rad per code,
//             and its sign is the pot's direction)
//
// Every sign, gain and offset is calibration data. The nominal values are
// the public drivers' (kNominalEncoderSign here; the gimbal lines in
// hw/firewire/firewire_omni.h's nominal_calibration()); a unit's own come
// from `hw calibrate`. The encoders' offsets come from the inkwell: the
// dock pose (inkwell_t123_rad) is known, so the docked counts fix them,
// and the FireWire driver fixes them again whenever the stylus is docked,
// as the drivers do. The pot constants differ per unit and come from two
// known angles per joint (e.g. both ends of its range).
// Eigen and the standard library only: no MuJoCo, no I/O.
#ifndef VMHAPTICS_HW_OMNI_CALIBRATION_H_
#define VMHAPTICS_HW_OMNI_CALIBRATION_H_

#include <array>
#include <cstdint>

#include "controller/types.h"

namespace vmh::hw {

// counts per revolution of each motor encoder (docs/sources.md §9.2, §6)
inline constexpr int kEncoderCountsPerRev = 15000;
// The direction each encoder counts in relative to the device angles t1..t3,
// as the public drivers decode them (docs/sources.md §9.2): they publish
// +x, -y, +z counts as the URDF's waist, shoulder and the absolute elbow
// angle, and waist = -t1, shoulder = t2, elbow + shoulder = t3. Nominal:
// a calibration may say otherwise.
inline constexpr std::array<int, 3> kNominalEncoderSign = {-1, -1, +1};
// The gimbal lines the public drivers decode with (docs/sources.md §9.2):
// t_j = gain_j * r + offset_j with r = a / (a + b) in [0, 1], for t4, t5,
// t6 (the drivers' gimbal angles are the device's t4..t6, same signs).
// Their signs differ: the t5 pot turns the other way. Nominal, and rough:
// the constants differ from unit to unit.
inline constexpr double kNominalPotGainPerRatio_rad[3] = {5.48, -5.28, 4.76};
inline constexpr double kNominalPotOffset_rad[3] = {-2.74, 2.64, -2.38};

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
  // +1 or -1: the direction each encoder counts in
  std::array<int, 3> encoder_sign = kNominalEncoderSign;
  // rad per ADC code (its sign the pot's direction), and the angle at code
  // zero, rad
  std::array<double, 3> pot_gain_rad{};
  std::array<double, 3> pot_offset_rad{};
  // t1..t3 with the stylus in the inkwell, rad: what the encoder offsets
  // are fitted to, in `hw calibrate` and whenever the stylus is docked
  std::array<double, 3> inkwell_t123_rad = {
      kInkwellDevice_rad[0], kInkwellDevice_rad[1], kInkwellDevice_rad[2]};

  // Throws std::invalid_argument naming the first bad field (non-finite,
  // a zero pot gain, e.g. "pot_gain_rad[1] (t5) is 0", a sign that is not
  // +1 or -1).
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
// docked, counted in the directions `sign`, equal the inkwell pose's t1..t3
// (device convention, rad). Throws std::invalid_argument for a non-finite
// pose or a sign that is not +1 or -1.
std::array<double, 3> fit_encoder_offsets(const EncoderCounts& counts_docked,
                                          const Vec3& inkwell_t123_rad,
                                          const std::array<int, 3>& sign);
// The same with the calibration's own pose and signs, for the servo path:
// `cal` must have passed validate(). No allocation, no exception.
std::array<double, 3> docked_encoder_offsets(const EncoderCounts& counts_docked,
                                             const OmniCalibration& cal) noexcept;

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
