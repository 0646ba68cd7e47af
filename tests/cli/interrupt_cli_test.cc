// SIGINT and SIGTERM during the verbs whose long work is not a device
// session (issue 34): compare, report, hw run outside its session. Each
// exits 128 + the FIRST signal's number with one line naming it, and its
// --out holds the previous whole set or a new whole set, never a part of
// one, and no private folder is left beside it. The signal is sent once
// the verb's private folder (output::OutputSet's ".<name>.tmp-<pid>-...")
// appears, so that it lands in the work whatever the host's load; no
// timing is asserted. Also compare --out's layout: one set, figures named
// by recording, and the --out folders it refuses to replace.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::first_line;
using vmh::testing::read_file;
using vmh::testing::run;
using vmh::testing::spawn_cli;

fs::path intr_dir(const std::string& name) {
  return vmh::testing::fresh_dir("vmh_interrupt_cli_", name);
}


// the private folders beside `out` (".<name>.tmp-...", ".<name>.render-...")
std::vector<fs::path> intr_private_folders(const fs::path& out) {
  std::vector<fs::path> found;
  const std::string prefix = "." + out.filename().string() + ".";
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out.parent_path(), ec)) {
    if (e.path().filename().string().rfind(prefix, 0) == 0) found.push_back(e.path());
  }
  return found;
}

// waits (at most a minute) until a private folder beside `out` exists or the
// child ended; whether the folder came
bool intr_wait_for_private_folder(const fs::path& out, pid_t pid) {
  for (int i = 0; i < 60000; ++i) {
    if (!intr_private_folders(out).empty()) return true;
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return false;
    usleep(1000);
  }
  return false;
}

int intr_exit_code(pid_t pid) {
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
}

// a recording of the emulator in lockstep: the workspace tour
void intr_record(const fs::path& dir, double seconds) {
  const auto r = run("hw record --device emulator --clock lockstep --quiet --duration " +
                     std::to_string(seconds) + " --out " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
}

// compare's set at `out` is whole: compare.json parses, and every figure it
// names is there, under `out`
void intr_expect_whole_compare_set(const fs::path& out) {
  ASSERT_TRUE(fs::is_regular_file(out / "compare.json")) << out;
  const json j = json::parse(read_file(out / "compare.json"));
  ASSERT_FALSE(j.at("figures").empty());
  for (const json& f : j.at("figures")) {
    const fs::path p = f.get<std::string>();
    EXPECT_EQ(p.parent_path().parent_path(), out) << p;
    EXPECT_TRUE(fs::is_regular_file(p)) << p;
  }
}

// the recording the compare tests read: one tour, made once per process
// (ctest runs each test in its own, maybe at once: a folder of its own)
const fs::path& intr_tour() {
  static const fs::path dir = [] {
    const fs::path d = intr_dir("tour_" + std::to_string(getpid()));
    intr_record(d, 4.0);
    return d;
  }();
  return dir;
}

// a/rec and b/rec: figures in rec/ and rec-2/, one set, named in the JSON
TEST(CompareOut, FiguresAreNamedByRecordingAndNeverShareAFolder) {
  const fs::path base = intr_dir("same_name");
  fs::create_directories(base / "a");
  fs::create_directories(base / "b");
  fs::copy(intr_tour(), base / "a" / "rec");
  fs::copy(intr_tour(), base / "b" / "rec");
  const fs::path out = base / "cmp";
  const auto r = run("compare " + (base / "a" / "rec").string() + " " +
                     (base / "b" / "rec/").string() + " --out " + out.string());
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 1) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j.at("recordings").size(), 2u);
  EXPECT_EQ(j.at("recordings")[0].at("figures_dir"), (out / "rec").string());
  EXPECT_EQ(j.at("recordings")[1].at("figures_dir"), (out / "rec-2").string());
  std::set<std::string> folders;
  for (const auto& e : fs::directory_iterator(out)) {
    folders.insert(e.path().filename().string());
  }
  EXPECT_EQ(folders, (std::set<std::string>{"compare.json", "rec", "rec-2"}));
  EXPECT_FALSE(fs::is_empty(out / "rec"));
  EXPECT_FALSE(fs::is_empty(out / "rec-2"));
  intr_expect_whole_compare_set(out);
  EXPECT_EQ(json::parse(read_file(out / "compare.json")), j);
  EXPECT_TRUE(intr_private_folders(out).empty());
}

