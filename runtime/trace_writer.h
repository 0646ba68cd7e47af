// trace.csv: one row per servo tick (device/tick_record.h), for `run` and
// for every `hw` session alike: the same columns, named the same way, in
// the same order, formatted the same way ("%.9g"). Which column groups a
// trace has depends on what its loop had, not on the verb:
//
//   always       t_s, period_s, q1_rad..q6_rad (the reading, DH),
//                p_x_mm..p_z_mm, a_x..a_z (its wrist centre and stylus
//                axis, device frame)
//   controller   theta_v_1.., theta_r_1.. (the VM's DOF), xv_*_mm, xr_*_mm,
//                e_1_mm..e_6_rad, f_1_N..f_6_Nmm, F_x_N..F_z_N
//   always       tau_1_Nm..tau_3_Nm (asked), tau_sent_1_Nm.. (sent)
//   truth        tau_applied_1_Nm.. (held by the motors), hand_*_mm (the
//                hand's target), hand_F_*_N (the hand's force)
//   controller   d_path_mm, status
//   phases       phase (the hand script's segment name)
//   always       read_error, write_error, safety, safety_flags, ramp_scale
//   present      buttons, docked; dev_p_*_mm, dev_R_11..33 (the device's
//                own stylus transform), dev_v_*_mm_s, dev_J_11..66, enc_1..3,
//                pot_4..6: as the device reports them (DeviceState::present)
//
// docs/outputs.md documents every column. The writer streams: rows go to
// the file a buffer at a time, so a trace's length is bounded by the disk.
#ifndef VMHAPTICS_RUNTIME_TRACE_WRITER_H_
#define VMHAPTICS_RUNTIME_TRACE_WRITER_H_

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "device/tick_record.h"

namespace vmh::runtime {

struct TraceLayout {
  bool controller = false;  // the controller's columns, d_path_mm, status
  int vm_dof = 0;           // theta_v_* and theta_r_* columns
  bool truth = false;       // the plant's columns
  // the hand script's segment names, indexed by PlantTruth::segment: a
  // phase column when not empty
  std::vector<std::string> phases;
  // DeviceState fields the device reports (kStateButtons, kStateInkwell,
  // kStateTransform, ...): their columns
  std::uint32_t present = 0;
};

std::vector<std::string> trace_columns(const TraceLayout& layout);
// the header line, '\n'-terminated
std::string trace_header(const TraceLayout& layout);
// one row, '\n'-terminated, appended to *out. A field the layout has but
// the record lacks (a failed read's transform) is written as nan.
void append_trace_row(const TickRecord& r, const TraceLayout& layout,
                      std::string* out);

// The names of the flags up in a safety status, '|'-joined ("ok" for none)
std::string safety_flags_text(SafetyStatus s);

// An upper bound on a trace's size for `ticks` rows of `columns` columns
// (bytes): "%.9g," of a negative number with an exponent is 16 bytes at
// most, and no text cell is longer.
double trace_bytes_bound(std::int64_t ticks, std::size_t columns);

// trace.csv written as the loop goes, a buffer of rows at a time. Every
// failure (open, write, a full disk, close) throws std::runtime_error
// naming the file (`shown`: where the file will be once its set is in
// place) and the OS's reason.
class TraceWriter {
 public:
  TraceWriter(const std::string& path, std::string shown, TraceLayout layout);
  ~TraceWriter();
  TraceWriter(const TraceWriter&) = delete;
  TraceWriter& operator=(const TraceWriter&) = delete;

  void add(const TickRecord& r);
  // the rows buffered so far to the file (a session flushes every poll, so
  // that a process killed mid-run keeps its trace up to then)
  void flush();
  void close();
  const TraceLayout& layout() const { return layout_; }
  const std::string& shown() const { return shown_; }

 private:
  static constexpr std::size_t kFlushBytes = std::size_t{1} << 18;
  [[noreturn]] void fail() const;
  std::string shown_;
  TraceLayout layout_;
  std::FILE* f_ = nullptr;
  std::string buf_;
};

}  // namespace vmh::runtime

#endif  // VMHAPTICS_RUNTIME_TRACE_WRITER_H_
