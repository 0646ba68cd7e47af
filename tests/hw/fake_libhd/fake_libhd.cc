// A test-only libHD.so: the HD API functions the OpenHaptics backend uses
// (hw/openhaptics/hd_api.h), exported with the C ABI and implemented over a
// device model (fake_hd_device.h), so that the backend's units, signs,
// frames, scheduler path and error paths run in CI without the SDK.
//
// Its kinematics are its own: positions, the stylus transform and the
// Jacobian come from the published OpenHaptics formula
// (tests/support/openhaptics_reference.h, docs/sources.md §4), not from
// controller/, so the tests compare two independent routes.
//
// The configuration name given to hdInitDevice picks the device and its
// faults, as comma-separated tokens:
//   missing (or any unknown token)  HD_INVALID_HANDLE, COMM_CONFIG_ERROR
//   warm_motors@N, exceeded_velocity@N, exceeded_force@N
//                                   that warning pushed at frame N, once
//   comm_error@N, device_fault@N    from frame N every frame fails with it
//                                   and the device is neither sampled nor
//                                   driven (it stops answering)
//   no_encoders                     HD_CURRENT_ENCODER_VALUES is refused
//   uncalibrated                    NEEDS_UPDATE until an inkwell update
//   docked, button1, button2        passed to the device model
#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "hw/openhaptics/hd_api.h"
#include "tests/hw/fake_libhd/fake_hd_device.h"
#include "tests/hw/fake_libhd/fake_hd_hooks.h"
#include "tests/support/openhaptics_reference.h"

using namespace vmh::hw::hd;  // NOLINT: this file implements the HD API

#define FAKE_HD_EXPORT extern "C" __attribute__((visibility("default")))

