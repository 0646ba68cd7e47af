#include "runtime/recording_reader.h"

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "output/output_file.h"

namespace vmh::runtime {
namespace {

constexpr std::size_t kReadChunk = std::size_t{1} << 20;
// the largest finite double: a bound that only says "finite"
constexpr double kHuge = std::numeric_limits<double>::max();

using output::bytes_text;

// a cell, shown in a message: at most 40 characters, control characters
// escaped, so that a binary file's bytes do not end up on the terminal
std::string shown(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c >= 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  if (s.size() > 40) out += "...";
  return out;
}

// ---- meta.json's schema --------------------------------------------------

class MetaChecker {
 public:
  MetaChecker(const Json& j, std::string path) : j_(j), path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw RecordingError(path_ + ": key '" + key + "': " + what);
  }
  // the value at a dotted key's last part, or nullptr
  static const Json* child(const Json& o, const char* key) {
    const auto it = o.find(key);
    return it == o.end() ? nullptr : &*it;
  }
  std::string text(const Json& o, const char* key, const std::string& name,
                   bool nullable = false) const {
    const Json* v = child(o, key);
    if (v == nullptr || (nullable && v->is_null())) return {};
    if (!v->is_string()) fail(name, std::string("must be a string, not ") + v->type_name());
    return v->get<std::string>();
  }
  // a finite number in [lo, hi] (lo excluded when open_lo), or NaN when
  // the key is not there
  double number(const Json& o, const char* key, const std::string& name,
                double lo, double hi, bool open_lo = false) const {
    const Json* v = child(o, key);
    if (v == nullptr) return std::nan("");
    if (!v->is_number()) fail(name, std::string("must be a number, not ") + v->type_name());
    const double x = v->get<double>();
    if (!std::isfinite(x) || x < lo || x > hi || (open_lo && x == lo)) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "%s is not a finite number in %s%g, %g]",
                    v->dump().substr(0, 40).c_str(), open_lo ? "(" : "[", lo, hi);
      fail(name, buf);
    }
    return x;
  }
  // a whole number in [lo, hi], or `absent` when the key is not there
  long long integer(const Json& o, const char* key, const std::string& name,
                    long long lo, long long hi, long long absent) const {
    const Json* v = child(o, key);
    if (v == nullptr) return absent;
    if (!v->is_number_integer()) {
      fail(name, v->dump().substr(0, 40) + " is not a whole number in [" +
                     std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    // a uint64 beyond int64 reads as negative: check it as unsigned first
    if (v->is_number_unsigned() && v->get<unsigned long long>() >
                                       static_cast<unsigned long long>(hi)) {
      fail(name, v->dump() + " is not in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "]");
    }
    const long long x = v->get<long long>();
    if (x < lo || x > hi) {
      fail(name, std::to_string(x) + " is not in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "]");
    }
    return x;
  }
  const Json* object(const Json& o, const char* key, const std::string& name) const {
    const Json* v = child(o, key);
    if (v == nullptr) return nullptr;
    if (!v->is_object()) fail(name, std::string("must be an object, not ") + v->type_name());
    return v;
  }
  void only_for(const char* key, const std::string& verb, const char* owner) const {
    if (child(j_, key) != nullptr && verb != owner) {
      fail(key, "a '" + verb + "' recording has no " + key + " (only '" + owner +
                    "' writes it): meta.json does not belong to this recording");
    }
  }

 private:
  const Json& j_;
  std::string path_;
};

}  // namespace

int open_regular_file(const std::string& path, std::uint64_t max_bytes,
                      bool* missing) {
  try {
    return output::open_regular_file(path, max_bytes, missing);
  } catch (const std::runtime_error& e) {
    throw RecordingError(e.what());
  }
}

std::string read_regular_file(const std::string& path, std::uint64_t max_bytes,
                              bool* missing) {
  try {
    return output::read_regular_file(path, max_bytes, missing);
  } catch (const std::runtime_error& e) {
    throw RecordingError(e.what());
  }
}

