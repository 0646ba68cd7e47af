#include "bringup/compare_kinematics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"
#include "output/output_file.h"
#include "output/svg_chart.h"

namespace vmh::bringup {
namespace {

using constants::kPi;
constexpr double kRadToDeg = 180.0 / kPi;
// a hypothesis other than the identity must beat it by this factor
constexpr double kClearlyBetter = 3.0;
// what the fit must find before a parameter is named (header comment)
constexpr double kLinkRelative = 0.0075;
constexpr double kJointOffsetRad = 0.005;
constexpr double kGimbalScaleRelative = 0.02;
constexpr double kBaseOffsetMm = 0.5;
constexpr double kSigmas = 3.0;
constexpr std::size_t kHypothesisSamples = 400;
// a right map converges in a handful of steps (4-6 on the synthetic
// recordings); a wrong one is not worth polishing
constexpr int kHypothesisIterations = 15;

std::string kin_fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[200];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

nlohmann::ordered_json stats_json(const ErrorStats& s) {
  return {{"mean", s.mean}, {"rms", s.rms}, {"p95", s.p95}, {"max", s.max},
          {"count", s.count}};
}

nlohmann::ordered_json fit_json(const GeometryFit& f) {
  nlohmann::ordered_json params = nlohmann::ordered_json::array();
  for (const FittedParam& p : f.params) {
    params.push_back({{"name", p.name}, {"nominal", p.nominal}, {"fitted", p.fitted},
                      {"sigma", p.sigma}, {"unit", p.unit}, {"free", p.free}});
  }
  nlohmann::ordered_json C = nlohmann::ordered_json::array();
  for (int r = 0; r < 3; ++r) C.push_back({f.convention(r, 0), f.convention(r, 1),
                                           f.convention(r, 2)});
  return {{"parameters", params},
          {"position_error_before_mm", stats_json(f.position_before_mm)},
          {"position_error_after_mm", stats_json(f.position_after_mm)},
          {"rotation_error_before_deg", stats_json(f.rotation_before_deg)},
          {"rotation_error_after_deg", stats_json(f.rotation_after_deg)},
          {"rotation_convention", C},
          {"rotation_convention_signed_permutation", f.convention_snapped},
          {"samples_used", f.samples_used},
          {"iterations", f.iterations},
          {"plausible", f.plausible},
          {"explains", f.explains}};
}

// An implausible fit (a sign taken up as a pot gain of -1) explains
// nothing: it is scored at the nominal geometry instead
double normalized_p95(const GeometryFit& f) {
  const ErrorStats& p = f.plausible ? f.position_after_mm : f.position_before_mm;
  const ErrorStats& r = f.plausible ? f.rotation_after_deg : f.rotation_before_deg;
  return std::max(p.p95 / kPositionErrorP95ThresholdMm,
                  r.p95 / kStylusAxisErrorP95ThresholdDeg);
}

GeometryFitOptions fit_options(std::size_t max_samples) {
  GeometryFitOptions o;
  o.max_samples = max_samples;
  o.position_threshold_mm = kPositionErrorP95ThresholdMm;
  o.rotation_threshold_deg = kStylusAxisErrorP95ThresholdDeg;
  return o;
}

// The parameters the fit singles out, as compare's fault names with their
// evidence (header comment: link lengths first, then offsets and scales)
std::vector<SuspectedFault> geometry_faults(const GeometryFit& f) {
  std::vector<SuspectedFault> out;
  auto significant = [](const FittedParam& p, double floor) {
    const double d = std::abs(p.fitted - p.nominal);
    return p.free && d > floor && d > kSigmas * p.sigma;
  };
  for (int i : {kL1, kL2}) {
    const FittedParam& p = f.params[i];
    if (!significant(p, kLinkRelative * p.nominal)) continue;
    const double pct = 100.0 * (p.fitted / p.nominal - 1.0);
    out.push_back({"link_length_" + std::to_string(static_cast<int>(std::lround(pct))) + "pct",
                   p.name + kin_fmt(" fitted %.2f mm (nominal %.2f, sigma %.3f mm)", p.fitted,
                                p.nominal, p.sigma) + kin_fmt(", %+.2f %%", pct),
                   {}});
  }
  if (!out.empty()) return out;
  for (int i = 0; i < 6; ++i) {
    const FittedParam& p = f.params[kOffsetT1 + i];
    if (!significant(p, kJointOffsetRad)) continue;
    out.push_back({"joint" + std::to_string(i + 1) + "_offset",
                   p.name + kin_fmt(" fitted %.4f rad (sigma %.4f rad)", p.fitted, p.sigma), {}});
  }
  for (int i = 0; i < 3; ++i) {
    const FittedParam& p = f.params[kScaleT4 + i];
    if (!significant(p, kGimbalScaleRelative)) continue;
    out.push_back({"joint" + std::to_string(i + 4) + "_scale",
                   p.name + kin_fmt(" fitted %.4f (sigma %.4f)", p.fitted, p.sigma), {}});
  }
  Vec3 b, sb;
  for (int k = 0; k < 3; ++k) {
    b[k] = f.params[kBaseX + k].fitted;
    sb[k] = f.params[kBaseX + k].sigma;
  }
  if (b.norm() > kBaseOffsetMm && b.norm() > kSigmas * sb.norm()) {
    out.push_back({"base_offset", kin_fmt("base offset fitted (%.2f, %.2f, %.2f) mm, device frame",
                                      b[0], b[1], b[2]), {}});
  }
  return out;
}

// compare_kinematics' four checks, in the order they are reported
constexpr const char* kKinematicsChecks[] = {
    "kinematics.position_error_p95", "kinematics.position_error_max",
    "kinematics.stylus_axis_error_p95", "kinematics.rotation_error_p95"};

// The good rows with a device transform, and at each the project's FK of
// the recorded angles against it: the wrist centre's error (mm), the
// model's stylus axis and the device's rotation (device frame)
struct KinematicsSamples {
  std::vector<std::size_t> rows;
  std::vector<double> t_s, pos_err_mm;
  std::vector<Vec3> axis_model;
  std::vector<Mat3> R_dev;
};

KinematicsSamples kinematics_samples(const Recording& rec) {
  const OmniParams params;
  KinematicsSamples k;
  for (std::size_t r : rec.good_rows()) {
    const Vec3 p_dev = rec.dev_p_mm(r);
    const Mat3 R = rec.dev_R(r);
    if (!p_dev.allFinite() || !R.allFinite()) continue;
    const OmniPose pose = omni_fk(params, rec.q_dh_rad(r));
    k.rows.push_back(r);
    k.t_s.push_back(rec.t_s(r));
    k.pos_err_mm.push_back(
        (base_to_device_mm(params, pose.p_base_m) - p_dev).norm());
    k.axis_model.push_back(base_to_device_vector(pose.R_base.col(2)));
    k.R_dev.push_back(R);
  }
  return k;
}

// the angle (deg) between the model's stylus axis and the device
// rotation's column col times sign, at each sample
std::vector<double> axis_errors(const KinematicsSamples& k, int col,
                                double sign) {
  std::vector<double> e;
  for (std::size_t i = 0; i < k.rows.size(); ++i) {
    const double c =
        std::clamp(k.axis_model[i].dot(sign * k.R_dev[i].col(col).normalized()),
                   -1.0, 1.0);
    e.push_back(std::acos(c) * kRadToDeg);
  }
  return e;
}

// The device's column (and sign) that is the stylus axis: the best median
struct StylusColumn {
  int col = 2;
  double sign = 1.0;
};

StylusColumn stylus_column(const KinematicsSamples& k) {
  StylusColumn best;
  double best_median = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 3; ++c) {
    for (double s : {1.0, -1.0}) {
      std::vector<double> e = axis_errors(k, c, s);
      std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
      if (e[e.size() / 2] < best_median) {
        best_median = e[e.size() / 2];
        best.col = c;
        best.sign = s;
      }
    }
  }
  return best;
}

// The four checks: the wrist centre's p95 and worst error, the stylus
// axis's p95 against the device rotation's column col_text, and the whole
// stylus frame's p95 (the axis alone does not see t6), through the
// device's rotation convention fitted at the nominal geometry
void add_kinematics_checks(const ErrorStats& pos, const ErrorStats& axis,
                           const std::string& col_text,
                           const GeometryFit& nominal_fit,
                           const std::string& dir, CompareSection* sec) {
  sec->checks.push_back(
      make_check(kKinematicsChecks[0], pos.p95, kPositionErrorP95ThresholdMm,
                 "mm", CompareCheck::kAtMost,
                 "project FK vs the device's wrist centre, p95 over " +
                     std::to_string(pos.count) + " samples"));
  sec->checks.push_back(
      make_check(kKinematicsChecks[1], pos.max, kPositionErrorMaxThresholdMm,
                 "mm", CompareCheck::kAtMost,
                 "project FK vs the device's wrist centre, worst sample"));
  sec->checks.push_back(
      make_check(kKinematicsChecks[2], axis.p95,
                 kStylusAxisErrorP95ThresholdDeg, "deg", CompareCheck::kAtMost,
                 "project stylus axis vs the device rotation's " + col_text));
  sec->checks.push_back(
      make_check(kKinematicsChecks[3], nominal_fit.rotation_before_deg.p95,
                 kStylusAxisErrorP95ThresholdDeg, "deg", CompareCheck::kAtMost,
                 "project stylus frame (times the device's fixed convention) "
                 "vs the device rotation, "
                 "p95 over " +
                     std::to_string(nominal_fit.samples_used) + " samples"));
  for (CompareCheck& c : sec->checks) c.recording = dir;
}

// the five samples with the largest position error, worst first
nlohmann::ordered_json worst_samples(const Recording& rec,
                                     const KinematicsSamples& k,
                                     const std::vector<double>& axis_err_deg) {
  const std::vector<double>& pos_err_mm = k.pos_err_mm;
  std::vector<std::size_t> order(k.rows.size());
  std::iota(order.begin(), order.end(), 0);
  const std::size_t n_worst = std::min<std::size_t>(5, order.size());
  std::partial_sort(order.begin(), order.begin() + n_worst, order.end(),
                    [&](std::size_t a, std::size_t b) {
                      return pos_err_mm[a] > pos_err_mm[b];
                    });
  nlohmann::ordered_json worst = nlohmann::ordered_json::array();
  for (std::size_t j = 0; j < n_worst; ++j) {
    const std::size_t i = order[j];
    const Joints q = rec.q_dh_rad(k.rows[i]);
    worst.push_back({{"t_s", k.t_s[i]},
                     {"q_dh_rad", std::vector<double>(q.data(), q.data() + 6)},
                     {"position_error_mm", pos_err_mm[i]},
                     {"stylus_axis_error_deg", axis_err_deg[i]}});
  }
  return worst;
}

// the reading map chosen, with its evidence and every hypothesis's figures
nlohmann::ordered_json readings_json(const ReadingDiagnosis& diag) {
  nlohmann::ordered_json hyps = nlohmann::ordered_json::array();
  for (const ReadingHypothesis& h : diag.hypotheses) {
    hyps.push_back(
        {{"map", h.map.is_identity() ? "identity" : h.map.name},
         {"perm", h.map.perm},
         {"sign", h.map.sign},
         {"position_p95_after_fit_mm", h.fit.position_after_mm.p95},
         {"rotation_p95_after_fit_deg", h.fit.rotation_after_deg.p95},
         {"normalized_p95", h.normalized_p95},
         {"iterations", h.fit.iterations},
         {"explains", h.fit.explains}});
  }
  return {{"map", diag.map.is_identity() ? "identity" : diag.map.name},
          {"perm", diag.map.perm},
          {"sign", diag.map.sign},
          {"evidence", diag.evidence},
          {"hypotheses", hyps}};
}

// What a failed check points to: the reading map found, else the
// geometry the fit singles out when it explains the transform, else
// kinematics_unexplained with the figures
void name_kinematics_faults(const ReadingDiagnosis& diag,
                            const GeometryFit& fit, const ErrorStats& pos,
                            const ErrorStats& axis, const std::string& dir,
                            CompareSection* sec) {
  if (!diag.map.is_identity()) {
    sec->faults.push_back({diag.map.name, diag.evidence, {}});
  } else if (fit.explains) {
    sec->faults = geometry_faults(fit);
  }
  if (sec->faults.empty()) {
    sec->faults.push_back(
        {"kinematics_unexplained",
         kin_fmt("position p95 %.2f mm, stylus axis p95 %.2f deg; after the "
                 "geometry fit "
                 "%.2f mm",
                 pos.p95, axis.p95, fit.position_after_mm.p95) +
             kin_fmt(", %.2f deg: no reading map or geometry explains it",
                     fit.rotation_after_deg.p95),
         {}});
  }
  for (SuspectedFault& f : sec->faults) f.recording = dir;
}

// a panel of the kinematics figure: an error over time, with its p95
// threshold as a dashed line
output::Chart error_panel(const std::string& y_label, const std::string& name,
                          const std::vector<double>& t_s,
                          const std::vector<double>& error, double threshold) {
  output::Chart c;
  c.x.label = "time (s)";
  c.y.label = y_label;
  c.series.push_back({name, t_s, error, "", true, false, false});
  c.series.push_back({"p95 threshold",
                      {t_s.front(), t_s.back()},
                      {threshold, threshold},
                      "#999999",
                      true,
                      false,
                      true});
  return c;
}

// kinematics_error.svg: the wrist centre's and the stylus axis's error
// over time, each with its p95 threshold
void write_kinematics_figure(const Recording& rec, const std::string& col_text,
                             const std::vector<double>& t_s,
                             const std::vector<double>& pos_err_mm,
                             const std::vector<double>& axis_err_deg,
                             const std::string& figure_dir,
                             CompareSection* sec) {
  output::ChartGrid g;
  g.title = "Project FK vs the device's transform";
  g.notes = {"recording " + rec.dir,
             "device frame; stylus axis vs the device's " + col_text};
  g.panels = {error_panel("wrist position error (mm)", "|p_FK - dev_p|", t_s,
                          pos_err_mm, kPositionErrorP95ThresholdMm),
              error_panel("stylus axis error (deg)", "angle(z_FK, dev axis)",
                          t_s, axis_err_deg, kStylusAxisErrorP95ThresholdDeg)};
  sec->figures.push_back(output::write_file_in(
      figure_dir, "kinematics_error.svg", output::chart_grid_svg(g)));
}

}  // namespace

