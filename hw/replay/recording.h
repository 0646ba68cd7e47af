// A recording of `vmhaptics hw record` (a folder with trace.csv and,
// normally, meta.json: runtime/trace_writer.h, docs/outputs.md) read into
// an immutable table the replay device serves rows from. Pure: files in,
// values out, no clock, no thread, no MuJoCo.
//
// What is kept, per row (units and frames as the device reported them, the
// device's own convention, device/device_state.h):
//   time_s          t_s, the session's loop time, s (strictly increasing)
//   q_device_rad    q1_rad..q6_rad converted from the trace's DH convention
//                   back to the device's (t1..t6, rad, t3 the absolute
//                   forearm angle: controller/device_frame.h)
//   read_error      read_error ("ok" where the column is missing): a row
//                   whose read failed is replayed as that failure
//   and, only where the trace has the columns (DeviceState::present):
//   buttons, docked, the device's transform (dev_p_*_mm, mm, and
//   dev_R_11..33), velocity (dev_v_*_mm_s, mm/s), Jacobian (dev_J_11..66),
//   encoder counts (enc_1..3) and gimbal potentiometers (pot_4..6).
// The controller's, the plant's and the safety layer's columns are the
// recording session's own doing, not the device's, and are not read.
//
// Refused, with the file, line and column named (RecordingError, a
// DeviceOpenError): a missing folder or trace.csv; whatever the shared
// reader refuses (runtime/recording_reader.h: a file that is not regular,
// a bound passed, a header with a column unnamed or named twice, a row of
// the wrong length, t_s not finite and increasing, meta.json not JSON or
// not the recording schema); and here a missing required column
// (q1_rad..q6_rad), a partial optional group, a cell that is not a number,
// a non-finite value where a good reading needs a number, no rows at all.
#ifndef VMHAPTICS_HW_REPLAY_RECORDING_H_
#define VMHAPTICS_HW_REPLAY_RECORDING_H_

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "controller/types.h"
#include "device/device_backend.h"
#include "device/device_state.h"
#include "runtime/recording_reader.h"

namespace vmh::hw::replay {

// The bounds and the error are the shared reader's
// (runtime/recording_reader.h): an hour at 1 kHz, 8 GiB of trace, 64 KiB
// a line, 1 MiB of meta.json. A row takes at most about 500 bytes in
// memory here (every optional group present), 70 with none.
using runtime::RecordingLimits;
using runtime::RecordingError;

struct Recording {
  std::string folder;      // as given, made absolute
  std::string trace_file;  // folder/trace.csv
  // DeviceState fields beyond the joints that every row carries
  // (kStateButtons, kStateInkwell, kStateTransform, kStateVelocity,
  // kStateJacobian, kStateEncoders, kStatePots)
  std::uint32_t present = 0;

  std::vector<double> time_s;
  std::vector<Joints> q_device_rad;
  std::vector<DeviceError> read_error;
  // sized rows() where present, else empty
  std::vector<std::uint32_t> buttons;
  std::vector<std::uint8_t> docked;
  std::vector<std::array<double, 12>> transform;  // p x,y,z then R row-major
  std::vector<std::array<double, 3>> velocity_mm_s;
  std::vector<std::array<double, 36>> jacobian;   // row-major
  std::vector<std::array<std::int32_t, 3>> encoders;
  std::vector<std::array<std::int32_t, 3>> pots;

  // meta.json, where there is one: the recorded device and the session's
  // nominal servo period (0 when not known)
  bool has_meta = false;
  DeviceIdentity recorded;
  double nominal_period_s = 0.0;

  std::size_t rows() const { return time_s.size(); }
  double first_s() const { return time_s.front(); }
  double last_s() const { return time_s.back(); }
  // how long the last row holds: the nominal period, else the last step
  // between rows, else 1 ms
  double last_hold_s() const;

  // The row serving recording time t_s: the last row whose time is at or
  // before t_s (a tolerance of 1e-8 (1 + |t|) s absorbs the trace's
  // 9-digit printing), row 0 before the first. No allocation.
  std::size_t row_at(double t_s) const noexcept;
  // Row i as the device reported it: its read error, and on a good row the
  // state with the joints and every present field. No allocation.
  DeviceError state_of(std::size_t i, DeviceState* state) const noexcept;
};

// Reads folder/trace.csv and folder/meta.json (optional). Throws
// RecordingError.
Recording read_recording(const std::string& folder,
                         const RecordingLimits& limits = RecordingLimits{});

// The DeviceError named as trace.csv's read_error column names it ("ok",
// "timeout", ...); false for a name that is none
bool parse_device_error(const std::string& name, DeviceError* e);

}  // namespace vmh::hw::replay

#endif  // VMHAPTICS_HW_REPLAY_RECORDING_H_
