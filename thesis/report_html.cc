#include "thesis/report_html.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "controller/vm_registry.h"
#include "output/output_file.h"
#include "thesis/html_parts.h"

#include "output/svg_text.h"
#include "thesis/force_field_svg.h"
#include "thesis/thesis_svg.h"

namespace vmh::thesis {
namespace {

using output::svg::escape;
using PageJson = nlohmann::json;

// a number as a reader reads it: 4 significant digits, integers whole
std::string num(const PageJson& v) {
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_number_integer()) return std::to_string(v.get<long long>());
  if (v.is_number()) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.4g", v.get<double>());
    return buf;
  }
  if (v.is_string()) return v.get<std::string>();
  if (v.is_null()) return "null";
  if (v.is_array()) {
    std::string s;
    for (const PageJson& x : v) s += (s.empty() ? "" : ", ") + num(x);
    return "(" + s + ")";
  }
  return v.dump();
}

// j[key] if j is an object holding it, else null
const PageJson& at(const PageJson& j, const char* key) {
  static const PageJson kNull;
  if (!j.is_object()) return kNull;
  const auto it = j.find(key);
  return it == j.end() ? kNull : *it;
}

std::string td(const std::string& text, const std::string& cls = "") {
  return (cls.empty() ? "<td>" : "<td class=\"" + cls + "\">") +
         escape(text) + "</td>";
}
std::string th(const std::string& text) { return "<th>" + escape(text) + "</th>"; }

// a figure, or a note where it is missing. `id` names the figure on the page
// and prefixes every id inside its SVG; `file` is the same SVG's file
// relative to the report (the browser test draws it standalone and compares).
std::string figure(const std::string& svg, const std::string& caption,
                   const std::string& id, const std::string& file) {
  std::string s = "<figure id=\"fig-" + escape(id) + "\"" +
                  (file.empty() ? "" : " data-file=\"" + escape(file) + "\"") +
                  ">\n";
  const std::string active = active_content(svg);
  if (svg.empty()) {
    s += "<p class=\"note\">" + escape(caption) + ": not available</p>\n";
  } else if (!active.empty()) {
    s += "<p class=\"note\">" + escape(file.empty() ? caption : file) +
         ": not shown: it holds " + escape(active) +
         ", which this page does not carry</p>\n";
  } else {
    s += inline_svg(svg, id + "-");
  }
  return s + "<figcaption>" + escape(caption) + "</figcaption>\n</figure>\n";
}

// a CSV as a table; the first line is the header
std::string csv_table(const std::string& csv, const std::string& cls) {
  std::istringstream in(csv);
  std::string line, s = "<div class=\"scroll\"><table class=\"" + cls + "\">\n";
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    s += "<tr>";
    std::istringstream cells(line);
    std::string c;
    while (std::getline(cells, c, ',')) {
      if (header) {
        s += th(c);
      } else {
        // numbers shortened; text as it is
        char* end = nullptr;
        const double v = std::strtod(c.c_str(), &end);
        s += td(!c.empty() && end != nullptr && *end == '\0' ? num(PageJson(v)) : c);
      }
    }
    s += "</tr>\n";
    header = false;
  }
  return s + "</table></div>\n";
}

const char* const kStyle =
    "body{font-family:sans-serif;margin:1.5em auto;max-width:1600px;"
    "color:#222;padding:0 1em}p,li,details{max-width:62em}"
    "h1{font-size:1.6em}h2{border-bottom:2px solid #ccc;margin-top:2em}"
    "table{border-collapse:collapse;margin:0.5em 0;font-size:0.9em}"
    "td,th{border:1px solid #ccc;padding:2px 6px;text-align:left}"
    "th{background:#f2f2f2}td.pass{background:#e6f4e6}"
    "td.partial{background:#fdf1cf;color:#750}"
    "td.fail,tr.fail td{background:#fbd9d9;font-weight:bold;color:#900}"
    "span.fail{color:#900;font-weight:bold}span.pass{color:#060}"
    "p.note{color:#775;font-style:italic}div.scroll{overflow-x:auto}"
    "figure{margin:1em 0}figcaption{font-size:0.85em;color:#555}"
    "svg{max-width:100%;height:auto}img{max-width:100%}"
    "details{margin:0.5em 0}"
    "table.matrix td{font-size:0.85em}table.matrix td.none{background:#fafafa}"
    "table.matrix a{color:inherit}ul.sides{margin:0;padding-left:1.1em}"
    "ul.sides li.fail{color:#900;font-weight:bold}p.legend{font-size:0.85em;color:#555}"
    // print: no heading left at a page's foot, no table, figure or row split
    "@media print{body{max-width:none;margin:0}h1,h2,h3{break-after:avoid;"
    "page-break-after:avoid}table,figure,tr,img{break-inside:avoid;"
    "page-break-inside:avoid}section{break-before:auto}a{color:inherit;"
    "text-decoration:none}details{display:block}div.scroll{overflow:visible}}";

