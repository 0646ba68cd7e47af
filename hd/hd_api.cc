// The open HD API (include/HD/hd.h): the exported C functions, the devices
// table, the error stacks and the scheduler. docs/libhd.md is the account
// of what each call does here.
//
// Threads. The scheduler's servo thread is the primary device's own (the
// backend's servo thread on the wall clock) or the library's lockstep
// thread (VMH_HD_CLOCK=lockstep: each tick runs one servo period of every
// simulated plant). Callbacks run there, highest priority first. A tick
// neither allocates nor throws: the callbacks run from a fixed table copied
// under a short lock, errors go to a fixed per-thread stack.
#define VMHAPTICS_HD_BUILDING 1
#include <HD/hd.h>
#include <HD/vmhd.h>

#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "hd/hd_config.h"
#include "hd/hd_device.h"
#include "hd/hd_registry.h"
#include "hw/omni_calibration.h"

namespace vmh::hd {
namespace {

constexpr int kMaxDevices = 4;
constexpr int kMaxCallbacks = 64;
constexpr int kErrorDepth = 32;

// internal error codes (HDErrorInfo::internalErrorCode), docs/libhd.md
enum Internal : int {
  kInternalNone = 0,
  kInternalNameNotConfigured = 1,
  kInternalConfigFile = 2,
  kInternalBackendRefused = 3,
  kInternalDeviceNotFound = 4,
  kInternalTooManyDevices = 5,
  kInternalSchedulerStart = 6,
  kInternalNotInScheduler = 7,
  kInternalFrameState = 8,
  kInternalReadOnly = 9,
  kInternalUnknownParameter = 10,
  // 11 is not used: every state call is answered outside a frame too (the
  // last published tick), so none raises HD_FRAME_ERROR
  kInternalSafety = 12,
};

// -- errors: a stack per thread, the most recent on top --
struct ErrorStack {
  HDErrorInfo e[kErrorDepth];
  int n = 0;
};
thread_local ErrorStack t_errors;

void push_error(HDerror code, int internal, HHD h) noexcept {
  ErrorStack& s = t_errors;
  if (s.n == kErrorDepth) {  // the oldest is dropped
    std::memmove(&s.e[0], &s.e[1], sizeof(HDErrorInfo) * (kErrorDepth - 1));
    --s.n;
  }
  s.e[s.n++] = HDErrorInfo{code, internal, h};
}

// the cause of the last failure of each code (hdGetErrorString), written
// only off the servo thread
std::mutex g_detail_mu;
std::string g_detail[8];  // index: kind below
int detail_slot(HDerror code) {
  switch (code) {
    case HD_COMM_CONFIG_ERROR: return 0;
    case HD_COMM_ERROR: return 1;
    case HD_DEVICE_FAULT: return 2;
    case HD_TIMER_ERROR: return 3;
    case HD_DEVICE_ALREADY_INITIATED: return 4;
    case HD_INVALID_VALUE: return 5;
    case HD_INVALID_OPERATION: return 6;
    default: return -1;
  }
}
void set_detail(HDerror code, const std::string& text) {
  const int i = detail_slot(code);
  if (i < 0) return;
  std::lock_guard<std::mutex> lock(g_detail_mu);
  g_detail[i] = text;
  if (std::getenv("VMH_HD_QUIET") == nullptr) {
    std::fprintf(stderr, "vmhaptics libHD: %s\n", text.c_str());
  }
}

const char* base_text(HDerror code) {
  switch (code) {
    case HD_SUCCESS: return "no error";
    case HD_INVALID_ENUM: return "invalid parameter name";
    case HD_INVALID_VALUE: return "invalid value";
    case HD_INVALID_OPERATION: return "invalid operation";
    case HD_INVALID_INPUT_TYPE: return "the parameter cannot be read or set as this type";
    case HD_BAD_HANDLE: return "no device has that handle";
    case HD_WARM_MOTORS: return "the motors are warm: the force is derated";
    case HD_EXCEEDED_MAX_FORCE: return "the force asked for exceeded the maximum";
    case HD_EXCEEDED_MAX_FORCE_IMPULSE: return "the force changed faster than the impulse limit allows";
    case HD_EXCEEDED_MAX_VELOCITY: return "the device moved faster than the velocity limit: force cut";
    case HD_FORCE_ERROR: return "force error";
    case HD_DEVICE_FAULT: return "device fault";
    case HD_DEVICE_ALREADY_INITIATED: return "the device is already initialised";
    case HD_COMM_ERROR: return "communication with the device failed";
    case HD_COMM_CONFIG_ERROR: return "the device could not be opened";
    case HD_TIMER_ERROR: return "the servo loop could not be started";
    case HD_ILLEGAL_BEGIN: return "hdBeginFrame in a frame of that device";
    case HD_ILLEGAL_END: return "hdEndFrame without hdBeginFrame";
    case HD_FRAME_ERROR: return "a state call outside the frame it needs";
    case HD_INVALID_PRIORITY: return "invalid scheduler priority";
    case HD_SCHEDULER_FULL: return "the scheduler has no room for another callback";
    case HD_INVALID_LICENSE: return "licence error (never raised here)";
    default: return "unknown HD error code";
  }
}

// -- the devices --
struct Context {
  std::mutex mu;  // devices table, scheduler state (never held by a tick)
  std::unique_ptr<HdDevice> devices[kMaxDevices];
  std::atomic<HdDevice*> live[kMaxDevices] = {};
  std::atomic<HHD> current{HD_INVALID_HANDLE};
  std::atomic<bool> running{false};
  std::atomic<bool> lockstep{false};
  double rate_hz = 1000.0;
  std::thread lockstep_thread;
  std::atomic<bool> lockstep_run{false};
  std::atomic<double> tick_start_wall_s{0.0};
  std::atomic<double> tick_now_s{0.0};  // the tick's own time
  std::atomic<pthread_t> servo_thread{};
  std::atomic<bool> servo_thread_known{false};
};
Context& ctx() {
  static Context* c = new Context;  // never destroyed: threads may outlive exit
  return *c;
}

thread_local HHD t_current = HD_INVALID_HANDLE;
thread_local int t_frame_depth[kMaxDevices] = {};

double wall_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

bool on_servo_thread() {
  Context& c = ctx();
  return c.running.load(std::memory_order_acquire) &&
         c.servo_thread_known.load(std::memory_order_acquire) &&
         pthread_equal(pthread_self(), c.servo_thread.load());
}

HHD current_handle() {
  return t_current != HD_INVALID_HANDLE ? t_current : ctx().current.load();
}

HdDevice* device_of(HHD h) {
  if (h >= static_cast<HHD>(kMaxDevices)) return nullptr;
  return ctx().live[h].load(std::memory_order_acquire);
}

HdDevice* current_device() {
  const HHD h = current_handle();
  HdDevice* d = device_of(h);
  if (d == nullptr) push_error(HD_BAD_HANDLE, kInternalNone, h);
  return d;
}

// -- the scheduler's callbacks --
struct Slot {
  HDSchedulerCallback cb = nullptr;
  void* user = nullptr;
  HDushort priority = 0;
  HDSchedulerHandle handle = 0;
  bool active = false;
  bool sync = false;
  bool done = false;
  std::uint64_t order = 0;
};
std::mutex g_sched_mu;
std::condition_variable g_sched_cv;
Slot g_slots[kMaxCallbacks];
HDSchedulerHandle g_next_handle = 1;
std::uint64_t g_next_order = 0;

void push_frame_errors(unsigned bits, HHD h) noexcept {
  for (int i = 0; i < kFrameErrorCount; ++i) {
    if (bits & (1u << i)) push_error(kFrameErrorCodes[i], kInternalSafety, h);
  }
}

// One tick: every device sampled, the callbacks run, every device sent.
bool run_tick(double now_s) noexcept {
  Context& c = ctx();
  if (!c.servo_thread_known.load(std::memory_order_relaxed)) {
    c.servo_thread.store(pthread_self());
    c.servo_thread_known.store(true, std::memory_order_release);
  }
  c.tick_start_wall_s.store(wall_s(), std::memory_order_relaxed);
  c.tick_now_s.store(now_s, std::memory_order_relaxed);
  for (HHD h = 0; h < static_cast<HHD>(kMaxDevices); ++h) {
    if (HdDevice* d = c.live[h].load(std::memory_order_acquire)) {
      push_frame_errors(d->sample(now_s), h);
    }
  }
  Slot run[kMaxCallbacks];
  int n = 0;
  {
    std::lock_guard<std::mutex> lock(g_sched_mu);
    for (const Slot& s : g_slots) {
      if (s.active) run[n++] = s;
    }
  }
  // highest priority first, earlier scheduled first among equals
  // (insertion sort: std::stable_sort would allocate)
  for (int i = 1; i < n; ++i) {
    for (int j = i; j > 0 && (run[j - 1].priority < run[j].priority ||
                              (run[j - 1].priority == run[j].priority &&
                               run[j - 1].order > run[j].order));
         --j) {
      std::swap(run[j - 1], run[j]);
    }
  }
  bool finished = false;
  for (int i = 0; i < n; ++i) {
    const HDCallbackCode r = run[i].cb(run[i].user);
    if (r != HD_CALLBACK_DONE && !run[i].sync) continue;
    std::lock_guard<std::mutex> lock(g_sched_mu);
    for (Slot& s : g_slots) {
      if (s.active && s.handle == run[i].handle) {
        s.active = false;
        s.done = true;
        finished = true;
      }
    }
  }
  if (finished) g_sched_cv.notify_all();
  for (HHD h = 0; h < static_cast<HHD>(kMaxDevices); ++h) {
    if (t_frame_depth[h] != 0) {  // a frame left open by a callback
      t_frame_depth[h] = 0;
      push_error(HD_ILLEGAL_END, kInternalFrameState, h);
    }
    if (HdDevice* d = c.live[h].load(std::memory_order_acquire)) {
      push_frame_errors(d->send(), h);
    }
  }
  return true;
}

class SchedulerLoop final : public ServoLoop {
 public:
  bool tick(double now_s) noexcept override { return run_tick(now_s); }
};
class IdleLoop final : public ServoLoop {
 public:
  bool tick(double) noexcept override { return true; }
};
SchedulerLoop g_loop;
IdleLoop g_idle;

bool parse_lockstep() {
  const char* v = std::getenv("VMH_HD_CLOCK");
  return v != nullptr && std::string(v) == "lockstep";
}

}  // namespace

// the registry the library opens devices from (hd_registry.cc)
}  // namespace vmh::hd

