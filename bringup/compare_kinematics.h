// compare's kinematics: the project's forward kinematics of the recorded
// joint angles against the device's own transform (dev_p_*_mm, dev_R_rc),
// with a geometry fit (geometry_fit.h) and a search over reading mistakes
// (reading_map.h) to name what is wrong.
//
// Checks (all over the good rows; device frame):
//   kinematics.position_error_p95 (mm, at most 1.0) and
//   kinematics.position_error_max (mm, at most 3.0): |p_FK - dev_p|, the
//     project's FK (OmniParams, DH angles of the trace) in the device
//     frame against the device's wrist centre. Justification: the wrist
//     position depends on t1..t3 only, read by 15000-count encoders: one
//     count is 0.42 mrad, so at the Omni's reach of at most 2 x 133 mm each
//     joint contributes at most 0.5 count x 0.42 mrad x 267 mm = 0.06 mm and
//     all three together under 0.2 mm. 1.0 mm is five times that and is what
//     a 0.75 % link error (1.0 mm on 133 mm) or a 7.5 mrad joint offset
//     produces; the max allows 3x for single glitches.
//   kinematics.stylus_axis_error_p95 (deg, at most 2.0): the angle between
//     the project's stylus axis (z of the DH stylus frame) and the device's
//     rotation column that matches it best over the recording (column and
//     sign in detail.rotation_column; a real device's rotation convention is
//     a fixed unknown rotation away). Justification: the axis depends on
//     t1..t5; the pots read 11 bits over ranges of 2.3-5.2 rad, a step of
//     1.1-2.5 mrad, so half a step on two pots plus the encoders is under
//     0.15 deg. 2 deg is ten times that and is what a 35 mrad gimbal offset
//     produces, well under what a sign or a swap does (tens of degrees).
//   kinematics.rotation_error_p95 (deg, at most 2.0): the angle of the whole
//     stylus-frame error, (R_FK C)^T dev_R, with C the device's fixed
//     rotation convention fitted over the recording (a signed permutation
//     when within 10 deg of one). The stylus axis does not see t6; this
//     does (joint6_sign, a t6 swap). Same justification: the t6 pot's step
//     is 2.5 mrad (0.07 deg).
// Measured on synthetic recordings (MuJoCo's site pose, an 8 s tour of all
// six joints at 1 kHz, angles quantized as the sensors do;
// tests/bringup/compare_kinematics_test.cc): clean position p95
// 0.046 mm, max 0.066 mm, stylus axis p95 0.063 deg, rotation p95 0.092 deg
// (each under a tenth of its threshold); l1 2 % longer: position p95
// 2.69 mm (fails), fitted l1 136.02 mm against 136.017 mm true.
//
// Fault vocabulary (CompareSection::faults), named only when a check fails:
//   joint<N>_sign (N = 1..6, device joint tN reported negated) and
//     gimbal_swap (two of t4, t5, t6 swapped): from diagnose_readings, when
//     reading the angles through that map and refitting the geometry
//     explains the transform (p95 below both thresholds) and beats the
//     identity by 3x in the normalized p95 (max of position p95 / 1.0 mm
//     and rotation p95 / 2 deg).
//   link_length_<P>pct: the fit finds l1 or l2 off by more than 0.75 % and
//     more than 3 sigma, and explains the error; P = round(100 (fitted /
//     nominal - 1)), signed: a 3 % short link is link_length_-3pct. The
//     evidence names the link (l1 or l2) and the fitted value.
//   joint<N>_offset: the fit explains the error with tN's zero off by more
//     than 5 mrad and 3 sigma (an encoder or pot zero, an index pulse).
//   joint<N>_scale (N = 4..6): a pot's gain off by more than 2 % and 3 sigma.
//   base_offset: the device frame's origin off by more than 0.5 mm and 3
//     sigma (an inkwell calibration off).
//   kinematics_unexplained: a check fails and neither a reading map nor the
//     geometry fit explains it.
// A consistent delay of every column (delay_<M>ms) moves none of these:
// the angles and the transform stay paired (the motor test catches it).
// A recording without the dev_* transform columns: every check is skipped
// (SkippedCheck names the missing columns), nothing is failed.
#ifndef VMHAPTICS_BRINGUP_COMPARE_KINEMATICS_H_
#define VMHAPTICS_BRINGUP_COMPARE_KINEMATICS_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bringup/compare_check.h"
#include "bringup/geometry_fit.h"
#include "bringup/reading_map.h"
#include "bringup/recording.h"

namespace vmh::bringup {

inline constexpr double kPositionErrorP95ThresholdMm = 1.0;
inline constexpr double kPositionErrorMaxThresholdMm = 3.0;
inline constexpr double kStylusAxisErrorP95ThresholdDeg = 2.0;

// The maps tried: identity, joint1_sign .. joint6_sign, and the three
// gimbal swaps (t4-t5, t4-t6, t5-t6, each named gimbal_swap)
std::vector<ReadingMap> reading_hypotheses();

// The good rows' (reported device angles read through `map`, device
// transform) pairs, at most max_samples of them evenly spaced over the
// recording (0: all). Throws RecordingError when the transform is missing.
std::vector<PoseSample> pose_samples(const Recording& rec, const ReadingMap& map,
                                     std::size_t max_samples = 0);

struct ReadingHypothesis {
  ReadingMap map;
  GeometryFit fit;
  // max(position p95 after the fit / 1.0 mm, rotation p95 / 2 deg), at the
  // nominal geometry when the fit is implausible: below 1 when the
  // hypothesis explains the transform
  double normalized_p95 = 0.0;
};

struct ReadingDiagnosis {
  ReadingMap map;  // the chosen one (identity unless another is clearly better)
  std::vector<ReadingHypothesis> hypotheses;  // in reading_hypotheses() order
  std::string evidence;  // one line: the chosen map's and the identity's figures
};

// Tries every reading_hypotheses() map with a geometry fit each (on at
// most 400 samples each) and picks one. A recording without the transform
// gets the identity and says so in evidence.
ReadingDiagnosis diagnose_readings(const Recording& rec);

// The kinematics checks, detail, faults and (when figure_dir is not empty)
// figure kinematics_error.svg. Section name "kinematics".
CompareSection compare_kinematics(const Recording& rec,
                                  const std::string& figure_dir);

}  // namespace vmh::bringup

#endif  // VMHAPTICS_BRINGUP_COMPARE_KINEMATICS_H_
