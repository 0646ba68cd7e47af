// Readings of a running sim::Emulator paired with its ground truth, for the
// tests that compare what the device reports with what is true.
#ifndef VMHAPTICS_TESTS_SUPPORT_EMULATOR_READING_H_
#define VMHAPTICS_TESTS_SUPPORT_EMULATOR_READING_H_

#include <vector>

#include "device/tick_timer.h"
#include "sim/emulator.h"
#include "tests/support/wait.h"

namespace vmh::testing {

// A reading and the truth of the period it was taken in (its timestamp is
// that period's publish time). A reading and its truth are published one
// after the other, so the pair is taken only when the truth did not move
// across the read and the timestamps agree; retried for up to 2 s.
inline bool matched_reading(sim::Emulator* emu, DeviceState* s,
                            sim::EmulatorTruth* t) {
  const double end = monotonic_now_s() + 2.0;
  while (monotonic_now_s() < end) {
    const sim::EmulatorTruth before = emu->truth();
    const DeviceError e = emu->read_state(s);
    const sim::EmulatorTruth after = emu->truth();
    if (e == DeviceError::kOk && before.periods == after.periods &&
        s->timestamp_s == before.wall_s) {
      *t = before;
      return true;
    }
    sleep_s(2e-4);
  }
  return false;
}

// Every truth published over `seconds` (polled every 0.1 ms; a period may
// be missed on a loaded machine), with a reading taken at each poll and
// the newest truth before and after that read.
struct Polled {
  std::vector<sim::EmulatorTruth> truths;
  struct Read {
    DeviceState state;
    long periods_before = -1, periods_after = -1;
  };
  std::vector<Read> reads;
};
inline Polled poll_emulator(sim::Emulator* emu, double seconds) {
  Polled p;
  p.truths.reserve(static_cast<std::size_t>(seconds * 2e3) + 16);
  p.reads.reserve(static_cast<std::size_t>(seconds * 1e4) + 16);
  const double end = monotonic_now_s() + seconds;
  while (monotonic_now_s() < end) {
    const sim::EmulatorTruth t = emu->truth();
    if (p.truths.empty() || p.truths.back().periods != t.periods) {
      p.truths.push_back(t);
    }
    Polled::Read r;
    r.periods_before = t.periods;
    if (emu->read_state(&r.state) == DeviceError::kOk) {
      r.periods_after = emu->truth().periods;
      p.reads.push_back(r);
    }
    sleep_s(1e-4);
  }
  return p;
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_EMULATOR_READING_H_
