// The OpenHaptics device frame and joint convention, and conversions to and
// from the DH base frame and DH joint angles of the thesis.
//
// Device frame: origin at the wrist centre of the DH zero pose (arm out toward
// the user, forearm hanging down), x to the user's right, y up, z toward the
// user; positions in mm. OpenHaptics reports joint 3 as the absolute forearm
// angle, and turns joints 1, 4 and 6 the other way round from the DH angles.
//
// How the mapping was found (docs/sources.md §4, checked in
// tests/controller/device_frame_test.cc): the OpenHaptics forward kinematics
//   x = -sin t1 (l1 cos t2 + l2 sin t3)
//   y = l2 - l2 cos t3 + l1 sin t2
//   z = cos t1 (l1 cos t2 + l2 sin t3) - l1
// equals eq. B.14 under
//   q1 = -t1, q2 = t2, q3 = t3 - t2,
//   x_dev = y_base, y_dev = z_base - l0 + l2, z_dev = x_base - l1.
// This rotation is proper (det +1). A first derivation paired x_dev = -y_base
// with q1 = t1, which fits the positions too but is a reflection (det -1): it
// would turn the stylus frame left-handed. See docs/errata.md.
//
// Gimbal angles (joints 4-6): t4 = -q4, t5 = q5, t6 = -q6. Source: the
// stylus rotation of Ubitrack's PhantomForwardKinematics, arm rotation times
// RotY(t4) RotX(-t5) RotZ(-t6), whose position part is the formula above.
// With these signs the DH stylus frame equals that rotation exactly, and at
// q = 0 it is the identity in the device frame. Ubitrack's printed arm
// matrix is not orthogonal; RotY(-t1) RotX(-t3) is used instead, and the DH
// chain reproduces it (docs/kinematics.md). Not yet checked on a device.
#ifndef VMHAPTICS_CONTROLLER_DEVICE_FRAME_H_
#define VMHAPTICS_CONTROLLER_DEVICE_FRAME_H_

#include "controller/omni_params.h"
#include "controller/types.h"

namespace vmh {

// Joint angles: device (OpenHaptics) convention <-> DH convention, rad.
Joints device_to_dh_joints(const Joints& q_device);
Joints dh_to_device_joints(const Joints& q_dh);

// OmniParams' joint ranges (DH) in the device convention, rad: each
// device joint's lower and upper end (t3's is q2 + q3 at the DH ends).
void device_joint_ranges(const OmniParams& params, Joints* lower_device_rad,
                         Joints* upper_device_rad);

// Torques on the three actuated joints: DH joints q1..q3 <-> motors t1..t3,
// N m. The motors drive t1..t3 (t3 the absolute forearm angle), so by equal
// power (tau_dh . dq = tau_motor . dt under the joint map above) the motor
// torques are (-tau1, tau2 - tau3, tau3), and back tau_dh =
// (-m1, m2 + m3, m3).
inline Vec3 dh_to_motor_torques(const Vec3& tau) {
  return Vec3(-tau[0], tau[1] - tau[2], tau[2]);
}
Vec3 motor_to_dh_torques(const Vec3& tau_motor_Nm);

// Rotation taking DH base-frame components to device-frame components.
// (inline, with the conversions below that the servo tick calls, so that a
// tick pays no call for a permutation)
inline Mat3 R_device_base() {
  Mat3 R;
  // rows: x_dev = y_base, y_dev = z_base, z_dev = x_base
  R << 0, 1, 0,  //
      0, 0, 1,   //
      1, 0, 0;
  return R;
}

// DH base point (m) that the device frame calls its origin: the wrist centre
// at q = 0, (l1, 0, l0 - l2) by eq. B.14
inline Vec3 device_origin_base_m(const OmniParams& p) {
  return Vec3(p.l1_m, 0.0, p.l0_m - p.l2_m);
}

// Points: DH base frame (m) <-> device frame (mm).
inline Vec3 base_to_device_mm(const OmniParams& p, const Vec3& p_base_m) {
  return kMmPerM * (R_device_base() * (p_base_m - device_origin_base_m(p)));
}
Vec3 device_mm_to_base(const OmniParams& params, const Vec3& p_device_mm);

// Free vectors (directions, forces): DH base frame <-> device frame. Units
// are unchanged.
inline Vec3 base_to_device_vector(const Vec3& v) { return R_device_base() * v; }
inline Vec3 device_to_base_vector(const Vec3& v) {
  return R_device_base().transpose() * v;
}

// Rotations (e.g. the stylus frame) expressed in the other frame.
Mat3 base_to_device_rotation(const Mat3& R_base);
Mat3 device_to_base_rotation(const Mat3& R_device);

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_DEVICE_FRAME_H_
