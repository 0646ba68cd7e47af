// Helpers shared by the study sub-verbs: which scene --case names, lists of
// numbers, and how a signal stops a study.
#ifndef VMHAPTICS_CLI_STUDY_FILES_H_
#define VMHAPTICS_CLI_STUDY_FILES_H_

#include <string>
#include <vector>

#include "runtime/stop.h"

namespace vmh::cli {

// The study verbs and a signal (issue 34): each holds a StopSignals
// (device/stop_signal.h) for its whole run and passes study_stop() as its
// study's should_stop, which the study polls between its runs, in their
// tick loops and on every thread, and last before it writes its first
// file. A study stopped so throws runtime::Interrupted, with nothing
// written; run_stoppable() turns that into runtime::SignalStop naming the
// verb and the first signal ("interrupted: study extremes stopped by
// SIGINT; nothing written"), which exits 130 / 143 (cli/main.cc).
runtime::StopFn study_stop();

template <typename Body>
decltype(auto) run_stoppable(const std::string& verb, Body&& body) {
  try {
    return body();
  } catch (const runtime::Interrupted&) {
    runtime::throw_if_stopped(verb, "; nothing written");
    throw;  // stopped without a signal: not from study_stop()
  }
}

// After the study's files went in (or, without --out, after it ended): a
// signal that came since its last poll exits 130 / 143 as well, saying the
// files in `out` were written whole (or that nothing was written).
void throw_if_stopped_after_writing(const std::string& verb,
                                    const std::string& out);

// "--case" as given: 1..6, case1..case6 or a scene path. Returns the scene
// path and sets *name; throws UsageError naming `option` otherwise.
std::string study_scene(const std::string& option, const std::string& value,
                        std::string* name);

// Splits "a,b,c" into finite numbers (any count >= 1); UsageError naming
// `option` on an empty item or one that is not a number.
std::vector<double> parse_number_list(const std::string& option,
                                      const std::string& text);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_STUDY_FILES_H_
