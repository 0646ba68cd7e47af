// What the parts of the open HD API share, not part of the interface: the
// devices table and the current device (hd_api.cc), the error stack
// (hd_api_errors.cc), the scheduler's thread (hd_api_scheduler.cc); the
// state calls are in hd_api_params.cc. Include it after defining
// VMHAPTICS_HD_BUILDING, as each of those files does, so that the hd*
// functions they define are exported.
#ifndef VMHAPTICS_HD_HD_API_DETAIL_H_
#define VMHAPTICS_HD_HD_API_DETAIL_H_

#ifndef VMHAPTICS_HD_BUILDING
#error "define VMHAPTICS_HD_BUILDING before including hd/hd_api_detail.h"
#endif

#include <HD/hd.h>
#include <pthread.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "hd/hd_device.h"

namespace vmh::hd::detail {

constexpr int kMaxDevices = 4;

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

// -- errors (hd_api_errors.cc) --

// onto the calling thread's error stack (the oldest dropped when full);
// neither allocates nor throws
void push_error(HDerror code, int internal, HHD h) noexcept;
// the cause of the last failure of `code`, for hdGetErrorString (and
// printed unless VMH_HD_QUIET is set); only off the servo thread
void set_detail(HDerror code, const std::string& text);

// -- the devices (hd_api.cc) --
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
// the one context (never destroyed: threads may outlive exit)
Context& ctx();

// the calling thread's current device, else the process's
HHD current_handle();
// the live device of handle h, or null
HdDevice* device_of(HHD h);
// the current device, or null with HD_BAD_HANDLE pushed
HdDevice* current_device();
// the calling thread's open frames of each device (hdBeginFrame nests; the
// scheduler's tick closes a frame its callbacks left open)
extern thread_local int t_frame_depth[kMaxDevices];

// -- the scheduler (hd_api_scheduler.cc) --

// true on the thread that runs the scheduler's ticks, while it runs
bool on_servo_thread();

}  // namespace vmh::hd::detail

#endif  // VMHAPTICS_HD_HD_API_DETAIL_H_