// the case's key parameters first, every one in a fold below
std::string parameters(const PageJson& summary) {
  const PageJson& params = at(summary, "parameters");
  std::string s = "<table class=\"params\">\n<tr>" + th("parameter") +
                  th("value") + th("unit") + th("source") + "</tr>\n";
  const char* const key[] = {"vm_kind",        "vm_pivot_mm",     "vm_length_mm",
                             "k_pos_N_per_mm", "k_ornt_multiple", "error",
                             "servo_period_s", "duration_s"};
  auto row = [&](const std::string& name, const PageJson& p) {
    return "<tr>" + td(name) + td(num(at(p, "value"))) +
           td(num(at(p, "unit"))) + td(num(at(p, "source"))) + "</tr>\n";
  };
  for (const char* k : key) {
    if (!at(params, k).is_null()) s += row(k, at(params, k));
  }
  const PageJson& phys = at(summary, "physics");
  s += "<tr>" + td("physics step_s, integrator") +
       td(num(at(phys, "step_s")) + ", " + num(at(phys, "integrator"))) +
       td("s") + td("scene") + "</tr>\n</table>\n";
  if (params.is_object()) {
    s += "<details><summary>every parameter</summary>\n<table class=\"params\">\n";
    // (parameters.hand repeats the hand's rows as a group: not a row itself)
    for (auto it = params.begin(); it != params.end(); ++it) {
      if (it->is_object() && it->contains("value")) s += row(it.key(), *it);
    }
    s += "</table></details>\n";
  }
  return s;
}

// "value comparison threshold unit (law: prediction, agrees)" in one cell
std::string measured_cell(const PageJson& c, const PageJson& side) {
  std::string v = num(at(side, "value")) + " " + num(at(c, "comparison")) +
                  " " + num(at(c, "threshold"));
  const PageJson& unit = at(c, "unit");
  if (unit.is_string() && !unit.get<std::string>().empty()) v += " " + num(unit);
  if (!at(side, "prediction").is_null()) {
    v += " (law: " + num(at(side, "prediction"));
    const PageJson& m = at(side, "matches_prediction");
    if (m.is_boolean()) v += m.get<bool>() ? ", agrees" : ", differs";
    v += ")";
  }
  return v;
}

// the verdict: pass, FAIL, or partial naming the sides where it fails
std::string verdict_text(const PageJson& c) {
  const PageJson& verdict = at(c, "pass");
  if (verdict.is_boolean()) return verdict.get<bool>() ? "pass" : "FAIL";
  std::string failing;
  for (const PageJson& side : at(c, "sides")) {
    const PageJson& p = at(side, "pass");
    if (p.is_boolean() && !p.get<bool>()) {
      failing += (failing.empty() ? "" : "; ") + num(at(side, "where"));
    }
  }
  return "partial: fails " + (failing.empty() ? std::string("on a side") : failing);
}

std::string verdict_class(const PageJson& c) {
  const PageJson& verdict = at(c, "pass");
  if (verdict.is_boolean()) return verdict.get<bool>() ? "pass" : "fail";
  return "partial";
}

std::string claim_anchor(const std::string& case_name, const PageJson& c) {
  return case_name + "-claim-" + num(at(c, "name"));
}

