// A baseline for bench/controller_bench.cc: the control computation of the
// thesis's Appendix D (listings D.1-D.5), re-implemented in the style it was
// written in - plain `float` arrays and generic, size-parameterised matrix
// routines after Dan Simon's "Kalman Filtering" (Embedded Systems
// Programming, 2001), which the listing calls.
//
// It is not the project's controller and nothing outside bench/ uses it. It
// exists to answer "what does the Eigen controller cost next to what the
// thesis ran on the device?", so it computes the same f_motion as
// vmh::Controller in its default settings (thesis error formulation, mm,
// W_A = I, pivot at the device origin, L = 50 mm, e_dot unused). For that it
// departs from the printed listing where the listing disagrees with the
// thesis text (each departure is marked "correction" in the .cc):
//   - gain = Kp * 2 pi L (eq. 3.28), not the listing's Kp * 3.14 * L;
//   - D.5 line 19 adds pivotLoc[1] twice; here once (eq. 3.30);
//   - theta_V2 = pi - acos(.) and theta_R2 = pi - acos(.) as in §3.4.1, not
//     the listing's -PI - acos(.) (same position and Jacobian; the angle
//     difference is the same too, but this keeps theta_V2 in [0, pi] as the
//     controller reports it);
//   - angle differences are wrapped to (-pi, pi] (the listing subtracts raw
//     atan2 results, which jumps by 2 pi where the two straddle +-pi);
//   - acos arguments are clamped to [-1, 1] (float rounding can exceed 1);
//   - perror and Jv are filled after eerror and JV are computed (the listing
//     initialises them before, which as printed would use stale values).
//
// The listing reads the wrist position and the stylus transform from
// OpenHaptics (hdGetDoublev). Here device_state_from_joints gets them from
// the project's own forward kinematics, so that a baseline tick pays for the
// same FK as Controller::tick; baseline_tick also pays for the torque
// mapping tau = J_r^T F (vmh::omni_jacobian's top-left 3 x 3, force taken to
// the DH base frame) that Controller::tick does and OpenHaptics did for the
// listing. It does not saturate force or torque and reports no status.
#ifndef VMHAPTICS_BENCH_APPENDIX_D_BASELINE_H_
#define VMHAPTICS_BENCH_APPENDIX_D_BASELINE_H_

#include "controller/omni_params.h"
#include "controller/types.h"

namespace vmh::appendix_d {

// rows of the task-space vectors (listing D.1's n)
inline constexpr int kN = 6;
// largest matrix the generic routines accept (rows, columns, inverse size)
inline constexpr int kMaxDim = 6;

// ------------------------------------------- generic matrix routines (float)
// All matrices are dense and row-major, passed as float* with their sizes,
// as the listing passes (float*) casts of 2-D arrays.

// out (cols x rows) = a^T, a is rows x cols
void matrix_transpose(const float* a, int rows, int cols, float* out);
// out (rows_a x cols_b) = a (rows_a x cols_a) * b (cols_a x cols_b)
void matrix_multiply(const float* a, const float* b, int rows_a, int cols_a,
                     int cols_b, float* out);
// out (n x n) = a^-1 by Gauss-Jordan elimination with partial pivoting on
// [a | I]; n <= kMaxDim. Returns false (out untouched) if a pivot is 0.
bool matrix_inversion(const float* a, int n, float* out);
// out = a - b, all rows x cols
void matrix_subtraction(const float* a, const float* b, int rows, int cols,
                        float* out);

// ------------------------------------------------------------- the listing

// Listing D.1's settings.
struct Settings {
  float pivotLoc[3] = {0.0f, 0.0f, 0.0f};  // device frame, mm
  float Lv = 50.0f;                        // mm
  float Kp = 0.5f;                         // N/mm
  float gain = 0.0f;                       // N mm/rad, see make_settings
};
// gain = Kp * 2 pi Lv (eq. 3.28; correction of the listing's 3.14)
Settings make_settings(float Kp_N_per_mm, float Lv_mm);

// What the servo callback reads from the device: state.position (wrist
// centre, device frame, mm) and state.transform[8..10] (the stylus z axis,
// the third column of the column-major 4 x 4 stylus transform).
struct DeviceState {
  float position[3] = {0.0f, 0.0f, 0.0f};
  float transform_z[3] = {0.0f, 0.0f, 1.0f};
};

// One evaluation of listing D.4 or D.5 followed by D.2.
struct LawResult {
  int m = 0;                         // VM degrees of freedom (1 or 3)
  float thetaV[2] = {0.0f, 0.0f};    // theta_V1, theta_V2 (sphere)
  float thetaR[2] = {0.0f, 0.0f};    // theta_R1, theta_R2 (sphere)
  float eerror[kN] = {};             // e = X_V - X_R (mm, rad)
  float Jv[kN * 3] = {};             // 6 x m, row-major
  float fmotion[kN] = {};            // N (rows 0-2), N mm (rows 3-5)
  bool inverted = false;             // matrix_inversion succeeded
};

// 1-DOF circle in the device x-y plane about pivotLoc (listing D.4)
void circle_law(const Settings& s, const DeviceState& state, LawResult* out);
// 3-DOF sphere about pivotLoc (listing D.5)
void sphere_law(const Settings& s, const DeviceState& state, LawResult* out);

// ----------------------------------------------------- a whole servo tick

// Stand-in for OpenHaptics's HD_CURRENT_POSITION / HD_CURRENT_TRANSFORM:
// vmh::omni_fk, vmh::base_to_device_mm and
// vmh::base_to_device_vector(pose.R_base.col(2)), rounded to float.
DeviceState device_state_from_joints(const OmniParams& params,
                                     const Joints& q_dh);

enum class Mechanism { kCircle, kSphere };

struct TickResult {
  LawResult law;
  Vec3 force_device_N = Vec3::Zero();  // fmotion rows 0-2 (listing D.3)
  Vec3 tau_dh_Nm = Vec3::Zero();       // J_r^T F, DH joints q1..q3
};

// FK, the law, and tau = J_r^T F with J_r = omni_jacobian's top-left 3 x 3
// and F = device_to_base_vector(force_device_N).
void baseline_tick(const OmniParams& params, const Settings& s,
                   Mechanism mechanism, const Joints& q_dh, TickResult* out);

}  // namespace vmh::appendix_d

#endif  // VMHAPTICS_BENCH_APPENDIX_D_BASELINE_H_
