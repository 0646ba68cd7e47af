// The sensitivity study's outputs: sensitivity.json (the sweep, its points,
// per claim what it depends on, the modelling spread), sensitivity.csv, the
// figure, what the command line prints, and the files. The partial files of
// shards and their merge are sensitivity_shards.cc.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "output/output_file.h"
#include "studies/sensitivity_detail.h"
#include "studies/sensitivity_study.h"

namespace vmh::studies {
namespace {

using Json = nlohmann::ordered_json;
using detail::sens_number_or_null;

Json value_json(const SweepValue& v) {
  return v.text.empty() ? Json(v.number) : Json(v.text);
}

const char* kind_name(SweepKind k) {
  switch (k) {
    case SweepKind::kField: return "case_field";
    case SweepKind::kFieldScale: return "case_field_scale";
    case SweepKind::kOmniMass: return "omni_mass_scale";
    case SweepKind::kOmniFriction: return "omni_friction_scale";
    case SweepKind::kChoice: return "case_field_choice";
  }
  return "?";
}
const char* scale_name(SweepScale s) {
  switch (s) {
    case SweepScale::kLinear: return "linear";
    case SweepScale::kLog: return "log";
    case SweepScale::kInteger: return "integer";
    case SweepScale::kChoice: return "choice";
  }
  return "?";
}
bool parse_kind(const std::string& s, SweepKind* k) {
  for (SweepKind x : {SweepKind::kField, SweepKind::kFieldScale,
                      SweepKind::kOmniMass, SweepKind::kOmniFriction,
                      SweepKind::kChoice}) {
    if (s == kind_name(x)) { *k = x; return true; }
  }
  return false;
}
bool parse_scale(const std::string& s, SweepScale* k) {
  for (SweepScale x : {SweepScale::kLinear, SweepScale::kLog,
                       SweepScale::kInteger, SweepScale::kChoice}) {
    if (s == scale_name(x)) { *k = x; return true; }
  }
  return false;
}

}  // namespace

namespace detail {

Json parameter_json(const SweepParameter& p) {
  Json j = {{"name", p.name},
            {"kind", kind_name(p.kind)},
            {"field", p.field.empty() ? Json() : Json(p.field)},
            {"scale", scale_name(p.scale)}};
  if (p.scale == SweepScale::kChoice) {
    j["choices"] = p.choices;
  } else {
    j["low"] = p.low;
    j["high"] = p.high;
  }
  j["unit"] = p.unit;
  j["source"] = p.source;
  j["optional"] = p.optional;
  return j;
}

SweepParameter parameter_from(const nlohmann::json& j) {
  SweepParameter p;
  p.name = j.at("name").get<std::string>();
  if (!parse_kind(j.at("kind").get<std::string>(), &p.kind) ||
      !parse_scale(j.at("scale").get<std::string>(), &p.scale)) {
    throw std::runtime_error("parameter " + p.name + ": unknown kind or scale");
  }
  if (j.at("field").is_string()) p.field = j.at("field").get<std::string>();
  if (p.scale == SweepScale::kChoice) {
    p.choices = j.at("choices").get<std::vector<std::string>>();
  } else {
    p.low = j.at("low").get<double>();
    p.high = j.at("high").get<double>();
  }
  p.unit = j.at("unit").get<std::string>();
  p.source = j.at("source").get<std::string>();
  p.optional = j.at("optional").get<bool>();
  return p;
}

}  // namespace detail

namespace {

// one case's claim as the sweep saw it
struct ClaimView {
  std::string name;
  std::string unit, comparison;
  double threshold = 0.0;
};

const ClaimOutcome* find_claim(const PointResult& r, const std::string& name) {
  for (const ClaimOutcome& c : r.claims) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

bool holds(const PointResult& r, const std::string& name) {
  const ClaimOutcome* c = find_claim(r, name);
  return r.error.empty() && c != nullptr && c->pass;
}

// the points of one case, by kind
struct CasePoints {
  std::size_t nominal = 0;
  std::vector<std::vector<std::size_t>> by_parameter;  // one at a time
  std::vector<std::size_t> sample;
};

CasePoints case_points(const SweepPlan& plan, std::size_t ci) {
  CasePoints cp;
  cp.by_parameter.resize(plan.parameters.size());
  for (const SweepPoint& pt : plan.points) {
    if (pt.case_index != ci) continue;
    switch (pt.kind) {
      case PointKind::kNominal: cp.nominal = pt.index; break;
      case PointKind::kOneAtATime:
        cp.by_parameter[static_cast<std::size_t>(pt.parameter)].push_back(pt.index);
        break;
      case PointKind::kSample: cp.sample.push_back(pt.index); break;
    }
  }
  return cp;
}

// the claims of a case, in the order its points first name them
std::vector<ClaimView> case_claims(const SweepPlan& plan, std::size_t ci,
                                   const std::vector<PointResult>& results) {
  std::vector<ClaimView> out;
  for (const SweepPoint& pt : plan.points) {
    if (pt.case_index != ci) continue;
    for (const ClaimOutcome& c : results[pt.index].claims) {
      const bool known = std::any_of(out.begin(), out.end(), [&](const ClaimView& v) {
        return v.name == c.name;
      });
      if (!known) out.push_back({c.name, c.unit, c.comparison, c.threshold});
    }
  }
  return out;
}

double fraction_holding(const std::vector<std::size_t>& points,
                        const std::vector<PointResult>& results,
                        const std::string& claim) {
  if (points.empty()) return std::nan("");
  std::size_t n = 0;
  for (std::size_t i : points) n += holds(results[i], claim) ? 1 : 0;
  return static_cast<double>(n) / static_cast<double>(points.size());
}

// min and max of the finite values
struct Range {
  double lo = std::nan(""), hi = std::nan("");
  void add(double x) {
    if (!std::isfinite(x)) return;
    lo = std::isfinite(lo) ? std::min(lo, x) : x;
    hi = std::isfinite(hi) ? std::max(hi, x) : x;
  }
  double span() const { return std::isfinite(lo) ? hi - lo : 0.0; }
  Json json() const { return Json::array({sens_number_or_null(lo), sens_number_or_null(hi)}); }
};

// a level's distance from the nominal on the parameter's own scale, 0..1
// of the range (choices: their order)
double distance(const SweepParameter& p, const SweepValue& v,
                const SweepValue& nominal) {
  if (p.scale == SweepScale::kChoice) return 0.0;
  if (p.scale == SweepScale::kLog && v.number > 0.0 && nominal.number > 0.0) {
    return std::abs(std::log(v.number / nominal.number)) /
           std::log(p.high / p.low);
  }
  return p.high > p.low ? std::abs(v.number - nominal.number) / (p.high - p.low)
                        : 0.0;
}

struct ParameterEffect {
  std::size_t parameter = 0;
  double holds_fraction = 0.0;
  Range value, margin;
  std::vector<SweepValue> flipped;  // levels where the verdict differs
  SweepValue flips_at;              // the one nearest the nominal
};

// the table as swept, each parameter with every case's nominal value
Json swept_parameters_json(const SweepPlan& plan) {
  Json params = Json::array();
  for (std::size_t j = 0; j < plan.parameters.size(); ++j) {
    Json p = detail::parameter_json(plan.parameters[j]);
    p.erase("optional");
    Json nominal = Json::object();
    for (const SweepCase& c : plan.cases) nominal[c.name] = value_json(c.nominal[j]);
    p["nominal"] = nominal;
    params.push_back(p);
  }
  return params;
}

// every point: what it set, its RMS path error, error and claims
Json points_json(const SweepPlan& plan,
                 const std::vector<PointResult>& results) {
  Json points = Json::array();
  for (const SweepPoint& pt : plan.points) {
    const PointResult& r = results[pt.index];
    Json values = Json::object();
    for (std::size_t j = 0; j < plan.parameters.size(); ++j) {
      values[plan.parameters[j].name] = value_json(pt.values[j]);
    }
    Json claims = Json::object();
    for (const ClaimOutcome& c : r.claims) {
      claims[c.name] = {{"value", sens_number_or_null(c.value)},
                        {"margin", sens_number_or_null(claim_margin(c))},
                        {"pass", c.pass}};
    }
    points.push_back(
        {{"index", pt.index},
         {"case", plan.cases[pt.case_index].name},
         {"kind", point_kind_name(pt.kind)},
         {"parameter", pt.parameter < 0 ? Json()
                                        : Json(plan.parameters[static_cast<std::size_t>(pt.parameter)].name)},
         {"values", values},
         {"set", pt.overrides},
         {"rms_path_error_mm", sens_number_or_null(r.rms_path_error_mm)},
         {"error", r.error.empty() ? Json() : Json(r.error)},
         {"claims", claims}});
  }
  return points;
}

// What parameter j does to a claim of case ci (points cp) one at a time:
// the share of its levels (and the nominal) where the claim holds, the
// claim's value and margin ranges, the levels where the verdict differs
// from the nominal's and, of those, the one nearest the nominal.
ParameterEffect parameter_effect(const SweepPlan& plan,
                                 const std::vector<PointResult>& results,
                                 std::size_t ci, const CasePoints& cp,
                                 const std::string& claim, bool nominal_holds,
                                 std::size_t j) {
  const SweepCase& c = plan.cases[ci];
  ParameterEffect e;
  e.parameter = j;
  std::vector<std::size_t> pts = {cp.nominal};
  pts.insert(pts.end(), cp.by_parameter[j].begin(), cp.by_parameter[j].end());
  e.holds_fraction = fraction_holding(pts, results, claim);
  double best = INFINITY;
  for (std::size_t i : pts) {
    const ClaimOutcome* o = find_claim(results[i], claim);
    if (o != nullptr) {
      e.value.add(o->value);
      e.margin.add(claim_margin(*o));
    }
    if (i == cp.nominal || holds(results[i], claim) == nominal_holds) {
      continue;
    }
    const SweepValue& v = plan.points[i].values[j];
    e.flipped.push_back(v);
    const double d = distance(plan.parameters[j], v, c.nominal[j]);
    if (d < best) {
      best = d;
      e.flips_at = v;
    }
  }
  return e;
}

// the parameters that flip the claim somewhere in their range, the widest
// margin span first, each with where it flips
Json depends_on_json(const SweepPlan& plan,
                     const std::vector<ParameterEffect>& effects) {
  std::vector<ParameterEffect> deciding;
  for (const ParameterEffect& e : effects) {
    if (!e.flipped.empty()) deciding.push_back(e);
  }
  std::stable_sort(deciding.begin(), deciding.end(),
                   [](const ParameterEffect& a, const ParameterEffect& b) {
                     return a.margin.span() > b.margin.span();
                   });
  Json depends_on = Json::array();
  for (const ParameterEffect& e : deciding) {
    Json levels = Json::array();
    for (const SweepValue& v : e.flipped) levels.push_back(value_json(v));
    depends_on.push_back({{"parameter", plan.parameters[e.parameter].name},
                          {"flips_at", value_json(e.flips_at)},
                          {"flipped_at", levels},
                          {"value_range", e.value.json()},
                          {"margin_range", e.margin.json()}});
  }
  return depends_on;
}

// The points a case's holds fractions and spread are taken over: the
// sample's if it has one, else the one-at-a-time points with the nominal.
struct CaseSpan {
  CasePoints cp;
  std::vector<std::size_t> oat;  // the nominal and every one-at-a-time point
  bool sampled = false;
  const std::vector<std::size_t>& over() const {
    return sampled ? cp.sample : oat;
  }
};

CaseSpan case_span(const SweepPlan& plan, std::size_t ci) {
  CaseSpan span;
  span.cp = case_points(plan, ci);
  span.oat = {span.cp.nominal};
  for (const auto& v : span.cp.by_parameter) {
    span.oat.insert(span.oat.end(), v.begin(), v.end());
  }
  span.sampled = !span.cp.sample.empty();
  return span;
}

// One claim of case ci: its threshold, value at the nominal, holds
// fractions (over the span, one at a time, over the sample), what it
// depends on and each parameter's effect.
Json claim_json(const SweepPlan& plan, const std::vector<PointResult>& results,
                std::size_t ci, const CaseSpan& span, const ClaimView& cv) {
  const CasePoints& cp = span.cp;
  const PointResult& nom = results[cp.nominal];
  const ClaimOutcome* nc = find_claim(nom, cv.name);
  const bool nominal_holds = holds(nom, cv.name);
  std::vector<ParameterEffect> effects;
  for (std::size_t j = 0; j < plan.parameters.size(); ++j) {
    effects.push_back(
        parameter_effect(plan, results, ci, cp, cv.name, nominal_holds, j));
  }
  Json by_parameter = Json::array();
  for (const ParameterEffect& e : effects) {
    by_parameter.push_back({{"parameter", plan.parameters[e.parameter].name},
                            {"holds_fraction", sens_number_or_null(e.holds_fraction)},
                            {"value_range", e.value.json()},
                            {"margin_range", e.margin.json()}});
  }
  const bool sampled = span.sampled;
  return {{"case", plan.cases[ci].name},
          {"name", cv.name},
          {"unit", cv.unit},
          {"comparison", cv.comparison},
          {"threshold", cv.threshold},
          {"value_at_nominal", nc != nullptr ? sens_number_or_null(nc->value) : Json()},
          {"holds_at_nominal", nominal_holds},
          {"holds_fraction",
           sens_number_or_null(fraction_holding(span.over(), results, cv.name))},
          {"holds_fraction_over", sampled ? "sample" : "one_at_a_time"},
          {"holds_fraction_one_at_a_time",
           sens_number_or_null(fraction_holding(span.oat, results, cv.name))},
          {"holds_fraction_sample",
           sampled ? sens_number_or_null(fraction_holding(cp.sample, results, cv.name))
                   : Json()},
          {"depends_on", depends_on_json(plan, effects)},
          {"by_parameter", by_parameter}};
}

// The modelling spread of case ci's RMS path error: its range over the
// span, and each parameter's range one at a time, the widest first.
Json spread_json(const SweepPlan& plan, const std::vector<PointResult>& results,
                 std::size_t ci, const CaseSpan& span) {
  const CasePoints& cp = span.cp;
  Range all;
  for (std::size_t i : span.over()) all.add(results[i].rms_path_error_mm);
  Json by_parameter = Json::array();
  std::vector<std::pair<double, Json>> ranked;
  for (std::size_t j = 0; j < plan.parameters.size(); ++j) {
    Range r;
    r.add(results[cp.nominal].rms_path_error_mm);
    for (std::size_t i : cp.by_parameter[j]) r.add(results[i].rms_path_error_mm);
    ranked.push_back({r.span(), Json{{"parameter", plan.parameters[j].name},
                                     {"range_mm", r.json()},
                                     {"spread_mm", r.span()}}});
  }
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (auto& r : ranked) by_parameter.push_back(r.second);
  return {{"case", plan.cases[ci].name},
          {"rms_path_error_mm",
           {{"nominal", sens_number_or_null(results[cp.nominal].rms_path_error_mm)},
            {"min", sens_number_or_null(all.lo)},
            {"max", sens_number_or_null(all.hi)},
            {"spread", all.span()},
            {"over", span.sampled ? "sample" : "one_at_a_time"},
            {"points", span.over().size()}}},
          {"by_parameter", by_parameter}};
}

}  // namespace

nlohmann::ordered_json sensitivity_file_json(
    const SweepPlan& plan, const std::vector<PointResult>& results) {
  Json cases = Json::array();
  for (const SweepCase& c : plan.cases) {
    cases.push_back({{"name", c.name}, {"scene", c.scene},
                     {"physics_step_s", c.physics_step_s}});
  }
  Json claims = Json::array();
  Json spreads = Json::array();
  for (std::size_t ci = 0; ci < plan.cases.size(); ++ci) {
    const CaseSpan span = case_span(plan, ci);
    for (const ClaimView& cv : case_claims(plan, ci, results)) {
      claims.push_back(claim_json(plan, results, ci, span, cv));
    }
    spreads.push_back(spread_json(plan, results, ci, span));
  }
  std::size_t failed = 0;
  for (const PointResult& r : results) failed += r.error.empty() ? 0 : 1;
  return {{"study", "sensitivity"},
          {"software", plan.options.software},
          {"sweep_id", plan.id},
          {"cases", cases},
          {"quick", plan.options.quick},
          {"levels", plan.options.levels},
          {"samples", plan.options.samples},
          {"seed", plan.options.seed},
          {"set", plan.options.overrides},
          {"parameters", swept_parameters_json(plan)},
          {"omitted", plan.omitted},
          {"point_count", plan.points.size()},
          {"failed_points", failed},
          {"claims", claims},
          {"modelling_spread", spreads},
          {"points", points_json(plan, results)}};
}

std::string sensitivity_csv(const SweepPlan& plan,
                            const std::vector<PointResult>& results) {
  std::ostringstream s;
  s.precision(9);
  s << "point,case,kind,parameter";
  for (const SweepParameter& p : plan.parameters) s << ',' << p.name;
  s << ",rms_path_error_mm,claim,claim_value,claim_unit,comparison,threshold,"
       "margin_rel,holds,error\n";
  for (const SweepPoint& pt : plan.points) {
    const PointResult& r = results[pt.index];
    std::ostringstream head;
    head.precision(9);
    head << pt.index << ',' << plan.cases[pt.case_index].name << ','
         << point_kind_name(pt.kind) << ','
         << (pt.parameter < 0 ? "" : plan.parameters[static_cast<std::size_t>(pt.parameter)].name);
    for (const SweepValue& v : pt.values) {
      if (v.text.empty()) head << ',' << v.number; else head << ',' << v.text;
    }
    head << ',' << r.rms_path_error_mm;
    std::string error = r.error;
    std::replace(error.begin(), error.end(), ',', ';');
    std::replace(error.begin(), error.end(), '\n', ' ');
    if (r.claims.empty()) {
      s << head.str() << ",,,,,,,0," << error << '\n';
    }
    for (const ClaimOutcome& c : r.claims) {
      s << head.str() << ',' << c.name << ',' << c.value << ',' << c.unit << ','
        << c.comparison << ',' << c.threshold << ',' << claim_margin(c) << ','
        << (c.pass ? 1 : 0) << ',' << error << '\n';
    }
  }
  return s.str();
}

output::ChartGrid sensitivity_chart(const SweepPlan& plan,
                                    const std::vector<PointResult>& results) {
  output::ChartGrid grid;
  grid.title = "Sensitivity: each claim's margin over each parameter's range, "
               "the others nominal";
  grid.notes = {
      "margin = (value - threshold)/|threshold| for >=, (threshold - value)/|threshold| "
      "for <=; >= 0 holds. A bar spans the margins over one parameter's levels; the dot "
      "is the nominal.",
      "sweep " + plan.id + ", " + plan.options.software};
  grid.columns = 2;
  for (std::size_t ci = 0; ci < plan.cases.size(); ++ci) {
    const CasePoints cp = case_points(plan, ci);
    for (const ClaimView& cv : case_claims(plan, ci, results)) {
      output::Chart ch;
      ch.title = plan.cases[ci].name + " " + cv.name;
      ch.x.label = "parameter (legend order)";
      ch.y.label = "claim margin (relative)";
      ch.width_px = 560;
      ch.height_px = 420;
      const ClaimOutcome* nc = find_claim(results[cp.nominal], cv.name);
      const double nominal_margin = nc ? claim_margin(*nc) : std::nan("");
      for (std::size_t j = 0; j < plan.parameters.size(); ++j) {
        Range r;
        r.add(nominal_margin);
        for (std::size_t i : cp.by_parameter[j]) {
          if (const ClaimOutcome* o = find_claim(results[i], cv.name)) {
            r.add(claim_margin(*o));
          }
        }
        output::ChartSeries s;
        s.label = plan.parameters[j].name;
        const double x = static_cast<double>(j + 1);
        s.x = {x, x};
        s.y = {r.lo, r.hi};
        ch.series.push_back(s);
      }
      output::ChartSeries zero;
      zero.label = "holds above 0";
      zero.x = {0.5, static_cast<double>(plan.parameters.size()) + 0.5};
      zero.y = {0.0, 0.0};
      zero.color = "#000000";
      zero.dashed = true;
      zero.markers = false;
      ch.series.push_back(zero);
      output::ChartSeries nom;
      nom.label = "nominal";
      for (std::size_t j = 0; j < plan.parameters.size(); ++j) {
        nom.x.push_back(static_cast<double>(j + 1));
        nom.y.push_back(nominal_margin);
      }
      nom.line = false;
      nom.color = "#000000";
      ch.series.push_back(nom);
      grid.panels.push_back(ch);
    }
  }
  return grid;
}

namespace {

// The whole sweep as the command line prints it: sensitivity.json's
// summary (per claim its holds fractions and the parameters that flip it,
// with where; each case's spread of the RMS path error) and the files.
Json sweep_summary_json(const Json& full,
                        const std::vector<std::string>& files) {
  Json claims = Json::array();
  for (const auto& c : full.at("claims")) {
    Json deps = Json::array();
    for (const auto& d : c.at("depends_on")) {
      deps.push_back({{"parameter", d.at("parameter")}, {"flips_at", d.at("flips_at")}});
    }
    claims.push_back({{"case", c.at("case")},
                      {"name", c.at("name")},
                      {"holds_at_nominal", c.at("holds_at_nominal")},
                      {"holds_fraction", c.at("holds_fraction")},
                      {"holds_fraction_one_at_a_time", c.at("holds_fraction_one_at_a_time")},
                      {"depends_on", deps}});
  }
  Json spread = Json::array();
  for (const auto& s : full.at("modelling_spread")) {
    spread.push_back({{"case", s.at("case")}, {"rms_path_error_mm", s.at("rms_path_error_mm")}});
  }
  return {{"study", "sensitivity"},
          {"sweep_id", full.at("sweep_id")},
          {"point_count", full.at("point_count")},
          {"failed_points", full.at("failed_points")},
          {"omitted", full.at("omitted")},
          {"claims", claims},
          {"modelling_spread", spread},
          {"files", files}};
}

}  // namespace

nlohmann::ordered_json sensitivity_json(const SensitivityResult& r) {
  if (r.is_shard()) {
    return {{"study", "sensitivity"},
            {"sweep_id", r.plan.id},
            {"shard", {{"k", r.shard_k}, {"n", r.shard_n}}},
            {"point_count", r.plan.points.size()},
            {"points_run", r.results.size()},
            {"files", r.files}};
  }
  return sweep_summary_json(sensitivity_file_json(r.plan, r.results), r.files);
}

std::vector<std::string> write_sensitivity_files(const SensitivityResult& r,
                                                 const std::string& out_dir) {
  if (r.is_shard()) {
    return {write_partial_file(r.plan, r.shard_k, r.shard_n, r.results,
                               out_dir)};
  }
  const std::string svg =
      output::chart_grid_svg(sensitivity_chart(r.plan, r.results));
  const std::string json =
      sensitivity_file_json(r.plan, r.results).dump(2) + "\n";
  return {output::write_file_in(out_dir, "sensitivity.json", json),
          output::write_file_in(out_dir, "sensitivity.csv",
                                sensitivity_csv(r.plan, r.results)),
          output::write_file_in(out_dir, "sensitivity.svg", svg)};
}

}  // namespace vmh::studies
