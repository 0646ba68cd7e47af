// The emulator's setup and lifecycle (sim/emulator.h): the options
// checked, the scene loaded, the hidden factory calibration, the identity,
// the viewer's mirror, the faults scheduled, start and stop. The physics is
// in emulator_physics.cc, the readings in emulator_readings.cc.
#include "sim/emulator.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <system_error>

#include "controller/device_frame.h"
#include "sim/closed_loop.h"
#include "sim/emulator_detail.h"
#include "sim/omni_model_edit.h"

#ifndef VMH_DEFAULT_MODELS_DIR
#define VMH_DEFAULT_MODELS_DIR "models"
#endif

namespace vmh::sim {
namespace {

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

}  // namespace vmh::sim
