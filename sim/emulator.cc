#include "sim/emulator.h"

#include <mujoco/mujoco.h>
#include <pthread.h>
#include <sched.h>
#include <time.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "device/tick_timer.h"
#include "sim/closed_loop.h"
#include "sim/emulator_hand.h"
#include "sim/emulator_kinematics.h"
#include "sim/sensor_model.h"

#ifndef VMH_DEFAULT_MODELS_DIR
#define VMH_DEFAULT_MODELS_DIR "models"
#endif

namespace vmh::sim {
namespace {

// how far the physics may fall behind before it drops periods, periods
constexpr long kMaxCatchUpPeriods = 3;
// a stalled physics shows as timeouts once its snapshot is this many
// periods old: one period of normal age, and one more late period
// forgiven (the physics thread, like the servo thread, is sometimes a few
// hundred microseconds late on a loaded host)
constexpr double kStaleReadPeriods = 3.0;

bool all_finite(const mjtNum* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

// FNV-1a: a fixed per-serial number for the factory calibration
std::uint64_t serial_hash(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

// a number as a person writes it ("2.5", not "2.500000")
std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

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

// The hidden factory calibration of a device: the public drivers' encoder
// signs and pot directions (hw::kNominalEncoderSign; t5's pot turns the
// other way, hw::kNominalPotGainPerRatio_rad), so that the host's decoding
// meets the signs a device has; encoder offsets of whole counts, moved per
// serial about two arbitrary bases (-0.23 and +0.37 rad for t1 and t2,
// which once stood for the drivers' inkwell offsets; kept so that traces
// stay comparable); pots reading the sensor model's 2^bits levels (its
// span: the joint's range) with a per-serial count of codes beyond the
// range's end at code zero. Computed exactly as SensorModel computes its
// levels, so that decoding gives its values.
hw::OmniCalibration factory_for(const std::string& serial,
                                const OmniParams& omni) {
  const std::uint64_t h = serial_hash(serial);
  const double step = hw::encoder_step_rad();
  const double base_counts[3] = {std::round(-0.23 / step),
                                 std::round(0.37 / step), 0.0};
  hw::OmniCalibration cal;
  cal.encoder_sign = hw::kNominalEncoderSign;
  Joints a, b;
  device_joint_ranges(omni, &a, &b);
  const double levels = std::ldexp(1.0, omni.gimbal_pot_bits);
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double moved = static_cast<double>((h >> (8 * i)) % 201) - 100.0;
    cal.encoder_offset_rad[k] = (base_counts[i] + moved) * step;
    const int j = i + 3;
    const double pot_step = std::abs(b[j] - a[j]) / (levels - 1.0);
    const double below = static_cast<double>(8 + (h >> (8 * i + 32)) % 33);
    if (hw::kNominalPotGainPerRatio_rad[i] >= 0.0) {
      cal.pot_gain_rad[k] = pot_step;
      cal.pot_offset_rad[k] = std::min(a[j], b[j]) - below * pot_step;
    } else {
      cal.pot_gain_rad[k] = -pot_step;
      cal.pot_offset_rad[k] = std::max(a[j], b[j]) + below * pot_step;
    }
  }
  return cal;
}

}  // namespace

struct Emulator::PhysicsState {
  explicit PhysicsState(ClosedLoop* loop)
      : hand(loop),
        sensor(loop->controller_params().omni, true),
        kinematics(loop->model(), loop->controller_params().omni) {
    const mjModel* m = loop->model();
    qpos_before.assign(static_cast<std::size_t>(m->nq), 0.0);
    dq.assign(static_cast<std::size_t>(m->nv), 0.0);
    mv.assign(static_cast<std::size_t>(m->nv), 0.0);
  }
  EmulatorHand hand;
  SensorModel sensor;  // always quantising (see the header)
  EmulatorKinematics kinematics;
  std::vector<mjtNum> qpos_before, dq, mv;
  // past readings, for a late fault
  std::array<Published, kMaxLatePeriods + 1> ring{};
  long periods = 0;
  long lag = 0;
  double t_sim_s = 0.0;
  double energy_motor_J = 0.0;
  double energy_hand_J = 0.0;
  std::array<bool, kMaxFaults> taken{};
  double late_until_s = -1.0;
  int late_count = 0;
  double unplug_until_s = -1.0;
  std::uint64_t replug_writes = 0;  // writes before the last replug
  bool watchdog_fired = false;
  bool invalid_command = false;
  bool stalled = false;
  bool manual_held = false;
  ScriptPose target;
  int segment = 0;
  HandProgram program = HandProgram::kTour;
  Joints q_start_dh = Joints::Zero();  // the true angles at the period's start
};

Emulator::Emulator(const EmulatorOptions& options) : options_(options) {
  if (!(options_.realtime_factor > 0.0) || !std::isfinite(options_.realtime_factor)) {
    throw std::invalid_argument("EmulatorOptions: realtime_factor must be finite and > 0");
  }
  if (!std::isfinite(options_.device_watchdog_s)) {
    throw std::invalid_argument("EmulatorOptions: device_watchdog_s must be finite");
  }
  if (options_.serial.empty()) {
    throw std::invalid_argument("EmulatorOptions: serial must not be empty");
  }
  for (const EmulatorFault& f : options_.faults) validate_emulator_fault(f);
  if (options_.faults.size() > static_cast<std::size_t>(kMaxFaults)) {
    throw std::invalid_argument("EmulatorOptions: more than " +
                                std::to_string(kMaxFaults) + " faults");
  }
  if (options_.scene.empty()) {
    options_.scene = std::string(VMH_DEFAULT_MODELS_DIR) + "/cases/case1.xml";
  }
  loop_ = std::make_unique<ClosedLoop>(
      options_.scene, options_.overrides,
      omni_model_hook(options_.model_file, options_.seeded.edit));
  period_s_ = loop_->controller_params().servo_period_s;
  if (options_.seeded.delay_ms > 0.0) {
    // the late-snapshot ring keeps whole periods only
    const double n = options_.seeded.delay_ms * 1e-3 / period_s_;
    if (std::abs(n - std::round(n)) > 1e-6 || std::round(n) < 1.0 ||
        std::round(n) > kMaxLatePeriods) {
      throw std::invalid_argument(
          "seeded emulator fault delay_" + number_text(options_.seeded.delay_ms) +
          "ms: must be a whole number of servo periods (" +
          number_text(1e3 * period_s_) + " ms), 1.." +
          std::to_string(kMaxLatePeriods) + " of them");
    }
    delay_periods_ = static_cast<int>(std::round(n));
  }
  substeps_ = loop_->substeps();
  factory_ = factory_for(options_.serial, loop_->controller_params().omni);
  cal_.write(factory_);
  program_.store(static_cast<int>(options_.hand));
  ps_ = std::make_unique<PhysicsState>(loop_.get());
  for (const EmulatorFault& f : options_.faults) inject(f);
}

Emulator::~Emulator() {
  stop();
  if (mirror_ != nullptr) mj_deleteData(mirror_);
}

void Emulator::enable_mirror() {
  if (running()) throw std::logic_error("Emulator::enable_mirror: call it before start()");
  if (mirror_ == nullptr) mirror_ = mj_makeData(loop_->model());
}

bool Emulator::copy_mirror(mjData* d) const {
  std::lock_guard<std::mutex> lock(mirror_mutex_);
  if (mirror_ == nullptr || !mirror_filled_) return false;
  mj_copyData(d, loop_->model(), mirror_);
  return true;
}

Vec3 Emulator::inkwell_mm() const noexcept { return ps_->hand.inkwell_mm(); }
Vec3 Emulator::inkwell_axis() const noexcept { return ps_->hand.inkwell_axis(); }

DeviceIdentity Emulator::identity() const {
  DeviceIdentity id;
  id.backend = "emulator";
  id.config = options_.scene;
  id.model = "PHANTOM Omni (MuJoCo emulator)";
  id.vendor = "vmhaptics";
  id.serial = options_.serial;
  const int v = mj_version();
  id.api_version = "MuJoCo " + std::to_string(v / 100) + "." +
                   std::to_string((v / 10) % 10) + "." + std::to_string(v % 10);
  id.input_dof = 6;
  id.output_dof = 3;
  return id;
}

void Emulator::set_calibration(const hw::OmniCalibration& cal) {
  cal.validate();
  cal_.write(cal);
}

void Emulator::inject(const EmulatorFault& fault) {
  validate_emulator_fault(fault);
  const int i = fault_count_.fetch_add(1);
  if (i >= kMaxFaults) {
    fault_count_.fetch_sub(1);
    throw std::length_error("Emulator::inject: more than " +
                            std::to_string(kMaxFaults) + " faults");
  }
  FaultSlot& slot = faults_[i];
  slot.fault = fault;
  slot.fault.at_s = std::max(fault.at_s, t_sim_now_s_.load());
  slot.ready.store(true, std::memory_order_release);
}

void Emulator::start(bool resume) {
  if (running_.load()) throw DeviceOpenError("emulator: already running");
  if (thread_.joinable()) thread_.join();
  stop_.store(false);
  drops_.store(0);
  unplugged_.store(false);
  frozen_until_s_ = -1.0;
  starved_reads_.store(0);
  if (!resume || !started_before_) {
    // a fresh run: the start pose, at rest, emulator time 0; faults given
    // before now keep their times from this start
    loop_->reset();
    ps_ = std::make_unique<PhysicsState>(loop_.get());
    t_sim_now_s_.store(0.0);
    lockstep_periods_.store(0);
    // the start's truth: the state at rest, before any period
    ps_->q_start_dh = loop_->device().true_q_dh();
  }
  started_before_ = true;
  publish(clock_s());
  running_.store(true);
  if (options_.lockstep) return;  // advance() runs the periods
  try {
    thread_ = std::thread([this] { run(); });
  } catch (const std::system_error& e) {
    running_.store(false);
    throw DeviceOpenError(std::string("emulator: cannot start the physics thread: ") +
                          e.what());
  }
}

void Emulator::stop() noexcept {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
  running_.store(false);
  if (loop_) loop_->device().reset();  // zero torque at the motors
}

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

void Emulator::publish(double now_s) noexcept {
  PhysicsState& ps = *ps_;
  const mjModel* m = loop_->model();
  mjData* d = loop_->data();
  SimDevice& dev = loop_->device();
  const Joints q_dh = dev.true_q_dh();

  Published p;
  p.publish_wall_s = now_s;
  p.finite = q_dh.allFinite();
  DeviceState& s = p.state;
  EmulatorTruth t;
  if (p.finite) {
    const Joints q_meas = ps.sensor.measure(dh_to_device_joints(q_dh));
    s.encoder_counts = hw::encoder_counts_from_angles(q_meas.head<3>(), factory_);
    s.gimbal_pots = hw::pot_codes_from_angles(q_meas.tail<3>(), factory_);
    s.q_device_rad = hw::angles_from_raw(s.encoder_counts, s.gimbal_pots, cal_.read());
    apply_seeded_readings(options_.seeded, &s.q_device_rad);
    s.docked = ps.hand.docked(q_dh, &t.p_end_mm, &t.stylus_axis);
    ps.kinematics.fill(m, d, &s);
  }
  s.timestamp_s = now_s;
  s.present |= kStateJoints | kStateButtons | kStateInkwell | kStateTimestamp |
              kStateEncoders | kStatePots;
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
  t.motor_torque_Nm = dev.motor_torque_Nm();
  t.energy_motor_J = ps.energy_motor_J;
  t.energy_hand_J = ps.energy_hand_J;
  mj_mulM(m, d, ps.mv.data(), d->qvel);
  t.kinetic_J = 0.5 * mju_dot(d->qvel, ps.mv.data(), m->nv);
  t.state_finite = all_finite(d->qpos, m->nq) && all_finite(d->qvel, m->nv) &&
                   all_finite(d->qacc, m->nv) && all_finite(d->ctrl, m->nu);
  t.docked = s.docked;
  t.manual_held = ps.manual_held;
  t.device_watchdog_fired = ps.watchdog_fired;
  t.invalid_command = ps.invalid_command;
  t.unplugged = unplugged_.load(std::memory_order_relaxed);
  t.stalled = ps.stalled;
  t.late = ps.late_count > 0;
  t.drops_pending = drops_.load(std::memory_order_relaxed);
  truth_.write(t);
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
