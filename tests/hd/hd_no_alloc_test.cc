// The open HD API's servo tick allocates nothing: the library's tick (every
// device sampled through the reading guard and the safety layer, the
// callbacks, every command sent), a callback's state reads and commands,
// its error checks, and the emulator's period in lockstep. Counted through
// operator new over 2000 ticks after a warm-up (the first ticks of a thread
// may allocate its thread-local storage).
#include <HD/hd.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <thread>

#include "tests/support/alloc_counter.h"

namespace {

std::atomic<long> g_frames{0};

HDCallbackCode HDCALLBACK servo(void*) {
  const HHD h = hdGetCurrentDevice();
  hdBeginFrame(h);
  double p[3], T[16], J[36], q[3];
  HDlong enc[6];
  hdGetDoublev(HD_CURRENT_POSITION, p);
  hdGetDoublev(HD_CURRENT_TRANSFORM, T);
  hdGetDoublev(HD_CURRENT_JACOBIAN, J);
  hdGetDoublev(HD_LAST_JOINT_ANGLES, q);
  hdGetLongv(HD_CURRENT_ENCODER_VALUES, enc);
  const double f[3] = {0.3 * ((g_frames.load() / 200) % 2), 0.1, 0.0};
  hdSetDoublev(HD_CURRENT_FORCE, f);
  const double tau[3] = {1.0, 0.0, -1.0};
  hdSetDoublev(HD_CURRENT_JOINT_TORQUE, tau);
  hdEndFrame(h);
  while (HD_DEVICE_ERROR(hdGetError())) {
  }
  g_frames.fetch_add(1);
  return HD_CALLBACK_CONTINUE;
}

void wait_for_frames(long n) {
  for (int i = 0; i < 60000 && g_frames.load() < n; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

TEST(HdNoAlloc, TheServoTickAllocatesNothing) {
  setenv("VMH_HD_CLOCK", "lockstep", 1);
  setenv("VMH_HD_PACE", "free", 1);
  setenv("VMH_HD_QUIET", "1", 1);
  const HHD h = hdInitDevice(HD_DEFAULT_DEVICE);
  ASSERT_NE(h, HD_INVALID_HANDLE) << hdGetErrorString(hdGetError().errorCode);
  const HDSchedulerHandle s =
      hdScheduleAsynchronous(servo, nullptr, HD_DEFAULT_SCHEDULER_PRIORITY);
  hdStartScheduler();
  wait_for_frames(200);
  const long start = g_frames.load();
  std::size_t allocations = 0;
  {
    vmh::testing::AllocationScope scope;
    wait_for_frames(start + 2000);
    allocations = scope.count();
  }
  const long counted = g_frames.load() - start;
  hdStopScheduler();
  hdUnschedule(s);
  hdDisableDevice(h);
  EXPECT_GE(counted, 2000);
  EXPECT_EQ(allocations, 0u) << "over " << counted << " ticks";
}

}  // namespace
