// A device backend: a HapticDevice together with how it is identified and
// how its servo loop is driven. The emulator (sim/emulator.h), OpenHaptics
// (hw/openhaptics/) and, later, the native drivers implement it; the `hw`
// verbs of the command line talk to nothing else.
//
// Lifetime: open (the backend's constructor or factory, which throws
// DeviceOpenError naming what was missing) -> start(loop) -> ... -> stop().
// stop() leaves zero torque at the device. The destructor stops.
#ifndef VMHAPTICS_DEVICE_DEVICE_BACKEND_H_
#define VMHAPTICS_DEVICE_DEVICE_BACKEND_H_

#include <stdexcept>
#include <string>

#include "device/haptic_device.h"
#include "device/servo_loop.h"
#include "device/tick_timer.h"

namespace vmh {

// A device that cannot be opened or started: the message names the cause
// (the library looked for, the device node, the configuration name).
class DeviceOpenError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What `hw probe` prints and `hw record` stores in meta.json. Empty strings
// for what the backend does not know.
struct DeviceIdentity {
  std::string backend;           // "emulator", "openhaptics", ...
  std::string config;            // the configuration or device name opened
  std::string model;             // e.g. "PHANTOM Omni"
  std::string vendor;
  std::string serial;            // the key calibrations are stored under
  std::string driver_version;
  std::string firmware_version;
  std::string api_version;       // e.g. the HD library's version
  int input_dof = 0;             // sensed joints
  int output_dof = 0;            // driven joints
};

// The device's own calibration state, as it reports it.
enum class CalibrationState { kUnknown, kOk, kNeedsUpdate, kNeedsManualInput };
const char* calibration_state_name(CalibrationState s);  // "unknown", "ok",
                                                         // "needs_update",
                                                         // "needs_manual_input"

// How the servo loop runs.
struct ServoOptions {
  double period_s = 1e-3;     // nominal servo period (1 kHz)
  bool realtime = true;       // ask for SCHED_FIFO and mlockall
  int priority = 80;          // SCHED_FIFO priority when granted
  // the loop's clock: false, the wall clock (a servo thread, or the
  // vendor's scheduler, ticks every period while the caller's thread
  // waits in pass()); true, lockstep (device/lockstep.h: the ticks run in
  // pass(), on the caller's thread, each followed by one period of the
  // simulated plant). Only a simulated plant can run in lockstep.
  bool lockstep = false;
};

// "realtime" or "lockstep", as meta.json and the timing report name them
inline const char* servo_clock_name(const ServoOptions& o) {
  return o.lockstep ? "lockstep" : "realtime";
}

// How the driver got on with the operating system, for the run's metadata.
struct ServoReport {
  bool sched_fifo = false;
  bool memory_locked = false;
  std::string note;  // e.g. why SCHED_FIFO was refused and how to allow it
};

class DeviceBackend {
 public:
  virtual ~DeviceBackend() = default;

  virtual DeviceIdentity identity() const = 0;
  virtual CalibrationState calibration_state() = 0;

  // The device the servo loop reads and writes (device convention). Owned
  // by the backend. Call it only from the servo loop once started.
  virtual HapticDevice* device() noexcept = 0;

  // Calls loop->tick() every options.period_s until stop() or the loop
  // returns false. Throws DeviceOpenError if the loop cannot be started
  // (options.lockstep on a backend that is not simulated included).
  virtual ServoReport start(ServoLoop* loop, const ServoOptions& options) = 0;
  // Lets dt_s of the loop's time pass. On the wall clock (the default) the
  // calling thread sleeps dt_s while the servo thread ticks; in lockstep
  // the backend runs those ticks now, on the calling thread.
  virtual void pass(double dt_s);
  // Why the device stopped answering, when the backend knows it is its own
  // doing rather than the device's (the emulator's physics thread starved
  // by a busy host); empty otherwise.
  virtual std::string stall_cause() const { return {}; }
  // The device's own calibration routine (OpenHaptics's
  // hdUpdateCalibration); false where the host calibrates from raw
  // readings instead (runtime/calibration.h)
  virtual bool has_driver_calibration() const { return false; }
  // Runs it and returns the state after; throws DeviceOpenError where
  // there is none or it failed.
  virtual CalibrationState update_calibration();
  // Ends the loop (waits for a running tick), then leaves zero torque.
  virtual void stop() noexcept = 0;
  // true while the loop runs (false once it returned false or stop() ran)
  virtual bool running() const noexcept = 0;
  // Timing of the ticks so far (safe to call while running).
  virtual TickStats timing() const = 0;
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_DEVICE_BACKEND_H_
