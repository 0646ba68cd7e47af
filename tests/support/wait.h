// Waiting in the tests that run against a wall-clock thread: sleep, and
// poll a condition with a time limit. Only the *Realtime suites need this
// (emulator_test.cc and emulator_firewire_test.cc, on the emulator's
// physics thread); every other emulator test runs it in lockstep and has
// nothing to wait for.
#ifndef VMHAPTICS_TESTS_SUPPORT_WAIT_H_
#define VMHAPTICS_TESTS_SUPPORT_WAIT_H_

#include <chrono>
#include <functional>
#include <thread>

#include "device/tick_timer.h"

namespace vmh::testing {

inline void sleep_s(double s) {
  std::this_thread::sleep_for(std::chrono::duration<double>(s));
}

// polls `done` every millisecond for at most limit_s; whether it came true
inline bool wait_for(const std::function<bool()>& done, double limit_s) {
  const double end = monotonic_now_s() + limit_s;
  while (monotonic_now_s() < end) {
    if (done()) return true;
    sleep_s(1e-3);
  }
  return done();
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_WAIT_H_
