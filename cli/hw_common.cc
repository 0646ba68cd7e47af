#include "cli/hw_common.h"

#include <cmath>
#include <cstdio>

#include <csignal>

#include "cli/args.h"
#include "hw/firewire/firewire_omni.h"
#include "report/output_file.h"

namespace vmh::cli {

void check_seconds(const std::string& what, double v, double lo_s, double hi_s) {
  if (std::isfinite(v) && v > lo_s && v <= hi_s) return;
  char buf[96];
  std::snprintf(buf, sizeof buf, " must be > %g and <= %g s, got %g", lo_s, hi_s, v);
  throw UsageError(what + buf);
}

void add_hw_common(CLI::App* cmd, HwCommon* c) {
  cmd->add_option("--device", c->device,
                  "emulator[:case|scene.xml] (default), "
                  "emulator:firewire[:case|scene.xml] (the emulator behind the "
                  "FireWire packets), openhaptics[:CONFIG_NAME] or "
                  "firewire[:GUID]");
  cmd->add_option("--hand", c->hand,
                  "emulator: what holds the stylus: case, tour, none, dock, "
                  "gimbal_sweep (default depends on the verb)");
  cmd->add_option("--fault", c->faults,
                  "emulator: transport faults, e.g. "
                  "drop@1.0:5,late@2:0.5:3,stall@3:0.2,unplug@4:1; "
                  "emulator:firewire: packet faults, e.g. loss@1:5,"
                  "late@2:0.5:3,length@3:2,reset@4,unplug@5:1,stall@6:0.2");
  cmd->add_option("--emulator-fault", c->seeded,
                  "emulator: seeded faults for bring-up tests, comma-separated: "
                  "joint<N>_sign, gimbal_swap, link_length_<P>pct, delay_<M>ms, "
                  "motor3_relative, motor<N>_sign, torque_units_Nm, "
                  "torque_units_mNm, mass_x<K>, friction_x<K>, damping_x<K> "
                  "(docs/hardware.md)");
  cmd->add_option("--model", c->model,
                  "emulator: a calibrated Omni MJCF (e.g. "
                  "models/omni/calibrated/<serial>.xml) whose parameters "
                  "replace the scene's Omni's");
  cmd->add_option("--hd-command", c->hd_command,
                  "openhaptics: joint_torque (HD_CURRENT_JOINT_TORQUE, "
                  "mN m; default) or force (HD_CURRENT_FORCE, N)");
  cmd->add_flag("--no-realtime", c->no_realtime,
                "do not ask for SCHED_FIFO and mlockall");
  cmd->add_flag("--require-deadman", c->require_deadman,
                "no force unless button 1 is held");
  cmd->add_flag("--no-calibration", c->no_calibration,
                "ignore the stored calibration for this serial number");
  cmd->add_flag("--quiet", c->quiet, "no progress lines on stderr");
}

OpenedDevice open_hw_device(const HwCommon& c, const std::string& default_hand,
                            const std::vector<std::string>& overrides) {
  const DeviceSpec spec = parse_device_spec(c.device);
  if (spec.backend != "emulator") {
    // a real device has no seeded faults and no model to replace
    if (!c.seeded.empty()) {
      throw UsageError("--emulator-fault: only the emulator takes seeded "
                       "faults, not --device " + c.device);
    }
    if (!c.model.empty()) {
      throw UsageError("--model: only the emulator simulates a model, not "
                       "--device " + c.device);
    }
  }
  OpenOptions oo;
  oo.overrides = overrides;
  oo.seeded = c.seeded;
  oo.model_file = c.model;
  oo.hand = c.hand.empty() ? default_hand : c.hand;
  oo.faults = c.faults;
  oo.hd_command = c.hd_command;
  oo.load_calibration = !c.no_calibration;
  return open_device(spec, oo);
}

SessionOptions session_options(const HwCommon& c, const std::string& verb) {
  SessionOptions o;
  o.verb = "hw " + verb;
  o.servo.realtime = !c.no_realtime;
  o.safety.require_deadman = c.require_deadman;
  o.progress = !c.quiet;
  return o;
}

Json identity_json(const DeviceIdentity& id) {
  return Json{{"backend", id.backend},
              {"config", id.config},
              {"model", id.model},
              {"vendor", id.vendor},
              {"serial", id.serial},
              {"driver_version", id.driver_version},
              {"firmware_version", id.firmware_version},
              {"api_version", id.api_version},
              {"input_dof", id.input_dof},
              {"output_dof", id.output_dof}};
}

Json timing_json(const TickStats& t) {
  return Json{{"ticks", t.ticks},
              {"overruns", t.overruns},
              {"nominal_period_us", 1e6 * t.nominal_period_s},
              {"period_mean_us", 1e6 * t.period_mean_s},
              {"period_min_us", 1e6 * t.period_min_s},
              {"period_p50_us", 1e6 * t.period_p50_s},
              {"period_p99_us", 1e6 * t.period_p99_s},
              {"period_max_us", 1e6 * t.period_max_s},
              {"jitter_p50_us", 1e6 * t.jitter_p50_s},
              {"jitter_p99_us", 1e6 * t.jitter_p99_s},
              {"jitter_max_us", 1e6 * t.jitter_max_s},
              {"work_p50_us", 1e6 * t.work_p50_s},
              {"work_p99_us", 1e6 * t.work_p99_s},
              {"work_max_us", 1e6 * t.work_max_s}};
}

Json session_json(const SessionResult& r) {
  Json safety = Json::object();
  for (const auto& [k, v] : r.safety_ticks) safety[k] = v;
  Json errors = Json::object();
  for (const auto& [k, v] : r.read_errors) errors[k] = v;
  return Json{{"duration_s", r.duration_s},
              {"ticks", r.ticks},
              {"samples_dropped", r.dropped},
              {"stop_reason", r.stop_reason},
              {"zeroed_ticks", r.zeroed_ticks},
              {"safety_ticks", safety},
              {"read_errors", errors},
              {"servo",
               Json{{"sched_fifo", r.servo_report.sched_fifo},
                    {"memory_locked", r.servo_report.memory_locked},
                    {"note", r.servo_report.note}}},
              {"timing", timing_json(r.timing)}};
}

Json meta_json(const OpenedDevice& dev, const SessionResult& r,
               const std::string& verb, const Json& extra) {
  Json m{{"verb", "hw " + verb},
         {"software", Json{{"name", "vmhaptics"}, {"version", VMH_VERSION}}},
         {"date_utc", utc_now()},
         {"device", identity_json(dev.backend->identity())},
         {"calibration",
          Json{{"state", calibration_state_name(dev.backend->calibration_state())},
               {"source", dev.calibration_source}}},
         {"session", session_json(r)}};
  // the periods' histogram, up to its last non-empty bin
  Json counts = Json::array();
  std::size_t last = 0;
  for (std::size_t i = 0; i < r.timing.histogram.size(); ++i) {
    if (r.timing.histogram[i] != 0) last = i + 1;
  }
  for (std::size_t i = 0; i < last; ++i) counts.push_back(r.timing.histogram[i]);
  m["period_histogram"] = Json{{"bin_us", 1e6 * r.timing.histogram_bin_s},
                               {"counts", counts},
                               {"last_bin_holds_the_rest", true}};
  if (dev.firewire != nullptr) {
    // the bus and the packets: where the node was, what was lost
    const hw::fw::NodeInfo n = dev.firewire->transport()->node();
    const hw::fw::TransportStats t = dev.firewire->transport()->stats();
    const hw::fw::FirewireOmniStats d = dev.firewire->omni()->stats();
    m["firewire"] = Json{
        {"node", Json{{"guid", n.guid},
                      {"vendor", n.vendor},
                      {"serial", n.serial},
                      {"description", n.description},
                      {"generation", n.generation}}},
        {"transport", Json{{"received", t.received},
                           {"sent", t.sent},
                           {"bad_packets", t.bad_packets},
                           {"timeouts", t.timeouts},
                           {"bus_resets", t.bus_resets},
                           {"recoveries", t.recoveries}}},
        {"device", Json{{"packets", d.packets},
                        {"lost_packets", d.lost_packets},
                        {"bad_packets", d.bad_packets},
                        {"timeouts", d.timeouts},
                        {"bus_resets", d.bus_resets},
                        {"recoveries_failed", d.recoveries_failed},
                        {"commands", d.commands},
                        {"saturated_commands", d.saturated_commands}}}};
  }
  if (dev.emulator != nullptr) {
    // what compare needs to simulate the same scene; the seeded faults are
    // the emulator's hidden setup, there for tests to grade compare by
    m["emulator"] = Json{
        {"scene", dev.scene},
        {"hand", dev.hand},
        {"model", dev.model_file.empty() ? Json(nullptr) : Json(dev.model_file)},
        {"seeded_faults", dev.seeded_faults},
        {"seeded_faults_note",
         "the emulator's hidden setup, for tests only: an analysis must not "
         "read it"}};
  }
  for (auto it = extra.begin(); it != extra.end(); ++it) m[it.key()] = it.value();
  return m;
}

void write_meta(const std::string& out_dir, const Json& meta) {
  if (out_dir.empty()) return;
  report::write_file_in(out_dir, "meta.json", dump_readable(meta) + "\n");
}

void raise_if_cut_short(const SessionResult& r, const std::string& verb) {
  if (r.signal != 0) {
    throw SignalStop("hw " + verb + ": stopped by " + r.stop_reason.substr(7) +
                         "; zero torque sent, trace kept up to t = " +
                         std::to_string(r.duration_s) + " s",
                     r.signal);
  }
  if (r.device_gone) {
    throw std::runtime_error("hw " + verb + ": " + r.stop_reason +
                             "; zero torque sent, trace kept up to t = " +
                             std::to_string(r.duration_s) + " s");
  }
}

}  // namespace vmh::cli
