// The map from motor torques to the force they make at the wrist centre,
// shared by the safety layer (its force clamp) and the OpenHaptics backend
// (its force mode, which sends HD_CURRENT_FORCE in place of joint torques).
//
// The force F (device frame, N) is the one whose joint torques J_v^T F (J_v
// the linear rows of the wrist-centre Jacobian, DH base frame, m/rad) equal
// the motor torques taken to the DH joints by equal power
// (controller/device_frame.h). Near a singularity J_v^T F = tau has no exact
// solution; damped least squares, F = (J_v J_v^T + d^2 I)^-1 J_v tau_dh,
// keeps F finite and changes it by about (d / sigma_min)^2 relative
// elsewhere (sigma_min the smallest singular value of J_v).
#ifndef VMHAPTICS_DEVICE_MOTOR_FORCE_MAP_H_
#define VMHAPTICS_DEVICE_MOTOR_FORCE_MAP_H_

#include "controller/omni_params.h"
#include "controller/types.h"

namespace vmh {

// The 3x3 matrix M with F_device_N = M tau_motor_Nm at device joint angles
// q_device_rad (t1..t6, t3 absolute). damping_m >= 0. Never allocates or
// throws; non-finite angles give a non-finite matrix.
Mat3 motor_torque_to_force_map(const OmniParams& omni,
                               const Joints& q_device_rad,
                               double damping_m) noexcept;

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_MOTOR_FORCE_MAP_H_
