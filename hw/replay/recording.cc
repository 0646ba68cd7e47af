#include "hw/replay/recording.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "controller/device_frame.h"
#include "report/output_file.h"

namespace vmh::hw::replay {
namespace {

namespace fs = std::filesystem;

constexpr const char* kXyz[] = {"x", "y", "z"};

std::string errno_text(int e) { return std::strerror(e); }

std::string bytes_text(std::uint64_t b) {
  char buf[64];
  if (b % (std::uint64_t{1} << 20) == 0) {
    std::snprintf(buf, sizeof buf, "%llu MiB",
                  static_cast<unsigned long long>(b >> 20));
  } else {
    std::snprintf(buf, sizeof buf, "%llu bytes", static_cast<unsigned long long>(b));
  }
  return buf;
}

// A regular file no larger than max_bytes, opened for reading without
// blocking on a FIFO that appeared between the stat and the open. nullptr
// with *missing = true when there is no such file; throws otherwise.
std::FILE* open_regular(const std::string& path, std::uint64_t max_bytes,
                        bool* missing) {
  *missing = false;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) {
      *missing = true;
      return nullptr;
    }
    throw RecordingError(path + ": " + errno_text(errno));
  }
  if (!S_ISREG(st.st_mode)) {
    throw RecordingError(path + " is " + report::file_kind(st.st_mode) +
                         ", not a regular file");
  }
  if (static_cast<std::uint64_t>(st.st_size) > max_bytes) {
    throw RecordingError(path + " is " +
                         bytes_text(static_cast<std::uint64_t>(st.st_size)) +
                         ", over the replay's bound of " + bytes_text(max_bytes));
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw RecordingError(path + ": " + errno_text(errno));
  struct stat st2 {};
  if (::fstat(fd, &st2) != 0 || !S_ISREG(st2.st_mode)) {
    ::close(fd);
    throw RecordingError(path + " changed into something that is not a "
                         "regular file while it was opened");
  }
  std::FILE* f = ::fdopen(fd, "rb");
  if (f == nullptr) {
    const int e = errno;
    ::close(fd);
    throw RecordingError(path + ": " + errno_text(e));
  }
  return f;
}

struct FileCloser {
  std::FILE* f;
  ~FileCloser() {
    if (f) std::fclose(f);
  }
};

// Lines of a file, at most max_bytes read in all (a file that grew after
// its stat is refused at the bound rather than read on).
class LineReader {
 public:
  LineReader(std::FILE* f, std::string path, std::uint64_t max_bytes)
      : f_(f), path_(std::move(path)), max_(max_bytes) {}
  ~LineReader() { std::free(buf_); }
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  // the next line without its '\n' (and '\r'); false at the end
  bool next(std::string* line) {
    errno = 0;
    const ssize_t n = ::getline(&buf_, &cap_, f_);
    if (n < 0) {
      if (std::ferror(f_)) throw RecordingError(path_ + ": " + errno_text(errno));
      return false;
    }
    read_ += static_cast<std::uint64_t>(n);
    if (read_ > max_) {
      throw RecordingError(path_ + " grew over the replay's bound of " +
                           bytes_text(max_) + " while it was read");
    }
    ++line_no_;
    std::size_t len = static_cast<std::size_t>(n);
    if (len > 0 && buf_[len - 1] == '\n') --len;
    if (len > 0 && buf_[len - 1] == '\r') --len;
    line->assign(buf_, len);
    return true;
  }
  long line_no() const { return line_no_; }

