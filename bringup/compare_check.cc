#include "bringup/compare_check.h"

#include <cmath>
#include <utility>

namespace vmh::bringup {

CompareCheck make_check(std::string name, double value, double threshold,
                        std::string unit, CompareCheck::Sense sense,
                        std::string detail) {
  CompareCheck c;
  c.name = std::move(name);
  c.value = value;
  c.threshold = threshold;
  c.unit = std::move(unit);
  c.sense = sense;
  c.detail = std::move(detail);
  c.pass = std::isfinite(value) &&
           (sense == CompareCheck::kAtMost ? value <= threshold : value >= threshold);
  return c;
}

nlohmann::ordered_json check_json(const CompareCheck& c) {
  nlohmann::ordered_json j{{"name", c.name},
                           {"pass", c.pass},
                           {"value", std::isfinite(c.value) ? nlohmann::ordered_json(c.value)
                                                            : nlohmann::ordered_json()},
                           {"threshold", c.threshold},
                           {"unit", c.unit},
                           {"sense", c.sense == CompareCheck::kAtMost ? "at_most" : "at_least"}};
  if (!c.recording.empty()) j["recording"] = c.recording;
  if (!c.detail.empty()) j["detail"] = c.detail;
  return j;
}

nlohmann::ordered_json section_json(const CompareSection& s) {
  nlohmann::ordered_json checks = nlohmann::ordered_json::array();
  for (const CompareCheck& c : s.checks) checks.push_back(check_json(c));
  nlohmann::ordered_json skipped = nlohmann::ordered_json::array();
  for (const SkippedCheck& k : s.skipped) {
    skipped.push_back({{"name", k.name}, {"reason", k.reason}, {"recording", k.recording}});
  }
  nlohmann::ordered_json faults = nlohmann::ordered_json::array();
  for (const SuspectedFault& f : s.faults) {
    faults.push_back({{"name", f.name}, {"evidence", f.evidence}, {"recording", f.recording}});
  }
  return {{"name", s.name}, {"checks", checks},   {"skipped", skipped},
          {"suspected_faults", faults}, {"detail", s.detail}, {"figures", s.figures}};
}

}  // namespace vmh::bringup
