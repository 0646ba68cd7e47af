// Kinematics of the PHANTOM Omni in the thesis's modified (Craig) DH
// convention, Appendix B.
//
// Frames: every position and rotation here is in the DH base frame {0} of
// Table B.1 (z up along joint 1, x toward the user at q1 = 0), in metres.
// Joint angles are in the DH convention: q3 is the elbow angle relative to the
// upper arm (the device reports it absolute; see device_frame.h).
//
// The wrist centre is the common origin of frames 4, 5 and 6, where the three
// gimbal axes meet. The stylus frame is frame 6; its z axis runs along the
// stylus (pointing toward the user at q = 0). A tool point sits on that axis at
// OmniParams::tool_offset_m from the wrist centre (eq. B.7 with -L_t).
//
// None of these functions allocates or throws; all are safe in a servo loop.
#ifndef VMHAPTICS_CONTROLLER_OMNI_KINEMATICS_H_
#define VMHAPTICS_CONTROLLER_OMNI_KINEMATICS_H_

#include <array>

#include "controller/omni_params.h"
#include "controller/types.h"

namespace vmh {

// One row of Table B.1: T_{i-1,i} = RotX(alpha) TransX(a) RotZ(theta) TransZ(d)
// with theta = q_i + theta_offset.
struct DhRow {
  double a_m;
  double alpha_rad;
  double d_m;
  double theta_offset_rad;
};

// Table B.1 with the lengths of `params`.
std::array<DhRow, kOmniJoints> omni_dh_table(const OmniParams& params);

// Homogeneous transform of one DH row at joint angle q (modified DH, eq. 2.1
// with its (3,4) entry corrected to cos(alpha) d; see docs/errata.md).
Eigen::Isometry3d dh_transform(const DhRow& row, double q_rad);

// Pose of every frame in the DH base frame: frames[0] is the identity (base),
// frames[i] = T_{0,i} for i = 1..6.
struct OmniFrames {
  std::array<Eigen::Isometry3d, kOmniJoints + 1> T_base;
};

void omni_frames(const OmniParams& params, const Joints& q_dh,
                 OmniFrames* frames);

// Wrist centre position (m) and stylus frame rotation, DH base frame
// (eq. B.13-B.14).
struct OmniPose {
  Vec3 p_base_m;
  Mat3 R_base;
};

OmniPose omni_fk(const OmniParams& params, const Joints& q_dh);

// Tool point (m, DH base frame): wrist centre + tool_offset_m * z6.
Vec3 omni_tool_point(const OmniParams& params, const OmniPose& pose);

// Geometric Jacobian (eq. 2.13, B.54 corrected), DH base frame, rows
// (v_x, v_y, v_z, w_x, w_y, w_z): m/rad in rows 1-3, rad/rad in rows 4-6.
// omni_jacobian: the point is the wrist centre (columns 4-6 have zero linear
// part). omni_jacobian_at: a point offset_m along the stylus axis z6.
Mat6 omni_jacobian(const OmniParams& params, const Joints& q_dh);
Mat6 omni_jacobian_at(const OmniParams& params, const Joints& q_dh,
                      double offset_m);

// FK and the Jacobian in one pass: the closed form of the chain of
// Table B.1's products (derived in docs/kinematics.md), with the sines and
// cosines of q1..q6 computed once and shared, and no 4 x 4 products. Equal to
// omni_fk and omni_jacobian_at (which compose the chain, omni_frames) within
// 1e-12 (tests/controller/omni_kinematics_one_pass_test.cc). *J (optional)
// is the geometric Jacobian at the point offset_m along z6, as
// omni_jacobian_at. The sines and cosines come from sin_cos
// (controller/trig.h).
void omni_fk_jacobian(const OmniParams& params, const Joints& q_dh,
                      OmniPose* pose, Mat6* J, double offset_m = 0.0);

// What a servo tick needs of the arm, in one pass over q1..q3 and the
// stylus axis: the wrist centre (m), the stylus axis z6 (the third column of
// omni_fk's R_base) and the wrist centre's linear Jacobian for q1..q3 (the
// top-left 3 x 3 of omni_jacobian, m/rad), all in the DH base frame.
struct OmniArmKinematics {
  Vec3 p_base_m;
  Vec3 z6_base;
  Mat3 Jv_arm;
};
OmniArmKinematics omni_arm_kinematics(const OmniParams& params,
                                      const Joints& q_dh);

// -- inverse kinematics (Pieper: the wrist centre fixes q1..q3, the
// orientation then fixes q4..q6; eq. B.15-B.53 re-derived, see docs) --

enum class IkStatus {
  kOk = 0,
  kUnreachable,   // no joint angles put the wrist centre there
  kInvalidInput,  // a non-finite target or hint, or a hint beyond kIkMaxHintRad
};

// The largest |angle| of an IK hint (`near`), rad. Solutions are shifted by
// whole turns to lie within pi of the hint, and beyond about 1e4 rad that
// shift loses the angle to rounding (near 1e17 rad a double cannot hold an
// angle at all), so a larger hint is refused as invalid input.
inline constexpr double kIkMaxHintRad = 1e4;

const char* ik_status_name(IkStatus status);

// Every solution of a wrist-centre or full-pose problem. Position problems
// have up to 4 (two shoulder branches x two elbow branches), pose problems up
// to 8 (x two wrist branches). Degenerate branches are merged.
struct IkSolutions {
  static constexpr int kMax = 8;
  std::array<Joints, kMax> q_dh;
  std::array<bool, kMax> within_limits;  // inside OmniParams joint ranges
  int count = 0;
  IkStatus status = IkStatus::kInvalidInput;
  // distance (m) by which the target lies outside the reachable shell
  // (|r| > l1 + l2 or |r| < |l1 - l2|); 0 when reachable
  double reach_excess_m = 0.0;
  // the wrist centre is on the joint-1 axis: q1 is free and taken from `near`
  bool shoulder_singular = false;
  // the wrist centre is on the reach boundary: the elbow branches coincide
  bool elbow_singular = false;
  // q5 = +-pi/2: q4 and q6 turn about one axis; q4 is taken from `near`
  bool wrist_singular = false;
};

// All joint solutions that put the wrist centre at p_base_m. q4..q6 of every
// solution are copied from `near`. Each angle is shifted by whole turns to lie
// within pi of the matching angle of `near`.
IkSolutions omni_ik_position(const OmniParams& params, const Vec3& p_base_m,
                             const Joints& near);

// All solutions for a wrist-centre position and a stylus-frame rotation R_base
// (a proper rotation, DH base frame).
IkSolutions omni_ik_pose(const OmniParams& params, const Vec3& p_base_m,
                         const Mat3& R_base, const Joints& near);

// Index of the solution nearest `near` (sum of squared angle differences,
// each wrapped to (-pi, pi]); -1 when there is none.
int omni_ik_nearest(const IkSolutions& solutions, const Joints& near);

// The wrist angles q4..q6 that give the stylus frame R_base for arm angles
// q1..q3. Writes up to 2 solutions; returns how many (0 for non-finite input).
// Sets *singular when q5 = +-pi/2, where q4 is taken from q4_hint.
int omni_wrist_angles(const OmniParams& params, const Eigen::Vector3d& q123,
                      const Mat3& R_base, double q4_hint,
                      std::array<Eigen::Vector3d, 2>* q456, bool* singular);

// Wraps an angle to (-pi, pi]. Non-finite input is returned unchanged.
// The common case, an angle already in range (two comparisons), is inline:
// the servo tick wraps five angles; the rest is out of line.
double wrap_angle_out_of_range(double a_rad);
inline double wrap_angle(double a_rad) {
  constexpr double kPi = 3.14159265358979323846;
  if (a_rad > -kPi && a_rad <= kPi) return a_rad;
  return wrap_angle_out_of_range(a_rad);
}

// Whether every joint angle, wrapped to (-pi, pi], lies inside the joint
// ranges of `params` (DH convention). False for non-finite angles.
bool omni_within_limits(const OmniParams& params, const Joints& q_dh);

}  // namespace vmh

#endif  // VMHAPTICS_CONTROLLER_OMNI_KINEMATICS_H_