// a name outside [A-Za-z0-9._-] (or hidden) is reduced to that set
TEST(CompareOut, AFolderNameIsReducedToTheSafeSet) {
  const fs::path base = intr_dir("odd_name");
  fs::create_directories(base);
  fs::copy(intr_tour(), base / ".odd name$");
  const fs::path out = base / "cmp";
  const auto r = run("compare '" + (base / ".odd name$").string() + "' --out " +
                     out.string());
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 1) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("recordings")[0].at("figures_dir"), (out / "_odd_name_").string());
  EXPECT_TRUE(fs::is_directory(out / "_odd_name_"));
}

// compare replaces --out whole: a folder that holds a recording given, or
// files that are not an earlier compare's, is refused (exit 2, untouched)
TEST(CompareOut, RefusesToReplaceWhatIsNotItsOwn) {
  const fs::path base = intr_dir("refuse");
  fs::create_directories(base / "keep");
  fs::copy(intr_tour(), base / "rec");
  {
    std::ofstream(base / "keep" / "notes.txt") << "mine\n";
  }
  const auto holds = run("compare " + (base / "rec").string() + " --out " + base.string());
  EXPECT_EQ(holds.exit_code, 2) << holds.err;
  EXPECT_NE(holds.err.find("holds the recording"), std::string::npos) << holds.err;
  const auto same = run("compare " + (base / "rec").string() + " --out " +
                        (base / "rec").string());
  EXPECT_EQ(same.exit_code, 2) << same.err;
  const auto foreign = run("compare " + (base / "rec").string() + " --out " +
                           (base / "keep").string());
  EXPECT_EQ(foreign.exit_code, 2) << foreign.err;
  EXPECT_NE(foreign.err.find("no compare.json"), std::string::npos) << foreign.err;
  EXPECT_EQ(read_file(base / "keep" / "notes.txt"), "mine\n");
  EXPECT_TRUE(fs::is_regular_file(base / "rec" / "trace.csv"));
  const auto dot = run("compare " + (base / "rec").string() + " --out .");
  EXPECT_EQ(dot.exit_code, 2) << dot.err;
}

// two compares into one --out at once: both finish, and --out is one whole
// set (the last one's)
TEST(CompareOut, TwoAtOnceBothFinishAndLeaveOneWholeSet) {
  const fs::path base = intr_dir("concurrent");
  const fs::path out = base / "cmp";
  const fs::path err_a = base.string() + "_a.txt", err_b = base.string() + "_b.txt";
  const pid_t a = spawn_cli({"compare", intr_tour().string(), "--out", out.string()}, err_a);
  const pid_t b = spawn_cli({"compare", intr_tour().string(), "--out", out.string()}, err_b);
  ASSERT_GT(a, 0);
  ASSERT_GT(b, 0);
  const int code_a = intr_exit_code(a), code_b = intr_exit_code(b);
  EXPECT_TRUE(code_a == 0 || code_a == 1) << code_a << " " << first_line(err_a);
  EXPECT_EQ(code_a, code_b) << first_line(err_b);
  intr_expect_whole_compare_set(out);
  EXPECT_TRUE(intr_private_folders(out).empty());
}

// a signal while compare works: exit 130 / 143 naming it, and --out still
// the previous whole set (or, had it finished first, the new whole set)
TEST(CompareOut, ASignalLeavesThePreviousSetOrAWholeNewOne) {
  const fs::path base = intr_dir("signal");
  const fs::path out = base / "cmp";
  ASSERT_LE(run("compare " + intr_tour().string() + " --out " + out.string()).exit_code, 1);
  const std::string before = read_file(out / "compare.json");
  // four copies of the tour, so that the work outlasts the signal's trip
  std::vector<std::string> args = {"compare"};
  for (int i = 0; i < 4; ++i) args.push_back(intr_tour().string());
  args.push_back("--out");
  args.push_back(out.string());
  for (const int signo : {SIGINT, SIGTERM}) {
    const std::string name = signo == SIGINT ? "SIGINT" : "SIGTERM";
    const fs::path err = base.string() + "_" + name + ".txt";
    const pid_t pid = spawn_cli(args, err);
    ASSERT_GT(pid, 0);
    ASSERT_TRUE(intr_wait_for_private_folder(out, pid)) << first_line(err);
    ASSERT_EQ(kill(pid, signo), 0);
    EXPECT_EQ(intr_exit_code(pid), 128 + signo) << first_line(err);
    const std::string line = first_line(err);
    EXPECT_EQ(line.rfind("vmhaptics: interrupted: compare stopped by " + name, 0), 0u)
        << line;
    intr_expect_whole_compare_set(out);
    if (line.find("nothing written") != std::string::npos) {
      EXPECT_EQ(read_file(out / "compare.json"), before);
    }
    EXPECT_TRUE(intr_private_folders(out).empty());
  }
}

