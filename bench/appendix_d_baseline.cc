#include "bench/appendix_d_baseline.h"

#include <cmath>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"

namespace vmh::appendix_d {
namespace {

constexpr float kPiF = 3.14159265358979323846f;

// correction: the listing subtracts raw angles; the controller (and any
// sensible reading of eq. 3.36/3.37) wraps the difference to (-pi, pi]
float wrap_difference(float a) {
  if (a > kPiF) return a - 2.0f * kPiF;
  if (a <= -kPiF) return a + 2.0f * kPiF;
  return a;
}

// correction: float rounding can put |x| a hair above 1, where acos is NaN
float clamp_unit(float x) { return x < -1.0f ? -1.0f : (x > 1.0f ? 1.0f : x); }

// Listing D.1's per-tick matrices and listing D.2, for a 6 x M Jacobian:
// every intermediate product is formed, in the listing's order, with the
// generic routines. perror is the 6 x 1 error eerror.
template <int M>
bool listing_d2(const Settings& s, const float (&Jv)[kN][M],
                const float (&eerror)[kN], float (&fmotion_out)[kN]) {
  constexpr int n = kN;
  constexpr int m = M;
  constexpr int p = 1;
  // listing D.1, lines 18-40
  float JvT[m][n];
  float JvTWA[m][n];
  float JvTWAJv[m][m];
  float JvTWAJvinv[m][m];
  float JvTWAJvinv_JvT[m][n];
  float Jv_JvTWAJvinv_JvT[n][n];
  float WAJv_JvTWAJvinv_JvT[n][n];
  float IminusWAJv_JvTWAJvinv_JvT[n][n];
  float Kpe[n][p];
  float fmotion[n][p];
  const float perror[n][p] = {{eerror[0]}, {eerror[1]}, {eerror[2]},
                              {eerror[3]}, {eerror[4]}, {eerror[5]}};
  const float I[n][n] = {{1, 0, 0, 0, 0, 0}, {0, 1, 0, 0, 0, 0},
                         {0, 0, 1, 0, 0, 0}, {0, 0, 0, 1, 0, 0},
                         {0, 0, 0, 0, 1, 0}, {0, 0, 0, 0, 0, 1}};
  const float WA[n][n] = {{1, 0, 0, 0, 0, 0}, {0, 1, 0, 0, 0, 0},
                          {0, 0, 1, 0, 0, 0}, {0, 0, 0, 1, 0, 0},
                          {0, 0, 0, 0, 1, 0}, {0, 0, 0, 0, 0, 1}};
  const float Kp1 = s.Kp;
  const float gain = s.gain;
  const float kkp[n][n] = {{Kp1, 0, 0, 0, 0, 0},  {0, Kp1, 0, 0, 0, 0},
                           {0, 0, Kp1, 0, 0, 0},  {0, 0, 0, gain, 0, 0},
                           {0, 0, 0, 0, gain, 0}, {0, 0, 0, 0, 0, gain}};

  // listing D.2: f = (I - WA Jv (Jv^T WA Jv)^-1 Jv^T) (kkp perror)
  matrix_transpose(&Jv[0][0], n, m, &JvT[0][0]);
  matrix_multiply(&JvT[0][0], &WA[0][0], m, n, n, &JvTWA[0][0]);
  matrix_multiply(&JvTWA[0][0], &Jv[0][0], m, n, m, &JvTWAJv[0][0]);
  const bool ok = matrix_inversion(&JvTWAJv[0][0], m, &JvTWAJvinv[0][0]);
  if (!ok) return false;
  matrix_multiply(&JvTWAJvinv[0][0], &JvT[0][0], m, m, n,
                  &JvTWAJvinv_JvT[0][0]);
  matrix_multiply(&Jv[0][0], &JvTWAJvinv_JvT[0][0], n, m, n,
                  &Jv_JvTWAJvinv_JvT[0][0]);
  matrix_multiply(&WA[0][0], &Jv_JvTWAJvinv_JvT[0][0], n, n, n,
                  &WAJv_JvTWAJvinv_JvT[0][0]);
  matrix_subtraction(&I[0][0], &WAJv_JvTWAJvinv_JvT[0][0], n, n,
                     &IminusWAJv_JvTWAJvinv_JvT[0][0]);
  matrix_multiply(&kkp[0][0], &perror[0][0], n, n, p, &Kpe[0][0]);
  matrix_multiply(&IminusWAJv_JvTWAJvinv_JvT[0][0], &Kpe[0][0], n, n, p,
                  &fmotion[0][0]);
  for (int i = 0; i < n; ++i) fmotion_out[i] = fmotion[i][0];
  return true;
}

}  // namespace

// ------------------------------------------------------ matrix routines

void matrix_transpose(const float* a, int rows, int cols, float* out) {
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) out[j * rows + i] = a[i * cols + j];
  }
}

