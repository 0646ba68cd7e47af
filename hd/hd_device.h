// One device opened through the open HD API (docs/libhd.md): a backend of
// the project's registry behind the project's reading guard and safety
// layer, with the HD API's view of it: each servo frame's state (CURRENT_*)
// and the previous one's (LAST_*), the commands a frame sets, the
// capabilities and the software limits.
//
// Threads: sample() and send() run on the scheduler's servo thread, once
// per tick, and neither allocates nor throws. Other threads read the last
// published frame (published()) through a seqlock and never block the
// servo thread.
//
// Frames and units: the HD API's. Positions in mm and forces in N in the
// device frame (controller/device_frame.h); joint angles in rad with joint 3
// absolute; torques in mN m; the Jacobian 6x6 with rows (v_x, v_y, v_z in
// mm/rad; w_x, w_y, w_z in rad/rad) and columns t1..t6 of the device
// convention, stored column-major (docs/libhd.md says this layout is the
// project's choice: no public source confirms the vendor's).
#ifndef VMHAPTICS_HD_HD_DEVICE_H_
#define VMHAPTICS_HD_HD_DEVICE_H_

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "controller/omni_params.h"
#include "device/reading_guard.h"
#include "device/safety.h"
#include "device/seqlock.h"
#include "device/tick_record.h"
#include "runtime/backend_registry.h"

namespace vmh::hd {

// One frame of a device as the HD API reports it. Plain data.
struct HdFrame {
  bool valid = false;  // a reading arrived this frame
  double t_s = 0.0;    // the tick's time, s
  double joint_angles_rad[3] = {0, 0, 0};  // t1, t2, t3 (absolute)
  double gimbal_angles_rad[3] = {0, 0, 0};  // t4, t5, t6
  double position_mm[3] = {0, 0, 0};
  double velocity_mm_s[3] = {0, 0, 0};
  double transform[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  double angular_velocity_rad_s[3] = {0, 0, 0};
  double jacobian[36] = {};
  long encoders[6] = {0, 0, 0, 0, 0, 0};
  int buttons = 0;
  unsigned char inkwell = 1;  // 0 while docked
  unsigned char safety_switch = 0;
  double motor_temperature[6] = {0, 0, 0, 0, 0, 0};  // of the cut-off, 0..1
  double rate_hz = 0.0;  // 1 / this tick's period
  // the commands sent at the end of the frame
  double force_N[3] = {0, 0, 0};
  double joint_torque_mNm[3] = {0, 0, 0};
  double gimbal_torque_mNm[3] = {0, 0, 0};
  long dac[3] = {0, 0, 0};
};

// What a frame asks for; cleared at each frame's start (a frame that sets
// nothing sends zero).
struct HdCommand {
  double force_N[3] = {0, 0, 0};
  double joint_torque_mNm[3] = {0, 0, 0};
  double gimbal_torque_mNm[3] = {0, 0, 0};
  long dac[3] = {0, 0, 0};
  bool dac_set = false;
};

// The capabilities (hdEnable) and software limits (hdSet...v). Read when
// the scheduler starts.
struct HdSettings {
  std::atomic<bool> force_output{true};
  std::atomic<bool> max_force_clamping{true};
  std::atomic<bool> force_ramping{false};
  std::atomic<bool> software_force_limit{true};
  std::atomic<bool> one_frame_limit{false};
  std::atomic<bool> velocity_limit_on{true};
  std::atomic<bool> impulse_limit_on{true};
  std::atomic<double> velocity_limit_mm_s{1500.0};
  std::atomic<double> impulse_limit_N{0.1};  // per frame
  std::atomic<double> ramp_rate_N_s{6.6};    // the max force in 0.5 s
  std::atomic<int> status_light{0};
};

// HD errors a frame raised, as a bit set the scheduler pushes on the
// callbacks' error stack (bit i: kFrameErrorCodes[i]).
inline constexpr unsigned kFrameErrorCodes[] = {0x0302 /*COMM_ERROR*/,
                                                0x0201 /*EXCEEDED_MAX_FORCE*/,
                                                0x0202 /*..._FORCE_IMPULSE*/,
                                                0x0203 /*..._VELOCITY*/,
                                                0x0200 /*WARM_MOTORS*/};
inline constexpr int kFrameErrorCount = 5;

class HdDevice {
 public:
  // Opens `spec` (hd_config.h's grammar) through `registry`. Throws
  // runtime::RequestError or DeviceOpenError (what the backend said) or
  // HdConfigError.
  HdDevice(const runtime::BackendRegistry& registry, const std::string& spec,
           bool lockstep);
  ~HdDevice();

  const std::string& spec() const { return spec_; }
  const DeviceIdentity& identity() const { return identity_; }
  DeviceBackend* backend() { return opened_.backend.get(); }
  const runtime::OpenedDevice& opened() const { return opened_; }
  HdSettings& settings() { return settings_; }
  // the backend runs in lockstep (a simulated plant, a replay)
  bool can_lockstep() const { return can_lockstep_; }
  // the box the wrist centre reaches over the arm's joint ranges (device
  // frame, mm: min x, y, z, max x, y, z), from the kinematics: no data
  // sheet gives HD_MAX_WORKSPACE_DIMENSIONS for the Omni
  const double* max_workspace_mm() const { return max_workspace_mm_; }

  // Before the scheduler starts: builds the safety layer from the settings
  // for servo period period_s.
  void arm(double period_s);

  // -- on the servo thread, each tick --
  // reads the device, makes this frame (the previous one becomes LAST);
  // returns the errors raised (kFrameErrorCodes bits)
  unsigned sample(double now_s) noexcept;
  // the command the frame's callbacks set (servo thread only)
  HdCommand& command() noexcept { return command_; }
  // sends the frame's command through the safety layer; returns the errors
  // raised
  unsigned send() noexcept;
  // zero torque now (stop, a failed frame)
  void send_zero() noexcept;

  // this frame and the previous one, servo thread only
  const HdFrame& current() const noexcept { return cur_; }
  const HdFrame& last() const noexcept { return last_; }
  // the last published frames, any thread
  void published(HdFrame* current, HdFrame* last) const noexcept;

  // the simulated plant's truth, where the backend has one
  bool read_truth(PlantTruth* truth) const noexcept;

 private:
  void fill_kinematics(const DeviceState& st, double dt_s) noexcept;

  std::string spec_;
  runtime::OpenedDevice opened_;
  DeviceIdentity identity_;
  bool can_lockstep_ = false;
  OmniParams omni_;
  double max_workspace_mm_[6] = {0, 0, 0, 0, 0, 0};
  HdSettings settings_;
  std::unique_ptr<ReadingGuard> guard_;
  std::unique_ptr<SafetyLayer> safety_;
  HdFrame cur_, last_;
  HdCommand command_;
  Joints q_last_ = Joints::Zero();
  bool have_last_ = false;
  double last_now_s_ = 0.0;
  double period_s_ = 1e-3;
  bool read_failed_ = false;
  SafetyStatus last_status_ = 0;
  struct Published {
    HdFrame current, last;
  };
  Seqlock<Published> pub_;
};

}  // namespace vmh::hd

#endif  // VMHAPTICS_HD_HD_DEVICE_H_
