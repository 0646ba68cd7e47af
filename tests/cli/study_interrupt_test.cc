// SIGINT and SIGTERM during the study verbs (issue 34, item 3): each exits
// 128 + the first signal's number with one line naming it, and its --out
// holds its previous files (or nothing, if it was not there) unless the
// signal came as the new ones went in, when they are all there. The study
// runs with stderr on a pseudo-terminal, so that it draws its progress bar
// there; the signal is sent once the bar's first line has come, so that it
// lands in the study's work whatever the host's load. No timing is
// asserted.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::read_file;

fs::path sti_dir(const std::string& name) {
  return vmh::testing::fresh_dir("vmh_study_interrupt_", name);
}

void sti_write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

// A study run in a child with stdout to /dev/null and stderr on a
// pseudo-terminal whose other end the test reads: the verb sees a terminal
// and draws its progress bar.
struct StiChild {
  pid_t pid = -1;
  int master = -1;
  std::string err;  // what came on the terminal so far
};

StiChild sti_spawn(const std::vector<std::string>& args) {
  StiChild c;
  c.master = posix_openpt(O_RDWR | O_NOCTTY);
  if (c.master < 0 || grantpt(c.master) != 0 || unlockpt(c.master) != 0) return c;
  const char* slave_name = ptsname(c.master);
  if (slave_name == nullptr) return c;
  c.pid = vmh::testing::spawn_cli(args, slave_name);
  return c;
}

// reads what the terminal has for at most `timeout_ms`; false once the
// child's end is closed (it ended)
bool sti_read_some(StiChild* c, int timeout_ms) {
  pollfd p{c->master, POLLIN, 0};
  const int ready = poll(&p, 1, timeout_ms);
  if (ready <= 0) return ready == 0 || errno == EINTR;
  char buf[4096];
  const ssize_t n = read(c->master, buf, sizeof buf);
  if (n <= 0) return false;  // EIO: no one holds the child's end any more
  c->err.append(buf, static_cast<std::size_t>(n));
  return true;
}

// waits (at most two minutes) until `text` has come on the terminal;
// whether it came before the child ended
bool sti_wait_for(StiChild* c, const std::string& text) {
  for (int i = 0; i < 1200; ++i) {
    if (c->err.find(text) != std::string::npos) return true;
    if (!sti_read_some(c, 100)) return c->err.find(text) != std::string::npos;
  }
  return false;
}

// waits (at most two minutes) until the bar shows an item done ("... 1/25
// elapsed ..."): the study is then in the middle of its work, its threads
// busy; whether that came before the child ended
bool sti_wait_for_an_item_done(StiChild* c) {
  const std::regex done(R"( [1-9][0-9]*/[0-9]+ +elapsed)");
  for (int i = 0; i < 1200; ++i) {
    if (std::regex_search(c->err, done)) return true;
    if (!sti_read_some(c, 100)) return std::regex_search(c->err, done);
  }
  return false;
}

// reads the terminal to the child's end and returns its exit code (1000 +
// the signal if a signal ended it)
int sti_finish(StiChild* c) {
  while (sti_read_some(c, 1000)) {
  }
  close(c->master);
  int status = 0;
  if (waitpid(c->pid, &status, 0) != c->pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
}

// the line the verb ended with ("vmhaptics: ..."), the bar's '\r's aside
std::string sti_error_line(const std::string& err) {
  const auto at = err.find("vmhaptics: ");
  if (at == std::string::npos) return "";
  const auto end = err.find_first_of("\r\n", at);
  return err.substr(at, end == std::string::npos ? std::string::npos : end - at);
}

// the private folders beside `dest` (output::OutputSet's ".<name>.tmp-...")
std::vector<fs::path> sti_private_folders(const fs::path& dest) {
  std::vector<fs::path> found;
  const std::string prefix = "." + dest.filename().string() + ".";
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dest.parent_path(), ec)) {
    if (e.path().filename().string().rfind(prefix, 0) == 0) found.push_back(e.path());
  }
  return found;
}

// every regular file under `dir` and what it holds
std::map<std::string, std::string> sti_files(const fs::path& dir) {
  std::map<std::string, std::string> files;
  std::error_code ec;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec)) {
    if (e.is_regular_file()) {
      files[fs::relative(e.path(), dir).string()] = read_file(e.path());
    }
  }
  return files;
}

// Runs `args` (a study writing into `out`), sends `signo` once the bar
// labelled `label` has come (with `mid_work`, once it shows an item
// done), and checks: exit 128 + signo, the line naming
// `verb` and the signal, and `out` as `before` (not there, if empty)
// unless the line says the new files were written whole (then
// `check_whole` judges them). Returns the line.
std::string sti_interrupt(const std::vector<std::string>& args, const std::string& label,
                          const std::string& verb, int signo, const fs::path& out,
                          const std::map<std::string, std::string>& before,
                          const std::function<void(const fs::path&)>& check_whole,
                          bool mid_work = false) {
  StiChild c = sti_spawn(args);
  EXPECT_GT(c.pid, 0);
  if (c.pid <= 0) return "";
  const bool started =
      sti_wait_for(&c, label) && (!mid_work || sti_wait_for_an_item_done(&c));
  EXPECT_TRUE(started) << c.err;
  if (started) {
    EXPECT_EQ(kill(c.pid, signo), 0);
  }
  const int code = sti_finish(&c);
  const std::string name = signo == SIGINT ? "SIGINT" : "SIGTERM";
  const std::string line = sti_error_line(c.err);
  EXPECT_EQ(code, 128 + signo) << c.err;
  EXPECT_EQ(line.rfind("vmhaptics: interrupted: " + verb + " stopped by " + name, 0), 0u)
      << c.err;
  if (line.find("written whole") != std::string::npos) {
    check_whole(out);
  } else {
    EXPECT_NE(line.find("nothing written"), std::string::npos) << line;
    if (before.empty()) {
      EXPECT_FALSE(fs::exists(out)) << out;
    } else {
      EXPECT_EQ(sti_files(out), before);
    }
  }
  return line;
}

