// The emulator's physics (sim/emulator.h): the real-time thread on the
// wall clock and lockstep's advance() on the emulator's own clock, the
// stall cause when the host starves the thread, and one servo period: the
// faults that fall due, the hand's target, the motor command through the
// device watchdog, the period's mj_step calls and the snapshot published.
#include <mujoco/mujoco.h>
#include <pthread.h>
#include <sched.h>
#include <time.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <string>

#include "device/tick_timer.h"
#include "sim/closed_loop.h"
#include "sim/emulator.h"
#include "sim/emulator_detail.h"

namespace vmh::sim {
namespace {

// how far the physics may fall behind before it drops periods, periods
constexpr long kMaxCatchUpPeriods = 3;

std::int64_t to_ns(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

timespec to_timespec(std::int64_t ns) {
  timespec ts;
  ts.tv_sec = static_cast<time_t>(ns / 1000000000);
  ts.tv_nsec = static_cast<long>(ns % 1000000000);
  return ts;
}

void sleep_until_ns(std::int64_t ns) noexcept {
  const timespec ts = to_timespec(ns);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace

double Emulator::clock_s() const noexcept {
  if (options_.lockstep) {
    return static_cast<double>(lockstep_periods_.load(std::memory_order_relaxed)) *
           period_s_;
  }
  return monotonic_now_s();
}

void Emulator::advance() noexcept {
  if (!options_.lockstep || !running_.load(std::memory_order_relaxed)) return;
  // the clock moves on first: the period's reading is stamped at its end,
  // when the next tick reads it
  lockstep_periods_.fetch_add(1, std::memory_order_relaxed);
  const double now_s = clock_s();
  // a stall: nothing moves (times on this clock are whole periods, up to
  // the rounding of k T: compared with a tolerance far below a period)
  if (now_s < frozen_until_s_ + time_tolerance_s()) return;
  const double freeze_s = step_period();
  // the period that met the stall is its first: as on the wall clock, the
  // physics loses freeze_s of time in all
  if (freeze_s > 0.0) frozen_until_s_ = now_s + freeze_s - period_s_;
}

double Emulator::time_tolerance_s() const noexcept {
  // lockstep times are k T, products whose last bits vary with k: a
  // millionth of a period tells equal from different. On the wall clock
  // nothing is exact anyway
  return options_.lockstep ? 1e-6 * period_s_ : 0.0;
}

std::string Emulator::stall_cause() const {
  if (options_.lockstep) return {};
  const long starved = starved_reads_.load();
  const long lag = truth_.read().lag_periods;
  if (starved == 0 && lag == 0) return {};
  return "the emulator's physics thread fell behind the wall clock (" +
         std::to_string(starved) + " reads found no fresh state, " +
         std::to_string(lag) +
         " periods dropped): the host did not give it the CPU; run with "
         "--clock lockstep, or give the process real-time priority "
         "(CAP_SYS_NICE)";
}

void Emulator::run() noexcept {
  if (options_.realtime_priority > 0) {
    // best effort: refused without CAP_SYS_NICE, and then it runs as before
    sched_param sp{};
    sp.sched_priority = options_.realtime_priority;
    if (pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) != 0) {
#ifdef __linux__
      // as the servo thread does without SCHED_FIFO: sleeps end on time
      prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
#endif
    }
  }
  const std::int64_t period_ns = to_ns(period_s_ / options_.realtime_factor);
  std::int64_t deadline_ns = to_ns(monotonic_now_s());
  while (!stop_.load(std::memory_order_relaxed)) {
    const double freeze_s = step_period();
    if (freeze_s > 0.0) {
      // a stall: the thread does nothing, in short sleeps so stop() is
      // not held up
      const std::int64_t until = to_ns(monotonic_now_s()) + to_ns(freeze_s);
      frozen_.store(true);
      while (!stop_.load(std::memory_order_relaxed) &&
             to_ns(monotonic_now_s()) < until) {
        sleep_until_ns(std::min(until, to_ns(monotonic_now_s()) + 1000000));
      }
      frozen_.store(false);
      deadline_ns = to_ns(monotonic_now_s());
      continue;
    }
    deadline_ns += period_ns;
    const std::int64_t now_ns = to_ns(monotonic_now_s());
    const std::int64_t behind = now_ns - deadline_ns;
    if (behind > kMaxCatchUpPeriods * period_ns) {
      ps_->lag += behind / period_ns;
      deadline_ns = now_ns;
    }
    sleep_until_ns(deadline_ns);
  }
}

double Emulator::apply_faults(double t_s) noexcept {
  PhysicsState& ps = *ps_;
  double freeze_s = 0.0;
  const int n = std::min(fault_count_.load(std::memory_order_acquire), kMaxFaults);
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (ps.taken[k] || !faults_[i].ready.load(std::memory_order_acquire)) continue;
    const EmulatorFault& f = faults_[i].fault;
    if (t_s + 1e-12 < f.at_s) continue;
    ps.taken[k] = true;
    switch (f.kind) {
      case EmulatorFaultKind::kDrop: drops_.fetch_add(f.count); break;
      case EmulatorFaultKind::kLate:
        ps.late_until_s = t_s + f.duration_s;
        ps.late_count = f.count;
        break;
      case EmulatorFaultKind::kStall: freeze_s = std::max(freeze_s, f.duration_s); break;
      case EmulatorFaultKind::kUnplug:
        ps.unplug_until_s = std::max(ps.unplug_until_s, t_s + f.duration_s);
        unplugged_.store(true);
        break;
    }
  }
  const double tol_s = time_tolerance_s();
  if (unplugged_.load(std::memory_order_relaxed) &&
      t_s >= ps.unplug_until_s - tol_s) {
    // replugged: the motors wait for a fresh command
    ps.replug_writes = command_.read().count;
    unplugged_.store(false);
  }
  if (ps.late_count > 0 && t_s >= ps.late_until_s - tol_s) ps.late_count = 0;
  return freeze_s;
}

Vec3 Emulator::motor_command(double now_s) noexcept {
  PhysicsState& ps = *ps_;
  const Command c = command_.read();
  ps.invalid_command = c.invalid;
  ps.watchdog_fired = false;
  if (unplugged_.load(std::memory_order_relaxed) || c.count <= ps.replug_writes) {
    return Vec3::Zero();
  }
  if (options_.device_watchdog_s > 0.0 &&
      now_s - c.wall_s > options_.device_watchdog_s + time_tolerance_s()) {
    ps.watchdog_fired = true;
    return Vec3::Zero();
  }
  // torque_units_*: the device reads the host's numbers in other units
  return options_.seeded.torque_scale * c.tau_Nm;
}

double Emulator::step_period() noexcept {
  PhysicsState& ps = *ps_;
  const double freeze_s = apply_faults(ps.t_sim_s);
  if (freeze_s > 0.0) {
    ps.stalled = true;
    return freeze_s;
  }
  const HandProgram program = static_cast<HandProgram>(program_.load());
  ps.program = program;
  ps.hand.set_target(program, ps.t_sim_s, &ps.target, &ps.segment);
  bool let_go = program == HandProgram::kNone;
  ps.manual_held = false;
  if (program == HandProgram::kManual) {
    const ManualHand mh = manual_.read();
    ps.manual_held = mh.held;
    let_go = !mh.held;
    if (mh.held) {
      loop_->hand().set_target(loop_->model(), loop_->data(), mh.target);
      ps.target = ps.hand.wrist_pose_of(mh.target);
    }
  }
  // the command reaches the motors through SimDevice: its clamps and its
  // delay line (one write per period)
  loop_->device().write_motor_torques(motor_command(clock_s()));
  // the period's start, as the closed loop records a tick's
  ps.q_start_dh = loop_->device().true_q_dh();

  const mjModel* m = loop_->model();
  mjData* d = loop_->data();
  for (int i = 0; i < substeps_; ++i) {
    if (let_go) ps.hand.let_go();
    mju_copy(ps.qpos_before.data(), d->qpos, m->nq);
    mj_step(m, d);
    // the passivity observer, as ClosedLoop::tick keeps it
    mj_differentiatePos(m, ps.dq.data(), 1.0, ps.qpos_before.data(), d->qpos);
    ps.energy_motor_J += mju_dot(d->qfrc_actuator, ps.dq.data(), m->nv);
    ps.energy_hand_J += mju_dot(d->qfrc_applied, ps.dq.data(), m->nv);
  }
  ++ps.periods;
  ps.t_sim_s = static_cast<double>(ps.periods) * period_s_;
  t_sim_now_s_.store(ps.t_sim_s, std::memory_order_relaxed);
  publish(clock_s());
  ps.stalled = false;
  if (mirror_ != nullptr && ps.periods % kMirrorPeriods == 0) {
    // a viewer's copy; never waits for the viewer
    std::unique_lock<std::mutex> lock(mirror_mutex_, std::try_to_lock);
    if (lock.owns_lock()) {
      mj_copyData(mirror_, m, d);
      mirror_filled_ = true;
    }
  }
  return 0.0;
}

}  // namespace vmh::sim
