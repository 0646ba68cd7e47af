// What the `hw` verbs share: the options every one of them takes, opening
// the device they name, and the metadata every recording carries.
#ifndef VMHAPTICS_CLI_HW_COMMON_H_
#define VMHAPTICS_CLI_HW_COMMON_H_

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "cli/hw_backends.h"
#include "cli/hw_session.h"
#include "cli/json_util.h"

namespace vmh::cli {

struct HwCommon {
  std::string device = "emulator";
  std::string hand;        // emulator: who holds the stylus (verb default)
  std::string faults;      // emulator: injected transport faults
  std::string seeded;      // emulator: seeded faults (--emulator-fault)
  std::string model;       // emulator: a calibrated Omni MJCF (--model)
  std::string hd_command = "joint_torque";
  bool no_realtime = false;
  bool require_deadman = false;
  bool no_calibration = false;
  bool quiet = false;
};

// Refuses (UsageError) a time in seconds that is not a finite number in
// (lo_s, hi_s]: "<what> must be > lo and <= hi s, got <v>". `what` names the
// verb and the option ("hw record: --duration").
void check_seconds(const std::string& what, double v, double lo_s, double hi_s);

// Adds --device, --hand, --fault, --emulator-fault, --model, --hd-command,
// --no-realtime, --require-deadman, --no-calibration and --quiet to a verb.
void add_hw_common(CLI::App* cmd, HwCommon* c);

// Opens the device named by c.device (UsageError for an unknown backend,
// for --emulator-fault or --model with another backend than the emulator,
// for a bad fault name or model file; DeviceOpenError for a device that
// cannot be opened).
OpenedDevice open_hw_device(const HwCommon& c, const std::string& default_hand,
                            const std::vector<std::string>& overrides = {});

// Session options from the common flags
SessionOptions session_options(const HwCommon& c, const std::string& verb);

// identity, calibration, software version and date, the servo thread's
// report and timing, the stop reason: what meta.json holds; on the
// emulator also "emulator": its scene (absolute path), hand program, model
// file (or null) and, as the emulator's hidden setup for tests,
// "seeded_faults"; on firewire and emulator:firewire also "firewire": the
// node, the transport's and the device's packet counts
Json identity_json(const DeviceIdentity& id);
Json timing_json(const TickStats& t);
Json session_json(const SessionResult& r);
Json meta_json(const OpenedDevice& dev, const SessionResult& r,
               const std::string& verb, const Json& extra);

// Writes out_dir/meta.json (atomically); nothing when out_dir is empty
void write_meta(const std::string& out_dir, const Json& meta);

// The session's end as an error, when it did not end as asked: a device
// that stopped answering (std::runtime_error, exit 1) or a signal
// (SignalStop, exit 130 / 143). Call after the outputs are written.
struct SignalStop : std::runtime_error {
  SignalStop(const std::string& what, int signo)
      : std::runtime_error(what), signal(signo) {}
  int signal;
};
void raise_if_cut_short(const SessionResult& r, const std::string& verb);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_HW_COMMON_H_