void matrix_multiply(const float* a, const float* b, int rows_a, int cols_a,
                     int cols_b, float* out) {
  for (int i = 0; i < rows_a; ++i) {
    for (int j = 0; j < cols_b; ++j) {
      float sum = 0.0f;
      for (int k = 0; k < cols_a; ++k) {
        sum += a[i * cols_a + k] * b[k * cols_b + j];
      }
      out[i * cols_b + j] = sum;
    }
  }
}

bool matrix_inversion(const float* a, int n, float* out) {
  if (n < 1 || n > kMaxDim) return false;
  // the augmented matrix [a | I], n x 2n, row-major
  float work[kMaxDim][2 * kMaxDim];
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      work[i][j] = a[i * n + j];
      work[i][n + j] = i == j ? 1.0f : 0.0f;
    }
  }
  for (int col = 0; col < n; ++col) {
    // partial pivoting: the largest magnitude in this column, on or below
    // the diagonal
    int pivot = col;
    for (int r = col + 1; r < n; ++r) {
      if (std::fabs(work[r][col]) > std::fabs(work[pivot][col])) pivot = r;
    }
    if (work[pivot][col] == 0.0f) return false;
    if (pivot != col) {
      for (int j = 0; j < 2 * n; ++j) {
        const float t = work[col][j];
        work[col][j] = work[pivot][j];
        work[pivot][j] = t;
      }
    }
    const float scale = 1.0f / work[col][col];
    for (int j = 0; j < 2 * n; ++j) work[col][j] *= scale;
    // clear the column in every other row
    for (int r = 0; r < n; ++r) {
      if (r == col) continue;
      const float factor = work[r][col];
      if (factor == 0.0f) continue;
      for (int j = 0; j < 2 * n; ++j) work[r][j] -= factor * work[col][j];
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) out[i * n + j] = work[i][n + j];
  }
  return true;
}

void matrix_subtraction(const float* a, const float* b, int rows, int cols,
                        float* out) {
  for (int i = 0; i < rows * cols; ++i) out[i] = a[i] - b[i];
}

// ------------------------------------------------------------- the listing

Settings make_settings(float Kp_N_per_mm, float Lv_mm) {
  Settings s;
  s.Lv = Lv_mm;
  s.Kp = Kp_N_per_mm;
  // correction: eq. 3.28's 2 pi L (the listing has Kp1 * 3.14 * Lv[0])
  s.gain = Kp_N_per_mm * 2.0f * kPiF * Lv_mm;
  return s;
}

void circle_law(const Settings& s, const DeviceState& state, LawResult* out) {
  const float* position = state.position;
  const float* pivotLoc = s.pivotLoc;
  const float Lv = s.Lv;
  // listing D.4: angle of the RM about the pivot, and of the stylus axis
  const float thetaV1 =
      std::atan2(position[1] - pivotLoc[1], position[0] - pivotLoc[0]);
  const float thetaR1 = std::atan2(state.transform_z[1], state.transform_z[0]);

  float eerror[kN];
  eerror[0] = pivotLoc[0] + Lv * std::cos(thetaV1) - position[0];
  eerror[1] = pivotLoc[1] + Lv * std::sin(thetaV1) - position[1];
  eerror[2] = pivotLoc[2] - position[2];
  eerror[3] = 0.0f;
  eerror[4] = 0.0f;
  eerror[5] = wrap_difference(thetaV1 - thetaR1);  // correction: wrapped

  float JV[kN];
  JV[0] = -Lv * std::sin(thetaV1);
  JV[1] = Lv * std::cos(thetaV1);
  JV[2] = 0.0f;
  JV[3] = 0.0f;
  JV[4] = 0.0f;
  JV[5] = 1.0f;
  // correction of order: filled after JV (the listing fills it before)
  const float Jv[kN][1] = {{JV[0]}, {JV[1]}, {JV[2]},
                           {JV[3]}, {JV[4]}, {JV[5]}};

  out->m = 1;
  out->thetaV[0] = thetaV1;
  out->thetaV[1] = 0.0f;
  out->thetaR[0] = thetaR1;
  out->thetaR[1] = 0.0f;
  for (int i = 0; i < kN; ++i) {
    out->eerror[i] = eerror[i];
    out->Jv[i] = Jv[i][0];
  }
  out->inverted = listing_d2<1>(s, Jv, eerror, out->fmotion);
}