namespace {

constexpr double kL1Mm = 133.35;  // docs/sources.md §4
constexpr double kL2Mm = 133.35;
constexpr double kCountsPerRev = 15000.0;  // §6
constexpr double kPi = 3.14159265358979323846;
constexpr HHD kHandle = 1;

struct Fault {
  HDerror code;
  long frame;
  bool persistent;  // the device stops answering from that frame on
};

struct Snapshot {
  vmh::Joints q = vmh::Joints::Zero();
  vmh::Vec3 position_mm = vmh::Vec3::Zero();
  vmh::Vec3 velocity_mm_s = vmh::Vec3::Zero();
  vmh::Mat3 rotation = vmh::Mat3::Identity();
  vmh::Mat3 jv_mm = vmh::Mat3::Zero();  // d position_mm / d t1..t3
  bool docked = false;
  std::uint32_t buttons = 0;
  double t_s = 0.0;
  bool valid = false;
};

// -- device, commands, errors: guarded by g_mu --
std::mutex g_mu;
std::unique_ptr<vmh::HapticDevice> g_dev;
std::vector<Fault> g_faults;
bool g_no_encoders = false;
bool g_uncalibrated = false;
Snapshot g_snap;
double g_torque_mNm[3] = {0, 0, 0};
double g_force_N[3] = {0, 0, 0};
double g_applied_Nm[3] = {0, 0, 0};
bool g_force_enabled = false;
long g_frame = 0;
int g_depth = 0;
bool g_frame_dead = false;
HDErrorInfo g_errors[64];
int g_n_errors = 0;
FakeHdCounters g_counters{};

// -- scheduler: guarded by g_sched_mu --
struct Slot {
  HDSchedulerCallback cb = nullptr;
  void* user = nullptr;
  HDushort priority = 0;
  HDSchedulerHandle handle = 0;
  bool active = false;
  bool sync = false;
  bool done = false;
};
constexpr int kSlots = 32;
std::mutex g_sched_mu;
std::condition_variable g_sched_cv;
Slot g_slots[kSlots];
HDSchedulerHandle g_next_handle = 1;
std::thread g_thread;
std::atomic<bool> g_run{false};
std::atomic<pthread_t> g_sched_thread{};

void push_error_locked(HDerror code) {
  if (g_n_errors == 64) {
    std::copy(g_errors + 1, g_errors + 64, g_errors);
    --g_n_errors;
  }
  g_errors[g_n_errors++] = HDErrorInfo{code, static_cast<int>(code) + 1, kHandle};
}

void push_error(HDerror code) {
  std::lock_guard<std::mutex> lock(g_mu);
  push_error_locked(code);
}

bool on_scheduler() {
  return g_run.load() && pthread_equal(pthread_self(), g_sched_thread.load());
}

// the fake's own kinematics at device joint angles q (mm, device frame)
void sample_locked() {
  vmh::DeviceState st;
  if (g_dev->read_state(&st) != vmh::DeviceError::kOk) return;
  Snapshot s;
  s.q = st.q_device_rad;
  s.docked = st.has(vmh::kStateInkwell) && st.docked;
  s.buttons = st.has(vmh::kStateButtons) ? st.buttons : 0u;
  s.t_s = st.timestamp_s;
  s.position_mm = vmh::testing::openhaptics_wrist_mm(s.q, kL1Mm, kL2Mm);
  s.rotation = vmh::testing::openhaptics_stylus_rotation(s.q);
  // derivatives of the position formula, column j = d p / d t_j
  const double s1 = std::sin(s.q[0]), c1 = std::cos(s.q[0]);
  const double s2 = std::sin(s.q[1]), c2 = std::cos(s.q[1]);
  const double s3 = std::sin(s.q[2]), c3 = std::cos(s.q[2]);
  const double reach = kL1Mm * c2 + kL2Mm * s3;
  s.jv_mm.col(0) << -c1 * reach, 0.0, -s1 * reach;
  s.jv_mm.col(1) << s1 * kL1Mm * s2, kL1Mm * c2, -c1 * kL1Mm * s2;
  s.jv_mm.col(2) << -s1 * kL2Mm * c3, kL2Mm * s3, c1 * kL2Mm * c3;
  if (g_snap.valid && s.t_s > g_snap.t_s) {
    s.velocity_mm_s = (s.position_mm - g_snap.position_mm) / (s.t_s - g_snap.t_s);
  }
  s.valid = true;
  g_snap = s;
}

bool handle_ok_locked(HHD h) {
  if (h == kHandle && g_dev) return true;
  push_error_locked(kBadHandle);
  return false;
}

void scheduler_main() {
  g_sched_thread.store(pthread_self());
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  while (g_run.load()) {
    // absolute deadlines 1 ms apart; after a long stall, start afresh
    next.tv_nsec += 1000000;
    if (next.tv_nsec >= 1000000000) {
      next.tv_nsec -= 1000000000;
      ++next.tv_sec;
    }
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    if (now.tv_sec > next.tv_sec + 1) next = now;
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);

    Slot run[kSlots];
    int n = 0;
    {
      std::lock_guard<std::mutex> lock(g_sched_mu);
      for (const Slot& s : g_slots) {
        if (s.active) run[n++] = s;
      }
    }
    // highest priority first, in scheduling order among equals (insertion
    // sort: std::stable_sort would allocate a buffer)
    for (int i = 1; i < n; ++i) {
      for (int j = i; j > 0 && run[j - 1].priority < run[j].priority; --j) {
        std::swap(run[j - 1], run[j]);
      }
    }
    bool finished = false;
    for (int i = 0; i < n; ++i) {
      if (run[i].cb(run[i].user) != kCallbackDone) continue;
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
  }
  g_sched_cv.notify_all();
}

HDSchedulerHandle add_slot(HDSchedulerCallback cb, void* user, HDushort prio,
                           bool sync) {
  std::lock_guard<std::mutex> lock(g_sched_mu);
  for (Slot& s : g_slots) {
    if (s.active) continue;
    s = Slot{cb, user, prio, g_next_handle++, true, sync, false};
    return s.handle;
  }
  push_error(kSchedulerFull);
  return 0;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string t;
  while (std::getline(in, t, ',')) {
    if (!t.empty()) out.push_back(t);
  }
  return out;
}

}  // namespace

// -- the HD API --

