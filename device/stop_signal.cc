#include "device/stop_signal.h"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

namespace vmh {

namespace {

// a handler may only touch lock-free atomics (async-signal-safe)
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free,
              "the signal flag must be lock-free");

// how many StopSignals live, and the handlers the outermost replaced
std::mutex g_mutex;
int g_depth = 0;
struct sigaction g_old_int {};
struct sigaction g_old_term {};

extern "C" void on_stop_signal(int signo) {
  // the first one wins: a later signal only repeats the request
  int none = 0;
  g_signal.compare_exchange_strong(none, signo, std::memory_order_relaxed);
}

void install(int signo, struct sigaction* old) {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  // both blocked while either handler runs: with SIGINT and SIGTERM
  // pending at once the kernel sets up SIGINT's handler first, and without
  // this it would set up SIGTERM's on top of it, which then runs first and
  // is taken for the first signal
  sigemptyset(&sa.sa_mask);
  sigaddset(&sa.sa_mask, SIGINT);
  sigaddset(&sa.sa_mask, SIGTERM);
  sa.sa_flags = SA_RESTART;
  if (sigaction(signo, &sa, old) != 0) {
    throw std::runtime_error(std::string("StopSignals: sigaction(") +
                             (signo == SIGINT ? "SIGINT" : "SIGTERM") +
                             ") failed: " + std::strerror(errno));
  }
}

}  // namespace

StopSignals::StopSignals() {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_depth == 0) {
    g_signal.store(0);
    install(SIGINT, &g_old_int);
    try {
      install(SIGTERM, &g_old_term);
    } catch (...) {
      sigaction(SIGINT, &g_old_int, nullptr);
      throw;
    }
  }
  ++g_depth;
}

StopSignals::~StopSignals() {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (--g_depth == 0) {
    sigaction(SIGTERM, &g_old_term, nullptr);
    sigaction(SIGINT, &g_old_int, nullptr);
    g_signal.store(0);
  }
}

int StopSignals::signal_number() const noexcept {
  return g_signal.load(std::memory_order_relaxed);
}

int stop_signal_number() noexcept {
  return g_signal.load(std::memory_order_relaxed);
}

}  // namespace vmh
