// bringup/recording: a trace written by hand, read back; a bad one
// refused with the file and the cause named.
#include "bringup/recording.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace vmh::bringup {
namespace {

namespace fs = std::filesystem;

fs::path make_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("rec_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

// the RecordingError's message of reading d, "no error" if it reads
std::string refusal_of(const fs::path& d) {
  try {
    load_recording(d.string());
  } catch (const RecordingError& e) {
    return std::string(e.what());
  }
  return std::string("no error");
}

const char* kHeader =
    "t_s,period_s,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,tau_sent_1_Nm,"
    "tau_sent_2_Nm,tau_sent_3_Nm,read_error,dev_p_x_mm,dev_p_y_mm,dev_p_z_mm\n";

TEST(Recording, ReadsNumbersTextAndNaN) {
  const fs::path d = make_dir("ok");
  write(d / "meta.json", R"({"verb": "hw record"})");
  write(d / "trace.csv", std::string(kHeader) +
                             "0,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n"
                             "0.001,0.001,nan,nan,nan,nan,nan,nan,0,0,0,timeout,nan,nan,nan\n"
                             "0.002,0.001,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.02,ok,1.5,2,3\n");
  const Recording r = load_recording(d.string());
  EXPECT_EQ(r.verb, "hw record");
  ASSERT_EQ(r.rows, 3u);
  EXPECT_DOUBLE_EQ(r.q_dh_rad(2)[5], 0.6);
  EXPECT_TRUE(std::isnan(r.col("q1_rad")[1]));
  EXPECT_EQ(r.text_col("read_error")[1], "timeout");
  EXPECT_EQ(r.good_rows(), (std::vector<std::size_t>{0, 2}));
  EXPECT_TRUE(r.has_transform());
  EXPECT_FALSE(r.has_jacobian());
  EXPECT_DOUBLE_EQ(r.dev_p_mm(2).x(), 1.5);
  EXPECT_DOUBLE_EQ(r.tau_sent_Nm(2)[2], 0.02);
  EXPECT_EQ(r.emulator_scene(), "");  // a device names no scene
}

TEST(Recording, TheEmulatorsSceneComesFromMeta) {
  const fs::path d = make_dir("emu");
  write(d / "meta.json", R"({"verb": "hw record", "emulator": {"scene": "/m/case2.xml"}})");
  write(d / "trace.csv", std::string(kHeader) +
                             "0,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n");
  EXPECT_EQ(load_recording(d.string()).emulator_scene(), "/m/case2.xml");
}

TEST(Recording, ALastRowCutShortIsDropped) {
  const fs::path d = make_dir("cut");
  write(d / "meta.json", R"({"verb": "hw run"})");
  write(d / "trace.csv", std::string(kHeader) +
                             "0,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n"
                             "0.001,0.001,0.1,0.2");  // no line end: cut
  EXPECT_EQ(load_recording(d.string()).rows, 1u);
  // a short row that has its line end was written short: refused
  write(d / "trace.csv", std::string(kHeader) +
                             "0,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n"
                             "0.001,0.001,0.1,0.2\n");
  EXPECT_NE(refusal_of(d).find("trace.csv:3: 4 cells, the header has 15"),
            std::string::npos)
      << refusal_of(d);
}

TEST(Recording, BadInputNamesTheFileAndTheCause) {
  const fs::path none = make_dir("none");
  EXPECT_NE(refusal_of(none).find("meta.json"), std::string::npos);
  const fs::path bad = make_dir("bad");
  write(bad / "meta.json", R"({"verb": "hw record"})");
  write(bad / "trace.csv", std::string(kHeader) +
                               "0,0,0.1,x,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n"
                               "0,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n");
  EXPECT_NE(refusal_of(bad).find("trace.csv:2:4 (q2_rad): 'x' is not a number"), std::string::npos) << refusal_of(bad);
  const fs::path nocol = make_dir("nocol");
  write(nocol / "meta.json", R"({"verb": "hw record"})");
  write(nocol / "trace.csv", "t_s,q1_rad\n0,0\n");
  EXPECT_NE(refusal_of(nocol).find("required column 'q6_rad' is missing"), std::string::npos) << refusal_of(nocol);
  const fs::path nojson = make_dir("nojson");
  write(nojson / "meta.json", "{");
  EXPECT_NE(refusal_of(nojson).find("not valid JSON"), std::string::npos);
}

// Saved with CRLF line ends (RFC 4180's own; spreadsheet tools on Windows
// write them): read as the same recording.
TEST(Recording, CrlfLineEndsAreRead) {
  const fs::path d = make_dir("crlf");
  write(d / "meta.json", "{\"verb\": \"hw record\"}\r\n");
  std::string header = kHeader;
  header.insert(header.size() - 1, "\r");
  write(d / "trace.csv", header +
                             "0,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\r\n"
                             "0.001,0.001,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.02,ok,1,2,979\r\n");
  const Recording r = load_recording(d.string());
  ASSERT_EQ(r.rows, 2u);
  EXPECT_DOUBLE_EQ(r.dev_p_mm(1).z(), 979.0);
  EXPECT_EQ(r.text_col("read_error")[1], "ok");
  EXPECT_TRUE(r.has("dev_p_z_mm"));
}

// A corrupt recording is refused, not judged (issue 34): a clock that does
// not increase (reversed or repeated rows, all zero), a time that is not
// finite, a column named twice, a line beyond the bound, and files that are
// not regular files. Each message names the file, the line or the column.
TEST(Recording, ACorruptRecordingIsRefusedAndNamed) {
  const std::string row0 = "0,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n";
  const std::string row1 = "0.001,0.001,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n";
  auto with_trace = [&](const std::string& name, const std::string& trace) {
    const fs::path d = make_dir(name);
    write(d / "meta.json", R"({"verb": "hw record"})");
    write(d / "trace.csv", trace);
    return d;
  };
  const auto npos = std::string::npos;

  std::string m = refusal_of(with_trace("reversed", std::string(kHeader) + row1 + row0));
  EXPECT_NE(m.find("trace.csv:3:1 (t_s): 0 does not come after"), npos) << m;
  m = refusal_of(with_trace("repeated", std::string(kHeader) + row0 + row0));
  EXPECT_NE(m.find("trace.csv:3:1 (t_s): 0 does not come after the row before's 0"), npos) << m;
  m = refusal_of(with_trace("nan_time", std::string(kHeader) +
                                         "nan,0,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n"));
  EXPECT_NE(m.find("trace.csv:2:1 (t_s): nan is not a finite time"), npos) << m;

  std::string twice = kHeader;
  twice.replace(twice.find("dev_p_z_mm"), 10, "q1_rad");
  m = refusal_of(with_trace("twice", twice + row0));
  EXPECT_NE(m.find("column 'q1_rad' appears twice"), npos) << m;

  m = refusal_of(with_trace("long", std::string(kHeader) + std::string(runtime::RecordingLimits{}.max_line_bytes + 10, '1') +
                                     "\n"));
  EXPECT_NE(m.find("trace.csv:2: line longer than the reader's bound of 65536 bytes"), npos) << m;

  // a FIFO in the trace's place: refused by its type, before any read
  // (which would block)
  const fs::path fifo = make_dir("fifo");
  write(fifo / "meta.json", R"({"verb": "hw record"})");
  ASSERT_EQ(mkfifo((fifo / "trace.csv").c_str(), 0600), 0);
  m = refusal_of(fifo);
  EXPECT_NE(m.find("trace.csv is a FIFO, not a regular file"), npos) << m;
  // a folder as meta.json
  const fs::path dirmeta = make_dir("dirmeta");
  fs::create_directories(dirmeta / "meta.json");
  m = refusal_of(dirmeta);
  EXPECT_NE(m.find("meta.json is a folder, not a regular file"), npos) << m;
}

// A long recording keeps memory bounded: every row is read and checked,
// only the first max_rows are kept, and the note says so. A bad row past
// the window is still refused.
TEST(Recording, ALongTraceIsCheckedWholeAndKeptToItsWindow) {
  const fs::path d = make_dir("window");
  write(d / "meta.json", R"({"verb": "hw record"})");
  std::string trace = kHeader;
  for (int k = 0; k < 5; ++k) {
    trace += std::to_string(0.001 * k) + ",0.001,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n";
  }
  write(d / "trace.csv", trace);
  const Recording r = load_recording(d.string(), 2);
  EXPECT_EQ(r.rows, 2u);
  EXPECT_EQ(r.rows_in_trace, 5u);
  EXPECT_EQ(r.col("t_s").size(), 2u);
  EXPECT_NE(window_note(r).find("judged on its first 2 of 5 rows"), std::string::npos)
      << window_note(r);
  EXPECT_EQ(window_note(load_recording(d.string())), "");
  write(d / "trace.csv", trace + "0.001,0.001,0.1,0.2,0.3,0.4,0.5,0.6,0,0,0.01,ok,1,2,3\n");
  try {
    (void)load_recording(d.string(), 2);
    ADD_FAILURE() << "a clock run backwards past the window was not seen";
  } catch (const RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("trace.csv:7:1 (t_s)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vmh::bringup