FAKE_HD_EXPORT HHD hdInitDevice(HDstring config) {
  const std::string name = config != nullptr ? config : "";
  std::vector<Fault> faults;
  std::string model_tokens;  // comma-separated, for the device model
  bool no_encoders = false;
  bool uncalibrated = false;
  bool bad = false;
  for (const std::string& t : split(name)) {
    const auto at = t.find('@');
    if (at != std::string::npos) {
      const std::string kind = t.substr(0, at);
      const long frame = std::atol(t.c_str() + at + 1);
      if (kind == "warm_motors") faults.push_back({kWarmMotors, frame, false});
      else if (kind == "exceeded_velocity")
        faults.push_back({kExceededMaxVelocity, frame, false});
      else if (kind == "exceeded_force")
        faults.push_back({kExceededMaxForce, frame, false});
      else if (kind == "comm_error") faults.push_back({kCommError, frame, true});
      else if (kind == "device_fault")
        faults.push_back({kDeviceFault, frame, true});
      else bad = true;
    } else if (t == "no_encoders") {
      no_encoders = true;
    } else if (t == "uncalibrated") {
      uncalibrated = true;
    } else if (t == "missing") {
      bad = true;
    } else {
      model_tokens += t + ",";
    }
  }
  std::unique_ptr<vmh::HapticDevice> dev;
  if (!bad) {
    try {
      dev = vmh::fake_hd::fake_hd_make_device(model_tokens);
    } catch (const std::exception&) {
      bad = true;
    }
  }
  std::lock_guard<std::mutex> lock(g_mu);
  if (bad) {
    push_error_locked(kCommConfigError);
    return kInvalidHandle;
  }
  if (g_dev) {
    push_error_locked(kDeviceAlreadyInitiated);
    return kInvalidHandle;
  }
  g_dev = std::move(dev);
  g_faults = faults;
  g_no_encoders = no_encoders;
  g_uncalibrated = uncalibrated;
  g_counters = FakeHdCounters{};
  g_counters.inits = 1;
  g_n_errors = 0;
  g_frame = 0;
  g_depth = 0;
  g_frame_dead = false;
  g_force_enabled = false;
  std::fill(g_torque_mNm, g_torque_mNm + 3, 0.0);
  std::fill(g_force_N, g_force_N + 3, 0.0);
  std::fill(g_applied_Nm, g_applied_Nm + 3, 0.0);
  g_snap = Snapshot{};
  // as OpenHaptics, which returns from hdInitDevice with the device's
  // state known: a device behind us on the wall clock (the emulator, on a
  // busy host) may answer its first reads with a timeout, which left the
  // position at zero for a test that reads it before the scheduler starts.
  // Up to 2 s of 1 ms tries; a device that never answers stays invalid.
  for (int tries = 0; tries < 2000; ++tries) {
    sample_locked();
    if (g_snap.valid) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return kHandle;
}

FAKE_HD_EXPORT void hdDisableDevice(HHD h) {
  std::lock_guard<std::mutex> lock(g_mu);
  if (!handle_ok_locked(h)) return;
  g_dev.reset();
  ++g_counters.disables;
}

FAKE_HD_EXPORT void hdMakeCurrentDevice(HHD h) {
  std::lock_guard<std::mutex> lock(g_mu);
  handle_ok_locked(h);
}

FAKE_HD_EXPORT void hdBeginFrame(HHD h) {
  std::lock_guard<std::mutex> lock(g_mu);
  if (!handle_ok_locked(h)) return;
  if (!on_scheduler()) {
    ++g_counters.illegal_frames;
    push_error_locked(kIllegalBegin);
    return;
  }
  if (g_depth++ > 0) return;
  ++g_frame;
  g_frame_dead = false;
  for (const Fault& f : g_faults) {
    if (f.persistent ? g_frame >= f.frame : g_frame == f.frame) {
      push_error_locked(f.code);
      if (f.persistent) g_frame_dead = true;
    }
  }
  if (g_frame_dead) return;
  ++g_counters.frames;
  sample_locked();
}

FAKE_HD_EXPORT void hdEndFrame(HHD h) {
  std::lock_guard<std::mutex> lock(g_mu);
  if (!handle_ok_locked(h)) return;
  if (!on_scheduler() || g_depth == 0) {
    ++g_counters.illegal_frames;
    push_error_locked(kIllegalEnd);
    return;
  }
  if (--g_depth > 0 || g_frame_dead) return;
  // joint torques (mN m) plus the force (N) through the transpose of the
  // fake's own Jacobian (mm/rad): N mm, so / 1000 to N m
  const vmh::Vec3 force_N(g_force_N[0], g_force_N[1], g_force_N[2]);
  vmh::Vec3 tau_Nm = vmh::Vec3(g_torque_mNm[0], g_torque_mNm[1], g_torque_mNm[2]) / 1000.0 +
                     g_snap.jv_mm.transpose() * force_N / 1000.0;
  if (!g_force_enabled) tau_Nm.setZero();
  g_dev->write_motor_torques(tau_Nm);
  for (int i = 0; i < 3; ++i) g_applied_Nm[i] = tau_Nm[i];
}

FAKE_HD_EXPORT HDErrorInfo hdGetError() {
  std::lock_guard<std::mutex> lock(g_mu);
  if (g_n_errors == 0) return HDErrorInfo{kSuccess, 0, kHandle};
  return g_errors[--g_n_errors];  // the most recent first
}

FAKE_HD_EXPORT HDstring hdGetErrorString(HDerror code) {
  switch (code) {
    case kSuccess: return "no error";
    case kWarmMotors: return "test libHD: motors warm";
    case kExceededMaxVelocity: return "test libHD: velocity limit exceeded";
    case kExceededMaxForce: return "test libHD: force limit exceeded";
    case kCommError: return "test libHD: the device stopped answering";
    case kCommConfigError: return "test libHD: no device by that name";
    case kDeviceFault: return "test libHD: device fault";
    default: return "test libHD: error";
  }
}

FAKE_HD_EXPORT void hdEnable(HDenum cap) {
  std::lock_guard<std::mutex> lock(g_mu);
  if (cap == kForceOutput) {
    g_force_enabled = true;
    ++g_counters.enables_force;
  }
}

FAKE_HD_EXPORT void hdDisable(HDenum cap) {
  std::lock_guard<std::mutex> lock(g_mu);
  if (cap == kForceOutput) g_force_enabled = false;
}

FAKE_HD_EXPORT void hdGetBooleanv(HDenum param, HDboolean* out) {
  std::lock_guard<std::mutex> lock(g_mu);
  if (!g_dev) return push_error_locked(kBadHandle);
  if (param == kCurrentInkwellSwitch) {
    *out = g_snap.docked ? 0 : 1;  // 0 while docked (§9.1)
  } else if (param == kCurrentSafetySwitch) {
    *out = 0;
  } else {
    push_error_locked(kInvalidEnum);
  }
}

FAKE_HD_EXPORT void hdGetIntegerv(HDenum param, HDint* out) {
  std::lock_guard<std::mutex> lock(g_mu);
  if (!g_dev) return push_error_locked(kBadHandle);
  switch (param) {
    case kCurrentButtons: *out = static_cast<HDint>(g_snap.buttons); break;
    case kInputDof: *out = 6; break;
    case kOutputDof: *out = 3; break;
    case kCalibrationStyle: *out = kCalibrationInkwell; break;
    default: push_error_locked(kInvalidEnum);
  }
}

FAKE_HD_EXPORT void hdGetDoublev(HDenum param, HDdouble* out) {
  std::lock_guard<std::mutex> lock(g_mu);
  if (!g_dev) return push_error_locked(kBadHandle);
  const Snapshot& s = g_snap;
  switch (param) {
    case kCurrentJointAngles:
      for (int i = 0; i < 3; ++i) out[i] = s.q[i];
      break;
    case kCurrentGimbalAngles:
      for (int i = 0; i < 3; ++i) out[i] = s.q[3 + i];
      break;
    case kCurrentPosition:
      for (int i = 0; i < 3; ++i) out[i] = s.position_mm[i];
      break;
    case kCurrentVelocity:
      for (int i = 0; i < 3; ++i) out[i] = s.velocity_mm_s[i];
      break;
    case kCurrentTransform:
      // column-major 4x4, mm
      for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) {
          double v = 0.0;
          if (r < 3 && c < 3) v = s.rotation(r, c);
          else if (r < 3) v = s.position_mm[r];
          else v = c == 3 ? 1.0 : 0.0;
          out[c * 4 + r] = v;
        }
      }
      break;
    case kCurrentJacobian:
      // the fake's choice of layout: column-major 6x6, rows (v, w), columns
      // t1..t6, linear rows mm/rad; its angular rows are left zero
      for (int c = 0; c < 6; ++c) {
        for (int r = 0; r < 6; ++r) {
          out[c * 6 + r] = (r < 3 && c < 3) ? s.jv_mm(r, c) : 0.0;
        }
      }
      break;
    case kNominalMaxForce: out[0] = 3.3; break;
    case kNominalMaxContinuousForce: out[0] = 0.88; break;
    default: push_error_locked(kInvalidEnum);
  }
}