std::string claims_table(const std::string& case_name, const PageJson& summary) {
  std::string s = "<table class=\"claims\">\n<tr>" + th("claim") +
                  th("what the thesis says") + th("verdict") +
                  th("measured vs threshold (law's prediction)") +
                  th("each side: measured (prediction), verdict") +
                  th("regime") + th("window") + "</tr>\n";
  for (const PageJson& c : at(summary, "claims")) {
    const std::string cls = verdict_class(c);
    std::string sides;
    for (const PageJson& side : at(c, "sides")) {
      const PageJson& p = at(side, "pass");
      const bool ok = p.is_boolean() && p.get<bool>();
      sides += "<li" + std::string(ok ? "" : " class=\"fail\"") + ">" +
               escape(num(at(side, "where")) + ": " + measured_cell(c, side) +
                      (ok ? ", holds" : ", FAILS")) +
               "</li>";
    }
    s += std::string(cls == "fail" ? "<tr class=\"fail\"" : "<tr") + " id=\"" +
         escape(claim_anchor(case_name, c)) + "\">" + td(num(at(c, "name"))) +
         td(num(at(c, "statement"))) + td(verdict_text(c), cls) +
         td(measured_cell(c, c)) +
         "<td>" + (sides.empty() ? std::string("one side") : "<ul class=\"sides\">" + sides + "</ul>") +
         "</td>" + td(num(at(c, "regime"))) + td(num(at(c, "window"))) + "</tr>\n";
  }
  return s + "</table>\n";
}

std::string case_section(const ReportCase& c) {
  const PageJson& m = at(c.summary, "metrics");
  std::string s = "<section id=\"" + escape(c.name) + "\">\n<h2>" +
                  escape(c.name) + ": thesis case " +
                  escape(num(at(c.summary, "thesis_case"))) + "</h2>\n";
  s += "<p>" + escape("simulated " + num(at(c.summary, "simulated_s")) +
                      " s in " + num(at(c.summary, "wall_time_s")) +
                      " s wall; RMS distance from the path " +
                      num(at(m, "rms_path_error_mm")) + " mm (max " +
                      num(at(m, "max_path_error_mm")) + " mm); mean |F| " +
                      num(at(m, "mean_force_N")) + " N (max " +
                      num(at(m, "max_force_N")) + " N); scene " +
                      num(at(c.summary, "scene"))) + "</p>\n";
  s += "<h3>Parameters</h3>\n" + parameters(c.summary);
  s += "<h3>Claims</h3>\n" + claims_table(c.name, c.summary);
  s += "<h3>Figures</h3>\n";
  s += figure(c.force_field_svg,
              c.name + ": the commanded force along the RM wrist-centre "
              "trajectory (device frame, mm)",
              c.name + "-force-field", c.name + "/force_field.svg");
  s += figure(c.thesis_svg,
              c.name + ": theta_V and theta_R against time, and the RM "
              "wrist centre's trajectory in the mechanism's plane coloured by "
              "time (the thesis's figures)",
              c.name + "-thesis", c.name + "/thesis.svg");
  s += figure(c.views_svg, c.name + ": the RM off the path and on it "
                           "(device frame, mm)",
              c.name + "-views", c.name + "/views.svg");
  s += figure(c.history_svg, c.name + ": error and force against time",
              c.name + "-history", c.name + "/history.svg");
  s += "<figure>\n";
  if (c.render_png) {
    s += "<img alt=\"" + escape(c.name) + " render\" src=\"data:image/png;base64," +
         base64(*c.render_png) + "\"/>\n";
  } else {
    s += "<p class=\"note\">render unavailable: " +
         escape(c.render_note.empty() ? "no renderer" : c.render_note) + "</p>\n";
  }
  s += "<figcaption>" + escape(c.name) + ": the scene</figcaption>\n</figure>\n";
  return s + "</section>\n";
}

// error to the path against the run's cost, a row per case
std::string run_time_table(const std::vector<ReportCase>& cases) {
  std::string s = "<table class=\"runtime\">\n<tr>" + th("case") +
                  th("simulated_s") + th("wall_time_s") +
                  th("realtime_factor") + th("rms_path_error_mm") +
                  th("max_path_error_mm") + th("mean_force_N") +
                  th("claims passed") + "</tr>\n";
  for (const ReportCase& c : cases) {
    const PageJson& m = at(c.summary, "metrics");
    int pass = 0, total = 0, failed = 0;
    for (const PageJson& k : at(c.summary, "claims")) {
      ++total;
      pass += at(k, "pass").is_boolean() && at(k, "pass").get<bool>() ? 1 : 0;
      failed += at(k, "pass").is_boolean() && !at(k, "pass").get<bool>() ? 1 : 0;
    }
    s += std::string(failed == 0 ? "<tr>" : "<tr class=\"fail\">") +
         td(c.name) + td(num(at(c.summary, "simulated_s"))) +
         td(num(at(c.summary, "wall_time_s"))) +
         td(num(at(c.summary, "realtime_factor"))) +
         td(num(at(m, "rms_path_error_mm"))) +
         td(num(at(m, "max_path_error_mm"))) +
         td(num(at(m, "mean_force_N"))) +
         td(std::to_string(pass) + "/" + std::to_string(total)) + "</tr>\n";
  }
  return s + "</table>\n";
}

