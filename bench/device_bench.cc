// What the servo loop's bookkeeping costs per tick: TickTimer::begin + end,
// and handing a DeviceState (about 560 bytes) through a Seqlock, written
// and read on one thread (no contention; the figure is the copy and the
// fences).
#include <benchmark/benchmark.h>

#include "device/device_state.h"
#include "device/seqlock.h"
#include "device/tick_timer.h"

namespace vmh {
namespace {

void BM_TickTimerBeginEnd(benchmark::State& state) {
  TickTimer timer(1e-3);
  double now_s = 0.0;
  for (auto _ : state) {
    now_s += 1.0003e-3;  // synthetic, so the clock read is not timed
    timer.begin(now_s);
    timer.end(now_s + 2e-4);
  }
  benchmark::DoNotOptimize(timer.stats().ticks);
}
BENCHMARK(BM_TickTimerBeginEnd);

void BM_MonotonicNow(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(monotonic_now_s());
}
BENCHMARK(BM_MonotonicNow);

DeviceState sample_state() {
  DeviceState s;
  s.present = kStateJoints | kStateButtons | kStateTransform;
  s.q_device_rad << 0.1, 0.2, 0.3, 0.4, 0.5, 0.6;
  s.transform_mm(0, 3) = 12.5;
  return s;
}

void BM_SeqlockWriteDeviceState(benchmark::State& state) {
  Seqlock<DeviceState> lock;
  DeviceState s = sample_state();
  for (auto _ : state) {
    s.timestamp_s += 1e-3;
    lock.write(s);
  }
  benchmark::DoNotOptimize(lock.writes());
  state.SetBytesProcessed(state.iterations() *
                          static_cast<long>(sizeof(DeviceState)));
}
BENCHMARK(BM_SeqlockWriteDeviceState);

void BM_SeqlockReadDeviceState(benchmark::State& state) {
  Seqlock<DeviceState> lock(sample_state());
  for (auto _ : state) {
    DeviceState s = lock.read();
    benchmark::DoNotOptimize(s);
  }
  state.SetBytesProcessed(state.iterations() *
                          static_cast<long>(sizeof(DeviceState)));
}
BENCHMARK(BM_SeqlockReadDeviceState);

}  // namespace
}  // namespace vmh

BENCHMARK_MAIN();
