#include "hw/replay/replay_device.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace vmh::hw::replay {
namespace {

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

}  // namespace

const char* replay_end_name(ReplayEnd e) {
  switch (e) {
    case ReplayEnd::kHold: return "hold";
    case ReplayEnd::kLoop: return "loop";
    case ReplayEnd::kStop: return "stop";
  }
  return "hold";
}

ReplayEnd parse_replay_end(const std::string& s) {
  if (s.empty() || s == "hold") return ReplayEnd::kHold;
  if (s == "loop") return ReplayEnd::kLoop;
  if (s == "stop") return ReplayEnd::kStop;
  throw std::invalid_argument("'" + s + "' is not an end of recording "
                              "(expected hold, loop or stop)");
}

// ---- the device ----

ReplayDevice::ReplayDevice(std::shared_ptr<const Recording> recording,
                           ReplayOptions options)
    : rec_(std::move(recording)), opt_(options) {
  if (!rec_ || rec_->rows() == 0) {
    throw std::invalid_argument("ReplayDevice: an empty recording");
  }
  if (!std::isfinite(opt_.speed) || opt_.speed <= 0.0 || opt_.speed > 1000.0) {
    throw std::invalid_argument("ReplayDevice: speed must be > 0 and <= 1000");
  }
  for (int i = 0; i < 3; ++i) {
    max_abs_[i].store(0.0);
    last_[i].store(0.0);
  }
  clock_s_.store(rec_->first_s());
}

void ReplayDevice::start_clock(bool lockstep, double period_s) noexcept {
  period_s_ = period_s;
  lockstep_.store(lockstep, std::memory_order_relaxed);
  ticks_.store(0, std::memory_order_relaxed);
  t0_ns_.store(monotonic_ns(), std::memory_order_relaxed);
  started_.store(true, std::memory_order_release);
}

void ReplayDevice::advance_period() noexcept {
  ticks_.store(ticks_.load(std::memory_order_relaxed) + 1,
               std::memory_order_release);
}

double ReplayDevice::elapsed_s() const noexcept {
  if (!started_.load(std::memory_order_acquire)) return 0.0;
  if (lockstep_.load(std::memory_order_relaxed)) {
    return static_cast<double>(ticks_.load(std::memory_order_acquire)) * period_s_;
  }
  return 1e-9 * static_cast<double>(monotonic_ns() -
                                    t0_ns_.load(std::memory_order_relaxed));
}

double ReplayDevice::recording_time(double elapsed_s, bool* ended,
                                    long* loops) const noexcept {
  *ended = false;
  *loops = 0;
  const Recording& r = *rec_;
  const double x = opt_.speed * std::max(0.0, elapsed_s);  // since the first row
  const double span = (r.last_s() - r.first_s()) + r.last_hold_s();
  const double tol = 1e-8 * (1.0 + std::fabs(r.first_s() + x));
  switch (opt_.end) {
    case ReplayEnd::kHold:
      break;
    case ReplayEnd::kStop:
      if (x + tol >= span) *ended = true;
      break;
    case ReplayEnd::kLoop:
      if (x + tol >= span) {
        const double n = std::floor((x + tol) / span);
        *loops = static_cast<long>(n);
        return r.first_s() + std::max(0.0, x - n * span);
      }
      break;
  }
  return r.first_s() + x;
}

DeviceError ReplayDevice::read_joints(Joints* q_device_rad) noexcept {
  return joints_of_state(q_device_rad);
}

DeviceError ReplayDevice::read_state(DeviceState* state) noexcept {
  bool ended = false;
  long loops = 0;
  const double t = recording_time(elapsed_s(), &ended, &loops);
  reads_.fetch_add(1, std::memory_order_relaxed);
  clock_s_.store(t, std::memory_order_relaxed);
  loops_.store(loops, std::memory_order_relaxed);
  if (ended) {
    failed_reads_.fetch_add(1, std::memory_order_relaxed);
    state->present = 0;
    return DeviceError::kNotConnected;
  }
  const DeviceError e = rec_->state_of(rec_->row_at(t), state);
  if (e != DeviceError::kOk) failed_reads_.fetch_add(1, std::memory_order_relaxed);
  return e;
}

