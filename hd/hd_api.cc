// The open HD API (include/HD/hd.h): the devices table and the current
// device, the device calls, frames, capabilities and calibration. The
// state calls (hdGet*, hdSet*) are in hd_api_params.cc, the error stack in
// hd_api_errors.cc, the scheduler in hd_api_scheduler.cc; hd_api_detail.h
// is what they share. docs/libhd.md is the account of what each call does
// here.
#define VMHAPTICS_HD_BUILDING 1
#include <HD/hd.h>
#include <HD/vmhd.h>

#include <atomic>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>

#include "hd/hd_api_detail.h"
#include "hd/hd_config.h"
#include "hd/hd_device.h"
#include "hd/hd_registry.h"

namespace vmh::hd {
namespace detail {
namespace {

thread_local HHD t_current = HD_INVALID_HANDLE;

bool parse_lockstep() {
  const char* v = std::getenv("VMH_HD_CLOCK");
  return v != nullptr && std::string(v) == "lockstep";
}

}  // namespace

thread_local int t_frame_depth[kMaxDevices] = {};

Context& ctx() {
  static Context* c = new Context;  // never destroyed: threads may outlive exit
  return *c;
}

HHD current_handle() {
  return t_current != HD_INVALID_HANDLE ? t_current : ctx().current.load();
}

HdDevice* device_of(HHD h) {
  if (h >= static_cast<HHD>(kMaxDevices)) return nullptr;
  return ctx().live[h].load(std::memory_order_acquire);
}

HdDevice* current_device() {
  const HHD h = current_handle();
  HdDevice* d = device_of(h);
  if (d == nullptr) push_error(HD_BAD_HANDLE, kInternalNone, h);
  return d;
}

}  // namespace detail

}  // namespace vmh::hd

using namespace vmh::hd;          // NOLINT: this file implements the C API
using namespace vmh::hd::detail;  // NOLINT: on the library's shared state

// The header declares every hd* function extern "C"; these definitions
// take that linkage from it.

// ---- devices ----

HDAPI HHD HDAPIENTRY hdInitDevice(HDstring config_name) {
  Context& c = ctx();
  const std::string shown = config_name == nullptr ? "HD_DEFAULT_DEVICE"
                                                    : std::string(config_name);
  // a refusal: its cause, after the call as the program made it, kept for
  // hdGetErrorString (and printed), its code on the error stack
  const auto refuse = [&shown](HDerror code, int internal, HHD h,
                               const std::string& cause) -> HHD {
    set_detail(code, "hdInitDevice(\"" + shown + "\")" + cause);
    push_error(code, internal, h);
    return HD_INVALID_HANDLE;
  };
  std::string spec;
  try {
    spec = resolve_device_name(load_hd_config(), config_name);
  } catch (const HdConfigError& e) {
    const bool file = std::string(e.what()).rfind("no device is configured", 0) != 0;
    return refuse(HD_COMM_CONFIG_ERROR,
                  file ? kInternalConfigFile : kInternalNameNotConfigured,
                  HD_INVALID_HANDLE, std::string(": ") + e.what());
  }
  std::lock_guard<std::mutex> lock(c.mu);
  if (c.running.load()) {
    return refuse(HD_INVALID_OPERATION, kInternalNone, HD_INVALID_HANDLE,
                  ": stop the scheduler before opening another device");
  }
  for (HHD h = 0; h < static_cast<HHD>(kMaxDevices); ++h) {
    if (c.devices[h] && c.devices[h]->spec() == spec) {
      return refuse(HD_DEVICE_ALREADY_INITIATED, kInternalNone, h,
                    ": '" + spec + "' is already open as handle " +
                        std::to_string(h));
    }
  }
  HHD slot = HD_INVALID_HANDLE;
  for (HHD h = 0; h < static_cast<HHD>(kMaxDevices); ++h) {
    if (!c.devices[h]) {
      slot = h;
      break;
    }
  }
  if (slot == HD_INVALID_HANDLE) {
    return refuse(HD_COMM_CONFIG_ERROR, kInternalTooManyDevices, HD_INVALID_HANDLE,
                  ": " + std::to_string(kMaxDevices) + " devices are open already");
  }
  const std::string opening = " -> '" + spec + "': ";
  const bool lockstep = parse_lockstep();
  try {
    c.devices[slot] = std::make_unique<HdDevice>(library_registry(), spec, lockstep);
  } catch (const vmh::DeviceOpenError& e) {
    return refuse(HD_COMM_CONFIG_ERROR, kInternalDeviceNotFound, HD_INVALID_HANDLE,
                  opening + e.what());
  } catch (const std::exception& e) {
    return refuse(HD_COMM_CONFIG_ERROR, kInternalBackendRefused, HD_INVALID_HANDLE,
                  opening + e.what());
  }
  if (lockstep && !c.devices[slot]->can_lockstep()) {
    c.devices[slot].reset();
    return refuse(HD_COMM_CONFIG_ERROR, kInternalBackendRefused, HD_INVALID_HANDLE,
                  opening +
                      "VMH_HD_CLOCK=lockstep needs a simulated device "
                      "(emulator...) or a recording (replay:DIR); a real "
                      "device runs on the wall clock");
  }
  c.lockstep.store(lockstep);
  c.live[slot].store(c.devices[slot].get(), std::memory_order_release);
  c.current.store(slot);
  t_current = slot;
  return slot;
}

