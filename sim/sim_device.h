// The MuJoCo Omni behind the device interface (device/haptic_device.h),
// so that the servo loop cannot tell it from the real device.
//
// read_joints: the model's DH joint angles (joints "q1".."q6"), converted to
// the device convention and passed through the sensor model.
// write_motor_torques: clamped to the motors' ctrlrange (actuators "m1".."m3",
// the OpenHaptics clamps), delayed by `delay_ticks` writes, and placed in
// d->ctrl, where they stay until the next write (zero-order hold).
#ifndef VMHAPTICS_SIM_SIM_DEVICE_H_
#define VMHAPTICS_SIM_SIM_DEVICE_H_

#include <mujoco/mujoco.h>

#include <array>
#include <string>

#include "device/haptic_device.h"
#include "controller/omni_params.h"
#include "sim/cases/case_params.h"  // kMaxDelayTicks
#include "sim/sensor_model.h"

namespace vmh::sim {

// the longest delay line: 64 servo ticks is 64 ms at 1 kHz, far beyond any
// USB or FireWire device (case_config checks delay_ticks against it)

class SimDevice final : public HapticDevice {
 public:
  // Throws SimError naming a missing joint or actuator of `source`.
  SimDevice(const mjModel* m, mjData* d, const OmniParams& omni,
            bool quantize, int delay_ticks, const std::string& source);

  DeviceError read_joints(Joints* q_device_rad) noexcept override;
  DeviceError write_motor_torques(const Vec3& tau_motor_Nm) noexcept override;

  // empties the delay line and zeroes the motors
  void reset() noexcept;

  // the true joint angles, DH convention (rad)
  Joints true_q_dh() const noexcept;
  // the torque the motors hold now (after delay and clamping), N m
  Vec3 motor_torque_Nm() const noexcept;
  // whether the last write was clamped to the motor limits
  bool clamped() const noexcept { return clamped_; }
  const SensorModel& sensor() const { return sensor_; }

 private:
  mjData* d_;
  SensorModel sensor_;
  int delay_ticks_;
  std::array<int, 6> qpos_adr_{};
  std::array<int, 3> actuator_{};
  std::array<double, 3> lo_{}, hi_{};
  // ring buffer of commands waiting to reach the motors
  std::array<Vec3, kMaxDelayTicks + 1> pending_;
  int head_ = 0;
  bool clamped_ = false;
};

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_SIM_DEVICE_H_