std::vector<ReadingMap> reading_hypotheses() {
  std::vector<ReadingMap> out(1);
  for (int i = 0; i < 6; ++i) {
    ReadingMap m;
    m.sign[i] = -1.0;
    m.name = "joint" + std::to_string(i + 1) + "_sign";
    out.push_back(m);
  }
  for (auto [a, b] : {std::pair{3, 4}, std::pair{3, 5}, std::pair{4, 5}}) {
    ReadingMap m;
    std::swap(m.perm[a], m.perm[b]);
    m.name = "gimbal_swap";
    out.push_back(m);
  }
  return out;
}

std::vector<PoseSample> pose_samples(const Recording& rec, const ReadingMap& map,
                                     std::size_t max_samples) {
  if (!rec.has_transform()) {
    throw RecordingError(rec.dir + "/trace.csv: no device transform (dev_p_*_mm, dev_R_rc)");
  }
  std::vector<std::size_t> rows = rec.good_rows();
  if (max_samples > 0 && rows.size() > max_samples) {
    std::vector<std::size_t> every;
    for (std::size_t k = 0; k < max_samples; ++k) every.push_back(rows[k * rows.size() / max_samples]);
    rows = every;
  }
  std::vector<PoseSample> out;
  for (std::size_t r : rows) {
    PoseSample s;
    s.t_reported_device_rad = map.true_from_reported(dh_to_device_joints(rec.q_dh_rad(r)));
    s.p_device_mm = rec.dev_p_mm(r);
    s.R_device = rec.dev_R(r);
    if (s.p_device_mm.allFinite() && s.R_device.allFinite()) out.push_back(s);
  }
  return out;
}

