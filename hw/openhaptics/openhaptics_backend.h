// The OpenHaptics backend (`--device openhaptics[:CONFIG_NAME]`): a PHANTOM
// Omni (or any device the vendor's HD library drives) through libHD.so,
// loaded at run time (hd_library.h). docs/openhaptics.md lists every HD
// call it makes and what has and has not been checked on a device.
//
// The servo loop runs inside the HD scheduler: start() schedules one
// asynchronous callback at the highest priority that, every servo frame,
// does hdBeginFrame, reads the state, calls loop->tick(), sends the torque
// the loop wrote and hdEndFrame, then drains hdGetError. device()'s
// read_state / write_motor_torques are meant to be called from inside that
// tick: they copy the state read this frame and store the torque to send.
//
// Units at the device() boundary are the device layer's (rad, N m, device
// convention); the backend converts to mN m, or to a device-frame force in N
// in force mode.
#ifndef VMHAPTICS_HW_OPENHAPTICS_OPENHAPTICS_BACKEND_H_
#define VMHAPTICS_HW_OPENHAPTICS_OPENHAPTICS_BACKEND_H_

#include <array>
#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "controller/omni_params.h"
#include "device/device_backend.h"
#include "device/tick_record.h"
#include "device/tick_timer.h"
#include "hw/openhaptics/hd_api.h"
#include "hw/openhaptics/hd_codec.h"
#include "hw/openhaptics/hd_library.h"

namespace vmh::hw {

struct OpenHapticsOptions {
  // the device configuration name given to hdInitDevice; empty: the default
  // device
  std::string config;
  enum HdCommand {
    // HD_CURRENT_JOINT_TORQUE, mN m: the motor torques as written
    kJointTorque,
    // HD_CURRENT_FORCE, N, device frame: the force whose Jacobian transpose
    // gives the motor torques, so that the device's own Jacobian maps it
    // back (comparing the two modes checks force directions on a device)
    kForce,
  };
  HdCommand command = kJointTorque;
  // the kinematics the force mode's map uses
  OmniParams omni;
};

// "joint_torque" or "force" -> HdCommand; throws std::invalid_argument naming
// the value otherwise
OpenHapticsOptions::HdCommand parse_hd_command(const std::string& name);
const char* hd_command_name(OpenHapticsOptions::HdCommand c);

// The HD errors seen while running: the latest and a count per name.
struct HdErrorReport {
  hd::HDerror last_code = hd::kSuccess;  // kSuccess: none yet
  std::string last_name;                 // hd_error_name(last_code)
  long warnings = 0;                     // errors the device went on after
  long fatal = 0;                        // errors that stopped it
  struct Count {
    std::string name;
    hd::HDerror code;
    bool fatal;
    long count;
  };
  std::vector<Count> counts;  // the codes seen at least once
};

class OpenHapticsBackend final : public DeviceBackend {
 public:
  using Options = OpenHapticsOptions;

  // Loads libHD.so (VMH_LIBHD or the loader's search path), opens the device
  // named options.config and reads its identification. Throws
  // DeviceOpenError naming the library, the symbol or the configuration.
  explicit OpenHapticsBackend(const Options& options);
  ~OpenHapticsBackend() override;
  OpenHapticsBackend(const OpenHapticsBackend&) = delete;
  OpenHapticsBackend& operator=(const OpenHapticsBackend&) = delete;

  DeviceIdentity identity() const override { return identity_; }
  // hdCheckCalibration (inside a scheduler frame once the loop runs)
  CalibrationState calibration_state() override;
  // hdUpdateCalibration with the style HD_CALIBRATION_STYLE allows (see
  // hd::calibration_style_to_use); throws DeviceOpenError if the device
  // names none or reports an error. Returns the state afterwards.
  CalibrationState update_calibration() override;
  bool has_driver_calibration() const override { return true; }

  HapticDevice* device() noexcept override { return &device_; }

