// `vmhaptics view` from the command line, under Xvfb: a short scripted run
// exits 0 and says how many frames it drew; a bad case is a usage error;
// without a display it says so.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <sys/wait.h>

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

}  // namespace
