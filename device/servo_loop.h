// What a servo loop runs each period, apart from what drives it. Two things
// drive it: the project's own real-time thread (device/servo_thread.h), for
// the emulator and the native drivers, and a vendor's scheduler (the
// OpenHaptics backend runs it inside hdScheduleAsynchronous). Both call
// ServoLoop::tick() once per period and time it with TickTimer
// (device/tick_timer.h).
#ifndef VMHAPTICS_DEVICE_SERVO_LOOP_H_
#define VMHAPTICS_DEVICE_SERVO_LOOP_H_

namespace vmh {

class ServoLoop {
 public:
  virtual ~ServoLoop() = default;
  // One servo tick, at now_s (CLOCK_MONOTONIC, s) on the driving thread.
  // Must not block, allocate or throw. Returns false to end the loop (the
  // driver then stops calling it; it does not write anything itself).
  virtual bool tick(double now_s) noexcept = 0;
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_SERVO_LOOP_H_