ReadingDiagnosis diagnose_readings(const Recording& rec) {
  ReadingDiagnosis d;
  if (!rec.has_transform()) {
    d.evidence = "no device transform in the recording: readings taken as they are";
    return d;
  }
  GeometryFitOptions o = fit_options(kHypothesisSamples);
  o.max_iterations = kHypothesisIterations;
  for (const ReadingMap& m : reading_hypotheses()) {
    ReadingHypothesis h;
    h.map = m;
    h.fit = fit_geometry(pose_samples(rec, m, kHypothesisSamples), o);
    h.normalized_p95 = normalized_p95(h.fit);
    d.hypotheses.push_back(h);
  }
  const ReadingHypothesis& id = d.hypotheses.front();
  const ReadingHypothesis* best = &id;
  for (const ReadingHypothesis& h : d.hypotheses) {
    if (&h == &id || !h.fit.explains) continue;
    if (h.normalized_p95 * kClearlyBetter < id.normalized_p95 &&
        h.normalized_p95 < best->normalized_p95) {
      best = &h;
    }
  }
  d.map = best->map;
  d.evidence = "identity: position p95 " + kin_fmt("%.2f mm, rotation p95 %.2f deg after the fit",
                                               id.fit.position_after_mm.p95,
                                               id.fit.rotation_after_deg.p95);
  if (best != &id) {
    d.evidence += "; " + best->map.name +
                  kin_fmt(": %.2f mm, %.2f deg (%.0fx lower)", best->fit.position_after_mm.p95,
                      best->fit.rotation_after_deg.p95,
                      id.normalized_p95 / std::max(best->normalized_p95, 1e-12));
  }
  return d;
}

