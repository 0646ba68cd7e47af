// The emulated Omni served to other processes (`vmhaptics view --serve-hd
// NAME`, docs/libhd.md "Seeing what a program does"): the MuJoCo emulator
// (sim/emulator.h) on the wall clock, with the kManual hand, behind a
// ServedServer (hw/served/served_device.h), so that a program on libHD.so
// with VMH_HD_DEVICE=served:NAME (or `vmhaptics hw ... --device
// served:NAME`) drives it while this process shows it and lets a person's
// mouse be the hand.
//
// Nobody holds the stylus until grab(): the device moves under the
// client's forces alone (as with the emulator's hand "none"). While
// grabbed, the hand's spring and damper (sim/hand.h, the scene's hand
// impedance) pull the grip toward the target a viewer moves; release()
// lets go again.
//
// Threads: the emulator's physics thread and the server's servo thread run
// on their own; the const methods may be called from any thread, the
// hand's (grab, set_target, release, held, target) from one (a viewer's).
#ifndef VMHAPTICS_SIM_SERVED_EMULATOR_H_
#define VMHAPTICS_SIM_SERVED_EMULATOR_H_

#include <memory>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "hw/served/served_device.h"
#include "sim/emulator.h"

namespace vmh::sim {

struct ServedEmulatorOptions {
  std::string name;                    // served:NAME
  std::string scene;                   // a scene file (resolve_scene's)
  std::vector<std::string> overrides;  // --set
  double watchdog_s = hw::served::kDefaultWatchdog_s;
  // the emulator's physics under SCHED_FIFO where the system allows it
  int realtime_priority = 70;
};

class ServedEmulator {
 public:
  // Builds the emulator (SimError for a bad scene or override) and creates
  // the served name (DeviceOpenError: taken, or shared memory refused).
  // Does not start.
  explicit ServedEmulator(const ServedEmulatorOptions& options);
  ~ServedEmulator();  // stops; the name is removed
  ServedEmulator(const ServedEmulator&) = delete;
  ServedEmulator& operator=(const ServedEmulator&) = delete;

  void start();            // physics, then serving
  void stop() noexcept;    // serving ends (clients see not connected), physics

  const std::string& name() const { return options_.name; }
  std::string spec() const { return server_->spec(); }
  const mjModel* model() const;
  const ClosedLoop& loop() const { return emu_->loop(); }
  // the physics state into d (made for model()); false before the first copy
  bool copy(mjData* d) const { return emu_->copy_mirror(d); }
  EmulatorTruth truth() const noexcept { return emu_->truth(); }
  hw::served::ServerStats server() const noexcept { return server_->stats(); }
  // the reading and torque of the server's last tick, as the client got it
  hw::served::ServedState published() const noexcept {
    return server_->last_published();
  }

  // The mouse's hand (world = DH base frame, SI): grab at the grip's pose
  // (nothing jumps), move the target while held, let go.
  void grab(const HandTargetState& target) noexcept;
  void set_target(const HandTargetState& target) noexcept;
  void release() noexcept;
  bool held() const noexcept { return held_; }
  const HandTargetState& target() const noexcept { return target_; }

 private:
  ServedEmulatorOptions options_;
  std::unique_ptr<Emulator> emu_;
  std::unique_ptr<hw::served::ServedServer> server_;
  HandTargetState target_;
  bool held_ = false;
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_SERVED_EMULATOR_H_
