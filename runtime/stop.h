// A verb stopped by SIGINT or SIGTERM: the error that carries the signal to
// cli/main.cc, which exits 128 + its number (130, 143) with its message.
//
// The verbs whose work is long outside a device session (compare,
// identify, report, render, hw run's judging, the study sub-verbs, whose
// studies poll a runtime::StopFn and throw runtime::Interrupted, which
// cli/study_files.h turns into SignalStop) hold a StopSignals
// (device/stop_signal.h) for their whole run and call throw_if_stopped()
// between the steps of their long loops and before each commit of their
// outputs: a signal then leaves the previous output sets as they were, or
// the new ones whole, and never a half-written folder.
#ifndef VMHAPTICS_RUNTIME_STOP_H_
#define VMHAPTICS_RUNTIME_STOP_H_

#include <functional>
#include <stdexcept>
#include <string>

namespace vmh::runtime {

struct SignalStop : std::runtime_error {
  SignalStop(const std::string& what, int signo)
      : std::runtime_error(what), signal(signo) {}
  int signal;
};

// "SIGINT", "SIGTERM", else "signal <n>"
std::string signal_name(int signo);

// Throws SignalStop "interrupted: <verb> stopped by <signal><detail>" if a
// SIGINT or SIGTERM has come since the outermost live StopSignals was
// made (the first one is named); does nothing otherwise, nor while no
// StopSignals lives. `detail` (e.g. "; nothing written") follows as is.
void throw_if_stopped(const std::string& verb, const std::string& detail = "");

// Asking long work to stop (issue 34): a verb passes a StopFn that polls
// its StopSignals (device/stop_signal.h). A case run (thesis/run_case.h)
// polls it in its tick loop; a study (studies/) between its runs
// (scenarios, points, rungs, bisection steps, cases) and in their tick
// loops, on every thread it uses. Both throw Interrupted before their
// first file is written, so a stopped run or study leaves its out_dir as
// it was; the verb turns Interrupted into SignalStop (exit 130 / 143).
//
// Polled between ticks and runs and before the outputs are written: true
// asks the work to stop; it then throws Interrupted.
using StopFn = std::function<bool()>;
struct Interrupted : std::runtime_error {
  Interrupted() : std::runtime_error("interrupted") {}
};

// whether `stop` (if set) asks to stop
inline bool stop_asked(const StopFn& stop) { return stop && stop(); }
// throws Interrupted if `stop` (if set) asks to stop
inline void throw_if_stop_asked(const StopFn& stop) {
  if (stop_asked(stop)) throw Interrupted();
}

}  // namespace vmh::runtime

#endif  // VMHAPTICS_RUNTIME_STOP_H_
