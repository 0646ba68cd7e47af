// The emulator's readings (sim/emulator.h): the snapshot a period
// publishes (the sensors quantised, turned into raw encoder counts and pot
// codes through the factory calibration and back through the current one,
// the seeded faults, the device's own kinematics, a late reading from the
// ring), the period's ground truth, and the servo thread's reads and
// writes through their Seqlocks.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "sim/closed_loop.h"
#include "sim/emulator.h"
#include "sim/emulator_detail.h"
#include "sim/mujoco_util.h"

namespace vmh::sim {
namespace {

// a stalled physics shows as timeouts once its snapshot is this many
// periods old: one period of normal age, and one more late period
// forgiven (the physics thread, like the servo thread, is sometimes a few
// hundred microseconds late on a loaded host)
constexpr double kStaleReadPeriods = 3.0;

}  // namespace

void Emulator::publish(double now_s) noexcept {
  const Joints q_dh = loop_->device().true_q_dh();

  Published p;
  p.publish_wall_s = now_s;
  p.finite = q_dh.allFinite();
  DeviceState& s = p.state;
  EmulatorTruth t;
  if (p.finite) read_sensors(q_dh, &s, &t);
  s.timestamp_s = now_s;
  s.present |= kStateJoints | kStateButtons | kStateInkwell | kStateTimestamp |
              kStateEncoders | kStatePots;
  publish_reading(p, now_s);
  fill_truth(q_dh, now_s, &t);
  t.docked = s.docked;
  truth_.write(t);
}

void Emulator::read_sensors(const Joints& q_dh, DeviceState* state,
                            EmulatorTruth* truth) noexcept {
  PhysicsState& ps = *ps_;
  DeviceState& s = *state;
  const Joints q_meas = ps.sensor.measure(dh_to_device_joints(q_dh));
  s.encoder_counts = hw::encoder_counts_from_angles(q_meas.head<3>(), factory_);
  s.gimbal_pots = hw::pot_codes_from_angles(q_meas.tail<3>(), factory_);
  s.q_device_rad = hw::angles_from_raw(s.encoder_counts, s.gimbal_pots, cal_.read());
  apply_seeded_readings(options_.seeded, &s.q_device_rad);
  s.docked = ps.hand.docked(q_dh, &truth->p_end_mm, &truth->stylus_axis);
  ps.kinematics.fill(loop_->model(), loop_->data(), &s);
}

void Emulator::publish_reading(const Published& p, double now_s) noexcept {
  PhysicsState& ps = *ps_;
  ps.ring[static_cast<std::size_t>(ps.periods % (kMaxLatePeriods + 1))] = p;
  const long late = std::min<long>(ps.late_count + delay_periods_, kMaxLatePeriods);
  if (late > 0 && (ps.periods >= late || delay_periods_ > 0)) {
    // a late reading: an old snapshot, with its old timestamp, delivered
    // now (a seeded delay: the first snapshot until there is an old enough
    // one, as a device's first readings would be)
    Published old = ps.ring[static_cast<std::size_t>(
        std::max(0L, ps.periods - late) % (kMaxLatePeriods + 1))];
    old.publish_wall_s = now_s;
    state_.write(old);
  } else {
    state_.write(p);
  }
}

void Emulator::fill_truth(const Joints& q_dh, double now_s,
                          EmulatorTruth* truth) noexcept {
  PhysicsState& ps = *ps_;
  const mjModel* m = loop_->model();
  mjData* d = loop_->data();
  EmulatorTruth& t = *truth;
  t.t_sim_s = ps.t_sim_s;
  t.wall_s = now_s;
  t.periods = ps.periods;
  t.lag_periods = ps.lag;
  t.q_end_dh = q_dh;
  // the period's start (the closed loop's record of a tick, PlantTruth)
  t.q_true_dh = ps.q_start_dh;
  if (ps.q_start_dh.allFinite()) {
    const OmniParams& omni = loop_->controller_params().omni;
    OmniPose pose;
    omni_fk_jacobian(omni, ps.q_start_dh, &pose, nullptr);
    t.p_true_mm = base_to_device_mm(omni, pose.p_base_m);
    t.nearest_true_mm = loop_->nearest_on_path_mm(t.p_true_mm);
  }
  t.substeps = ps.periods > 0 ? substeps_ : 0;
  t.hand_force_N = base_to_device_vector(loop_->hand().force_N());
  t.hand_target = ps.target;
  t.segment = ps.segment;
  t.program = ps.program;
  t.motor_torque_Nm = loop_->device().motor_torque_Nm();
  t.energy_motor_J = ps.energy_motor_J;
  t.energy_hand_J = ps.energy_hand_J;
  mj_mulM(m, d, ps.mv.data(), d->qvel);
  t.kinetic_J = 0.5 * mju_dot(d->qvel, ps.mv.data(), m->nv);
  t.state_finite = all_finite(d->qpos, m->nq) && all_finite(d->qvel, m->nv) &&
                   all_finite(d->qacc, m->nv) && all_finite(d->ctrl, m->nu);
  t.manual_held = ps.manual_held;
  t.device_watchdog_fired = ps.watchdog_fired;
  t.invalid_command = ps.invalid_command;
  t.unplugged = unplugged_.load(std::memory_order_relaxed);
  t.stalled = ps.stalled;
  t.late = ps.late_count > 0;
  t.drops_pending = drops_.load(std::memory_order_relaxed);
}

DeviceError Emulator::read_state(DeviceState* state) noexcept {
  state->present = 0;
  if (!running_.load(std::memory_order_acquire) ||
      unplugged_.load(std::memory_order_acquire)) {
    return DeviceError::kNotConnected;
  }
  int drops = drops_.load(std::memory_order_relaxed);
  while (drops > 0) {
    if (drops_.compare_exchange_weak(drops, drops - 1)) return DeviceError::kTimeout;
  }
  const Published p = state_.read();
  // three periods of the emulator's own time: of simulated time in
  // lockstep, of wall time scaled by the real-time factor on the wall clock
  const double stale_s =
      kStaleReadPeriods * period_s_ /
      (options_.lockstep ? 1.0 : options_.realtime_factor);
  if (clock_s() - p.publish_wall_s > stale_s + time_tolerance_s()) {
    // behind by the host's doing, not a stall fault's: the emulator's own
    // problem (stall_cause), not the device's
    if (!options_.lockstep && !frozen_.load(std::memory_order_relaxed)) {
      starved_reads_.fetch_add(1, std::memory_order_relaxed);
    }
    return DeviceError::kTimeout;
  }
  if (!p.finite) return DeviceError::kSensorFault;
  *state = p.state;
  state->buttons = buttons_.load(std::memory_order_relaxed);
  return DeviceError::kOk;
}

DeviceError Emulator::read_joints(Joints* q_device_rad) noexcept {
  return joints_of_state(q_device_rad);
}

DeviceError Emulator::write_motor_torques(const Vec3& tau_motor_Nm) noexcept {
  if (!running_.load(std::memory_order_acquire) ||
      unplugged_.load(std::memory_order_acquire)) {
    return DeviceError::kNotConnected;
  }
  Command c;
  c.invalid = !tau_motor_Nm.allFinite();
  c.tau_Nm = c.invalid ? Vec3::Zero() : tau_motor_Nm;
  c.wall_s = clock_s();
  c.count = writes_.fetch_add(1, std::memory_order_relaxed) + 1;
  command_.write(c);
  return c.invalid ? DeviceError::kInvalidCommand : DeviceError::kOk;
}

}  // namespace vmh::sim