 private:
  std::FILE* f_;
  std::string path_;
  std::uint64_t max_;
  char* buf_ = nullptr;
  std::size_t cap_ = 0;
  std::uint64_t read_ = 0;
  long line_no_ = 0;
};

// splits at ',' (trace.csv has no quoting: no cell holds a comma)
void split(const std::string& line, std::vector<std::string>* cells) {
  cells->clear();
  std::size_t from = 0;
  for (;;) {
    const std::size_t comma = line.find(',', from);
    cells->push_back(line.substr(from, comma - from));
    if (comma == std::string::npos) break;
    from = comma + 1;
  }
}

// The columns the reader takes and where they are in the header.
struct Layout {
  std::size_t t = 0;
  std::array<std::size_t, 6> q{};
  std::size_t read_error = SIZE_MAX;
  std::size_t buttons = SIZE_MAX, docked = SIZE_MAX;
  std::array<std::size_t, 12> transform{};
  std::array<std::size_t, 3> velocity{};
  std::array<std::size_t, 36> jacobian{};
  std::array<std::size_t, 3> enc{}, pot{};
};

class TraceParser {
 public:
  TraceParser(std::string path, const std::vector<std::string>& header)
      : path_(std::move(path)), header_(header) {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (!index_.emplace(header[i], i).second) {
        throw RecordingError(path_ + ":1:" + std::to_string(i + 1) +
                             ": column '" + header[i] + "' appears twice");
      }
    }
  }

  // a column every recording has
  std::size_t required(const std::string& name) const {
    auto it = index_.find(name);
    if (it == index_.end()) {
      throw RecordingError(path_ + ": required column '" + name +
                           "' is missing from the header (a trace of "
                           "`vmhaptics hw record` has t_s and q1_rad..q6_rad)");
    }
    return it->second;
  }
  std::size_t optional(const std::string& name) const {
    auto it = index_.find(name);
    return it == index_.end() ? SIZE_MAX : it->second;
  }
  // a group of columns that are there together or not at all
  template <std::size_t N>
  bool group(const std::vector<std::string>& names, const std::string& what,
             std::array<std::size_t, N>* at) const {
    std::size_t found = 0;
    std::string have, lack;
    for (std::size_t i = 0; i < N; ++i) {
      (*at)[i] = optional(names[i]);
      if ((*at)[i] != SIZE_MAX) {
        ++found;
        if (have.empty()) have = names[i];
      } else if (lack.empty()) {
        lack = names[i];
      }
    }
    if (found == 0) return false;
    if (found < N) {
      throw RecordingError(path_ + ": column '" + lack + "' is missing (" +
                           have + " is there: " + what +
                           " needs all its columns)");
    }
    return true;
  }

  std::string where(long line, std::size_t col) const {
    return path_ + ":" + std::to_string(line) + ":" + std::to_string(col + 1) +
           " (" + header_[col] + ")";
  }

  // the cell as a number (nan and inf parse; the caller says whether they
  // may be there)
  double number(const std::vector<std::string>& cells, long line,
                std::size_t col) const {
    const std::string& c = cells[col];
    char* end = nullptr;
    const double v = c.empty() ? 0.0 : std::strtod(c.c_str(), &end);
    if (c.empty() || end != c.c_str() + c.size() || std::isspace(
                                                        static_cast<unsigned char>(c[0]))) {
      throw RecordingError(where(line, col) + ": '" + c + "' is not a number");
    }
    return v;
  }
  double finite(const std::vector<std::string>& cells, long line,
                std::size_t col) const {
    const double v = number(cells, line, col);
    if (!std::isfinite(v)) {
      throw RecordingError(where(line, col) + ": " + cells[col] +
                           " where a good reading has a finite number");
    }
    return v;
  }
  std::int64_t integer(const std::vector<std::string>& cells, long line,
                       std::size_t col, double lo, double hi) const {
    const double v = finite(cells, line, col);
    if (v != std::floor(v) || v < lo || v > hi) {
      char buf[96];
      std::snprintf(buf, sizeof buf, ": %s is not an integer in [%.0f, %.0f]",
                    cells[col].c_str(), lo, hi);
      throw RecordingError(where(line, col) + buf);
    }
    return static_cast<std::int64_t>(v);
  }

 private:
  std::string path_;
  const std::vector<std::string>& header_;
  std::map<std::string, std::size_t> index_;
};

std::vector<std::string> names(const std::string& prefix, const char* const* parts,
                               int n, const std::string& suffix) {
  std::vector<std::string> v;
  for (int i = 0; i < n; ++i) v.push_back(prefix + parts[i] + suffix);
  return v;
}

