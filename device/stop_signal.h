// Ctrl-C and kill as a request to stop: while a StopSignals lives, SIGINT
// and SIGTERM only record which signal came first (in a lock-free atomic,
// the one thing a handler may safely touch); the program polls requested()
// (or stop_requested(), from code that holds no StopSignals) and shuts its
// work down in order: a servo loop leaves zero torque at the device
// instead of the motors holding their last torque, a verb removes its
// unfinished output sets instead of leaving them half-written.
//
// The first signal wins: SIGINT then SIGTERM is reported as SIGINT (the
// later ones only repeat the request).
//
// Instances nest: the outermost installs the handlers and clears the flag,
// an inner one (a session inside a verb that already listens) shares them
// and sees any signal that came before it; when the last one goes, the
// handlers that were there before are put back and the flag is cleared.
// Handlers are installed with SA_RESTART, so that a recorder's I/O is not
// cut short by the signal.
#ifndef VMHAPTICS_DEVICE_STOP_SIGNAL_H_
#define VMHAPTICS_DEVICE_STOP_SIGNAL_H_

#include <signal.h>

namespace vmh {

class StopSignals {
 public:
  // Installs the handlers (the outermost instance). Throws
  // std::runtime_error naming the signal and errno if sigaction fails.
  StopSignals();
  ~StopSignals();  // the last one restores the previous handlers

  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // a SIGINT or SIGTERM arrived since the outermost instance was made
  bool requested() const noexcept { return signal_number() != 0; }
  // the first one that arrived (SIGINT or SIGTERM), 0 if none
  int signal_number() const noexcept;
};

// The same, for code that polls without holding a StopSignals (a long
// loop in a library the verb calls): the first SIGINT or SIGTERM since the
// outermost live StopSignals was made; 0 (false) while none lives.
int stop_signal_number() noexcept;
inline bool stop_requested() noexcept { return stop_signal_number() != 0; }

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_STOP_SIGNAL_H_
