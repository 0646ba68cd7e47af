// libHD.so on a served emulator, across processes: this test serves the
// emulated Omni (sim/served_emulator.h, what `view --serve-hd` runs behind
// its window) and a separate Python process, the ctypes client of
// spring_client.py, opens it through the project's libHD.so with
// VMH_HD_DEVICE=served:NAME and closes a 2 s spring. The stylus must end
// nearer the spring's point; a client killed mid-run must leave zero
// torque on the served device within the watchdog, and its slot free for
// the next client.
//
// The served device runs on the wall clock (both processes' servo
// threads): the suite is *Realtime (serial) and asserts only what holds on
// a busy host: where the stylus ends, never how long anything took.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "sim/served_emulator.h"

extern char** environ;

namespace vmh::sim {
namespace {

std::string served_name(const char* what) {
  return std::string("hd-") + what + "-" + std::to_string(::getpid());
}

ServedEmulatorOptions options(const std::string& name) {
  ServedEmulatorOptions o;
  o.name = name;
  o.scene = VMH_MODELS_DIR "/cases/case1.xml";
  o.realtime_priority = 0;
  return o;
}

// the client's environment: the project's libHD.so, no user's hd.conf, the
// served device as the default device, the wall clock
std::string client_env(const std::string& name) {
  return "env -u VMH_HD_CLOCK -u VMH_HD_CONFIG VMH_HD_QUIET=1 "
         "XDG_CONFIG_HOME=" VMH_TEST_TMP " LD_LIBRARY_PATH=" VMH_HD_LIB_DIR
         " VMH_HD_DEVICE=served:" + name + " ";
}

bool eventually(const std::function<bool()>& cond) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < until) {
    if (cond()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return cond();
}

// runs the spring client to the end; its JSON line and exit status
nlohmann::json run_spring(const std::string& name, int* status) {
  const std::string cmd = client_env(name) + VMH_PYTHON " " VMH_SPRING_CLIENT
                          " --seconds 2";
  FILE* p = ::popen(cmd.c_str(), "r");
  EXPECT_NE(p, nullptr);
  std::string out;
  std::array<char, 4096> buf{};
  while (p != nullptr && std::fgets(buf.data(), buf.size(), p) != nullptr) {
    out += buf.data();
  }
  const int rc = p != nullptr ? ::pclose(p) : -1;
  *status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  std::printf("[ client   ] %s", out.c_str());
  return nlohmann::json::parse(out, nullptr, false);
}

TEST(HdServedRealtime, APythonClientInAnotherProcessCarriesTheServedStylus) {
  const std::string name = served_name("spring");
  ServedEmulator served(options(name));
  served.start();
  int status = -1;
  const nlohmann::json r = run_spring(name, &status);
  ASSERT_FALSE(r.is_discarded());
  EXPECT_EQ(status, 0);
  ASSERT_TRUE(r.contains("end_distance_mm")) << r.dump();
  // 36 mm from the spring's point at the start, much nearer at the end
  EXPECT_LT(r["end_distance_mm"].get<double>(),
            0.5 * r["start_distance_mm"].get<double>());
  // (a busy host starves the client's servo thread: the frame and command
  // counts only say the loop ran; 2000 each on a quiet one)
  EXPECT_GT(r["frames"].get<long>(), 10);
  // the server saw the client's commands; the client has gone
  EXPECT_GT(served.server().commands, 10u);
  EXPECT_EQ(served.server().client_pid, 0);
  EXPECT_TRUE(eventually([&] {
    return served.published().tau_applied_Nm == Vec3::Zero();
  }));
}

TEST(HdServedRealtime, AKilledClientLeavesZeroTorqueAndAFreeSlot) {
  const std::string name = served_name("kill");
  ServedEmulator served(options(name));
  served.start();
  // a long spring in its own process
  const std::string cmd = client_env(name) + VMH_PYTHON " " VMH_SPRING_CLIENT
                          " --seconds 60 > /dev/null";
  std::vector<char*> argv{const_cast<char*>("/bin/sh"), const_cast<char*>("-c"),
                          const_cast<char*>(cmd.c_str()), nullptr};
  pid_t shell = 0;
  ASSERT_EQ(::posix_spawn(&shell, "/bin/sh", nullptr, nullptr, argv.data(), environ),
            0);
  ASSERT_TRUE(eventually([&] {
    return served.server().commands > 50 &&
           served.server().command_state == hw::served::CommandState::kApplied;
  }));
  const int client = served.server().client_pid;
  ASSERT_GT(client, 0);
  // killed without a chance to say goodbye
  ::kill(client, SIGKILL);
  int st = 0;
  ::waitpid(shell, &st, 0);
  // the watchdog: zero torque, and the server says why
  ASSERT_TRUE(eventually([&] {
    return served.server().command_state == hw::served::CommandState::kStale;
  }));
  EXPECT_EQ(served.published().tau_applied_Nm, Vec3::Zero());
  // and the emulator's motors, from its next period on
  EXPECT_TRUE(eventually([&] {
    return served.truth().motor_torque_Nm == Vec3::Zero();
  }));
  // the dead client's slot is taken over by the next
  int status = -1;
  const nlohmann::json r = run_spring(name, &status);
  EXPECT_EQ(status, 0) << r.dump();
}

TEST(HdServedRealtime, AClientOfANameNobodyServesGetsANamedError) {
  // the library's own message, through hdGetErrorString
  const std::string name = served_name("nobody");
  int status = -1;
  const nlohmann::json r = run_spring(name, &status);
  EXPECT_EQ(status, 2);
  ASSERT_FALSE(r.is_discarded());
  const std::string text = r.dump();
  EXPECT_NE(text.find("no such served device"), std::string::npos) << text;
  EXPECT_NE(text.find("view --serve-hd " + name), std::string::npos) << text;
}

}  // namespace
}  // namespace vmh::sim
