// libFuzzer harness: what the program reads from a recording folder and
// from the calibration store (runtime/recording_reader.h,
// runtime/calibration_store.h), the files a user hands it.
//
// The first byte picks the reader (modulo 3; the seeds use '0', '1', '2'),
// the rest is the file's content, written to a private temporary file:
//  0  trace.csv through TraceReader, with small bounds (4 KiB a line, 4096
//     rows). Checks: a refusal is a RecordingError (nothing else) whose
//     message names the file; the header has t_s, and no column name is
//     empty or repeated; every row has the header's number of cells and a
//     finite t_s larger than the row before's; rows() counts the rows
//     returned and stays within the bound; no cell holds '\n' and none ends
//     in '\r'; number() of a cell that parses is what strtod makes of it.
//  1  meta.json through read_recording_meta. Checks: a refusal is a
//     RecordingError naming the file; an accepted one has a verb of
//     kRecordingVerbs, a motor in 1..3 exactly for a motor test (0
//     otherwise), a gain scale that is NaN or finite >= 0, a nominal
//     period in [0, 1] s, dof counts in 0..6.
//  2  a stored calibration through load_calibration. Checks: a refusal is
//     a CalibrationError naming the file; an accepted one passes
//     check_calibration again (every value finite and within its range)
//     and its signs are +-1.
#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>

#include "runtime/calibration_store.h"
#include "runtime/recording_reader.h"
#include "tests/fuzz/fuzz_check.h"

namespace {

namespace fs = std::filesystem;
using namespace vmh::runtime;

// a private folder for this process's files, and XDG_CONFIG_HOME in it so
// that the calibration store reads from there
const std::string& scratch() {
  static const std::string dir = [] {
    char tmpl[] = "/tmp/vmh_recording_fuzz_XXXXXX";
    const char* d = ::mkdtemp(tmpl);
    if (d == nullptr) std::abort();
    ::setenv("XDG_CONFIG_HOME", d, 1);
    fs::create_directories(fs::path(d) / "vmhaptics" / "calibration");
    return std::string(d);
  }();
  return dir;
}

void put(const std::string& path, const std::uint8_t* data, std::size_t size) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) std::abort();
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n <= 0) std::abort();
    done += static_cast<std::size_t>(n);
  }
  ::close(fd);
}

bool names(const std::string& what, const std::string& path) {
  return what.find(path) != std::string::npos;
}

void fuzz_trace(const std::uint8_t* data, std::size_t size) {
  const std::string path = scratch() + "/trace.csv";
  put(path, data, size);
  RecordingLimits l;
  l.max_line_bytes = 4096;
  l.max_rows = 4096;
  try {
    TraceReader r(path, l);
    const auto& cols = r.columns();
    FUZZ_CHECK(r.find("t_s") != TraceReader::npos, "header without t_s accepted");
    for (std::size_t i = 0; i < cols.size(); ++i) {
      FUZZ_CHECK(!cols[i].empty(), "an unnamed column accepted");
      FUZZ_CHECK(r.find(cols[i]) == i, "column " + cols[i] + " found elsewhere");
    }
    double last = -INFINITY;
    std::size_t rows = 0;
    while (r.next()) {
      ++rows;
      FUZZ_CHECK(r.cells().size() == cols.size(), "row of the wrong length");
      FUZZ_CHECK(std::isfinite(r.t_s()) && r.t_s() > last,
                 "t_s not finite and increasing at line " + std::to_string(r.line()));
      last = r.t_s();
      for (std::size_t i = 0; i < r.cells().size(); ++i) {
        const std::string cell(r.cells()[i]);
        FUZZ_CHECK(cell.find('\n') == std::string::npos, "a cell holds a line end");
        FUZZ_CHECK(cell.empty() || cell.back() != '\r', "a cell ends in CR");
        try {
          const double v = r.number(i);
          // an accepted cell is all number, as strtod reads it
          char* end = nullptr;
          const double w = std::strtod(cell.c_str(), &end);
          FUZZ_CHECK(end == cell.c_str() + cell.size(), "'" + cell + "' accepted");
          FUZZ_CHECK((std::isnan(v) && std::isnan(w)) || v == w,
                     "'" + cell + "' read as something strtod does not make of it");
        } catch (const RecordingError& e) {
          FUZZ_CHECK(names(e.what(), path), std::string("no file named: ") + e.what());
        }
      }
    }
    FUZZ_CHECK(rows == r.rows() && rows <= l.max_rows, "row count");
  } catch (const RecordingError& e) {
    FUZZ_CHECK(names(e.what(), path), std::string("no file named: ") + e.what());
  }
}

void fuzz_meta(const std::uint8_t* data, std::size_t size) {
  const std::string path = scratch() + "/meta.json";
  put(path, data, size);
  try {
    bool missing = true;
    const RecordingMeta m = read_recording_meta(path, RecordingLimits{}, &missing);
    FUZZ_CHECK(!missing, "a file that is there read as missing");
    bool known = false;
    for (const char* v : kRecordingVerbs) known |= m.verb == v;
    FUZZ_CHECK(known, "verb '" + m.verb + "' accepted");
    FUZZ_CHECK((m.verb == "hw motor-test") == (m.motor >= 1 && m.motor <= 3) &&
                   (m.verb == "hw motor-test" || m.motor == 0),
               "motor " + std::to_string(m.motor) + " for " + m.verb);
    FUZZ_CHECK(std::isnan(m.gain_scale) ||
                   (std::isfinite(m.gain_scale) && m.gain_scale >= 0.0),
               "gain scale " + std::to_string(m.gain_scale));
    FUZZ_CHECK(m.nominal_period_s >= 0.0 && m.nominal_period_s <= 1.0,
               "period " + std::to_string(m.nominal_period_s));
    FUZZ_CHECK(m.device.input_dof >= 0 && m.device.input_dof <= 6 &&
                   m.device.output_dof >= 0 && m.device.output_dof <= 6,
               "dof");
  } catch (const RecordingError& e) {
    FUZZ_CHECK(names(e.what(), path), std::string("no file named: ") + e.what());
  }
}

void fuzz_calibration(const std::uint8_t* data, std::size_t size) {
  (void)scratch();  // sets XDG_CONFIG_HOME first
  const std::string path = calibration_path("fuzz");
  put(path, data, size);
  std::optional<StoredCalibration> c;
  try {
    c = load_calibration("fuzz");
  } catch (const CalibrationError& e) {
    FUZZ_CHECK(names(e.what(), path), std::string("no file named: ") + e.what());
    return;
  }
  FUZZ_CHECK(c.has_value(), "a file that is there read as missing");
  try {
    check_calibration(c->calibration, "accepted");
  } catch (const CalibrationError& e) {
    FUZZ_CHECK(false, std::string("an accepted calibration fails its check: ") +
                          e.what());
  }
  for (const int s : c->calibration.encoder_sign) {
    FUZZ_CHECK(s == 1 || s == -1, "sign " + std::to_string(s));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  switch (data[0] % 3) {
    case 0: fuzz_trace(data + 1, size - 1); break;
    case 1: fuzz_meta(data + 1, size - 1); break;
    default: fuzz_calibration(data + 1, size - 1); break;
  }
  return 0;
}
