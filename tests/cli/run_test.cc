// `vmhaptics run`, as a user runs it: the files it writes and their columns,
// the summary's fields, and the errors for bad input (named, exit 2, nothing
// written).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using vmh::testing::first_line;
using vmh::testing::run;
using vmh::testing::spawn_cli;

fs::path fresh_dir(const std::string& name) {
  return vmh::testing::fresh_dir("vmh_run_", name);
}


TEST(RunCli, WritesTraceAndSummary) {
  const fs::path out = fresh_dir("case1");
  const auto r = run("run case1 --duration 1.5 --out " + out.string());
  // a 1.5 s run has no settled windows for the claims: they fail, exit 1,
  // but the outputs are complete
  EXPECT_EQ(r.exit_code, 1) << r.err;
  ASSERT_TRUE(fs::exists(out / "case1" / "trace.csv"));
  ASSERT_TRUE(fs::exists(out / "case1" / "summary.json"));
  EXPECT_FALSE(fs::exists(out / "case1" / "trace.csv.tmp"));
  for (const char* svg : {"views.svg", "history.svg"}) {
    EXPECT_EQ(first_line(out / "case1" / svg).rfind("<svg", 0), 0u) << svg;
  }

  // the documented columns, in order (docs/outputs.md, "trace.csv")
  const std::string header = first_line(out / "case1" / "trace.csv");
  EXPECT_EQ(header.rfind("t_s,period_s,q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,"
                         "p_x_mm,p_y_mm,p_z_mm,a_x,a_y,a_z,theta_v_1,"
                         "theta_r_1,xv_x_mm,xv_y_mm,xv_z_mm,xr_x_mm,",
                         0),
            0u)
      << header;
  for (const char* col : {"e_1_mm", "e_6_rad", "f_1_N", "f_6_Nmm", "F_x_N",
                          "F_z_N", "tau_1_Nm", "tau_3_Nm", "hand_x_mm",
                          "hand_z_mm", "d_path_mm", "status", "phase"}) {
    EXPECT_NE(header.find(col), std::string::npos) << col;
  }
  // one row per servo tick: 1.5 s at 1 kHz
  std::ifstream in(out / "case1" / "trace.csv");
  int lines = 0;
  std::string line;
  while (std::getline(in, line)) ++lines;
  EXPECT_EQ(lines, 1 + 1500);

  std::ifstream js(out / "case1" / "summary.json");
  const nlohmann::json s = nlohmann::json::parse(js);
  EXPECT_EQ(s.at("case"), "case1");
  EXPECT_EQ(s.at("thesis_case"), 1);
  EXPECT_EQ(s.at("metrics").at("ticks"), 1500);
  EXPECT_DOUBLE_EQ(s.at("simulated_s").get<double>(), 1.5);
  EXPECT_EQ(s.at("parameters").at("duration_s").at("source"), "set");
  EXPECT_EQ(s.at("parameters").at("vm_kind").at("value"), "circle");
  EXPECT_EQ(s.at("parameters").at("hand_k_pos_N_per_m").at("source"), "scene");
  // the hand's values, together, each with where its default comes from
  const auto& hand = s.at("parameters").at("hand");
  EXPECT_EQ(hand.size(), 8u);  // six scalars, and the per-axis stiffness and damping
  for (const auto& [name, v] : hand.items()) {
    EXPECT_EQ(name.rfind("hand_", 0), 0u) << name;
    ASSERT_TRUE(v.contains("reference")) << name;
    const std::string ref = v.at("reference");
    EXPECT_NE(ref.find("docs/sources.md"), std::string::npos) << name << ": " << ref;
  }
  // MuJoCo's warnings: none, in the documented shape
  EXPECT_EQ(s.at("mujoco_warnings"),
            nlohmann::json({{"count", 0},
                            {"kinds", nlohmann::json::object()},
                            {"messages", nlohmann::json::array()}}));
  EXPECT_FALSE(s.contains("mujoco_warning_kinds"));
  ASSERT_EQ(s.at("claims").size(), 2u);
  for (const auto& c : s.at("claims")) {
    for (const char* k : {"name", "value", "threshold", "comparison", "unit",
                          "samples", "pass", "prediction", "tolerance",
                          "matches_prediction", "prediction_note",
                          "saturated_fraction", "regime", "holds_where",
                          "sides"}) {
      EXPECT_TRUE(c.contains(k)) << k;
    }
    const std::string regime = c.at("regime");
    EXPECT_TRUE(regime == "linear" || regime == "saturated") << regime;
    // both sides of the pivot (and near the path for an off-path claim)
    ASSERT_GE(c.at("sides").size(), 2u) << c.dump();
    EXPECT_NE(c.at("sides")[0].at("where"), c.at("sides")[1].at("where"));
  }
}