// what "pass" says for a scenario with this outcome
std::string pass_means(const std::string& outcome) {
  if (outcome == "ok") {
    return "finite, force and torques within their limits, energy bounded "
           "at rest, the expected status seen";
  }
  if (outcome == "limit_cycle") {
    return "finite and within the limits; the energy pumped in at rest is a "
           "known, documented limit cycle of this gain, not a fault: the "
           "device is not passive here";
  }
  if (outcome.rfind("fault_detected", 0) == 0) {
    return "the injected fault was detected (" + outcome.substr(15) +
           ") and the torque zeroed";
  }
  if (outcome.rfind("fault_undetected", 0) == 0) {
    return "a fault the device layer is known not to see (" +
           outcome.substr(17) + "): the run stayed finite and within the "
           "limits, nothing more; a documented blind spot, not a safety claim";
  }
  return "failed: " + outcome;
}

std::string extremes_table(const PageJson& ex) {
  std::string s = "<table class=\"extremes\">\n<tr>" + th("scenario") +
                  th("stresses") + th("outcome") + th("pass") +
                  th("what pass means here") +
                  th("max_force_N") + th("force_limit_N") +
                  th("energy motor_max_J") + th("energy rest_rise_J") +
                  th("wall_time_s") + "</tr>\n";
  for (const PageJson& r : at(ex, "scenarios")) {
    const bool pass = at(r, "pass").is_boolean() && at(r, "pass").get<bool>();
    const PageJson& e = at(r, "energy");
    s += std::string(pass ? "<tr>" : "<tr class=\"fail\">") +
         td(num(at(r, "name"))) + td(num(at(r, "stresses"))) +
         td(num(at(r, "outcome"))) +
         td(pass ? "pass" : "FAIL", pass ? "pass" : "fail") +
         td(pass_means(num(at(r, "outcome")))) +
         td(num(at(r, "max_force_N"))) + td(num(at(r, "force_limit_N"))) +
         td(num(at(e, "motor_max_J"))) + td(num(at(e, "rest_rise_J"))) +
         td(num(at(r, "wall_time_s"))) + "</tr>\n";
  }
  return s + "</table>\n";
}

std::string list_text(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "none" : s;
}

}  // namespace