namespace {

// "verb": there, a string, and one of the verbs that write a recording
std::string meta_verb(const MetaChecker& c, const Json& j,
                      const std::string& path) {
  const Json* verb = MetaChecker::child(j, "verb");
  if (verb == nullptr) {
    throw RecordingError(path + ": no key 'verb' (not written by vmhaptics hw)");
  }
  if (!verb->is_string()) c.fail("verb", std::string("must be a string, not ") + verb->type_name());
  std::string name = verb->get<std::string>();
  bool known = false;
  for (const char* v : kRecordingVerbs) known |= name == v;
  if (!known) {
    c.fail("verb", "'" + shown(name) +
                       "' is not a verb that writes a recording (hw record, hw "
                       "motor-test, hw run)");
  }
  return name;
}

// "recording_format" (this reader's when absent), "software" (vmhaptics,
// a version string) and "date_utc": what wrote the recording
void check_writer(const MetaChecker& c, const Json& j) {
  const long long format = c.integer(j, "recording_format", "recording_format",
                                     0, 1'000'000, kRecordingFormat);
  if (format != kRecordingFormat) {
    c.fail("recording_format",
           std::to_string(format) + " is a format this reader does not know "
           "(it reads " + std::to_string(kRecordingFormat) +
           "): read it with the vmhaptics that wrote it");
  }
  if (const Json* s = c.object(j, "software", "software")) {
    if (MetaChecker::child(*s, "name") != nullptr &&
        c.text(*s, "name", "software.name") != "vmhaptics") {
      c.fail("software.name", "'" + shown(c.text(*s, "name", "software.name")) +
                                  "' is not vmhaptics");
    }
    c.text(*s, "version", "software.version");
  }
  c.text(j, "date_utc", "date_utc");
}

// "device": the identity of the device recorded
void read_device(const MetaChecker& c, const Json& d, DeviceIdentity* device) {
  device->backend = c.text(d, "backend", "device.backend");
  device->config = c.text(d, "config", "device.config");
  device->model = c.text(d, "model", "device.model");
  device->vendor = c.text(d, "vendor", "device.vendor");
  device->serial = c.text(d, "serial", "device.serial");
  device->driver_version = c.text(d, "driver_version", "device.driver_version");
  device->firmware_version =
      c.text(d, "firmware_version", "device.firmware_version");
  device->api_version = c.text(d, "api_version", "device.api_version");
  device->input_dof =
      static_cast<int>(c.integer(d, "input_dof", "device.input_dof", 0, 6, 0));
  device->output_dof = static_cast<int>(
      c.integer(d, "output_dof", "device.output_dof", 0, 6, 0));
}

// "session": its duration, ticks and nominal period
void read_session(const MetaChecker& c, const Json& s, RecordingMeta* m) {
  m->duration_s = c.number(s, "duration_s", "session.duration_s", 0.0, 1e7);
  c.integer(s, "ticks", "session.ticks", 0, 1'000'000'000'000LL, 0);
  if (const Json* t = c.object(s, "timing", "session.timing")) {
    const double us =
        c.number(*t, "nominal_period_us", "session.timing.nominal_period_us",
                 0.0, 1e6, true);
    if (std::isfinite(us)) m->nominal_period_s = 1e-6 * us;
  }
}

// the keys only one verb writes: refused in another verb's recording
void check_verb_keys(const MetaChecker& c, const std::string& verb) {
  c.only_for("motor", verb, "hw motor-test");
  c.only_for("torque_asked_mNm", verb, "hw motor-test");
  c.only_for("pulse_ms", verb, "hw motor-test");
  c.only_for("sets", verb, "hw run");
  c.only_for("gain_scale", verb, "hw run");
  c.only_for("case", verb, "hw run");
}

// hw motor-test's keys: the motor pulsed (required), the torque asked for,
// the pulse's length
void read_motor_test(const MetaChecker& c, const Json& j, RecordingMeta* m) {
  m->motor = static_cast<int>(c.integer(j, "motor", "motor", 1, 3, 0));
  if (m->motor == 0) {
    c.fail("motor", "missing: a motor test's meta.json names the motor it "
                    "pulsed (1, 2 or 3)");
  }
  m->torque_asked_mNm =
      c.number(j, "torque_asked_mNm", "torque_asked_mNm", -kHuge, kHuge);
  m->pulse_ms = c.number(j, "pulse_ms", "pulse_ms", 0.0, 1e4, true);
}

// hw run's keys: the case, its scene, its --set overrides, the gain scale
void read_run(const MetaChecker& c, const Json& j, RecordingMeta* m) {
  m->case_name = c.text(j, "case", "case");
  m->scene = c.text(j, "scene", "scene");
  if (const Json* s = MetaChecker::child(j, "sets")) {
    if (!s->is_array()) c.fail("sets", std::string("must be an array of strings, not ") + s->type_name());
    for (std::size_t i = 0; i < s->size(); ++i) {
      if (!(*s)[i].is_string()) {
        c.fail("sets[" + std::to_string(i) + "]",
               std::string("must be a string, not ") + (*s)[i].type_name());
      }
      m->sets.push_back((*s)[i].get<std::string>());
    }
  }
  m->gain_scale = c.number(j, "gain_scale", "gain_scale", 0.0, kHuge);
}

}  // namespace

