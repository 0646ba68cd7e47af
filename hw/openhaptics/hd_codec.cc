#include "hw/openhaptics/hd_codec.h"

#include <cstdio>

#include "device/device_state.h"
#include "device/motor_force_map.h"

namespace vmh::hw::hd {

Vec3 torque_Nm_to_mNm(const Vec3& tau_Nm) noexcept {
  return tau_Nm * kMilliPerUnit;
}

Vec3 torque_mNm_to_Nm(const Vec3& tau_mNm) noexcept {
  return tau_mNm / kMilliPerUnit;
}

Eigen::Matrix4d transform_from_hd(const double* column_major16_mm) noexcept {
  // Eigen's default storage is column-major too: a straight copy
  return Eigen::Map<const Eigen::Matrix4d>(column_major16_mm);
}

std::uint32_t buttons_from_hd(HDint buttons) noexcept {
  const auto bits = static_cast<std::uint32_t>(buttons);
  return bits & (kButton1 | kButton2);
}

bool docked_from_hd(HDboolean inkwell) noexcept { return inkwell == 0; }

const HDerror kHdKnownErrors[kHdKnownErrorCount] = {
    kInvalidEnum,       kInvalidValue,          kInvalidOperation,
    kInvalidInputType,  kBadHandle,             kWarmMotors,
    kExceededMaxForce,  kExceededMaxForceImpulse, kExceededMaxVelocity,
    kForceError,        kDeviceFault,           kDeviceAlreadyInitiated,
    kCommError,         kCommConfigError,       kTimerError,
    kIllegalBegin,      kIllegalEnd,            kFrameError,
    kInvalidPriority,   kSchedulerFull,         kInvalidLicense,
};

int hd_error_index(HDerror code) noexcept {
  for (int i = 0; i < kHdKnownErrorCount; ++i) {
    if (kHdKnownErrors[i] == code) return i;
  }
  return kHdKnownErrorCount;
}

HdErrorClass classify_hd_error(HDerror code) noexcept {
  using E = DeviceError;
  switch (code) {
    case kSuccess: return {E::kOk, false, "ok"};
    // usage errors: the backend asked for something this device lacks; the
    // device itself keeps going
    case kInvalidEnum: return {E::kOk, false, "invalid_enum"};
    case kInvalidValue: return {E::kOk, false, "invalid_value"};
    case kInvalidOperation: return {E::kOk, false, "invalid_operation"};
    case kInvalidInputType: return {E::kOk, false, "invalid_input_type"};
    // the handle no longer names a device
    case kBadHandle: return {E::kNotConnected, true, "bad_handle"};
    // the device limits or warns and keeps reporting its state; the safety
    // layer (device/safety.h) has its own thermal and velocity limits
    case kWarmMotors: return {E::kOk, false, "warm_motors"};
    case kExceededMaxForce: return {E::kOk, false, "exceeded_max_force"};
    case kExceededMaxForceImpulse:
      return {E::kOk, false, "exceeded_max_force_impulse"};
    case kExceededMaxVelocity: return {E::kOk, false, "exceeded_max_velocity"};
    case kForceError: return {E::kOk, false, "force_error"};
    // the device stops answering
    case kDeviceFault: return {E::kIo, true, "device_fault"};
    case kDeviceAlreadyInitiated:
      return {E::kOk, false, "device_already_initiated"};
    case kCommError: return {E::kIo, true, "comm_error"};
    case kCommConfigError: return {E::kNotConnected, true, "comm_config_error"};
    case kTimerError: return {E::kTimeout, true, "timer_error"};
    // frame and scheduler misuse: logged, the device keeps going
    case kIllegalBegin: return {E::kOk, false, "illegal_begin"};
    case kIllegalEnd: return {E::kOk, false, "illegal_end"};
    case kFrameError: return {E::kOk, false, "frame_error"};
    case kInvalidPriority: return {E::kOk, false, "invalid_priority"};
    case kSchedulerFull: return {E::kOk, false, "scheduler_full"};
    case kInvalidLicense: return {E::kNotConnected, true, "invalid_license"};
    default:
      // a code §9.1 does not list: stop rather than guess it is harmless
      return {E::kIo, true, nullptr};
  }
}

std::string hd_error_name(HDerror code) {
  const HdErrorClass c = classify_hd_error(code);
  if (c.name != nullptr) return c.name;
  char buf[32];
  std::snprintf(buf, sizeof buf, "hd_error_0x%x", code);
  return buf;
}

CalibrationState calibration_from_hd(HDenum result) noexcept {
  switch (result) {
    case kCalibrationOk: return CalibrationState::kOk;
    case kCalibrationNeedsUpdate: return CalibrationState::kNeedsUpdate;
    case kCalibrationNeedsManualInput:
      return CalibrationState::kNeedsManualInput;
    default: return CalibrationState::kUnknown;
  }
}

HDint calibration_style_to_use(HDint supported_styles) noexcept {
  if ((supported_styles & kCalibrationAuto) != 0) return kCalibrationAuto;
  if ((supported_styles & kCalibrationInkwell) != 0) return kCalibrationInkwell;
  if ((supported_styles & kCalibrationEncoderReset) != 0) {
    return kCalibrationEncoderReset;
  }
  return 0;
}

Vec3 force_for_motor_torques_N(const OmniParams& omni,
                               const Joints& q_device_rad,
                               const Vec3& tau_motor_Nm,
                               double damping_m) noexcept {
  return motor_torque_to_force_map(omni, q_device_rad, damping_m) *
         tau_motor_Nm;
}

}  // namespace vmh::hw::hd