using namespace vmh::hd;  // NOLINT: this file implements the C API

// The header declares every hd* function extern "C"; these definitions
// take that linkage from it.

// ---- devices ----

HDAPI HHD HDAPIENTRY hdInitDevice(HDstring config_name) {
  Context& c = ctx();
  const std::string shown = config_name == nullptr ? "HD_DEFAULT_DEVICE"
                                                    : std::string(config_name);
  // a refusal: its cause, after the call as the program made it, kept for
  // hdGetErrorString (and printed), its code on the error stack
  const auto refuse = [&shown](HDerror code, int internal, HHD h,
                               const std::string& cause) -> HHD {
    set_detail(code, "hdInitDevice(\"" + shown + "\")" + cause);
    push_error(code, internal, h);
    return HD_INVALID_HANDLE;
  };
  std::string spec;
  try {
    spec = resolve_device_name(load_hd_config(), config_name);
  } catch (const HdConfigError& e) {
    const bool file = std::string(e.what()).rfind("no device is configured", 0) != 0;
    return refuse(HD_COMM_CONFIG_ERROR,
                  file ? kInternalConfigFile : kInternalNameNotConfigured,
                  HD_INVALID_HANDLE, std::string(": ") + e.what());
  }
  std::lock_guard<std::mutex> lock(c.mu);
  if (c.running.load()) {
    return refuse(HD_INVALID_OPERATION, kInternalNone, HD_INVALID_HANDLE,
                  ": stop the scheduler before opening another device");
  }
  for (HHD h = 0; h < static_cast<HHD>(kMaxDevices); ++h) {
    if (c.devices[h] && c.devices[h]->spec() == spec) {
      return refuse(HD_DEVICE_ALREADY_INITIATED, kInternalNone, h,
                    ": '" + spec + "' is already open as handle " +
                        std::to_string(h));
    }
  }
  HHD slot = HD_INVALID_HANDLE;
  for (HHD h = 0; h < static_cast<HHD>(kMaxDevices); ++h) {
    if (!c.devices[h]) {
      slot = h;
      break;
    }
  }
  if (slot == HD_INVALID_HANDLE) {
    return refuse(HD_COMM_CONFIG_ERROR, kInternalTooManyDevices, HD_INVALID_HANDLE,
                  ": " + std::to_string(kMaxDevices) + " devices are open already");
  }
  const std::string opening = " -> '" + spec + "': ";
  const bool lockstep = parse_lockstep();
  try {
    c.devices[slot] = std::make_unique<HdDevice>(library_registry(), spec, lockstep);
  } catch (const vmh::DeviceOpenError& e) {
    return refuse(HD_COMM_CONFIG_ERROR, kInternalDeviceNotFound, HD_INVALID_HANDLE,
                  opening + e.what());
  } catch (const std::exception& e) {
    return refuse(HD_COMM_CONFIG_ERROR, kInternalBackendRefused, HD_INVALID_HANDLE,
                  opening + e.what());
  }
  if (lockstep && !c.devices[slot]->can_lockstep()) {
    c.devices[slot].reset();
    return refuse(HD_COMM_CONFIG_ERROR, kInternalBackendRefused, HD_INVALID_HANDLE,
                  opening +
                      "VMH_HD_CLOCK=lockstep needs a simulated device "
                      "(emulator...) or a recording (replay:DIR); a real "
                      "device runs on the wall clock");
  }
  c.lockstep.store(lockstep);
  c.live[slot].store(c.devices[slot].get(), std::memory_order_release);
  c.current.store(slot);
  t_current = slot;
  return slot;
}

