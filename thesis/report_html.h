// `vmhaptics report`'s page: one self-contained HTML document (XHTML-style
// markup, every element closed) with the thesis's figures for each case,
// every measured claim, and the numerical studies. SVG figures are inlined,
// PNG renders embedded as base64 data: URIs; nothing outside the file is
// referenced, so it can be mailed or archived as it is.
//
// The writer takes what the runs left on disk (summary.json, the SVGs, the
// studies' CSVs and JSON) as text, so that a report can be made from runs
// finished earlier (--reuse) as well as from fresh ones.
#ifndef VMHAPTICS_THESIS_REPORT_HTML_H_
#define VMHAPTICS_THESIS_REPORT_HTML_H_

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "thesis/html_parts.h"

namespace vmh::thesis {

// A render of a case's scene as PNG file bytes, or nullopt with *why_not
// saying why there is none (no GL, no renderer built, ...).
using RenderFn = std::function<std::optional<std::string>(
    const std::string& case_name, const std::string& scene_path,
    std::string* why_not)>;

struct ReportHeader {
  std::string version;       // VMH_VERSION
  std::string git_describe;  // when the build was configured, or "unknown"
  std::string generated_utc;  // ISO 8601
  std::string command_line;
  int cores = 0;
  double wall_s = 0.0;        // the whole job
  std::vector<std::string> reused, ran;  // what came from disk, what ran
};

// One case's outputs (run_case's files, docs/outputs.md "run"). An empty
// SVG is shown as missing.
struct ReportCase {
  std::string name;
  nlohmann::json summary;  // summary.json
  std::string force_field_svg, views_svg, history_svg;
  std::string thesis_svg;  // theta_V, theta_R against time; the trajectory
  std::optional<std::string> render_png;  // PNG bytes
  std::string render_note;                // why there is no render
};

// The studies' outputs; an empty text is shown as "not run".
struct ReportStudies {
  std::string precision_case;  // the case the precision study ran on
  std::string precision_csv, precision_svg, precision_order_svg;
  std::string stability_note;  // the map's setting, in words
  std::string stability_map_csv, stability_map_svg;
  nlohmann::json extremes;  // extremes.json; null: not run
  std::string extremes_svg;
};

struct ReportInputs {
  ReportHeader header;
  std::vector<ReportCase> cases;
  ReportStudies studies;
};

// One case from the files run_case wrote under dir/<name>/: summary.json,
// views.svg and history.svg as they are, the force field drawn from
// trace.csv and the case's VM parameters, and the render if `render` gives
// one (empty `render`: a note says there is no renderer). Throws
// std::runtime_error naming the file that is missing or unreadable.
ReportCase load_report_case(const std::string& dir, const std::string& name,
                            const RenderFn& render);

// claims over every case's summary.json
struct ClaimTally {
  int passed = 0;
  int total = 0;
  std::vector<std::string> failed;  // "case:claim"
  // held on some sides only (of the pivot, or far off the path and not near
  // it; "pass": "partial"), "case:claim";
  // counted in total, neither passed nor failed
  std::vector<std::string> partial;
};
ClaimTally tally_claims(const std::vector<ReportCase>& cases);

// the page
std::string report_html(const ReportInputs& in);

}  // namespace vmh::thesis

#endif  // VMHAPTICS_THESIS_REPORT_HTML_H_
