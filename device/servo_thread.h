// The project's own real-time thread: calls a ServoLoop (device/servo_loop.h)
// once per ServoOptions::period_s, on absolute CLOCK_MONOTONIC deadlines
// (clock_nanosleep with TIMER_ABSTIME), so that the time a tick takes does
// not shift the ticks after it. The emulator and the native drivers run
// their loops on it; OpenHaptics has its own scheduler.
//
// Deadlines: the next is the previous plus one period. A tick that starts
// late by less than a period runs at once and the grid is kept; when more
// than one deadline has passed (a tick that blocked, a preempted thread) the
// missed ones are skipped, so the loop runs one late tick and then resumes
// on the grid, never a burst of catch-up ticks. TickTimer counts the long
// period as an overrun.
//
// Real time (ServoOptions::realtime): SCHED_FIFO at `priority` for the servo
// thread and mlockall(MCL_CURRENT | MCL_FUTURE) for the process. Either may
// be refused (no CAP_SYS_NICE or rtprio limit; no CAP_IPC_LOCK or memlock
// limit); the loop then runs at normal priority and ServoReport::note says
// what was refused and how to allow it. The thread's stack is touched
// before the loop so that the first ticks take no page faults.
//
// The loop allocates nothing, takes no lock and throws nothing between
// ticks. A tick that never returns blocks stop(); the stall handler is how
// a program finds out (it runs on a separate, normal-priority thread).
#ifndef VMHAPTICS_DEVICE_SERVO_THREAD_H_
#define VMHAPTICS_DEVICE_SERVO_THREAD_H_

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

#include "device/device_backend.h"
#include "device/servo_loop.h"
#include "device/tick_timer.h"

namespace vmh {

// The deadline arithmetic, apart for testing: the deadline after
// prev_deadline_ns for a tick that ended at now_ns. Normally prev + period;
// when now is past that by a whole period or more, the latest deadline not
// after now, so that the missed deadlines are skipped rather than caught up.
// CLOCK_MONOTONIC, ns.
std::int64_t next_deadline_ns(std::int64_t prev_deadline_ns,
                              std::int64_t now_ns,
                              std::int64_t period_ns) noexcept;

class ServoThread {
 public:
  using StallHandler = void (*)(void* user) noexcept;

  // The loop is not owned and must outlive the thread. Throws
  // std::invalid_argument for a null loop, a period that is not finite and
  // positive, or (when realtime) a priority outside SCHED_FIFO's range.
  ServoThread(ServoLoop* loop, const ServoOptions& opt);
  ~ServoThread();  // stop()

  ServoThread(const ServoThread&) = delete;
  ServoThread& operator=(const ServoThread&) = delete;

  // Creates the thread, asks for real time if the options say so, and
  // returns once the loop is about to run its first tick. Throws
  // std::runtime_error if it is already running or the thread cannot be
  // created. A thread whose loop has ended may be started again; the tick
  // count and timing start from zero.
  ServoReport start();

  // Asks the loop to end, waits for the tick under way and joins the
  // threads; releases the memory lock this thread took. Idempotent.
  void stop() noexcept;

  // true from start() until the loop returned false or stop() ran
  bool running() const noexcept {
    return running_.load(std::memory_order_acquire);
  }
  // timing of the ticks so far (callable while running)
  TickStats timing() const { return timer_.stats(); }
  // ticks completed (tick() returned) since start()
  long ticks() const noexcept {
    return ticks_.load(std::memory_order_acquire);
  }

  // Optional, before start(): fn(user) is called once, on a monitor thread
  // waking every periods/2 servo periods, when no tick has completed for
  // `periods` periods; again only after ticks resumed and stalled again.
  // Throws std::invalid_argument for periods < 2 or a null fn, and
  // std::logic_error while running.
  void set_stall_handler(StallHandler fn, void* user, int periods);

 private:
  void run() noexcept;      // the servo thread
  void monitor() noexcept;  // the stall monitor thread
  ServoReport setup_realtime() noexcept;  // on the servo thread

  ServoLoop* loop_;
  ServoOptions opt_;
  std::int64_t period_ns_;
  TickTimer timer_;

  std::thread thread_;
  std::thread monitor_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_requested_{false};
  std::atomic<long> ticks_{0};
  bool locked_memory_ = false;

  StallHandler stall_fn_ = nullptr;
  void* stall_user_ = nullptr;
  int stall_periods_ = 0;

  // start-up handshake and the monitor's wake-up; never taken by the loop
  std::mutex mutex_;
  std::condition_variable cv_;
  bool ready_ = false;
  ServoReport report_;
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_SERVO_THREAD_H_
