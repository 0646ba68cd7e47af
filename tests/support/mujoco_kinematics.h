// Reading an MJCF Omni's kinematics out of MuJoCo, for the tests that hold
// the controller's FK and Jacobian against it (tests/controller's chain
// built from Table B.1, tests/models' omni.xml). Assumes qpos[0..5] are
// q1..q6 (DH) and nv = 6.
#ifndef VMHAPTICS_TESTS_SUPPORT_MUJOCO_KINEMATICS_H_
#define VMHAPTICS_TESTS_SUPPORT_MUJOCO_KINEMATICS_H_

#include <mujoco/mujoco.h>

#include <algorithm>

#include "controller/omni_kinematics.h"
#include "controller/types.h"

namespace vmh::testing {

using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
using RowJac = Eigen::Matrix<double, 3, kOmniJoints, Eigen::RowMajor>;

// the largest absolute entry of a - b
template <typename A, typename B>
double max_abs_diff(const Eigen::MatrixBase<A>& a,
                    const Eigen::MatrixBase<B>& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

// puts q into qpos and runs the position stages mj_jacSite depends on:
// frames, then the com-based quantities (docs/sources.md §12)
inline void set_joints(const mjModel* m, mjData* d, const Joints& q) {
  for (int i = 0; i < kOmniJoints; ++i) d->qpos[i] = q[i];
  mj_kinematics(m, d);
  mj_comPos(m, d);
}

inline Vec3 site_pos(const mjData* d, int site) {
  return Eigen::Map<const Vec3>(d->site_xpos + 3 * site);
}

inline Mat3 site_rot(const mjData* d, int site) {
  return Eigen::Map<const RowMat3>(d->site_xmat + 9 * site);
}

// mj_jacSite as one 6 x 6 matrix: linear rows over angular rows, the layout
// of omni_jacobian
inline Mat6 site_jacobian(const mjModel* m, const mjData* d, int site) {
  RowJac jacp, jacr;
  mj_jacSite(m, d, jacp.data(), jacr.data(), site);
  Mat6 J;
  J.topRows<3>() = jacp;
  J.bottomRows<3>() = jacr;
  return J;
}

// the largest difference between the frames of bodies 1..6 (xpos, xmat)
// and T_{0,i} of omni_frames
inline double max_body_frame_error(const mjData* d, const OmniFrames& frames) {
  double e = 0.0;
  for (int b = 1; b <= kOmniJoints; ++b) {
    const Vec3 p = Eigen::Map<const Vec3>(d->xpos + 3 * b);
    const Mat3 R = Eigen::Map<const RowMat3>(d->xmat + 9 * b);
    e = std::max({e, max_abs_diff(p, frames.T_base[b].translation()),
                  max_abs_diff(R, frames.T_base[b].linear())});
  }
  return e;
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_MUJOCO_KINEMATICS_H_
