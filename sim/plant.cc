#include "sim/plant.h"

#include <cmath>
#include <utility>

#include "sim/cases/case_params_detail.h"
#include "sim/mujoco_util.h"

namespace vmh::sim {

std::string PhysicsFault::message() const {
  std::string where = part;
  if (index >= 0) {
    where += (part == "ctrl" ? ", actuator " : ", DOF ") + std::to_string(index);
  }
  return "physics went non-finite at t=" + detail::format_number(t_s) +
         " s (" + where + ")";
}

Plant::Plant(ModelPtr model, std::string path)
    : path_(std::move(path)), model_(std::move(model)) {}

void Plant::make_data() {
  data_.reset(mj_makeData(model_.get()));
  if (!data_) throw SimError(path_ + ": mj_makeData failed");
  qpos_before_.assign(static_cast<std::size_t>(model_->nq), 0.0);
  dq_.assign(static_cast<std::size_t>(model_->nv), 0.0);
  mv_.assign(static_cast<std::size_t>(model_->nv), 0.0);
}

void Plant::reset() {
  mj_resetData(model_.get(), data_.get());
  energy_motor_J_ = 0.0;
  energy_hand_J_ = 0.0;
  // mj_resetData cleared mjData::warning[]
  warning_counts_.fill(0);
  warning_seen_.fill(0);
  physics_fault_.reset();
}

bool Plant::step(int n, double t_s) {
  const mjModel* m = model_.get();
  mjData* d = data_.get();
  const double h = m->opt.timestep;
  bool bad_step = false;
  for (int i = 0; i < n; ++i) {
    mju_copy(qpos_before_.data(), d->qpos, m->nq);
    const double time_before = d->time;
    mj_step(m, d);
    if (check_step(t_s + (i + 1) * h, time_before)) bad_step = true;
    // the true motion over the step, and the work of the forces held on it
    mj_differentiatePos(m, dq_.data(), 1.0, qpos_before_.data(), d->qpos);
    energy_motor_J_ += mju_dot(d->qfrc_actuator, dq_.data(), m->nv);
    energy_hand_J_ += mju_dot(d->qfrc_applied, dq_.data(), m->nv);
  }
  return !bad_step;
}

double Plant::kinetic_J() {
  const mjModel* m = model_.get();
  mjData* d = data_.get();
  mj_mulM(m, d, mv_.data(), d->qvel);
  return 0.5 * mju_dot(d->qvel, mv_.data(), m->nv);
}

bool Plant::state_finite() const {
  const mjModel* m = model_.get();
  const mjData* d = data_.get();
  return all_finite(d->qpos, m->nq) && all_finite(d->qvel, m->nv) &&
         all_finite(d->qacc, m->nv) && all_finite(d->ctrl, m->nu);
}

void Plant::throw_if_physics_fault() const {
  if (physics_fault_) throw PhysicsError(path_ + ": " + physics_fault_->message());
}

bool Plant::check_step(double t_s, double time_before) {
  const mjModel* m = model_.get();
  const mjData* d = data_.get();
  // mj_step's checks (mj_checkPos, mj_checkVel, mj_checkAcc) count a bad
  // value in d->warning[] and reset the state, which clears the counters
  // (and MuJoCo's clock) before counting it: after a reset every count is
  // new. A step that did not move MuJoCo's clock forward was reset
  const bool reset = !(d->time > time_before);
  bool bad = false;
  for (int k = 0; k < mjNWARNING; ++k) {
    const int now = d->warning[k].number;
    const int seen = warning_seen_[static_cast<std::size_t>(k)];
    const int added = reset || now < seen ? now : now - seen;
    warning_seen_[static_cast<std::size_t>(k)] = now;
    if (added == 0) continue;
    warning_counts_[static_cast<std::size_t>(k)] += added;
    const bool bad_kind = k == mjWARN_BADQPOS || k == mjWARN_BADQVEL ||
                          k == mjWARN_BADQACC || k == mjWARN_BADCTRL;
    if (bad_kind && !bad) {
      bad = true;
      if (!physics_fault_) {
        static const char* const kParts[] = {"qpos", "qvel", "qacc", "ctrl"};
        physics_fault_ = PhysicsFault{t_s, kParts[k - mjWARN_BADQPOS],
                                      d->warning[k].lastinfo};
      }
    }
  }
  if (!bad && !(all_finite(d->qpos, m->nq) && all_finite(d->qvel, m->nv))) {
    bad = true;
    if (!physics_fault_) {
      physics_fault_ = PhysicsFault{
          t_s, all_finite(d->qpos, m->nq) ? "qvel" : "qpos", -1};
    }
  }
  return bad;
}

}  // namespace vmh::sim
