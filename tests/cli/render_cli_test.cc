// `vmhaptics render` as a user runs it, under a display (Xvfb): the JSON on
// stdout names PNG files that exist, bad input is exit 2 with one line
// naming the bad value (a time past the scene's duration included), no
// display is exit 1 naming it, SIGINT is exit 130; nothing is written for
// any of these.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using vmh::testing::run;

fs::path fresh_dir(const std::string& name) {
  return vmh::testing::fresh_dir("vmh_render_cli_", name);
}

std::string head(const fs::path& p, std::size_t n) {
  std::ifstream in(p, std::ios::binary);
  std::string s(n, '\0');
  in.read(s.data(), static_cast<std::streamsize>(n));
  s.resize(static_cast<std::size_t>(in.gcount()));
  return s;
}

int lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n' ? 1 : 0;
  return n;
}

TEST(RenderCli, WritesTheImagesItNames) {
  const fs::path out = fresh_dir("ok");
  const auto r = run("render case1 --t 1,0.5 --width 200 --height 150 --out " +
                     out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j.at("case"), "case1");
  EXPECT_EQ(fs::path(j.at("scene").get<std::string>()).filename(), "case1.xml");
  EXPECT_EQ(j.at("width_px"), 200);
  EXPECT_EQ(j.at("height_px"), 150);
  EXPECT_EQ(j.at("camera"), "default");
  const json& images = j.at("images");
  ASSERT_EQ(images.size(), 2u);
  // in increasing time, whatever the order given
  EXPECT_EQ(images[0].at("t_s"), 0.5);
  EXPECT_EQ(images[1].at("t_s"), 1.0);
  for (const json& im : images) {
    const fs::path p = im.at("path").get<std::string>();
    EXPECT_EQ(p.parent_path(), out);
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_EQ(head(p, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << p;
    // IHDR: width and height, big-endian, after the signature and the
    // chunk's length and type
    const std::string ihdr = head(p, 24);
    ASSERT_EQ(ihdr.size(), 24u);
    EXPECT_EQ(ihdr.substr(12, 4), "IHDR");
    EXPECT_EQ(static_cast<unsigned char>(ihdr[19]), 200);
    EXPECT_EQ(static_cast<unsigned char>(ihdr[23]), 150);
    EXPECT_GE(im.at("sim_t_s").get<double>(), im.at("t_s").get<double>());
  }
  EXPECT_EQ(fs::path(images[0].at("path").get<std::string>()).filename(),
            "case1_t000500ms.png");
  // no temporary file is left behind
  int files = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    EXPECT_EQ(e.path().extension(), ".png") << e.path();
    ++files;
  }
  EXPECT_EQ(files, 2);
}

// each bad input: exit 2, one line on stderr naming the value, no folder
void expect_refused(const std::string& args, const std::string& named) {
  const fs::path out = fresh_dir("bad");
  const auto r = run("render " + args + " --out " + out.string());
  EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("vmhaptics: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(named), std::string::npos)
      << args << ": '" << named << "' not in: " << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_FALSE(fs::exists(out)) << args << " wrote " << out;
}

TEST(RenderCli, BadInputIsExit2NamingIt) {
  expect_refused("case1 --t -1", "'-1'");
  expect_refused("case1 --t x", "'x'");
  expect_refused("case1 --t 0.5,nan", "nan");
  expect_refused("case9 --t 1", "'case9'");
  expect_refused("case1 --t 1 --width 3", "--width: 3");
  expect_refused("case1 --t 1 --height 9000", "--height: 9000");
  expect_refused("case1 --t 1 --camera nosuchcam", "'nosuchcam'");
  expect_refused("case1 --t 1 --set nosuchfield=1", "nosuchfield");
  // past the script's end (issue 34: --t 1e6 ran for hours), the bound the
  // scene's duration_s with its overrides
  expect_refused("case1 --t 0.5,1e6",
                 "--t: time 1e+06 s is past the scene's duration_s, 20 s");
  expect_refused("case1 --t 21", "--t: time 21 s is past the scene's duration_s, 20 s");
  expect_refused("case1 --set duration_s=1 --t 1.5",
                 "--t: time 1.5 s is past the scene's duration_s, 1 s");
}

// the images drawn so far, if any, are in a private folder beside --out
std::vector<fs::path> render_scratch_folders(const fs::path& out) {
  std::vector<fs::path> found;
  const std::string prefix = "." + out.filename().string() + ".render-";
  for (const auto& e : fs::directory_iterator(out.parent_path())) {
    if (e.path().filename().string().rfind(prefix, 0) == 0) found.push_back(e.path());
  }
  return found;
}

// SIGINT while rendering (sent once the private folder exists): exit 130
// naming it, and nothing written: no --out, no private folder left
TEST(RenderCli, ASignalWritesNothing) {
  const fs::path out = fresh_dir("signal");
  const fs::path err = fresh_dir("signal_stderr.txt");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int fd = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) dup2(fd, 2);
    const int null = open("/dev/null", O_WRONLY);
    if (null >= 0) dup2(null, 1);
    execl(VMH_CLI_PATH, VMH_CLI_PATH, "render", "case1", "--t", "1,5,10,19.5",
          "--width", "64", "--height", "48", "--out", out.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  bool started = false;
  for (int i = 0; i < 60000 && !started; ++i) {
    started = !render_scratch_folders(out).empty();
    int status = 0;
    ASSERT_NE(waitpid(pid, &status, WNOHANG), pid) << vmh::testing::first_line(err);
    if (!started) usleep(1000);
  }
  ASSERT_TRUE(started);
  ASSERT_EQ(kill(pid, SIGINT), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  const std::string line = vmh::testing::first_line(err);
  EXPECT_EQ(WEXITSTATUS(status), 130) << line;
  if (line.find("nothing written") != std::string::npos) {
    EXPECT_EQ(line, "vmhaptics: interrupted: render stopped by SIGINT; nothing written");
    EXPECT_FALSE(fs::exists(out));
  } else {
    // it had finished drawing: every image is in place
    EXPECT_EQ(line.rfind("vmhaptics: interrupted: render stopped by SIGINT", 0), 0u) << line;
    EXPECT_TRUE(fs::exists(out / "case1_t019500ms.png"));
  }
  EXPECT_TRUE(render_scratch_folders(out).empty());
}

// without a display: exit 1 (not bad input), the cause named, nothing
// written
TEST(RenderCli, NoDisplayIsExit1NamingIt) {
  const fs::path out = fresh_dir("nodisplay");
  const auto r = run("render case1 --t 0.5 --out " + out.string(),
                     "env -u DISPLAY -u WAYLAND_DISPLAY ");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("no OpenGL context"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("xvfb-run"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(RenderCli, HelpNamesTheOptions) {
  const auto r = run("render --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* opt : {"--t", "--out", "--width", "--height", "--camera",
                          "--set", "--no-overlay", "xvfb-run"}) {
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
  }
}

}  // namespace