HDAPI void HDAPIENTRY hdDisableDevice(HHD h) {
  Context& c = ctx();
  if (device_of(h) == nullptr) {
    push_error(HD_BAD_HANDLE, kInternalNone, h);
    return;
  }
  bool others = false;
  for (HHD i = 0; i < static_cast<HHD>(kMaxDevices); ++i) {
    if (i != h && device_of(i) != nullptr) others = true;
  }
  // the scheduler's ticks hold every device: it stops while one leaves,
  // and starts again for the others (docs/libhd.md)
  const bool was_running = c.running.load();
  if (was_running) hdStopScheduler();
  {
    std::lock_guard<std::mutex> lock(c.mu);
    c.live[h].store(nullptr, std::memory_order_release);
    c.devices[h]->send_zero();
    c.devices[h].reset();
  }
  if (was_running && others) hdStartScheduler();
  if (c.current.load() == h) c.current.store(HD_INVALID_HANDLE);
  if (t_current == h) t_current = HD_INVALID_HANDLE;
}

HDAPI HHD HDAPIENTRY hdGetCurrentDevice(void) {
  const HHD h = current_handle();
  if (device_of(h) == nullptr) {
    push_error(HD_BAD_HANDLE, kInternalNone, h);
    return HD_INVALID_HANDLE;
  }
  return h;
}

HDAPI void HDAPIENTRY hdMakeCurrentDevice(HHD h) {
  if (device_of(h) == nullptr) {
    push_error(HD_BAD_HANDLE, kInternalNone, h);
    return;
  }
  t_current = h;
  if (!on_servo_thread()) ctx().current.store(h);
}

HDAPI void HDAPIENTRY hdBeginFrame(HHD h) {
  if (device_of(h) == nullptr) {
    push_error(HD_BAD_HANDLE, kInternalNone, h);
    return;
  }
  t_current = h;
  if (!on_servo_thread()) return;  // outside the scheduler: nothing to frame
  ++t_frame_depth[h];  // nested frames share the tick's sample
}

HDAPI void HDAPIENTRY hdEndFrame(HHD h) {
  if (device_of(h) == nullptr) {
    push_error(HD_BAD_HANDLE, kInternalNone, h);
    return;
  }
  if (!on_servo_thread()) return;
  if (t_frame_depth[h] == 0) {
    push_error(HD_ILLEGAL_END, kInternalFrameState, h);
    return;
  }
  --t_frame_depth[h];  // the command goes out when the tick ends
}