FAKE_HD_EXPORT void hdGetLongv(HDenum param, HDlong* out) {
  std::lock_guard<std::mutex> lock(g_mu);
  if (!g_dev) return push_error_locked(kBadHandle);
  if (param != kCurrentEncoderValues || g_no_encoders) {
    return push_error_locked(kInvalidEnum);
  }
  for (int i = 0; i < 3; ++i) {
    out[i] = std::lround(g_snap.q[i] * kCountsPerRev / (2.0 * kPi));
  }
}

FAKE_HD_EXPORT HDstring hdGetString(HDenum param) {
  switch (param) {
    case kVersion: return "3.0.0 (vmhaptics test libHD)";
    case kDeviceModelType: return "PHANTOM Omni (test libHD)";
    case kDeviceDriverVersion: return "test-driver 1.0";
    case kDeviceVendor: return "vmhaptics tests";
    case kDeviceSerialNumber: return "TEST-00001";
    case kDeviceFirmwareVersion: return "test-firmware 0.1";
    default: push_error(kInvalidEnum); return nullptr;
  }
}

FAKE_HD_EXPORT void hdSetDoublev(HDenum param, const HDdouble* in) {
  const bool in_frame = on_scheduler();
  std::lock_guard<std::mutex> lock(g_mu);
  if (!g_dev) return push_error_locked(kBadHandle);
  if (in_frame && g_depth > 0) ++g_counters.sets_in_frame;
  else ++g_counters.sets_outside_frame;
  if (param == kCurrentJointTorque) {
    std::copy(in, in + 3, g_torque_mNm);
  } else if (param == kCurrentForce) {
    std::copy(in, in + 3, g_force_N);
  } else {
    push_error_locked(kInvalidEnum);
  }
}

