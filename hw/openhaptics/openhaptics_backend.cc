#include "hw/openhaptics/openhaptics_backend.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace vmh::hw {

using namespace hd;  // NOLINT: the HD names are the subject of this file

OpenHapticsOptions::HdCommand parse_hd_command(const std::string& name) {
  if (name == "joint_torque") return OpenHapticsOptions::kJointTorque;
  if (name == "force") return OpenHapticsOptions::kForce;
  throw std::invalid_argument("--hd-command: unknown value \"" + name +
                              "\" (expected joint_torque or force)");
}

const char* hd_command_name(OpenHapticsOptions::HdCommand c) {
  return c == OpenHapticsOptions::kForce ? "force" : "joint_torque";
}

namespace {

std::string config_label(const std::string& config) {
  return config.empty() ? std::string("the default device")
                        : "device \"" + config + "\"";
}

std::string hex(unsigned v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%x", v);
  return buf;
}

// waits up to timeout_s for done() to hold; false on timeout
template <typename F>
bool wait_for(F done, double timeout_s) {
  const double until = monotonic_now_s() + timeout_s;
  while (!done()) {
    if (monotonic_now_s() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

}  // namespace

// -- opening --

OpenHapticsBackend::OpenHapticsBackend(const Options& options)
    : options_(options) {
  lib_ = std::make_unique<HdLibrary>();
  api_ = &lib_->api();
  const HDstring cfg = options_.config.empty() ? nullptr : options_.config.c_str();
  handle_ = api_->hdInitDevice(cfg);
  if (handle_ == kInvalidHandle) {
    const HDerror code = setup_error();
    throw DeviceOpenError("openhaptics: cannot open " +
                          config_label(options_.config) + " (hdInitDevice, " +
                          lib_->file() + "): " + describe(code));
  }
  api_->hdMakeCurrentDevice(handle_);

  auto text = [&](HDenum param) {
    const HDstring s = api_->hdGetString(param);
    return s != nullptr ? std::string(s) : std::string();
  };
  identity_.backend = "openhaptics";
  identity_.config = options_.config;
  identity_.model = text(kDeviceModelType);
  identity_.vendor = text(kDeviceVendor);
  identity_.serial = text(kDeviceSerialNumber);
  identity_.driver_version = text(kDeviceDriverVersion);
  identity_.firmware_version = text(kDeviceFirmwareVersion);
  identity_.api_version = text(kVersion);
  HDint dof = 0;
  api_->hdGetIntegerv(kInputDof, &dof);
  identity_.input_dof = dof;
  dof = 0;
  api_->hdGetIntegerv(kOutputDof, &dof);
  identity_.output_dof = dof;
  setup_error();  // a string the device lacks stays empty

  // optional state: read once; a device without it answers with an error
  HDlong counts[16] = {};
  api_->hdGetLongv(kCurrentEncoderValues, counts);
  has_encoders_ = setup_error() == kSuccess;
  HDboolean inkwell = 0;
  api_->hdGetBooleanv(kCurrentInkwellSwitch, &inkwell);
  has_inkwell_ = setup_error() == kSuccess;
}

OpenHapticsBackend::~OpenHapticsBackend() { stop(); }

HDerror OpenHapticsBackend::setup_error() noexcept {
  HDerror first = kSuccess;
  for (int i = 0; i < 64; ++i) {
    const HDErrorInfo e = api_->hdGetError();
    if (e.errorCode == kSuccess) break;
    if (first == kSuccess) first = e.errorCode;
  }
  return first;
}

std::string OpenHapticsBackend::describe(HDerror code) const {
  if (code == kSuccess) return "no HD error reported";
  const HDstring s = api_->hdGetErrorString(code);
  std::string out = "HD error " + hex(code) + " " + hd_error_name(code);
  if (s != nullptr && *s != '\0') out += " (" + std::string(s) + ")";
  return out;
}

// -- calibration --

HDCallbackCode OpenHapticsBackend::calibration_callback(void* self) noexcept {
  auto* b = static_cast<OpenHapticsBackend*>(self);
  b->api_->hdBeginFrame(b->handle_);
  b->calibration_result_ = b->api_->hdCheckCalibration();
  b->api_->hdEndFrame(b->handle_);
  return kCallbackDone;
}

CalibrationState OpenHapticsBackend::calibration_state() {
  if (handle_ == kInvalidHandle) return CalibrationState::kUnknown;
  if (running()) {
    // the state the check looks at is sampled in a frame
    api_->hdScheduleSynchronous(&calibration_callback, this,
                                kDefaultSchedulerPriority);
  } else {
    calibration_result_ = api_->hdCheckCalibration();
  }
  return calibration_from_hd(calibration_result_);
}

CalibrationState OpenHapticsBackend::update_calibration() {
  if (handle_ == kInvalidHandle) {
    throw DeviceOpenError("openhaptics: update_calibration on a stopped device");
  }
  HDint styles = 0;
  api_->hdGetIntegerv(kCalibrationStyle, &styles);
  const HDint style = calibration_style_to_use(styles);
  if (style == 0) {
    throw DeviceOpenError("openhaptics: " + config_label(options_.config) +
                          " names no calibration style (HD_CALIBRATION_STYLE = " +
                          hex(static_cast<unsigned>(styles)) + ")");
  }
  api_->hdUpdateCalibration(static_cast<HDenum>(style));
  const HDerror code = setup_error();
  if (code != kSuccess) {
    throw DeviceOpenError("openhaptics: hdUpdateCalibration(" +
                          std::to_string(style) + ") failed: " + describe(code));
  }
  return calibration_state();
}

// -- the servo callback --

void OpenHapticsBackend::read_frame_state() noexcept {
  if (fault_.load(std::memory_order_relaxed) != 0) return;
  DeviceState& s = frame_state_;
  double arm_rad[3] = {0, 0, 0};
  double gimbal_rad[3] = {0, 0, 0};
  api_->hdGetDoublev(kCurrentJointAngles, arm_rad);
  api_->hdGetDoublev(kCurrentGimbalAngles, gimbal_rad);
  s.q_device_rad << arm_rad[0], arm_rad[1], arm_rad[2], gimbal_rad[0],
      gimbal_rad[1], gimbal_rad[2];
  s.present = kStateJoints | kStateButtons | kStateTimestamp |
              kStateTransform | kStateVelocity | kStateJacobian;
  s.timestamp_s = frame_time_s();
  HDint buttons = 0;
  api_->hdGetIntegerv(kCurrentButtons, &buttons);
  s.buttons = buttons_from_hd(buttons);
  if (has_inkwell_) {
    HDboolean inkwell = 1;
    api_->hdGetBooleanv(kCurrentInkwellSwitch, &inkwell);
    s.docked = docked_from_hd(inkwell);
    s.present |= kStateInkwell;
  }
  double transform_mm[16];
  api_->hdGetDoublev(kCurrentTransform, transform_mm);
  s.transform_mm = transform_from_hd(transform_mm);
  double velocity_mm_s[3] = {0, 0, 0};
  api_->hdGetDoublev(kCurrentVelocity, velocity_mm_s);
  s.velocity_mm_s << velocity_mm_s[0], velocity_mm_s[1], velocity_mm_s[2];
  // stored as read; its layout is unconfirmed (docs/openhaptics.md)
  double jacobian[36];
  api_->hdGetDoublev(kCurrentJacobian, jacobian);
  s.jacobian = Eigen::Map<const Eigen::Matrix<double, 6, 6>>(jacobian);
  if (has_encoders_) {
    // more room than any device reports, in case it writes six
    HDlong counts[16] = {};
    api_->hdGetLongv(kCurrentEncoderValues, counts);
    for (int i = 0; i < 3; ++i) {
      s.encoder_counts[i] = static_cast<std::int32_t>(counts[i]);
    }
    s.present |= kStateEncoders;
  }
  have_frame_ = true;
}

void OpenHapticsBackend::send_torque(const Vec3& tau_motor_Nm) noexcept {
  Vec3 out;
  HDenum param;
  if (options_.command == Options::kForce) {
    param = kCurrentForce;
    out = have_frame_ ? force_for_motor_torques_N(options_.omni,
                                                  frame_state_.q_device_rad,
                                                  tau_motor_Nm)
                      : Vec3::Zero();
  } else {
    param = kCurrentJointTorque;
    out = torque_Nm_to_mNm(tau_motor_Nm);
  }
  if (!out.allFinite()) out.setZero();
  const double v[3] = {out[0], out[1], out[2]};
  api_->hdSetDoublev(param, v);
}

void OpenHapticsBackend::drain_errors() noexcept {
  // bounded: a library that never empties its stack must not hang the frame
  for (int i = 0; i < 32; ++i) {
    const HDErrorInfo e = api_->hdGetError();
    if (e.errorCode == kSuccess) return;
    const int idx = hd_error_index(e.errorCode);
    error_counts_[idx].fetch_add(1, std::memory_order_relaxed);
    if (idx == kHdKnownErrorCount) {
      last_unknown_code_.store(e.errorCode, std::memory_order_relaxed);
    }
    last_code_.store(e.errorCode, std::memory_order_relaxed);
    const HdErrorClass c = classify_hd_error(e.errorCode);
    if (c.fatal) {
      fatal_count_.fetch_add(1, std::memory_order_relaxed);
      int none = 0;
      const int err = static_cast<int>(c.error == DeviceError::kOk
                                           ? DeviceError::kIo
                                           : c.error);
      fault_.compare_exchange_strong(none, err, std::memory_order_relaxed);
    } else {
      warnings_.fetch_add(1, std::memory_order_relaxed);
    }
  }
}

HDCallbackCode OpenHapticsBackend::servo_callback(void* self) noexcept {
  auto* b = static_cast<OpenHapticsBackend*>(self);
  if (b->stop_requested_.load(std::memory_order_acquire)) {
    b->running_.store(false, std::memory_order_release);
    return kCallbackDone;
  }
  if (b->frames_.load(std::memory_order_relaxed) == 0) {
    int policy = -1;
    sched_param param{};
    if (pthread_getschedparam(pthread_self(), &policy, &param) == 0) {
      b->sched_policy_.store(policy, std::memory_order_relaxed);
    }
  }
  const HdApi& api = *b->api_;
  api.hdBeginFrame(b->handle_);
  b->drain_errors();  // a device that stopped answering says so here
  b->read_frame_state();
  const double now_s = b->frame_time_s();
  const double work_start_s = monotonic_now_s();
  b->timer_.begin(now_s);
  const bool go_on = b->loop_->tick(now_s);
  b->timer_.end(now_s + (monotonic_now_s() - work_start_s));
  // the last frame of a loop that ended, and every frame after a fatal
  // error, sends zero
  const bool zero = !go_on || b->fault_.load(std::memory_order_relaxed) != 0;
  b->send_torque(zero ? Vec3::Zero() : b->tau_cmd_Nm_);
  api.hdEndFrame(b->handle_);
  b->drain_errors();
  b->frames_.fetch_add(1, std::memory_order_release);
  if (!go_on) {
    b->running_.store(false, std::memory_order_release);
    return kCallbackDone;
  }
  return kCallbackContinue;
}

double OpenHapticsBackend::frame_time_s() const noexcept {
  return api_->vmhdGetSchedulerTime != nullptr ? api_->vmhdGetSchedulerTime()
                                               : monotonic_now_s();
}

bool OpenHapticsBackend::read_truth(PlantTruth* truth) const noexcept {
  if (api_->vmhdReadTruth == nullptr || handle_ == kInvalidHandle) return false;
  return api_->vmhdReadTruth(handle_, truth, sizeof(PlantTruth)) == 1;
}

HDCallbackCode OpenHapticsBackend::zero_callback(void* self) noexcept {
  auto* b = static_cast<OpenHapticsBackend*>(self);
  b->api_->hdBeginFrame(b->handle_);
  b->send_torque(Vec3::Zero());
  b->api_->hdEndFrame(b->handle_);
  b->drain_errors();
  return kCallbackDone;
}

// -- the device the loop sees --

DeviceError OpenHapticsBackend::FrameDevice::read_joints(
    Joints* q_device_rad) noexcept {
  return joints_of_state(q_device_rad);
}

DeviceError OpenHapticsBackend::FrameDevice::read_state(
    DeviceState* state) noexcept {
  const int fault = owner_->fault_.load(std::memory_order_relaxed);
  if (fault != 0) {
    state->present = 0;
    return static_cast<DeviceError>(fault);
  }
  if (!owner_->have_frame_) {
    state->present = 0;
    return DeviceError::kNotConnected;
  }
  if (!owner_->frame_state_.q_device_rad.allFinite()) {
    state->present = 0;
    return DeviceError::kSensorFault;
  }
  *state = owner_->frame_state_;
  return DeviceError::kOk;
}

DeviceError OpenHapticsBackend::FrameDevice::write_motor_torques(
    const Vec3& tau_motor_Nm) noexcept {
  if (!tau_motor_Nm.allFinite()) {
    owner_->tau_cmd_Nm_.setZero();
    return DeviceError::kInvalidCommand;
  }
  const int fault = owner_->fault_.load(std::memory_order_relaxed);
  if (fault != 0) {
    owner_->tau_cmd_Nm_.setZero();
    return static_cast<DeviceError>(fault);
  }
  owner_->tau_cmd_Nm_ = tau_motor_Nm;
  return DeviceError::kOk;
}

// -- starting and stopping --

ServoReport OpenHapticsBackend::start(ServoLoop* loop,
                                      const ServoOptions& options) {
  if (stopped_.load()) {
    throw DeviceOpenError("openhaptics: the backend was stopped; open " +
                          config_label(options_.config) + " again");
  }
  if (started_.load()) throw DeviceOpenError("openhaptics: already started");
  if (loop == nullptr) throw DeviceOpenError("openhaptics: start without a loop");
  if (options.lockstep) {
    throw DeviceOpenError("openhaptics: the HD scheduler runs on the wall "
                          "clock; lockstep is for the emulator (--clock "
                          "realtime)");
  }
  if (!(std::fabs(options.period_s - 1e-3) <= 1e-9)) {
    throw DeviceOpenError(
        "openhaptics: the HD scheduler runs at 1 kHz; period_s = " +
        std::to_string(options.period_s) + " is not supported");
  }
  ServoReport report;
  if (options.realtime) {
    report.memory_locked = mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
    if (!report.memory_locked) {
      report.note = std::string("mlockall: ") + std::strerror(errno) +
                    " (raise RLIMIT_MEMLOCK, e.g. ulimit -l unlimited); ";
    }
  }
  loop_ = loop;
  timer_.reset();
  tau_cmd_Nm_.setZero();
  have_frame_ = false;
  setup_error();  // anything left from opening

  api_->hdEnable(kForceOutput);
  HDerror code = setup_error();
  if (code != kSuccess) {
    throw DeviceOpenError("openhaptics: hdEnable(HD_FORCE_OUTPUT) failed: " +
                          describe(code));
  }
  servo_handle_ = api_->hdScheduleAsynchronous(&servo_callback, this,
                                               kMaxSchedulerPriority);
  code = setup_error();
  if (code != kSuccess) {
    throw DeviceOpenError("openhaptics: hdScheduleAsynchronous failed: " +
                          describe(code));
  }
  started_.store(true);
  running_.store(true, std::memory_order_release);
  api_->hdStartScheduler();
  code = setup_error();
  if (code != kSuccess) {
    stop();  // no scheduler: stop() does not ask it for a zero frame
    throw DeviceOpenError("openhaptics: hdStartScheduler failed: " +
                          describe(code));
  }
  scheduler_ok_ = true;
  const bool ran = wait_for(
      [&] {
        return frames_.load(std::memory_order_acquire) > 0 || !running();
      },
      2.0);
  if (!ran) {
    scheduler_ok_ = false;  // a synchronous call could wait for ever
    stop();
    throw DeviceOpenError(
        "openhaptics: the HD scheduler ran no servo frame within 2 s");
  }
  const int policy = sched_policy_.load(std::memory_order_relaxed);
  report.sched_fifo = policy == SCHED_FIFO;
  report.note += "the servo loop runs on the HD scheduler's thread (policy " +
                 std::string(policy == SCHED_FIFO   ? "SCHED_FIFO"
                             : policy == SCHED_RR   ? "SCHED_RR"
                             : policy == SCHED_OTHER ? "SCHED_OTHER"
                                                     : "unknown") +
                 ", set by libHD)";
  return report;
}

void OpenHapticsBackend::stop() noexcept {
  if (stopped_.exchange(true)) return;
  if (started_.load()) {
    stop_requested_.store(true, std::memory_order_release);
    // a scheduler that stopped calling (a dead device) must not hang stop(),
    // nor be asked for a synchronous frame it would never run
    const bool ended = wait_for([&] { return !running(); }, 1.0);
    if (scheduler_ok_ && ended) {
      api_->hdScheduleSynchronous(&zero_callback, this, kMaxSchedulerPriority);
    }
    api_->hdStopScheduler();
    api_->hdUnschedule(servo_handle_);
  }
  running_.store(false, std::memory_order_release);
  if (handle_ != kInvalidHandle) {
    api_->hdDisableDevice(handle_);
    handle_ = kInvalidHandle;
  }
  setup_error();
}

HdErrorReport OpenHapticsBackend::last_errors() const {
  HdErrorReport r;
  r.last_code = last_code_.load(std::memory_order_relaxed);
  r.last_name = r.last_code == kSuccess ? std::string() : hd_error_name(r.last_code);
  r.warnings = warnings_.load(std::memory_order_relaxed);
  r.fatal = fatal_count_.load(std::memory_order_relaxed);
  for (int i = 0; i <= kHdKnownErrorCount; ++i) {
    const long n = error_counts_[i].load(std::memory_order_relaxed);
    if (n == 0) continue;
    const HDerror code = i < kHdKnownErrorCount
                             ? kHdKnownErrors[i]
                             : last_unknown_code_.load(std::memory_order_relaxed);
    r.counts.push_back({hd_error_name(code), code,
                        classify_hd_error(code).fatal, n});
  }
  return r;
}

}  // namespace vmh::hw
