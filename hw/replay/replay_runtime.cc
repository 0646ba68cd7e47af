#include "hw/replay/replay_runtime.h"

#include <cmath>
#include <cstdlib>
#include <memory>

namespace vmh::hw::replay {
namespace {

runtime::OpenedDevice open_replay(const runtime::OpenRequest& rq) {
  const std::string& dir = rq.argument;
  if (dir.empty()) {
    throw runtime::RequestError(
        "--device replay: give a recording folder, replay:DIR (DIR written "
        "by `vmhaptics hw record --out DIR`)");
  }
  if (const std::size_t q = dir.find('?'); q != std::string::npos) {
    throw runtime::RequestError(
        "--device replay:" + dir + ": '" + dir.substr(q + 1) +
        "' is not a replay option (replay takes replay-end=hold|loop|stop "
        "and replay-speed=F: --replay-end/--replay-speed on the command "
        "line, replay:DIR?replay-end=loop through the HD API)");
  }
  const ReplayOptions ro = replay_options(rq);
  auto rec = std::make_shared<const Recording>(read_recording(dir));
  auto backend = std::make_unique<ReplayBackend>(rec, ro);
  ReplayDevice* device = backend->replay();
  runtime::OpenedDevice dev;
  dev.calibration_source =
      "the recording's (its angles were decoded when it was recorded: " +
      rec->trace_file + ")";
  dev.meta = [device]() { return Json{{"replay", replay_meta_json(*device)}}; };
  dev.backend = std::move(backend);
  return dev;
}

}  // namespace

ReplayOptions replay_options(const runtime::OpenRequest& rq) {
  ReplayOptions o;
  try {
    o.end = parse_replay_end(rq.option("replay-end"));
  } catch (const std::invalid_argument& e) {
    throw runtime::RequestError(std::string("--replay-end: ") + e.what());
  }
  const std::string speed = rq.option("replay-speed");
  if (!speed.empty()) {
    char* end = nullptr;
    const double v = std::strtod(speed.c_str(), &end);
    if (end != speed.c_str() + speed.size() || !std::isfinite(v) || v <= 0.0 ||
        v > 1000.0) {
      throw runtime::RequestError("--replay-speed: '" + speed +
                                  "' is not a number > 0 and <= 1000");
    }
    o.speed = v;
  }
  return o;
}

Json replay_meta_json(const ReplayDevice& device) {
  const Recording& r = device.recording();
  const ReplayStats s = device.stats();
  Json recorded = Json::object();
  if (r.has_meta) {
    recorded = Json{{"backend", r.recorded.backend},
                    {"model", r.recorded.model},
                    {"serial", r.recorded.serial}};
  }
  return Json{
      {"folder", r.folder},
      {"rows", r.rows()},
      {"first_s", r.first_s()},
      {"last_s", r.last_s()},
      {"recorded_device", recorded},
      {"end", replay_end_name(device.options().end)},
      {"speed", device.options().speed},
      {"reads", s.reads},
      {"failed_reads", s.failed_reads},
      {"loops", s.loops},
      {"last_clock_s", s.clock_s},
      {"writes", s.writes},
      {"invalid_writes", s.invalid_writes},
      {"max_abs_tau_Nm",
       {s.max_abs_tau_Nm[0], s.max_abs_tau_Nm[1], s.max_abs_tau_Nm[2]}},
      {"writes_note",
       "torques the program sent, counted; nothing moved (the joints are the "
       "recording's)"}};
}

void register_replay_backend(runtime::BackendRegistry* registry) {
  runtime::BackendInfo b;
  b.name = "replay";
  b.grammar = "replay:DIR";
  b.summary = "a recording of `hw record` (DIR/trace.csv) served as a device";
  b.options = {
      {"replay-end",
       "after the recording's last row, hold (keep serving it; "
       "default), loop (from the first row again) or stop (reads fail: the "
       "device is gone)"},
      {"replay-speed",
       "recording seconds per second of replay, > 0 and <= 1000 "
       "(default 1)"},
  };
  b.lockstep = true;
  b.list = [] {
    return Json{{"available", false},
                {"why_not",
                 "no discovery: give a recording folder, --device replay:DIR "
                 "(DIR written by `vmhaptics hw record --out DIR`)"},
                {"clocks", {"realtime", "lockstep"}}};
  };
  b.open = open_replay;
  registry->add(std::move(b));
}

}  // namespace vmh::hw::replay
