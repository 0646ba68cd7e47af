#include "device/servo_thread.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include <cerrno>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <system_error>

namespace vmh {

namespace {

constexpr std::int64_t kNsPerS = 1000000000;

// stack the servo thread touches before its loop, so that the first ticks
// do not take page faults (with mlockall the pages also stay)
constexpr std::size_t kPrefaultStackBytes = 256 * 1024;

std::int64_t now_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

timespec to_timespec(std::int64_t ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(ns % kNsPerS);
  return ts;
}

__attribute__((noinline)) void prefault_stack() noexcept {
  volatile unsigned char buf[kPrefaultStackBytes];
  for (std::size_t i = 0; i < kPrefaultStackBytes; i += 4096) buf[i] = 0;
  (void)buf[0];  // a volatile read: the writes above are not dead
}

// the symbolic name, which is what the note's reader looks up
std::string errno_name(int e) {
  switch (e) {
    case EPERM: return "EPERM";
    case EINVAL: return "EINVAL";
    case ENOMEM: return "ENOMEM";
    case EAGAIN: return "EAGAIN";
    case ESRCH: return "ESRCH";
    case ENOTSUP: return "ENOTSUP";
    default: return "errno " + std::to_string(e);
  }
}

}  // namespace

std::int64_t next_deadline_ns(std::int64_t prev_deadline_ns,
                              std::int64_t now_ns, std::int64_t period_ns)
    noexcept {
  std::int64_t next = prev_deadline_ns + period_ns;
  const std::int64_t late_ns = now_ns - next;
  if (late_ns >= period_ns) next += (late_ns / period_ns) * period_ns;
  return next;
}

namespace {

// the period in ns, after checking the constructor's arguments
std::int64_t checked_period_ns(const ServoLoop* loop, const ServoOptions& opt) {
  if (loop == nullptr) {
    throw std::invalid_argument("ServoThread: loop is null");
  }
  if (!std::isfinite(opt.period_s) || opt.period_s < 1e-6 ||
      opt.period_s > 10.0) {
    throw std::invalid_argument(
        "ServoThread: period_s must be finite and in [1e-6, 10] s, got " +
        std::to_string(opt.period_s));
  }
  if (opt.realtime) {
    const int lo = sched_get_priority_min(SCHED_FIFO);
    const int hi = sched_get_priority_max(SCHED_FIFO);
    if (opt.priority < lo || opt.priority > hi) {
      throw std::invalid_argument(
          "ServoThread: priority " + std::to_string(opt.priority) +
          " outside SCHED_FIFO's range " + std::to_string(lo) + ".." +
          std::to_string(hi));
    }
  }
  return std::llround(opt.period_s * 1e9);
}

}  // namespace

ServoThread::ServoThread(ServoLoop* loop, const ServoOptions& opt)
    : loop_(loop),
      opt_(opt),
      period_ns_(checked_period_ns(loop, opt)),
      timer_(opt.period_s) {}

ServoThread::~ServoThread() { stop(); }

void ServoThread::set_stall_handler(StallHandler fn, void* user,
                                    int periods) {
  if (running()) {
    throw std::logic_error("ServoThread::set_stall_handler: loop is running");
  }
  if (fn == nullptr) {
    throw std::invalid_argument("ServoThread::set_stall_handler: fn is null");
  }
  if (periods < 2) {
    throw std::invalid_argument(
        "ServoThread::set_stall_handler: periods must be >= 2, got " +
        std::to_string(periods));
  }
  stall_fn_ = fn;
  stall_user_ = user;
  stall_periods_ = periods;
}

ServoReport ServoThread::start() {
  if (running()) {
    throw std::runtime_error("ServoThread::start: already running");
  }
  stop();  // joins a thread whose loop ended by itself
  stop_requested_.store(false);
  ticks_.store(0);
  timer_.reset();
  {
    std::lock_guard<std::mutex> lk(mutex_);
    ready_ = false;
    report_ = ServoReport{};
  }
  running_.store(true, std::memory_order_release);
  try {
    thread_ = std::thread(&ServoThread::run, this);
  } catch (const std::system_error& e) {
    running_.store(false);
    throw std::runtime_error(
        std::string("ServoThread::start: cannot create the servo thread: ") +
        e.what());
  }
  ServoReport report;
  {
    std::unique_lock<std::mutex> lk(mutex_);
    cv_.wait(lk, [this] { return ready_; });
    report = report_;
  }
  locked_memory_ = report.memory_locked;
  if (stall_fn_ != nullptr) {
    try {
      monitor_ = std::thread(&ServoThread::monitor, this);
    } catch (const std::system_error& e) {
      stop();
      throw std::runtime_error(
          std::string("ServoThread::start: cannot create the stall monitor "
                      "thread: ") + e.what());
    }
  }
  return report;
}

void ServoThread::stop() noexcept {
  stop_requested_.store(true, std::memory_order_release);
  {
    // under the mutex, so that the monitor cannot miss the wake-up
    std::lock_guard<std::mutex> lk(mutex_);
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (monitor_.joinable()) monitor_.join();
  running_.store(false, std::memory_order_release);
  if (locked_memory_) {
    munlockall();
    locked_memory_ = false;
  }
}

ServoReport ServoThread::setup_realtime() noexcept {
  ServoReport r;
  // std::string may throw on allocation failure; the note is then lost,
  // the flags are not
  try {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      r.memory_locked = true;
    } else {
      r.note += "mlockall was refused (" + errno_name(errno) +
                "), so the servo loop's memory may be paged out; allow it "
                "with CAP_IPC_LOCK or an unlimited memlock limit in "
                "/etc/security/limits.conf.";
    }
    sched_param sp{};
    sp.sched_priority = opt_.priority;
    const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
    if (e == 0) {
      r.sched_fifo = true;
    } else {
      if (!r.note.empty()) r.note += " ";
      r.note += "SCHED_FIFO at priority " + std::to_string(opt_.priority) +
                " was refused (" + errno_name(e) +
                "), so the servo loop runs at normal priority; allow it with "
                "CAP_SYS_NICE (e.g. setcap cap_sys_nice+ep on the program) "
                "or an rtprio limit of at least " +
                std::to_string(opt_.priority) +
                " in /etc/security/limits.conf.";
    }
  } catch (...) {
  }
  return r;
}

void ServoThread::run() noexcept {
  prefault_stack();
  ServoReport report;
  if (opt_.realtime) report = setup_realtime();
#ifdef __linux__
  // a normal thread's sleeps end up to 50 us late by default (timer slack);
  // SCHED_FIFO threads have none
  if (!report.sched_fifo) prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
#endif
  {
    std::lock_guard<std::mutex> lk(mutex_);
    report_ = std::move(report);
    ready_ = true;
  }
  cv_.notify_all();

  // from here on: no allocation, no lock, nothing that throws
  std::int64_t deadline_ns = now_ns() + period_ns_;
  while (!stop_requested_.load(std::memory_order_acquire)) {
    const timespec ts = to_timespec(deadline_ns);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) ==
           EINTR) {
    }
    if (stop_requested_.load(std::memory_order_acquire)) break;
    const double now_s = monotonic_now_s();
    timer_.begin(now_s);
    const bool more = loop_->tick(now_s);
    timer_.end(monotonic_now_s());
    ticks_.fetch_add(1, std::memory_order_release);
    if (!more) break;
    deadline_ns = next_deadline_ns(deadline_ns, now_ns(), period_ns_);
  }
  running_.store(false, std::memory_order_release);
}

void ServoThread::monitor() noexcept {
  const double window_s = stall_periods_ * opt_.period_s;
  const int wake_periods = stall_periods_ / 2 > 0 ? stall_periods_ / 2 : 1;
  const std::chrono::nanoseconds wake(period_ns_ * wake_periods);
  long seen = ticks();
  double progress_s = monotonic_now_s();  // when `seen` was first observed
  bool armed = true;
  std::unique_lock<std::mutex> lk(mutex_);
  for (;;) {
    if (cv_.wait_for(lk, wake, [this] {
          return stop_requested_.load(std::memory_order_acquire);
        })) {
      break;
    }
    if (!running()) break;  // the loop ended: not a stall
    const long n = ticks();
    const double now_s = monotonic_now_s();
    if (n != seen) {
      seen = n;
      progress_s = now_s;
      armed = true;
    } else if (armed && now_s - progress_s >= window_s) {
      // no tick completed since progress_s, at least window_s ago
      armed = false;
      lk.unlock();
      stall_fn_(stall_user_);
      lk.lock();
    }
  }
}

}  // namespace vmh
