// Runs the built command line as a user runs it, for the tests of its verbs.
// The including target defines VMH_CLI_PATH, the path of build/vmhaptics.
#ifndef VMHAPTICS_TESTS_SUPPORT_CLI_RUN_H_
#define VMHAPTICS_TESTS_SUPPORT_CLI_RUN_H_

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/support/read_file.h"

namespace vmh::testing {

struct CliRun {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// runs `vmhaptics <args>` through the shell, capturing stdout and stderr;
// `env` (e.g. "VAR=value ") is put before the command
inline CliRun run(const std::string& args, const std::string& env = "") {
  // a file of its own: ctest runs the test cases in parallel processes
  std::string err_path = ::testing::TempDir() + "vmh_cli_stderr_XXXXXX";
  const int fd = mkstemp(err_path.data());
  if (fd < 0) return CliRun{};
  close(fd);
  const std::string cmd =
      env + std::string(VMH_CLI_PATH) + " " + args + " 2>" + err_path;
  CliRun r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = read_file(err_path);
  std::remove(err_path.c_str());
  return r;
}

// starts `vmhaptics <args>` in a child process, its stdout to /dev/null and
// its stderr to `stderr_path` (a file, created or emptied, or a terminal's
// device such as a pty's slave); returns the child's pid for the caller to
// signal and wait on
inline pid_t spawn_cli(const std::vector<std::string>& args,
                       const std::string& stderr_path) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = open(stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOCTTY, 0644);
    if (fd >= 0) dup2(fd, 2);
    const int null = open("/dev/null", O_WRONLY);
    if (null >= 0) dup2(null, 1);
    std::vector<char*> argv = {const_cast<char*>(VMH_CLI_PATH)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(VMH_CLI_PATH, argv.data());
    _exit(127);
  }
  return pid;
}

// an empty path under the test temp directory, named `prefix` + `name`
// (removed first if an earlier run left it)
inline std::filesystem::path fresh_dir(const std::string& prefix,
                                       const std::string& name) {
  const std::filesystem::path d =
      std::filesystem::path(::testing::TempDir()) / (prefix + name);
  std::filesystem::remove_all(d);
  return d;
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_CLI_RUN_H_