FAKE_HD_EXPORT HDenum hdCheckCalibration() {
  std::lock_guard<std::mutex> lock(g_mu);
  return g_uncalibrated ? kCalibrationNeedsUpdate : kCalibrationOk;
}

FAKE_HD_EXPORT void hdUpdateCalibration(HDenum style) {
  std::lock_guard<std::mutex> lock(g_mu);
  if (style == static_cast<HDenum>(kCalibrationInkwell)) {
    g_uncalibrated = false;
  } else {
    push_error_locked(kInvalidValue);
  }
}

FAKE_HD_EXPORT void hdStartScheduler() {
  if (g_run.exchange(true)) return;
  g_thread = std::thread(scheduler_main);
  std::lock_guard<std::mutex> lock(g_mu);
  g_counters.scheduler_running = 1;
}

FAKE_HD_EXPORT void hdStopScheduler() {
  if (!g_run.exchange(false)) return;
  if (g_thread.joinable()) g_thread.join();
  std::lock_guard<std::mutex> lock(g_mu);
  g_counters.scheduler_running = 0;
}

FAKE_HD_EXPORT HDSchedulerHandle hdScheduleAsynchronous(HDSchedulerCallback cb,
                                                        void* user,
                                                        HDushort priority) {
  {
    std::lock_guard<std::mutex> lock(g_mu);
    ++g_counters.async_scheduled;
    g_counters.max_priority = std::max<long>(g_counters.max_priority, priority);
  }
  return add_slot(cb, user, priority, false);
}

