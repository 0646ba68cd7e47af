#include "hw/served/served_device.h"

#include <unistd.h>

#include <cmath>

#include "device/tick_timer.h"

namespace vmh::hw::served {
namespace {

// a reader retries while a write overlaps it; a writer's copy takes
// nanoseconds, so a few hundred tries only fail if the writer died mid-write
constexpr int kReadTries = 256;

template <typename T>
bool read_bounded(const Seqlock<T>& lock, T* out) noexcept {
  for (int i = 0; i < kReadTries; ++i) {
    if (lock.try_read(out)) return true;
  }
  return false;
}

}  // namespace

// ---- the server ----

class ServedServer::Loop final : public ServoLoop {
 public:
  explicit Loop(ServedServer* s) : s_(s) {}
  bool tick(double now_s) noexcept override {
    ServedRegion* r = s_->shm_->region();
    ServedState out;
    const DeviceError e = s_->device_->read_state(&out.state);
    if (e != DeviceError::kOk) {
      out.state.present = 0;
      s_->read_errors_.fetch_add(1, std::memory_order_relaxed);
    }
    ServedCommand c;
    if (read_bounded(r->command, &c)) last_command_ = c;
    CommandState cs = CommandState::kNone;
    const Vec3 tau = command_to_apply(last_command_, now_s,
                                      s_->options_.watchdog_s, &cs);
    s_->device_->write_motor_torques(tau);
    out.error = static_cast<std::int32_t>(e);
    out.server_s = now_s;
    out.tick = ++ticks_;
    out.tau_applied_Nm = tau;
    out.command_state = static_cast<std::int32_t>(cs);
    out.commands_seen = last_command_.count;
    r->state.write(out);
    return true;
  }