HDAPI void HDAPIENTRY hdDisableDevice(HHD h) {
  Context& c = ctx();
  if (device_of(h) == nullptr) {
    push_error(HD_BAD_HANDLE, kInternalNone, h);
    return;
  }
  bool others = false;
  for (HHD i = 0; i < static_cast<HHD>(kMaxDevices); ++i) {
    if (i != h && device_of(i) != nullptr) others = true;
  }
  // the scheduler's ticks hold every device: it stops while one leaves,
  // and starts again for the others (docs/libhd.md)
  const bool was_running = c.running.load();
  if (was_running) hdStopScheduler();
  {
    std::lock_guard<std::mutex> lock(c.mu);
    c.live[h].store(nullptr, std::memory_order_release);
    c.devices[h]->send_zero();
    c.devices[h].reset();
  }
  if (was_running && others) hdStartScheduler();
  if (c.current.load() == h) c.current.store(HD_INVALID_HANDLE);
  if (t_current == h) t_current = HD_INVALID_HANDLE;
}

HDAPI HHD HDAPIENTRY hdGetCurrentDevice(void) {
  const HHD h = current_handle();
  if (device_of(h) == nullptr) {
    push_error(HD_BAD_HANDLE, kInternalNone, h);
    return HD_INVALID_HANDLE;
  }
  return h;
}

HDAPI void HDAPIENTRY hdMakeCurrentDevice(HHD h) {
  if (device_of(h) == nullptr) {
    push_error(HD_BAD_HANDLE, kInternalNone, h);
    return;
  }
  t_current = h;
  if (!on_servo_thread()) ctx().current.store(h);
}

HDAPI void HDAPIENTRY hdBeginFrame(HHD h) {
  if (device_of(h) == nullptr) {
    push_error(HD_BAD_HANDLE, kInternalNone, h);
    return;
  }
  t_current = h;
  if (!on_servo_thread()) return;  // outside the scheduler: nothing to frame
  ++t_frame_depth[h];  // nested frames share the tick's sample
}

