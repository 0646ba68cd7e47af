#include "runtime/meta.h"

#include "runtime/recording_reader.h"

#ifndef VMH_VERSION
#define VMH_VERSION "unknown"
#endif

namespace vmh::runtime {

Json software_json() {
  return Json{{"name", "vmhaptics"}, {"version", VMH_VERSION}};
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

Json timing_json(const TickStats& t, const std::string& clock) {
  return Json{{"clock", clock},
              {"ticks", t.ticks},
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
              {"clock", r.clock},
              {"samples_dropped", r.dropped},
              {"stop_reason", r.stop_reason},
              {"zeroed_ticks", r.zeroed_ticks},
              {"safety_ticks", safety},
              {"read_errors", errors},
              {"servo",
               Json{{"sched_fifo", r.servo_report.sched_fifo},
                    {"memory_locked", r.servo_report.memory_locked},
                    {"note", r.servo_report.note}}},
              {"timing", timing_json(r.timing, r.clock)}};
}

Json calibration_json(OpenedDevice* dev) {
  return Json{{"state", calibration_state_name(dev->backend->calibration_state())},
              {"source", dev->calibration_source}};
}

Json meta_json(OpenedDevice* dev, const SessionResult& r,
               const std::string& verb, const Json& extra) {
  Json m{{"verb", "hw " + verb},
         {"recording_format", kRecordingFormat},
         {"software", software_json()},
         {"date_utc", utc_now()},
         {"device", identity_json(dev->backend->identity())},
         {"calibration", calibration_json(dev)},
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
  if (dev->meta) {
    const Json own = dev->meta();
    for (auto it = own.begin(); it != own.end(); ++it) m[it.key()] = it.value();
  }
  for (auto it = extra.begin(); it != extra.end(); ++it) m[it.key()] = it.value();
  return m;
}

}  // namespace vmh::runtime
