// The device servo_jitter drives: the one seam to change when the MuJoCo
// emulator (sim/emulator.h) replaces the stand-in below.
#ifndef VMHAPTICS_BENCH_SERVO_JITTER_DEVICE_H_
#define VMHAPTICS_BENCH_SERVO_JITTER_DEVICE_H_

#include <memory>

#include "device/haptic_device.h"

namespace vmh {

// A device for period_s ticks, starting at q0_device_rad (device
// convention, t1..t6, rad).
std::unique_ptr<HapticDevice> make_jitter_device(double period_s,
                                                 const Joints& q0_device_rad);

}  // namespace vmh

#endif  // VMHAPTICS_BENCH_SERVO_JITTER_DEVICE_H_