HDAPI void HDAPIENTRY hdEndFrame(HHD h) {
  if (device_of(h) == nullptr) {
    push_error(HD_BAD_HANDLE, kInternalNone, h);
    return;
  }
  if (!on_servo_thread()) return;
  if (t_frame_depth[h] == 0) {
    push_error(HD_ILLEGAL_END, kInternalFrameState, h);
    return;
  }
  --t_frame_depth[h];  // the command goes out when the tick ends
}

// ---- capabilities ----

namespace {
std::atomic<bool>* capability(HdDevice* d, HDenum cap) {
  HdSettings& s = d->settings();
  switch (cap) {
    case HD_FORCE_OUTPUT: return &s.force_output;
    case HD_MAX_FORCE_CLAMPING: return &s.max_force_clamping;
    case HD_FORCE_RAMPING: return &s.force_ramping;
    case HD_SOFTWARE_FORCE_LIMIT: return &s.software_force_limit;
    case HD_ONE_FRAME_LIMIT: return &s.one_frame_limit;
    case HD_SOFTWARE_VELOCITY_LIMIT: return &s.velocity_limit_on;
    case HD_SOFTWARE_FORCE_IMPULSE_LIMIT: return &s.impulse_limit_on;
    default: return nullptr;
  }
}
void set_capability(HDenum cap, bool on) {
  HdDevice* d = current_device();
  if (d == nullptr) return;
  std::atomic<bool>* a = capability(d, cap);
  if (a == nullptr) {
    push_error(HD_INVALID_ENUM, kInternalUnknownParameter, current_handle());
    return;
  }
  a->store(on);
}
}  // namespace

HDAPI void HDAPIENTRY hdEnable(HDenum cap) { set_capability(cap, true); }
HDAPI void HDAPIENTRY hdDisable(HDenum cap) { set_capability(cap, false); }
HDAPI HDboolean HDAPIENTRY hdIsEnabled(HDenum cap) {
  HdDevice* d = current_device();
  if (d == nullptr) return HD_FALSE;
  std::atomic<bool>* a = capability(d, cap);
  if (a == nullptr) {
    push_error(HD_INVALID_ENUM, kInternalUnknownParameter, current_handle());
    return HD_FALSE;
  }
  return a->load() ? HD_TRUE : HD_FALSE;
}

// ---- state ----

