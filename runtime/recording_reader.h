// Reading a recording back: the folder a `hw record | motor-test | run`
// session wrote (meta.json beside trace.csv: runtime/meta.h,
// runtime/trace_writer.h, docs/outputs.md "hw"). The one reader under
// every verb that reads recordings (compare, identify, the replay device)
// treats the files as untrusted input:
//
//   - only regular files: a FIFO, a device, a folder or a socket is
//     refused by its type before a byte is read, and the file is opened
//     with O_NONBLOCK and checked again with fstat, so one swapped in
//     between the two cannot block the reader;
//   - sizes bounded before and while reading (RecordingLimits): meta.json's
//     size, trace.csv's size, its longest line and its number of rows;
//   - the header's columns named and each named once, t_s among them;
//   - every row complete (a last row cut short by a crash, without its
//     line end, is dropped), t_s finite and strictly increasing;
//   - meta.json an object that matches the recording schema
//     (runtime/recording_meta.h), from a verb that writes recordings and a
//     format this reader knows.
//
// Every refusal is a RecordingError whose one-line message names the file,
// the line and column (or the JSON key) and what was wrong. Pure: files
// in, values out; no MuJoCo, no clock.
#ifndef VMHAPTICS_RUNTIME_RECORDING_READER_H_
#define VMHAPTICS_RUNTIME_RECORDING_READER_H_

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "device/device_backend.h"
#include "runtime/json_util.h"
#include "runtime/recording_meta.h"

namespace vmh::runtime {

// The bounds a recording is read within. The defaults admit an hour at
// 1 kHz with every optional column group (about 1.3 kB a row).
struct RecordingLimits {
  std::uint64_t max_meta_bytes = std::uint64_t{1} << 20;
  std::uint64_t max_trace_bytes = std::uint64_t{8} << 30;
  std::size_t max_line_bytes = std::size_t{1} << 16;
  std::size_t max_rows = 3'600'001;
};

// A recording that cannot be read. A DeviceOpenError, so that replaying
// one is refused as a device that cannot be opened is (exit 2).
class RecordingError : public DeviceOpenError {
 public:
  using DeviceOpenError::DeviceOpenError;
};

// Opens `path` for reading if it is a regular file of at most max_bytes:
// returns the descriptor (O_RDONLY | O_NONBLOCK | O_CLOEXEC), or -1 with
// *missing = true when nothing is there. Throws RecordingError naming the
// path and what is there instead (a FIFO, a character device, ...), its
// size against the bound, or the OS error.
int open_regular_file(const std::string& path, std::uint64_t max_bytes,
                      bool* missing);

// The whole of a regular file of at most max_bytes (open_regular_file),
// read through the descriptor with the bound checked as it is read.
// Throws RecordingError; *missing as above.
std::string read_regular_file(const std::string& path, std::uint64_t max_bytes,
                              bool* missing);

// ---- meta.json -------------------------------------------------------------

// Reads and validates folder/meta.json. Throws RecordingError; *missing =
// true (and an empty meta) when the file is not there.
RecordingMeta read_recording_meta(const std::string& path,
                                  const RecordingLimits& limits, bool* missing);

// ---- trace.csv -------------------------------------------------------------

// trace.csv row by row: the header read and checked on construction, then
// next() until it returns false. The row's cells are views into the
// reader's buffer, valid until the next call to next().
class TraceReader {
 public:
  // Opens and reads the header. Throws RecordingError for a file that is
  // missing, not regular, too large, empty, or whose header has an empty
  // or a repeated column name or no t_s.
  TraceReader(std::string path, const RecordingLimits& limits);
  ~TraceReader();
  TraceReader(const TraceReader&) = delete;
  TraceReader& operator=(const TraceReader&) = delete;

  const std::string& path() const { return path_; }
  const std::vector<std::string>& columns() const { return columns_; }
  // the column's index, or npos when the trace has no such column
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);
  std::size_t find(const std::string& name) const;
  // the column's index; throws RecordingError naming the file and column
  std::size_t require(const std::string& name) const;

  // The next complete row, checked (its cell count, t_s finite and larger
  // than the row before's, the row bound). False at the end: a last line
  // without its '\n' and with too few cells is a row cut short by a crash
  // or a full disk and is dropped (cut_short() says so). Blank lines are
  // skipped. Throws RecordingError naming the line.
  bool next();
  const std::vector<std::string_view>& cells() const { return cells_; }
  std::size_t rows() const { return rows_; }  // rows returned so far
  long line() const { return line_no_; }      // the current row's line, 1-based
  double t_s() const { return t_s_; }         // the current row's time
  bool cut_short() const { return cut_short_; }

  // "<path>:<line>:<column number> (<name>)", for messages
  std::string where(std::size_t col) const;
  // The current row's cell as a number: "%.9g" text, "nan", "inf". Throws
  // naming the cell when it is empty or not a whole number text.
  double number(std::size_t col) const;
  // as number(), and finite
  double finite(std::size_t col) const;
  // as finite(), and a whole number in [lo, hi]
  std::int64_t integer(std::size_t col, double lo, double hi) const;

 private:
  bool read_line(std::string_view* line);
  void split(std::string_view line);
  // refuses a carriage return anywhere in line (its CRLF end is off)
  void check_no_carriage_return(std::string_view line) const;

  std::string path_;
  RecordingLimits limits_;
  int fd_ = -1;
  std::vector<char> buf_;
  std::size_t begin_ = 0, end_ = 0;  // unread bytes in buf_
  bool eof_ = false;
  bool last_line_ended_ = true;  // the line read last had its '\n'
  std::uint64_t bytes_read_ = 0;
  std::string line_;  // a line that crossed the buffer's end
  std::vector<std::string> columns_;
  std::unordered_map<std::string, std::size_t> index_;
  std::size_t t_col_ = 0;
  std::vector<std::string_view> cells_;
  std::size_t rows_ = 0;
  long line_no_ = 0;
  double t_s_ = -std::numeric_limits<double>::infinity();
  bool cut_short_ = false;
};

}  // namespace vmh::runtime

#endif  // VMHAPTICS_RUNTIME_RECORDING_READER_H_
