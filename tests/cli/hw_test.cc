// `vmhaptics hw`, as a user runs it, on the emulator (and, in
// hw_openhaptics_cli_test.cc, through the test libHD.so): each verb's JSON,
// the files it writes, and the errors for bad input and for a device that
// stops answering. These run in real time: a few seconds each.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::first_line;
using vmh::testing::run;

fs::path fresh_dir(const std::string& name) {
  return vmh::testing::fresh_dir("vmh_hw_", name);
}

// a private calibration store, so that no test reads another's
const std::string kEnv = "XDG_CONFIG_HOME=" + ::testing::TempDir() + "vmh_hw_cfg ";

json parse(const std::string& text) { return json::parse(text); }

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  return out;
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  int column(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return static_cast<int>(i);
    }
    return -1;
  }
};

Csv read_csv(const fs::path& p) {
  Csv c;
  std::ifstream in(p);
  std::string line;
  if (std::getline(in, line)) c.header = split(line);
  while (std::getline(in, line)) c.rows.push_back(split(line));
  return c;
}

TEST(HwCli, ListNamesEveryBackendAndWhyNot) {
  const auto r = run("hw list");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = parse(r.out);
  std::vector<std::string> names;
  for (const auto& b : j.at("backends")) {
    names.push_back(b.at("name"));
    EXPECT_TRUE(b.contains("available"));
    if (!b.at("available").get<bool>()) {
      EXPECT_FALSE(b.at("why_not").get<std::string>().empty()) << b.dump();
    }
  }
  // each backend as it registered: hw/'s (hw/backends.cc), then sim/'s
  EXPECT_EQ(names, (std::vector<std::string>{"openhaptics", "firewire", "usb",
                                             "served", "replay", "emulator",
                                             "emulator:firewire"}));
  EXPECT_TRUE(j["backends"][5]["available"].get<bool>());
  // served devices are listed from shared memory (whatever this machine
  // serves now): always available
  EXPECT_TRUE(j["backends"][3]["available"].get<bool>());
  EXPECT_TRUE(j["backends"][3]["found"].is_array());
  // a recording has no discovery: the row says what to give instead
  EXPECT_NE(j["backends"][4]["why_not"].get<std::string>().find(
                "give a recording folder"),
            std::string::npos);
}

TEST(HwCli, ListSaysWhichLibHDItLookedFor) {
  const auto r = run("hw list", "VMH_LIBHD=/nonexistent/libHD.so ");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json oh = parse(r.out).at("backends").at(0);
  EXPECT_FALSE(oh.at("available").get<bool>());
  EXPECT_NE(oh.at("why_not").get<std::string>().find("/nonexistent/libHD.so"),
            std::string::npos)
      << oh.dump();
}