void sphere_law(const Settings& s, const DeviceState& state, LawResult* out) {
  const float* position = state.position;
  const float* transform_z = state.transform_z;
  const float* pivotLoc = s.pivotLoc;
  const float Lv = s.Lv;
  const float dx = position[0] - pivotLoc[0];
  const float dy = position[1] - pivotLoc[1];
  const float dz = position[2] - pivotLoc[2];
  // listing D.5: distance of the RM from the pivot
  const float LL = std::sqrt(dx * dx + dy * dy + dz * dz);

  // correction: pi - acos (§3.4.1), not -PI - acos; acos argument clamped
  const float thetaV1 = std::atan2(dy, dx);
  const float thetaV2 = kPiF - std::acos(clamp_unit(dz / LL));
  const float thetaR1 = std::atan2(transform_z[1], transform_z[0]);
  const float thetaR2 = kPiF - std::acos(clamp_unit(transform_z[2]));

  const float s1 = std::sin(thetaV1), c1 = std::cos(thetaV1);
  const float s2 = std::sin(thetaV2), c2 = std::cos(thetaV2);
  float eerror[kN];
  eerror[0] = pivotLoc[0] + Lv * s2 * c1 - position[0];
  // correction: the listing adds pivotLoc[1] twice here
  eerror[1] = pivotLoc[1] + Lv * s2 * s1 - position[1];
  eerror[2] = pivotLoc[2] - Lv * c2 - position[2];
  eerror[3] = 0.0f;
  eerror[4] = wrap_difference(thetaV2 - thetaR2);  // correction: wrapped
  eerror[5] = wrap_difference(thetaV1 - thetaR1);  // correction: wrapped

  // eq. 3.31
  float Jva[9];
  Jva[0] = -Lv * s1 * s2;
  Jva[1] = Lv * c1 * c2;
  Jva[2] = 0.0f;
  Jva[3] = Lv * c1 * s2;
  Jva[4] = Lv * s1 * c2;
  Jva[5] = 0.0f;
  Jva[6] = 0.0f;
  Jva[7] = Lv * s2;
  Jva[8] = 0.0f;
  float Jvb[9];
  Jvb[0] = 0.0f;
  Jvb[1] = s1;
  Jvb[2] = c1 * s2;
  Jvb[3] = 0.0f;
  Jvb[4] = -c1;
  Jvb[5] = s1 * s2;
  Jvb[6] = 1.0f;
  Jvb[7] = 0.0f;
  Jvb[8] = -c2;
  const float Jv[kN][3] = {{Jva[0], Jva[1], Jva[2]}, {Jva[3], Jva[4], Jva[5]},
                           {Jva[6], Jva[7], Jva[8]}, {Jvb[0], Jvb[1], Jvb[2]},
                           {Jvb[3], Jvb[4], Jvb[5]}, {Jvb[6], Jvb[7], Jvb[8]}};

  out->m = 3;
  out->thetaV[0] = thetaV1;
  out->thetaV[1] = thetaV2;
  out->thetaR[0] = thetaR1;
  out->thetaR[1] = thetaR2;
  for (int i = 0; i < kN; ++i) {
    out->eerror[i] = eerror[i];
    for (int j = 0; j < 3; ++j) out->Jv[i * 3 + j] = Jv[i][j];
  }
  out->inverted = listing_d2<3>(s, Jv, eerror, out->fmotion);
}

// ----------------------------------------------------- a whole servo tick

DeviceState device_state_from_joints(const OmniParams& params,
                                     const Joints& q_dh) {
  const OmniPose pose = omni_fk(params, q_dh);
  const Vec3 p = base_to_device_mm(params, pose.p_base_m);
  const Vec3 z = base_to_device_vector(pose.R_base.col(2));
  DeviceState state;
  for (int i = 0; i < 3; ++i) {
    state.position[i] = static_cast<float>(p[i]);
    state.transform_z[i] = static_cast<float>(z[i]);
  }
  return state;
}

void baseline_tick(const OmniParams& params, const Settings& s,
                   Mechanism mechanism, const Joints& q_dh, TickResult* out) {
  const DeviceState state = device_state_from_joints(params, q_dh);
  if (mechanism == Mechanism::kCircle) {
    circle_law(s, state, &out->law);
  } else {
    sphere_law(s, state, &out->law);
  }
  // listing D.3: rows 0-2 are the device force
  const float* f = out->law.fmotion;
  out->force_device_N = Vec3(f[0], f[1], f[2]);
  // eq. 3.12 (done by OpenHaptics for the listing): tau = J_r^T F
  const Vec3 F_base = device_to_base_vector(out->force_device_N);
  const Mat6 Jr = omni_jacobian(params, q_dh);
  out->tau_dh_Nm = Jr.topLeftCorner<3, 3>().transpose() * F_base;
}

}  // namespace vmh::appendix_d
