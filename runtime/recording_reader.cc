#include "runtime/recording_reader.h"

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "output/output_file.h"
#include "runtime/recording_detail.h"

namespace vmh::runtime {
namespace {

constexpr std::size_t kReadChunk = std::size_t{1} << 20;

using output::bytes_text;
using recording_detail::shown;

}  // namespace

namespace recording_detail {

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

}  // namespace recording_detail

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
