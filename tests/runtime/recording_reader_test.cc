// runtime/recording_reader: the one reader of recordings against small
// hand-written files. Each bad input of issue 34's list is refused with
// its file, its line and column (or its JSON key) and what was wrong; what
// the trace writer writes is read back.
#include "runtime/recording_reader.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/types.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using vmh::Json;
using vmh::runtime::parse_recording_meta;
using vmh::runtime::read_recording_meta;
using vmh::runtime::RecordingError;
using vmh::runtime::RecordingLimits;
using vmh::runtime::RecordingMeta;
using vmh::runtime::TraceReader;

fs::path rr_dir(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("vmh_rr_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

fs::path rr_file(const std::string& name, const std::string& text) {
  const fs::path p = rr_dir(name) / "trace.csv";
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

// every row the reader returns: its t_s and its cells as text
struct ReadBack {
  std::vector<double> t_s;
  std::vector<std::vector<std::string>> cells;
  bool cut_short = false;
};

ReadBack read_all(const fs::path& p, const RecordingLimits& l = {}) {
  TraceReader r(p.string(), l);
  ReadBack out;
  while (r.next()) {
    out.t_s.push_back(r.t_s());
    out.cells.emplace_back(r.cells().begin(), r.cells().end());
  }
  out.cut_short = r.cut_short();
  return out;
}

// the message reading the whole trace throws ("" when it reads)
std::string trace_refusal(const fs::path& p, const RecordingLimits& l = {}) {
  try {
    (void)read_all(p, l);
  } catch (const RecordingError& e) {
    return e.what();
  }
  return "";
}

std::string meta_refusal(const Json& j) {
  try {
    (void)parse_recording_meta(j, "R/meta.json");
  } catch (const RecordingError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_HAS(text, part)                                   \
  EXPECT_NE(std::string(text).find(part), std::string::npos)     \
      << "expected \"" << (part) << "\" in: " << (text)

TEST(TraceReader, ReadsRowsAsWrittenWithLfOrCrlf) {
  for (const std::string eol : {"\n", "\r\n"}) {
    const fs::path p = rr_file("good", "t_s,q1_rad,read_error" + eol +
                                           "0.001,0.5,ok" + eol + "0.002,-1e-3,timeout" +
                                           eol + "0.003,nan,ok" + eol);
    const ReadBack b = read_all(p);
    ASSERT_EQ(b.t_s.size(), 3u);
    EXPECT_DOUBLE_EQ(b.t_s[0], 0.001);
    EXPECT_DOUBLE_EQ(b.t_s[2], 0.003);
    EXPECT_EQ(b.cells[1][1], "-1e-3");
    EXPECT_EQ(b.cells[1][2], "timeout");  // no '\r' left on the last cell
    EXPECT_FALSE(b.cut_short);
  }
}

// found by recording_fuzz: a CR inside a line (not the CR of its CRLF end)
// used to stay in a cell, unseen in a column name or a text cell
TEST(TraceReader, ACarriageReturnInsideALineIsRefused) {
  EXPECT_HAS(trace_refusal(rr_file("cr_cell", "t_s,q1_rad,read_error\n"
                                              "0.001,0.5,ok\r,\n")),
             "trace.csv:2:13: a carriage return inside the line");
  EXPECT_HAS(trace_refusal(rr_file("cr_header", "t_s,q1\r_rad\r\n0.001,0.5\r\n")),
             "trace.csv:1:7: a carriage return inside the line");
  // the last line, cut short without its line end
  EXPECT_HAS(trace_refusal(rr_file("cr_last", "t_s,x\n0.001,1\n0.002,\r2")),
             "trace.csv:3:7: a carriage return inside the line");
}

TEST(TraceReader, NumbersAreWholeCellsOrRefused) {
  const fs::path p = rr_file("numbers", "t_s,x\n1,-2.5e3\n2,inf\n3,-nan\n");
  TraceReader r(p.string(), {});
  ASSERT_TRUE(r.next());
  EXPECT_DOUBLE_EQ(r.number(1), -2500.0);
  ASSERT_TRUE(r.next());
  EXPECT_TRUE(std::isinf(r.number(1)));
  EXPECT_HAS(([&] {
               try {
                 (void)r.finite(1);
               } catch (const RecordingError& e) {
                 return std::string(e.what());
               }
               return std::string();
             }()),
             ":3:2 (x): inf where a finite number belongs");
  ASSERT_TRUE(r.next());
  EXPECT_TRUE(std::isnan(r.number(1)));
  for (const char* bad : {"", " 1", "+1", "--1", "1x", "0x10", "- 1", "1 "}) {
    const fs::path q = rr_file("bad_number", std::string("t_s,x,y\n1,") + bad + ",0\n");
    const std::string why = [&] {
      try {
        TraceReader t(q.string(), {});
        if (!t.next()) return std::string("no row");
        (void)t.number(1);
      } catch (const RecordingError& e) {
        return std::string(e.what());
      }
      return std::string();
    }();
    EXPECT_FALSE(why.empty()) << "'" << bad << "' was read as a number";
  }
}

TEST(TraceReader, TimeMustBeFiniteAndIncrease) {
  EXPECT_HAS(trace_refusal(rr_file("backwards", "t_s,x\n0.002,1\n0.001,1\n")),
             "trace.csv:3:1 (t_s): 0.001 does not come after the row before's 0.002");
  EXPECT_HAS(trace_refusal(rr_file("zeros", "t_s,x\n0,1\n0,1\n")),
             ":3:1 (t_s): 0 does not come after");
  EXPECT_HAS(trace_refusal(rr_file("nan_t", "t_s,x\nnan,1\n")),
             ":2:1 (t_s): nan is not a finite time");
  EXPECT_HAS(trace_refusal(rr_file("inf_t", "t_s,x\n1,1\ninf,1\n")),
             ":3:1 (t_s): inf is not a finite time");
}

TEST(TraceReader, HeaderColumnsAreNamedOnceAndHaveTime) {
  EXPECT_HAS(trace_refusal(rr_file("twice", "t_s,q1_rad,q1_rad\n1,2,9\n")),
             "trace.csv:1:3: column 'q1_rad' appears twice");
  EXPECT_HAS(trace_refusal(rr_file("unnamed", "t_s,,x\n1,2,3\n")),
             "trace.csv:1:2: a column has no name");
  EXPECT_HAS(trace_refusal(rr_file("no_time", "q1_rad\n1\n")),
             "required column 't_s' is missing");
  EXPECT_HAS(trace_refusal(rr_file("empty", "")), "is empty: no header line");
}

TEST(TraceReader, RowsAreCompleteExceptALastOneCutShort) {
  // a row short in the middle, or a whole last line with its '\n', is
  // refused
  EXPECT_HAS(trace_refusal(rr_file("short", "t_s,x,y\n1,2,3\n2,3\n3,4,5\n")),
             "trace.csv:3: 2 cells, the header has 3");
  EXPECT_HAS(trace_refusal(rr_file("short_last", "t_s,x,y\n1,2,3\n2,3\n")),
             ":3: 2 cells, the header has 3");
  EXPECT_HAS(trace_refusal(rr_file("long", "t_s,x\n1,2,3\n")),
             ":2: 3 cells, the header has 2");
  // the last line without its '\n', short: where the writer was stopped
  const ReadBack b = read_all(rr_file("cut", "t_s,x,y\n1,2,3\n2,3"));
  EXPECT_EQ(b.t_s.size(), 1u);
  EXPECT_TRUE(b.cut_short);
  // whole but without its '\n': read
  const ReadBack w = read_all(rr_file("no_eol", "t_s,x,y\n1,2,3\n2,3,4"));
  EXPECT_EQ(w.t_s.size(), 2u);
  EXPECT_FALSE(w.cut_short);
}

TEST(TraceReader, BoundsAreCheckedBeforeMemoryGrows) {
  RecordingLimits small;
  small.max_trace_bytes = 64;
  EXPECT_HAS(trace_refusal(rr_file("big", "t_s,x\n" + std::string(100, '#') + "\n"), small),
             "is 107 bytes, over the reader's bound of 64 bytes");
  // a 200 MB header line is refused at the line bound, not read whole
  RecordingLimits line;
  line.max_line_bytes = 1000;
  EXPECT_HAS(trace_refusal(rr_file("long_line", "t_s," + std::string(5000, 'x') + "\n1,2\n"),
                           line),
             "trace.csv:1: line longer than the reader's bound of 1000 bytes");
  RecordingLimits rows;
  rows.max_rows = 2;
  EXPECT_HAS(trace_refusal(rr_file("rows", "t_s\n1\n2\n3\n"), rows),
             "trace.csv:4: more than 2 rows");
  EXPECT_EQ(RecordingLimits{}.max_rows, 3'600'001u);
}

TEST(TraceReader, OnlyARegularFileIsOpened) {
  const fs::path d = rr_dir("kinds");
  const fs::path fifo = d / "trace.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // refused by its type: no writer ever comes, and the reader must not wait
  EXPECT_HAS(trace_refusal(fifo), "is a FIFO, not a regular file");
  fs::remove(fifo);
  fs::create_symlink("/dev/zero", fifo);
  EXPECT_HAS(trace_refusal(fifo), "is a character device, not a regular file");
  fs::remove(fifo);
  fs::create_directory(fifo);
  EXPECT_HAS(trace_refusal(fifo), "is a folder, not a regular file");
  EXPECT_HAS(trace_refusal(d / "none.csv"), "none.csv: no such file");
}

Json good_meta(const std::string& verb) {
  Json j{{"verb", verb},
         {"recording_format", 1},
         {"software", {{"name", "vmhaptics"}, {"version", "0.1.0"}}},
         {"device", {{"backend", "emulator"}, {"serial", "EMU-0001"}, {"input_dof", 6}}},
         {"session",
          {{"duration_s", 2.0}, {"ticks", 2000}, {"timing", {{"nominal_period_us", 1000.0}}}}},
         {"emulator", {{"scene", "models/cases/case1.xml"}, {"hand", "tour"}, {"model", nullptr}}}};
  if (verb == "hw motor-test") {
    j["motor"] = 2;
    j["torque_asked_mNm"] = -30.0;
    j["pulse_ms"] = 200.0;
  }
  if (verb == "hw run") {
    j["case"] = "case1";
    j["scene"] = "models/cases/case1.xml";
    j["sets"] = Json::array({"k_pos_N_per_mm=0.1"});
    j["gain_scale"] = 0.5;
  }
  return j;
}

TEST(RecordingMeta, WhatTheHwVerbsWriteIsRead) {
  const RecordingMeta rec = parse_recording_meta(good_meta("hw record"), "m");
  EXPECT_EQ(rec.verb, "hw record");
  EXPECT_EQ(rec.device.serial, "EMU-0001");
  EXPECT_EQ(rec.device.input_dof, 6);
  EXPECT_DOUBLE_EQ(rec.nominal_period_s, 1e-3);
  EXPECT_EQ(rec.emulator_scene, "models/cases/case1.xml");
  const RecordingMeta mt = parse_recording_meta(good_meta("hw motor-test"), "m");
  EXPECT_EQ(mt.motor, 2);
  EXPECT_DOUBLE_EQ(mt.torque_asked_mNm, -30.0);
  const RecordingMeta run = parse_recording_meta(good_meta("hw run"), "m");
  EXPECT_EQ(run.sets, std::vector<std::string>{"k_pos_N_per_mm=0.1"});
  EXPECT_DOUBLE_EQ(run.gain_scale, 0.5);
  EXPECT_EQ(run.case_name, "case1");
  // written before the format key existed: read as format 1
  Json old = good_meta("hw record");
  old.erase("recording_format");
  EXPECT_EQ(parse_recording_meta(old, "m").verb, "hw record");
}

TEST(RecordingMeta, SchemaRefusalsNameTheKey) {
  const auto with = [](const std::string& verb, const char* key, Json v) {
    Json j = good_meta(verb);
    j[key] = std::move(v);
    return meta_refusal(j);
  };
  EXPECT_HAS(meta_refusal(Json::array()), "R/meta.json: not a JSON object");
  EXPECT_HAS(meta_refusal(Json{{"software", "x"}}), "R/meta.json: no key 'verb'");
  EXPECT_HAS(with("hw record", "verb", "hw probe"),
             "key 'verb': 'hw probe' is not a verb that writes a recording");
  EXPECT_HAS(with("hw record", "verb", 3), "key 'verb': must be a string, not number");
  EXPECT_HAS(with("hw record", "recording_format", 2),
             "key 'recording_format': 2 is a format this reader does not know");
  // a hw record labelled as a motor test names no motor; motor 99, 1e308
  {
    Json j = good_meta("hw record");
    j["verb"] = "hw motor-test";
    EXPECT_HAS(meta_refusal(j), "key 'motor': missing");
  }
  EXPECT_HAS(with("hw motor-test", "motor", 99), "key 'motor': 99 is not in [1, 3]");
  EXPECT_HAS(with("hw motor-test", "motor", 1e308),
             "key 'motor': 1e+308 is not a whole number in [1, 3]");
  EXPECT_HAS(with("hw motor-test", "motor", 18446744073709551615ull),
             "key 'motor': 18446744073709551615 is not in [1, 3]");
  EXPECT_HAS(with("hw record", "motor", 1),
             "key 'motor': a 'hw record' recording has no motor");
  EXPECT_HAS(with("hw motor-test", "torque_asked_mNm", "30"),
             "key 'torque_asked_mNm': must be a number, not string");
  EXPECT_HAS(with("hw motor-test", "pulse_ms", 0),
             "key 'pulse_ms': 0 is not a finite number in (0, 10000]");
  EXPECT_HAS(with("hw run", "gain_scale", -1), "key 'gain_scale': -1 is not a finite");
  EXPECT_HAS(with("hw run", "sets", Json::array({"a", 7})),
             "key 'sets[1]': must be a string, not number");
  EXPECT_HAS(with("hw run", "sets", "a=1"), "key 'sets': must be an array");
  {
    Json j = good_meta("hw record");
    j["device"]["serial"] = 12;
    EXPECT_HAS(meta_refusal(j), "key 'device.serial': must be a string, not number");
    j = good_meta("hw record");
    j["session"]["timing"]["nominal_period_us"] = 0;
    EXPECT_HAS(meta_refusal(j), "key 'session.timing.nominal_period_us': 0 is not");
    j = good_meta("hw record");
    j["session"]["duration_s"] = -1;
    EXPECT_HAS(meta_refusal(j), "key 'session.duration_s': -1 is not");
    j = good_meta("hw record");
    j["software"]["name"] = "other";
    EXPECT_HAS(meta_refusal(j), "key 'software.name': 'other' is not vmhaptics");
    j = good_meta("hw record");
    j["emulator"]["scene"] = Json::array();
    EXPECT_HAS(meta_refusal(j), "key 'emulator.scene': must be a string");
  }
}

TEST(RecordingMeta, TheFileIsReadAsTheTraceIs) {
  const fs::path d = rr_dir("meta");
  bool missing = false;
  (void)read_recording_meta((d / "meta.json").string(), {}, &missing);
  EXPECT_TRUE(missing);
  const fs::path m = d / "meta.json";
  ASSERT_EQ(::mkfifo(m.c_str(), 0600), 0);
  try {
    (void)read_recording_meta(m.string(), {}, &missing);
    ADD_FAILURE() << "a FIFO was read";
  } catch (const RecordingError& e) {
    EXPECT_HAS(e.what(), "meta.json is a FIFO, not a regular file");
  }
  fs::remove(m);
  std::ofstream(m) << "{\"verb\": ";
  try {
    (void)read_recording_meta(m.string(), {}, &missing);
    ADD_FAILURE() << "broken JSON was read";
  } catch (const RecordingError& e) {
    EXPECT_HAS(e.what(), "meta.json: not valid JSON");
  }
  RecordingLimits tiny;
  tiny.max_meta_bytes = 4;
  try {
    (void)read_recording_meta(m.string(), tiny, &missing);
    ADD_FAILURE() << "a file over the bound was read";
  } catch (const RecordingError& e) {
    EXPECT_HAS(e.what(), "over the reader's bound of 4 bytes");
  }
}

}  // namespace