TEST(HwCli, ProbeEmulatorIdentifiesAndReads) {
  const auto r = run("hw probe --device emulator --seconds 1", kEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = parse(r.out);
  EXPECT_EQ(j.at("device").at("backend"), "emulator");
  EXPECT_FALSE(j.at("device").at("serial").get<std::string>().empty());
  EXPECT_EQ(j.at("device").at("input_dof"), 6);
  EXPECT_EQ(j.at("device").at("output_dof"), 3);
  // a loop that ran: far more than a handful of ticks in a second
  EXPECT_GT(j.at("rate_Hz").get<double>(), 100.0);
  ASSERT_EQ(j.at("q_device_rad").size(), 6u);
  for (const auto& q : j.at("q_device_rad")) {
    EXPECT_TRUE(std::isfinite(q.get<double>()));
  }
  const auto reports = j.at("reports").get<std::vector<std::string>>();
  for (const char* f : {"joints", "buttons", "inkwell", "timestamp", "encoders"}) {
    EXPECT_NE(std::find(reports.begin(), reports.end(), f), reports.end()) << f;
  }
  EXPECT_FALSE(j.at("calibration").at("source").get<std::string>().empty());
}

TEST(HwCli, RecordWritesRunsColumnsAndMeta) {
  const fs::path out = fresh_dir("record");
  const auto r = run("hw record --device emulator --duration 2 --quiet --out " +
                         out.string(), kEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Csv c = read_csv(out / "trace.csv");
  // the same names as `vmhaptics run` for the same quantities
  for (const char* col : {"t_s", "q1_rad", "q6_rad", "p_x_mm", "a_z", "tau_1_Nm",
                          "tau_applied_1_Nm", "hand_x_mm", "buttons", "docked",
                          "period_s", "safety_flags", "enc_1", "pot_6"}) {
    EXPECT_GE(c.column(col), 0) << col;
  }
  ASSERT_GT(c.rows.size(), 1000u);
  for (const auto& row : c.rows) ASSERT_EQ(row.size(), c.header.size());
  // the scripted hand tours the workspace: the joints move
  const int q1 = c.column("q1_rad");
  const int q5 = c.column("q5_rad");
  double lo1 = 1e9, hi1 = -1e9, lo5 = 1e9, hi5 = -1e9;
  for (const auto& row : c.rows) {
    lo1 = std::min(lo1, std::stod(row[q1]));
    hi1 = std::max(hi1, std::stod(row[q1]));
    lo5 = std::min(lo5, std::stod(row[q5]));
    hi5 = std::max(hi5, std::stod(row[q5]));
  }
  EXPECT_GT(hi1 - lo1, 0.01);
  EXPECT_GT(hi5 - lo5, 0.01);
  // zero force while recording
  const int tau = c.column("tau_sent_1_Nm");
  for (const auto& row : c.rows) ASSERT_EQ(std::stod(row[tau]), 0.0);

  std::ifstream in(out / "meta.json");
  const json m = json::parse(in);
  EXPECT_EQ(m.at("device").at("backend"), "emulator");
  EXPECT_FALSE(m.at("date_utc").get<std::string>().empty());
  EXPECT_FALSE(m.at("software").at("version").get<std::string>().empty());
  EXPECT_EQ(m.at("session").at("stop_reason"), "duration");
  EXPECT_TRUE(m.at("session").at("timing").contains("jitter_p99_us"));
  // the periods' histogram counts every period but the first tick's
  long periods = 0;
  for (const auto& n : m.at("period_histogram").at("counts")) periods += n.get<long>();
  EXPECT_EQ(periods, m.at("session").at("timing").at("ticks").get<long>() - 1);
}

TEST(HwCli, MotorTestMovesTheJointWithTheTorquesSign) {
  for (const double torque : {40.0, -40.0}) {
    const fs::path out = fresh_dir("motor");
    const auto r = run("hw motor-test --device emulator --motor 1 --torque-mNm " +
                           std::to_string(torque) + " --ms 300 --quiet --out " +
                           out.string(), kEnv);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json j = parse(r.out);
    EXPECT_TRUE(j.at("moved_with_torque_sign").get<bool>()) << r.out;
    // the safety layer let it through, and no more than was asked
    const double sent = j.at("torque_sent_peak_mNm").get<double>();
    EXPECT_GT(sent * torque, 0.0);
    EXPECT_LE(std::abs(sent), std::abs(torque) + 1e-9);
    EXPECT_TRUE(fs::exists(out / "trace.csv"));
  }
}

TEST(HwCli, UnknownDeviceIsNamed) {
  const auto r = run("hw probe --device nosuch");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("'nosuch'"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST(HwCli, BadEmulatorOptionsAreNamed) {
  const auto f = run("hw probe --device emulator --fault bogus@1");
  EXPECT_EQ(f.exit_code, 2);
  EXPECT_NE(f.err.find("bogus"), std::string::npos) << f.err;
  const auto h = run("hw probe --device emulator --hand juggle");
  EXPECT_EQ(h.exit_code, 2);
  EXPECT_NE(h.err.find("juggle"), std::string::npos) << h.err;
  const auto s = run("hw probe --device emulator:nosuch_case");
  EXPECT_EQ(s.exit_code, 2);
  EXPECT_NE(s.err.find("nosuch_case"), std::string::npos) << s.err;
}

// Every time option of hw is bounded and checked before the device is
// opened: exit 2 and one line naming the verb, the option, the range and
// the value (nan and 0 are not "the default"; 1e308 is not a long run).
TEST(HwCli, TimesOutOfRangeAreRefusedNamingTheOption) {
  const struct {
    const char* args;
    const char* message;
  } bad[] = {
      {"hw run case1 --device emulator --duration 1e308",
       "hw run: --duration must be > 0 and <= 3600 s, got 1e+308"},
      {"hw run case1 --device emulator --duration nan",
       "hw run: --duration must be > 0 and <= 3600 s, got nan"},
      {"hw run case1 --device emulator --duration 0",
       "hw run: --duration must be > 0 and <= 3600 s, got 0"},
      {"hw record --device emulator --duration 1e308",
       "hw record: --duration must be > 0 and <= 86400 s, got 1e+308"},
      {"hw record --device emulator --duration nan",
       "hw record: --duration must be > 0 and <= 86400 s, got nan"},
      {"hw probe --device emulator --seconds 1e9",
       "hw probe: --seconds must be > 0 and <= 3600 s, got 1e+09"},
      {"hw calibrate --device emulator --dock-s inf",
       "hw calibrate: --dock-s must be > 1 and <= 600 s, got inf"},
      {"hw calibrate --device emulator --sweep-s 1",
       "hw calibrate: --sweep-s must be > 1 and <= 600 s, got 1"},
      {"hw capture --device usb --duration 1e9 --out x.bin",
       "hw capture: --duration must be > 0 and <= 3600 s, got 1e+09"},
  };
  for (const auto& b : bad) {
    const auto r = run(b.args, kEnv);
    EXPECT_EQ(r.exit_code, 2) << b.args << ": " << r.err;
    EXPECT_EQ(r.err.substr(0, r.err.find('\n')),
              std::string("vmhaptics: error: ") + b.message)
        << b.args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

// --out is checked before the device opens: a folder that cannot be made,
// a file, an empty name are usage errors (exit 2), named, nothing written
TEST(HwCli, UnusableOutputIsRefusedBeforeTheDeviceOpens) {
  const fs::path file = fresh_dir("out_is_a_file");
  std::ofstream(file) << "x";
  for (const std::string& out :
       {std::string("/proc/vmh_no_such_dir"), file.string(), std::string("''")}) {
    const auto r = run("hw record --device emulator --duration 1 --quiet "
                       "--out " + out, kEnv);
    EXPECT_EQ(r.exit_code, 2) << out << ": " << r.err;
    EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
    if (out != "''") {
      EXPECT_NE(r.err.find(out), std::string::npos) << r.err;
    }
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_EQ(first_line(file), "x");
}

// a disk that fills up mid-session (a file size limit of 64 kB, its signal
// ignored, so that the write fails with EFBIG as on a full disk): the
// session stops at once with the cause named, rather than drive the device
// unrecorded, and leaves no half set
TEST(HwCli, AFullDiskStopsTheSession) {
  const fs::path out = fresh_dir("full");
  const auto r = run("hw record --device emulator --duration 20 --quiet --out " +
                         out.string(),
                     "ulimit -f 128; trap '' XFSZ; " + kEnv);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("trace.csv"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("failed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("zero torque"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "meta.json"));
}

TEST(HwCli, RunOnTheEmulatorTakesTheSceneAsTarget) {
  const auto r = run("hw run --device emulator:case2 case1", kEnv);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("emulator:case2"), std::string::npos) << r.err;
}

TEST(HwCli, MissingLibHDIsNamedAndNothingIsWritten) {
  const fs::path out = fresh_dir("nolib");
  const auto r = run("hw record --device openhaptics --out " + out.string(),
                     "VMH_LIBHD=/nonexistent/libHD.so ");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("/nonexistent/libHD.so"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out / "trace.csv"));
}

TEST(HwCli, DeviceThatStopsAnsweringKeepsTheTrace) {
  const fs::path out = fresh_dir("unplug");
  const auto r = run("hw record --device emulator --fault unplug@1.0:60 "
                     "--duration 10 --quiet --out " + out.string(), kEnv);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("not_connected"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  const Csv c = read_csv(out / "trace.csv");
  // the readings up to the unplug are all there, and every row is whole
  ASSERT_GT(c.rows.size(), 500u);
  for (const auto& row : c.rows) ASSERT_EQ(row.size(), c.header.size());
  std::ifstream in(out / "meta.json");
  const json m = json::parse(in);
  EXPECT_EQ(m.at("session").at("stop_reason").get<std::string>().rfind(
                "device_gone", 0),
            0u);
  EXPECT_GT(m.at("session").at("read_errors").at("not_connected").get<long>(), 0);
}

// SIGINT in the middle of a recording on the wall clock: it stops at once,
// exit 130, and the set holds every tick up to the signal, each row whole,
// with its meta.json. A real-time test (tests/CMakeLists.txt: label
// realtime): on a host so busy that the emulator starved before the signal
// the session ends first, as emulator_stalled (exit 1), with the same
// whole set; either way no torn row and the cause named.
TEST(HwCliRealtime, SigintStopsAndKeepsACompleteTrace) {
  const fs::path out = fresh_dir("sigint");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string dir = out.string();
    setenv("XDG_CONFIG_HOME", (::testing::TempDir() + "vmh_hw_cfg").c_str(), 1);
    execl(VMH_CLI_PATH, VMH_CLI_PATH, "hw", "record", "--device", "emulator",
          "--clock", "realtime", "--duration", "60", "--quiet", "--out",
          dir.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // let it record, then interrupt
  usleep(2000000);
  kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  const int code = WEXITSTATUS(status);
  std::ifstream in(out / "meta.json");
  const json m = json::parse(in);
  const std::string reason = m.at("session").at("stop_reason");
  if (code == 130) {
    EXPECT_EQ(reason, "signal SIGINT");
  } else {
    EXPECT_EQ(code, 1);
    EXPECT_EQ(reason.rfind("emulator_stalled", 0), 0u) << reason;
  }
  const Csv c = read_csv(out / "trace.csv");
  ASSERT_GT(c.rows.size(), 100u);
  for (const auto& row : c.rows) ASSERT_EQ(row.size(), c.header.size());
}

// hw calibrate on the emulator: the scripted hand docks the stylus and
// sweeps the gimbal; the fit lands near the emulator's hidden calibration,
// is stored under the serial number, and the next probe loads it.
TEST(HwCli, CalibrateStoresAFitNearTheTruthAndProbeLoadsIt) {
  const std::string cfg = ::testing::TempDir() + "vmh_hw_cfg_cal";
  fs::remove_all(cfg);
  const std::string env = "XDG_CONFIG_HOME=" + cfg + " ";
  const auto r = run("hw calibrate --device emulator --quiet", env);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const json j = parse(r.out);
  const std::string stored = j.at("stored");
  EXPECT_EQ(stored.rfind(cfg + "/vmhaptics/calibration/", 0), 0u) << stored;
  EXPECT_TRUE(fs::exists(stored));
  const auto err = j.at("error_vs_truth_rad").get<std::vector<double>>();
  ASSERT_EQ(err.size(), 6u);
  // encoders: within a few counts (2 pi / 15000 = 0.42 mrad each) plus
  // how far the hand's dock misses the inkwell pose
  for (int i = 0; i < 3; ++i) EXPECT_LT(err[i], 0.02) << "t" << i + 1;
  // pots: the sweep presses each joint against its stop
  for (int i = 3; i < 6; ++i) EXPECT_LT(err[i], 0.1) << "t" << i + 1;

  const auto p = run("hw probe --device emulator --seconds 0.5", env);
  ASSERT_EQ(p.exit_code, 0) << p.err;
  EXPECT_EQ(parse(p.out).at("calibration").at("source"), stored);
}

TEST(HwCli, MalformedStoredCalibrationIsNamed) {
  const std::string cfg = ::testing::TempDir() + "vmh_hw_cfg_bad";
  fs::remove_all(cfg);
  fs::create_directories(cfg + "/vmhaptics/calibration");
  std::ofstream(cfg + "/vmhaptics/calibration/EMU-0001.json")
      << R"({"encoder_offset_rad": [0, 0], "pot_gain_rad": [1, 1, 1],
            "pot_offset_rad": [0, 0, 0]})";
  const auto r = run("hw probe --device emulator --seconds 0.2",
                     "XDG_CONFIG_HOME=" + cfg + " ");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("encoder_offset_rad"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("EMU-0001.json"), std::string::npos) << r.err;
}

// A sweep too short to reach every gimbal joint's ends (the emulator's hand
// turns t4, t5, t6 in turn, 3 s each): the fit is refused naming the joint
// it missed and what to redo, nothing is stored, exit 1.
TEST(HwCli, CalibrateRefusesASweepThatMissedAJoint) {
  const std::string cfg = ::testing::TempDir() + "vmh_hw_cfg_short";
  fs::remove_all(cfg);
  const auto r = run("hw calibrate --device emulator --sweep-s 3 --quiet",
                     "XDG_CONFIG_HOME=" + cfg + " ");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.err.find("the sweep of t5 covered codes"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("turn t5 fully"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nothing stored"), std::string::npos) << r.err;
  // a dock phase too short for the hand to settle in the inkwell: the
  // encoders still moved over its last second
  const auto d = run("hw calibrate --device emulator --dock-s 1.5 --quiet",
                     "XDG_CONFIG_HOME=" + cfg + " ");
  EXPECT_EQ(d.exit_code, 1) << d.out;
  EXPECT_NE(d.err.find("moved by"), std::string::npos) << d.err;
  EXPECT_NE(d.err.find("while docked"), std::string::npos) << d.err;
  EXPECT_FALSE(fs::exists(cfg + "/vmhaptics/calibration/EMU-0001.json"));
}

// Two recordings into one --out at the same time: each writes its own set
// and puts it in place whole, so both succeed and the folder holds one of
// them, trace and meta agreeing, every row whole.
TEST(HwCli, TwoWritersOfOneFolderLeaveOneWholeSet) {
  const fs::path out = fresh_dir("two_writers");
  const std::string cmd = std::string(VMH_CLI_PATH) +
                          " hw record --device emulator --duration 4 --quiet --out " +
                          out.string() + " > /dev/null";
  const std::string both = kEnv + cmd + " & p=$!; " + kEnv + cmd +
                           " & q=$!; wait $p; a=$?; wait $q; b=$?; exit $((a + b))";
  EXPECT_EQ(std::system(("bash -c '" + both + "'").c_str()), 0);
  const Csv c = read_csv(out / "trace.csv");
  for (const auto& row : c.rows) ASSERT_EQ(row.size(), c.header.size());
  std::ifstream in(out / "meta.json");
  const json m = json::parse(in);
  EXPECT_EQ(static_cast<long>(c.rows.size()),
            m.at("session").at("ticks").get<long>());
  // t_s strictly increasing: no rows of the other writer in between
  const int t = c.column("t_s");
  for (std::size_t k = 1; k < c.rows.size(); ++k) {
    ASSERT_GT(std::stod(c.rows[k][t]), std::stod(c.rows[k - 1][t])) << k;
  }
  // nothing left behind but the set
  int entries = 0;
  for (const auto& e : fs::directory_iterator(out.parent_path())) {
    if (e.path().filename().string().find("vmh_hw_two_writers") != std::string::npos) {
      ++entries;
    }
  }
  EXPECT_EQ(entries, 1);
}

// `hw run --device emulator caseN` reproduces `run caseN`'s claims, on the
// emulator in lockstep (20 s each, about a second of wall time).
class HwRunCase : public ::testing::TestWithParam<int> {};

TEST_P(HwRunCase, ReproducesTheThesisClaims) {
  const std::string name = "case" + std::to_string(GetParam());
  const fs::path out = fresh_dir("run_" + name);
  const auto r = run("hw run --device emulator " + name + " --quiet --out " +
                         out.string(), kEnv);
  const json j = parse(r.out);
  ASSERT_TRUE(j.contains("claims")) << r.out << r.err;
  ASSERT_FALSE(j.at("claims").empty());
  for (const auto& c : j.at("claims")) {
    EXPECT_TRUE(c.at("pass").get<bool>()) << c.dump();
  }
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const Csv c = read_csv(out / "trace.csv");
  for (const char* col : {"theta_v_1", "F_x_N", "tau_1_Nm", "d_path_mm",
                          "status", "safety", "safety_flags", "tau_sent_1_Nm"}) {
    EXPECT_GE(c.column(col), 0) << col;
  }
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_TRUE(fs::exists(out / "meta.json"));
}

INSTANTIATE_TEST_SUITE_P(Cases, HwRunCase, ::testing::Range(1, 7));

// The same on the wall clock, as a device runs: on an idle host the claims
// hold; on a busy one the session may be disturbed (overruns, read
// timeouts, an emulator stall), and then hw run says so and judges no
// claim, rather than fail or pass one on the host's account. Either way
// the set is whole and the device left at zero torque. Case 2: its claims
// hold on a 6 s script with margin (in lockstep: 16 deg against 25, every
// fraction 1.0 against 0.95); case 1's on_path_no_force needs about 10 s
// of script to settle (0.31 N against 0.05 N at 6 s, in lockstep too), so
// on a host that kept real time case 1 failed here for its script, not
// for the clock.
TEST(HwRunRealtime, ClaimsHoldOrTheDisturbanceIsNamed) {
  const fs::path out = fresh_dir("run_realtime");
  const auto r = run("hw run --device emulator --clock realtime case2 "
                     "--duration 6 --quiet --out " + out.string(), kEnv);
  const json j = parse(r.out);
  EXPECT_EQ(j.at("clock"), "realtime");
  if (j.value("claims_judged", false)) {
    EXPECT_EQ(r.exit_code, 0) << r.err;
    for (const auto& c : j.at("claims")) {
      EXPECT_TRUE(c.at("pass").get<bool>()) << c.dump();
    }
  } else {
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_TRUE(r.err.find("did not keep real time") != std::string::npos ||
                r.err.find("emulator_stalled") != std::string::npos)
        << r.err;
    EXPECT_TRUE(j.at("claims").empty());
  }
  const Csv c = read_csv(out / "trace.csv");
  ASSERT_GT(c.rows.size(), 100u);
  for (const auto& row : c.rows) ASSERT_EQ(row.size(), c.header.size());
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_TRUE(fs::exists(out / "meta.json"));
}

}  // namespace