// SIGINT, SIGINT, SIGTERM at once: the first one is named and sets the
// exit (issue 34: 143 naming SIGTERM)
TEST(CompareOut, TheFirstOfSeveralSignalsWins) {
  const fs::path base = intr_dir("three");
  const fs::path out = base / "cmp";
  const fs::path err = base.string() + "_err.txt";
  std::vector<std::string> args = {"compare"};
  for (int i = 0; i < 4; ++i) args.push_back(intr_tour().string());
  args.push_back("--out");
  args.push_back(out.string());
  const pid_t pid = spawn_cli(args, err);
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(intr_wait_for_private_folder(out, pid)) << first_line(err);
  kill(pid, SIGINT);
  kill(pid, SIGINT);
  kill(pid, SIGTERM);
  EXPECT_EQ(intr_exit_code(pid), 130) << first_line(err);
  EXPECT_EQ(first_line(err).rfind("vmhaptics: interrupted: compare stopped by SIGINT", 0),
            0u)
      << first_line(err);
  EXPECT_FALSE(fs::exists(out) && !fs::is_regular_file(out / "compare.json"));
  EXPECT_TRUE(intr_private_folders(out).empty());
}

// hw run on the emulator, stopped once its set's private folder exists
// (before, in or after its session): exit 130, and --out is nothing or the
// whole set, trace.csv never without summary.json and meta.json
TEST(HwRunInterrupt, ASignalLeavesNothingOrTheWholeSet) {
  const fs::path base = intr_dir("hw_run");
  const fs::path out = base / "run";
  const fs::path err = base.string() + "_err.txt";
  fs::create_directories(base);
  const pid_t pid = spawn_cli({"hw", "run", "case1", "--device", "emulator", "--clock",
                                "lockstep", "--quiet", "--out", out.string()},
                               err);
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(intr_wait_for_private_folder(out, pid)) << first_line(err);
  ASSERT_EQ(kill(pid, SIGINT), 0);
  EXPECT_EQ(intr_exit_code(pid), 130) << first_line(err);
  EXPECT_NE(first_line(err).find("SIGINT"), std::string::npos) << first_line(err);
  if (fs::exists(out)) {
    for (const char* f : {"trace.csv", "summary.json", "meta.json"}) {
      EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
    }
    const json summary = json::parse(read_file(out / "summary.json"), nullptr, false);
    EXPECT_FALSE(summary.is_discarded());
  }
  EXPECT_TRUE(intr_private_folders(out).empty());
}

// report stopped once its first case's set is being written: exit 143, no
// report.html, each case folder there a whole set
TEST(ReportInterrupt, ASignalLeavesWholeSetsAndNoPage) {
  const fs::path out = intr_dir("report");
  const fs::path err = out.string() + "_err.txt";
  const pid_t pid = spawn_cli({"report", "--quick", "--jobs", "1", "--out", out.string()},
                               err);
  ASSERT_GT(pid, 0);
  // the first case's private folder, inside --out
  bool started = false;
  for (int i = 0; i < 60000 && !started; ++i) {
    started = !intr_private_folders(out / "case1").empty();
    int status = 0;
    if (!started) usleep(1000);
    ASSERT_NE(waitpid(pid, &status, WNOHANG), pid) << first_line(err);
  }
  ASSERT_TRUE(started);
  ASSERT_EQ(kill(pid, SIGTERM), 0);
  EXPECT_EQ(intr_exit_code(pid), 143) << first_line(err);
  EXPECT_EQ(first_line(err).rfind("vmhaptics: interrupted: report stopped by SIGTERM", 0), 0u)
      << first_line(err);
  EXPECT_FALSE(fs::exists(out / "report.html"));
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    EXPECT_NE(name[0], '.') << name;  // no private folder left
    if (name.rfind("case", 0) == 0) {
      EXPECT_TRUE(fs::is_regular_file(e.path() / "summary.json")) << name;
      EXPECT_TRUE(fs::is_regular_file(e.path() / "trace.csv")) << name;
    }
  }
}

}  // namespace
