// `--device replay:DIR` end to end, as a user runs it: a recording made by
// `vmhaptics hw record --device emulator` is replayed by `hw record` and
// `hw motor-test`, and the replayed joint angles are compared with the
// recorded trace.csv's own values at the recorded times (the two CSV files
// read here, not through the replay's reader). In lockstep, so the verdict
// does not depend on the host's load; one wall-clock test asserts only
// what holds on a busy host.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::run;

const std::string kEnv =
    "XDG_CONFIG_HOME=" + ::testing::TempDir() + "vmh_replay_cfg ";

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::size_t col(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return i;
    }
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
  double num(std::size_t r, const std::string& name) const {
    return std::stod(rows[r][col(name)]);
  }
};

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  return out;
}

Csv read_csv(const fs::path& p) {
  Csv c;
  std::ifstream in(p);
  std::string line;
  if (std::getline(in, line)) c.header = split(line);
  while (std::getline(in, line)) c.rows.push_back(split(line));
  return c;
}

json read_json(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

// one recording on the emulator, made once for the suite (lockstep: the
// emulator's default clock)
const fs::path& recorded() {
  static const fs::path dir = [] {
    // a folder of this process's own: ctest runs the cases in parallel
    const fs::path d = vmh::testing::fresh_dir(
        "vmh_replay_", "rec_" + std::to_string(::getpid()));
    const auto r = run("hw record --device emulator --duration 1 --quiet --out " +
                           d.string(),
                       kEnv);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return d;
  }();
  return dir;
}

const char* const kQ[] = {"q1_rad", "q2_rad", "q3_rad", "q4_rad", "q5_rad", "q6_rad"};
const char* const kDevP[] = {"dev_p_x_mm", "dev_p_y_mm", "dev_p_z_mm"};

TEST(ReplayCli, LockstepReplayGivesTheRecordedAnglesAtTheRecordedTimes) {
  const fs::path rec = recorded();
  const fs::path out = vmh::testing::fresh_dir("vmh_replay_", "rep");
  const auto r = run("hw record --device replay:" + rec.string() +
                         " --clock lockstep --duration 1 --quiet --out " +
                         out.string(),
                     kEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Csv a = read_csv(rec / "trace.csv");
  const Csv b = read_csv(out / "trace.csv");
  ASSERT_GT(a.rows.size(), 900u);
  ASSERT_EQ(b.rows.size(), a.rows.size());
  double max_dq = 0.0, max_dt = 0.0, max_dp = 0.0;
  for (std::size_t i = 0; i < a.rows.size(); ++i) {
    max_dt = std::max(max_dt, std::fabs(a.num(i, "t_s") - b.num(i, "t_s")));
    for (const char* q : kQ) {
      max_dq = std::max(max_dq, std::fabs(a.num(i, q) - b.num(i, q)));
    }
    // the device's own transform, replayed as recorded
    for (const char* p : kDevP) {
      max_dp = std::max(max_dp, std::fabs(a.num(i, p) - b.num(i, p)));
    }
    EXPECT_EQ(a.rows[i][a.col("docked")], b.rows[i][b.col("docked")]) << i;
    EXPECT_EQ(a.rows[i][a.col("buttons")], b.rows[i][b.col("buttons")]) << i;
  }
  std::printf("replay vs recording over %zu rows: max |dt| %.3g s, max |dq| "
              "%.3g rad, max |dp| %.3g mm\n",
              a.rows.size(), max_dt, max_dq, max_dp);
  EXPECT_LT(max_dt, 1e-9);
  // the recording's 9 printed digits, through the DH <-> device conversion
  EXPECT_LT(max_dq, 1e-8);
  EXPECT_LT(max_dp, 1e-9);
  const json meta = read_json(out / "meta.json");
  EXPECT_EQ(meta.at("device").at("backend"), "replay");
  const json& rp = meta.at("replay");
  EXPECT_EQ(rp.at("rows").get<std::size_t>(), a.rows.size());
  // hw record sends zero torque every tick: every one counted
  EXPECT_EQ(rp.at("writes").get<long>(), meta.at("session").at("ticks").get<long>());
  EXPECT_EQ(rp.at("invalid_writes"), 0);
  EXPECT_EQ(rp.at("max_abs_tau_Nm")[0].get<double>(), 0.0);
}

TEST(ReplayCli, MotorTestTorquesAreCountedAndTheirPeakReported) {
  const fs::path rec = recorded();
  const fs::path out = vmh::testing::fresh_dir("vmh_replay_", "mt");
  const auto r = run("hw motor-test --device replay:" + rec.string() +
                         " --clock lockstep --motor 2 --torque-mNm -40 --ms 200 "
                         "--quiet --out " + out.string(),
                     kEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Csv t = read_csv(out / "trace.csv");
  double peak = 0.0;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    peak = std::max(peak, std::fabs(t.num(i, "tau_sent_2_Nm")));
  }
  const json meta = read_json(out / "meta.json");
  const json& rp = meta.at("replay");
  EXPECT_EQ(rp.at("writes").get<long>(), meta.at("session").at("ticks").get<long>());
  EXPECT_GT(peak, 0.0);
  // the peak the device was sent, as the trace's own column says it
  EXPECT_NEAR(rp.at("max_abs_tau_Nm")[1].get<double>(), peak, 1e-9);
  EXPECT_LE(peak, 0.040 + 1e-12);
}

TEST(ReplayCli, RefusesAMissingRecordingAndLockstepOnARealDevice) {
  const auto r = run("hw record --device replay:/nonexistent/rec --duration 0.1",
                     kEnv);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("no such folder"), std::string::npos) << r.err;
  const auto e = run("hw record --device replay:" + recorded().string() +
                         " --replay-end rewind --duration 0.1",
                     kEnv);
  EXPECT_EQ(e.exit_code, 2) << e.err;
  EXPECT_NE(e.err.find("--replay-end: 'rewind'"), std::string::npos) << e.err;
  const auto f = run("hw record --device firewire --clock lockstep --duration 0.1",
                     kEnv);
  EXPECT_EQ(f.exit_code, 2) << f.err;
  EXPECT_NE(f.err.find("only a simulated device or a recording"), std::string::npos)
      << f.err;
}

// On the wall clock which row a tick gets depends on when it ran: asserted
// is only that every replayed reading is a recorded row's, in the
// recording's order.
TEST(ReplayCliRealtime, WallClockReplayServesRecordedRowsInOrder) {
  const fs::path rec = recorded();
  const fs::path out = vmh::testing::fresh_dir("vmh_replay_", "wall");
  const auto r = run("hw record --device replay:" + rec.string() +
                         " --no-realtime --duration 0.5 --quiet --out " +
                         out.string(),
                     kEnv);
  // a host that starves the servo thread for long may end the session as
  // the device gone (exit 1); the trace up to then is still judged
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 1) << r.err;
  ASSERT_TRUE(fs::exists(out / "trace.csv")) << r.err;
  const Csv a = read_csv(rec / "trace.csv");
  const Csv b = read_csv(out / "trace.csv");
  ASSERT_GT(b.rows.size(), 0u);
  std::size_t at = 0;
  for (std::size_t i = 0; i < b.rows.size(); ++i) {
    if (b.rows[i][b.col("read_error")] != "ok") continue;
    // the first recorded row at or after the last match whose angles agree
    std::size_t k = at;
    for (; k < a.rows.size(); ++k) {
      double d = 0.0;
      for (const char* q : kQ) d = std::max(d, std::fabs(a.num(k, q) - b.num(i, q)));
      if (d < 1e-8) break;
    }
    ASSERT_LT(k, a.rows.size()) << "replayed row " << i << " is no recorded row "
                                << "at or after row " << at;
    at = k;
  }
}

}  // namespace
