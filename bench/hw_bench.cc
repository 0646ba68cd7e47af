// What the hw path costs per tick beyond servo_tick(): the same controller
// (the circle of L = 50 mm, the thesis's case 2 gains) on the same device
// (one that answers at once with a fixed reading), ticked
//   BM_ServoTick        by servo_tick() alone, straight on the device;
//   BM_SafetyServoTick  by servo_tick() through the reading guard and the
//                       safety layer (device/safety.h);
//   BM_HwLoopTick       by the session's loop (runtime/session_loop.h): the
//                       same chain (device/servo_chain.h), plus the
//                       record's bookkeeping and its push into the ring.
// The difference of the last two from the first is the hw path's own cost.
#include <benchmark/benchmark.h>

#include "runtime/session_loop.h"
#include "controller/controller.h"
#include "device/reading_guard.h"
#include "device/safety.h"
#include "device/servo_tick.h"

namespace vmh {
namespace {

// answers at once, always the same pose (a few cm off the circle)
class FixedDevice final : public HapticDevice {
 public:
  Joints q = (Joints() << -0.1, 0.4, 0.1, -0.2, 0.3, 0.1).finished();
  DeviceError read_joints(Joints* out) noexcept override {
    *out = q;
    return DeviceError::kOk;
  }
  DeviceError write_motor_torques(const Vec3& tau) noexcept override {
    benchmark::DoNotOptimize(tau);
    return DeviceError::kOk;
  }
};

ControllerParams circle() {
  ControllerParams p;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  return p;
}

void BM_ServoTick(benchmark::State& state) {
  FixedDevice dev;
  Controller c(circle());
  ControlOutput out;
  for (auto _ : state) benchmark::DoNotOptimize(servo_tick(&dev, &c, &out));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ServoTick);

void BM_SafetyServoTick(benchmark::State& state) {
  FixedDevice dev;
  ReadingGuard guard(&dev, GuardParams());
  SafetyLayer safety(&guard, SafetyParams());
  Controller c(circle());
  ControlOutput out;
  double t = 0.0;
  for (auto _ : state) {
    safety.set_read_time(t += 1e-3);
    benchmark::DoNotOptimize(servo_tick(&safety, &c, &out));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SafetyServoTick);

void BM_HwLoopTick(benchmark::State& state) {
  FixedDevice dev;
  ChainOptions o;
  o.mode = ChainMode::kRun;
  o.controller = circle();
  runtime::SessionLoop loop(&dev, o, 1e-3, 1e30, nullptr);
  TickRecord s;
  double t = 0.0;
  long n = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(loop.tick(t += 1e-3));
    // the recorder's side, outside the timing would be fairer but it runs
    // on another thread in a session; drain now and then so the ring never
    // fills (a full ring would skip the copy)
    if (++n % 1024 == 0) {
      state.PauseTiming();
      while (loop.ring().pop(&s)) {
      }
      state.ResumeTiming();
    }
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_HwLoopTick);

}  // namespace
}  // namespace vmh

BENCHMARK_MAIN();
