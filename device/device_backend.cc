#include "device/device_backend.h"

#include <chrono>
#include <cmath>
#include <thread>

namespace vmh {

const char* calibration_state_name(CalibrationState s) {
  switch (s) {
    case CalibrationState::kUnknown: return "unknown";
    case CalibrationState::kOk: return "ok";
    case CalibrationState::kNeedsUpdate: return "needs_update";
    case CalibrationState::kNeedsManualInput: return "needs_manual_input";
  }
  return "unknown";
}

void DeviceBackend::pass(double dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) return;
  std::this_thread::sleep_for(std::chrono::duration<double>(dt_s));
}

CalibrationState DeviceBackend::update_calibration() {
  throw DeviceOpenError(identity().backend +
                        ": the device has no calibration routine of its own");
}

}  // namespace vmh