void read_meta(const std::string& path, const RecordingLimits& limits,
               Recording* rec) {
  bool missing = false;
  std::FILE* f = open_regular(path, limits.max_meta_bytes, &missing);
  if (missing) return;
  FileCloser closer{f};
  std::string text;
  char buf[65536];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) {
    text.append(buf, n);
    if (text.size() > limits.max_meta_bytes) {
      throw RecordingError(path + " grew over the replay's bound of " +
                           bytes_text(limits.max_meta_bytes));
    }
  }
  if (std::ferror(f)) throw RecordingError(path + ": read failed");
  nlohmann::json m;
  try {
    m = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw RecordingError(path + ": not JSON: " + e.what());
  }
  if (!m.is_object()) throw RecordingError(path + ": not a JSON object");
  rec->has_meta = true;
  const auto text_of = [](const nlohmann::json& o, const char* key) {
    auto it = o.find(key);
    return it != o.end() && it->is_string() ? it->get<std::string>() : std::string();
  };
  if (auto d = m.find("device"); d != m.end() && d->is_object()) {
    rec->recorded.backend = text_of(*d, "backend");
    rec->recorded.config = text_of(*d, "config");
    rec->recorded.model = text_of(*d, "model");
    rec->recorded.vendor = text_of(*d, "vendor");
    rec->recorded.serial = text_of(*d, "serial");
    rec->recorded.driver_version = text_of(*d, "driver_version");
    rec->recorded.firmware_version = text_of(*d, "firmware_version");
    rec->recorded.api_version = text_of(*d, "api_version");
  }
  // session.timing.nominal_period_us
  if (auto s = m.find("session"); s != m.end() && s->is_object()) {
    if (auto t = s->find("timing"); t != s->end() && t->is_object()) {
      if (auto p = t->find("nominal_period_us");
          p != t->end() && p->is_number()) {
        const double us = p->get<double>();
        if (std::isfinite(us) && us > 0.0) rec->nominal_period_s = 1e-6 * us;
      }
    }
  }
}

}  // namespace

bool parse_device_error(const std::string& name, DeviceError* e) {
  for (DeviceError d : {DeviceError::kOk, DeviceError::kNotConnected,
                        DeviceError::kIo, DeviceError::kTimeout,
                        DeviceError::kSensorFault, DeviceError::kInvalidCommand}) {
    if (name == device_error_name(d)) {
      *e = d;
      return true;
    }
  }
  return false;
}

double Recording::last_hold_s() const {
  if (nominal_period_s > 0.0) return nominal_period_s;
  if (rows() >= 2) return time_s[rows() - 1] - time_s[rows() - 2];
  return 1e-3;
}

std::size_t Recording::row_at(double t_s) const noexcept {
  if (time_s.empty()) return 0;
  const double tol = 1e-8 * (1.0 + std::fabs(t_s));
  const auto it = std::upper_bound(time_s.begin(), time_s.end(), t_s + tol);
  if (it == time_s.begin()) return 0;
  return static_cast<std::size_t>(it - time_s.begin()) - 1;
}

DeviceError Recording::state_of(std::size_t i, DeviceState* st) const noexcept {
  if (i >= rows()) {
    st->present = 0;
    return DeviceError::kNotConnected;
  }
  if (read_error[i] != DeviceError::kOk) {
    st->present = 0;
    return read_error[i];
  }
  st->present = kStateJoints | present;
  st->q_device_rad = q_device_rad[i];
  st->rehomed = false;
  if (present & kStateButtons) st->buttons = buttons[i];
  if (present & kStateInkwell) st->docked = docked[i] != 0;
  if (present & kStateTransform) {
    const auto& m = transform[i];
    st->transform_mm.setIdentity();
    for (int r = 0; r < 3; ++r) {
      st->transform_mm(r, 3) = m[static_cast<std::size_t>(r)];
      for (int c = 0; c < 3; ++c) {
        st->transform_mm(r, c) = m[static_cast<std::size_t>(3 + 3 * r + c)];
      }
    }
  }
  if (present & kStateVelocity) {
    for (int k = 0; k < 3; ++k) {
      st->velocity_mm_s[k] = velocity_mm_s[i][static_cast<std::size_t>(k)];
    }
  }
  if (present & kStateJacobian) {
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) {
        st->jacobian(r, c) = jacobian[i][static_cast<std::size_t>(6 * r + c)];
      }
    }
  }
  if (present & kStateEncoders) st->encoder_counts = encoders[i];
  if (present & kStatePots) st->gimbal_pots = pots[i];
  return DeviceError::kOk;
}

