#include "sim/served_emulator.h"

#include "sim/closed_loop.h"

namespace vmh::sim {

ServedEmulator::ServedEmulator(const ServedEmulatorOptions& options)
    : options_(options) {
  EmulatorOptions eo;
  eo.scene = options.scene;
  eo.overrides = options.overrides;
  eo.hand = HandProgram::kManual;
  eo.realtime_priority = options.realtime_priority;
  eo.serial = "EMU-SERVED";
  emu_ = std::make_unique<Emulator>(eo);  // SimError
  emu_->enable_mirror();
  hw::served::ServerOptions so;
  so.period_s = emu_->servo_period_s();
  so.watchdog_s = options.watchdog_s;
  DeviceIdentity id = emu_->identity();
  id.config = "emulator:" + options.scene;
  server_ = std::make_unique<hw::served::ServedServer>(options.name, emu_.get(),
                                                       id, so);
}

ServedEmulator::~ServedEmulator() { stop(); }

const mjModel* ServedEmulator::model() const { return emu_->loop().model(); }

void ServedEmulator::start() {
  emu_->start();
  try {
    server_->start();
  } catch (...) {
    emu_->stop();
    throw;
  }
}

void ServedEmulator::stop() noexcept {
  if (server_) server_->stop();  // zero torque, clients see it end
  if (emu_) emu_->stop();
}

void ServedEmulator::grab(const HandTargetState& target) noexcept {
  target_ = target;
  target_.v_m_s.setZero();
  target_.w_rad_s.setZero();
  held_ = true;
  emu_->set_manual_hand(target_, true);
}

void ServedEmulator::set_target(const HandTargetState& target) noexcept {
  target_ = target;
  if (held_) emu_->set_manual_hand(target_, true);
}

void ServedEmulator::release() noexcept {
  held_ = false;
  emu_->set_manual_hand(target_, false);
}

}  // namespace vmh::sim
