// The open HD API's scheduler (include/HD/hdScheduler.h): the tick that
// samples every device, runs the callbacks and sends every device's
// command, on the primary device's own servo thread (the backend's, on the
// wall clock) or the library's lockstep thread (VMH_HD_CLOCK=lockstep: each
// tick runs one servo period of every simulated plant). Callbacks run
// there, highest priority first. A tick neither allocates nor throws: the
// callbacks run from a fixed table copied under a short lock, errors go to
// a fixed per-thread stack. docs/libhd.md is the account of each call.
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
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>

#include "hd/hd_api_detail.h"
#include "hd/hd_device.h"

namespace vmh::hd::detail {
namespace {

constexpr int kMaxCallbacks = 64;

double wall_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
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

// VMH_HD_PACE: how many times faster than real time the lockstep thread
// runs, 0 for as fast as it can ("free"); 1 when unset or not a number > 0
double lockstep_pace() {
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
  return factor;
}

}  // namespace

bool on_servo_thread() {
  Context& c = ctx();
  return c.running.load(std::memory_order_acquire) &&
         c.servo_thread_known.load(std::memory_order_acquire) &&
         pthread_equal(pthread_self(), c.servo_thread.load());
}

}  // namespace vmh::hd::detail

using namespace vmh::hd;          // NOLINT: this file implements the C API
using namespace vmh::hd::detail;  // NOLINT: on the library's shared state

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
    const double factor = lockstep_pace();
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
