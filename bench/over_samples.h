// The loop every benchmark here uses: one call per iteration, cycling
// through a fixed sample set built outside the timed region.
#ifndef VMHAPTICS_BENCH_OVER_SAMPLES_H_
#define VMHAPTICS_BENCH_OVER_SAMPLES_H_

#include <benchmark/benchmark.h>

#include <cstddef>

namespace vmh::bench {

// `set` must have a power-of-two size (the index wraps with a mask)
template <typename Set, typename F>
void over_samples(benchmark::State& state, const Set& set, F f) {
  const std::size_t mask = set.size() - 1;
  std::size_t i = 0;
  for (auto _ : state) {
    f(set[i]);
    i = (i + 1) & mask;
  }
  state.SetItemsProcessed(state.iterations());
}

}  // namespace vmh::bench

#endif  // VMHAPTICS_BENCH_OVER_SAMPLES_H_