namespace {

// Every value a parameter has, as doubles (n of them), for the typed getters.
// Returns n, 0 for a parameter that is not readable as a number.
int read_numbers(HdDevice* d, HDenum p, double* out) {
  HdFrame cur, last;
  if (on_servo_thread()) {
    cur = d->current();
    last = d->last();
  } else {
    d->published(&cur, &last);
  }
  // a LAST_ parameter reads the previous frame under its CURRENT_ name
  bool is_last = true;
  HDenum q = p;
  switch (p) {
    case HD_LAST_FORCE: q = HD_CURRENT_FORCE; break;
    case HD_LAST_TORQUE: q = HD_CURRENT_TORQUE; break;
    case HD_LAST_JOINT_TORQUE: q = HD_CURRENT_JOINT_TORQUE; break;
    case HD_LAST_GIMBAL_TORQUE: q = HD_CURRENT_GIMBAL_TORQUE; break;
    case HD_LAST_MOTOR_DAC_VALUES: q = HD_CURRENT_MOTOR_DAC_VALUES; break;
    default:
      if (p >= 0x2200 && p < 0x2400) {
        q = p - 0x200;
      } else {
        is_last = false;
      }
  }
  // on the servo thread a command reads back what this frame set so far
  if (!is_last && on_servo_thread()) {
    const HdCommand& cmd = d->command();
    switch (q) {
      case HD_CURRENT_FORCE: std::copy(cmd.force_N, cmd.force_N + 3, cur.force_N); break;
      case HD_CURRENT_JOINT_TORQUE:
        std::copy(cmd.joint_torque_mNm, cmd.joint_torque_mNm + 3, cur.joint_torque_mNm);
        break;
      case HD_CURRENT_TORQUE:
      case HD_CURRENT_GIMBAL_TORQUE:
        std::copy(cmd.gimbal_torque_mNm, cmd.gimbal_torque_mNm + 3, cur.gimbal_torque_mNm);
        break;
      case HD_CURRENT_MOTOR_DAC_VALUES: std::copy(cmd.dac, cmd.dac + 3, cur.dac); break;
      default: break;
    }
  }
  const HdFrame& f = is_last ? last : cur;
  const auto copy = [out](const double* v, int n) {
    std::copy(v, v + n, out);
    return n;
  };
  const HdSettings& s = d->settings();
  const vmh::DeviceIdentity& id = d->identity();
  switch (q) {
    case HD_CURRENT_BUTTONS: out[0] = f.buttons; return 1;
    case HD_CURRENT_SAFETY_SWITCH: out[0] = f.safety_switch; return 1;
    case HD_CURRENT_INKWELL_SWITCH: out[0] = f.inkwell; return 1;
    case HD_CURRENT_ENCODER_VALUES:
      for (int i = 0; i < 6; ++i) out[i] = static_cast<double>(f.encoders[i]);
      return 6;
    case HD_CURRENT_POSITION: return copy(f.position_mm, 3);
    case HD_CURRENT_VELOCITY: return copy(f.velocity_mm_s, 3);
    case HD_CURRENT_TRANSFORM: return copy(f.transform, 16);
    case HD_CURRENT_ANGULAR_VELOCITY: return copy(f.angular_velocity_rad_s, 3);
    case HD_CURRENT_JACOBIAN: return copy(f.jacobian, 36);
    case HD_CURRENT_JOINT_ANGLES: return copy(f.joint_angles_rad, 3);
    case HD_CURRENT_GIMBAL_ANGLES: return copy(f.gimbal_angles_rad, 3);
    // commands (0x27xx) and, shifted above, their LAST (0x28xx)
    case HD_CURRENT_FORCE: return copy(f.force_N, 3);
    case HD_CURRENT_TORQUE:
    case HD_CURRENT_GIMBAL_TORQUE: return copy(f.gimbal_torque_mNm, 3);
    case HD_CURRENT_JOINT_TORQUE: return copy(f.joint_torque_mNm, 3);
    case HD_CURRENT_MOTOR_DAC_VALUES:
      for (int i = 0; i < 3; ++i) out[i] = static_cast<double>(f.dac[i]);
      return 3;
    case HD_JOINT_ANGLE_REFERENCES: {
      // the pose the encoders are referenced to: the inkwell (device
      // convention, rad; hw/omni_calibration.h)
      const double* r = vmh::hw::kInkwellDevice_rad;
      for (int i = 0; i < 6; ++i) out[i] = r[i];
      return 6;
    }
    case HD_MOTOR_TEMPERATURE: return copy(f.motor_temperature, 6);
    case HD_INSTANTANEOUS_UPDATE_RATE: out[0] = std::round(cur.rate_hz); return 1;
    case HD_UPDATE_RATE: out[0] = ctx().rate_hz; return 1;
    case HD_INPUT_DOF: out[0] = id.input_dof > 0 ? id.input_dof : 6; return 1;
    case HD_OUTPUT_DOF: out[0] = id.output_dof > 0 ? id.output_dof : 3; return 1;
    case HD_CALIBRATION_STYLE:
      out[0] = d->opened().raw != nullptr ? HD_CALIBRATION_INKWELL
                                          : HD_CALIBRATION_AUTO;
      return 1;
    // the Omni's figures (docs/libhd.md gives each one's source)
    case HD_MAX_WORKSPACE_DIMENSIONS: return copy(d->max_workspace_mm(), 6);
    case HD_USABLE_WORKSPACE_DIMENSIONS: {
      // the data sheet's 160 x 120 x 70 mm, centred on the device origin
      const double w[6] = {-80, -60, -35, 80, 60, 35};
      return copy(w, 6);
    }
    // an estimate: the lowest the wrist centre reaches
    case HD_TABLETOP_OFFSET: out[0] = d->max_workspace_mm()[1]; return 1;
    case HD_NOMINAL_MAX_STIFFNESS: out[0] = 0.7; return 1;    // N/mm (CHAI3D)
    case HD_NOMINAL_MAX_DAMPING: out[0] = 0.005; return 1;    // N s/mm (CHAI3D)
    case HD_NOMINAL_MAX_FORCE: out[0] = 3.3; return 1;        // N
    case HD_NOMINAL_MAX_CONTINUOUS_FORCE: out[0] = 0.88; return 1;  // N
    case HD_NOMINAL_MAX_TORQUE_STIFFNESS:
    case HD_NOMINAL_MAX_TORQUE_DAMPING:
    case HD_NOMINAL_MAX_TORQUE_FORCE:
    case HD_NOMINAL_MAX_TORQUE_CONTINUOUS_FORCE:
      out[0] = 0.0;  // no gimbal motors on the Omni
      return 1;
    case HD_SOFTWARE_VELOCITY_LIMIT: out[0] = s.velocity_limit_mm_s.load(); return 1;
    case HD_SOFTWARE_FORCE_IMPULSE_LIMIT: out[0] = s.impulse_limit_N.load(); return 1;
    case HD_FORCE_RAMPING_RATE: out[0] = s.ramp_rate_N_s.load(); return 1;
    case HD_USER_STATUS_LIGHT: out[0] = s.status_light.load(); return 1;
    default: return 0;
  }
}

template <typename T, typename Convert>
void get_numbers(HDenum p, T* params, Convert convert) {
  if (params == nullptr) {
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return;
  }
  HdDevice* d = current_device();
  if (d == nullptr) return;
  double v[36];
  const int n = read_numbers(d, p, v);
  if (n == 0) {
    const bool string_param = p >= HD_VERSION && p <= HD_DEVICE_FIRMWARE_VERSION;
    push_error(string_param ? HD_INVALID_INPUT_TYPE : HD_INVALID_ENUM,
               kInternalUnknownParameter, current_handle());
    return;
  }
  for (int i = 0; i < n; ++i) params[i] = convert(v[i]);
}

template <typename T>
void get_numbers(HDenum p, T* params) {
  get_numbers(p, params, [](double v) { return static_cast<T>(v); });
}

}  // namespace

HDAPI void HDAPIENTRY hdGetBooleanv(HDenum p, HDboolean* params) {
  // any non-zero value is HD_TRUE (a button mask read as a boolean)
  get_numbers(p, params, [](double v) -> HDboolean {
    return v != 0.0 ? HD_TRUE : HD_FALSE;
  });
}
HDAPI void HDAPIENTRY hdGetIntegerv(HDenum p, HDint* params) { get_numbers(p, params); }
HDAPI void HDAPIENTRY hdGetFloatv(HDenum p, HDfloat* params) { get_numbers(p, params); }
HDAPI void HDAPIENTRY hdGetDoublev(HDenum p, HDdouble* params) { get_numbers(p, params); }
HDAPI void HDAPIENTRY hdGetLongv(HDenum p, HDlong* params) { get_numbers(p, params); }

