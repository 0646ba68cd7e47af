// Ctrl-C and kill as a request to stop: while a StopSignals lives, SIGINT
// and SIGTERM only record which signal came (in a lock-free atomic, the one
// thing a handler may safely touch); the program polls requested() and
// shuts its servo loop down in order, leaving zero torque at the device,
// instead of dying with the motors holding their last torque.
//
// One instance at a time (the handlers share one flag). The destructor puts
// back the handlers that were there before. Handlers are installed with
// SA_RESTART, so that a recorder's I/O is not cut short by the signal.
#ifndef VMHAPTICS_DEVICE_STOP_SIGNAL_H_
#define VMHAPTICS_DEVICE_STOP_SIGNAL_H_

#include <signal.h>

namespace vmh {

class StopSignals {
 public:
  // Installs the handlers. Throws std::logic_error if another StopSignals
  // is alive, std::runtime_error naming the signal and errno if sigaction
  // fails.
  StopSignals();
  ~StopSignals();  // restores the previous handlers

  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // a SIGINT or SIGTERM arrived since construction
  bool requested() const noexcept { return signal_number() != 0; }
  // the last one that arrived (SIGINT or SIGTERM), 0 if none
  int signal_number() const noexcept;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

}  // namespace vmh

#endif  // VMHAPTICS_DEVICE_STOP_SIGNAL_H_
