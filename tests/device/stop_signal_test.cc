// StopSignals: a raised SIGINT or SIGTERM is recorded, not fatal, the first
// one is the one named, instances nest (a session inside a verb that
// listens), and the handler that was there before comes back when the last
// one goes.
#include "device/stop_signal.h"

#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <stdexcept>

namespace vmh {
namespace {

std::atomic<int> g_previous_calls{0};
extern "C" void previous_handler(int) { g_previous_calls.fetch_add(1); }

// installs previous_handler for signo, and puts back what was there
class PreviousHandler {
 public:
  explicit PreviousHandler(int signo) : signo_(signo) {
    struct sigaction sa {};
    sa.sa_handler = previous_handler;
    sigemptyset(&sa.sa_mask);
    sigaction(signo_, &sa, &saved_);
  }
  ~PreviousHandler() { sigaction(signo_, &saved_, nullptr); }

 private:
  int signo_;
  struct sigaction saved_ {};
};

void (*current_handler(int signo))(int) {
  struct sigaction now {};
  sigaction(signo, nullptr, &now);
  return now.sa_handler;
}

TEST(StopSignals, NothingRequestedAtFirst) {
  StopSignals s;
  EXPECT_FALSE(s.requested());
  EXPECT_EQ(s.signal_number(), 0);
}

TEST(StopSignals, SigintIsRecorded) {
  StopSignals s;
  ASSERT_EQ(raise(SIGINT), 0);  // the process would end without the handler
  EXPECT_TRUE(s.requested());
  EXPECT_EQ(s.signal_number(), SIGINT);
}

TEST(StopSignals, SigtermIsRecorded) {
  StopSignals s;
  ASSERT_EQ(raise(SIGTERM), 0);
  EXPECT_TRUE(s.requested());
  EXPECT_EQ(s.signal_number(), SIGTERM);
}

TEST(StopSignals, ANewInstanceStartsClear) {
  {
    StopSignals s;
    raise(SIGINT);
    ASSERT_TRUE(s.requested());
  }
  StopSignals again;
  EXPECT_FALSE(again.requested());
}

// SIGINT, SIGINT, SIGTERM: the first one is named (issue 34: the last one
// was, so a Ctrl-C followed by a kill exited 143)
TEST(StopSignals, TheFirstSignalIsNamed) {
  StopSignals s;
  raise(SIGINT);
  raise(SIGINT);
  raise(SIGTERM);
  EXPECT_EQ(s.signal_number(), SIGINT);
  EXPECT_EQ(stop_signal_number(), SIGINT);
}

// SIGINT and SIGTERM pending at once (sent within a few ms to a process
// not scheduled in between): the kernel sets up SIGINT's handler first;
// SIGTERM's must not be set up on top of it and run first
TEST(StopSignals, TheFirstSignalIsNamedWhenBothArePending) {
  StopSignals s;
  sigset_t both, old;
  sigemptyset(&both);
  sigaddset(&both, SIGINT);
  sigaddset(&both, SIGTERM);
  ASSERT_EQ(pthread_sigmask(SIG_BLOCK, &both, &old), 0);
  raise(SIGINT);
  raise(SIGTERM);
  EXPECT_EQ(s.signal_number(), 0);  // not delivered yet
  ASSERT_EQ(pthread_sigmask(SIG_SETMASK, &old, nullptr), 0);  // both now
  EXPECT_EQ(s.signal_number(), SIGINT);
}

// an inner instance shares the outer's flag both ways, and its end leaves
// the handlers installed
TEST(StopSignals, InstancesNest) {
  StopSignals outer;
  raise(SIGTERM);
  {
    StopSignals inner;
    EXPECT_EQ(inner.signal_number(), SIGTERM);  // came before it
    raise(SIGINT);
    EXPECT_EQ(inner.signal_number(), SIGTERM);
  }
  EXPECT_NE(current_handler(SIGINT), SIG_DFL);
  raise(SIGINT);  // still caught
  EXPECT_EQ(outer.signal_number(), SIGTERM);
}

// the free functions read the same flag, and nothing while none lives
TEST(StopSignals, StopRequestedWithoutAnInstance) {
  EXPECT_FALSE(stop_requested());
  {
    StopSignals s;
    EXPECT_FALSE(stop_requested());
    raise(SIGTERM);
    EXPECT_TRUE(stop_requested());
    EXPECT_EQ(stop_signal_number(), SIGTERM);
  }
  EXPECT_FALSE(stop_requested());
  EXPECT_EQ(stop_signal_number(), 0);
}

TEST(StopSignals, ThePreviousHandlersAreRestored) {
  for (int signo : {SIGINT, SIGTERM}) {
    PreviousHandler prev(signo);
    g_previous_calls.store(0);
    {
      StopSignals s;
      EXPECT_NE(current_handler(signo), &previous_handler);
      raise(signo);
      EXPECT_EQ(s.signal_number(), signo);
      EXPECT_EQ(g_previous_calls.load(), 0);  // not the old handler
    }
    EXPECT_EQ(current_handler(signo), &previous_handler);
    raise(signo);
    EXPECT_EQ(g_previous_calls.load(), 1);  // the old handler again
  }
}

TEST(StopSignals, DefaultDispositionIsRestored) {
  // gtest leaves SIGINT and SIGTERM at SIG_DFL
  ASSERT_EQ(current_handler(SIGINT), SIG_DFL);
  { StopSignals s; }
  EXPECT_EQ(current_handler(SIGINT), SIG_DFL);
  EXPECT_EQ(current_handler(SIGTERM), SIG_DFL);
}

}  // namespace
}  // namespace vmh