Recording read_recording(const std::string& folder, const RecordingLimits& limits) {
  Recording rec;
  if (folder.empty()) {
    throw RecordingError("replay: no recording folder given (replay:DIR, DIR "
                         "written by `vmhaptics hw record --out DIR`)");
  }
  struct stat st {};
  if (::stat(folder.c_str(), &st) != 0) {
    throw RecordingError("replay: recording folder '" + folder + "': " +
                         (errno == ENOENT ? std::string("no such folder")
                                          : errno_text(errno)));
  }
  if (!S_ISDIR(st.st_mode)) {
    throw RecordingError("replay: '" + folder + "' is " +
                         (S_ISREG(st.st_mode) ? std::string("a file")
                                              : report::file_kind(st.st_mode)) +
                         ", not a folder; give the folder `vmhaptics hw "
                         "record --out DIR` wrote");
  }
  std::error_code ec;
  rec.folder = fs::absolute(folder, ec).lexically_normal().string();
  if (ec) rec.folder = folder;
  rec.trace_file = (fs::path(rec.folder) / "trace.csv").string();

  bool missing = false;
  std::FILE* f = open_regular(rec.trace_file, limits.max_trace_bytes, &missing);
  if (missing) {
    throw RecordingError("replay: no trace.csv in '" + rec.folder +
                         "' (a recording is the folder `vmhaptics hw record "
                         "--out DIR` wrote)");
  }
  FileCloser closer{f};
  LineReader lines(f, rec.trace_file, limits.max_trace_bytes);
  std::string line;
  std::vector<std::string> header;
  if (!lines.next(&line) || line.empty()) {
    throw RecordingError(rec.trace_file + " is empty: no header line");
  }
  split(line, &header);
  const TraceParser p(rec.trace_file, header);
  Layout L;
  L.t = p.required("t_s");
  for (int i = 0; i < 6; ++i) {
    L.q[static_cast<std::size_t>(i)] = p.required("q" + std::to_string(i + 1) + "_rad");
  }
  L.read_error = p.optional("read_error");
  L.buttons = p.optional("buttons");
  L.docked = p.optional("docked");
  if (L.buttons != SIZE_MAX) rec.present |= kStateButtons;
  if (L.docked != SIZE_MAX) rec.present |= kStateInkwell;
  {
    std::vector<std::string> n = names("dev_p_", kXyz, 3, "_mm");
    for (int r = 1; r <= 3; ++r) {
      for (int c = 1; c <= 3; ++c) {
        n.push_back("dev_R_" + std::to_string(r) + std::to_string(c));
      }
    }
    if (p.group(n, "the device's transform (dev_p_*_mm, dev_R_11..33)",
                &L.transform)) {
      rec.present |= kStateTransform;
    }
  }
  if (p.group(names("dev_v_", kXyz, 3, "_mm_s"),
              "the device's velocity (dev_v_*_mm_s)", &L.velocity)) {
    rec.present |= kStateVelocity;
  }
  {
    std::vector<std::string> n;
    for (int r = 1; r <= 6; ++r) {
      for (int c = 1; c <= 6; ++c) {
        n.push_back("dev_J_" + std::to_string(r) + std::to_string(c));
      }
    }
    if (p.group(n, "the device's Jacobian (dev_J_11..66)", &L.jacobian)) {
      rec.present |= kStateJacobian;
    }
  }
  {
    const char* const e[] = {"1", "2", "3"};
    const char* const q[] = {"4", "5", "6"};
    if (p.group(names("enc_", e, 3, ""), "the encoder counts (enc_1..3)", &L.enc)) {
      rec.present |= kStateEncoders;
    }
    if (p.group(names("pot_", q, 3, ""), "the gimbal pots (pot_4..6)", &L.pot)) {
      rec.present |= kStatePots;
    }
  }

  std::vector<std::string> cells;
  while (lines.next(&line)) {
    const long ln = lines.line_no();
    if (rec.rows() >= limits.max_rows) {
      throw RecordingError(rec.trace_file + ":" + std::to_string(ln) +
                           ": more than " + std::to_string(limits.max_rows) +
                           " rows, the replay's bound");
    }
    split(line, &cells);
    if (cells.size() != header.size()) {
      throw RecordingError(rec.trace_file + ":" + std::to_string(ln) + ": " +
                           std::to_string(cells.size()) + " cells, the header has " +
                           std::to_string(header.size()));
    }
    const double t = p.finite(cells, ln, L.t);
    if (!rec.time_s.empty() && !(t > rec.time_s.back())) {
      char buf[128];
      std::snprintf(buf, sizeof buf,
                    ": %.9g is not after the previous row's %.9g (time must "
                    "increase)",
                    t, rec.time_s.back());
      throw RecordingError(p.where(ln, L.t) + buf);
    }
    DeviceError err = DeviceError::kOk;
    if (L.read_error != SIZE_MAX && !parse_device_error(cells[L.read_error], &err)) {
      throw RecordingError(p.where(ln, L.read_error) + ": '" +
                           cells[L.read_error] + "' is not a read error's name "
                           "(ok, not_connected, io, timeout, sensor_fault, "
                           "invalid_command)");
    }
    const bool good = err == DeviceError::kOk;
    // a good row's values must be finite numbers; a failed read's may be nan
    const auto value = [&](std::size_t col) {
      return good ? p.finite(cells, ln, col) : p.number(cells, ln, col);
    };
    Joints q_dh;
    for (int i = 0; i < 6; ++i) q_dh[i] = value(L.q[static_cast<std::size_t>(i)]);
    rec.time_s.push_back(t);
    rec.read_error.push_back(err);
    rec.q_device_rad.push_back(good ? dh_to_device_joints(q_dh)
                                    : Joints::Constant(std::nan("")));
    // the switches are written on every row, good or not
    if (rec.present & kStateButtons) {
      rec.buttons.push_back(
          static_cast<std::uint32_t>(p.integer(cells, ln, L.buttons, 0, 4294967295.0)));
    }
    if (rec.present & kStateInkwell) {
      rec.docked.push_back(static_cast<std::uint8_t>(p.integer(cells, ln, L.docked, 0, 1)));
    }
    if (rec.present & kStateTransform) {
      std::array<double, 12> m{};
      for (std::size_t k = 0; k < 12; ++k) m[k] = value(L.transform[k]);
      rec.transform.push_back(m);
    }
    if (rec.present & kStateVelocity) {
      std::array<double, 3> v{};
      for (std::size_t k = 0; k < 3; ++k) v[k] = value(L.velocity[k]);
      rec.velocity_mm_s.push_back(v);
    }
    if (rec.present & kStateJacobian) {
      std::array<double, 36> j{};
      for (std::size_t k = 0; k < 36; ++k) j[k] = value(L.jacobian[k]);
      rec.jacobian.push_back(j);
    }
    constexpr double kI32Lo = -2147483648.0, kI32Hi = 2147483647.0;
    if (rec.present & kStateEncoders) {
      std::array<std::int32_t, 3> e{};
      for (std::size_t k = 0; k < 3; ++k) {
        e[k] = static_cast<std::int32_t>(p.integer(cells, ln, L.enc[k], kI32Lo, kI32Hi));
      }
      rec.encoders.push_back(e);
    }
    if (rec.present & kStatePots) {
      std::array<std::int32_t, 3> e{};
      for (std::size_t k = 0; k < 3; ++k) {
        e[k] = static_cast<std::int32_t>(p.integer(cells, ln, L.pot[k], kI32Lo, kI32Hi));
      }
      rec.pots.push_back(e);
    }
  }
  if (rec.rows() == 0) {
    throw RecordingError(rec.trace_file +
                         ": no rows after the header: the recording is empty");
  }
  read_meta((fs::path(rec.folder) / "meta.json").string(), limits, &rec);
  return rec;
}

}  // namespace vmh::hw::replay
