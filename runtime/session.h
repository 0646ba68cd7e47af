// A session on a device: the servo loop the `hw` verbs run (record, run,
// motor-test, calibrate, probe), and the recorder that streams each tick
// to trace.csv.
//
//   the loop's clock (ServoOptions::lockstep, device/device_backend.h):
//     wall clock: the backend's servo thread (or the vendor's scheduler)
//       ticks every period; the session's thread waits in pass()
//     lockstep: the ticks run inside pass(), on the session's thread, each
//       followed by one period of the simulated plant (device/lockstep.h)
//   each tick: SessionLoop::tick -> ServoChain (servo_tick or a pulse or
//     zero -> SafetyLayer -> ReadingGuard -> the backend's device); one
//     TickRecord into a ring
//   the session's thread, every 20 ms of loop time: drains the ring, writes
//     the rows (flushed each time), calls on_record for each, prints
//     progress on stderr, watches for SIGINT / SIGTERM and for a device
//     that stopped answering, then stops the loop (the backend leaves zero
//     torque) and drains the rest.
//
// So a session cut short (a signal, a device gone) keeps its trace up to
// the last tick, and the device is left at zero torque. The trace goes
// where the caller says: a verb gives the private folder of its output set
// (output::OutputSet), so that trace.csv, meta.json and summary.json
// appear together or not at all.
#ifndef VMHAPTICS_RUNTIME_SESSION_H_
#define VMHAPTICS_RUNTIME_SESSION_H_

#include <functional>
#include <map>
#include <string>

#include "device/servo_chain.h"
#include "device/tick_timer.h"
#include "runtime/backend_registry.h"
#include "runtime/stop.h"
#include "runtime/trace_writer.h"

namespace vmh::runtime {

struct SessionOptions {
  std::string verb = "hw";  // for messages ("hw record")
  ChainOptions chain;       // what commands the motors, guard, safety
  ServoOptions servo;       // period, real-time scheduling, the clock
  double duration_s = 5.0;  // of loop time
  // trace.csv is written to trace_path (empty: no trace); errors name
  // trace_shown, where it will be once its set is in place
  std::string trace_path;
  std::string trace_shown;
  // the device counts as gone after comm_lost for this long (loop time)
  double give_up_s = 0.5;
  bool progress = true;  // a line per second of loop time on stderr
  // every record, in order, on the session's thread (claims, metrics,
  // calibration: keep what is needed, not everything)
  std::function<void(const TickRecord&)> on_record;
  // about every 20 ms of loop time, with the loop time so far
  std::function<void(double t_s)> on_poll;
};

struct SessionResult {
  long ticks = 0;
  long dropped = 0;          // records the recorder could not keep up with
  double duration_s = 0.0;   // of the loop, as run (the last record's t_s)
  std::string clock;         // "realtime" or "lockstep"
  TickStats timing;
  ServoReport servo_report;
  // ticks on which each safety flag was up, by name
  std::map<std::string, long> safety_ticks;
  std::map<std::string, long> read_errors;   // by DeviceError name
  long zeroed_ticks = 0;
  // why it ended: "duration", "signal SIGINT", "device_gone: ...",
  // "emulator_stalled: ...", "loop_ended"
  std::string stop_reason;
  bool device_gone = false;  // a device_gone or emulator_stalled end
  int signal = 0;
  std::string trace_path;    // trace_shown, when a trace was written
  // the first good reading (present = 0 when there was none) and the last
  DeviceState first_reading;
  DeviceState last_reading;
};

// A controller's session as `hw run` and the viewer run it: the chain in
// run mode behind the safety layer with the controller's limits
// (safety_params_for; the dead-man setting kept), the reading guard's
// longest period 4 servo periods, the servo period the controller's.
void configure_controller_session(const ControllerParams& params,
                                  SessionOptions* so);
// every gain of a controller times `scale` (bring-up: start low)
void scale_gains(ControllerParams* params, double scale);

// Runs one session on an opened device. Throws DeviceOpenError if the loop
// cannot start (nothing written then), std::runtime_error naming the file
// when the trace cannot be written (the device is stopped at zero torque
// first).
SessionResult run_session(OpenedDevice* dev, const SessionOptions& options);

// The session as it ended, as an error, when it did not end as asked: a
// device that stopped answering (std::runtime_error, exit 1) or a signal
// (SignalStop, runtime/stop.h: exit 130 / 143). Call after the outputs are
// written.
void raise_if_cut_short(const SessionResult& r, const std::string& verb);

// A session left running for another thread to watch (the viewer): the
// chain on the device's wall clock until stop(), no recorder.
class LiveSession {
 public:
  // starts the loop; throws what run_session throws
  LiveSession(OpenedDevice* dev, const ChainOptions& chain,
              const ServoOptions& servo);
  ~LiveSession();  // stop()
  LiveSession(const LiveSession&) = delete;
  LiveSession& operator=(const LiveSession&) = delete;

  TickRecord latest() const;
  long ticks() const;
  void stop() noexcept;  // zero torque at the device

 private:
  OpenedDevice* dev_;
  std::unique_ptr<class SessionLoop> loop_;
  bool stopped_ = false;
};

}  // namespace vmh::runtime

#endif  // VMHAPTICS_RUNTIME_SESSION_H_