CompareSection compare_kinematics(const Recording& rec,
                                  const std::string& figure_dir) {
  CompareSection sec;
  sec.name = "kinematics";
  if (!rec.has_transform()) {
    for (const char* c : kKinematicsChecks) {
      sec.skipped.push_back(
          {c, "the recording has no device transform (dev_p_*_mm, dev_R_rc)",
           rec.dir});
    }
    return sec;
  }
  const KinematicsSamples k = kinematics_samples(rec);
  if (k.rows.size() < 20) {
    for (const char* c : kKinematicsChecks) {
      sec.skipped.push_back(
          {c,
           std::to_string(k.rows.size()) +
               " good rows with a device transform, at least 20 needed",
           rec.dir});
    }
    return sec;
  }
  const StylusColumn column = stylus_column(k);
  const std::vector<double> axis_err_deg =
      axis_errors(k, column.col, column.sign);
  const ErrorStats pos = error_stats(k.pos_err_mm);
  const ErrorStats axis = error_stats(axis_err_deg);
  const std::string col_text = std::string(column.sign > 0 ? "+" : "-") +
                               "column " + std::to_string(column.col + 1);
  const ReadingDiagnosis diag = diagnose_readings(rec);
  add_kinematics_checks(pos, axis, col_text, diag.hypotheses.front().fit,
                        rec.dir, &sec);

  const std::size_t fit_samples = GeometryFitOptions{}.max_samples;
  const GeometryFit fit = fit_geometry(pose_samples(rec, diag.map, fit_samples),
                                       fit_options(fit_samples));
  sec.detail["samples"] = k.rows.size();
  sec.detail["position_error_mm"] = stats_json(pos);
  sec.detail["stylus_axis_error_deg"] = stats_json(axis);
  sec.detail["worst_samples"] = worst_samples(rec, k, axis_err_deg);
  sec.detail["rotation_column"] = {
      {"column", column.col + 1}, {"sign", column.sign}, {"text", col_text}};
  sec.detail["readings"] = readings_json(diag);
  sec.detail["geometry_fit"] = fit_json(fit);
  sec.detail["geometry_fit"]["readings_map"] =
      diag.map.is_identity() ? "identity" : diag.map.name;

  const bool failed =
      std::any_of(sec.checks.begin(), sec.checks.end(),
                  [](const CompareCheck& c) { return !c.pass; });
  if (failed) name_kinematics_faults(diag, fit, pos, axis, rec.dir, &sec);
  if (!figure_dir.empty()) {
    write_kinematics_figure(rec, col_text, k.t_s, k.pos_err_mm, axis_err_deg,
                            figure_dir, &sec);
  }
  return sec;
}

}  // namespace vmh::bringup
