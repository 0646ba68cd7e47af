// The lockstep clock (device/lockstep.h): loop and plant in turn, tick k at
// exactly k T, no period after the loop's last tick, as many ticks as the
// time passed holds; and it allocates nothing.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "device/lockstep.h"
#include "tests/support/alloc_counter.h"

namespace vmh {
namespace {

// writes what happened, in order, into a fixed log
struct Log {
  char events[4096];
  int n = 0;
  void add(char c) { if (n < 4096) events[n++] = c; }
  std::string text() const { return std::string(events, static_cast<std::size_t>(n)); }
};

class Loop final : public ServoLoop {
 public:
  Log* log;
  int stop_after = 1 << 30;
  double times[4096];
  int k = 0;
  bool tick(double now_s) noexcept override {
    log->add('t');
    if (k < 4096) times[k] = now_s;
    return ++k < stop_after;
  }
};

class Plant final : public LockstepPlant {
 public:
  Log* log;
  void advance_period() noexcept override { log->add('p'); }
};

TEST(Lockstep, TicksAndPeriodsAlternateOnExactTimes) {
  Log log;
  Loop loop;
  loop.log = &log;
  Plant plant;
  plant.log = &log;
  LockstepDriver d(1e-3);
  d.start(&loop, &plant);
  d.pass(0.02);
  std::string want;
  for (int k = 0; k < 20; ++k) want += "tp";
  EXPECT_EQ(log.text(), want);
  for (int k = 0; k < 20; ++k) EXPECT_EQ(loop.times[k], static_cast<double>(k) * 1e-3);
  EXPECT_EQ(d.ticks(), 20);
  EXPECT_TRUE(d.running());
  const TickStats t = d.timing();
  EXPECT_EQ(t.ticks, 20);
  EXPECT_EQ(t.overruns, 0);
}

TEST(Lockstep, NoPeriodFollowsTheLoopsLastTick) {
  Log log;
  Loop loop;
  loop.log = &log;
  loop.stop_after = 3;
  Plant plant;
  plant.log = &log;
  LockstepDriver d(1e-3);
  d.start(&loop, &plant);
  d.pass(1.0);
  EXPECT_EQ(log.text(), "tptpt");
  EXPECT_FALSE(d.running());
  d.pass(1.0);  // nothing more
  EXPECT_EQ(log.text(), "tptpt");
}

TEST(Lockstep, StopEndsIt) {
  Log log;
  Loop loop;
  loop.log = &log;
  Plant plant;
  plant.log = &log;
  LockstepDriver d(1e-3);
  d.start(&loop, &plant);
  d.pass(0.002);
  d.stop();
  d.pass(0.002);
  EXPECT_EQ(log.text(), "tptp");
}

TEST(NoAlloc, LockstepPass) {
  Log log;
  Loop loop;
  loop.log = &log;
  Plant plant;
  plant.log = &log;
  LockstepDriver d(1e-3);
  d.start(&loop, &plant);
  testing::AllocationScope scope;
  d.pass(1.0);
  EXPECT_EQ(scope.count(), 0u);
}

}  // namespace
}  // namespace vmh
