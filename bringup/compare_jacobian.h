// compare's Jacobian: the project's Jacobian (controller/omni_kinematics.h)
// at the recorded angles, read through the ReadingMap diagnose_readings
// chose (compare_kinematics.h), against what the device reports of its own
// Jacobian (dev_J_rc) and velocity (dev_v_*_mm_s), device frame.
//
// Checks:
//   jacobian.matrix_rel_error (ratio, at most 0.02): median over samples
//     of ||W (J_dev - J_project)||_F / ||W J_project||_F, rows (v mm/rad;
//     w rad/rad) in the device frame, W weighting the angular rows by
//     100 mm/rad (as the geometry fit does) so that both halves count.
//     dev_J's layout is unknown on a real device, so four are tried:
//     {as stored, transposed} x {device joint columns t1..t6 (t3
//     absolute), DH joint columns q1..q6}; the best is checked and named in
//     detail.layout. Justification: the project's J at angles quantized to
//     0.4 mrad (encoders) and 1-2.5 mrad (pots) differs from the true one by
//     about that, a relative 0.03-0.3 %; a wrong layout, sign or swap
//     gives tens of %. A 2 % longer l1 measures 1.0 % and passes: the
//     kinematics check names it.
//   jacobian.velocity_rel_error (ratio, at most 0.10): median over samples
//     with |dev_v| > 20 mm/s of |J(q) qdot - dev_v| / |dev_v|, qdot the
//     central difference of the recorded angles over +-10 ms.
//     Justification: one encoder count (0.42 mrad) over a 20 ms baseline
//     is 0.021 rad/s, up to 5.6 mm/s at the reach of 267 mm, typically
//     (uniform rounding at both ends) 2-3 mm/s over the three joints: a few
//     % of the 50-300 mm/s a tour moves at; 10 % leaves margin for slower
//     recordings. A consistent delay of every column does not move it.
//   jacobian.fd_velocity_rel_error (ratio, at most 0.10): the same J qdot
//     against the central difference of dev_p over the same window (the
//     device's positions, its velocity filter aside), median over samples
//     moving faster than 20 mm/s. Same justification.
// Measured on the synthetic clean tour (compare_kinematics_test.cc): matrix
// 0.0003, velocity 0.006, finite-difference velocity 0.006.
// Skipped (SkippedCheck naming the columns) when dev_J, dev_v or dev_p are
// absent. When the readings map is not the identity the detail says the
// checks were made through it (explained_by). Names no faults of its own: a
// reading mistake is named once, by compare_kinematics.
#ifndef VMHAPTICS_BRINGUP_COMPARE_JACOBIAN_H_
#define VMHAPTICS_BRINGUP_COMPARE_JACOBIAN_H_

#include <string>

#include "bringup/compare_check.h"
#include "bringup/reading_map.h"
#include "bringup/recording.h"

namespace vmh::bringup {

inline constexpr double kJacobianRelErrorThreshold = 0.02;
inline constexpr double kVelocityRelErrorThreshold = 0.10;
inline constexpr double kVelocityMinSpeedMmS = 20.0;
inline constexpr double kVelocityHalfWindowS = 0.010;

// The Jacobian checks, detail and (when figure_dir is not empty) figure
// jacobian_velocity.svg. Section name "jacobian".
CompareSection compare_jacobian(const Recording& rec, const ReadingMap& readings,
                                const std::string& figure_dir);

}  // namespace vmh::bringup

#endif  // VMHAPTICS_BRINGUP_COMPARE_JACOBIAN_H_
