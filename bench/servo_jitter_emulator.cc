// servo_jitter's device when the testbed is built: the MuJoCo Omni in real
// time (sim/emulator.h) with its physics on a thread of its own, moved
// through the workspace by the scripted hand, so that the servo thread's
// timing is measured beside the emulator's own load. The period and start
// pose are the scene's (case1); servo_jitter's are not used. The emulator
// stops its physics when it is destroyed.
#include <memory>

#include "bench/servo_jitter_device.h"
#include "sim/emulator.h"

namespace vmh {

std::unique_ptr<HapticDevice> make_jitter_device(double, const Joints&) {
  sim::EmulatorOptions o;
  o.hand = sim::HandProgram::kTour;
  auto emu = std::make_unique<sim::Emulator>(o);
  emu->start();
  return emu;
}

std::string jitter_device_name() {
  return "the MuJoCo emulator (case1 scene, scripted hand tour)";
}

}  // namespace vmh
