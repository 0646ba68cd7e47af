#include "cli/hw_common.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cli/args.h"

namespace vmh::cli {

namespace fs = std::filesystem;

void check_seconds(const std::string& what, double v, double lo_s, double hi_s) {
  if (std::isfinite(v) && v > lo_s && v <= hi_s) return;
  char buf[96];
  std::snprintf(buf, sizeof buf, " must be > %g and <= %g s, got %g", lo_s, hi_s, v);
  throw UsageError(what + buf);
}

void add_hw_common(CLI::App* cmd, HwCommon* c) {
  const runtime::BackendRegistry& reg = runtime::BackendRegistry::global();
  std::string devices;
  for (const runtime::BackendInfo& b : reg.all()) {
    if (!b.servo) continue;
    devices += (devices.empty() ? "" : ", ") + b.grammar;
  }
  cmd->add_option("--device", c->device,
                  "the device: " + devices + " (default emulator; `vmhaptics "
                  "hw list` shows what this machine has)");
  for (const runtime::BackendRegistry::OptionUse& u : reg.option_uses()) {
    const std::string key = u.key;
    cmd->add_option_function<std::string>(
           "--" + key,
           [c, key](const std::string& v) { c->options[key] = v; },
           u.backends + ": " + u.help)
        ->type_name("TEXT");
  }
  cmd->add_option("--clock", c->clock,
                  "realtime (the wall clock: a servo thread, as on a device) "
                  "or lockstep (one period of simulated physics per tick, on "
                  "one thread: deterministic, as fast as the machine allows; "
                  "simulated devices and replay:DIR only). Default: lockstep "
                  "for a simulated device, realtime otherwise")
      ->check(CLI::IsMember({"realtime", "lockstep"}));
  cmd->add_flag("--no-realtime", c->no_realtime,
                "do not ask for SCHED_FIFO and mlockall");
  cmd->add_flag("--require-deadman", c->require_deadman,
                "no force unless button 1 is held");
  cmd->add_flag("--no-calibration", c->no_calibration,
                "ignore the stored calibration for this serial number");
  cmd->add_flag("--quiet", c->quiet, "no progress lines on stderr");
}

const runtime::BackendInfo& hw_backend(const HwCommon& c, std::string* argument) {
  const runtime::BackendRegistry& reg = runtime::BackendRegistry::global();
  if (c.device == "emulator" && reg.find("emulator") == nullptr) {
    // the default device where the build has no testbed
    throw UsageError("--device: this build has no emulator (it was built "
                     "without MuJoCo, VMH_BUILD_SIM=OFF); give one of " +
                     reg.grammars());
  }
  return reg.resolve(c.device, argument);
}

bool hw_lockstep(const HwCommon& c) {
  std::string argument;
  const runtime::BackendInfo& b = hw_backend(c, &argument);
  if (c.clock == "lockstep" && !b.can_lockstep()) {
    throw UsageError("--clock lockstep: only a simulated device or a "
                     "recording (replay:DIR) runs in lockstep, not --device " +
                     c.device);
  }
  if (c.clock.empty()) return b.simulated;
  return c.clock == "lockstep";
}

runtime::OpenedDevice open_hw_device(const HwCommon& c,
                                     const std::string& default_hand,
                                     const std::vector<std::string>& sets,
                                     const std::string& argument) {
  runtime::OpenRequest rq;
  rq.options = c.options;
  rq.defaults["hand"] = default_hand;
  rq.scene_sets = sets;
  rq.load_calibration = !c.no_calibration;
  rq.lockstep = hw_lockstep(c);
  std::string spec = c.device;
  if (!argument.empty()) {
    std::string given;
    const runtime::BackendInfo& b = hw_backend(c, &given);
    spec = b.name + ":" + argument;
  }
  return runtime::BackendRegistry::global().open(spec, rq);
}

runtime::SessionOptions session_options(const HwCommon& c, const std::string& verb) {
  runtime::SessionOptions o;
  o.verb = "hw " + verb;
  o.servo.realtime = !c.no_realtime;
  o.servo.lockstep = hw_lockstep(c);
  o.chain.safety_params.require_deadman = c.require_deadman;
  o.progress = !c.quiet;
  return o;
}

std::unique_ptr<output::OutputSet> hw_output_set(const std::string& verb,
                                                 const std::string& out,
                                                 bool given) {
  if (!given) return nullptr;
  if (out.empty()) {
    throw UsageError("hw " + verb + ": --out: an empty name is not a folder");
  }
  std::error_code ec;
  const fs::file_status st = fs::status(out, ec);
  if (!ec && fs::exists(st) && !fs::is_directory(st)) {
    throw UsageError("hw " + verb + ": --out '" + out +
                     "' is not a folder (it is a file)");
  }
  try {
    return std::make_unique<output::OutputSet>(out);
  } catch (const std::runtime_error& e) {
    throw UsageError("hw " + verb + ": --out '" + out + "': " + e.what());
  }
}

void trace_into(output::OutputSet* set, const std::string& out,
                runtime::SessionOptions* so) {
  if (set == nullptr) return;
  so->trace_path = (fs::path(set->temp_dir()) / "trace.csv").string();
  so->trace_shown = (fs::path(out) / "trace.csv").string();
}

}  // namespace vmh::cli
