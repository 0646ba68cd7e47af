// The FireWire Omni as a HapticDevice and a DeviceBackend (firewire_omni.h
// is the specification: statuses, unwrap, motors-on bit, bus resets).
#include "hw/firewire/firewire_omni.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "device/servo_thread.h"
#include "device/tick_timer.h"

namespace vmh::hw::fw {

namespace {

DeviceError device_error_of(TransportStatus s) noexcept {
  switch (s) {
    case TransportStatus::kOk: return DeviceError::kOk;
    case TransportStatus::kTimeout: return DeviceError::kTimeout;
    case TransportStatus::kBusReset:
    case TransportStatus::kDisconnected: return DeviceError::kNotConnected;
    case TransportStatus::kIo:
    case TransportStatus::kBadPacket: return DeviceError::kIo;
  }
  return DeviceError::kIo;
}

std::string motor_field(const char* name, std::size_t i) {
  return std::string(name) + "[" + std::to_string(i) + "] (t" +
         std::to_string(i + 1) + ")";
}

}  // namespace

void FirewireOmniOptions::validate() const {
  calibration.validate();
  for (std::size_t i = 0; i < 3; ++i) {
    if (!std::isfinite(full_scale_Nm[i]) || full_scale_Nm[i] <= 0.0) {
      throw std::invalid_argument(
          "FirewireOmniOptions: " + motor_field("full_scale_Nm", i) +
          " must be finite and > 0, is " + std::to_string(full_scale_Nm[i]));
    }
    if (motor_sign[i] != 1 && motor_sign[i] != -1) {
      throw std::invalid_argument("FirewireOmniOptions: " +
                                  motor_field("motor_sign", i) +
                                  " must be +1 or -1, is " +
                                  std::to_string(motor_sign[i]));
    }
  }
  if (!std::isfinite(receive_timeout_s) || receive_timeout_s <= 0.0) {
    throw std::invalid_argument(
        "FirewireOmniOptions: receive_timeout_s must be finite and > 0, is " +
        std::to_string(receive_timeout_s));
  }
}

// -- FirewireOmni --

FirewireOmni::FirewireOmni(Transport* transport,
                           const FirewireOmniOptions& options)
    : transport_(transport), options_(options) {
  if (transport_ == nullptr) {
    throw std::invalid_argument("FirewireOmni: the transport is null");
  }
  options_.validate();
  cal_.write(options_.calibration);
  cal_local_ = options_.calibration;
  in_use_.write(options_.calibration);
  calibrated_.store(options_.calibrated, std::memory_order_release);
  stats_.write(s_);
  last_.write(StatePacket{});
}

void FirewireOmni::set_calibration(const OmniCalibration& cal) {
  cal.validate();
  cal_.write(cal);
  cal_gen_.fetch_add(1, std::memory_order_acq_rel);
  calibrated_.store(true, std::memory_order_release);
}

OmniCalibration FirewireOmni::calibration() const noexcept {
  // the servo loop's copy once it has taken the latest set_calibration()
  const std::uint64_t set = cal_gen_.load(std::memory_order_acquire);
  if (in_use_gen_.load(std::memory_order_acquire) == set) {
    const OmniCalibration c = in_use_.read();
    if (in_use_gen_.load(std::memory_order_acquire) == set) return c;
  }
  return cal_.read();
}

DeviceError FirewireOmni::read_joints(Joints* q_device_rad) noexcept {
  return joints_of_state(q_device_rad);
}

DeviceError FirewireOmni::read_state(DeviceState* state) noexcept {
  state->present = 0;
  std::size_t size = 0;
  ReceiveInfo info;
  const TransportStatus ts = transport_->receive(
      rx_.data(), rx_.size(), &size, options_.receive_timeout_s, &info);
  if (ts != TransportStatus::kOk) return receive_failed(ts);

  StatePacket p;
  if (size > rx_.size() ||
      decode_state(rx_.data(), size, &p) != PacketError::kOk) {
    ++s_.bad_packets;
    publish();
    return DeviceError::kIo;
  }
  count_packet(p, info);
  unwrap_counts(p);
  last_.write(p);
  const bool docked = p.docked();
  const bool rehomed = take_calibration(docked);
  publish();
  return fill_state(p, docked, rehomed, state);
}

// A receive that gave no packet: counted, and a bus reset answered.
DeviceError FirewireOmni::receive_failed(TransportStatus ts) noexcept {
  switch (ts) {
    case TransportStatus::kTimeout:
      ++s_.timeouts;
      publish();
      return DeviceError::kTimeout;
    case TransportStatus::kBusReset:
      // The node id and the iso channels may have changed: zero words with
      // the motors off for whatever the device takes meanwhile, then find
      // the node again and restart it. This tick has no reading either
      // way, and the counts after the reset need not continue the ones
      // before it.
      ++s_.bus_resets;
      send_zero();
      if (transport_->recover() != TransportStatus::kOk) {
        ++s_.recoveries_failed;
      }
      have_counts_ = false;
      have_counter_ = false;
      publish();
      return DeviceError::kNotConnected;
    case TransportStatus::kBadPacket:
      ++s_.bad_packets;
      publish();
      return DeviceError::kIo;
    case TransportStatus::kOk:  // (not called with it)
    case TransportStatus::kDisconnected:
    case TransportStatus::kIo:
      return device_error_of(ts);
  }
  return device_error_of(ts);
}

// A decoded packet counted: the packets that came with it superseded, some
// late, and those its counter says never arrived lost.
void FirewireOmni::count_packet(const StatePacket& p,
                                const ReceiveInfo& info) noexcept {
  ++s_.packets;
  const std::uint32_t arrived = info.packets > 0 ? info.packets : 1u;
  s_.superseded_packets += arrived - 1u;
  s_.late_packets += info.late;
  if (have_counter_) {
    // The counter moves one a packet. A step of k with `arrived` packets
    // taken means k - arrived were sent and never arrived; a counter that
    // went backwards (a restarted device) is not a loss.
    const std::uint32_t step = p.counter - s_.last_counter;
    if (step < 0x80000000u && step > arrived) s_.lost_packets += step - arrived;
  }
  have_counter_ = true;
  s_.last_counter = p.counter;
}

// The packet's int16 encoder readings unwrapped into the running counts.
void FirewireOmni::unwrap_counts(const StatePacket& p) noexcept {
  for (std::size_t i = 0; i < 3; ++i) {
    counts_[i] = have_counts_ ? unwrap_encoder(counts_[i], p.encoders[i])
                              : static_cast<std::int32_t>(p.encoders[i]);
  }
  have_counts_ = true;
}

// The calibration in use: a newly set one, the inkwell's offsets while the
// stylus is docked (re-homing, if the options allow it), published for
// calibration(). True when this packet re-homed the encoders.
bool FirewireOmni::take_calibration(bool docked) noexcept {
  bool changed = false;
  const std::uint64_t gen = cal_gen_.load(std::memory_order_acquire);
  if (gen != cal_local_gen_) {
    cal_local_ = cal_.read();
    cal_local_gen_ = gen;
    changed = true;
  }
  bool rehomed = false;
  if (options_.rehome_in_inkwell && docked) {
    const std::array<double, 3> off = docked_encoder_offsets(counts_, cal_local_);
    if (off != cal_local_.encoder_offset_rad) {
      cal_local_.encoder_offset_rad = off;
      changed = true;
      rehomed = true;
    }
    if (!was_docked_) ++s_.rehomes;
  }
  was_docked_ = docked;
  if (changed) {
    in_use_.write(cal_local_);
    in_use_gen_.store(cal_local_gen_, std::memory_order_release);
  }
  return rehomed;
}

// The reading: the pots' codes (an open pot is a sensor fault), the angles
// through the calibration in use, the switches, the raw counts and codes.
DeviceError FirewireOmni::fill_state(const StatePacket& p, bool docked,
                                     bool rehomed,
                                     DeviceState* state) noexcept {
  PotCodes pots{};
  for (std::size_t i = 0; i < 3; ++i) {
    pots[i] = pot_code(p.gimbal_a[i], p.gimbal_b[i]);
    if (pots[i] < 0) return DeviceError::kSensorFault;  // an open pot
  }

  state->q_device_rad = angles_from_raw(counts_, pots, cal_local_);
  state->buttons = (p.button1_pressed() ? kButton1 : 0u) |
                   (p.button2_pressed() ? kButton2 : 0u);
  state->docked = docked;
  state->rehomed = rehomed;
  state->timestamp_s = monotonic_now_s();
  state->encoder_counts = counts_;
  state->gimbal_pots = pots;
  state->present = kStateJoints | kStateButtons | kStateInkwell |
                   kStateTimestamp | kStateEncoders | kStatePots;
  return DeviceError::kOk;
}

DeviceError FirewireOmni::send_command(const CommandPacket& c) noexcept {
  std::uint8_t bytes[kCommandPacketBytes];
  encode_command(c, bytes);
  const TransportStatus ts = transport_->send(bytes, sizeof bytes);
  if (ts == TransportStatus::kOk) ++s_.commands;
  publish();
  return device_error_of(ts);
}

DeviceError FirewireOmni::write_motor_torques(const Vec3& tau_motor_Nm) noexcept {
  if (!tau_motor_Nm.allFinite()) {
    send_zero();
    return DeviceError::kInvalidCommand;
  }
  CommandPacket c;
  bool saturated = false;
  for (std::size_t i = 0; i < 3; ++i) {
    const double u = options_.motor_sign[i] *
                     tau_motor_Nm[static_cast<Eigen::Index>(i)] /
                     options_.full_scale_Nm[i];
    if (std::fabs(u) > 1.0) saturated = true;
    c.motor[i] = motor_word_from_unit(u);
  }
  if (saturated) ++s_.saturated_commands;
  c.status = static_cast<std::uint16_t>(kCommandStatusInitial |
                                        kCommandMotorsOn);
  motors_on_ = true;
  return send_command(c);
}

DeviceError FirewireOmni::send_zero() noexcept {
  CommandPacket c;  // zero words, kCommandStatusInitial: motors off
  c.status = static_cast<std::uint16_t>(kCommandStatusInitial &
                                        ~kCommandMotorsOn);
  motors_on_ = false;
  return send_command(c);
}

// -- FirewireBackend --

namespace {

Transport* checked(const std::unique_ptr<Transport>& t) {
  if (!t) throw std::invalid_argument("FirewireBackend: the transport is null");
  return t.get();
}

}  // namespace

FirewireBackend::FirewireBackend(std::unique_ptr<Transport> transport,
                                 const FirewireOmniOptions& options,
                                 DeviceIdentity identity,
                                 LockstepPlant* lockstep)
    : transport_(std::move(transport)),
      omni_(checked(transport_), options),
      identity_(std::move(identity)),
      plant_(lockstep) {
  const NodeInfo n = transport_->node();
  if (identity_.backend.empty()) identity_.backend = "firewire";
  if (identity_.model.empty()) identity_.model = "PHANTOM Omni";
  if (identity_.vendor.empty() && n.vendor == kVendorSensable) {
    identity_.vendor = "SensAble Technologies";
  }
  if (identity_.serial.empty()) identity_.serial = n.serial;
  if (identity_.input_dof == 0) identity_.input_dof = 6;
  if (identity_.output_dof == 0) identity_.output_dof = 3;
}

FirewireBackend::~FirewireBackend() { stop(); }

DeviceIdentity FirewireBackend::identity() const { return identity_; }

CalibrationState FirewireBackend::calibration_state() {
  return omni_.calibrated() ? CalibrationState::kOk
                            : CalibrationState::kNeedsUpdate;
}

ServoReport FirewireBackend::start(ServoLoop* loop,
                                   const ServoOptions& options) {
  if (running()) {
    throw DeviceOpenError("firewire: the servo loop is already running");
  }
  if (thread_) thread_->stop();
  if (options.lockstep) {
    if (plant_ == nullptr) {
      throw DeviceOpenError("firewire: a device on a bus runs on the wall "
                            "clock; lockstep is for a simulated plant");
    }
    if (loop == nullptr) throw DeviceOpenError("firewire: start without a loop");
    auto driver = std::make_unique<LockstepDriver>(options.period_s);
    transport_->start();
    started_ = true;
    omni_.send_zero();
    lockstep_ = std::move(driver);
    lockstep_->start(loop, plant_);
    ServoReport r;
    r.note = "lockstep: the loop runs on the caller's thread, one period of "
             "the simulated plant per tick";
    return r;
  }
  // validates before anything is started (std::invalid_argument)
  auto thread = std::make_unique<ServoThread>(loop, options);
  transport_->start();  // throws DeviceOpenError naming the failed step
  started_ = true;
  omni_.send_zero();    // motors off until the loop writes a torque
  thread_ = std::move(thread);
  try {
    return thread_->start();
  } catch (const std::exception& e) {
    stop();
    throw DeviceOpenError(std::string("firewire: cannot start the servo "
                                      "thread: ") + e.what());
  }
}

void FirewireBackend::stop() noexcept {
  if (thread_) thread_->stop();
  if (lockstep_) lockstep_->stop();
  if (started_) {
    omni_.send_zero();  // the last packet: zero words, motors off
    transport_->stop();
    started_ = false;
  }
}

bool FirewireBackend::running() const noexcept {
  if (lockstep_) return lockstep_->running();
  return thread_ != nullptr && thread_->running();
}

TickStats FirewireBackend::timing() const {
  if (lockstep_) return lockstep_->timing();
  return thread_ ? thread_->timing() : TickStats{};
}

void FirewireBackend::pass(double dt_s) {
  if (lockstep_) {
    lockstep_->pass(dt_s);
    return;
  }
  DeviceBackend::pass(dt_s);
}

}  // namespace vmh::hw::fw
