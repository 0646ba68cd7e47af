#include "thesis/summary_json.h"

namespace vmh::thesis {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)

nlohmann::json claim_json(const Claim& c) {
  const auto opt = [](const auto& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  nlohmann::json sides = nlohmann::json::array();
  for (const Claim::Side& s : c.sides) {
    sides.push_back({{"where", s.where},
                     {"value", s.value},
                     {"pass", s.pass},
                     {"prediction", opt(s.prediction)},
                     {"matches_prediction", opt(s.matches_prediction)},
                     {"regime", s.regime},
                     {"mean_path_distance_mm", s.mean_path_distance_mm}});
  }
  return {{"name", c.name},         {"statement", c.statement},
          {"window", c.window},     {"value", c.value},
          {"comparison", c.comparison}, {"threshold", c.threshold},
          {"unit", c.unit},         {"samples", c.samples},
          {"mean_path_distance_mm", c.mean_path_distance_mm},
          {"pass", c.partial ? nlohmann::json("partial") : nlohmann::json(c.pass)},
          {"holds_where", c.partial ? nlohmann::json(c.holds_where)
                                    : nlohmann::json(nullptr)},
          {"sides", sides},
          {"prediction", c.prediction ? nlohmann::json(*c.prediction)
                                      : nlohmann::json(nullptr)},
          {"tolerance", c.prediction ? nlohmann::json(c.tolerance)
                                     : nlohmann::json(nullptr)},
          {"matches_prediction",
           c.matches_prediction ? nlohmann::json(*c.matches_prediction)
                                : nlohmann::json(nullptr)},
          {"prediction_note", c.prediction_note},
          {"saturated_fraction", c.saturated_fraction},
          {"regime", c.regime}};
}

nlohmann::json mujoco_warnings_json(
    const std::array<std::int64_t, mjNWARNING>& per_step,
    const MujocoWarningTally& messages) {
  nlohmann::json kinds = nlohmann::json::object();
  std::int64_t count = 0;
  for (int k = 0; k < mjNWARNING; ++k) {
    const std::int64_t n = per_step[static_cast<std::size_t>(k)];
    if (n > 0) kinds[mujoco_warning_name(k)] = n;
    count += n;
  }
  // what MuJoCo said besides its per-step warnings (those are counted above
  // at every step; it says each only once until the state is reset)
  const std::int64_t other = messages.count("other");
  if (other > 0) kinds["other"] = other;
  count += other;
  nlohmann::json texts = nlohmann::json::array();
  for (const MujocoWarningTally::Entry& e : messages.entries) {
    texts.push_back({{"kind", e.kind}, {"text", e.text}, {"count", e.count}});
  }
  return {{"count", count}, {"kinds", kinds}, {"messages", texts}};
}

nlohmann::json metrics_json(const RunMetrics& m) {
  return {{"ticks", m.ticks},
          {"rms_path_error_mm", m.rms_path_error_mm},
          {"max_path_error_mm", m.max_path_error_mm},
          {"rms_xv_error_mm", m.rms_xv_error_mm},
          {"mean_force_N", m.mean_force_N},
          {"rms_force_N", m.rms_force_N},
          {"max_force_N", m.max_force_N},
          {"time_on_path_s", m.time_on_path_s},
          {"on_path_within_mm", kOnPathMm},
          {"force_saturated_ticks", m.force_saturated_ticks},
          {"torque_saturated_ticks", m.torque_saturated_ticks},
          {"fault_ticks", m.fault_ticks},
          {"placement_not_converged_ticks", m.placement_not_converged_ticks},
          {"max_placement_iterations", m.max_placement_iterations}};
}

}  // namespace vmh::thesis
