// The Omni's motor torque limits from its rated force (docs/safety.md,
// "Torque limits from the rated force").
//
// The data sheet rates the Omni by forces at the stylus (3.3 N peak, 0.88 N
// continuous, "at the nominal position", docs/sources.md §7), not by motor
// torques. A motor's torque for a force F at the wrist centre is
// tau_motor = D J_v^T F_base (eq. 3.12 with D the DH-to-motor map of
// device_frame.h), so at a pose the largest torque motor i needs for a
// force of magnitude |F| in any direction is |F| times the norm of row i of
// D J_v^T. At the nominal pose (DH q = 0: upper arm level, forearm vertical,
// the device origin) the three rows are orthogonal with norms l1, l1, l2,
// so a limit of |F| times that norm lets the rated force through along any
// direction there, and no more along the motor's own worst direction.
//
// The OpenHaptics sample clamps (200, 350, 200 mN·m) are kept as a named
// choice: they are what the vendor's examples send, and they cap the force
// at the nominal pose at 1.50 N along device x and z.
#ifndef VMHAPTICS_CONTROLLER_OMNI_RATINGS_H_
#define VMHAPTICS_CONTROLLER_OMNI_RATINGS_H_

#include <array>
#include <string>

#include "controller/omni_params.h"
#include "controller/types.h"

namespace vmh {

// Which motor torque limits: derived from the rated peak force (default),
// or the OpenHaptics samples' clamps.
enum class TorqueLimits { kRated, kOpenHapticsSamples };

// t1..t3, N m: the clamps in the OpenHaptics SDK's samples [oh]
inline constexpr std::array<double, kOmniActuated>
    kOpenHapticsSampleTorqueLimit_Nm = {0.200, 0.350, 0.200};

// "rated" or "openhaptics_samples"
const char* torque_limits_name(TorqueLimits t);
// The inverse; throws std::invalid_argument naming the text and the words.
TorqueLimits parse_torque_limits(const std::string& text);

// Per motor t1..t3, the torque a unit force in that motor's worst direction
// at the wrist centre needs at the DH pose q_dh: |row i of D J_v^T|, m (N m
// per N).
Vec3 motor_torque_per_force_m(const OmniParams& omni, const Joints& q_dh);

// force_N times motor_torque_per_force_m at the nominal pose (DH q = 0): the
// smallest limits that let `force_N` through in every direction there.
std::array<double, kOmniActuated> motor_torques_for_force_Nm(const OmniParams& omni,
                                                            double force_N);

// The limits `t` names for this Omni: motor_torques_for_force_Nm(omni,
// omni.max_force_N), or the sample clamps.
std::array<double, kOmniActuated> motor_torque_limits_Nm(const OmniParams& omni,
                                                         TorqueLimits t);

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_OMNI_RATINGS_H_
