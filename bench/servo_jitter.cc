// servo_jitter: how regularly ServoThread ticks on this machine, with real
// work in each tick (servo_tick(): read, the controller for a circle VM of
// L = 50 mm, write) against the device of bench/servo_jitter_device.h: the
// MuJoCo emulator, its physics in real time on a thread of its own, when the
// testbed is built; a stand-in rotor model otherwise. Not a test: it asserts
// nothing; it measures and prints.
//
// Two conditions, --seconds each: "idle", and "cpu_hog", with a thread
// spinning flat out. With two or more usable cores the servo thread is
// pinned to the first and the hog to the second (the hog then competes for
// caches, memory and the kernel, not for the servo's core); with one core
// they share it.
//
// Usage: servo_jitter [--seconds S] [--period-s P] [--no-realtime]
//                     [--out FILE.json] [--markdown FILE.md]
// Prints JSON to stdout (and to FILE.json with --out; a table for the docs
// to FILE.md with --markdown). Times in us (_us).
// Ctrl-C ends the current condition early and skips the rest.
#include <pthread.h>
#include <sched.h>
#include <sys/utsname.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bench/servo_jitter_device.h"
#include "controller/controller.h"
#include "device/servo_thread.h"
#include "device/servo_tick.h"
#include "device/stop_signal.h"

namespace vmh {
namespace {

struct Args {
  double seconds = 10.0;
  double period_s = 1e-3;
  bool realtime = true;
  std::string out;
  std::string markdown;
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "servo_jitter: %s\nusage: servo_jitter [--seconds S] "
               "[--period-s P] [--no-realtime] [--out FILE.json]\n",
               why.c_str());
  std::exit(2);
}

double positive(const char* flag, const char* text) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(v) || v <= 0.0) {
    usage(std::string(flag) + " wants a positive number, got '" + text + "'");
  }
  return v;
}

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string f = argv[i];
    const bool has_value = i + 1 < argc;
    if (f == "--seconds" && has_value) {
      a.seconds = positive("--seconds", argv[++i]);
    } else if (f == "--period-s" && has_value) {
      a.period_s = positive("--period-s", argv[++i]);
    } else if (f == "--markdown" && has_value) {
      a.markdown = argv[++i];
    } else if (f == "--out" && has_value) {
      a.out = argv[++i];
    } else if (f == "--no-realtime") {
      a.realtime = false;
    } else {
      usage("unknown or incomplete argument '" + f + "'");
    }
  }
  return a;
}

// the CPUs this process may run on
std::vector<int> usable_cpus() {
  std::vector<int> cpus;
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) {
    for (int c = 0; c < CPU_SETSIZE; ++c) {
      if (CPU_ISSET(c, &set)) cpus.push_back(c);
    }
  }
  return cpus;
}

bool pin(pthread_t t, int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  return pthread_setaffinity_np(t, sizeof set, &set) == 0;
}

void unpin(pthread_t t, const std::vector<int>& cpus) {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (int c : cpus) CPU_SET(c, &set);
  pthread_setaffinity_np(t, sizeof set, &set);
}

// one tick: servo_tick() on the device with the controller
class JitterLoop : public ServoLoop {
 public:
  JitterLoop(HapticDevice* device, Controller* controller)
      : device_(device), controller_(controller) {}
  bool tick(double) noexcept override {
    const ServoTickResult r =
        servo_tick(device_, controller_, &out_, &state_);
    if (r.zeroed) {
      zeroed_.store(zeroed_.load(std::memory_order_relaxed) + 1,
                    std::memory_order_relaxed);
    }
    return true;
  }
  long zeroed() const { return zeroed_.load(); }

 private:
  HapticDevice* device_;
  Controller* controller_;
  ControlOutput out_;
  DeviceState state_;
  std::atomic<long> zeroed_{0};
};

struct Condition {
  std::string name;
  TickStats stats;
  ServoReport report;
  long zeroed = 0;
  double seconds = 0.0;
  int servo_cpu = -1;
  int hog_cpu = -1;
};

void sleep_s(double s) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(s);
  ts.tv_nsec = static_cast<long>((s - static_cast<double>(ts.tv_sec)) * 1e9);
  nanosleep(&ts, nullptr);
}

