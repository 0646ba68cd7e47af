// Joint-angle calibrations of devices whose raw sensor values the host
// decodes (hw/omni_calibration.h), one JSON file per device serial number
// under $XDG_CONFIG_HOME/vmhaptics/calibration/ (~/.config when
// XDG_CONFIG_HOME is not set), written by `hw calibrate` and loaded by the
// other hw verbs unless --no-calibration.
//
// A calibration is checked field by field when it is stored and when it
// is loaded (check_calibration): every value a finite number of the right
// type, and each within what an Omni can have. A bad file is refused with
// its path and the field, never loaded.
#ifndef VMHAPTICS_RUNTIME_CALIBRATION_STORE_H_
#define VMHAPTICS_RUNTIME_CALIBRATION_STORE_H_

#include <optional>
#include <stdexcept>
#include <string>

#include "hw/omni_calibration.h"
#include "runtime/json_util.h"

namespace vmh::runtime {

struct StoredCalibration {
  hw::OmniCalibration calibration;
  std::string serial;
  std::string backend;
  std::string date_utc;
  Json details;  // how it was found (samples, code ranges, spreads)
};

// A calibration that is malformed or cannot be an Omni's: the message
// names the file (or "the fit") and the field.
struct CalibrationError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The plausible ranges (docs/hardware.md, "Calibration"):
//   encoder_offset_rad  |x| <= pi: an offset is where count zero is, and
//                       the counts are zeroed near the inkwell pose
//   encoder_sign        +1 or -1 (a file without it: the nominal signs,
//                       hw::kNominalEncoderSign)
//   inkwell_t123_rad    |x| <= pi (a file without it: the estimate
//                       hw::kInkwellDevice_rad)
//   pot_gain_rad        1e-4 <= |x| <= 1e-2 rad per code: a 10- to 12-bit
//                       pot across a gimbal joint's 2.3 to 5.2 rad range is
//                       5.5e-4 to 5.1e-3 rad per code; 1e-2 is a sweep that
//                       covered a fifth of a 10-bit pot's codes
//   pot_offset_rad      |x| <= 4 pi, and the angle at code 2^12 - 1 too
inline constexpr double kMaxEncoderOffsetRad = 3.14159265358979323846;
inline constexpr double kMinPotGainRad = 1e-4;
inline constexpr double kMaxPotGainRad = 1e-2;
inline constexpr double kMaxPotAngleRad = 4.0 * 3.14159265358979323846;

// Throws CalibrationError "<where>: <field>[i] (t<N>) <what>" for the first
// value outside the ranges above (or not finite).
void check_calibration(const hw::OmniCalibration& c, const std::string& where);

// the folder and the file for a serial number (characters other than
// letters, digits, '-', '_' and '.' become '_')
std::string calibration_dir();
std::string calibration_path(const std::string& serial);

// nullopt when there is no file; throws CalibrationError naming the file
// and the field when it is not a regular file, too large, not JSON, a
// field is missing or of the wrong type, or check_calibration refuses it
std::optional<StoredCalibration> load_calibration(const std::string& serial);

// checks it (check_calibration) and writes it atomically; returns the path
std::string save_calibration(const StoredCalibration& c);

}  // namespace vmh::runtime

#endif  // VMHAPTICS_RUNTIME_CALIBRATION_STORE_H_
