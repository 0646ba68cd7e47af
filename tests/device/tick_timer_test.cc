// TickTimer on synthetic timestamps (no clock): every figure is checked
// against one worked out by hand from the sequence fed in. The histogram
// has 400 bins of 10 us at a 1 ms nominal period; the periods are chosen
// mid-bin so that rounding cannot move them.
#include "device/tick_timer.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

namespace vmh {
namespace {

constexpr double kNominal = 1e-3;
constexpr double kBin = 1e-5;  // 4 nominal periods / 400 bins

// one tick every period in `periods`, each spending work_s inside
void feed(TickTimer* t, const std::vector<double>& periods, double work_s) {
  double now = 10.0;  // the clock's origin does not matter
  t->begin(now);
  t->end(now + work_s);
  for (double p : periods) {
    now += p;
    t->begin(now);
    t->end(now + work_s);
  }
}

TEST(TickTimer, RefusesABadPeriod) {
  EXPECT_THROW(TickTimer(0.0), std::invalid_argument);
  EXPECT_THROW(TickTimer(-1e-3), std::invalid_argument);
  EXPECT_THROW(TickTimer{std::numeric_limits<double>::quiet_NaN()},
               std::invalid_argument);
}

TEST(TickTimer, EmptyAndSingleTick) {
  TickTimer t(kNominal);
  TickStats s = t.stats();
  EXPECT_EQ(s.ticks, 0);
  EXPECT_EQ(s.period_mean_s, 0.0);
  EXPECT_EQ(s.histogram.size(), static_cast<std::size_t>(TickTimer::kBins));
  EXPECT_DOUBLE_EQ(s.histogram_bin_s, kBin);
  t.begin(1.0);
  t.end(1.0002);
  s = t.stats();
  EXPECT_EQ(s.ticks, 1);
  EXPECT_EQ(s.overruns, 0);
  long binned = 0;
  for (long c : s.histogram) binned += c;
  EXPECT_EQ(binned, 0);  // one tick, no period yet
  EXPECT_NEAR(s.work_max_s, 2e-4, 1e-12);
}

TEST(TickTimer, FiguresWorkedOutByHand) {
  // 100 periods: one short (0.905 ms), 97 of 1.005 ms, one of 2.005 ms and
  // one of 3.005 ms. Sorted, the cumulative counts are 1 (bin 90), 98 (bin
  // 100), 99 (bin 200), 100 (bin 300).
  std::vector<double> periods;
  periods.push_back(0.905e-3);
  for (int i = 0; i < 97; ++i) periods.push_back(1.005e-3);
  periods.push_back(2.005e-3);
  periods.push_back(3.005e-3);
  TickTimer t(kNominal);
  feed(&t, periods, 0.255e-3);
  const TickStats s = t.stats();
  EXPECT_EQ(s.ticks, 101);
  EXPECT_EQ(s.overruns, 2);  // the two over 1.5 ms
  EXPECT_DOUBLE_EQ(s.nominal_period_s, kNominal);
  const double sum_ms = 0.905 + 97 * 1.005 + 2.005 + 3.005;
  EXPECT_NEAR(s.period_mean_s, sum_ms * 1e-3 / 100, 1e-12);
  EXPECT_NEAR(s.period_min_s, 0.905e-3, 1e-12);
  EXPECT_NEAR(s.period_max_s, 3.005e-3, 1e-12);
  // p50: the 50th of 100 lies in bin 100 -> its centre, 1.005 ms;
  // p99: the 99th lies in bin 200 -> 2.005 ms
  EXPECT_NEAR(s.period_p50_s, 100.5 * kBin, 1e-12);
  EXPECT_NEAR(s.period_p99_s, 200.5 * kBin, 1e-12);
  // jitter |p - 1 ms|: 97 of 5 us (bin 0), one of 95 us (bin 9), one of
  // 1.005 ms (bin 100), one of 2.005 ms (bin 200). p50 in bin 0, the 99th
  // in bin 100.
  EXPECT_NEAR(s.jitter_p50_s, 0.5 * kBin, 1e-12);
  EXPECT_NEAR(s.jitter_p99_s, 100.5 * kBin, 1e-12);
  EXPECT_NEAR(s.jitter_max_s, 2.005e-3, 1e-12);
  // work: 101 ticks of 0.255 ms, bin 25
  EXPECT_NEAR(s.work_p50_s, 25.5 * kBin, 1e-12);
  EXPECT_NEAR(s.work_p99_s, 25.5 * kBin, 1e-12);
  EXPECT_NEAR(s.work_max_s, 0.255e-3, 1e-12);
  // the histogram itself
  ASSERT_EQ(s.histogram.size(), 400u);
  std::vector<long> expected(400, 0);
  expected[90] = 1;
  expected[100] = 97;
  expected[200] = 1;
  expected[300] = 1;
  EXPECT_EQ(s.histogram, expected);
}

TEST(TickTimer, LongPeriodsLandInTheLastBinWithAnExactMax) {
  TickTimer t(kNominal);
  feed(&t, {1.005e-3, 7.0e-3, 1.005e-3, 25.0e-3}, 0.0);
  const TickStats s = t.stats();
  EXPECT_EQ(s.overruns, 2);
  EXPECT_EQ(s.histogram[399], 2);  // beyond 4 ms
  EXPECT_EQ(s.histogram[100], 2);
  EXPECT_NEAR(s.period_max_s, 25.0e-3, 1e-12);
  EXPECT_NEAR(s.jitter_max_s, 24.0e-3, 1e-12);
  // two of four past the range: p99 is the last bin's centre
  EXPECT_NEAR(s.period_p99_s, 399.5 * kBin, 1e-12);
}

TEST(TickTimer, OverrunThresholdIsHalfAPeriodLate) {
  TickTimer t(kNominal);
  feed(&t, {1.495e-3, 1.505e-3, 1.2e-3, 2.5e-3}, 0.0);
  EXPECT_EQ(t.stats().overruns, 2);  // 1.505 and 2.5 ms
}

TEST(TickTimer, ResetForgetsEverything) {
  TickTimer t(kNominal);
  feed(&t, {1.005e-3, 3.0e-3}, 1e-4);
  t.reset();
  const TickStats s = t.stats();
  EXPECT_EQ(s.ticks, 0);
  EXPECT_EQ(s.overruns, 0);
  EXPECT_EQ(s.period_max_s, 0.0);
  EXPECT_EQ(s.work_max_s, 0.0);
  for (long c : s.histogram) EXPECT_EQ(c, 0);
  // and the first tick after a reset makes no period
  t.begin(100.0);
  t.begin(100.001005);
  EXPECT_NEAR(t.stats().period_max_s, 1.005e-3, 1e-9);
}

TEST(TickTimer, StatsFromAnotherThreadWhileTicking) {
  constexpr long kTicks = 200000;
  TickTimer t(kNominal);
  std::atomic<bool> done{false}, reading{false};
  std::thread loop([&] {
    while (!reading.load()) std::this_thread::yield();  // overlap the reader
    double now = 0.0;
    for (long i = 0; i < kTicks; ++i) {
      now += (i % 10 == 0) ? 2.005e-3 : 1.005e-3;
      t.begin(now);
      t.end(now + 1e-4);
    }
    done.store(true);
  });
  long last = 0, backwards = 0, over = 0;
  do {
    const TickStats s = t.stats();
    reading.store(true);
    if (s.ticks < last) ++backwards;
    if (s.ticks > kTicks) ++over;
    last = s.ticks;
  } while (!done.load());
  loop.join();
  EXPECT_EQ(backwards, 0);
  EXPECT_EQ(over, 0);
  const TickStats s = t.stats();
  EXPECT_EQ(s.ticks, kTicks);
  long binned = 0;
  for (long c : s.histogram) binned += c;
  EXPECT_EQ(binned, kTicks - 1);
  // every tenth period but the first (which has none before it) is long
  EXPECT_EQ(s.overruns, (kTicks - 1) / 10);
  EXPECT_EQ(s.histogram[200], (kTicks - 1) / 10);
}

}  // namespace
}  // namespace vmh
