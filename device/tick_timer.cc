#include "device/tick_timer.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace vmh {

double monotonic_now_s() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

namespace {

// single writer: a relaxed load and store is an increment nobody races
void bump(std::atomic<long>& c) noexcept {
  c.store(c.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

int bin_of(double v_s, double bin_s) noexcept {
  if (!(v_s >= 0.0)) return 0;  // negative or NaN (a clock step back)
  const double b = std::floor(v_s / bin_s);
  return b >= TickTimer::kBins - 1 ? TickTimer::kBins - 1 : static_cast<int>(b);
}

// the value below which a fraction p of the counts lie, to the bin centre
double percentile(const std::array<std::atomic<long>, TickTimer::kBins>& h,
                  double p, double bin_s) {
  long total = 0;
  for (const auto& c : h) total += c.load(std::memory_order_relaxed);
  if (total == 0) return 0.0;
  const double want = p * static_cast<double>(total);
  long seen = 0;
  for (int i = 0; i < TickTimer::kBins; ++i) {
    seen += h[i].load(std::memory_order_relaxed);
    if (static_cast<double>(seen) >= want) return (i + 0.5) * bin_s;
  }
  return (TickTimer::kBins - 0.5) * bin_s;
}

}  // namespace

TickTimer::TickTimer(double nominal_period_s) : nominal_s_(nominal_period_s) {
  if (!std::isfinite(nominal_period_s) || nominal_period_s <= 0.0) {
    throw std::invalid_argument("TickTimer: nominal_period_s must be > 0");
  }
  bin_s_ = 4.0 * nominal_s_ / kBins;
  reset();
}

void TickTimer::reset() noexcept {
  have_begin_ = false;
  last_begin_s_ = 0.0;
  ticks_.store(0);
  overruns_.store(0);
  sum_period_s_.store(0.0);
  min_period_s_.store(0.0);
  max_period_s_.store(0.0);
  max_jitter_s_.store(0.0);
  max_work_s_.store(0.0);
  for (auto& c : period_hist_) c.store(0);
  for (auto& c : jitter_hist_) c.store(0);
  for (auto& c : work_hist_) c.store(0);
}

void TickTimer::begin(double now_s) noexcept {
  bump(ticks_);
  if (have_begin_) {
    const double period = now_s - last_begin_s_;
    const double jitter = std::abs(period - nominal_s_);
    const auto r = std::memory_order_relaxed;
    bump(period_hist_[bin_of(period, bin_s_)]);
    bump(jitter_hist_[bin_of(jitter, bin_s_)]);
    sum_period_s_.store(sum_period_s_.load(r) + period, r);
    // the first period seeds the minimum
    if (ticks_.load(r) == 2 || period < min_period_s_.load(r)) {
      min_period_s_.store(period, r);
    }
    if (period > max_period_s_.load(r)) max_period_s_.store(period, r);
    if (jitter > max_jitter_s_.load(r)) max_jitter_s_.store(jitter, r);
    if (period > 1.5 * nominal_s_) bump(overruns_);
  }
  last_begin_s_ = now_s;
  have_begin_ = true;
}

void TickTimer::end(double now_s) noexcept {
  const double work = now_s - last_begin_s_;
  bump(work_hist_[bin_of(work, bin_s_)]);
  if (work > max_work_s_.load(std::memory_order_relaxed)) {
    max_work_s_.store(work, std::memory_order_relaxed);
  }
}

TickStats TickTimer::stats() const {
  const auto r = std::memory_order_relaxed;
  TickStats s;
  s.ticks = ticks_.load(r);
  s.overruns = overruns_.load(r);
  s.nominal_period_s = nominal_s_;
  const long periods = std::max(0L, s.ticks - 1);
  s.period_mean_s = periods > 0 ? sum_period_s_.load(r) / static_cast<double>(periods)
                                  : 0.0;
  s.period_min_s = min_period_s_.load(r);
  s.period_max_s = max_period_s_.load(r);
  s.period_p50_s = percentile(period_hist_, 0.50, bin_s_);
  s.period_p99_s = percentile(period_hist_, 0.99, bin_s_);
  s.jitter_p50_s = percentile(jitter_hist_, 0.50, bin_s_);
  s.jitter_p99_s = percentile(jitter_hist_, 0.99, bin_s_);
  s.jitter_max_s = max_jitter_s_.load(r);
  s.work_p50_s = percentile(work_hist_, 0.50, bin_s_);
  s.work_p99_s = percentile(work_hist_, 0.99, bin_s_);
  s.work_max_s = max_work_s_.load(r);
  s.histogram.reserve(kBins);
  for (const auto& c : period_hist_) s.histogram.push_back(c.load(r));
  s.histogram_bin_s = bin_s_;
  return s;
}

}  // namespace vmh