RecordingMeta parse_recording_meta(const Json& j, const std::string& path) {
  if (!j.is_object()) {
    throw RecordingError(path + ": not a JSON object (a recording's meta.json "
                         "is one)");
  }
  const MetaChecker c(j, path);
  RecordingMeta m;
  m.json = j;
  m.verb = meta_verb(c, j, path);
  check_writer(c, j);
  if (const Json* d = c.object(j, "device", "device")) {
    read_device(c, *d, &m.device);
  }
  if (const Json* s = c.object(j, "session", "session")) {
    read_session(c, *s, &m);
  }
  check_verb_keys(c, m.verb);
  if (m.verb == "hw motor-test") read_motor_test(c, j, &m);
  if (m.verb == "hw run") {
    read_run(c, j, &m);
  } else if (MetaChecker::child(j, "scene") != nullptr) {
    c.text(j, "scene", "scene");
  }
  if (const Json* e = MetaChecker::child(j, "emulator"); e != nullptr && !e->is_null()) {
    if (!e->is_object()) c.fail("emulator", std::string("must be an object, not ") + e->type_name());
    m.emulator_scene = c.text(*e, "scene", "emulator.scene", true);
    c.text(*e, "hand", "emulator.hand", true);
  }
  return m;
}

RecordingMeta read_recording_meta(const std::string& path,
                                  const RecordingLimits& limits, bool* missing) {
  const std::string text = read_regular_file(path, limits.max_meta_bytes, missing);
  if (*missing) return {};
  Json j;
  try {
    j = Json::parse(text);
  } catch (const Json::exception& e) {
    throw RecordingError(path + ": not valid JSON (" + e.what() + ")");
  }
  return parse_recording_meta(j, path);
}

// ---- trace.csv -----------------------------------------------------------

TraceReader::TraceReader(std::string path, const RecordingLimits& limits)
    : path_(std::move(path)), limits_(limits) {
  bool missing = false;
  fd_ = open_regular_file(path_, limits_.max_trace_bytes, &missing);
  if (missing) throw RecordingError(path_ + ": no such file");
  buf_.resize(kReadChunk);
  std::string_view header;
  if (!read_line(&header) || header.empty()) {
    throw RecordingError(path_ + " is empty: no header line");
  }
  split(header);
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    const std::string name(cells_[i]);
    if (name.empty()) {
      throw RecordingError(path_ + ":1:" + std::to_string(i + 1) +
                           ": a column has no name");
    }
    if (!index_.emplace(name, i).second) {
      throw RecordingError(path_ + ":1:" + std::to_string(i + 1) + ": column '" +
                           shown(name) + "' appears twice");
    }
    columns_.push_back(name);
  }
  t_col_ = require("t_s");
  cells_.clear();
}

TraceReader::~TraceReader() {
  if (fd_ >= 0) ::close(fd_);
}

std::size_t TraceReader::find(const std::string& name) const {
  const auto it = index_.find(name);
  return it == index_.end() ? npos : it->second;
}

std::size_t TraceReader::require(const std::string& name) const {
  const std::size_t i = find(name);
  if (i == npos) {
    throw RecordingError(path_ + ": required column '" + name +
                         "' is missing from the header");
  }
  return i;
}

// One line into *line (without '\n' or a '\r' before it), false at the
// end. A line that does not fit the buffer's rest is gathered in line_.
bool TraceReader::read_line(std::string_view* line) {
  line_.clear();
  bool gathering = false;
  for (;;) {
    const char* from = buf_.data() + begin_;
    const auto* nl = static_cast<const char*>(std::memchr(from, '\n', end_ - begin_));
    const std::size_t take = nl ? static_cast<std::size_t>(nl - from) : end_ - begin_;
    if ((gathering ? line_.size() : 0) + take > limits_.max_line_bytes) {
      throw RecordingError(path_ + ":" + std::to_string(line_no_ + 1) +
                           ": line longer than the reader's bound of " +
                           bytes_text(limits_.max_line_bytes));
    }
    if (nl != nullptr) {
      ++line_no_;
      last_line_ended_ = true;
      begin_ += take + 1;
      std::string_view v;
      if (gathering) {
        line_.append(from, take);
        v = line_;
      } else {
        v = std::string_view(from, take);
      }
      if (!v.empty() && v.back() == '\r') v.remove_suffix(1);
      check_no_carriage_return(v);
      *line = v;
      return true;
    }
    // no line end in what is buffered: keep it and read on
    if (take > 0) {
      line_.append(from, take);
      gathering = true;
    }
    begin_ = end_ = 0;
    if (eof_) {
      if (!gathering) return false;
      ++line_no_;
      last_line_ended_ = false;
      std::string_view v = line_;
      if (!v.empty() && v.back() == '\r') v.remove_suffix(1);
      check_no_carriage_return(v);
      *line = v;
      return true;
    }
    ssize_t n;
    do {
      n = ::read(fd_, buf_.data(), buf_.size());
    } while (n < 0 && errno == EINTR);
    if (n < 0) throw RecordingError(path_ + ": " + std::strerror(errno));
    if (n == 0) {
      eof_ = true;
      continue;
    }
    bytes_read_ += static_cast<std::uint64_t>(n);
    if (bytes_read_ > limits_.max_trace_bytes) {
      throw RecordingError(path_ + " grew over the reader's bound of " +
                           bytes_text(limits_.max_trace_bytes) +
                           " while it was read");
    }
    end_ = static_cast<std::size_t>(n);
  }
}

