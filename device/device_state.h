// Everything a device reports in one servo tick, read once per tick with no
// allocation: the joint angles every backend has, and what only some have
// (switches, a clock, the device's own kinematics, raw sensor values).
// `present` says which fields the backend filled; the rest keep their
// defaults and must not be used.
//
// Frames and units: the device's own convention (OpenHaptics): joint angles
// t1..t6 in rad with t3 the absolute forearm angle; positions in mm and
// velocities in mm/s in the device frame (controller/device_frame.h); the
// stylus transform column-major as OpenHaptics returns it (HD_CURRENT_
// TRANSFORM, docs/sources.md §9.1).
#ifndef VMHAPTICS_DEVICE_DEVICE_STATE_H_
#define VMHAPTICS_DEVICE_DEVICE_STATE_H_

#include <Eigen/Core>

#include <array>
#include <cstdint>

#include "controller/types.h"

namespace vmh {

// Which optional fields of DeviceState a backend filled.
enum DeviceStateField : std::uint32_t {
  kStateJoints = 1u << 0,     // q_device_rad (every successful read)
  kStateButtons = 1u << 1,    // buttons
  kStateInkwell = 1u << 2,    // docked
  kStateTimestamp = 1u << 3,  // timestamp_s
  kStateTransform = 1u << 4,  // transform_mm
  kStateVelocity = 1u << 5,   // velocity_mm_s
  kStateJacobian = 1u << 6,   // jacobian
  kStateEncoders = 1u << 7,   // encoder_counts
  kStatePots = 1u << 8,       // gimbal_pots
  kStateSafetySwitch = 1u << 9,  // safety_switch
};

// Button bits (HD_CURRENT_BUTTONS): bit 0 the first (front, dark grey)
// button, bit 1 the second.
inline constexpr std::uint32_t kButton1 = 1u << 0;
inline constexpr std::uint32_t kButton2 = 1u << 1;

struct DeviceState {
  std::uint32_t present = 0;  // DeviceStateField bits

  // t1..t6, rad, device convention
  Joints q_device_rad = Joints::Zero();
  // pressed buttons, one bit each (kButton1, kButton2)
  std::uint32_t buttons = 0;
  // the stylus is in the inkwell (the switch is closed)
  bool docked = false;
  // the device set its encoder offsets again with this reading (a FireWire
  // Omni re-homed in its inkwell): a step in t1..t3 is that, not a slip
  bool rehomed = false;
  // a safety switch where the device has one (not on the Omni)
  bool safety_switch = false;
  // when the reading was taken, s, on a monotonic clock (the backend's; the
  // emulator's is CLOCK_MONOTONIC)
  double timestamp_s = 0.0;

  // the device's own forward kinematics and Jacobian, where it computes them
  // (OpenHaptics): stylus transform, mm, device frame, as a 4x4 matrix
  Eigen::Matrix4d transform_mm = Eigen::Matrix4d::Identity();
  // wrist-centre velocity, mm/s, device frame
  Vec3 velocity_mm_s = Vec3::Zero();
  // HD_CURRENT_JACOBIAN as read (row/column order and units as the device
  // gives them; docs/hardware.md says what is known of them)
  Eigen::Matrix<double, 6, 6> jacobian = Eigen::Matrix<double, 6, 6>::Zero();

  // raw sensor values where the backend sees them: encoder counts of the
  // three motors (t1..t3) and the gimbal potentiometers (t4..t6), in the
  // device's own units (counts, ADC codes)
  std::array<std::int32_t, 3> encoder_counts{};
  std::array<std::int32_t, 3> gimbal_pots{};

  bool has(DeviceStateField f) const { return (present & f) != 0; }
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_DEVICE_STATE_H_