HDAPI HDstring HDAPIENTRY hdGetString(HDenum p) {
  HdDevice* d = current_device();
  if (d == nullptr) return nullptr;
  const vmh::DeviceIdentity& id = d->identity();
  // one buffer per device and string, so that strings fetched one after
  // the other are all still valid (a program prints several in one
  // printf); rewritten only here, with the same text each time
  static thread_local std::string kept[kMaxDevices][HD_DEVICE_FIRMWARE_VERSION -
                                                    HD_VERSION + 1];
  const bool is_string = p >= HD_VERSION && p <= HD_DEVICE_FIRMWARE_VERSION;
  std::string& s = kept[current_handle()][is_string ? p - HD_VERSION : 0];
  switch (p) {
    case HD_VERSION: return "3.0.0 (vmhaptics open HD API)";
    case HD_DEVICE_MODEL_TYPE:
      s = id.model.empty() ? "PHANTOM Omni" : id.model;
      return s.c_str();
    case HD_DEVICE_DRIVER_VERSION:
      s = "vmhaptics " + (id.backend.empty() ? std::string("device") : id.backend) +
          (id.driver_version.empty() ? "" : " " + id.driver_version);
      return s.c_str();
    case HD_DEVICE_VENDOR:
      s = id.vendor.empty() ? "vmhaptics" : id.vendor;
      return s.c_str();
    case HD_DEVICE_SERIAL_NUMBER:
      s = id.serial;
      return s.c_str();
    case HD_DEVICE_FIRMWARE_VERSION:
      s = id.firmware_version;
      return s.c_str();
    default: {
      double v[36];
      push_error(read_numbers(d, p, v) > 0 ? HD_INVALID_INPUT_TYPE : HD_INVALID_ENUM,
                 kInternalUnknownParameter, current_handle());
      return nullptr;
    }
  }
}

namespace {

template <typename T>
void set_numbers(HDenum p, const T* params) {
  if (params == nullptr) {
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return;
  }
  HdDevice* d = current_device();
  if (d == nullptr) return;
  HdSettings& s = d->settings();
  const auto positive = [&](double v) {
    if (std::isfinite(v) && v > 0.0) return true;
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return false;
  };
  switch (p) {
    case HD_SOFTWARE_VELOCITY_LIMIT:
      if (positive(double(params[0]))) s.velocity_limit_mm_s.store(double(params[0]));
      return;
    case HD_SOFTWARE_FORCE_IMPULSE_LIMIT:
      if (positive(double(params[0]))) s.impulse_limit_N.store(double(params[0]));
      return;
    case HD_FORCE_RAMPING_RATE:
      if (positive(double(params[0]))) s.ramp_rate_N_s.store(double(params[0]));
      return;
    case HD_USER_STATUS_LIGHT:
      s.status_light.store(static_cast<int>(params[0]) & LED_MASK);
      return;
    default:
      break;
  }
  const bool command = p == HD_CURRENT_FORCE || p == HD_CURRENT_TORQUE ||
                       p == HD_CURRENT_JOINT_TORQUE ||
                       p == HD_CURRENT_GIMBAL_TORQUE ||
                       p == HD_CURRENT_MOTOR_DAC_VALUES;
  if (!command) {
    double v[36];
    const bool readable = read_numbers(d, p, v) > 0;
    push_error(readable ? HD_INVALID_OPERATION : HD_INVALID_ENUM,
               readable ? kInternalReadOnly : kInternalUnknownParameter,
               current_handle());
    return;
  }
  if (!on_servo_thread()) {
    // commands belong to a servo frame: a scheduler callback
    push_error(HD_INVALID_OPERATION, kInternalNotInScheduler, current_handle());
    return;
  }
  HdCommand& c = d->command();
  for (int i = 0; i < 3; ++i) {
    const double v = static_cast<double>(params[i]);
    if (!std::isfinite(v)) {
      push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
      return;
    }
  }
  for (int i = 0; i < 3; ++i) {
    const double v = static_cast<double>(params[i]);
    switch (p) {
      case HD_CURRENT_FORCE: c.force_N[i] = v; break;
      case HD_CURRENT_JOINT_TORQUE: c.joint_torque_mNm[i] = v; break;
      case HD_CURRENT_TORQUE:
      case HD_CURRENT_GIMBAL_TORQUE: c.gimbal_torque_mNm[i] = v; break;
      case HD_CURRENT_MOTOR_DAC_VALUES:
        c.dac[i] = std::lround(std::clamp(v, -2047.0, 2047.0));
        c.dac_set = true;
        break;
      default: break;
    }
  }
}

}  // namespace

HDAPI void HDAPIENTRY hdSetBooleanv(HDenum p, const HDboolean* params) {
  set_numbers(p, params);
}
HDAPI void HDAPIENTRY hdSetIntegerv(HDenum p, const HDint* params) { set_numbers(p, params); }
HDAPI void HDAPIENTRY hdSetFloatv(HDenum p, const HDfloat* params) { set_numbers(p, params); }
HDAPI void HDAPIENTRY hdSetDoublev(HDenum p, const HDdouble* params) { set_numbers(p, params); }
HDAPI void HDAPIENTRY hdSetLongv(HDenum p, const HDlong* params) { set_numbers(p, params); }

// ---- errors ----

