// The open HD API's state calls (include/HD/hdDevice.h): hdGet* of every
// parameter, as numbers or strings, from the tick's frame on the servo
// thread or the last published one off it; hdSet* of the commands and the
// settings. docs/libhd.md is the account of each parameter here.
#define VMHAPTICS_HD_BUILDING 1
#include <HD/hd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "hd/hd_api_detail.h"
#include "hd/hd_device.h"
#include "hw/omni_calibration.h"

using namespace vmh::hd;          // NOLINT: this file implements the C API
using namespace vmh::hd::detail;  // NOLINT: on the library's shared state

// ---- state ----

namespace {

// The frames a state call reads: the tick's own on the servo thread, else
// the last published ones.
void frames_of(HdDevice* d, HdFrame* cur, HdFrame* last) {
  if (on_servo_thread()) {
    *cur = d->current();
    *last = d->last();
  } else {
    d->published(cur, last);
  }
}

// A LAST_ parameter reads the previous frame under its CURRENT_ name: *q is
// p's CURRENT_ name (p itself if it has none); true when p is a LAST_ one.
bool current_name_of(HDenum p, HDenum* q) {
  bool is_last = true;
  *q = p;
  switch (p) {
    case HD_LAST_FORCE: *q = HD_CURRENT_FORCE; break;
    case HD_LAST_TORQUE: *q = HD_CURRENT_TORQUE; break;
    case HD_LAST_JOINT_TORQUE: *q = HD_CURRENT_JOINT_TORQUE; break;
    case HD_LAST_GIMBAL_TORQUE: *q = HD_CURRENT_GIMBAL_TORQUE; break;
    case HD_LAST_MOTOR_DAC_VALUES: *q = HD_CURRENT_MOTOR_DAC_VALUES; break;
    default:
      if (p >= 0x2200 && p < 0x2400) {
        *q = p - 0x200;
      } else {
        is_last = false;
      }
  }
  return is_last;
}

// On the servo thread a command reads back what this frame set so far: the
// command q (a CURRENT_ name) copied from the device's command into *cur.
void read_back_command(HdDevice* d, HDenum q, HdFrame* cur) {
  const HdCommand& cmd = d->command();
  switch (q) {
    case HD_CURRENT_FORCE: std::copy(cmd.force_N, cmd.force_N + 3, cur->force_N); break;
    case HD_CURRENT_JOINT_TORQUE:
      std::copy(cmd.joint_torque_mNm, cmd.joint_torque_mNm + 3, cur->joint_torque_mNm);
      break;
    case HD_CURRENT_TORQUE:
    case HD_CURRENT_GIMBAL_TORQUE:
      std::copy(cmd.gimbal_torque_mNm, cmd.gimbal_torque_mNm + 3, cur->gimbal_torque_mNm);
      break;
    case HD_CURRENT_MOTOR_DAC_VALUES: std::copy(cmd.dac, cmd.dac + 3, cur->dac); break;
    default: break;
  }
}

// The table of the parameters readable as numbers: q's values (q a
// CURRENT_ name) from frame f, or from cur where only the current frame
// has them (the update rate), written to out. Returns how many, 0 for a
// parameter that is not readable as a number.
int frame_numbers(HdDevice* d, HDenum q, const HdFrame& f, const HdFrame& cur,
                  double* out) {
  const auto copy = [out](const double* v, int n) {
    std::copy(v, v + n, out);
    return n;
  };
  const HdSettings& s = d->settings();
  const vmh::DeviceIdentity& id = d->identity();
  switch (q) {
    case HD_CURRENT_BUTTONS: out[0] = f.buttons; return 1;
    case HD_CURRENT_SAFETY_SWITCH: out[0] = f.safety_switch; return 1;
    case HD_CURRENT_INKWELL_SWITCH: out[0] = f.inkwell; return 1;
    case HD_CURRENT_ENCODER_VALUES:
      for (int i = 0; i < 6; ++i) out[i] = static_cast<double>(f.encoders[i]);
      return 6;
    case HD_CURRENT_POSITION: return copy(f.position_mm, 3);
    case HD_CURRENT_VELOCITY: return copy(f.velocity_mm_s, 3);
    case HD_CURRENT_TRANSFORM: return copy(f.transform, 16);
    case HD_CURRENT_ANGULAR_VELOCITY: return copy(f.angular_velocity_rad_s, 3);
    case HD_CURRENT_JACOBIAN: return copy(f.jacobian, 36);
    case HD_CURRENT_JOINT_ANGLES: return copy(f.joint_angles_rad, 3);
    case HD_CURRENT_GIMBAL_ANGLES: return copy(f.gimbal_angles_rad, 3);
    // commands (0x27xx) and, shifted above, their LAST (0x28xx)
    case HD_CURRENT_FORCE: return copy(f.force_N, 3);
    case HD_CURRENT_TORQUE:
    case HD_CURRENT_GIMBAL_TORQUE: return copy(f.gimbal_torque_mNm, 3);
    case HD_CURRENT_JOINT_TORQUE: return copy(f.joint_torque_mNm, 3);
    case HD_CURRENT_MOTOR_DAC_VALUES:
      for (int i = 0; i < 3; ++i) out[i] = static_cast<double>(f.dac[i]);
      return 3;
    case HD_JOINT_ANGLE_REFERENCES: {
      // the pose the encoders are referenced to: the inkwell (device
      // convention, rad; hw/omni_calibration.h)
      const double* r = vmh::hw::kInkwellDevice_rad;
      for (int i = 0; i < 6; ++i) out[i] = r[i];
      return 6;
    }
    case HD_MOTOR_TEMPERATURE: return copy(f.motor_temperature, 6);
    case HD_INSTANTANEOUS_UPDATE_RATE: out[0] = std::round(cur.rate_hz); return 1;
    case HD_UPDATE_RATE: out[0] = ctx().rate_hz; return 1;
    case HD_INPUT_DOF: out[0] = id.input_dof > 0 ? id.input_dof : 6; return 1;
    case HD_OUTPUT_DOF: out[0] = id.output_dof > 0 ? id.output_dof : 3; return 1;
    case HD_CALIBRATION_STYLE:
      out[0] = d->opened().raw != nullptr ? HD_CALIBRATION_INKWELL
                                          : HD_CALIBRATION_AUTO;
      return 1;
    // the Omni's figures (docs/libhd.md gives each one's source)
    case HD_MAX_WORKSPACE_DIMENSIONS: return copy(d->max_workspace_mm(), 6);
    case HD_USABLE_WORKSPACE_DIMENSIONS: {
      // the data sheet's 160 x 120 x 70 mm, centred on the device origin
      const double w[6] = {-80, -60, -35, 80, 60, 35};
      return copy(w, 6);
    }
    // an estimate: the lowest the wrist centre reaches
    case HD_TABLETOP_OFFSET: out[0] = d->max_workspace_mm()[1]; return 1;
    case HD_NOMINAL_MAX_STIFFNESS: out[0] = 0.7; return 1;    // N/mm (CHAI3D)
    case HD_NOMINAL_MAX_DAMPING: out[0] = 0.005; return 1;    // N s/mm (CHAI3D)
    case HD_NOMINAL_MAX_FORCE: out[0] = 3.3; return 1;        // N
    case HD_NOMINAL_MAX_CONTINUOUS_FORCE: out[0] = 0.88; return 1;  // N
    case HD_NOMINAL_MAX_TORQUE_STIFFNESS:
    case HD_NOMINAL_MAX_TORQUE_DAMPING:
    case HD_NOMINAL_MAX_TORQUE_FORCE:
    case HD_NOMINAL_MAX_TORQUE_CONTINUOUS_FORCE:
      out[0] = 0.0;  // no gimbal motors on the Omni
      return 1;
    case HD_SOFTWARE_VELOCITY_LIMIT: out[0] = s.velocity_limit_mm_s.load(); return 1;
    case HD_SOFTWARE_FORCE_IMPULSE_LIMIT: out[0] = s.impulse_limit_N.load(); return 1;
    case HD_FORCE_RAMPING_RATE: out[0] = s.ramp_rate_N_s.load(); return 1;
    case HD_USER_STATUS_LIGHT: out[0] = s.status_light.load(); return 1;
    default: return 0;
  }
}

// Every value a parameter has, as doubles (n of them), for the typed getters.
// Returns n, 0 for a parameter that is not readable as a number.
int read_numbers(HdDevice* d, HDenum p, double* out) {
  HdFrame cur, last;
  frames_of(d, &cur, &last);
  HDenum q = p;
  const bool is_last = current_name_of(p, &q);
  if (!is_last && on_servo_thread()) read_back_command(d, q, &cur);
  return frame_numbers(d, q, is_last ? last : cur, cur, out);
}

template <typename T, typename Convert>
void get_numbers(HDenum p, T* params, Convert convert) {
  if (params == nullptr) {
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return;
  }
  HdDevice* d = current_device();
  if (d == nullptr) return;
  double v[36];
  const int n = read_numbers(d, p, v);
  if (n == 0) {
    const bool string_param = p >= HD_VERSION && p <= HD_DEVICE_FIRMWARE_VERSION;
    push_error(string_param ? HD_INVALID_INPUT_TYPE : HD_INVALID_ENUM,
               kInternalUnknownParameter, current_handle());
    return;
  }
  for (int i = 0; i < n; ++i) params[i] = convert(v[i]);
}

template <typename T>
void get_numbers(HDenum p, T* params) {
  get_numbers(p, params, [](double v) { return static_cast<T>(v); });
}

}  // namespace