// sensitivity's three files, whole: the JSON parses and names its points
void sti_whole_sensitivity(const fs::path& out) {
  const json j = json::parse(read_file(out / "sensitivity.json"), nullptr, false);
  ASSERT_FALSE(j.is_discarded());
  EXPECT_GT(j.at("point_count").get<int>(), 0);
  EXPECT_FALSE(read_file(out / "sensitivity.csv").empty());
  EXPECT_FALSE(read_file(out / "sensitivity.svg").empty());
}

// extremes' files, whole: the JSON parses, and every scenario it names has
// its series
void sti_whole_extremes(const fs::path& out) {
  const json j = json::parse(read_file(out / "extremes.json"), nullptr, false);
  ASSERT_FALSE(j.is_discarded());
  for (const json& s : j.at("scenarios")) {
    EXPECT_TRUE(fs::is_regular_file(out / "extremes" /
                                    (s.at("scenario").get<std::string>() + ".csv")))
        << s.dump();
  }
  EXPECT_TRUE(fs::is_regular_file(out / "extremes.svg"));
}

// study sensitivity --quick, one case, stopped once its bar is drawn: SIGINT
// exits 130 and SIGTERM 143, each naming its signal, and the folder's
// previous files are as they were
TEST(StudyInterrupt, SensitivityStopsOnEitherSignalAndKeepsThePreviousFiles) {
  const fs::path out = sti_dir("sensitivity");
  sti_write(out / "sensitivity.json", "{\"previous\": true}\n");
  sti_write(out / "sensitivity.csv", "previous\n");
  sti_write(out / "sensitivity.svg", "<svg/>\n");
  const auto before = sti_files(out);
  for (const int signo : {SIGINT, SIGTERM}) {
    // SIGINT once a point is done (the other thread amid one), SIGTERM as
    // the sweep starts
    sti_interrupt({"study", "sensitivity", "--quick", "--case", "1", "--jobs", "2", "--out",
                   out.string()},
                  "study sensitivity", "study sensitivity", signo, out, before,
                  sti_whole_sensitivity, signo == SIGINT);
  }
}

// a shard stopped so writes no sensitivity.partial.json, and a folder the
// run would have made is not left behind
TEST(StudyInterrupt, ASensitivityShardStoppedLeavesNoFolder) {
  const fs::path out = sti_dir("shard");
  sti_interrupt({"study", "sensitivity", "--quick", "--case", "1", "--jobs", "2", "--shard",
                 "1/2", "--out", out.string()},
                "study sensitivity", "study sensitivity", SIGINT, out, {}, [](const fs::path& o) {
                  EXPECT_TRUE(fs::is_regular_file(o / "sensitivity.partial.json"));
                });
}

// study extremes stopped once its bar shows a scenario done (its series
// written into the private folder, the next ones running on two threads): exit 130 naming SIGINT, the previous files and series as
// they were (a series the run had written stays in its private folder,
// which is removed), and no private folder left
TEST(StudyInterrupt, ExtremesStopsOnSigintAndKeepsThePreviousSet) {
  const fs::path out = sti_dir("extremes");
  sti_write(out / "extremes.json", "{\"previous\": true}\n");
  sti_write(out / "extremes.csv", "previous\n");
  sti_write(out / "extremes.svg", "<svg/>\n");
  sti_write(out / "extremes" / "baseline.csv", "previous\n");
  const auto before = sti_files(out);
  sti_interrupt({"study", "extremes", "--jobs", "2", "--out", out.string()},
                "study extremes", "study extremes", SIGINT, out, before, sti_whole_extremes,
                true);
  EXPECT_TRUE(sti_private_folders(out / "extremes").empty());
}

// into a folder that was not there, SIGTERM: exit 143, and no folder
TEST(StudyInterrupt, ExtremesStoppedBySigtermLeavesNoNewFolder) {
  const fs::path out = sti_dir("extremes_new") / "out";
  fs::create_directories(out.parent_path());
  sti_interrupt({"study", "extremes", "--jobs", "1", "--out", out.string()},
                "study extremes", "study extremes", SIGTERM, out, {}, sti_whole_extremes);
  EXPECT_TRUE(sti_private_folders(out / "extremes").empty());
  EXPECT_TRUE(sti_private_folders(out).empty());
}

// study precision stopped in its references (two threads): exit 130,
// nothing written
TEST(StudyInterrupt, PrecisionStopsInItsReferences) {
  const fs::path out = sti_dir("precision");
  sti_interrupt({"study", "precision", "--duration", "0.5", "--out", out.string()},
                "study precision", "study precision", SIGINT, out, {}, [](const fs::path& o) {
                  EXPECT_TRUE(fs::is_regular_file(o / "precision.csv"));
                });
}

// study stability --map stopped in its bisections: exit 143, nothing
// written, and the folder it checked is not left behind
TEST(StudyInterrupt, StabilityMapStopsInItsBisections) {
  const fs::path out = sti_dir("stability");
  sti_interrupt({"study", "stability", "--map", "--mass", "0.08", "--damping", "0.028",
                 "--servo-period", "0.001", "--jobs", "2", "--out", out.string()},
                "study stability --map", "study stability", SIGTERM, out, {}, [](const fs::path& o) {
                  EXPECT_TRUE(fs::is_regular_file(o / "stability_map.csv"));
                });
}

}  // namespace
