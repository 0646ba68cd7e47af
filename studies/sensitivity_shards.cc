// The sensitivity study's shards: a shard's partial file
// (sensitivity.partial.json: the sweep's identity, its options and the
// shard's results), the options and results read back from one, and the
// merge of a sweep's partial files into the whole sweep's result.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "output/output_file.h"
#include "studies/sensitivity_detail.h"
#include "studies/sensitivity_study.h"

namespace vmh::studies {
namespace {

using Json = nlohmann::ordered_json;
using detail::parameter_from;
using detail::parameter_json;
using detail::sens_number_or_null;
using sim::SimError;
namespace fs = std::filesystem;

// a number a partial file holds, or NaN for its null
double number_from(const nlohmann::json& j) {
  return j.is_number() ? j.get<double>() : std::nan("");
}

}  // namespace

nlohmann::ordered_json partial_json(const SweepPlan& plan, int k, int n,
                                    const std::vector<PointResult>& results) {
  const SweepOptions& o = plan.options;
  Json table = Json();
  if (!o.parameters.empty()) {
    table = Json::array();
    for (const SweepParameter& p : o.parameters) table.push_back(parameter_json(p));
  }
  Json rs = Json::array();
  for (const PointResult& r : results) {
    Json claims = Json::array();
    for (const ClaimOutcome& c : r.claims) {
      claims.push_back({{"name", c.name}, {"value", sens_number_or_null(c.value)},
                        {"threshold", c.threshold}, {"comparison", c.comparison},
                        {"unit", c.unit}, {"pass", c.pass}});
    }
    rs.push_back({{"index", r.index},
                  {"error", r.error},
                  {"rms_path_error_mm", sens_number_or_null(r.rms_path_error_mm)},
                  {"claims", claims}});
  }
  return {{"study", "sensitivity-partial"},
          {"software", o.software},
          {"sweep_id", plan.id},
          {"shard", {{"k", k}, {"n", n}}},
          {"point_count", plan.points.size()},
          {"options",
           {{"cases", o.cases},
            {"quick", o.quick},
            {"levels", o.levels},
            {"samples", o.samples},
            {"seed", o.seed},
            {"set", o.overrides},
            {"parameters", table}}},
          {"results", rs}};
}

std::string write_partial_file(const SweepPlan& plan, int k, int n,
                               const std::vector<PointResult>& results,
                               const std::string& out_dir) {
  return output::write_file_in(out_dir, "sensitivity.partial.json",
                               partial_json(plan, k, n, results).dump(2) + "\n");
}

SweepOptions partial_options(const nlohmann::json& partial,
                             const std::string& where) {
  try {
    if (partial.at("study") != "sensitivity-partial") {
      throw std::runtime_error("not a sensitivity.partial.json");
    }
    const nlohmann::json& o = partial.at("options");
    SweepOptions s;
    s.cases = o.at("cases").get<std::vector<std::string>>();
    s.quick = o.at("quick").get<bool>();
    s.levels = o.at("levels").get<int>();
    s.samples = o.at("samples").get<int>();
    s.seed = o.at("seed").get<std::uint64_t>();
    s.overrides = o.at("set").get<std::vector<std::string>>();
    if (o.at("parameters").is_array()) {
      for (const auto& p : o.at("parameters")) s.parameters.push_back(parameter_from(p));
    }
    s.software = partial.at("software").get<std::string>();
    return s;
  } catch (const std::exception& e) {
    throw SimError(where + ": not a sensitivity shard's file (" + e.what() + ")");
  }
}

std::vector<PointResult> partial_results(const nlohmann::json& partial,
                                         const std::string& where) {
  std::vector<PointResult> out;
  try {
    for (const auto& r : partial.at("results")) {
      PointResult p;
      p.index = r.at("index").get<std::size_t>();
      p.error = r.at("error").get<std::string>();
      p.rms_path_error_mm = number_from(r.at("rms_path_error_mm"));
      for (const auto& c : r.at("claims")) {
        p.claims.push_back({c.at("name").get<std::string>(), number_from(c.at("value")),
                            c.at("threshold").get<double>(),
                            c.at("comparison").get<std::string>(),
                            c.at("unit").get<std::string>(), c.at("pass").get<bool>()});
      }
      out.push_back(p);
    }
  } catch (const std::exception& e) {
    throw SimError(where + ": a result that cannot be read (" + e.what() + ")");
  }
  return out;
}

SensitivityResult merge_partials(const std::vector<std::string>& paths,
                                 const std::string& software) {
  if (paths.empty()) throw SimError("merge: no partial files given");
  std::vector<std::pair<std::string, nlohmann::json>> files;
  for (const std::string& given : paths) {
    std::string path = given;
    if (fs::is_directory(path)) path = (fs::path(path) / "sensitivity.partial.json").string();
    std::ifstream in(path);
    if (!in) throw SimError(path + ": cannot read");
    nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded()) throw SimError(path + ": not JSON");
    files.emplace_back(path, std::move(j));
  }
  SweepOptions options = partial_options(files[0].second, files[0].first);
  const std::string first_software = options.software;
  options.software = software;
  SensitivityResult m;
  m.plan = plan_sweep(options);
  std::vector<bool> seen(m.plan.points.size(), false);
  m.results.resize(m.plan.points.size());
  for (const auto& [path, j] : files) {
    partial_options(j, path);  // the same checks on every file
    const std::string id = j.value("sweep_id", std::string());
    if (id != m.plan.id) {
      throw SimError(path + ": sweep " + id + " is not the sweep " + m.plan.id +
                     " that " + files[0].first + " describes (planned again by " +
                     software + "; the file was written by " +
                     j.value("software", std::string("?")) + ", the first by " +
                     first_software + ")");
    }
    for (PointResult& r : partial_results(j, path)) {
      if (r.index >= seen.size()) {
        throw SimError(path + ": point " + std::to_string(r.index) + " is not in the sweep");
      }
      if (seen[r.index]) {
        throw SimError(path + ": point " + std::to_string(r.index) +
                       " is given twice (the same shard merged twice?)");
      }
      seen[r.index] = true;
      m.results[r.index] = std::move(r);
    }
  }
  std::string missing;
  std::size_t n_missing = 0;
  for (std::size_t i = 0; i < seen.size(); ++i) {
    if (seen[i]) continue;
    if (++n_missing <= 5) missing += " " + std::to_string(i);
  }
  if (n_missing > 0) {
    throw SimError("merge: " + std::to_string(n_missing) + " of " +
                   std::to_string(seen.size()) + " points missing (" +
                   missing.substr(1) + (n_missing > 5 ? " ..." : "") +
                   "): a shard was not given");
  }
  return m;
}

}  // namespace vmh::studies
