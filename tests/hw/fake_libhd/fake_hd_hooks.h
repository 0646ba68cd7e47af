// What the test libHD.so exports beside the HD API, for the tests to look at
// what the backend did (resolved with dlsym from the same loaded library).
#ifndef VMHAPTICS_TESTS_HW_FAKE_LIBHD_FAKE_HD_HOOKS_H_
#define VMHAPTICS_TESTS_HW_FAKE_LIBHD_FAKE_HD_HOOKS_H_

extern "C" {

struct FakeHdCounters {
  long frames;              // outermost hdBeginFrame calls that sampled
  long sets_in_frame;       // hdSetDoublev inside begin/end on the scheduler
  long sets_outside_frame;  // hdSetDoublev anywhere else
  long illegal_frames;      // begin/end off the scheduler thread or unpaired
  long async_scheduled;     // hdScheduleAsynchronous calls
  long max_priority;        // highest priority any callback was given
  long enables_force;       // hdEnable(HD_FORCE_OUTPUT) calls
  long inits;               // successful hdInitDevice calls
  long disables;            // hdDisableDevice calls
  int scheduler_running;    // between hdStartScheduler and hdStopScheduler
};

// counters since the last hdInitDevice
typedef void (*FakeHdCountersFn)(FakeHdCounters* out);
// last HD_CURRENT_JOINT_TORQUE set, mN m; last HD_CURRENT_FORCE, N
typedef void (*FakeHdVec3Fn)(double* out3);
// the model's joint angles at the last frame, rad (device convention)
typedef void (*FakeHdJointsFn)(double* out6);
// the model's own DH joint angles (rad, MuJoCo's state): 1 if it has them
typedef int (*FakeHdTrueJointsFn)(double* out6);
// 1 on the scheduler thread between hdBeginFrame and hdEndFrame
typedef int (*FakeHdInFrameFn)();

}  // extern "C"

#endif  // VMHAPTICS_TESTS_HW_FAKE_LIBHD_FAKE_HD_HOOKS_H_
