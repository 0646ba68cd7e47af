// What the `hw` verbs share: the options every one of them takes (the
// backends' own options come from the registry: a --KEY flag for each key
// some backend takes), the clock, opening the device they name, and the
// output set every recording is written as.
#ifndef VMHAPTICS_CLI_HW_COMMON_H_
#define VMHAPTICS_CLI_HW_COMMON_H_

#include <CLI/CLI.hpp>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "output/output_file.h"
#include "runtime/backend_registry.h"
#include "runtime/json_util.h"
#include "runtime/session.h"

namespace vmh::cli {

struct HwCommon {
  std::string device = "emulator";
  // the backends' options by key, as given (--hand, --fault, ...)
  std::map<std::string, std::string> options;
  // "realtime", "lockstep" or "" (the verb's default: lockstep for a
  // simulated device, the wall clock for a real one)
  std::string clock;
  bool no_realtime = false;
  bool require_deadman = false;
  bool no_calibration = false;
  bool quiet = false;
};

// Refuses (UsageError) a time in seconds that is not a finite number in
// (lo_s, hi_s]: "<what> must be > lo and <= hi s, got <v>". `what` names the
// verb and the option ("hw record: --duration").
void check_seconds(const std::string& what, double v, double lo_s, double hi_s);

// Adds --device, a flag per registered backend option, --clock,
// --no-realtime, --require-deadman, --no-calibration and --quiet to a verb.
void add_hw_common(CLI::App* cmd, HwCommon* c);

// The backend c.device names and its argument (UsageError when none).
const runtime::BackendInfo& hw_backend(const HwCommon& c, std::string* argument);
// Whether the verb runs in lockstep: --clock, else lockstep exactly when
// the backend is simulated. UsageError for lockstep on a real device.
bool hw_lockstep(const HwCommon& c);

// Opens the device named by c.device for a servo loop (RequestError for an
// unknown backend or an option it does not take; DeviceOpenError for a
// device that cannot be opened). `default_hand`: the hand program a
// simulated device plays unless --hand says otherwise. `argument`, when
// not empty, replaces the spec's (hw run's scene). `sets`: the scene's
// --set overrides.
runtime::OpenedDevice open_hw_device(const HwCommon& c,
                                     const std::string& default_hand,
                                     const std::vector<std::string>& sets = {},
                                     const std::string& argument = "");

// Session options from the common flags: the verb's name, the clock, the
// scheduling, the dead-man, progress.
runtime::SessionOptions session_options(const HwCommon& c, const std::string& verb);

// The output set of a recording verb (--out DIR): created before the
// device is opened, so that an unusable DIR (a file, /proc, an empty
// name) is a usage error (exit 2) with nothing opened or written. Null
// when `out` was not given. trace.csv goes into its private folder as the
// session runs; commit() puts trace, meta and summary in place together.
std::unique_ptr<output::OutputSet> hw_output_set(const std::string& verb,
                                                 const std::string& out,
                                                 bool given);
// the session's trace path in the set and the path it will have
void trace_into(output::OutputSet* set, const std::string& out,
                runtime::SessionOptions* so);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_HW_COMMON_H_
