#include "sim/hand.h"

#include <Eigen/Eigenvalues>
#include <array>
#include <atomic>
#include <cstring>
#include <mutex>

#include "controller/device_frame.h"
#include "sim/mujoco_util.h"

namespace vmh::sim {
namespace {

using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

Mat3 quat_to_mat(const mjtNum* q) {
  RowMat3 R;
  mju_quat2Mat(R.data(), q);
  return R;
}

// inertia of a point mass m at offset r about the origin
Mat3 point_inertia(double m, const Vec3& r) {
  return m * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
}

// The registry of hands: which SimHand belongs to which mjData. Slots are
// claimed and released under a mutex (construction and destruction); the
// callback reads them without a lock, at every evaluation of the dynamics.
// A slot's hand is written before its data and cleared after it, so a
// reader that finds the data finds its hand.
struct Slot {
  std::atomic<const mjData*> data{nullptr};
  std::atomic<SimHand*> hand{nullptr};
};
std::array<Slot, SimHand::kMaxHands> g_slots;
std::mutex g_registry_mutex;
// the callback another copy of this file installed before ours (a plugin
// that links the testbed, e.g. libHD.so over the emulator, in the same
// process as the command line): data this copy does not know goes to it
std::atomic<mjfGeneric> g_next{nullptr};
// set while this copy hands a call on, so that two copies chained to each
// other stop after one round for data neither knows
thread_local bool t_handing_on = false;

void register_hand(const mjData* d, SimHand* hand, const std::string& source) {
  std::lock_guard<std::mutex> lock(g_registry_mutex);
  if (mjcb_control != nullptr && mjcb_control != hand_control_callback) {
    // another copy of the hand's code (its callback chains in turn) or
    // someone else's: ours goes first and hands the rest on
    g_next.store(mjcb_control, std::memory_order_release);
  }
  Slot* free_slot = nullptr;
  for (Slot& s : g_slots) {
    const mjData* owner = s.data.load(std::memory_order_acquire);
    if (owner == d) throw SimError(source + ": this mjData already has a hand");
    if (owner == nullptr && free_slot == nullptr) free_slot = &s;
  }
  if (free_slot == nullptr) {
    throw SimError(source + ": more than " + std::to_string(SimHand::kMaxHands) +
                   " simulated hands at once");
  }
  free_slot->hand.store(hand, std::memory_order_release);
  free_slot->data.store(d, std::memory_order_release);
  mjcb_control = hand_control_callback;
}

void unregister_hand(const mjData* d) {
  std::lock_guard<std::mutex> lock(g_registry_mutex);
  bool any = false;
  for (Slot& s : g_slots) {
    if (s.data.load(std::memory_order_acquire) == d) {
      s.data.store(nullptr, std::memory_order_release);
      s.hand.store(nullptr, std::memory_order_release);
    }
    any = any || s.data.load(std::memory_order_acquire) != nullptr;
  }
  // the last hand gone: hand the callback back, so that other code in the
  // process (another copy of this library inside a plugin, e.g. the test
  // libHD.so over the emulator) may install its own
  if (!any && mjcb_control == hand_control_callback) {
    mjcb_control = g_next.exchange(nullptr, std::memory_order_acq_rel);
  }
}

}  // namespace

SimHand* registered_hand(const mjData* d) {
  for (Slot& s : g_slots) {
    if (s.data.load(std::memory_order_acquire) == d) {
      return s.hand.load(std::memory_order_acquire);
    }
  }
  return nullptr;
}

void hand_control_callback(const mjModel* m, mjData* d) {
  SimHand* hand = registered_hand(d);
  if (hand != nullptr) {
    hand->apply(m, d);
    return;
  }
  const mjfGeneric next = g_next.load(std::memory_order_acquire);
  if (next != nullptr && !t_handing_on) {
    t_handing_on = true;
    next(m, d);
    t_handing_on = false;
  }
}

HandParams hand_params(const CaseParams& c) {
  HandParams h;
  h.mass_kg = c.hand.mass_kg;
  h.inertia_kgm2 = c.hand.inertia_kgm2;
  h.k_pos_N_per_m = c.hand.k_pos_N_per_m;
  h.b_pos_Ns_per_m = c.hand.b_pos_Ns_per_m;
  h.k_pos_axes_N_per_m = c.hand.k_pos_axes_N_per_m;
  h.b_pos_axes_Ns_per_m = c.hand.b_pos_axes_Ns_per_m;
  h.k_rot_Nm_per_rad = c.hand.k_rot_Nm_per_rad;
  h.b_rot_Nms_per_rad = c.hand.b_rot_Nms_per_rad;
  return h;
}

SimHand::SimHand(mjModel* m, mjData* d, const HandParams& params,
                 const std::string& source)
    : params_(params) {
  // diag(k) along the device axes, seen from the world (DH base) frame:
  // R_db diag(k) R_bd
  const Mat3 R_bd = R_device_base();
  k_axes_ = !params_.k_pos_axes_N_per_m.isZero(0.0);
  b_axes_ = !params_.b_pos_axes_Ns_per_m.isZero(0.0);
  K_world_ = R_bd.transpose() * params_.k_pos_axes_N_per_m.asDiagonal() * R_bd;
  B_world_ = R_bd.transpose() * params_.b_pos_axes_Ns_per_m.asDiagonal() * R_bd;
  grip_site_ = require_id(m, mjOBJ_SITE, "grip", source);
  grip_body_ = m->site_bodyid[grip_site_];
  const int target_body = require_id(m, mjOBJ_BODY, "hand_target", source);
  target_mocap_ = m->body_mocapid[target_body];
  if (target_mocap_ < 0) {
    throw SimError(source + ": body 'hand_target' must be a mocap body");
  }

  // the hand, rigidly at the grip: combine the two bodies' mass, centre of
  // mass and inertia (parallel-axis theorem) in the body frame
  const int b = grip_body_;
  const double m_body = m->body_mass[b];
  const Vec3 c_body(m->body_ipos + 3 * b);
  const Mat3 R_body = quat_to_mat(m->body_iquat + 4 * b);
  const Mat3 I_body = R_body * Vec3(m->body_inertia + 3 * b).asDiagonal() *
                      R_body.transpose();
  const Vec3 c_hand(m->site_pos + 3 * grip_site_);
  const Mat3 R_hand = quat_to_mat(m->site_quat + 4 * grip_site_);
  const Mat3 I_hand =
      R_hand * params_.inertia_kgm2.asDiagonal() * R_hand.transpose();

  const double mass = m_body + params_.mass_kg;
  const Vec3 com = (m_body * c_body + params_.mass_kg * c_hand) / mass;
  const Mat3 I = I_body + point_inertia(m_body, c_body - com) + I_hand +
                 point_inertia(params_.mass_kg, c_hand - com);
  Eigen::SelfAdjointEigenSolver<Mat3> eig(I);
  Mat3 axes = eig.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) *= -1.0;
  RowMat3 axes_row = axes;