DeviceError ReplayDevice::write_motor_torques(const Vec3& tau) noexcept {
  writes_.fetch_add(1, std::memory_order_relaxed);
  if (!tau.allFinite()) {
    invalid_writes_.fetch_add(1, std::memory_order_relaxed);
    for (int i = 0; i < 3; ++i) last_[i].store(0.0, std::memory_order_relaxed);
    return DeviceError::kInvalidCommand;
  }
  for (int i = 0; i < 3; ++i) {
    const double a = std::fabs(tau[i]);
    // one writer (the servo thread): load and store suffice
    if (a > max_abs_[i].load(std::memory_order_relaxed)) {
      max_abs_[i].store(a, std::memory_order_relaxed);
    }
    last_[i].store(tau[i], std::memory_order_relaxed);
  }
  return DeviceError::kOk;
}

ReplayStats ReplayDevice::stats() const noexcept {
  ReplayStats s;
  s.reads = reads_.load();
  s.failed_reads = failed_reads_.load();
  s.loops = loops_.load();
  s.writes = writes_.load();
  s.invalid_writes = invalid_writes_.load();
  for (int i = 0; i < 3; ++i) {
    s.max_abs_tau_Nm[i] = max_abs_[i].load();
    s.last_tau_Nm[i] = last_[i].load();
  }
  s.clock_s = clock_s_.load();
  return s;
}

// ---- the backend ----

ReplayBackend::ReplayBackend(std::shared_ptr<const Recording> recording,
                             ReplayOptions options)
    : device_(std::move(recording), options), plant_(&device_) {}

ReplayBackend::~ReplayBackend() { stop(); }

DeviceIdentity ReplayBackend::identity() const {
  const Recording& r = device_.recording();
  DeviceIdentity id;
  id.backend = "replay";
  id.config = r.folder;
  const std::string was = r.recorded.model.empty() ? std::string("a device")
                                                   : r.recorded.model;
  id.model = "replay of " + was +
             (r.recorded.backend.empty() ? std::string()
                                         : " (" + r.recorded.backend + ")");
  id.vendor = r.recorded.vendor;
  // not the recorded serial: a calibration stored for the real device must
  // not be read or written through its replay
  id.serial = "replay-" + (r.recorded.serial.empty() ? std::string("unknown")
                                                     : r.recorded.serial);
  id.driver_version = "vmhaptics replay (hw/replay)";
  id.firmware_version = r.recorded.firmware_version;
  id.api_version = r.recorded.api_version;
  id.input_dof = 6;
  id.output_dof = 3;
  return id;
}

ServoReport ReplayBackend::start(ServoLoop* loop, const ServoOptions& options) {
  if (running()) throw DeviceOpenError("replay: already running");
  if (!(options.period_s > 0.0) || !std::isfinite(options.period_s)) {
    throw DeviceOpenError("replay: the servo period must be > 0");
  }
  thread_.reset();
  lockstep_ = options.lockstep;
  device_.start_clock(options.lockstep, options.period_s);
  if (options.lockstep) {
    driver_ = std::make_unique<LockstepDriver>(options.period_s);
    driver_->start(loop, &plant_);
    ServoReport r;
    r.note = "lockstep: the loop runs on the caller's thread, the replay "
             "clock one period per tick";
    return r;
  }
  driver_.reset();
  thread_ = std::make_unique<ServoThread>(loop, options);
  try {
    return thread_->start();
  } catch (const std::exception& e) {
    thread_.reset();
    throw DeviceOpenError(std::string("replay: the servo thread: ") + e.what());
  }
}

void ReplayBackend::pass(double dt_s) {
  if (lockstep_ && driver_) {
    driver_->pass(dt_s);
    return;
  }
  DeviceBackend::pass(dt_s);
}

void ReplayBackend::stop() noexcept {
  if (thread_) thread_->stop();
  if (driver_) driver_->stop();
}

bool ReplayBackend::running() const noexcept {
  if (lockstep_) return driver_ != nullptr && driver_->running();
  return thread_ != nullptr && thread_->running();
}

TickStats ReplayBackend::timing() const {
  if (lockstep_) return driver_ ? driver_->timing() : TickStats{};
  return thread_ ? thread_->timing() : TickStats{};
}

}  // namespace vmh::hw::replay
