#include "studies/modelling_spread.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "sim/mujoco_util.h"

namespace vmh::studies {

ModellingSpread read_modelling_spread(const std::string& given,
                                      const std::string& case_name) {
  std::string path = given;
  if (std::filesystem::is_directory(path)) {
    path = (std::filesystem::path(path) / "sensitivity.json").string();
  }
  std::ifstream in(path);
  if (!in) throw sim::SimError(path + ": cannot read");
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object() || j.value("study", "") != "sensitivity" ||
      !j.contains("modelling_spread")) {
    throw sim::SimError(path + ": not a sensitivity.json");
  }
  std::string known;
  for (const auto& c : j.at("modelling_spread")) {
    const std::string name = c.value("case", "");
    known += " " + name;
    if (name != case_name) continue;
    const auto& e = c.at("rms_path_error_mm");
    ModellingSpread s;
    s.present = true;
    s.source = path;
    s.case_name = name;
    s.sweep_id = j.value("sweep_id", "");
    s.over = e.value("over", "");
    s.points = e.value("points", 0);
    auto num = [](const nlohmann::json& x) {
      return x.is_number() ? x.get<double>() : std::nan("");
    };
    s.nominal_mm = num(e.at("nominal"));
    s.min_mm = num(e.at("min"));
    s.max_mm = num(e.at("max"));
    s.spread_mm = num(e.at("spread"));
    return s;
  }
  throw sim::SimError(path + ": no modelling spread for " + case_name +
                      " (it has:" + (known.empty() ? " none" : known) + ")");
}

nlohmann::ordered_json modelling_spread_json(const ModellingSpread& s,
                                             double numerical_error_mm) {
  using OJson = nlohmann::ordered_json;
  auto n = [](double x) { return std::isfinite(x) ? OJson(x) : OJson(); };
  const double ratio = s.spread_mm / numerical_error_mm;
  OJson dominant;
  if (std::isfinite(ratio)) dominant = ratio >= 1.0 ? "modelling" : "numerical";
  return {{"source", s.source},
          {"case", s.case_name},
          {"sweep_id", s.sweep_id},
          {"over", s.over},
          {"points", s.points},
          {"rms_path_error_nominal_mm", n(s.nominal_mm)},
          {"rms_path_error_min_mm", n(s.min_mm)},
          {"rms_path_error_max_mm", n(s.max_mm)},
          {"spread_mm", n(s.spread_mm)},
          {"default_rms_error_mm", n(numerical_error_mm)},
          {"spread_over_default_error", n(ratio)},
          {"dominant", dominant}};
}

void add_modelling_spread(output::Chart* chart, const ModellingSpread& s) {
  if (!s.present || !(s.spread_mm > 0.0)) return;
  double lo = INFINITY, hi = -INFINITY;
  for (const output::ChartSeries& series : chart->series) {
    for (double x : series.x) {
      if (!std::isfinite(x) || x <= 0.0) continue;
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
  }
  if (!(lo <= hi)) return;
  output::ChartSeries line;
  char label[160];
  std::snprintf(label, sizeof label,
                "modelling spread of the RMS path error, %s (%.3g mm)",
                s.case_name.c_str(), s.spread_mm);
  line.label = label;
  line.color = "#d62728";
  line.markers = false;
  line.dashed = true;
  line.x = {lo, hi};
  line.y = {s.spread_mm, s.spread_mm};
  chart->series.push_back(line);
}

}  // namespace vmh::studies
