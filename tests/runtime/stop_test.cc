// throw_if_stopped: nothing while no signal came (or no StopSignals lives),
// else a SignalStop carrying the first signal, its message naming the verb,
// the signal and what the verb left.
#include "runtime/stop.h"

#include <gtest/gtest.h>
#include <signal.h>

#include "device/stop_signal.h"

namespace vmh::runtime {
namespace {

TEST(ThrowIfStopped, NothingWithoutASignal) {
  EXPECT_NO_THROW(throw_if_stopped("compare"));
  StopSignals s;
  EXPECT_NO_THROW(throw_if_stopped("compare", "; nothing written"));
}

TEST(ThrowIfStopped, TheFirstSignalIsCarriedAndNamed) {
  StopSignals s;
  raise(SIGINT);
  raise(SIGTERM);
  try {
    throw_if_stopped("compare", "; nothing written");
    FAIL() << "no SignalStop";
  } catch (const SignalStop& e) {
    EXPECT_EQ(e.signal, SIGINT);
    EXPECT_STREQ(e.what(), "interrupted: compare stopped by SIGINT; nothing written");
  }
}

TEST(ThrowIfStopped, SigtermIs143) {
  StopSignals s;
  raise(SIGTERM);
  try {
    throw_if_stopped("render");
    FAIL() << "no SignalStop";
  } catch (const SignalStop& e) {
    EXPECT_EQ(128 + e.signal, 143);
    EXPECT_STREQ(e.what(), "interrupted: render stopped by SIGTERM");
  }
}

TEST(ThrowIfStopped, SignalNames) {
  EXPECT_EQ(signal_name(SIGINT), "SIGINT");
  EXPECT_EQ(signal_name(SIGTERM), "SIGTERM");
  EXPECT_EQ(signal_name(SIGHUP), "signal " + std::to_string(SIGHUP));
}

}  // namespace
}  // namespace vmh::runtime
