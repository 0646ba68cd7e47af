// The device backends the `hw` verbs can open, by name:
//   emulator[:SCENE]        the MuJoCo Omni in real time (sim/emulator.h);
//                           the default. SCENE: a case name or scene file
//   openhaptics[:CONFIG]    the vendor's driver through libHD.so, loaded at
//                           run time (hw/openhaptics/); CONFIG: the device's
//                           configuration name (empty: the default device)
// and what `hw list` reports about each, including those that are planned
// but not built yet (the native FireWire and USB drivers).
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

namespace vmh::cli {

// What `--device` names: the backend and its argument.
struct DeviceSpec {
  std::string backend;   // "emulator", "openhaptics"
  std::string argument;  // after the first ':' (may be empty)
};
// Throws UsageError naming the spec and the backends there are.
DeviceSpec parse_device_spec(const std::string& text);

// How to open a backend, beyond its spec.
struct OpenOptions {
  // emulator: the scene's parameter overrides, what holds the stylus
  // ("case", "tour", "none", "dock", "gimbal_sweep"), and injected faults
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

// An opened backend. `emulator` is set when it is the emulator (for its
// ground truth, hand programs and faults); `calibration_source` says where
// the joint-angle calibration in use came from. The emulator's setup, for
// meta.json: its scene (absolute path), hand program at the start, model
// file (absolute; empty: none) and seeded faults (hidden from analyses).
struct OpenedDevice {
  std::unique_ptr<DeviceBackend> backend;
  sim::Emulator* emulator = nullptr;
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
