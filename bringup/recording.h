// A recording as `vmhaptics hw record | motor-test | run | calibrate`
// writes it (docs/outputs.md, "hw"): DIR/meta.json and DIR/trace.csv, read
// back for compare and identification.
//
// Columns keep their names from the trace (units in the names); numbers
// are parsed to double (an empty cell or "nan" is NaN), the text columns
// (read_error, write_error, safety_flags) are kept as text. Frames as the
// trace has them: q*_rad DH joint angles (q3 relative), p_*_mm / a_* the
// project's FK in the device frame, dev_* the device's own (device frame,
// mm; dev_J_rc row r column c as DeviceState::jacobian held them).
#ifndef VMHAPTICS_BRINGUP_RECORDING_H_
#define VMHAPTICS_BRINGUP_RECORDING_H_

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "controller/types.h"
#include "runtime/recording_reader.h"

namespace vmh::bringup {

// A recording that cannot be read: the message names the file and what
// was wrong with it (a missing column, a short row, a bad number). The
// shared reader's error (runtime/recording_reader.h).
using RecordingError = runtime::RecordingError;

struct Recording {
  std::string dir;
  nlohmann::ordered_json meta;  // meta.json as written
  std::string verb;             // meta["verb"]: "hw record", "hw run", ...
  std::vector<std::string> columns;
  std::map<std::string, std::vector<double>> num;
  std::map<std::string, std::vector<std::string>> text;
  std::size_t rows = 0;           // rows kept: what every analysis reads
  std::size_t rows_in_trace = 0;  // rows the trace has (all checked)
  bool cut_to_window() const { return rows_in_trace > rows; }

  bool has(const std::string& column) const;
  // throws RecordingError naming the column and the trace
  const std::vector<double>& col(const std::string& column) const;
  const std::vector<std::string>& text_col(const std::string& column) const;

  // rows with a good reading: read_error "ok" and finite joint angles
  std::vector<std::size_t> good_rows() const;

  // the device reports its own kinematics (dev_p_*, dev_R_*), its
  // velocity (dev_v_*), its Jacobian (dev_J_*)
  bool has_transform() const { return has("dev_p_x_mm"); }
  bool has_velocity() const { return has("dev_v_x_mm_s"); }
  bool has_jacobian() const { return has("dev_J_11"); }
  // the emulator's ground truth is in the trace (tau_applied_*, hand_*)
  bool has_truth() const { return has("tau_applied_1_Nm"); }

  // the scene the emulator simulated (meta.json emulator.scene), empty for
  // a device: what compare and identify predict with
  std::string emulator_scene() const;

  double t_s(std::size_t row) const { return col("t_s")[row]; }
  Joints q_dh_rad(std::size_t row) const;   // q1..q6, DH (q3 relative)
  Vec3 p_mm(std::size_t row) const;          // project FK, device frame
  Vec3 tau_cmd_Nm(std::size_t row) const;    // tau_1..3_Nm
  Vec3 tau_sent_Nm(std::size_t row) const;   // tau_sent_1..3_Nm
  Vec3 dev_p_mm(std::size_t row) const;
  Mat3 dev_R(std::size_t row) const;
  Vec3 dev_v_mm_s(std::size_t row) const;
  Eigen::Matrix<double, 6, 6> dev_J(std::size_t row) const;
  // three columns prefix1suffix, prefix2suffix, prefix3suffix (or x/y/z)
  Vec3 vec3(const std::string& prefix, const std::string& suffix,
            std::size_t row, bool xyz = false) const;
};

// Reads DIR/meta.json and DIR/trace.csv with the shared reader
// (runtime/recording_reader.h: regular files only, opened without
// blocking; sizes, lines and rows bounded; meta.json validated against the
// recording schema; columns named once; rows complete, a last row cut
// short dropped; t_s finite and increasing; CRLF read as LF) and requires
// meta.json and the columns q1_rad..q6_rad and tau_sent_1_Nm..3. A cell
// of a numeric column must be a number ("nan" and "inf" are). Throws
// RecordingError naming the file, the line and column, or the key.
//
// Memory stays bounded on a long recording: the whole trace is read and
// checked, but only its first max_rows rows are kept (kMaxAnalysedRows by
// default: two minutes at 1 kHz, about 120 MB with every column; an hour's
// `hw run` trace of 119 columns would take 3.4 GB). rows_in_trace says how
// many the trace has; the verbs report the window.
inline constexpr std::size_t kMaxAnalysedRows = 120'000;
Recording load_recording(const std::string& dir,
                         std::size_t max_rows = kMaxAnalysedRows);

// "DIR: read on its first N of M rows (...)" for a recording cut to its
// window, "" for one read whole: what compare and identify print
std::string window_note(const Recording& r);

}  // namespace vmh::bringup

#endif  // VMHAPTICS_BRINGUP_RECORDING_H_
