// The device servo_jitter drives: the MuJoCo emulator (sim/emulator.h,
// servo_jitter_emulator.cc) when the testbed is built, else a stand-in
// rotor model (servo_jitter_device.cc).
#ifndef VMHAPTICS_BENCH_SERVO_JITTER_DEVICE_H_
#define VMHAPTICS_BENCH_SERVO_JITTER_DEVICE_H_

#include <memory>
#include <string>

#include "device/haptic_device.h"

namespace vmh {

// A device for period_s ticks, starting at q0_device_rad (device
// convention, t1..t6, rad).
std::unique_ptr<HapticDevice> make_jitter_device(double period_s,
                                                 const Joints& q0_device_rad);
// what make_jitter_device makes, for the report
std::string jitter_device_name();

}  // namespace vmh

#endif  // VMHAPTICS_BENCH_SERVO_JITTER_DEVICE_H_