HDAPI HDErrorInfo HDAPIENTRY hdGetError(void) {
  ErrorStack& s = t_errors;
  if (s.n == 0) return HDErrorInfo{HD_SUCCESS, 0, current_handle()};
  return s.e[--s.n];
}

HDAPI HDstring HDAPIENTRY hdGetErrorString(HDerror code) {
  const int i = detail_slot(code);
  if (i >= 0 && !on_servo_thread()) {
    // "<what the code means>: <the last cause>", kept until the next one
    static thread_local std::string out;
    std::lock_guard<std::mutex> lock(g_detail_mu);
    if (!g_detail[i].empty()) {
      out = std::string(base_text(code)) + ": " + g_detail[i];
      return out.c_str();
    }
  }
  return base_text(code);
}

// ---- calibration ----

HDAPI HDenum HDAPIENTRY hdCheckCalibration(void) {
  HdDevice* d = current_device();
  if (d == nullptr) return HD_CALIBRATION_NEEDS_MANUAL_INPUT;
  switch (d->backend()->calibration_state()) {
    case vmh::CalibrationState::kNeedsUpdate: return HD_CALIBRATION_NEEDS_UPDATE;
    case vmh::CalibrationState::kNeedsManualInput: return HD_CALIBRATION_NEEDS_MANUAL_INPUT;
    default: return HD_CALIBRATION_OK;
  }
}

HDAPI void HDAPIENTRY hdUpdateCalibration(HDenum style) {
  HdDevice* d = current_device();
  if (d == nullptr) return;
  if (style != HD_CALIBRATION_ENCODER_RESET && style != HD_CALIBRATION_AUTO &&
      style != HD_CALIBRATION_INKWELL) {
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return;
  }
  if (!d->backend()->has_driver_calibration()) return;  // nothing to update
  try {
    d->backend()->update_calibration();
  } catch (const std::exception& e) {
    set_detail(HD_DEVICE_FAULT, std::string("hdUpdateCalibration: ") + e.what());
    push_error(HD_DEVICE_FAULT, kInternalNone, current_handle());
  }
}

// ---- the scheduler ----

HDAPI void HDAPIENTRY hdSetSchedulerRate(HDulong rate_Hz) {
  Context& c = ctx();
  if (rate_Hz < 100 || rate_Hz > 2000 || c.running.load()) {
    set_detail(HD_INVALID_VALUE,
               "hdSetSchedulerRate(" + std::to_string(rate_Hz) +
                   "): the rate must be 100..2000 Hz and set before "
                   "hdStartScheduler");
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return;
  }
  c.rate_hz = static_cast<double>(rate_Hz);
}

HDAPI void HDAPIENTRY hdStartScheduler(void) {
  Context& c = ctx();
  std::lock_guard<std::mutex> lock(c.mu);
  if (c.running.load()) return;
  HdDevice* devs[kMaxDevices];
  int n = 0;
  for (auto& d : c.devices) {
    if (d) devs[n++] = d.get();
  }
  if (n == 0) {
    set_detail(HD_TIMER_ERROR, "hdStartScheduler: no device is open (hdInitDevice first)");
    push_error(HD_TIMER_ERROR, kInternalSchedulerStart, HD_INVALID_HANDLE);
    return;
  }
  const double period_s = 1.0 / c.rate_hz;
  const bool lockstep = c.lockstep.load();
  vmh::ServoOptions so;
  so.period_s = period_s;
  so.lockstep = lockstep;
  so.realtime = std::getenv("VMH_HD_NO_REALTIME") == nullptr && !lockstep;
  c.servo_thread_known.store(false);
  c.running.store(true, std::memory_order_release);
  int started = 0;
  try {
    for (int i = 0; i < n; ++i) {
      devs[i]->arm(period_s);
      // the first device's servo thread runs the scheduler's tick; the
      // others run their own loops idle (their plants, their watchdogs)
      devs[i]->backend()->start(i == 0 ? static_cast<vmh::ServoLoop*>(&g_loop)
                                       : static_cast<vmh::ServoLoop*>(&g_idle),
                                so);
      ++started;
    }
  } catch (const std::exception& e) {
    for (int i = 0; i < started; ++i) devs[i]->backend()->stop();
    c.running.store(false);
    set_detail(HD_TIMER_ERROR, std::string("hdStartScheduler: ") + e.what());
    push_error(HD_TIMER_ERROR, kInternalSchedulerStart, HD_INVALID_HANDLE);
    return;
  }
  if (lockstep) {
    // one servo period of every plant per tick, paced to the wall clock:
    // VMH_HD_PACE=free runs as fast as it can, VMH_HD_PACE=F (a number > 0)
    // F times faster than real time
    const char* pace = std::getenv("VMH_HD_PACE");
    double factor = 1.0;
    if (pace != nullptr && *pace != '\0') {
      if (std::string(pace) == "free") {
        factor = 0.0;
      } else {
        char* end = nullptr;
        const double f = std::strtod(pace, &end);
        if (end != pace && *end == '\0' && std::isfinite(f) && f > 0.0) factor = f;
      }
    }
    c.lockstep_run.store(true);
    c.lockstep_thread = std::thread([devs, n, period_s, factor]() mutable {
      Context& cc = ctx();
      const auto t0 = std::chrono::steady_clock::now();
      std::int64_t k = 0;
      while (cc.lockstep_run.load(std::memory_order_acquire)) {
        for (int i = 0; i < n; ++i) devs[i]->backend()->pass(period_s);
        ++k;
        if (factor > 0.0) {
          std::this_thread::sleep_until(
              t0 + std::chrono::duration<double>(static_cast<double>(k) *
                                                 period_s / factor));
        }
      }
    });
  }
}

