// The lockstep clock: a servo loop and a simulated plant advanced in turn
// on the calling thread, one servo period of the plant per tick, with no
// thread racing another and no wall clock read for the loop's time. The
// same settings give the same ticks, to the last bit, however busy the
// machine, and as fast as it allows.
//
//   tick k at now_s = k T:  loop->tick(k T)      reads the state the plant
//                                                published at k T, writes
//                                                a command
//                           plant->advance_period()  steps [k T, (k+1) T]
//                                                with that command held
//
// which is the simulated closed loop's order (sim/closed_loop.h): read at
// the start of a period, the torque held over it.
//
// The wall-clock alternative is ServoThread (device/servo_thread.h); a
// backend picks one by ServoOptions::lockstep (device/device_backend.h).
#ifndef VMHAPTICS_DEVICE_LOCKSTEP_H_
#define VMHAPTICS_DEVICE_LOCKSTEP_H_

#include <cstdint>

#include "device/servo_loop.h"
#include "device/tick_timer.h"

namespace vmh {

// A plant that can be advanced by one servo period on demand.
class LockstepPlant {
 public:
  virtual ~LockstepPlant() = default;
  // one servo period of the plant with the last command held. No
  // allocation, no exception, no sleep.
  virtual void advance_period() noexcept = 0;
};

class LockstepDriver {
 public:
  // throws std::invalid_argument for a period that is not finite and > 0
  explicit LockstepDriver(double period_s);

  // Ready to run `loop` against `plant` from t = 0 (neither owned; both
  // must outlive the driving). Resets the timing.
  void start(ServoLoop* loop, LockstepPlant* plant) noexcept;

  // Runs the ticks of the next dt_s of loop time (round(dt_s / T), at
  // least one), each followed by a period of the plant, until the loop
  // returns false (the driver then stops; no period follows that tick) or
  // stop(). On the calling thread.
  void pass(double dt_s) noexcept;

  void stop() noexcept { running_ = false; }
  bool running() const noexcept { return running_; }
  long ticks() const noexcept { return static_cast<long>(k_); }
  // the loop time of the next tick, s
  double now_s() const noexcept { return static_cast<double>(k_) * period_s_; }

  // Periods are the nominal one by construction (zero jitter, no
  // overruns); the work times are each tick's wall-clock time, loop and
  // plant together.
  TickStats timing() const { return timer_.stats(); }
  double period_s() const noexcept { return period_s_; }

 private:
  double period_s_;
  TickTimer timer_;
  ServoLoop* loop_ = nullptr;
  LockstepPlant* plant_ = nullptr;
  std::int64_t k_ = 0;
  bool running_ = false;
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_LOCKSTEP_H_
