// compare's closed-loop analyses of a `hw run` recording: did the device's
// servo loop compute what the project's controller computes from the same
// readings (replay), and does the run look like the simulated run of the
// same scene (simulation).
//
// Replay (exact). The scene's ControllerParams are rebuilt as hw run built
// them: sim::ClosedLoop(scene, overrides).controller_params() with every
// gain multiplied by the gain scale. The scene is meta["scene"]; the
// overrides are meta["sets"] (when a later hw run writes them) followed by
// ReplayOptions::overrides; the gain scale is ReplayOptions::gain_scale
// when given, else meta["gain_scale"], else DIR/summary.json's
// "gain_scale", else 1. hw run's meta.json of this writing holds neither
// the --set overrides nor the gain scale: give them as options.
// A fresh Controller ticks on every row in order, as servo_tick did: a row
// whose read failed (read_error not "ok" or a NaN angle) resets it and
// expects zero; a controller fault or a failed write (write_error not
// "ok") expects zero; otherwise the motor torques tau_motor_Nm.
//   - closed_loop.replay_torque_error_max (mN m, at most 1e-3): the largest
//     |recorded - replayed| over the rows and motors. The trace prints
//     angles and torques with 9 significant digits, which moves the
//     replayed torques by ~1e-5 mN m; any real difference (a gain, a
//     placement, a frame) is far larger. detail names the first row over
//     the threshold (index from 0, t_s, both torques).
//
// Simulation (statistical). The scene run by sim::ClosedLoop for the
// recording's duration with the same overrides and gain scale, its hand
// playing the scene's script; a real hand is not that hand, so only the
// statistics are compared:
//   - closed_loop.error_rms_ratio (recorded / simulated RMS of |e_1..3_mm|,
//     the position error, controller length unit, device frame)
//   - closed_loop.force_rms_ratio (recorded / simulated RMS of |F|, N,
//     device frame)
//   each passing within [0.5, 2]: a person's grip and path may differ from
//   the script's by tens of percent; a factor of two points at gains,
//   units or a force that does not reach the hand.
// Faults named when a check fails: controller_mismatch (the replay: the
// device ran other parameters, or other code, than the scene's),
// closed_loop_error_level and closed_loop_force_level (the statistics).
// Figure closed_loop.svg: |e| and |F| over time, recorded and simulated.
// A recording that is not a hw run, or lacks the columns, skips its checks
// with the reason.
#ifndef VMHAPTICS_BRINGUP_COMPARE_REPLAY_H_
#define VMHAPTICS_BRINGUP_COMPARE_REPLAY_H_

#include <cmath>
#include <string>
#include <vector>

#include "bringup/compare_check.h"
#include "bringup/recording.h"

namespace vmh::bringup {

struct ReplayOptions {
  std::string scene;                   // empty: meta["scene"]
  std::vector<std::string> overrides;  // hw run's --set, name=value
  double gain_scale = std::nan("");    // NaN: from the recording, else 1
  double torque_error_max_mNm = 1e-3;
  double ratio_min = 0.5;
  double ratio_max = 2.0;
  bool simulate = true;  // run the scene for the statistical checks

  // throws std::invalid_argument naming the first bad field
  void validate() const;
};

CompareSection compare_closed_loop(const Recording& run,
                                   const ReplayOptions& opts,
                                   const std::string& figure_dir);

}  // namespace vmh::bringup

#endif  // VMHAPTICS_BRINGUP_COMPARE_REPLAY_H_