HDAPI void HDAPIENTRY hdGetBooleanv(HDenum p, HDboolean* params) {
  // any non-zero value is HD_TRUE (a button mask read as a boolean)
  get_numbers(p, params, [](double v) -> HDboolean {
    return v != 0.0 ? HD_TRUE : HD_FALSE;
  });
}
HDAPI void HDAPIENTRY hdGetIntegerv(HDenum p, HDint* params) { get_numbers(p, params); }
HDAPI void HDAPIENTRY hdGetFloatv(HDenum p, HDfloat* params) { get_numbers(p, params); }
HDAPI void HDAPIENTRY hdGetDoublev(HDenum p, HDdouble* params) { get_numbers(p, params); }
HDAPI void HDAPIENTRY hdGetLongv(HDenum p, HDlong* params) { get_numbers(p, params); }

HDAPI HDstring HDAPIENTRY hdGetString(HDenum p) {
  HdDevice* d = current_device();
  if (d == nullptr) return nullptr;
  const vmh::DeviceIdentity& id = d->identity();
  // one buffer per device and string, so that strings fetched one after
  // the other are all still valid (a program prints several in one
  // printf); rewritten only here, with the same text each time
  static thread_local std::string kept[kMaxDevices][HD_DEVICE_FIRMWARE_VERSION -
                                                    HD_VERSION + 1];
  const bool is_string = p >= HD_VERSION && p <= HD_DEVICE_FIRMWARE_VERSION;
  std::string& s = kept[current_handle()][is_string ? p - HD_VERSION : 0];
  switch (p) {
    case HD_VERSION: return "3.0.0 (vmhaptics open HD API)";
    case HD_DEVICE_MODEL_TYPE:
      s = id.model.empty() ? "PHANTOM Omni" : id.model;
      return s.c_str();
    case HD_DEVICE_DRIVER_VERSION:
      s = "vmhaptics " + (id.backend.empty() ? std::string("device") : id.backend) +
          (id.driver_version.empty() ? "" : " " + id.driver_version);
      return s.c_str();
    case HD_DEVICE_VENDOR:
      s = id.vendor.empty() ? "vmhaptics" : id.vendor;
      return s.c_str();
    case HD_DEVICE_SERIAL_NUMBER:
      s = id.serial;
      return s.c_str();
    case HD_DEVICE_FIRMWARE_VERSION:
      s = id.firmware_version;
      return s.c_str();
    default: {
      double v[36];
      push_error(read_numbers(d, p, v) > 0 ? HD_INVALID_INPUT_TYPE : HD_INVALID_ENUM,
                 kInternalUnknownParameter, current_handle());
      return nullptr;
    }
  }
}