// ---- capabilities ----

namespace {
std::atomic<bool>* capability(HdDevice* d, HDenum cap) {
  HdSettings& s = d->settings();
  switch (cap) {
    case HD_FORCE_OUTPUT: return &s.force_output;
    case HD_MAX_FORCE_CLAMPING: return &s.max_force_clamping;
    case HD_FORCE_RAMPING: return &s.force_ramping;
    case HD_SOFTWARE_FORCE_LIMIT: return &s.software_force_limit;
    case HD_ONE_FRAME_LIMIT: return &s.one_frame_limit;
    case HD_SOFTWARE_VELOCITY_LIMIT: return &s.velocity_limit_on;
    case HD_SOFTWARE_FORCE_IMPULSE_LIMIT: return &s.impulse_limit_on;
    default: return nullptr;
  }
}
void set_capability(HDenum cap, bool on) {
  HdDevice* d = current_device();
  if (d == nullptr) return;
  std::atomic<bool>* a = capability(d, cap);
  if (a == nullptr) {
    push_error(HD_INVALID_ENUM, kInternalUnknownParameter, current_handle());
    return;
  }
  a->store(on);
}
}  // namespace

HDAPI void HDAPIENTRY hdEnable(HDenum cap) { set_capability(cap, true); }
HDAPI void HDAPIENTRY hdDisable(HDenum cap) { set_capability(cap, false); }
HDAPI HDboolean HDAPIENTRY hdIsEnabled(HDenum cap) {
  HdDevice* d = current_device();
  if (d == nullptr) return HD_FALSE;
  std::atomic<bool>* a = capability(d, cap);
  if (a == nullptr) {
    push_error(HD_INVALID_ENUM, kInternalUnknownParameter, current_handle());
    return HD_FALSE;
  }
  return a->load() ? HD_TRUE : HD_FALSE;
}

// ---- calibration ----

HDAPI HDenum HDAPIENTRY hdCheckCalibration(void) {
  HdDevice* d = current_device();
  if (d == nullptr) return HD_CALIBRATION_NEEDS_MANUAL_INPUT;
  switch (d->backend()->calibration_state()) {
    case vmh::CalibrationState::kNeedsUpdate: return HD_CALIBRATION_NEEDS_UPDATE;
    case vmh::CalibrationState::kNeedsManualInput: return HD_CALIBRATION_NEEDS_MANUAL_INPUT;
    default: return HD_CALIBRATION_OK;
  }
}

HDAPI void HDAPIENTRY hdUpdateCalibration(HDenum style) {
  HdDevice* d = current_device();
  if (d == nullptr) return;
  if (style != HD_CALIBRATION_ENCODER_RESET && style != HD_CALIBRATION_AUTO &&
      style != HD_CALIBRATION_INKWELL) {
    push_error(HD_INVALID_VALUE, kInternalNone, current_handle());
    return;
  }
  if (!d->backend()->has_driver_calibration()) return;  // nothing to update
  try {
    d->backend()->update_calibration();
  } catch (const std::exception& e) {
    set_detail(HD_DEVICE_FAULT, std::string("hdUpdateCalibration: ") + e.what());
    push_error(HD_DEVICE_FAULT, kInternalNone, current_handle());
  }
}

// ---- the project's extension (not in the vendor's API) ----

// The simulated plant's ground truth for device h (device/tick_record.h's
// PlantTruth), for the project's own OpenHaptics backend: `size` must be
// sizeof(vmh::PlantTruth) of the same build. Returns 1 when filled, 0 for a
// device without a truth or a size that does not match.
HDAPI int HDAPIENTRY vmhdReadTruth(HHD h, void* truth, unsigned long size) {
  HdDevice* d = device_of(h);
  if (d == nullptr || truth == nullptr || size != sizeof(vmh::PlantTruth)) return 0;
  return d->read_truth(static_cast<vmh::PlantTruth*>(truth)) ? 1 : 0;
}

