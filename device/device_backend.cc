#include "device/device_backend.h"

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

}  // namespace vmh