FAKE_HD_EXPORT void hdScheduleSynchronous(HDSchedulerCallback cb, void* user,
                                          HDushort priority) {
  if (!g_run.load()) return push_error(kInvalidOperation);
  const HDSchedulerHandle h = add_slot(cb, user, priority, true);
  if (h == 0) return;
  std::unique_lock<std::mutex> lock(g_sched_mu);
  g_sched_cv.wait(lock, [&] {
    if (!g_run.load()) return true;
    for (const Slot& s : g_slots) {
      if (s.handle == h) return s.done;
    }
    return true;
  });
}

FAKE_HD_EXPORT void hdUnschedule(HDSchedulerHandle handle) {
  std::lock_guard<std::mutex> lock(g_sched_mu);
  for (Slot& s : g_slots) {
    if (s.active && s.handle == handle) s.active = false;
  }
}

// the functions above have exactly the types the backend resolves them as
static_assert(std::is_same_v<decltype(&hdInitDevice), PfnInitDevice>);
static_assert(std::is_same_v<decltype(&hdGetError), PfnGetError>);
static_assert(std::is_same_v<decltype(&hdSetDoublev), PfnSetDoublev>);
static_assert(std::is_same_v<decltype(&hdGetDoublev), PfnGetDoublev>);
static_assert(std::is_same_v<decltype(&hdScheduleAsynchronous),
                             PfnScheduleAsynchronous>);
static_assert(std::is_same_v<decltype(&hdScheduleSynchronous),
                             PfnScheduleSynchronous>);
static_assert(std::is_same_v<decltype(&hdCheckCalibration), PfnCheckCalibration>);
static_assert(std::is_same_v<decltype(&hdGetString), PfnGetString>);

// -- what the tests look at (fake_hd_hooks.h) --

FAKE_HD_EXPORT void fake_hd_counters(FakeHdCounters* out) {
  std::lock_guard<std::mutex> lock(g_mu);
  *out = g_counters;
}

FAKE_HD_EXPORT void fake_hd_last_joint_torque_mNm(double* out3) {
  std::lock_guard<std::mutex> lock(g_mu);
  std::copy(g_torque_mNm, g_torque_mNm + 3, out3);
}

FAKE_HD_EXPORT void fake_hd_last_force_N(double* out3) {
  std::lock_guard<std::mutex> lock(g_mu);
  std::copy(g_force_N, g_force_N + 3, out3);
}

FAKE_HD_EXPORT void fake_hd_applied_torque_Nm(double* out3) {
  std::lock_guard<std::mutex> lock(g_mu);
  std::copy(g_applied_Nm, g_applied_Nm + 3, out3);
}

FAKE_HD_EXPORT void fake_hd_position_mm(double* out3) {
  std::lock_guard<std::mutex> lock(g_mu);
  for (int i = 0; i < 3; ++i) out3[i] = g_snap.position_mm[i];
}

FAKE_HD_EXPORT void fake_hd_model_joints_rad(double* out6) {
  std::lock_guard<std::mutex> lock(g_mu);
  for (int i = 0; i < 6; ++i) out6[i] = g_snap.q[i];
}

FAKE_HD_EXPORT int fake_hd_true_q_dh_rad(double* out6) {
  std::lock_guard<std::mutex> lock(g_mu);
  vmh::Joints q;
  if (!g_dev || !vmh::fake_hd::fake_hd_true_q_dh(*g_dev, &q)) return 0;
  for (int i = 0; i < 6; ++i) out6[i] = q[i];
  return 1;
}

FAKE_HD_EXPORT int fake_hd_in_frame() {
  const bool sched = on_scheduler();
  std::lock_guard<std::mutex> lock(g_mu);
  return sched && g_depth > 0 ? 1 : 0;
}
