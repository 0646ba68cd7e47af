// A recording (hw/replay/recording.h) served as a device: each read gives
// the row whose time matches the replay clock, each write is checked and
// counted, and nothing moves. So an OpenHaptics program (through the open
// HD API) or any `hw` verb can be developed against a real recording
// without the device.
//
// The replay clock: recording time = first row's t_s + speed x (time since
// start()). On the wall clock (the default) that time is CLOCK_MONOTONIC's
// since start(), with the project's servo thread ticking the loop; in
// lockstep (ServoOptions::lockstep, device/lockstep.h) it is k T after k
// ticks, each tick followed by one period of the replay, so that tick k
// reads the row recorded at k T (speed 1): deterministic however busy the
// host. Before start() reads give the first row.
//
// A read serves the last row at or before the clock (zero-order hold, the
// device convention of device/device_state.h): its joints (rad), and the
// buttons, inkwell, transform (mm), velocity (mm/s), Jacobian, encoder
// counts and pots where the trace has them; a row whose read failed is
// replayed as that failure (DeviceState::present = 0). After the last row
// (its time plus one hold: Recording::last_hold_s) the end behaviour
// decides: hold (the last row for ever), loop (from the first row again),
// stop (reads fail with not_connected: the device is gone).
//
// A write is accepted and counted; a non-finite torque is kInvalidCommand
// (nothing to zero: no motor moves) and counted apart. ReplayStats says
// what was written; the backend's meta.json entry carries it.
#ifndef VMHAPTICS_HW_REPLAY_REPLAY_DEVICE_H_
#define VMHAPTICS_HW_REPLAY_REPLAY_DEVICE_H_

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "device/device_backend.h"
#include "device/haptic_device.h"
#include "device/lockstep.h"
#include "device/servo_thread.h"
#include "hw/replay/recording.h"

namespace vmh::hw::replay {

enum class ReplayEnd { kHold, kLoop, kStop };
const char* replay_end_name(ReplayEnd e);  // "hold", "loop", "stop"
// throws std::invalid_argument naming the accepted values
ReplayEnd parse_replay_end(const std::string& s);

struct ReplayOptions {
  ReplayEnd end = ReplayEnd::kHold;
  double speed = 1.0;  // recording seconds per replay second, (0, 1000]
};

// What the replay served and what it was sent (any thread).
struct ReplayStats {
  long reads = 0;
  long failed_reads = 0;     // rows replayed as a failed read, and reads
                             // after the end with end = stop
  long loops = 0;            // times the replay began again (end = loop),
                             // as seen by the last read
  long writes = 0;           // write_motor_torques calls
  long invalid_writes = 0;   // of them, with a non-finite torque
  double max_abs_tau_Nm[3] = {0, 0, 0};  // of the finite writes, per motor
  double last_tau_Nm[3] = {0, 0, 0};
  double clock_s = 0.0;      // replay time of the last read (recording time)
};

class ReplayDevice final : public HapticDevice {
 public:
  ReplayDevice(std::shared_ptr<const Recording> recording, ReplayOptions options);

  DeviceError read_joints(Joints* q_device_rad) noexcept override;
  DeviceError read_state(DeviceState* state) noexcept override;
  DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override;

  // the replay clock: starts it on the wall clock (now) or in lockstep
  // (advanced by advance_period)
  void start_clock(bool lockstep, double period_s) noexcept;
  // lockstep: one period of the replay
  void advance_period() noexcept;

  // The recording time a read at replay time `elapsed_s` (since start)
  // serves, and whether the recording has ended there (end = stop). Pure.
  double recording_time(double elapsed_s, bool* ended, long* loops) const noexcept;

  ReplayStats stats() const noexcept;
  const Recording& recording() const { return *rec_; }
  const ReplayOptions& options() const { return opt_; }

 private:
  double elapsed_s() const noexcept;

  std::shared_ptr<const Recording> rec_;
  ReplayOptions opt_;
  std::atomic<bool> started_{false};
  std::atomic<bool> lockstep_{false};
  std::atomic<std::int64_t> t0_ns_{0};
  std::atomic<std::int64_t> ticks_{0};
  double period_s_ = 1e-3;

  std::atomic<long> reads_{0}, failed_reads_{0}, loops_{0};
  std::atomic<long> writes_{0}, invalid_writes_{0};
  std::atomic<double> max_abs_[3];
  std::atomic<double> last_[3];
  std::atomic<double> clock_s_{0.0};
};

class ReplayBackend final : public DeviceBackend {
 public:
  ReplayBackend(std::shared_ptr<const Recording> recording,
                ReplayOptions options);
  ~ReplayBackend() override;

  DeviceIdentity identity() const override;
  CalibrationState calibration_state() override { return CalibrationState::kOk; }
  HapticDevice* device() noexcept override { return &device_; }
  // either clock: the wall clock (the servo thread) or lockstep
  ServoReport start(ServoLoop* loop, const ServoOptions& options) override;
  void pass(double dt_s) override;
  void stop() noexcept override;
  bool running() const noexcept override;
  TickStats timing() const override;

  ReplayDevice* replay() { return &device_; }

 private:
  class Plant final : public LockstepPlant {
   public:
    explicit Plant(ReplayDevice* d) : d_(d) {}
    void advance_period() noexcept override { d_->advance_period(); }

   private:
    ReplayDevice* d_;
  };

  ReplayDevice device_;
  Plant plant_;
  bool lockstep_ = false;
  std::unique_ptr<LockstepDriver> driver_;
  std::unique_ptr<ServoThread> thread_;
};

}  // namespace vmh::hw::replay

#endif  // VMHAPTICS_HW_REPLAY_REPLAY_DEVICE_H_
