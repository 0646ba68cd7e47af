// Synthetic device recordings for the bring-up tests, built in memory (no
// trace.csv): the joint angles a device would report and, from MuJoCo's own
// site pose and site Jacobian (not from controller/), the transform,
// velocity and Jacobian a device reports of itself. Columns and units as
// bringup/recording.h reads them.
#ifndef VMHAPTICS_TESTS_STUDIES_BRINGUP_SYNTHETIC_RECORDING_H_
#define VMHAPTICS_TESTS_STUDIES_BRINGUP_SYNTHETIC_RECORDING_H_

#include <mujoco/mujoco.h>

#include <cstdint>
#include <vector>

#include "controller/types.h"
#include "bringup/reading_map.h"
#include "bringup/recording.h"

namespace vmh::testing {

// One instant of the true motion: DH angles (q3 relative) and rates
struct SyntheticSample {
  double t_s = 0.0;
  Joints q_dh_rad = Joints::Zero();
  Joints qdot_dh_rad_s = Joints::Zero();
};

// All six joints swinging sinusoidally inside OmniParams' ranges (at most
// 70 % of each half-range about its centre), at incommensurate rates of
// 0.2-0.6 Hz: the wrist reaches a few hundred mm/s, as the tour hand
// program does. Samples every 1 / rate_hz from 0 to duration_s; delay_s
// shifts the motion (every column alike: a consistently late device).
std::vector<SyntheticSample> tour_motion(double duration_s, double rate_hz,
                                         double delay_s = 0.0);

struct SyntheticOptions {
  // round t1..t3 to encoder counts and t4..t6 to pot levels (sim/sensor_model.h)
  bool quantize = true;
  // the reported device angles: map.reported_from_true(sensed) + offset,
  // plus Gaussian noise of noise_rad (seeded) when > 0
  // and the pots t4..t6 read with these gains (reported = gain * sensed)
  bringup::ReadingMap map;
  Joints reported_offset_device_rad = Joints::Zero();
  Vec3 gimbal_gain = Vec3::Ones();
  double noise_rad = 0.0;
  std::uint32_t seed = 1;
  // which of the device's own columns to write
  bool transform = true;  // dev_p_*_mm, dev_R_rc
  bool velocity = true;   // dev_v_*_mm_s
  bool jacobian = true;   // dev_J_rc
  // dev_J stored transposed, or with DH joint columns (q) instead of device
  // joint columns (t): the layouts a real device's API might use
  bool jacobian_transposed = false;
  bool jacobian_dh_columns = false;
  // the device frame's origin off (an inkwell calibration off): added to
  // dev_p, device frame
  Vec3 origin_offset_mm = Vec3::Zero();
  // the device's own stylus-frame convention: dev_R = R_site * convention
  // (a real device numbers or signs the stylus axes its own way)
  Mat3 rotation_convention = Mat3::Identity();
};

// The recording a device would give of `motion` on model m (an Omni with
// qpos = DH angles, site "wrist"; edit it first for a longer link). Device
// frame as docs/sources.md §4 gives it, written out here: x_dev = y_base,
// y_dev = z_base + l2, z_dev = x_base - l1 with the NOMINAL l1 = l2 =
// 133.35 mm (the frame is the nominal device's). dev_R's columns are the
// site frame's axes in the device frame; dev_J rows (v mm/rad, w rad/rad)
// in the device frame. Throws std::invalid_argument naming a missing site.
bringup::Recording synthetic_recording(const mjModel* m,
                                       const std::vector<SyntheticSample>& motion,
                                       const SyntheticOptions& options = {});

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_STUDIES_BRINGUP_SYNTHETIC_RECORDING_H_
