// What a person at the terminal waits for, end to end: the `vmhaptics`
// program itself started for each iteration, as a user starts it (issue
// 32). Wall time is what is reported (UseRealTime); the children's CPU
// time (getrusage) is a counter beside it, so that a reader can tell a
// busy machine from a slow program.
//
// BM_RunAll/0: `run --all` (nothing written)
// BM_RunAll/1: `run --all --out DIR` (every trace, summary and figure)
// BM_SensitivityQuick: `study sensitivity --case 2 --quick --out DIR`
//
// scripts/bench-tables runs it and puts the medians in
// docs/figures/performance.md. Each iteration takes seconds: run it with
// --benchmark_repetitions, not under ctest.
#include <benchmark/benchmark.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

extern char** environ;

namespace {

namespace fs = std::filesystem;

// the children's user + system CPU seconds so far
double children_cpu_s() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// runs the program with `args`, its output to /dev/null; its exit status
// (-1: it could not be started or did not exit)
int run_cli(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  std::string bin = VMH_CLI_PATH;
  argv.push_back(bin.data());
  std::vector<std::string> copy = args;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, bin.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return -1;
  int status = 0;
  if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

// a fresh folder for one iteration's files, under the system's temporary
// directory
std::string scratch_dir() {
  const fs::path dir = fs::temp_directory_path() /
                       ("vmh_e2e_bench_" + std::to_string(getpid()));
  fs::remove_all(dir);
  return dir.string();
}

// one timed program run per iteration; exit status 0 or 1 (1: a claim
// failed, which is a result) counts, anything else stops the benchmark
void time_cli(benchmark::State& state, const std::vector<std::string>& args,
              const std::string& out_dir) {
  double cpu_s = 0.0;
  int failed = 0;
  for (auto _ : state) {
    const double cpu0 = children_cpu_s();
    const int rc = run_cli(args);
    cpu_s += children_cpu_s() - cpu0;
    state.PauseTiming();
    if (!out_dir.empty()) fs::remove_all(out_dir);
    state.ResumeTiming();
    if (rc != 0 && rc != 1) {
      state.SkipWithError(("vmhaptics exited with " + std::to_string(rc)).c_str());
      return;
    }
    failed += rc;
  }
  state.counters["child_cpu_s"] = benchmark::Counter(
      cpu_s, benchmark::Counter::kAvgIterations);
  state.counters["exit_1"] = failed;
}

void BM_RunAll(benchmark::State& state) {
  std::vector<std::string> args = {"run", "--all"};
  std::string out;
  if (state.range(0) == 1) {
    out = scratch_dir();
    args.insert(args.end(), {"--out", out});
  }
  time_cli(state, args, out);
}
BENCHMARK(BM_RunAll)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)
    ->UseRealTime()->Iterations(1);

void BM_SensitivityQuick(benchmark::State& state) {
  const std::string out = scratch_dir();
  time_cli(state, {"study", "sensitivity", "--case", "2", "--quick", "--out", out},
           out);
}
BENCHMARK(BM_SensitivityQuick)->Unit(benchmark::kMillisecond)->UseRealTime()
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
