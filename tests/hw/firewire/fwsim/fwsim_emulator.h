// The MuJoCo Omni behind the libraw1394 stand-in, for tests that run the
// native driver's bus code end to end (Raw1394Transport, FirewireOmni) in
// lockstep. The far end of the cable is the emulator's own transport
// (sim/emulator_firewire.h): its state packets become the stand-in Omni's,
// the commands the Omni takes from the bus go to it. Time is the bus's:
// advance_period() runs the stand-in for one servo period, in which the
// Omni takes the host's commands every cycle and, at the period's end,
// runs the emulator's physics for the period with the newest of them and
// sends the state packet. So tick k's command acts over period k and tick
// k + 1 reads the state at its end, as in the simulated loop.
// Test-only: needs the testbed (MuJoCo).
#ifndef VMHAPTICS_TESTS_HW_FIREWIRE_FWSIM_FWSIM_EMULATOR_H_
#define VMHAPTICS_TESTS_HW_FIREWIRE_FWSIM_FWSIM_EMULATOR_H_

#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "device/lockstep.h"
#include "sim/emulator_firewire.h"
#include "tests/hw/firewire/fwsim/fwsim_client.h"

namespace vmh::testing {

class EmulatorOnTheBus final : public LockstepPlant {
 public:
  // Attaches the emulated Omni to the bus's Omni `guid`. The emulator must
  // be in lockstep (o.emulator.lockstep).
  EmulatorOnTheBus(const Fwsim& bus, std::uint64_t guid,
                   const sim::EmulatorFirewireOptions& o)
      : bus_(bus), guid_(guid), device_(o) {
    if (!o.emulator.lockstep) {
      throw std::invalid_argument("EmulatorOnTheBus: the emulator must be in lockstep");
    }
    period_ns_ = static_cast<std::int64_t>(
        std::llround(device_.emulator()->servo_period_s() * 1e9));
    device_.start();  // the Omni powered up
    ops_.user = this;
    ops_.state = &EmulatorOnTheBus::state;
    ops_.command = &EmulatorOnTheBus::command;
    if (bus_.attach_device(guid_, &ops_) != 0) {
      throw std::runtime_error("EmulatorOnTheBus: no Omni with that GUID on the bus");
    }
  }
  ~EmulatorOnTheBus() override {
    bus_.attach_device(guid_, nullptr);
    device_.stop();
  }
  EmulatorOnTheBus(const EmulatorOnTheBus&) = delete;
  EmulatorOnTheBus& operator=(const EmulatorOnTheBus&) = delete;

  // one servo period of the bus
  void advance_period() noexcept override { bus_.advance_ns(period_ns_); }

  sim::Emulator* emulator() noexcept { return device_.emulator(); }
  sim::EmulatorFirewireTransport& device() noexcept { return device_; }
  long periods() const noexcept { return periods_; }
  long commands() const noexcept { return commands_; }

 private:
  // the state packet at bus time t: the physics brought up to t first, a
  // period at a time, each with the newest command taken before it
  static unsigned state(void* user, std::int64_t t_ns, std::uint8_t* out,
                        unsigned capacity) {
    auto* self = static_cast<EmulatorOnTheBus*>(user);
    while ((self->periods_ + 1) * self->period_ns_ <= t_ns + self->period_ns_ / 2) {
      if (self->fresh_) {
        self->device_.send(self->command_.data(), self->command_.size());
        self->fresh_ = false;
      }
      self->device_.emulator()->advance();
      ++self->periods_;
    }
    std::size_t size = 0;
    if (self->device_.receive(out, capacity, &size, 0.0, nullptr) !=
        hw::fw::TransportStatus::kOk) {
      return 0;
    }
    return static_cast<unsigned>(size);
  }
  static void command(void* user, std::int64_t, const std::uint8_t* data,
                      unsigned len) {
    auto* self = static_cast<EmulatorOnTheBus*>(user);
    if (len != self->command_.size()) return;
    std::memcpy(self->command_.data(), data, len);
    self->fresh_ = true;
    ++self->commands_;
  }

  const Fwsim& bus_;
  std::uint64_t guid_;
  sim::EmulatorFirewireTransport device_;
  fwsim_device_ops ops_{};
  std::int64_t period_ns_ = 1000000;
  long periods_ = 0;
  long commands_ = 0;
  std::array<std::uint8_t, hw::fw::kCommandPacketBytes> command_{};
  bool fresh_ = false;
};

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_HW_FIREWIRE_FWSIM_FWSIM_EMULATOR_H_
