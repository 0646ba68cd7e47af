#include "studies/bringup/recording.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "report/output_file.h"

namespace vmh::bringup {
namespace {

bool is_text_column(const std::string& name) {
  return name == "read_error" || name == "write_error" ||
         name == "safety_flags" || name == "phase";
}

// Refuses, by its type and size, a file that is not a regular file (a
// FIFO would block the reader, a device never end) or is larger than
// max_bytes, before it is opened.
void check_regular(const std::string& path, std::int64_t max_bytes) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return;  // the open names a missing one
  if (!S_ISREG(st.st_mode)) {
    throw RecordingError(path + ": not a regular file (" +
                         report::file_kind(st.st_mode) +
                         "); a recording's files are plain files");
  }
  if (st.st_size > max_bytes) {
    throw RecordingError(path + ": " + std::to_string(st.st_size) +
                         " bytes, more than a recording's " +
                         std::to_string(max_bytes));
  }
}

// One line of at most kMaxLineBytes into *line, without its '\n' or a
// '\r' before it (CRLF line ends, RFC 4180's own, as spreadsheet tools on
// Windows write them). False at the end of the file; throws on a longer
// line, naming it.
bool read_line(std::istream& in, std::string* line, const std::string& path,
               std::size_t line_no) {
  line->clear();
  char c = 0;
  bool any = false;
  while (in.get(c)) {
    any = true;
    if (c == '\n') break;
    if (line->size() >= kMaxLineBytes) {
      throw RecordingError(path + ": line " + std::to_string(line_no) +
                           " is longer than " + std::to_string(kMaxLineBytes) +
                           " bytes");
    }
    line->push_back(c);
  }
  if (!line->empty() && line->back() == '\r') line->pop_back();
  return any;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream s(line);
  while (std::getline(s, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
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

Recording load_recording(const std::string& dir) {
  Recording rec;
  rec.dir = dir;
  const std::string meta_path = dir + "/meta.json";
  check_regular(meta_path, kMaxMetaBytes);
  std::ifstream mf(meta_path);
  if (!mf) throw RecordingError(meta_path + ": cannot open (is " + dir + " a recording?)");
  try {
    rec.meta = nlohmann::ordered_json::parse(mf);
  } catch (const nlohmann::json::exception& e) {
    throw RecordingError(meta_path + ": not valid JSON (" + e.what() + ")");
  }
  if (!rec.meta.is_object() || !rec.meta.contains("verb") ||
      !rec.meta["verb"].is_string()) {
    throw RecordingError(meta_path + ": no \"verb\" (not written by vmhaptics hw)");
  }
  rec.verb = rec.meta["verb"].get<std::string>();

  const std::string trace_path = dir + "/trace.csv";
  check_regular(trace_path, kMaxTraceBytes);
  std::ifstream tf(trace_path, std::ios::binary);
  if (!tf) throw RecordingError(trace_path + ": cannot open");
  std::string line;
  if (!read_line(tf, &line, trace_path, 1) || line.empty()) {
    throw RecordingError(trace_path + ": empty (no header)");
  }
  rec.columns = split(line);
  std::set<std::string> seen;
  for (const std::string& c : rec.columns) {
    if (c.empty()) {
      throw RecordingError(trace_path + ": line 1: a column has no name");
    }
    if (!seen.insert(c).second) {
      throw RecordingError(trace_path + ": line 1: column '" + c +
                           "' appears twice");
    }
    if (is_text_column(c)) rec.text[c];
    else rec.num[c];
  }
  for (const char* required : {"t_s", "q1_rad", "q6_rad", "tau_sent_1_Nm"}) {
    if (!rec.has(required)) {
      throw RecordingError(trace_path + ": no column '" + required + "'");
    }
  }
  // the clock's column, checked row by row below
  const std::size_t t_cell = static_cast<std::size_t>(
      std::find(rec.columns.begin(), rec.columns.end(), "t_s") -
      rec.columns.begin());
  const std::vector<double>& t_col = rec.num.at("t_s");
  std::size_t line_no = 1;
  double last_t_s = -std::numeric_limits<double>::infinity();
  while (read_line(tf, &line, trace_path, line_no + 1)) {
    ++line_no;
    if (line.empty()) continue;
    const std::vector<std::string> cells = split(line);
    if (cells.size() != rec.columns.size()) {
      // a last row cut short by a crash or a full disk: stop there
      if (tf.peek() == EOF) break;
      throw RecordingError(trace_path + ": line " + std::to_string(line_no) +
                           " has " + std::to_string(cells.size()) +
                           " cells, the header " +
                           std::to_string(rec.columns.size()));
    }
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const std::string& name = rec.columns[i];
      if (is_text_column(name)) {
        rec.text[name].push_back(cells[i]);
        continue;
      }
      double v = std::nan("");
      if (!cells[i].empty() && cells[i] != "nan") {
        char* end = nullptr;
        v = std::strtod(cells[i].c_str(), &end);
        if (end == cells[i].c_str() || *end != '\0') {
          throw RecordingError(trace_path + ": line " + std::to_string(line_no) +
                               ", column '" + name + "': not a number: '" +
                               cells[i] + "'");
        }
      }
      rec.num[name].push_back(v);
    }
    // the clock: finite and strictly increasing, or the recording is not
    // one (reversed, repeated or zeroed rows)
    const double t_s = t_col.back();
    if (!std::isfinite(t_s) || !(t_s > last_t_s)) {
      throw RecordingError(trace_path + ": line " + std::to_string(line_no) +
                           ": t_s = " + cells[t_cell] +
                           (std::isfinite(t_s)
                                ? " does not come after the line before's"
                                : " is not a finite time") +
                           "; t_s must increase from row to row");
    }
    last_t_s = t_s;
    ++rec.rows;
  }
  if (rec.rows == 0) throw RecordingError(trace_path + ": no rows");
  return rec;
}

}  // namespace vmh::bringup