Condition run_condition(const std::string& name, bool hog, const Args& args,
                        const StopSignals& signals) {
  Condition c;
  c.name = name;
  const std::vector<int> cpus = usable_cpus();
  // the circle VM about the device origin, K_pos 0.5 N/mm, half the
  // thesis's orientation gain, a little velocity gain
  ControllerParams p;
  p.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, 50.0);
  p.gains.k_vel_Ns_per_mm = 0.01;
  p.servo_period_s = args.period_s;
  Controller controller(p);
  const Joints q0 =
      (Joints() << -0.1, 0.4, 0.1, -0.2, 0.3, 0.1).finished();
  std::unique_ptr<HapticDevice> device = make_jitter_device(args.period_s, q0);
  JitterLoop loop(device.get(), &controller);

  std::atomic<bool> hog_stop{false};
  std::thread hog_thread;
  if (hog) {
    hog_thread = std::thread([&hog_stop] {
      volatile double x = 1.0;
      while (!hog_stop.load(std::memory_order_relaxed)) x = x * 1.0000001 + 1e-9;
    });
    if (cpus.size() >= 2 && pin(hog_thread.native_handle(), cpus[1])) {
      c.hog_cpu = cpus[1];
    }
  }
  ServoOptions opt;
  opt.period_s = args.period_s;
  opt.realtime = args.realtime;
  ServoThread servo(&loop, opt);
  // the servo thread inherits this thread's affinity when it is created
  if (cpus.size() >= 2 && pin(pthread_self(), cpus[0])) c.servo_cpu = cpus[0];
  c.report = servo.start();
  unpin(pthread_self(), cpus);

  const double t0 = monotonic_now_s();
  while (monotonic_now_s() - t0 < args.seconds && !signals.requested() &&
         servo.running()) {
    sleep_s(0.05);
  }
  servo.stop();
  c.seconds = monotonic_now_s() - t0;
  hog_stop.store(true);
  if (hog_thread.joinable()) hog_thread.join();
  c.stats = servo.timing();
  c.zeroed = loop.zeroed();
  return c;
}

std::string quoted(const std::string& s) {
  std::string o = "\"";
  for (char ch : s) {
    if (ch == '"' || ch == '\\') {
      o += '\\';
      o += ch;
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      o += ' ';
    } else {
      o += ch;
    }
  }
  return o + "\"";
}

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

std::string condition_json(const Condition& c) {
  const TickStats& s = c.stats;
  const auto us = [](double v_s) { return number(v_s * 1e6); };
  std::string j = "    {\n";
  j += "      \"condition\": " + quoted(c.name) + ",\n";
  j += "      \"seconds\": " + number(c.seconds) + ",\n";
  j += "      \"servo_cpu\": " + std::to_string(c.servo_cpu) + ",\n";
  j += "      \"hog_cpu\": " + std::to_string(c.hog_cpu) + ",\n";
  j += "      \"ticks\": " + std::to_string(s.ticks) + ",\n";
  j += "      \"overruns\": " + std::to_string(s.overruns) + ",\n";
  j += "      \"zeroed_ticks\": " + std::to_string(c.zeroed) + ",\n";
  j += "      \"period_mean_us\": " + us(s.period_mean_s) + ",\n";
  j += "      \"period_min_us\": " + us(s.period_min_s) + ",\n";
  j += "      \"period_p50_us\": " + us(s.period_p50_s) + ",\n";
  j += "      \"period_p99_us\": " + us(s.period_p99_s) + ",\n";
  j += "      \"period_max_us\": " + us(s.period_max_s) + ",\n";
  j += "      \"jitter_p50_us\": " + us(s.jitter_p50_s) + ",\n";
  j += "      \"jitter_p99_us\": " + us(s.jitter_p99_s) + ",\n";
  j += "      \"jitter_max_us\": " + us(s.jitter_max_s) + ",\n";
  j += "      \"work_p50_us\": " + us(s.work_p50_s) + ",\n";
  j += "      \"work_p99_us\": " + us(s.work_p99_s) + ",\n";
  j += "      \"work_max_us\": " + us(s.work_max_s) + ",\n";
  j += "      \"histogram_bin_us\": " + us(s.histogram_bin_s) + ",\n";
  j += std::string("      \"sched_fifo\": ") +
       (c.report.sched_fifo ? "true" : "false") + ",\n";
  j += std::string("      \"memory_locked\": ") +
       (c.report.memory_locked ? "true" : "false") + ",\n";
  j += "      \"note\": " + quoted(c.report.note) + "\n";
  j += "    }";
  return j;
}

