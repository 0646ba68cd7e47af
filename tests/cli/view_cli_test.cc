// `vmhaptics view` from the command line, under Xvfb: a short scripted run
// exits 0 and says how many frames it drew; a bad case is a usage error;
// without a display it says so.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace {

struct Result {
  int code = -1;
  std::string err;
};

// `env_prefix` runs the program under e.g. "env -u DISPLAY "
Result run(const std::string& args, const std::string& env_prefix = "") {
  const std::string cmd =
      env_prefix + std::string(VMH_CLI_PATH) + " " + args + " 2>&1";
  Result r;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  char buf[512];
  while (fgets(buf, sizeof buf, p) != nullptr) r.err += buf;
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

TEST(ViewCli, ThirtyFramesExitZero) {
  const Result r = run("view case1 --frames 30 --width 320 --height 240");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("30 frames"), std::string::npos) << r.err;
}

TEST(ViewCli, UnknownCaseIsABadUsage) {
  const Result r = run("view case9 --frames 3");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("vmhaptics: error: view: 'case9'"), std::string::npos)
      << r.err;
}

TEST(ViewCli, EmulatorDeviceShowsItsState) {
  const Result r =
      run("view case1 --device emulator --frames 20 --width 320 --height 240");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("20 frames"), std::string::npos) << r.err;
}

// without a display: exit 1 and GLFW's own reason, on one line
TEST(ViewCli, NoDisplayIsExit1NamingIt) {
  const Result r = run("view case1 --frames 3", "env -u DISPLAY -u WAYLAND_DISPLAY ");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("vmhaptics: error: view: cannot open a window"),
            std::string::npos) << r.err;
  EXPECT_NE(r.err.find("DISPLAY"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
}

// view --serve-hd: the emulator served under a name while the window
// runs, the name gone once it has closed (a client's test is
// tests/hd/hd_served_test.cc, the window's tests/viz/viewer_served_test.cc)
TEST(ViewCli, ServeHdServesWhileOpenAndRemovesItsName) {
  const std::string name = "cli-" + std::to_string(::getpid());
  const Result r = run("view --serve-hd " + name +
                       " --frames 10 --width 320 --height 240");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("as served:" + name), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("VMH_HD_DEVICE=served:" + name), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists("/dev/shm/vmhaptics-hd-" + name));
}

TEST(ViewCli, ServeHdRefusesABadNameAndADevice) {
  Result r = run("view --serve-hd a/b --frames 3");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("letters, digits"), std::string::npos) << r.err;
  r = run("view case1 --serve-hd ok --device emulator --frames 3");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("not with --device"), std::string::npos) << r.err;
  // no window: exit 1, and the name was not left behind
  const std::string name = "nodisplay-" + std::to_string(::getpid());
  r = run("view --serve-hd " + name + " --frames 3",
          "env -u DISPLAY -u WAYLAND_DISPLAY ");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists("/dev/shm/vmhaptics-hd-" + name));
}

}  // namespace
