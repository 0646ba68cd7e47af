// Independent runs (cases, scenarios, map points) spread over threads. Each
// run builds its own model and data; each loop's hand is registered for its
// own mjData (sim/hand.h) and model loading is serialised (mujoco_util.h),
// so runs on different threads do not disturb each other.
#ifndef VMHAPTICS_OUTPUT_PARALLEL_H_
#define VMHAPTICS_OUTPUT_PARALLEL_H_

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace vmh::output {

// the number of hardware threads, at least 1
inline int core_count() {
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

// Calls body(i) once for each i in [0, n), on min(threads, n) threads (at
// least one; the calling thread is one of them), taking indices in order as
// threads come free. `body` must not throw: catch per item and record it.
template <typename Body>
void parallel_for(std::size_t n, int threads, Body body) {
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i = next++; i < n; i = next++) body(i);
  };
  const std::size_t n_threads =
      std::min<std::size_t>(n, static_cast<std::size_t>(std::max(1, threads)));
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < n_threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
}

}  // namespace vmh::output

#endif  // VMHAPTICS_OUTPUT_PARALLEL_H_