namespace {

template <typename T>
void set_numbers(HDenum p, const T* params) {
  if (params == nullptr) {
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return;
  }
  HdDevice* d = current_device();
  if (d == nullptr) return;
  HdSettings& s = d->settings();
  const auto positive = [&](double v) {
    if (std::isfinite(v) && v > 0.0) return true;
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return false;
  };
  switch (p) {
    case HD_SOFTWARE_VELOCITY_LIMIT:
      if (positive(double(params[0]))) s.velocity_limit_mm_s.store(double(params[0]));
      return;
    case HD_SOFTWARE_FORCE_IMPULSE_LIMIT:
      if (positive(double(params[0]))) s.impulse_limit_N.store(double(params[0]));
      return;
    case HD_FORCE_RAMPING_RATE:
      if (positive(double(params[0]))) s.ramp_rate_N_s.store(double(params[0]));
      return;
    case HD_USER_STATUS_LIGHT:
      s.status_light.store(static_cast<int>(params[0]) & LED_MASK);
      return;
    default:
      break;
  }
  const bool command = p == HD_CURRENT_FORCE || p == HD_CURRENT_TORQUE ||
                       p == HD_CURRENT_JOINT_TORQUE ||
                       p == HD_CURRENT_GIMBAL_TORQUE ||
                       p == HD_CURRENT_MOTOR_DAC_VALUES;
  if (!command) {
    double v[36];
    const bool readable = read_numbers(d, p, v) > 0;
    push_error(readable ? HD_INVALID_OPERATION : HD_INVALID_ENUM,
               readable ? kInternalReadOnly : kInternalUnknownParameter,
               current_handle());
    return;
  }
  if (!on_servo_thread()) {
    // commands belong to a servo frame: a scheduler callback
    push_error(HD_INVALID_OPERATION, kInternalNotInScheduler, current_handle());
    return;
  }
  HdCommand& c = d->command();
  for (int i = 0; i < 3; ++i) {
    const double v = static_cast<double>(params[i]);
    if (!std::isfinite(v)) {
      push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
      return;
    }
  }
  for (int i = 0; i < 3; ++i) {
    const double v = static_cast<double>(params[i]);
    switch (p) {
      case HD_CURRENT_FORCE: c.force_N[i] = v; break;
      case HD_CURRENT_JOINT_TORQUE: c.joint_torque_mNm[i] = v; break;
      case HD_CURRENT_TORQUE:
      case HD_CURRENT_GIMBAL_TORQUE: c.gimbal_torque_mNm[i] = v; break;
      case HD_CURRENT_MOTOR_DAC_VALUES:
        c.dac[i] = std::lround(std::clamp(v, -2047.0, 2047.0));
        c.dac_set = true;
        break;
      default: break;
    }
  }
}

}  // namespace

HDAPI void HDAPIENTRY hdSetBooleanv(HDenum p, const HDboolean* params) {
  set_numbers(p, params);
}
HDAPI void HDAPIENTRY hdSetIntegerv(HDenum p, const HDint* params) { set_numbers(p, params); }
HDAPI void HDAPIENTRY hdSetFloatv(HDenum p, const HDfloat* params) { set_numbers(p, params); }
HDAPI void HDAPIENTRY hdSetDoublev(HDenum p, const HDdouble* params) { set_numbers(p, params); }
HDAPI void HDAPIENTRY hdSetLongv(HDenum p, const HDlong* params) { set_numbers(p, params); }
