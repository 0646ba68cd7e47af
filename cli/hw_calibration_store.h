// Joint-angle calibrations, one JSON file per device serial number under
// $XDG_CONFIG_HOME/vmhaptics/calibration/ (~/.config when XDG_CONFIG_HOME
// is not set), written by `hw calibrate` and loaded by the other hw verbs
// unless --no-calibration.
#ifndef VMHAPTICS_CLI_HW_CALIBRATION_STORE_H_
#define VMHAPTICS_CLI_HW_CALIBRATION_STORE_H_

#include <optional>
#include <string>

#include "cli/json_util.h"
#include "hw/omni_calibration.h"

namespace vmh::cli {

struct StoredCalibration {
  hw::OmniCalibration calibration;
  std::string serial;
  std::string backend;
  std::string date_utc;
  Json details;  // how it was found (samples, residuals, ranges)
};

// the folder and the file for a serial number (characters other than
// letters, digits, '-', '_' and '.' become '_')
std::string calibration_dir();
std::string calibration_path(const std::string& serial);

// nullopt when there is no file; throws std::runtime_error naming the file
// and the field when it is malformed
std::optional<StoredCalibration> load_calibration(const std::string& serial);

// writes it atomically; returns the path
std::string save_calibration(const StoredCalibration& c);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_HW_CALIBRATION_STORE_H_
