// A session on a device: the servo loop the `hw` verbs run (record, run,
// motor-test, calibrate), the safety layer in front of the device, and the
// recorder that streams each tick to DIR/trace.csv.
//
//   servo thread (or the vendor's scheduler):
//     HwLoop::tick -> servo_tick / a pulse / zero -> SafetyLayer ->
//     ReadingGuard -> the backend's device; one HwSample into a ring
//   main thread: drains the ring every 20 ms, appends rows to trace.csv
//     (flushed each time), prints progress on stderr, watches for SIGINT /
//     SIGTERM and for a device that stopped answering, then stops the loop
//     (the backend leaves zero torque) and flushes the rest.
//
// So a session cut short (a signal, a device gone) keeps its trace up to
// the last tick, and the device is left at zero torque.
#ifndef VMHAPTICS_CLI_HW_SESSION_H_
#define VMHAPTICS_CLI_HW_SESSION_H_

#include <array>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cli/hw_backends.h"
#include "controller/controller.h"
#include "device/reading_guard.h"
#include "device/safety.h"
#include "device/servo_tick.h"
#include "sim/emulator.h"

namespace vmh::cli {

enum class HwMode { kRecord, kRun, kMotorTest };

// One servo tick as the loop saw it. Plain data (it crosses threads
// through SpscRing). Frames: device frame, mm, unless named.
struct HwSample {
  double t_s = 0.0;         // since the loop's first tick (monotonic clock)
  double period_s = 0.0;    // since the previous tick (0 for the first)
  DeviceState state;        // the reading (present = 0 if it failed)
  ServoTickResult servo;    // read and write errors, controller status
  ControlOutput out;        // the controller's output (run only)
  Vec3 tau_cmd_Nm = Vec3::Zero();   // what the loop asked of the safety layer
  Vec3 tau_sent_Nm = Vec3::Zero();  // what the safety layer sent
  SafetyStatus safety = kSafetyOk;
  double ramp_scale = 0.0;
  Vec3 thermal = Vec3::Zero();      // the safety layer's thermal state
  GuardFault guard = GuardFault::kNone;
  // a reference gain set on the same reading (claims that compare cases)
  Vec3 force_reference_N = Vec3::Constant(std::nan(""));
  // the emulator's ground truth at the tick, when the device is emulated
  bool has_truth = false;
  sim::EmulatorTruth truth;
};

struct SessionOptions {
  HwMode mode = HwMode::kRecord;
  double duration_s = 5.0;   // of the loop, s
  std::string out_dir;       // empty: no files
  ServoOptions servo;
  SafetyParams safety;
  GuardParams guard;
  // run: the controller, and optionally a reference gain set
  std::optional<ControllerParams> controller;
  std::optional<ControllerParams> reference;
  // motor-test: one pulse on `motor` (1..3) of torque_Nm for pulse_s,
  // starting at pulse_start_s
  int motor = 1;
  double torque_Nm = 0.0;
  double pulse_s = 0.0;
  double pulse_start_s = 0.5;
  // keep every sample in memory as well (for claims and calibration)
  bool keep_samples = false;
  // the device counts as gone after comm_lost for this long, s
  double give_up_s = 0.5;
  bool progress = true;       // a line per second on stderr
  std::string verb = "hw";    // for messages
  // called from the main thread about every 20 ms with the time so far
  std::function<void(double t_s)> on_poll;
};

struct SessionResult {
  long ticks = 0;
  long dropped = 0;          // samples the recorder could not keep up with
  double duration_s = 0.0;   // of the loop, as run
  TickStats timing;
  ServoReport servo_report;
  // ticks on which each safety flag was up, by name
  std::map<std::string, long> safety_ticks;
  std::map<std::string, long> read_errors;   // by DeviceError name
  long zeroed_ticks = 0;
  // why it ended: "duration", "signal SIGINT", "device_gone: ...",
  // "loop_ended"
  std::string stop_reason;
  bool device_gone = false;
  int signal = 0;
  std::vector<HwSample> samples;  // with keep_samples
  std::string trace_path;
};

// Runs one session on an opened device. Writes out_dir/trace.csv as it goes
// (if out_dir is set). Throws DeviceOpenError if the loop cannot start.
SessionResult run_session(OpenedDevice* dev, const SessionOptions& options);

// trace.csv's columns for a session: which depend on the mode, what the
// device reports (state.present of the first reading) and the emulator
std::vector<std::string> hw_trace_columns(HwMode mode, std::uint32_t present,
                                          bool truth, int vm_dof);

// The names of the flags up in a safety status, '|'-joined ("ok" for none)
std::string safety_flags_text(SafetyStatus s);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_HW_SESSION_H_
