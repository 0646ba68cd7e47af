// Timing of a servo loop's ticks: the period between tick starts and the
// time spent inside each tick, kept in fixed histograms so that recording
// allocates nothing and another thread can read the figures while the loop
// runs (single writer; the counters are relaxed atomics, so a reading taken
// mid-tick may be one tick out of date, never torn).
//
// Jitter is |period - nominal period|. An overrun is a tick whose period
// exceeded 1.5 nominal periods (a deadline missed by half a period or more).
#ifndef VMHAPTICS_DEVICE_TICK_TIMER_H_
#define VMHAPTICS_DEVICE_TICK_TIMER_H_

#include <array>
#include <atomic>
#include <vector>

namespace vmh {

// CLOCK_MONOTONIC, s
double monotonic_now_s() noexcept;

struct TickStats {
  long ticks = 0;       // ticks begun
  long overruns = 0;    // periods over 1.5 nominal
  double nominal_period_s = 0.0;
  // periods between successive tick starts, s (ticks - 1 of them)
  double period_mean_s = 0.0;
  double period_min_s = 0.0;
  double period_p50_s = 0.0;
  double period_p99_s = 0.0;
  double period_max_s = 0.0;
  // |period - nominal|, s
  double jitter_p50_s = 0.0;
  double jitter_p99_s = 0.0;
  double jitter_max_s = 0.0;
  // time inside tick(), s
  double work_p50_s = 0.0;
  double work_p99_s = 0.0;
  double work_max_s = 0.0;
  // periods binned from 0 in steps of histogram_bin_s; the last bin holds
  // everything beyond
  std::vector<long> histogram;
  double histogram_bin_s = 0.0;
};

class TickTimer {
 public:
  // histogram range: 0 to 4 nominal periods in 400 bins (10 us at 1 kHz);
  // percentiles are read to the bin's centre. Min and max are exact.
  static constexpr int kBins = 400;

  // throws std::invalid_argument for a non-positive or non-finite period
  explicit TickTimer(double nominal_period_s);

  // at the start of a tick and at its end, on the loop's thread
  void begin(double now_s) noexcept;
  void end(double now_s) noexcept;

  // the figures so far; callable from any thread
  TickStats stats() const;

  // forget everything (not while the loop runs)
  void reset() noexcept;

  double nominal_period_s() const noexcept { return nominal_s_; }

 private:
  double nominal_s_;
  double bin_s_;
  double last_begin_s_ = 0.0;
  bool have_begin_ = false;
  std::atomic<long> ticks_{0};
  std::atomic<long> overruns_{0};
  std::atomic<double> sum_period_s_{0.0};
  std::atomic<double> min_period_s_{0.0};
  std::atomic<double> max_period_s_{0.0};
  std::atomic<double> max_jitter_s_{0.0};
  std::atomic<double> max_work_s_{0.0};
  std::array<std::atomic<long>, kBins> period_hist_{};
  std::array<std::atomic<long>, kBins> jitter_hist_{};
  std::array<std::atomic<long>, kBins> work_hist_{};
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_TICK_TIMER_H_