HDAPI void HDAPIENTRY hdStopScheduler(void) {
  Context& c = ctx();
  std::lock_guard<std::mutex> lock(c.mu);
  if (!c.running.load()) return;
  if (c.lockstep_thread.joinable()) {
    c.lockstep_run.store(false, std::memory_order_release);
    c.lockstep_thread.join();
  }
  for (auto& d : c.devices) {
    if (d) d->backend()->stop();  // leaves zero torque
  }
  c.running.store(false, std::memory_order_release);
  c.servo_thread_known.store(false);
  // callbacks still scheduled stay scheduled; synchronous waiters are
  // released (their callback will not run)
  {
    std::lock_guard<std::mutex> sl(g_sched_mu);
    for (Slot& s : g_slots) {
      if (s.active && s.sync) {
        s.active = false;
        s.done = true;
      }
    }
  }
  g_sched_cv.notify_all();
}

HDAPI HDSchedulerHandle HDAPIENTRY hdScheduleAsynchronous(HDSchedulerCallback cb,
                                                          void* user,
                                                          HDushort priority) {
  if (cb == nullptr) {
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return 0;
  }
  std::lock_guard<std::mutex> lock(g_sched_mu);
  for (Slot& s : g_slots) {
    if (!s.active) {
      s = Slot{cb, user, priority, g_next_handle++, true, false, false, g_next_order++};
      return s.handle;
    }
  }
  push_error(HD_SCHEDULER_FULL, kInternalNone, current_handle());
  return 0;
}

HDAPI void HDAPIENTRY hdScheduleSynchronous(HDSchedulerCallback cb, void* user,
                                            HDushort priority) {
  if (cb == nullptr) {
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return;
  }
  if (on_servo_thread()) {  // from a callback: run it now, in this frame
    cb(user);
    return;
  }
  if (!ctx().running.load(std::memory_order_acquire)) {
    // no scheduler: run it once here, on the caller's thread, against the
    // last published frame (docs/libhd.md)
    cb(user);
    return;
  }
  std::unique_lock<std::mutex> lock(g_sched_mu);
  Slot* slot = nullptr;
  for (Slot& s : g_slots) {
    if (!s.active && !s.sync) {
      s = Slot{cb, user, priority, g_next_handle++, true, true, false, g_next_order++};
      slot = &s;
      break;
    }
  }
  if (slot == nullptr) {
    push_error(HD_SCHEDULER_FULL, kInternalNone, current_handle());
    return;
  }
  const HDSchedulerHandle h = slot->handle;
  g_sched_cv.wait(lock, [&] { return slot->handle != h || slot->done; });
  if (slot->handle == h) slot->sync = false;  // the slot is free again
}

HDAPI void HDAPIENTRY hdUnschedule(HDSchedulerHandle handle) {
  {
    std::lock_guard<std::mutex> lock(g_sched_mu);
    for (Slot& s : g_slots) {
      if (s.active && s.handle == handle) {
        s.active = false;
        s.done = true;
        g_sched_cv.notify_all();
        return;
      }
    }
  }
  push_error(HD_INVALID_OPERATION, kInternalNone, current_handle());
}

HDAPI HDboolean HDAPIENTRY hdWaitForCompletion(HDSchedulerHandle handle,
                                               HDWaitCode param) {
  std::unique_lock<std::mutex> lock(g_sched_mu);
  const auto active = [&] {
    for (const Slot& s : g_slots) {
      if (s.active && s.handle == handle) return true;
    }
    return false;
  };
  if (param == HD_WAIT_CHECK_STATUS) return active() ? HD_TRUE : HD_FALSE;
  if (param != HD_WAIT_INFINITE) {
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return HD_FALSE;
  }
  if (on_servo_thread()) return active() ? HD_FALSE : HD_TRUE;  // would deadlock
  g_sched_cv.wait(lock, [&] { return !active() || !ctx().running.load(); });
  return active() ? HD_FALSE : HD_TRUE;
}

HDAPI HDdouble HDAPIENTRY hdGetSchedulerTimeStamp(void) {
  if (!on_servo_thread()) return 0.0;
  return wall_s() - ctx().tick_start_wall_s.load(std::memory_order_relaxed);
}

// ---- the project's extension (not in the vendor's API) ----

// The time of the tick in progress, s, as the scheduler's driver gives it:
// CLOCK_MONOTONIC on the wall clock, the simulated time in lockstep. 0 off
// the servo thread.
HDAPI HDdouble HDAPIENTRY vmhdGetSchedulerTime(void) {
  if (!on_servo_thread()) return 0.0;
  return ctx().tick_now_s.load(std::memory_order_relaxed);
}

// The simulated plant's ground truth for device h (device/tick_record.h's
// PlantTruth), for the project's own OpenHaptics backend: `size` must be
// sizeof(vmh::PlantTruth) of the same build. Returns 1 when filled, 0 for a
// device without a truth or a size that does not match.
HDAPI int HDAPIENTRY vmhdReadTruth(HHD h, void* truth, unsigned long size) {
  HdDevice* d = device_of(h);
  if (d == nullptr || truth == nullptr || size != sizeof(vmh::PlantTruth)) return 0;
  return d->read_truth(static_cast<vmh::PlantTruth*>(truth)) ? 1 : 0;
}

