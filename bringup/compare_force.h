// compare's force analyses: does a motor push the way, as hard and as soon
// as the MJCF Omni says it should (a `hw motor-test` recording), and does
// the project's tau = J_r^T F agree with the device's own Jacobian (a `hw
// run` recording).
//
// Force direction (compare_force_direction, one motor-test recording)
//   The pulse starts at the first row whose tau_sent on the pulsed motor
//   (meta "motor") is nonzero. The recorded angles are read through the
//   ReadingMap found by kinematics (true = map.true_from_reported), so a
//   reading mistake is not blamed on a motor. ResponseSimulator predicts
//   the Omni from the state pre_ms / 2 before the pulse (the angles there,
//   the velocity fitted over the pre_ms before the pulse) under the
//   recorded tau_sent series; a second run with zero torque gives the free
//   motion (gravity, the initial velocity), and the pulse's effect is each
//   series minus it. Joint space t1..t3 (device convention, rad) is the
//   primary space: the motors act on those joints and the encoders read
//   them, so no link length or FK error enters, and a motor's sign or its
//   joint shows up directly in the component it moves.
//   Checks, per motor N:
//   - force_direction.motor<N>_lag (ms, at most lag_baseline_ms +
//     lag_excess_ms): the extra delay, 0..lag_max_ms in 1 ms steps, that
//     best fits the effect over the window (pulse + settle_ms) with the
//     amplitude left free. Clean emulator recordings show 0 ms (60 mN m,
//     50 ms pulses on each motor: the prediction already holds the scene's
//     own command delay), so lag_baseline_ms is 0; a real device's
//     transport may add a few, to be measured at bring-up and set here.
//     3 ms more than the baseline is beyond jitter at 1 kHz.
//   - force_direction.motor<N>_angle (deg, at most angle_max_deg = 25):
//     the angle between the measured and predicted effects, stacked sample
//     by sample, over the response's first initial_ms from the fitted lag
//     (longer, up to the window's end, until the prediction has moved ten
//     encoder counts: a few counts' quantization would decide the angle).
//     A sign error gives ~180 deg and motor 3 on the relative angle tens of
//     degrees; encoder quantization and a model off by tens of percent in
//     its masses give a few.
//   - force_direction.motor<N>_gain (ratio, within [gain_min, gain_max] =
//     [0.5, 2]): the least-squares amplitude of the measured effect on the
//     predicted one over the same samples. Friction or inertia off by 2x
//     is identification's business, not a fault.
//   When a check fails, alternatives are simulated and the one that fits
//   best (rms of t1..t3 over the window below hypothesis_ratio = 0.5 of the
//   nominal's) is named: motor<N>_sign (that motor's gain -1),
//   motor3_relative (motor 3 turns q3), torque_units_Nm (torques x1000,
//   then the clamps), torque_units_mNm (x0.001), delay_<M>ms (the fitted
//   lag, M its excess over lag_baseline_ms, when >= lag_excess_ms). With
//   none clearly better: gain > 10 names torque_units_Nm, gain < 0.1
//   torque_units_mNm, another gain outside the band motor<N>_gain, an
//   angle alone motor<N>_direction.
//   Measured on recordings synthesized from the closed loop (15000-count
//   encoders, 120-200 mN m pulses of 40 ms): clean 1.7-4.6 deg, gain
//   0.97-1.00, lag 0-1 ms; a reversed motor 172-177 deg; motor 3 on q3
//   68 deg and gain 3.6; readings 5 ms late a lag of 6 ms.
//   No pulse (not a motor test, or tau_sent never nonzero): every check is
//   skipped with the reason. So are they when the prediction moves t1..t3
//   less than three encoder counts (a pulse into a joint limit or below
//   the friction); the arm moving ten counts anyway still tries the
//   alternatives.
//   Figure force_direction_motor<N>.svg: t1..t3 measured and predicted
//   over the window; the same, subsampled, in detail["history"].
//
// Force mapping (compare_force_mapping, one hw run recording with F_*_N
// and dev_J_*): the recorded motor torques tau_1..3_Nm (the controller's
// J_r^T F) against the device's J_dev^T F (its linear rows mm/rad, so
// /1000 for N m), J_dev read as stored and transposed, its columns as
// device joints t1..t3 or DH joints q1..q3; the best of the four is
// reported. Check force_mapping.torque_angle_p95 (deg, at most 10) over
// good rows with |F| > 0.1 N and a torque sent: the two Jacobians are two
// codes for one arm, so beyond a few degrees one of them has a wrong sign,
// joint or frame.
#ifndef VMHAPTICS_BRINGUP_COMPARE_FORCE_H_
#define VMHAPTICS_BRINGUP_COMPARE_FORCE_H_

#include <string>

#include "bringup/compare_check.h"
#include "bringup/reading_map.h"
#include "bringup/recording.h"

namespace vmh::bringup {

struct ForceOptions {
  // the scene to predict with when the recording's meta names none
  // (meta["emulator"]["scene"]); empty: models/cases/case1.xml, the
  // emulator's default
  std::string scene;
  std::string model_file;        // a calibrated Omni (--model); empty: none
  double pre_ms = 20.0;          // before the pulse, for the initial velocity
  double settle_ms = 50.0;       // after the pulse, still compared
  double max_window_ms = 300.0;  // pulse + settle at most this
  double initial_ms = 25.0;      // the response's start: angle and gain
  double angle_max_deg = 25.0;
  double gain_min = 0.5;
  double gain_max = 2.0;
  double lag_max_ms = 30.0;
  double lag_baseline_ms = 0.0;  // a clean recording's lag (the emulator's)
  double lag_excess_ms = 3.0;
  double hypothesis_ratio = 0.5;

  // throws std::invalid_argument naming the first bad field
  void validate() const;
};

CompareSection compare_force_direction(const Recording& motor_test,
                                       const ReadingMap& readings,
                                       const ForceOptions& opts,
                                       const std::string& figure_dir);

CompareSection compare_force_mapping(const Recording& run);

}  // namespace vmh::bringup

#endif  // VMHAPTICS_BRINGUP_COMPARE_FORCE_H_