  m->body_mass[b] = mass;
  for (int i = 0; i < 3; ++i) {
    m->body_ipos[3 * b + i] = com[i];
    m->body_inertia[3 * b + i] = eig.eigenvalues()[i];
  }
  mju_mat2Quat(m->body_iquat + 4 * b, axes_row.data());
  mj_setConst(m, d);

  // the joints the grip's wrench acts on, if all are hinges
  chain_count_ = 0;
  for (int body = grip_body_; body > 0 && chain_count_ >= 0;
       body = m->body_parentid[body]) {
    for (int k = 0; k < m->body_jntnum[body]; ++k) {
      const int j = m->body_jntadr[body] + k;
      if (m->jnt_type[j] != mjJNT_HINGE || chain_count_ == kMaxChain) {
        chain_count_ = -1;
        break;
      }
      chain_joint_[chain_count_++] = j;
    }
  }

  register_hand(d, this, source);
  data_ = d;
}

SimHand::~SimHand() {
  if (data_ != nullptr) unregister_hand(data_);
}

void SimHand::set_target(const mjModel* m, mjData* d,
                         const HandTargetState& target) {
  (void)m;
  target_ = target;
  RowMat3 R = target.R;
  for (int i = 0; i < 3; ++i) d->mocap_pos[3 * target_mocap_ + i] = target.p_m[i];
  mju_mat2Quat(d->mocap_quat + 4 * target_mocap_, R.data());
}

void SimHand::apply(const mjModel* m, mjData* d) {
  mju_zero(d->qfrc_applied, m->nv);
  const Vec3 p(d->site_xpos + 3 * grip_site_);
  const Mat3 R = Eigen::Map<const RowMat3>(d->site_xmat + 9 * grip_site_);
  // site velocity, world frame: [angular; linear]
  mjtNum vel[6];
  mj_objectVelocity(m, d, mjOBJ_SITE, grip_site_, vel, 0);
  const Vec3 w(vel[0], vel[1], vel[2]);
  const Vec3 v(vel[3], vel[4], vel[5]);

  const Eigen::AngleAxisd dR(target_.R * R.transpose());
  const Vec3 rotvec = dR.angle() * dR.axis();
  const Vec3 dp = target_.p_m - p;
  const Vec3 dv = target_.v_m_s - v;
  force_N_ = (k_axes_ ? Vec3(K_world_ * dp) : Vec3(params_.k_pos_N_per_m * dp)) +
             (b_axes_ ? Vec3(B_world_ * dv) : Vec3(params_.b_pos_Ns_per_m * dv));
  torque_Nm_ = params_.k_rot_Nm_per_rad * rotvec +
               params_.b_rot_Nms_per_rad * (target_.w_rad_s - w);
  if (chain_count_ < 0) {
    mj_applyFT(m, d, force_N_.data(), torque_Nm_.data(), p.data(),
               grip_body_, d->qfrc_applied);
    return;
  }
  // J^T [F; tau] over the hinge chain: a hinge with world axis a through
  // the anchor c has Jacobian column (a x (p - c); a)
  for (int k = 0; k < chain_count_; ++k) {
    const int j = chain_joint_[k];
    const Eigen::Map<const Vec3> axis(d->xaxis + 3 * j);
    const Eigen::Map<const Vec3> anchor(d->xanchor + 3 * j);
    d->qfrc_applied[m->jnt_dofadr[j]] +=
        axis.dot(torque_Nm_ + (p - anchor).cross(force_N_));
  }
}

}  // namespace vmh::sim