TEST(RunCli, FullCasePassesItsClaims) {
  const auto r = run("run case2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j.at("case2").at("all_claims_pass").get<bool>());
  EXPECT_GE(j.at("case2").at("claims").size(), 4u);
}

TEST(RunCli, UnknownSetNameIsNamedAndWritesNothing) {
  const fs::path out = fresh_dir("badset");
  const auto r = run("run case1 --set k_pos=1 --out " + out.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown parameter 'k_pos'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(RunCli, BadValueIsNamed) {
  const auto r = run("run case1 --set vm_pivot_mm=1,2");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("vm_pivot_mm"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("expects 3"), std::string::npos) << r.err;
}

TEST(RunCli, MalformedSceneIsNamedAndWritesNothing) {
  const fs::path dir = fresh_dir("malformed");
  fs::create_directories(dir);
  const fs::path scene = dir / "broken.xml";
  std::ofstream(scene) << "<mujoco><worldbody><body>\n";
  const auto r = run("run " + scene.string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(scene.string()), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// case1.xml's text, to edit into another scene
std::string case1_xml() {
  return vmh::testing::read_file(std::string(VMH_MODELS_DIR) + "/cases/case1.xml");
}

// `xml` written as dir/cases/<name>. MuJoCo resolves includes relative to
// the scene's folder (even absolute ones), so the copy sits in a cases/
// folder beside links to the real omni/ and hand/ folders
fs::path scene_in(const fs::path& dir, const std::string& name,
                  const std::string& xml) {
  fs::create_directories(dir / "cases");
  for (const char* sub : {"omni", "hand"}) {
    fs::create_directory_symlink(fs::path(VMH_MODELS_DIR) / sub, dir / sub);
  }
  const fs::path scene = dir / "cases" / name;
  std::ofstream(scene) << xml;
  return scene;
}

TEST(RunCli, MissingFieldIsNamed) {
  const fs::path dir = fresh_dir("missing");
  // case1 without vm_kind
  std::string xml = case1_xml();
  const std::size_t at = xml.find("<text name=\"vm_kind\"");
  ASSERT_NE(at, std::string::npos);
  xml.erase(at, xml.find("/>", at) + 2 - at);
  const fs::path scene = scene_in(dir, "no_vm_kind.xml", xml);
  const auto r = run("run " + scene.string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("missing <custom> field 'vm_kind'"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(scene.string()), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(RunCli, UnknownCaseAndUsage) {
  auto r = run("run case8");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("'case8'"), std::string::npos) << r.err;
  r = run("run");
  EXPECT_EQ(r.exit_code, 2);
  r = run("run case1 --all");
  EXPECT_EQ(r.exit_code, 2);
}

// ---- bounds, checked before any work, and physics gone bad (issue 17) ----

// refused as bad input: exit 2, nothing on stdout, one line on stderr with
// every needle
void expect_refused(const std::string& args,
                    const std::vector<std::string>& needles) {
  const auto r = run(args);
  EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
  EXPECT_TRUE(r.out.empty()) << args << " printed " << r.out;
  for (const std::string& n : needles) {
    EXPECT_NE(r.err.find(n), std::string::npos)
        << args << ": '" << r.err << "' lacks '" << n << "'";
  }
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
}

// --duration was a double CLI11 read leniently: "", 0 and nan ran the
// scene's 20 s, 1e308 and 4294968 s wrapped the tick count and ran forever,
// 1e-7 was reported as "0.000000"
TEST(RunCli, DurationIsCheckedBeforeAnyWork) {
  const std::string range = "--duration: field 'duration_s' must be > 0 and "
                            "<= 3600, got ";
  expect_refused("run case1 --duration 1e308", {range + "1e+308"});
  expect_refused("run case1 --duration 4294968", {range + "4294968"});
  expect_refused("run case1 --duration 0", {range + "0"});
  expect_refused("run case1 --duration=-2", {range + "-2"});
  expect_refused("run case1 --duration nan",
                 {"--duration: value 'nan' is not a finite number"});
  expect_refused("run case1 --duration 1e999", {"not a finite number"});
  expect_refused("run case1 --duration ''", {"--duration", "empty"});
  expect_refused("run case1 --duration 1e-7",
                 {"duration_s (1e-07 s) must last from 1 to 1000000000 servo "
                  "periods"});
  // and the check comes before the scene is even looked for
  expect_refused("run case8 --duration 1e308", {"--duration"});
}

TEST(RunCli, TimingParametersAreBounded) {
  expect_refused("run case1 --set servo_period_s=3e6",
                 {"--set: field 'servo_period_s' must be in [1e-05, 1], got "
                  "3000000"});
  expect_refused("run case1 --set physics_step_s=1e-300",
                 {"servo_period_s / physics_step_s (0.001 s / 1e-300 s)",
                  "[1, 1000000], got 1e+297"});
  expect_refused("run case1 --set servo_jitter_s=0.0004,1e12",
                 {"field 'servo_jitter_s' must be >= 0 and <= 1, got 1e+12"});
  expect_refused("run case1 --set physics_step_s=1e-7 "
                 "--set servo_jitter_s=0.0004,0.9",
                 {"servo_jitter_s's longest period", "got 9000000"});
  expect_refused("run case1 --set delay_ticks=65",
                 {"field 'delay_ticks' must be a whole number in [0, 64], got "
                  "65"});
  expect_refused("run case1 --set duration_s=",
                 {"field 'duration_s' expects 1 value(s), got 0"});
  expect_refused("run case1 --jobs ''", {"--jobs", "empty"});
}

// issue 17's hostile inputs that had no test: each is a bad argument (exit
// 2, one line naming it), none hangs or fails as a run (exit 1)
TEST(RunCli, HostileArgumentsAreBadUsage) {
  expect_refused("run case1 --duration 1e5",
                 {"--duration: field 'duration_s' must be > 0 and <= 3600, "
                  "got 100000"});
  expect_refused("run case1 --jobs=-5", {"--jobs", "-5"});
  expect_refused("run case1 --set force_limit_N=1e6", {"force_limit_N"});
  const fs::path dir = fresh_dir("hostile");
  fs::create_directories(dir);
  // a FIFO as the scene blocked the loader's open forever
  const fs::path fifo = dir / "scene.xml";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  expect_refused("run " + fifo.string(), {fifo.string(), "not a regular file"});
  // a symlink loop and a 100,000-character name threw filesystem_error
  // (exit 1)
  const fs::path loop = dir / "loop.xml";
  fs::create_symlink(loop, loop);
  expect_refused("run " + loop.string(), {loop.string()});
  expect_refused("run " + std::string(100000, 'a') + ".xml", {"run: '"});
}

// an ANSI escape in an argument reached the terminal through the error line
TEST(RunCli, ControlCharactersInArgumentsAreEscapedOnStderr) {
  const auto r = run("run \"$(printf '\\033[31mcase9')\"");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("\\x1b[31mcase9"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
}

// a scene whose own step is 0 made the servo period an infinite number of
// physics steps
TEST(RunCli, ASceneStepOfZeroIsRefused) {
  const fs::path dir = fresh_dir("timestep0");
  std::string xml = case1_xml();
  const std::size_t at = xml.find("timestep=\"0.001\"");
  ASSERT_NE(at, std::string::npos);
  xml.replace(at, std::string("timestep=\"0.001\"").size(), "timestep=\"0\"");
  const fs::path scene = scene_in(dir, "timestep0.xml", xml);
  expect_refused("run " + scene.string(),
                 {scene.string(),
                  "the scene's <option timestep> must be finite and > 0, got "
                  "0 s"});
}

// Physics that goes non-finite at the first step: MuJoCo resets the state
// and warns (on stdout, into MUJOCO_LOG.TXT, 999 times over a run, by
// default); the run went on and exited 0. Now it stops with exit 1 and a
// named error, MuJoCo's warning on stderr before it, nothing on stdout and
// no log file in the working directory.
TEST(RunCli, NonFinitePhysicsStopsTheRunWithExitOne) {
  const fs::path dir = fresh_dir("nan_physics");
  fs::create_directories(dir);
  const auto r = run("run case1 --json --set hand_k_pos_N_per_m=1e30",
                     "cd " + dir.string() + " && ");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("vmhaptics: error: run case1: "), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("physics went non-finite at t=0.001 s (q"),
            std::string::npos)
      << r.err;
  // MuJoCo's warning, once, on stderr before the error line
  EXPECT_EQ(r.err.rfind("vmhaptics: warning: MuJoCo warning (bad", 0), 0u)
      << r.err;
  const std::size_t last = r.err.rfind('\n', r.err.size() - 2);
  EXPECT_EQ(r.err.compare(last + 1, 17, "vmhaptics: error:"), 0) << r.err;
  EXPECT_TRUE(fs::is_empty(dir)) << "left a file in the working directory";
}

// ---- whole output sets (docs/outputs.md, "run": how a set is written) ----

// the lines of a text file
int count_lines(const fs::path& p) {
  std::ifstream in(p);
  int lines = 0;
  std::string line;
  while (std::getline(in, line)) ++lines;
  return lines;
}

// `out` holds only complete sets: no hidden or temporary entry, and each
// case folder has the four files, a summary that parses and a trace of
// metrics.ticks rows after its header. Returns the summaries by case.
std::map<std::string, nlohmann::json> complete_sets(const fs::path& out) {
  std::map<std::string, nlohmann::json> sets;
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    EXPECT_NE(name[0], '.') << "left behind: " << name;
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << "left behind: " << name;
    if (name[0] == '.') continue;
    EXPECT_TRUE(e.is_directory()) << name;
    std::set<std::string> files;
    for (const auto& f : fs::directory_iterator(e.path())) {
      files.insert(f.path().filename().string());
    }
    EXPECT_EQ(files, std::set<std::string>({"history.svg", "summary.json",
                                            "trace.csv", "views.svg"}))
        << name;
    std::ifstream js(e.path() / "summary.json");
    nlohmann::json s;
    try {
      s = nlohmann::json::parse(js);
    } catch (const std::exception& ex) {
      ADD_FAILURE() << name << "/summary.json: " << ex.what();
      continue;
    }
    EXPECT_EQ(count_lines(e.path() / "trace.csv"),
              s.at("metrics").at("ticks").get<int>() + 1)
        << name;
    sets[name] = s;
  }
  return sets;
}

// a run over an existing set replaces it whole: the new trace and summary,
// nothing of the old and no temporary left beside it
TEST(RunCli, ASecondRunReplacesTheSetWhole) {
  const fs::path out = fresh_dir("replace");
  ASSERT_EQ(run("run case1 --duration 0.3 --set thesis_case=0 --out " + out.string())
                .exit_code,
            0);
  EXPECT_EQ(complete_sets(out).at("case1").at("metrics").at("ticks"), 300);
  std::ofstream(out / "case1" / "stale.txt") << "from before";
  const auto r = run("run case1 --duration 0.5 --set thesis_case=0 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto sets = complete_sets(out);  // stale.txt would fail it
  ASSERT_EQ(sets.size(), 1u);
  EXPECT_EQ(sets.at("case1").at("metrics").at("ticks"), 500);
}

// a file that cannot be written (here past a file-size limit, EFBIG; a full
// disk, ENOSPC, takes the same path): exit 1 naming the file and the OS's
// reason; the previous set is left as it was, and no temporary
TEST(RunCli, AFailedWriteLeavesThePreviousSet) {
  const fs::path out = fresh_dir("write_fails");
  ASSERT_EQ(run("run case1 --duration 0.05 --set thesis_case=0 --out " + out.string())
                .exit_code,
            0);
  // 100 blocks of 512 bytes: the summary fits, a 1 s trace (~0.9 MB) not
  const auto r = run("run case1 --duration 1 --set thesis_case=0 --out " + out.string(),
                     "trap '' XFSZ; ulimit -f 100; ");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("vmhaptics: error: run case1: " + (out / "case1" / "trace.csv").string() +
                       ": File too large"),
            std::string::npos)
      << r.err;
  const auto sets = complete_sets(out);
  ASSERT_EQ(sets.size(), 1u);
  EXPECT_EQ(sets.at("case1").at("metrics").at("ticks"), 50);
}


// SIGTERM or SIGINT during `run --all`: exit 143 / 130 soon after, one line
// "interrupted: ...", and the out folder holds complete sets only (most
// likely none: a case of 20 simulated seconds takes longer than 0.3 s)
TEST(RunCli, ASignalLeavesOnlyCompleteSets) {
  for (const int signo : {SIGTERM, SIGINT}) {
    const std::string tag = signo == SIGTERM ? "sigterm" : "sigint";
    const fs::path out = fresh_dir(tag);
    const fs::path err = fresh_dir(tag + "_stderr.txt");
    const pid_t pid = spawn_cli({"run", "--all", "--out", out.string()}, err);
    ASSERT_GT(pid, 0);
    usleep(300000);
    const auto sent = std::chrono::steady_clock::now();
    ASSERT_EQ(kill(pid, signo), 0);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
    ASSERT_TRUE(WIFEXITED(status)) << tag;
    EXPECT_EQ(WEXITSTATUS(status), 128 + signo) << tag;
    EXPECT_LT(took, 5.0) << tag;
    const std::string text = first_line(err);
    EXPECT_EQ(text.rfind("vmhaptics: interrupted: run stopped by " +
                             std::string(signo == SIGTERM ? "SIGTERM" : "SIGINT"),
                         0),
              0u)
        << text;
    // the sets finished before the signal, if any, are whole; nothing else
    if (fs::exists(out)) complete_sets(out);
  }
}

// a signal once some sets are complete: those are kept whole, the rest
// removed
TEST(RunCli, ASignalKeepsTheSetsAlreadyComplete) {
  const fs::path out = fresh_dir("sigterm_late");
  const fs::path err = fresh_dir("sigterm_late_stderr.txt");
  // one case at a time, each of 5 simulated s (about a second of wall time
  // with its mirrored and near-path runs): stopped as soon as case1's set
  // is in place, while case2 runs
  const pid_t pid = spawn_cli({"run", "--all", "--jobs", "1", "--duration", "5",
                           "--out", out.string()},
                          err);
  ASSERT_GT(pid, 0);
  for (int i = 0; i < 3000 && !fs::exists(out / "case1"); ++i) usleep(10000);
  ASSERT_EQ(kill(pid, SIGTERM), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 143) << first_line(err);
  EXPECT_EQ(first_line(err),
            "vmhaptics: interrupted: run stopped by SIGTERM; complete sets kept: case1");
  const auto sets = complete_sets(out);
  ASSERT_EQ(sets.size(), 1u);
  EXPECT_EQ(sets.at("case1").at("metrics").at("ticks"), 5000);
}

// two runs into one --out at once: both finish, and what is left is whole
// sets, each one run's own (the summary's ticks match the trace's rows)
TEST(RunCli, ConcurrentRunsIntoOneOutLeaveWholeSets) {
  const fs::path out = fresh_dir("concurrent");
  vmh::testing::CliRun a;
  vmh::testing::CliRun b;
  std::thread ta([&] {
    a = run("run case1 --duration 3 --set thesis_case=0 --out " + out.string());
  });
  std::thread tb([&] {
    b = run("run case1 --duration 4 --set thesis_case=0 --out " + out.string());
  });
  ta.join();
  tb.join();
  EXPECT_EQ(a.exit_code, 0) << a.err;
  EXPECT_EQ(b.exit_code, 0) << b.err;
  const auto sets = complete_sets(out);
  ASSERT_EQ(sets.size(), 1u);
  const int ticks = sets.at("case1").at("metrics").at("ticks");
  EXPECT_TRUE(ticks == 3000 || ticks == 4000) << ticks;
}

// an --out that cannot hold the sets: exit 2 before any simulation (--all
// would take minutes), one line naming the path and the OS's reason
void expect_refused_out(const fs::path& out, const std::string& reason) {
  const auto start = std::chrono::steady_clock::now();
  const auto r = run("run --all --out " + out.string());
  const double took =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.exit_code, 2) << out << ": " << r.err;
  EXPECT_LT(took, 2.0) << out;
  EXPECT_EQ(r.err, "vmhaptics: error: run: --out " + out.string() + ": " + reason + "\n");
  EXPECT_EQ(r.out, "");
}

TEST(RunCli, AnOutThatIsAFileIsRefusedBeforeAnyRun) {
  const fs::path dir = fresh_dir("out_file");
  fs::create_directories(dir);
  std::ofstream(dir / "file") << "x";
  expect_refused_out(dir / "file", "Not a directory");
  expect_refused_out(dir / "file" / "sub", "Not a directory");
  EXPECT_EQ(first_line(dir / "file"), "x");
}

TEST(RunCli, AReadOnlyOutIsRefusedBeforeAnyRun) {
  if (getuid() == 0) GTEST_SKIP() << "root writes in a read-only folder";
  const fs::path dir = fresh_dir("out_read_only");
  fs::create_directories(dir);
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
  expect_refused_out(dir, "Permission denied");
  expect_refused_out(dir / "sub", "Permission denied");
  fs::permissions(dir, fs::perms::owner_all);
}

}  // namespace
