// Asking a study to stop (issue 34): the command line's verbs pass a StopFn
// that polls their StopSignals (device/stop_signal.h). A study polls it
// between its runs (scenarios, points, rungs, bisection steps, cases) and
// in its runs' tick loops, on every thread it uses, and throws Interrupted
// before it writes its first file: a stopped study leaves its out_dir as it
// was. The verb turns Interrupted into runtime::SignalStop (exit 130 / 143).
#ifndef VMHAPTICS_STUDIES_STOP_H_
#define VMHAPTICS_STUDIES_STOP_H_

#include <functional>
#include <stdexcept>

namespace vmh::studies {

// Polled between ticks and runs and before the outputs are written: true
// asks the study (or run_case) to stop; it then throws Interrupted.
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

}  // namespace vmh::studies

#endif  // VMHAPTICS_STUDIES_STOP_H_
