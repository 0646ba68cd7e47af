// `hw calibrate`'s procedure: the joint-angle calibration of a device that
// reports raw sensor values (the FireWire Omni, the emulator directly or
// behind the packets), stored per serial number (runtime/calibration_store.h):
//   1. the stylus in the inkwell: the encoder offsets that make the docked
//      counts, counted in the calibration's encoder signs, read as its
//      inkwell pose (hw::fit_encoder_offsets);
//   2. each gimbal joint turned to both ends of its range: a two-point fit
//      of its potentiometer, the extreme codes taken as the range's ends
//      (hw::fit_pot_two_point).
// A simulated hand does both (hand programs dock and gimbal_sweep); on a
// device the user does, prompted on stderr. A fit is stored only when it
// is plausible: the stylus held still in the inkwell, each pot swept over
// enough of its codes, every value within check_calibration's ranges;
// otherwise CalibrationError names the joint and what to redo, and nothing
// is stored.
//
// A device with its own calibration routine (OpenHaptics) is asked to run
// it instead (DeviceBackend::update_calibration).
#ifndef VMHAPTICS_RUNTIME_CALIBRATE_H_
#define VMHAPTICS_RUNTIME_CALIBRATE_H_

#include <string>

#include "runtime/backend_registry.h"
#include "runtime/calibration_store.h"
#include "runtime/json_util.h"
#include "runtime/session.h"

namespace vmh::runtime {

struct CalibrateOptions {
  double dock_s = 6.0;    // the inkwell phase, s of loop time
  double sweep_s = 10.0;  // the gimbal sweep, s
  ServoOptions servo;     // the clock and real-time scheduling
  bool progress = true;
  std::string verb = "hw calibrate";
};

// the least number of codes a sweep must cover on each pot: a quarter of a
// 10-bit pot's, about a third of a joint's range at the coarsest pot
inline constexpr int kMinSweepCodes = 256;
// the most the docked counts may spread over the inkwell phase's last
// second (max - min, per encoder): 0.02 rad, a stylus that did not sit still
inline constexpr int kMaxDockSpreadCounts = 50;

// Runs the calibration and returns what `hw calibrate` prints: the device,
// the fit (or the driver's states before and after), where it was stored
// and, on a simulated device, how far the fit is from the truth. Throws
// CalibrationError (a fit refused: nothing stored), std::runtime_error (a
// session cut short), DeviceOpenError.
Json calibrate(OpenedDevice* dev, const CalibrateOptions& options);

}  // namespace vmh::runtime

#endif  // VMHAPTICS_RUNTIME_CALIBRATE_H_
