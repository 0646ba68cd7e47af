// The servo loop of a session (runtime/session.h): each tick runs the servo
// chain (device/servo_chain.h) on the backend's device and hands one
// TickRecord to the recorder through a ring, and publishes it as the
// latest for any other thread (a viewer). Everything it touches is
// allocated before the first tick; tick() allocates nothing, takes no lock
// and throws nothing (tests/runtime/session_loop_test.cc).
//
// The plant's truth (runtime/backend_registry.h, TruthSource) describes a
// tick only once the plant has run it, so a record leaves the loop one
// tick late: tick k+1 adds the truth the plant published for period k to
// record k and pushes it. In lockstep that is exactly the simulated loop's
// record (sim/closed_loop.h); on the wall clock it is the plant's latest
// at tick k+1. flush() pushes the last one once the loop has stopped. The
// record's period_s is the tick's own length (to the next tick), as the
// simulated loop's is.
#ifndef VMHAPTICS_RUNTIME_SESSION_LOOP_H_
#define VMHAPTICS_RUNTIME_SESSION_LOOP_H_

#include <atomic>
#include <cstddef>

#include "device/seqlock.h"
#include "device/servo_chain.h"
#include "device/servo_loop.h"
#include "device/spsc_ring.h"
#include "device/tick_record.h"
#include "runtime/backend_registry.h"

namespace vmh::runtime {

// 4 s of ticks at 1 kHz: the recorder drains every 20 ms of loop time, so
// the ring only fills if the main thread stalls for seconds (the record is
// then dropped and counted, the loop never waits)
constexpr std::size_t kRingCapacity = 4096;

class SessionLoop final : public ServoLoop {
 public:
  // `device` and `truth` (may be null) are not owned. The loop ends at the
  // first tick at or past duration_s - period_s / 2 of loop time (so a
  // loop of duration D at period T runs round(D / T) ticks, as the
  // simulated loop does). Throws what ServoChain throws.
  SessionLoop(HapticDevice* device, const ChainOptions& chain,
              double period_s, double duration_s, const TruthSource* truth);

  bool tick(double now_s) noexcept override;
  // After the loop stopped (no tick running): pushes the pending record.
  void flush() noexcept;

  // every record, in order, for the one recorder thread
  SpscRing<TickRecord>& ring() { return ring_; }
  // the latest record, for any other thread: never blocks the loop
  TickRecord latest() const { return latest_.read(); }
  // ticks run
  long ticks() const { return ticks_.load(std::memory_order_acquire); }
  ServoChain& chain() { return chain_; }

 private:
  // now_s: the next tick's clock reading (< 0: there is none)
  void push_pending(double now_s) noexcept;

  ServoChain chain_;
  const TruthSource* truth_;
  double period_s_;
  double duration_s_;
  SpscRing<TickRecord> ring_;
  Seqlock<TickRecord> latest_;
  TickRecord rec_;
  bool pending_ = false;
  bool started_ = false;
  double t0_s_ = 0.0;
  std::atomic<long> ticks_{0};
};

}  // namespace vmh::runtime

#endif  // VMHAPTICS_RUNTIME_SESSION_LOOP_H_
