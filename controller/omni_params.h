// Parameters of the PHANTOM Omni: geometry, joint ranges and ratings.
//
// All of the device's numbers live here, each with its source. Lengths are in
// metres, angles in radians in the DH convention of the thesis (Table B.1;
// joint 3 relative to joint 2), torques in N·m, forces in N.
//
// Sources (see docs/omni.md for the reasoning behind each estimate):
//   [ubitrack] Ubitrack component_haptic_calibration,
//              PhantomForwardKinematics.cpp, "Phantom Omni defaults".
//   [urdf]     omni_description/urdf/omni.urdf (ROS phantom_omni family) and
//              the ROS omni_state.cpp joint mapping that publishes it.
//   [oh]       OpenHaptics sample torque clamps and the Omni data sheet.
//   [tsutano]  Y. Tsutano's raw Omni driver (encoder resolution).
//   [hd]       OpenHaptics inkwell pose (0, -65.51, -88.11) mm, device frame.
#ifndef VMHAPTICS_CONTROLLER_OMNI_PARAMS_H_
#define VMHAPTICS_CONTROLLER_OMNI_PARAMS_H_

#include <array>
#include <string>

namespace vmh {

inline constexpr int kOmniJoints = 6;
inline constexpr int kOmniActuated = 3;

struct OmniParams {
  // -- geometry (Table B.1) --
  // height of joint 2 above the DH base; the base frame sits at the shoulder,
  // so 0 [docs/sources.md §4]
  double l0_m = 0.0;
  // upper arm, shoulder axis to elbow axis [ubitrack]
  double l1_m = 0.13335;
  // forearm, elbow axis to the wrist centre (gimbal intersection) [ubitrack]
  double l2_m = 0.13335;
  // signed distance from the wrist centre to the tool point along the stylus
  // axis z6; eq. B.7 uses -L_t. 0 puts the tool point at the wrist centre.
  double tool_offset_m = 0.0;

  // -- joint ranges, DH convention (q3 relative to q2) --
  // q1 from [urdf] waist; q2 upper and q3 from [urdf] shoulder/elbow; q2
  // lower widened from the URDF's 0 so that the inkwell pose (q2 = -0.65)
  // and the observed reach y = -112 mm (q2 = -1.03) fit [hd]; the gimbal
  // ranges are the URDF's widths centred on the DH zero, an estimate.
  // docs/omni.md gives the reasoning.
  std::array<double, kOmniJoints> joint_lower_rad = {-0.98, -1.05, -0.81,
                                                     -2.45, -1.13, -2.58};
  std::array<double, kOmniJoints> joint_upper_rad = {0.98, 1.75, 1.25,
                                                     2.45, 1.13, 2.58};

  // -- ratings --
  // motor torque clamps of the three actuated joints [oh]: 200, 350, 200
  // mN·m, the OpenHaptics samples' (TorqueLimits::kOpenHapticsSamples). The
  // limits derived from the rated force, 0.44 N·m each, are
  // TorqueLimits::kRated (controller/omni_ratings.h, docs/safety.md).
  std::array<double, kOmniActuated> motor_torque_limit_Nm = {0.200, 0.350,
                                                             0.200};
  double max_force_N = 3.3;          // peak force at nominal position [oh]
  double continuous_force_N = 0.88;  // continuous force [oh]

  // -- sensing --
  double encoder_counts_per_rev = 15000.0;  // actuated joints [tsutano]
  int gimbal_pot_bits = 11;                 // valid bits of a pot ratio

  // Throws std::invalid_argument naming the first bad field (non-finite,
  // non-positive length, lower >= upper, ...). Setup time only.
  void validate() const;
};

// Name of joint i (0-based) in the DH convention: "q1".."q6".
const char* joint_name(int i);

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_OMNI_PARAMS_H_