int run(int argc, char** argv) {
  const Args args = parse(argc, argv);
  StopSignals signals;
  std::vector<Condition> conditions;
  conditions.push_back(run_condition("idle", false, args, signals));
  if (!signals.requested()) {
    conditions.push_back(run_condition("cpu_hog", true, args, signals));
  }

  utsname u{};
  uname(&u);
  std::string j = "{\n";
  j += "  \"program\": \"servo_jitter\",\n";
  j += "  \"device\": " + quoted(jitter_device_name()) + ",\n";
  j += "  \"period_us\": " + number(args.period_s * 1e6) + ",\n";
  j += "  \"seconds_per_condition\": " + number(args.seconds) + ",\n";
  j += std::string("  \"realtime_requested\": ") +
       (args.realtime ? "true" : "false") + ",\n";
  j += "  \"cores_online\": " +
       std::to_string(sysconf(_SC_NPROCESSORS_ONLN)) + ",\n";
  j += "  \"cores_usable\": " + std::to_string(usable_cpus().size()) + ",\n";
  j += "  \"kernel\": " + quoted(std::string(u.sysname) + " " + u.release +
                                 " " + u.version + " " + u.machine) +
       ",\n";
  j += std::string("  \"interrupted\": ") +
       (signals.requested() ? "true" : "false") + ",\n";
  j += "  \"conditions\": [\n";
  for (std::size_t i = 0; i < conditions.size(); ++i) {
    j += condition_json(conditions[i]);
    j += i + 1 < conditions.size() ? ",\n" : "\n";
  }
  j += "  ]\n}\n";

  std::fputs(j.c_str(), stdout);
  if (!args.out.empty()) {
    std::FILE* f = std::fopen(args.out.c_str(), "w");
    if (f == nullptr) {
      std::fprintf(stderr, "servo_jitter: cannot write %s: %s\n",
                   args.out.c_str(), std::strerror(errno));
      return 1;
    }
    std::fputs(j.c_str(), f);
    if (std::fclose(f) != 0) {
      std::fprintf(stderr, "servo_jitter: cannot write %s\n",
                   args.out.c_str());
      return 1;
    }
  }
  if (!args.markdown.empty()) {
    std::string m;
    m += "<!-- generated by bench/servo_jitter --markdown; do not edit -->\n";
    m += "Servo thread on " + jitter_device_name() + ", " + number(args.seconds) +
         " s per condition, period " + number(args.period_s * 1e6) +
         " us; " + std::to_string(sysconf(_SC_NPROCESSORS_ONLN)) +
         " cores, " + u.sysname + " " + u.release + ". Percentiles to the " +
         "centre of 10 us bins.\n\n";
    m += "| condition | SCHED_FIFO | ticks | overruns | period p50 / p99 / max (us) "
         "| jitter p50 / p99 / max (us) | work in tick p50 / p99 / max (us) |\n";
    m += "|---|---|---|---|---|---|---|\n";
    for (const Condition& c : conditions) {
      const TickStats& t = c.stats;
      const auto us = [](double v_s) { return number(v_s * 1e6); };
      m += "| " + c.name + " | " + (c.report.sched_fifo ? "yes" : "no") + " | " +
           std::to_string(t.ticks) + " | " + std::to_string(t.overruns) + " | " +
           us(t.period_p50_s) + " / " + us(t.period_p99_s) + " / " +
           us(t.period_max_s) + " | " + us(t.jitter_p50_s) + " / " +
           us(t.jitter_p99_s) + " / " + us(t.jitter_max_s) + " | " +
           us(t.work_p50_s) + " / " + us(t.work_p99_s) + " / " +
           us(t.work_max_s) + " |\n";
    }
    std::FILE* f = std::fopen(args.markdown.c_str(), "w");
    if (f == nullptr || std::fputs(m.c_str(), f) < 0 || std::fclose(f) != 0) {
      std::fprintf(stderr, "servo_jitter: cannot write %s\n",
                   args.markdown.c_str());
      return 1;
    }
  }
  return 0;
}

}  // namespace
}  // namespace vmh

int main(int argc, char** argv) {
  try {
    return vmh::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "servo_jitter: %s\n", e.what());
    return 1;
  }
}