ReportCase load_report_case(const std::string& dir, const std::string& name,
                            const RenderFn& render) {
  namespace fs = std::filesystem;
  auto read_text = [](const fs::path& p) { return read_file_text(p.string()); };
  ReportCase c;
  c.name = name;
  const fs::path d = fs::path(dir) / name;
  try {
    c.summary = nlohmann::json::parse(read_text(d / "summary.json"));
  } catch (const std::exception& e) {
    throw std::runtime_error((d / "summary.json").string() + ": " + e.what());
  }
  c.views_svg = read_text(d / "views.svg");
  c.history_svg = read_text(d / "history.svg");
  ForceFieldPath path;
  try {
    const nlohmann::json& p = c.summary.at("parameters");
    path.vm_kind = p.at("vm_kind").at("value").get<std::string>();
    const auto pivot = p.at("vm_pivot_mm").at("value").get<std::vector<double>>();
    for (std::size_t i = 0; i < 3 && i < pivot.size(); ++i) path.pivot_mm[i] = pivot[i];
    path.length_mm = p.at("vm_length_mm").at("value").get<double>();
    if (find_vm(path.vm_kind) == nullptr) {
      throw std::runtime_error((d / "summary.json").string() +
                               ": the VM's parameters: unknown vm_kind '" +
                               path.vm_kind + "' (expected one of: " +
                               vm_kind_names() + ")");
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error((d / "summary.json").string() +
                             ": the VM's parameters: " + e.what());
  }
  try {
    const std::string trace = read_text(d / "trace.csv");
    c.force_field_svg = force_field_svg(force_samples_from_csv(trace), path);
    c.thesis_svg = thesis_svg(thesis_samples_from_csv(trace), path);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error((d / "trace.csv").string() + ": " + e.what());
  }
  std::string why;
  if (render) {
    c.render_png = render(name, c.summary.value("scene", ""), &why);
  } else {
    why = "no renderer in this build";
  }
  if (!c.render_png) c.render_note = why.empty() ? "the renderer gave none" : why;
  return c;
}

ClaimTally tally_claims(const std::vector<ReportCase>& cases) {
  ClaimTally t;
  for (const ReportCase& c : cases) {
    for (const PageJson& k : at(c.summary, "claims")) {
      ++t.total;
      const PageJson& v = at(k, "pass");
      if (v.is_boolean() && v.get<bool>()) {
        ++t.passed;
      } else if (v.is_string() && v.get<std::string>() == "partial") {
        t.partial.push_back(c.name + ":" + num(at(k, "name")));
      } else {
        t.failed.push_back(c.name + ":" + num(at(k, "name")));
      }
    }
  }
  return t;
}

namespace {

// rows: every claim (in the order first met), columns: the cases; a cell
// is the claim's verdict in that case, linked to its row, or blank where
// the case does not make that claim
std::string claim_matrix(const std::vector<ReportCase>& cases) {
  std::vector<std::string> names;
  for (const ReportCase& c : cases) {
    for (const PageJson& k : at(c.summary, "claims")) {
      const std::string n = num(at(k, "name"));
      if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
    }
  }
  std::string s = "<table class=\"matrix\">\n<tr>" + th("claim");
  for (const ReportCase& c : cases) {
    s += "<th><a href=\"#" + escape(c.name) + "\">" + escape(c.name) + "</a></th>";
  }
  s += "</tr>\n";
  for (const std::string& n : names) {
    s += "<tr>" + td(n);
    for (const ReportCase& c : cases) {
      const PageJson* claim = nullptr;
      for (const PageJson& k : at(c.summary, "claims")) {
        if (num(at(k, "name")) == n) claim = &k;
      }
      if (claim == nullptr) {
        s += "<td class=\"none\"></td>";
        continue;
      }
      s += "<td class=\"" + verdict_class(*claim) + "\"><a href=\"#" +
           escape(claim_anchor(c.name, *claim)) + "\">" +
           escape(verdict_text(*claim)) + "</a></td>";
    }
    s += "</tr>\n";
  }
  return s + "</table>\n";
}

// The line under the title: how many claims passed, and those that fail
// or hold on some sides only.
std::string claims_summary(const ClaimTally& tally) {
  const bool all_pass = tally.failed.empty();
  return std::string("<p id=\"summary\" class=\"summary\">Claims passed: ") +
         "<span class=\"" + (all_pass ? "pass" : "fail") + "\">" +
         std::to_string(tally.passed) + "/" + std::to_string(tally.total) +
         "</span>" +
         (all_pass ? std::string()
                   : " &#8212; failing: <span class=\"fail\">" +
                         escape(list_text(tally.failed)) + "</span>") +
         (tally.partial.empty()
              ? std::string()
              : " &#8212; holding on some sides only (the cell names the side "
                "where it fails): " + escape(list_text(tally.partial))) +
         "</p>\n";
}

// The two overviews: which claims hold in which case (claim_matrix), and
// each case's accuracy and run time, each with its legend.
std::string overview_sections(const std::vector<ReportCase>& cases) {
  std::string s =
      "<section id=\"matrix\">\n<h2>Which claims hold, in which case</h2>\n" +
      claim_matrix(cases) +
      "<p class=\"legend\">pass: holds on every side it is measured on; "
      "partial: holds on some, the cell names where it fails; FAIL: fails "
      "on every side; blank: the case makes no such claim. Each cell links "
      "to the claim's row with every side's value.</p>\n</section>\n";
  s += "<section id=\"runtime\">\n<h2>Accuracy and run time, per case</h2>\n" +
       run_time_table(cases) +
       "<p class=\"legend\">rms and max path error: the RM wrist centre's "
       "distance from the VM's path after the first second (mm); mean_force_N: "
       "the commanded |F|; realtime_factor: simulated over wall seconds on "
       "this machine.</p>\n</section>\n";
  return s;
}

// The page's contents: each case, the three studies, the page's making.
std::string contents_list(const std::vector<ReportCase>& cases) {
  std::string s = "<ul class=\"contents\">\n";
  for (const ReportCase& c : cases) {
    s += "<li><a href=\"#" + escape(c.name) + "\">" + escape(c.name) + "</a></li>\n";
  }
  s += "<li><a href=\"#precision\">work-precision</a></li>\n"
       "<li><a href=\"#stability\">stability map</a></li>\n"
       "<li><a href=\"#extremes\">extreme scenarios</a></li>\n"
       "<li><a href=\"#about\">how this page was made</a></li>\n</ul>\n";
  return s;
}

// The precision study: error against wall time, error against h, and every
// run's row folded away.
std::string precision_section(const ReportStudies& st) {
  const std::string name =
      st.precision_case.empty() ? "not run" : st.precision_case;
  std::string s = "<section id=\"precision\">\n<h2>Work-precision (" +
                  escape(name) + ")</h2>\n";
  s += figure(st.precision_svg, "trajectory error (RMS, mm) against wall "
                                "time (s), per integrator and physics step",
              "precision", "study/precision.svg");
  s += figure(st.precision_order_svg, "trajectory error against the physics "
                                      "step h, with the fitted orders",
              "precision-order", "study/precision_order.svg");
  if (!st.precision_csv.empty()) {
    s += "<details><summary>every run (precision.csv)</summary>\n" +
         csv_table(st.precision_csv, "precision") + "</details>\n";
  }
  return s + "</section>\n";
}

// The stability map: its setting, the figure and the table folded away.
std::string stability_section(const ReportStudies& st) {
  std::string s = "<section id=\"stability\">\n<h2>Stability map of the "
                  "sampled-data wall</h2>\n<p>" +
                  escape(st.stability_note) + "</p>\n";
  s += figure(st.stability_map_svg, "K_crit (N/m) against the virtual "
                                    "damping B (N s/m), per delay",
              "stability-map", "study/stability_map.svg");
  if (!st.stability_map_csv.empty()) {
    s += "<details><summary>the map (stability_map.csv)</summary>\n" +
         csv_table(st.stability_map_csv, "stability") + "</details>\n";
  }
  return s + "</section>\n";
}

// The extreme scenarios: their table (or "not run") and the observer's
// energy.
std::string extremes_section(const ReportStudies& st) {
  std::string s = "<section id=\"extremes\">\n<h2>Extreme scenarios</h2>\n";
  if (st.extremes.is_null()) {
    s += "<p class=\"note\">not run</p>\n";
  } else {
    s += extremes_table(st.extremes);
  }
  s += figure(st.extremes_svg, "the passivity observer's energy per scenario (mJ)",
              "extremes", "study/extremes.svg");
  return s + "</section>\n";
}

// How the page was made: the software, where and when, what ran and what
// was reused.
std::string about_section(const ReportHeader& h) {
  std::string s = "<section id=\"about\">\n<h2>How this page was made</h2>\n";
  s += "<table class=\"header\">\n";
  s += "<tr>" + th("software") + td("vmhaptics " + h.version) + "</tr>\n";
  s += "<tr>" + th("git describe (at configure time)") + td(h.git_describe) + "</tr>\n";
  s += "<tr>" + th("generated (UTC)") + td(h.generated_utc) + "</tr>\n";
  s += "<tr>" + th("command line") + td(h.command_line) + "</tr>\n";
  s += "<tr>" + th("cores") + td(std::to_string(h.cores)) + "</tr>\n";
  s += "<tr>" + th("wall time (s)") + td(num(PageJson(h.wall_s))) + "</tr>\n";
  s += "<tr>" + th("ran") + td(list_text(h.ran)) + "</tr>\n";
  s += "<tr>" + th("reused from disk") + td(list_text(h.reused)) + "</tr>\n";
  return s + "</table>\n</section>\n";
}

}  // namespace

std::string report_html(const ReportInputs& in) {
  const ClaimTally tally = tally_claims(in.cases);
  std::string s =
      "<!DOCTYPE html>\n<html xmlns=\"http://www.w3.org/1999/xhtml\" "
      "lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n"
      "<title>vmhaptics report</title>\n<style>" +
      std::string(kStyle) + "</style>\n</head>\n<body>\n";
  s += "<h1>vmhaptics: virtual-mechanism control of the PHANTOM Omni, the "
       "thesis's cases measured</h1>\n";
  s += claims_summary(tally);
  s += overview_sections(in.cases);
  s += contents_list(in.cases);
  for (const ReportCase& c : in.cases) s += case_section(c);
  s += precision_section(in.studies);
  s += stability_section(in.studies);
  s += extremes_section(in.studies);
  s += about_section(in.header);
  s += "<p class=\"summary\">Claims passed: " + std::to_string(tally.passed) +
       "/" + std::to_string(tally.total) + "</p>\n</body>\n</html>\n";
  return s;
}

}  // namespace vmh::thesis
