#include "runtime/stop.h"

#include <signal.h>

#include "device/stop_signal.h"

namespace vmh::runtime {

std::string signal_name(int signo) {
  if (signo == SIGINT) return "SIGINT";
  if (signo == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signo);
}

void throw_if_stopped(const std::string& verb, const std::string& detail) {
  const int signo = stop_signal_number();
  if (signo == 0) return;
  throw SignalStop("interrupted: " + verb + " stopped by " + signal_name(signo) +
                       detail,
                   signo);
}

}  // namespace vmh::runtime
