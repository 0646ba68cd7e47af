#include "bringup/recording.h"

#include <cmath>
#include <filesystem>

#include "runtime/recording_reader.h"

namespace vmh::bringup {
namespace {

bool is_text_column(const std::string& name) {
  return name == "read_error" || name == "write_error" ||
         name == "safety_flags" || name == "phase";
}

}  // namespace

bool Recording::has(const std::string& c) const {
  return num.count(c) != 0 || text.count(c) != 0;
}

const std::vector<double>& Recording::col(const std::string& c) const {
  auto it = num.find(c);
  if (it == num.end()) {
    throw RecordingError(dir + "/trace.csv: no numeric column '" + c + "'");
  }
  return it->second;
}

const std::vector<std::string>& Recording::text_col(const std::string& c) const {
  auto it = text.find(c);
  if (it == text.end()) {
    throw RecordingError(dir + "/trace.csv: no text column '" + c + "'");
  }
  return it->second;
}

std::vector<std::size_t> Recording::good_rows() const {
  std::vector<std::size_t> out;
  const std::vector<std::string>* err = nullptr;
  if (text.count("read_error")) err = &text.at("read_error");
  for (std::size_t r = 0; r < rows; ++r) {
    if (err && (*err)[r] != "ok") continue;
    if (!q_dh_rad(r).allFinite()) continue;
    out.push_back(r);
  }
  return out;
}

std::string Recording::emulator_scene() const {
  if (meta.contains("emulator") && meta["emulator"].is_object() &&
      meta["emulator"].contains("scene") && meta["emulator"]["scene"].is_string()) {
    return meta["emulator"]["scene"].get<std::string>();
  }
  return {};
}

Vec3 Recording::vec3(const std::string& prefix, const std::string& suffix,
                     std::size_t row, bool xyz) const {
  static const char* kXyz[] = {"x", "y", "z"};
  Vec3 v;
  for (int i = 0; i < 3; ++i) {
    const std::string mid = xyz ? kXyz[i] : std::to_string(i + 1);
    v[i] = col(prefix + mid + suffix)[row];
  }
  return v;
}

Joints Recording::q_dh_rad(std::size_t row) const {
  Joints q;
  for (int i = 0; i < 6; ++i) q[i] = col("q" + std::to_string(i + 1) + "_rad")[row];
  return q;
}
Vec3 Recording::p_mm(std::size_t row) const { return vec3("p_", "_mm", row, true); }
Vec3 Recording::tau_cmd_Nm(std::size_t row) const { return vec3("tau_", "_Nm", row); }
Vec3 Recording::tau_sent_Nm(std::size_t row) const {
  return vec3("tau_sent_", "_Nm", row);
}
Vec3 Recording::dev_p_mm(std::size_t row) const {
  return vec3("dev_p_", "_mm", row, true);
}
Vec3 Recording::dev_v_mm_s(std::size_t row) const {
  return vec3("dev_v_", "_mm_s", row, true);
}
Mat3 Recording::dev_R(std::size_t row) const {
  Mat3 R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      R(r, c) = col("dev_R_" + std::to_string(r + 1) + std::to_string(c + 1))[row];
    }
  }
  return R;
}
Eigen::Matrix<double, 6, 6> Recording::dev_J(std::size_t row) const {
  Eigen::Matrix<double, 6, 6> J;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      J(r, c) = col("dev_J_" + std::to_string(r + 1) + std::to_string(c + 1))[row];
    }
  }
  return J;
}

Recording load_recording(const std::string& dir, std::size_t max_rows) {
  Recording rec;
  rec.dir = dir;
  const runtime::RecordingLimits limits;
  const std::string meta_path = dir + "/meta.json";
  bool missing = false;
  const runtime::RecordingMeta meta =
      runtime::read_recording_meta(meta_path, limits, &missing);
  if (missing) {
    throw RecordingError(meta_path + ": no such file (is " + dir +
                         " a recording of vmhaptics hw record, motor-test or "
                         "run?)");
  }
  rec.meta = meta.json;
  rec.verb = meta.verb;

  const std::string trace_path = dir + "/trace.csv";
  {
    // the shared reader names a missing file by its path; say what it is
    std::error_code ec;
    if (!std::filesystem::exists(std::filesystem::symlink_status(trace_path, ec))) {
      throw RecordingError(trace_path + ": no such file (a recording has its "
                           "trace beside meta.json)");
    }
  }
  runtime::TraceReader trace(trace_path, limits);
  rec.columns = trace.columns();
  for (const std::string& c : rec.columns) {
    if (is_text_column(c)) rec.text[c];
    else rec.num[c];
  }
  for (const char* required : {"q1_rad", "q6_rad", "tau_sent_1_Nm"}) {
    (void)trace.require(required);
  }
  // the columns' vectors in header order, so that a row is appended
  // without a lookup per cell
  std::vector<std::vector<double>*> num_of(rec.columns.size(), nullptr);
  std::vector<std::vector<std::string>*> text_of(rec.columns.size(), nullptr);
  for (std::size_t i = 0; i < rec.columns.size(); ++i) {
    const std::string& c = rec.columns[i];
    if (is_text_column(c)) text_of[i] = &rec.text.at(c);
    else num_of[i] = &rec.num.at(c);
  }
  while (trace.next()) {
    ++rec.rows_in_trace;
    if (rec.rows >= max_rows) continue;  // checked by next(), not kept
    const std::vector<std::string_view>& cells = trace.cells();
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (text_of[i] != nullptr) {
        text_of[i]->emplace_back(cells[i]);
      } else {
        num_of[i]->push_back(trace.number(i));
      }
    }
    ++rec.rows;
  }
  if (rec.rows == 0) throw RecordingError(trace_path + ": no rows after the header");
  return rec;
}

std::string window_note(const Recording& r) {
  if (!r.cut_to_window()) return {};
  return r.dir + ": judged on its first " + std::to_string(r.rows) + " of " +
         std::to_string(r.rows_in_trace) +
         " rows (every row was checked; a verb keeps at most " +
         std::to_string(kMaxAnalysedRows) + " so that its memory stays bounded)";
}

}  // namespace vmh::bringup
