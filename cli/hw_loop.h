// The servo loop of an hw session (cli/hw_session.h): each tick reads the
// device through the safety layer and the reading guard, runs the
// controller (run), a torque pulse (motor-test) or nothing (record, zero
// torque), pushes one HwSample into a ring for the recorder and publishes
// it as the latest state for other threads. Everything
// it touches is allocated before the first tick; tick() allocates nothing
// and takes no lock (tests/cli/hw_loop_test.cc).
#ifndef VMHAPTICS_CLI_HW_LOOP_H_
#define VMHAPTICS_CLI_HW_LOOP_H_

#include <atomic>
#include <memory>

#include "cli/hw_session.h"
#include "device/seqlock.h"
#include "device/servo_loop.h"
#include "device/spsc_ring.h"

namespace vmh::cli {

// 4 s of ticks at 1 kHz: the recorder drains every 20 ms, so the ring only
// fills if the main thread stalls for seconds
constexpr std::size_t kRingCapacity = 4096;

// The servo loop of a session. Everything it touches is allocated before
// the first tick.
class HwLoop final : public ServoLoop {
 public:
  HwLoop(HapticDevice* raw, const SessionOptions& o, const OmniParams& omni,
         sim::Emulator* emulator)
      : o_(o),
        guard_(raw, o.guard),
        safety_(&guard_, o.safety, omni),
        ring_(kRingCapacity),
        emulator_(emulator) {
    if (o.controller) controller_ = std::make_unique<Controller>(*o.controller);
    if (o.reference) reference_ = std::make_unique<Controller>(*o.reference);
  }

  // the device chain: servo_tick -> SafetyLayer -> ReadingGuard -> raw
  bool tick(double now_s) noexcept override;

  // every tick, in order, for the one recorder thread
  SpscRing<HwSample>& ring() { return ring_; }
  // the latest tick, for any other thread (a viewer, a monitor): never
  // blocks the loop
  HwSample latest() const { return latest_.read(); }
  SafetyLayer& safety() { return safety_; }
  long ticks() const { return ticks_.load(std::memory_order_acquire); }

 private:
  const SessionOptions& o_;
  ReadingGuard guard_;
  SafetyLayer safety_;
  std::unique_ptr<Controller> controller_;
  std::unique_ptr<Controller> reference_;
  ControlOutput ref_out_;
  SpscRing<HwSample> ring_;
  Seqlock<HwSample> latest_;
  sim::Emulator* emulator_;
  HwSample sample_;
  bool started_ = false;
  double t0_s_ = 0.0;
  double last_s_ = 0.0;
  std::atomic<long> ticks_{0};
};

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_HW_LOOP_H_
