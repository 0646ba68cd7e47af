// Runs the built command line as a user runs it, for the tests of its verbs.
// The including target defines VMH_CLI_PATH, the path of build/vmhaptics.
#ifndef VMHAPTICS_TESTS_SUPPORT_CLI_RUN_H_
#define VMHAPTICS_TESTS_SUPPORT_CLI_RUN_H_

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

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
  std::ifstream err(err_path);
  std::stringstream ss;
  ss << err.rdbuf();
  r.err = ss.str();
  std::remove(err_path.c_str());
  return r;
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

// the first line of a text file ("" if it cannot be read)
inline std::string first_line(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  return line;
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_SUPPORT_CLI_RUN_H_
