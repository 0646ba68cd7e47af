// Pure conversions between the HD API's values and the device layer's:
// units (mN m, mm), the transform's layout, the switches, the error codes and
// the calibration results (docs/sources.md §9.1), and the motor-torque to
// force map of the backend's force mode. No I/O; the real-time ones are
// noexcept and allocate nothing.
#ifndef VMHAPTICS_HW_OPENHAPTICS_HD_CODEC_H_
#define VMHAPTICS_HW_OPENHAPTICS_HD_CODEC_H_

#include <Eigen/Core>

#include <cstdint>
#include <string>

#include "controller/omni_params.h"
#include "controller/types.h"
#include "device/device_backend.h"
#include "device/haptic_device.h"
#include "hw/openhaptics/hd_api.h"

namespace vmh::hw::hd {

inline constexpr double kMilliPerUnit = 1000.0;

// motor torques: N m (device layer) <-> mN m (HD_CURRENT_JOINT_TORQUE)
Vec3 torque_Nm_to_mNm(const Vec3& tau_Nm) noexcept;
Vec3 torque_mNm_to_Nm(const Vec3& tau_mNm) noexcept;

// HD_CURRENT_TRANSFORM: 16 doubles, column-major, mm, device frame
Eigen::Matrix4d transform_from_hd(const double* column_major16_mm) noexcept;

// HD_CURRENT_BUTTONS -> kButton1 | kButton2 (device_state.h); other bits
// are dropped
std::uint32_t buttons_from_hd(HDint buttons) noexcept;

// HD_CURRENT_INKWELL_SWITCH: 0 while the stylus is in the inkwell
bool docked_from_hd(HDboolean inkwell) noexcept;

// What an HD error means for the servo loop.
struct HdErrorClass {
  // the device error a read reports once a fatal error was seen; kOk for a
  // warning
  DeviceError error = DeviceError::kOk;
  // true: the device stops answering (communication, fault, licence);
  // false: the device keeps going (warm motors, a limit exceeded, a usage
  // error the backend logs)
  bool fatal = false;
  // "warm_motors", ... ; nullptr for a code not in §9.1
  const char* name = nullptr;
};

HdErrorClass classify_hd_error(HDerror code) noexcept;

// The status name: classify_hd_error's name, or "hd_error_0x..." (lower-case
// hex) for an unknown code; "ok" for HD_SUCCESS.
std::string hd_error_name(HDerror code);

// Every code §9.1 names, for tables indexed by code (kHdKnownErrors[i]);
// hd_error_index gives i, or kHdKnownErrorCount for an unknown code.
inline constexpr int kHdKnownErrorCount = 21;
extern const HDerror kHdKnownErrors[kHdKnownErrorCount];
int hd_error_index(HDerror code) noexcept;

// hdCheckCalibration's result; anything else is kUnknown
CalibrationState calibration_from_hd(HDenum result) noexcept;

// The style hdUpdateCalibration is asked for, from HD_CALIBRATION_STYLE's
// bit mask: the one needing no help from the user first (auto, then the
// inkwell, then the encoder-reset pose); 0 when the mask names none.
HDint calibration_style_to_use(HDint supported_styles) noexcept;

// Force mode: the device-frame force F (N) at the wrist centre that the
// device's own Jacobian maps to the motor torques tau_motor_Nm at the joint
// angles q_device_rad (device convention), by damped least squares
// (device/motor_force_map.h) with damping_m.
inline constexpr double kForceModeDampingM = 1e-5;
Vec3 force_for_motor_torques_N(const OmniParams& omni,
                               const Joints& q_device_rad,
                               const Vec3& tau_motor_Nm,
                               double damping_m = kForceModeDampingM) noexcept;

}  // namespace vmh::hw::hd

#endif  // VMHAPTICS_HW_OPENHAPTICS_HD_CODEC_H_
