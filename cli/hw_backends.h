// The device backends the `hw` verbs can open, by name:
//   emulator[:SCENE]        the MuJoCo Omni in real time (sim/emulator.h);
//                           the default. SCENE: a case name or scene file
//   emulator:firewire[:SCENE]  the same emulator behind the FireWire Omni's
//                           packets (sim/emulator_firewire.h) and the native
//                           driver's device layer (hw/firewire/)
//   openhaptics[:CONFIG]    the vendor's driver through libHD.so, loaded at
//                           run time (hw/openhaptics/); CONFIG: the device's
//                           configuration name (empty: the default device)
//   firewire[:GUID]         the FireWire Omni through libraw1394 (where the
//                           build has it); GUID: which one (default: the
//                           first found)
// and what `hw list` reports about each (the USB Touch is listed and probed
// only: its payload protocol is not public).
#ifndef VMHAPTICS_CLI_HW_BACKENDS_H_
#define VMHAPTICS_CLI_HW_BACKENDS_H_

#include <memory>
#include <string>
#include <vector>

#include "cli/json_util.h"
#include "device/device_backend.h"

namespace vmh::sim {
class Emulator;
}
namespace vmh::hw::fw {
class FirewireBackend;
}

namespace vmh::cli {

// What `--device` names: the backend and its argument.
struct DeviceSpec {
  std::string backend;   // "emulator", "openhaptics", "firewire", "usb"
  std::string argument;  // after the first ':' (may be empty); for
                         // emulator:firewire:SCENE, SCENE
  // emulator only: "firewire" when the emulator is reached through the
  // FireWire packets, else empty
  std::string wire;
  // the spec as text again (backend[:wire][:argument])
  std::string text() const;
};
// Throws UsageError naming the spec and the backends there are.
DeviceSpec parse_device_spec(const std::string& text);

// How to open a backend, beyond its spec.
struct OpenOptions {
  // emulator: the scene's parameter overrides, what holds the stylus
  // ("case", "tour", "none", "dock", "gimbal_sweep"), and injected faults
  // (emulator:firewire: packet-level ones, sim::parse_wire_faults)
  std::vector<std::string> overrides;
  std::string hand = "tour";
  std::string faults;
  // emulator: seeded faults (sim::parse_seeded_faults) and a calibrated
  // Omni MJCF replacing the scene's Omni's parameters (empty: none)
  std::string seeded;
  std::string model_file;
  // openhaptics: "joint_torque" (HD_CURRENT_JOINT_TORQUE, mN m) or "force"
  // (HD_CURRENT_FORCE, N, device frame)
  std::string hd_command = "joint_torque";
  // load the stored calibration for the device's serial number, if any
  bool load_calibration = true;
};

// An opened backend. `emulator` is set when it is the emulator, directly
// or behind the FireWire packets (for its ground truth, hand programs and
// faults); `calibration_source` says where
// the joint-angle calibration in use came from. The emulator's setup, for
// meta.json: its scene (absolute path), hand program at the start, model
// file (absolute; empty: none) and seeded faults (hidden from analyses).
struct OpenedDevice {
  std::unique_ptr<DeviceBackend> backend;
  sim::Emulator* emulator = nullptr;
  // set when the backend is the FireWire Omni's (firewire, emulator:firewire)
  hw::fw::FirewireBackend* firewire = nullptr;
  std::string calibration_source;
  std::string scene;
  std::string hand;
  std::string model_file;
  std::vector<std::string> seeded_faults;
};

// Throws DeviceOpenError (the cause in one line) or UsageError.
OpenedDevice open_device(const DeviceSpec& spec, const OpenOptions& options);

// `hw list`: every backend, whether it can be opened here and why not.
Json list_backends();

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_HW_BACKENDS_H_