// A carriage return is allowed only as the CR of a CRLF line end (taken
// off before this): one inside a line would end up in a cell, where a
// column name or a number carries it unseen.
void TraceReader::check_no_carriage_return(std::string_view line) const {
  const auto* cr = static_cast<const char*>(std::memchr(line.data(), '\r', line.size()));
  if (cr == nullptr) return;
  throw RecordingError(path_ + ":" + std::to_string(line_no_) + ":" +
                       std::to_string(cr - line.data() + 1) +
                       ": a carriage return inside the line (only a CRLF line "
                       "end may hold one)");
}

void TraceReader::split(std::string_view line) {
  cells_.clear();
  std::size_t from = 0;
  for (;;) {
    const std::size_t comma = line.find(',', from);
    if (comma == std::string_view::npos) {
      cells_.push_back(line.substr(from));
      return;
    }
    cells_.push_back(line.substr(from, comma - from));
    from = comma + 1;
  }
}

bool TraceReader::next() {
  std::string_view line;
  for (;;) {
    if (!read_line(&line)) return false;
    if (!line.empty()) break;
  }
  split(line);
  if (cells_.size() != columns_.size()) {
    if (!last_line_ended_ && cells_.size() < columns_.size()) {
      // the last row, cut short where the writer stopped
      cut_short_ = true;
      cells_.clear();
      return false;
    }
    throw RecordingError(path_ + ":" + std::to_string(line_no_) + ": " +
                         std::to_string(cells_.size()) + " cells, the header has " +
                         std::to_string(columns_.size()));
  }
  if (rows_ >= limits_.max_rows) {
    throw RecordingError(path_ + ":" + std::to_string(line_no_) +
                         ": more than " + std::to_string(limits_.max_rows) +
                         " rows, the reader's bound (an hour at 1 kHz)");
  }
  const double t = number(t_col_);
  if (!std::isfinite(t)) {
    throw RecordingError(where(t_col_) + ": " + shown(cells_[t_col_]) +
                         " is not a finite time");
  }
  if (!(t > t_s_)) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  ": %.9g does not come after the row before's %.9g (t_s must "
                  "increase from row to row)",
                  t, t_s_);
    throw RecordingError(where(t_col_) + buf);
  }
  t_s_ = t;
  ++rows_;
  return true;
}

std::string TraceReader::where(std::size_t col) const {
  return path_ + ":" + std::to_string(line_no_) + ":" + std::to_string(col + 1) +
         " (" + columns_[col] + ")";
}

double TraceReader::number(std::size_t col) const {
  const std::string_view c = cells_[col];
  double v = 0.0;
  bool ok = !c.empty();
  if (ok) {
    // from_chars takes "nan" and "inf" but not a sign on them, nor a '+'
    std::string_view body = c;
    const bool neg = body.front() == '-';
    if (neg) body.remove_prefix(1);
    ok = !body.empty() && body.front() != '-';
    const auto r = std::from_chars(body.data(), body.data() + body.size(), v);
    ok = ok && r.ec != std::errc::invalid_argument && r.ptr == body.data() + body.size();
    if (r.ec == std::errc::result_out_of_range) {
      // beyond double's range: as strtod, an infinity or a zero
      v = std::strtod(std::string(body).c_str(), nullptr);
    }
    if (neg) v = -v;
  }
  if (!ok) {
    throw RecordingError(where(col) + ": '" + shown(c) + "' is not a number");
  }
  return v;
}

double TraceReader::finite(std::size_t col) const {
  const double v = number(col);
  if (!std::isfinite(v)) {
    throw RecordingError(where(col) + ": " + shown(cells_[col]) +
                         " where a finite number belongs");
  }
  return v;
}

std::int64_t TraceReader::integer(std::size_t col, double lo, double hi) const {
  const double v = finite(col);
  if (v != std::floor(v) || v < lo || v > hi) {
    char buf[96];
    std::snprintf(buf, sizeof buf, ": %s is not a whole number in [%.0f, %.0f]",
                  shown(cells_[col]).c_str(), lo, hi);
    throw RecordingError(where(col) + buf);
  }
  return static_cast<std::int64_t>(v);
}

}  // namespace vmh::runtime
