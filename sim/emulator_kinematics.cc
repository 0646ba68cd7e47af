#include "sim/emulator_kinematics.h"

#include "controller/device_frame.h"
#include "sim/omni_model_edit.h"

namespace vmh::sim {
namespace {

// the DH columns' weights in each device column, d q_dh / d t
// (device_to_dh_joints: q1 = -t1, q2 = t2, q3 = t3 - t2, q4 = -t4,
// q5 = t5, q6 = -t6): device column c = sum over k of J_dh(:, k) * w[k][c]
constexpr double kDqDt[6][6] = {
    {-1, 0, 0, 0, 0, 0}, {0, 1, 0, 0, 0, 0},  {0, -1, 1, 0, 0, 0},
    {0, 0, 0, -1, 0, 0}, {0, 0, 0, 0, 1, 0},  {0, 0, 0, 0, 0, -1}};

}  // namespace

EmulatorKinematics::EmulatorKinematics(const mjModel* m, const OmniParams& omni)
    : omni_(omni), scratch_(mj_makeData(m)) {
  site_ = mj_name2id(m, mjOBJ_SITE, "wrist");
  if (site_ < 0) throw SimError("emulator: the scene has no site 'wrist'");
  for (int i = 0; i < 6; ++i) {
    const int j = mj_name2id(m, mjOBJ_JOINT, kOmniJoints[i]);
    if (j < 0) {
      throw SimError(std::string("emulator: the scene has no joint '") +
                     kOmniJoints[i] + "'");
    }
    dof_[static_cast<std::size_t>(i)] = m->jnt_dofadr[j];
  }
  if (!scratch_) throw SimError("emulator: cannot allocate mjData");
  const auto n = static_cast<std::size_t>(3 * m->nv);
  jacp_.assign(n, 0.0);
  jacr_.assign(n, 0.0);
  v_.assign(3, 0.0);
}

void EmulatorKinematics::fill(const mjModel* m, const mjData* d,
                              DeviceState* s) noexcept {
  mjData* k = scratch_.get();
  mju_copy(k->qpos, d->qpos, m->nq);
  mju_copy(k->qvel, d->qvel, m->nv);
  mju_copy(k->mocap_pos, d->mocap_pos, 3 * m->nmocap);
  mju_copy(k->mocap_quat, d->mocap_quat, 4 * m->nmocap);
  mj_kinematics(m, k);
  mj_comPos(m, k);  // cdof and subtree_com, which mj_jacSite reads

  // MuJoCo's arrays are row-major
  using MjMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  const Vec3 p_base_m(k->site_xpos + 3 * site_);
  const Mat3 R_base = Eigen::Map<const MjMat3>(k->site_xmat + 9 * site_);
  s->transform_mm.setIdentity();
  s->transform_mm.topLeftCorner<3, 3>() = base_to_device_rotation(R_base);
  s->transform_mm.topRightCorner<3, 1>() = base_to_device_mm(omni_, p_base_m);

  mj_jacSite(m, k, jacp_.data(), jacr_.data(), site_);
  mju_mulMatVec(v_.data(), jacp_.data(), k->qvel, 3, m->nv);
  s->velocity_mm_s = 1e3 * base_to_device_vector(Vec3(v_.data()));

  const Mat3 R = R_device_base();
  const int nv = m->nv;
  for (int c = 0; c < 6; ++c) {
    Vec3 lin = Vec3::Zero(), ang = Vec3::Zero();
    for (int q = 0; q < 6; ++q) {
      const double w = kDqDt[q][c];
      if (w == 0.0) continue;
      const int dof = dof_[static_cast<std::size_t>(q)];
      for (int r = 0; r < 3; ++r) {
        lin[r] += w * jacp_[static_cast<std::size_t>(r * nv + dof)];
        ang[r] += w * jacr_[static_cast<std::size_t>(r * nv + dof)];
      }
    }
    s->jacobian.block<3, 1>(0, c) = 1e3 * (R * lin);
    s->jacobian.block<3, 1>(3, c) = R * ang;
  }
  s->present |= kStateTransform | kStateVelocity | kStateJacobian;
}

}  // namespace vmh::sim
