// A verb stopped by SIGINT or SIGTERM: the error that carries the signal to
// cli/main.cc, which exits 128 + its number (130, 143) with its message.
//
// The verbs whose work is long outside a device session (compare,
// identify, report, render, hw run's judging, the study sub-verbs, whose
// studies poll a studies::StopFn and throw studies::Interrupted, which
// cli/study_files.h turns into SignalStop) hold a StopSignals
// (device/stop_signal.h) for their whole run and call throw_if_stopped()
// between the steps of their long loops and before each commit of their
// outputs: a signal then leaves the previous output sets as they were, or
// the new ones whole, and never a half-written folder.
#ifndef VMHAPTICS_RUNTIME_STOP_H_
#define VMHAPTICS_RUNTIME_STOP_H_

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

}  // namespace vmh::runtime

#endif  // VMHAPTICS_RUNTIME_STOP_H_
