#include "device/stop_signal.h"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace vmh {

namespace {

// a handler may only touch lock-free atomics (async-signal-safe)
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free,
              "the signal flag must be lock-free");
std::atomic<bool> g_installed{false};

extern "C" void on_stop_signal(int signo) {
  g_signal.store(signo, std::memory_order_relaxed);
}

void install(int signo, struct sigaction* old) {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  if (sigaction(signo, &sa, old) != 0) {
    throw std::runtime_error(std::string("StopSignals: sigaction(") +
                             (signo == SIGINT ? "SIGINT" : "SIGTERM") +
                             ") failed: " + std::strerror(errno));
  }
}

}  // namespace

StopSignals::StopSignals() {
  if (g_installed.exchange(true)) {
    throw std::logic_error("StopSignals: another instance is installed");
  }
  g_signal.store(0);
  try {
    install(SIGINT, &old_int_);
    try {
      install(SIGTERM, &old_term_);
    } catch (...) {
      sigaction(SIGINT, &old_int_, nullptr);
      throw;
    }
  } catch (...) {
    g_installed.store(false);
    throw;
  }
}

StopSignals::~StopSignals() {
  sigaction(SIGTERM, &old_term_, nullptr);
  sigaction(SIGINT, &old_int_, nullptr);
  g_installed.store(false);
}

int StopSignals::signal_number() const noexcept {
  return g_signal.load(std::memory_order_relaxed);
}

}  // namespace vmh