  // Enables HD_FORCE_OUTPUT, schedules the servo callback at the highest
  // priority and starts the HD scheduler; returns once the first frame ran.
  // The HD scheduler runs at its own rate (1 kHz): a different
  // options.period_s is refused. Throws DeviceOpenError on an HD error.
  ServoReport start(ServoLoop* loop, const ServoOptions& options) override;
  // Ends the callback, sends zero torque in one more (synchronous) frame,
  // stops the scheduler and disables the device. The zero frame is skipped
  // when the scheduler never ran or the callback did not end within 1 s (a
  // synchronous call would then wait for ever). Once stopped, the backend
  // cannot be started again.
  void stop() noexcept override;
  bool running() const noexcept override {
    return running_.load(std::memory_order_acquire);
  }
  TickStats timing() const noexcept override { return timer_.stats(); }

  // The HD errors seen so far (callable while running).
  HdErrorReport last_errors() const;
  // Whether HD_CURRENT_ENCODER_VALUES / the inkwell switch answered at open
  bool has_encoders() const noexcept { return has_encoders_; }
  bool has_inkwell() const noexcept { return has_inkwell_; }
  const Options& options() const noexcept { return options_; }

  // The simulated plant's truth behind the project's own HD library
  // (vmhdReadTruth, docs/libhd.md); false for any other library. Called
  // from the servo loop (the session reads it after each tick).
  bool has_truth() const noexcept { return api_->vmhdReadTruth != nullptr; }
  bool read_truth(PlantTruth* truth) const noexcept;

 private:
  // the device() the loop sees: the frame's state and the torque to send
  class FrameDevice final : public HapticDevice {
   public:
    explicit FrameDevice(OpenHapticsBackend* owner) : owner_(owner) {}
    DeviceError read_joints(Joints* q_device_rad) noexcept override;
    DeviceError read_state(DeviceState* state) noexcept override;
    DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override;

   private:
    OpenHapticsBackend* owner_;
  };

  static hd::HDCallbackCode servo_callback(void* self) noexcept;
  static hd::HDCallbackCode zero_callback(void* self) noexcept;
  static hd::HDCallbackCode calibration_callback(void* self) noexcept;

  void read_frame_state() noexcept;
  // the tick's time, s: the scheduler's own (vmhdGetSchedulerTime, which
  // in lockstep is the simulated time) where the library has it, else
  // CLOCK_MONOTONIC
  double frame_time_s() const noexcept;
  void send_torque(const Vec3& tau_motor_Nm) noexcept;
  void drain_errors() noexcept;
  // the first error code pending after a setup call (kSuccess if none); the
  // rest are drained and recorded
  hd::HDerror setup_error() noexcept;
  std::string describe(hd::HDerror code) const;

  Options options_;
  std::unique_ptr<hd::HdLibrary> lib_;
  const hd::HdApi* api_ = nullptr;
  hd::HHD handle_ = hd::kInvalidHandle;
  DeviceIdentity identity_;
  bool has_encoders_ = false;
  bool has_inkwell_ = false;
  FrameDevice device_{this};

  // -- owned by the scheduler thread while running --
  ServoLoop* loop_ = nullptr;
  DeviceState frame_state_;
  bool have_frame_ = false;
  Vec3 tau_cmd_Nm_ = Vec3::Zero();
  hd::HDenum calibration_result_ = 0;
  TickTimer timer_{1e-3};

  // -- shared with the controlling thread --
  std::atomic<bool> started_{false};
  std::atomic<bool> stopped_{false};
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_requested_{false};
  std::atomic<long> frames_{0};
  std::atomic<int> sched_policy_{-1};  // the scheduler thread's, first frame
  hd::HDSchedulerHandle servo_handle_ = 0;
  // hdStartScheduler succeeded and the scheduler ran a frame
  bool scheduler_ok_ = false;
  // the first fatal error (DeviceError as int; 0 = none)
  std::atomic<int> fault_{0};
  std::atomic<hd::HDerror> last_code_{hd::kSuccess};
  std::atomic<long> warnings_{0};
  std::atomic<long> fatal_count_{0};
  std::array<std::atomic<long>, hd::kHdKnownErrorCount + 1> error_counts_{};
  // the latest unknown code (their counts share the last slot)
  std::atomic<hd::HDerror> last_unknown_code_{hd::kSuccess};
};

}  // namespace vmh::hw

#endif  // VMHAPTICS_HW_OPENHAPTICS_OPENHAPTICS_BACKEND_H_
