// hw/replay: the reader against small hand-written recordings (each bad
// input refused with what was wrong and where), the device on the lockstep
// clock (tick k serves row k; hold, loop, stop; writes checked and
// counted), and the backend as the registry opens it. The expected joint
// angles are worked out here from the DH columns by hand (t1 = -q1,
// t2 = q2, t3 = q2 + q3, t4 = -q4, t5 = q5, t6 = -q6), not by the reader.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/types.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "hw/backends.h"
#include "hw/replay/recording.h"
#include "hw/replay/replay_device.h"
#include "hw/replay/replay_runtime.h"

namespace {

namespace fs = std::filesystem;
using namespace vmh;
using namespace vmh::hw::replay;

fs::path fresh(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("vmh_replay_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

const std::string kHeader =
    "t_s,period_s,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,read_error,"
    "buttons,docked\n";

// row k: time k ms, DH angles 0.1 k + (0.01, 0.02, ..., 0.06)
std::string row(int k, const char* err = "ok") {
  char buf[256];
  const double b = 0.1 * k;
  std::snprintf(buf, sizeof buf, "%.9g,0.001,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%s,%d,%d\n",
                0.001 * k, b + 0.01, b + 0.02, b + 0.03, b + 0.04, b + 0.05,
                b + 0.06, err, k % 4, k % 2);
  return buf;
}

fs::path recording(const std::string& name, int rows) {
  const fs::path d = fresh(name);
  std::string t = kHeader;
  for (int k = 0; k < rows; ++k) t += row(k);
  write(d / "trace.csv", t);
  return d;
}

// the device angles of row k, worked out by hand
Joints expected_q(int k) {
  const double b = 0.1 * k;
  Joints q;
  q << -(b + 0.01), b + 0.02, (b + 0.02) + (b + 0.03), -(b + 0.04), b + 0.05,
      -(b + 0.06);
  return q;
}

// the message of the RecordingError reading `dir` throws ("" if none)
std::string refusal(const fs::path& dir, const RecordingLimits& l = {}) {
  try {
    (void)read_recording(dir.string(), l);
  } catch (const RecordingError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_HAS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

TEST(ReplayReader, ReadsRowsInDeviceConvention) {
  const fs::path d = recording("good", 5);
  const Recording r = read_recording(d.string());
  ASSERT_EQ(r.rows(), 5u);
  EXPECT_EQ(r.present, kStateButtons | kStateInkwell);
  EXPECT_FALSE(r.has_meta);
  for (int k = 0; k < 5; ++k) {
    EXPECT_DOUBLE_EQ(r.time_s[static_cast<std::size_t>(k)], 0.001 * k);
    DeviceState st;
    ASSERT_EQ(r.state_of(static_cast<std::size_t>(k), &st), DeviceError::kOk);
    EXPECT_LT((st.q_device_rad - expected_q(k)).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_EQ(st.buttons, static_cast<std::uint32_t>(k % 4));
    EXPECT_EQ(st.docked, k % 2 == 1);
    EXPECT_EQ(st.present, kStateJoints | kStateButtons | kStateInkwell);
  }
  // the last row at or before t, within the 9-digit printing
  EXPECT_EQ(r.row_at(-1.0), 0u);
  EXPECT_EQ(r.row_at(0.0), 0u);
  EXPECT_EQ(r.row_at(0.0019999999), 2u);
  EXPECT_EQ(r.row_at(0.0025), 2u);
  EXPECT_EQ(r.row_at(10.0), 4u);
}

TEST(ReplayReader, OptionalGroupsAndMeta) {
  const fs::path d = fresh("groups");
  std::string h = "t_s,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,dev_p_x_mm,"
                  "dev_p_y_mm,dev_p_z_mm";
  for (int r = 1; r <= 3; ++r) {
    for (int c = 1; c <= 3; ++c) h += ",dev_R_" + std::to_string(r) + std::to_string(c);
  }
  h += ",enc_1,enc_2,enc_3\n";
  write(d / "trace.csv",
        h + "0,0,0,0,0,0,0,10,-20,30,1,0,0,0,1,0,0,0,1,100,-200,300\n");
  write(d / "meta.json",
        R"({"verb": "hw record", "device": {"backend": "firewire", "model": "PHANTOM Omni",
            "serial": "11129400000"},
            "session": {"timing": {"nominal_period_us": 1000}}})");
  const Recording r = read_recording(d.string());
  EXPECT_EQ(r.present, kStateTransform | kStateEncoders);
  EXPECT_TRUE(r.has_meta);
  EXPECT_EQ(r.recorded.serial, "11129400000");
  EXPECT_DOUBLE_EQ(r.nominal_period_s, 1e-3);
  DeviceState st;
  ASSERT_EQ(r.state_of(0, &st), DeviceError::kOk);
  EXPECT_EQ(st.transform_mm(0, 3), 10.0);
  EXPECT_EQ(st.transform_mm(1, 3), -20.0);
  EXPECT_EQ(st.transform_mm(2, 3), 30.0);
  EXPECT_EQ(st.transform_mm(3, 3), 1.0);
  EXPECT_EQ(st.encoder_counts[1], -200);
}

TEST(ReplayReader, AFailedReadIsReplayedAsThatFailure) {
  const fs::path d = fresh("failed");
  write(d / "trace.csv",
        kHeader + row(0) +
            "0.001,0.001,nan,nan,nan,nan,nan,nan,timeout,0,0\n" + row(2));
  const Recording r = read_recording(d.string());
  DeviceState st;
  EXPECT_EQ(r.state_of(1, &st), DeviceError::kTimeout);
  EXPECT_EQ(st.present, 0u);
  EXPECT_EQ(r.state_of(2, &st), DeviceError::kOk);
}

TEST(ReplayReader, RefusesAMissingFolderAndTrace) {
  const fs::path d = fresh("nofolder");
  EXPECT_HAS(refusal(d / "absent"), "no such folder");
  write(d / "file", "x");
  EXPECT_HAS(refusal(d / "file"), "is a file, not a folder");
  EXPECT_HAS(refusal(d), "no trace.csv in");
  EXPECT_HAS(refusal(""), "no recording folder given");
}

TEST(ReplayReader, RefusesATraceThatIsNotARegularFile) {
  const fs::path d = fresh("notregular");
  fs::create_directories(d / "trace.csv");
  EXPECT_HAS(refusal(d), "trace.csv is a folder, not a regular file");
  const fs::path f = fresh("fifo");
  ASSERT_EQ(::mkfifo((f / "trace.csv").c_str(), 0600), 0);
  // no writer ever opens it: a reader that opened it would block here
  EXPECT_HAS(refusal(f), "trace.csv is a FIFO, not a regular file");
}

TEST(ReplayReader, RefusesATraceOverTheBounds) {
  const fs::path d = recording("big", 10);
  RecordingLimits l;
  l.max_trace_bytes = 200;
  EXPECT_HAS(refusal(d, l), "over the reader's bound of 200 bytes");
  RecordingLimits rows;
  rows.max_rows = 4;
  EXPECT_HAS(refusal(d, rows), "trace.csv:6: more than 4 rows, the reader's bound");
  // the defaults, stated
  EXPECT_EQ(RecordingLimits{}.max_trace_bytes, std::uint64_t{8} << 30);
  EXPECT_EQ(RecordingLimits{}.max_rows, 3600001u);
}

TEST(ReplayReader, NamesAMissingColumn) {
  const fs::path d = fresh("nocol");
  write(d / "trace.csv", "t_s,q1_rad,q2_rad,q4_rad,q5_rad,q6_rad\n0,0,0,0,0,0\n");
  EXPECT_HAS(refusal(d), "required column 'q3_rad' is missing");
  write(d / "trace.csv", "q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad\n0,0,0,0,0,0\n");
  EXPECT_HAS(refusal(d), "required column 't_s' is missing");
  write(d / "trace.csv",
        "t_s,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,dev_v_x_mm_s\n"
        "0,0,0,0,0,0,0,0\n");
  EXPECT_HAS(refusal(d), "column 'dev_v_y_mm_s' is missing (dev_v_x_mm_s is there");
  write(d / "trace.csv", "t_s,t_s,q1_rad\n");
  EXPECT_HAS(refusal(d), "column 't_s' appears twice");
}

TEST(ReplayReader, NamesTheCellThatIsNotANumber) {
  const fs::path d = fresh("nan");
  write(d / "trace.csv",
        kHeader + row(0) + "0.001,0.001,0.1,0.2,abc,0.4,0.5,0.6,ok,0,0\n");
  const std::string trace = (d / "trace.csv").string();
  EXPECT_HAS(refusal(d), trace + ":3:5 (q3_rad): 'abc' is not a number");
  write(d / "trace.csv", kHeader + "0,0.001,0.1,0.2,0.3,nan,0.5,0.6,ok,0,0\n");
  EXPECT_HAS(refusal(d), trace + ":2:6 (q4_rad): nan where a finite number belongs");
  write(d / "trace.csv", kHeader + "0,0.001,0.1,0.2,0.3,0.4,0.5,0.6,ok,0,0.5\n");
  EXPECT_HAS(refusal(d), trace + ":2:11 (docked): 0.5 is not a whole number in [0, 1]");
  write(d / "trace.csv", kHeader + "0,0.001,0.1,0.2,0.3,0.4,0.5,0.6,gone,0,0\n");
  EXPECT_HAS(refusal(d), trace + ":2:9 (read_error): 'gone' is not a read error");
  write(d / "trace.csv", kHeader + "0,0.001,0.1,0.2\n");
  EXPECT_HAS(refusal(d), trace + ":2: 4 cells, the header has 11");
  write(d / "trace.csv", kHeader + "nan,0.001,0.1,0.2,0.3,0.4,0.5,0.6,ok,0,0\n");
  EXPECT_HAS(refusal(d), trace + ":2:1 (t_s): nan is not a finite time");
  write(d / "trace.csv", kHeader + "0,0.001, 0.1,0.2,0.3,0.4,0.5,0.6,ok,0,0\n");
  EXPECT_HAS(refusal(d), trace + ":2:3 (q1_rad): ' 0.1' is not a number");
}

TEST(ReplayReader, RefusesTimeThatDoesNotIncrease) {
  const fs::path d = fresh("time");
  write(d / "trace.csv", kHeader + row(0) + row(1) + row(1));
  const std::string trace = (d / "trace.csv").string();
  EXPECT_HAS(refusal(d), trace + ":4:1 (t_s): 0.001 does not come after the "
                                 "row before's 0.001");
  write(d / "trace.csv", kHeader + row(2) + row(1));
  EXPECT_HAS(refusal(d), trace + ":3:1 (t_s): 0.001 does not come after");
}

TEST(ReplayReader, RefusesAnEmptyRecording) {
  const fs::path d = fresh("empty");
  write(d / "trace.csv", kHeader);
  EXPECT_HAS(refusal(d), "no rows after the header: the recording is empty");
  write(d / "trace.csv", "");
  EXPECT_HAS(refusal(d), "is empty: no header line");
}

TEST(ReplayReader, RefusesAMetaThatIsNotJson) {
  const fs::path d = recording("meta", 2);
  write(d / "meta.json", "{not json");
  EXPECT_HAS(refusal(d), "meta.json: not valid JSON");
  fs::remove(d / "meta.json");
  ASSERT_EQ(::mkfifo((d / "meta.json").c_str(), 0600), 0);
  EXPECT_HAS(refusal(d), "meta.json is a FIFO, not a regular file");
}

// ---- the device, in lockstep ----

// reads every tick, writes a torque, keeps what it read
struct Reader final : ServoLoop {
  HapticDevice* dev;
  std::vector<DeviceError> errors;
  std::vector<Joints> q;
  std::vector<double> now;
  Vec3 tau = Vec3(0.01, -0.02, 0.03);
  bool tick(double now_s) noexcept override {
    DeviceState st;
    errors.push_back(dev->read_state(&st));
    q.push_back(st.q_device_rad);
    now.push_back(now_s);
    (void)dev->write_motor_torques(tau);
    return true;
  }
};

std::shared_ptr<const Recording> load(const fs::path& d) {
  return std::make_shared<const Recording>(read_recording(d.string()));
}

void run_lockstep(ReplayBackend* b, Reader* loop, int ticks) {
  loop->dev = b->device();
  ServoOptions so;
  so.lockstep = true;
  so.realtime = false;
  b->start(loop, so);
  b->pass(ticks * 1e-3);
  b->stop();
}

TEST(ReplayDevice, LockstepTickKServesRowK) {
  ReplayBackend b(load(recording("lock", 20)), ReplayOptions{});
  Reader loop;
  run_lockstep(&b, &loop, 25);
  ASSERT_EQ(loop.q.size(), 25u);
  for (int k = 0; k < 25; ++k) {
    ASSERT_EQ(loop.errors[static_cast<std::size_t>(k)], DeviceError::kOk) << k;
    // hold: past the end, the last row
    const Joints want = expected_q(std::min(k, 19));
    EXPECT_LT((loop.q[static_cast<std::size_t>(k)] - want).cwiseAbs().maxCoeff(), 1e-12)
        << "tick " << k;
  }
  const ReplayStats s = b.replay()->stats();
  EXPECT_EQ(s.reads, 25);
  EXPECT_EQ(s.writes, 25);
  EXPECT_EQ(s.invalid_writes, 0);
  EXPECT_DOUBLE_EQ(s.max_abs_tau_Nm[1], 0.02);
  EXPECT_EQ(b.timing().ticks, 25);
}

TEST(ReplayDevice, LoopBeginsAgainAndStopEnds) {
  ReplayOptions loop_o;
  loop_o.end = ReplayEnd::kLoop;
  ReplayBackend looped(load(recording("loop", 10)), loop_o);
  Reader a;
  run_lockstep(&looped, &a, 25);
  for (int k = 0; k < 25; ++k) {
    EXPECT_LT((a.q[static_cast<std::size_t>(k)] - expected_q(k % 10)).cwiseAbs().maxCoeff(),
              1e-12)
        << "tick " << k;
  }
  EXPECT_EQ(looped.replay()->stats().loops, 2);

  ReplayOptions stop_o;
  stop_o.end = ReplayEnd::kStop;
  ReplayBackend stopped(load(recording("stop", 10)), stop_o);
  Reader s;
  run_lockstep(&stopped, &s, 12);
  for (int k = 0; k < 12; ++k) {
    EXPECT_EQ(s.errors[static_cast<std::size_t>(k)],
              k < 10 ? DeviceError::kOk : DeviceError::kNotConnected)
        << "tick " << k;
  }
  EXPECT_EQ(stopped.replay()->stats().failed_reads, 2);
}

TEST(ReplayDevice, SpeedScalesTheClock) {
  ReplayOptions o;
  o.speed = 2.0;
  ReplayBackend b(load(recording("speed", 20)), o);
  Reader loop;
  run_lockstep(&b, &loop, 8);
  for (int k = 0; k < 8; ++k) {
    EXPECT_LT((loop.q[static_cast<std::size_t>(k)] - expected_q(2 * k)).cwiseAbs().maxCoeff(),
              1e-12);
  }
}

TEST(ReplayDevice, NonFiniteTorqueIsAnInvalidCommandAndCounted) {
  ReplayDevice d(load(recording("tau", 3)), ReplayOptions{});
  EXPECT_EQ(d.write_motor_torques(Vec3(0.1, 0.0, -0.3)), DeviceError::kOk);
  EXPECT_EQ(d.write_motor_torques(Vec3(std::nan(""), 0.0, 0.0)),
            DeviceError::kInvalidCommand);
  EXPECT_EQ(d.write_motor_torques(Vec3(0.0, INFINITY, 0.0)),
            DeviceError::kInvalidCommand);
  const ReplayStats s = d.stats();
  EXPECT_EQ(s.writes, 3);
  EXPECT_EQ(s.invalid_writes, 2);
  EXPECT_DOUBLE_EQ(s.max_abs_tau_Nm[0], 0.1);
  EXPECT_DOUBLE_EQ(s.max_abs_tau_Nm[2], 0.3);
  // before start: the first row
  DeviceState st;
  ASSERT_EQ(d.read_state(&st), DeviceError::kOk);
  EXPECT_LT((st.q_device_rad - expected_q(0)).cwiseAbs().maxCoeff(), 1e-12);
}

// On the wall clock the row a tick gets depends on when it ran, so only
// what holds on a busy host is asserted: every reading is one of the
// recording's rows, in the recording's order, and the loop ran.
TEST(ReplayDeviceRealtime, WallClockServesRowsInOrder) {
  ReplayOptions o;
  o.end = ReplayEnd::kHold;
  const auto rec = load(recording("wall", 200));
  ReplayBackend b(rec, o);
  Reader loop;
  loop.dev = b.device();
  ServoOptions so;
  so.realtime = false;
  b.start(&loop, so);
  // a few ticks, however long a busy host makes them take
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (b.replay()->stats().reads < 5 && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  b.stop();
  ASSERT_GE(loop.q.size(), 1u);
  int last = -1;
  for (std::size_t i = 0; i < loop.q.size(); ++i) {
    ASSERT_EQ(loop.errors[i], DeviceError::kOk);
    int match = -1;
    for (int k = 0; k < 200 && match < 0; ++k) {
      if ((loop.q[i] - expected_q(k)).cwiseAbs().maxCoeff() < 1e-12) match = k;
    }
    ASSERT_GE(match, 0) << "reading " << i << " is no row of the recording";
    EXPECT_GE(match, last);
    last = match;
  }
  EXPECT_EQ(b.replay()->stats().writes, static_cast<long>(loop.q.size()));
}

// ---- the backend as the registry opens it ----

runtime::BackendRegistry registry() {
  runtime::BackendRegistry r;
  hw::register_backends(&r);
  return r;
}

std::string request_refusal(const std::string& spec,
                            const runtime::OpenRequest& rq = {}) {
  try {
    (void)registry().open(spec, rq);
  } catch (const runtime::RequestError& e) {
    return std::string("RequestError: ") + e.what();
  } catch (const DeviceOpenError& e) {
    return std::string("DeviceOpenError: ") + e.what();
  }
  return "";
}

TEST(ReplayBackend, RegisteredOnceWithItsGrammarAndOptions) {
  const runtime::BackendRegistry r = registry();
  const runtime::BackendInfo* b = r.find("replay");
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->grammar, "replay:DIR");
  EXPECT_TRUE(b->lockstep);
  EXPECT_FALSE(b->simulated);
  EXPECT_TRUE(b->can_lockstep());
  const Json row = b->list();
  EXPECT_FALSE(row.at("available").get<bool>());
  EXPECT_HAS(row.at("why_not").get<std::string>(), "give a recording folder");
  ASSERT_EQ(b->options.size(), 2u);
  EXPECT_EQ(b->options[0].key, "replay-end");
  EXPECT_EQ(b->options[1].key, "replay-speed");
}

TEST(ReplayBackend, RefusesBadRequestsByName) {
  const fs::path d = recording("reg", 5);
  EXPECT_HAS(request_refusal("replay"), "RequestError: --device replay: give a "
                                        "recording folder");
  EXPECT_HAS(request_refusal("replay:" + (d / "nope").string()),
             "DeviceOpenError: replay: recording folder");
  runtime::OpenRequest rq;
  rq.options["replay-end"] = "rewind";
  EXPECT_HAS(request_refusal("replay:" + d.string(), rq),
             "--replay-end: 'rewind' is not an end of recording");
  runtime::OpenRequest sp;
  sp.options["replay-speed"] = "0";
  EXPECT_HAS(request_refusal("replay:" + d.string(), sp),
             "--replay-speed: '0' is not a number > 0");
  EXPECT_HAS(request_refusal("replay:" + d.string() + "?rewind"),
             "'rewind' is not a replay option");
}

TEST(ReplayBackend, OpensAndReportsWritesInMeta) {
  const fs::path d = recording("open", 10);
  runtime::OpenRequest rq;
  rq.options["replay-end"] = "loop";
  rq.lockstep = true;
  runtime::OpenedDevice dev = registry().open("replay:" + d.string(), rq);
  EXPECT_EQ(dev.backend->identity().backend, "replay");
  EXPECT_EQ(dev.backend->identity().config, fs::absolute(d).lexically_normal().string());
  Reader loop;
  loop.dev = dev.backend->device();
  ServoOptions so;
  so.lockstep = true;
  dev.backend->start(&loop, so);
  dev.backend->pass(0.015);
  dev.backend->stop();
  const Json m = dev.meta().at("replay");
  EXPECT_EQ(m.at("rows"), 10);
  EXPECT_EQ(m.at("end"), "loop");
  EXPECT_EQ(m.at("writes"), 15);
  EXPECT_EQ(m.at("loops"), 1);
  EXPECT_DOUBLE_EQ(m.at("max_abs_tau_Nm")[2].get<double>(), 0.03);
}

}  // namespace