 private:
  ServedServer* s_;
  ServedCommand last_command_;
  std::uint64_t ticks_ = 0;
};

ServedServer::ServedServer(const std::string& name, HapticDevice* device,
                           const DeviceIdentity& identity,
                           const ServerOptions& options)
    : device_(device), options_(options) {
  if (device == nullptr) throw std::invalid_argument("serve: no device");
  if (!(options.period_s > 0.0) || !(options.watchdog_s > 0.0)) {
    throw std::invalid_argument("serve: period_s and watchdog_s must be > 0");
  }
  shm_ = ShmRegion::create(name);
  ServedIdentity& id = shm_->region()->identity;
  copy_text(id.backend, identity.backend);
  copy_text(id.config, identity.config);
  copy_text(id.model, identity.model);
  copy_text(id.vendor, identity.vendor);
  copy_text(id.serial, identity.serial);
  id.input_dof = identity.input_dof;
  id.output_dof = identity.output_dof;
  id.period_s = options.period_s;
  loop_ = std::make_unique<Loop>(this);
}

ServedServer::~ServedServer() { stop(); }

ServoReport ServedServer::start() {
  if (serving()) throw DeviceOpenError("serve " + spec() + ": already serving");
  ServoOptions so;
  so.period_s = options_.period_s;
  so.realtime = options_.realtime;
  thread_ = std::make_unique<ServoThread>(loop_.get(), so);
  shm_->region()->serving.store(1);
  try {
    return thread_->start();
  } catch (const std::exception& e) {
    shm_->region()->serving.store(0);
    throw DeviceOpenError("serve " + spec() + ": " + e.what());
  }
}

void ServedServer::stop() noexcept {
  if (shm_) shm_->region()->serving.store(0);
  if (thread_) {
    thread_->stop();
    thread_.reset();
    device_->write_motor_torques(Vec3::Zero());
  }
}

ServerStats ServedServer::stats() const noexcept {
  // what the last tick published, and who holds the client's slot now
  const ServedState s = last_published();
  ServerStats st;
  st.ticks = static_cast<long>(s.tick);
  st.commands = s.commands_seen;
  st.command_state = static_cast<CommandState>(s.command_state);
  st.tau_applied_Nm = s.tau_applied_Nm;
  st.client_pid = shm_->region()->client_pid.load(std::memory_order_relaxed);
  st.read_errors = read_errors_.load(std::memory_order_relaxed);
  return st;
}

bool ServedServer::serving() const noexcept {
  return thread_ != nullptr && thread_->running();
}

// ---- the client ----

ServedDevice::ServedDevice(ServedRegion* region, double stale_s)
    : region_(region), stale_s_(stale_s) {}

DeviceError ServedDevice::server_gone() const noexcept {
  if (region_->serving.load(std::memory_order_acquire) == 0 ||
      !process_alive(region_->server_pid.load(std::memory_order_relaxed))) {
    return DeviceError::kNotConnected;
  }
  return DeviceError::kOk;
}

DeviceError ServedDevice::read_joints(Joints* q_device_rad) noexcept {
  return joints_of_state(q_device_rad);
}

DeviceError ServedDevice::read_state(DeviceState* state) noexcept {
  state->present = 0;
  if (region_->serving.load(std::memory_order_acquire) == 0) {
    return DeviceError::kNotConnected;
  }
  ServedState s;
  if (!read_bounded(region_->state, &s)) {
    // a write that never ends: a server that died in the middle of one
    const DeviceError gone = server_gone();
    return gone != DeviceError::kOk ? gone : DeviceError::kTimeout;
  }
  if (s.tick == 0) return DeviceError::kTimeout;  // nothing published yet
  const double now_s = monotonic_now_s();
  if (now_s - s.server_s > stale_s_) {
    // a server that stopped ticking: gone, or only late
    const DeviceError gone = server_gone();
    return gone != DeviceError::kOk ? gone : DeviceError::kTimeout;
  }
  last_ = s;
  if (s.error != 0) return static_cast<DeviceError>(s.error);
  *state = s.state;
  return DeviceError::kOk;
}

DeviceError ServedDevice::write_motor_torques(const Vec3& tau_motor_Nm) noexcept {
  ServedCommand c;
  const bool finite = tau_motor_Nm.allFinite();
  c.tau_Nm = finite ? tau_motor_Nm : Vec3::Zero();
  c.client_s = monotonic_now_s();
  c.count = ++count_;
  region_->command.write(c);
  if (!finite) return DeviceError::kInvalidCommand;
  if (region_->serving.load(std::memory_order_acquire) == 0) {
    return DeviceError::kNotConnected;
  }
  return DeviceError::kOk;
}

ServedBackend::ServedBackend(const std::string& name, double stale_s)
    : shm_(ShmRegion::open(name)), device_(shm_->region(), stale_s) {
  ServedRegion* r = shm_->region();
  const std::int32_t me = static_cast<std::int32_t>(::getpid());
  std::int32_t held = 0;
  if (!r->client_pid.compare_exchange_strong(held, me)) {
    if (held != me && process_alive(held)) {
      throw DeviceOpenError("served:" + name + ": in use by the client pid " +
                            std::to_string(held) + " (one client at a time)");
    }
    // a client that died (or this process again): take the slot over
    r->client_pid.store(me);
  }
}

ServedBackend::~ServedBackend() {
  stop();
  std::int32_t me = static_cast<std::int32_t>(::getpid());
  shm_->region()->client_pid.compare_exchange_strong(me, 0);
}

DeviceIdentity ServedBackend::identity() const {
  const ServedIdentity& s = shm_->region()->identity;
  DeviceIdentity id;
  id.backend = "served";
  id.config = name();
  id.model = text_of(s.model);
  id.vendor = text_of(s.vendor);
  id.serial = text_of(s.serial);
  id.driver_version = "vmhaptics served device (" + text_of(s.backend) + " " +
                      text_of(s.config) + ", server pid " +
                      std::to_string(shm_->region()->server_pid.load()) + ")";
  id.input_dof = s.input_dof;
  id.output_dof = s.output_dof;
  return id;
}

ServoReport ServedBackend::start(ServoLoop* loop, const ServoOptions& options) {
  if (running()) throw DeviceOpenError("served:" + name() + ": already running");
  if (options.lockstep) {
    throw DeviceOpenError("served:" + name() + ": a served device runs on the "
                          "wall clock of its server; lockstep is for a "
                          "simulated plant in this process");
  }
  thread_ = std::make_unique<ServoThread>(loop, options);
  try {
    return thread_->start();
  } catch (const std::exception& e) {
    throw DeviceOpenError("served:" + name() + ": " + e.what());
  }
}

void ServedBackend::stop() noexcept {
  if (thread_) thread_->stop();
  device_.write_motor_torques(Vec3::Zero());
}

bool ServedBackend::running() const noexcept {
  return thread_ != nullptr && thread_->running();
}

TickStats ServedBackend::timing() const {
  return thread_ ? thread_->timing() : TickStats{};
}

std::string ServedBackend::stall_cause() const {
  ServedRegion* r = shm_->region();
  if (r->serving.load() == 0) return "the server stopped serving served:" + name();
  if (!process_alive(r->server_pid.load())) {
    return "the server process (pid " + std::to_string(r->server_pid.load()) +
           ") of served:" + name() + " is gone";
  }
  return {};
}

}  // namespace vmh::hw::served
