// The test libHD.so's device when the testbed is built: the MuJoCo Omni in
// real time (sim/emulator.h), so that the OpenHaptics backend is tested
// against the same physics as every other backend. Nobody holds the stylus
// unless the configuration has the "tour" token (then the scripted hand
// moves it through the workspace); "docked", "button1" and "button2" force
// the switches the emulator would otherwise report.
#include "sim/emulator.h"
#include "tests/hw/fake_libhd/fake_hd_device.h"

namespace vmh::fake_hd {

namespace {

class EmulatedOmni final : public HapticDevice {
 public:
  EmulatedOmni(sim::HandProgram hand, bool docked, std::uint32_t buttons)
      : docked_(docked), buttons_(buttons) {
    sim::EmulatorOptions o;
    o.hand = hand;
    o.serial = "FAKE-HD-EMU";
    emu_ = std::make_unique<sim::Emulator>(o);
    emu_->start();
  }
  ~EmulatedOmni() override { emu_->stop(); }

  DeviceError read_joints(Joints* q) noexcept override {
    return emu_->read_joints(q);
  }
  DeviceError read_state(DeviceState* s) noexcept override {
    const DeviceError e = emu_->read_state(s);
    if (docked_) s->docked = true;
    s->buttons |= buttons_;
    return e;
  }
  DeviceError write_motor_torques(const Vec3& tau_Nm) noexcept override {
    return emu_->write_motor_torques(tau_Nm);
  }
  Joints true_q_dh() const noexcept { return emu_->truth().q_true_dh; }

 private:
  std::unique_ptr<sim::Emulator> emu_;
  bool docked_;
  std::uint32_t buttons_;
};

}  // namespace

std::unique_ptr<HapticDevice> fake_hd_make_device(const std::string& config) {
  const ModelTokens m = parse_model_tokens(config);
  return std::make_unique<EmulatedOmni>(
      m.tour ? sim::HandProgram::kTour : sim::HandProgram::kNone, m.docked,
      m.buttons);
}

bool fake_hd_true_q_dh(const HapticDevice& device, Joints* q_dh_rad) {
  const auto* e = dynamic_cast<const EmulatedOmni*>(&device);
  if (e == nullptr) return false;
  *q_dh_rad = e->true_q_dh();
  return true;
}

}  // namespace vmh::fake_hd
