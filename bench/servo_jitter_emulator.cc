// servo_jitter's device when the testbed is built: the MuJoCo Omni in real
// time (sim/emulator.h) with its physics on a thread of its own, moved
// through the workspace by the scripted hand, so that the servo thread's
// timing is measured beside the emulator's own load. The period and start
// pose are the scene's (case1); servo_jitter's are not used.
#include <memory>

#include "bench/servo_jitter_device.h"
#include "sim/emulator.h"

namespace vmh {

namespace {

class StartedEmulator final : public HapticDevice {
 public:
  StartedEmulator() {
    sim::EmulatorOptions o;
    o.hand = sim::HandProgram::kTour;
    emu_ = std::make_unique<sim::Emulator>(o);
    emu_->start();
  }
  ~StartedEmulator() override { emu_->stop(); }
  DeviceError read_joints(Joints* q) noexcept override {
    return emu_->read_joints(q);
  }
  DeviceError read_state(DeviceState* s) noexcept override {
    return emu_->read_state(s);
  }
  DeviceError write_motor_torques(const Vec3& tau) noexcept override {
    return emu_->write_motor_torques(tau);
  }

 private:
  std::unique_ptr<sim::Emulator> emu_;
};

}  // namespace

std::unique_ptr<HapticDevice> make_jitter_device(double, const Joints&) {
  return std::make_unique<StartedEmulator>();
}

std::string jitter_device_name() {
  return "the MuJoCo emulator (case1 scene, scripted hand tour)";
}

}  // namespace vmh
