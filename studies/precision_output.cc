// The work-precision study's outputs: the JSON the command line prints (keys
// in the order a reader meets them), the CSV and the charts, and the files
// under the output folder.
#include <cmath>
#include <string>

#include "output/output_file.h"
#include "output/svg_chart.h"
#include "studies/precision_study.h"

namespace vmh::studies {
namespace {

using Json = nlohmann::ordered_json;

// NaN (a run that blew up) as JSON null
Json number_or_null(double x) { return std::isfinite(x) ? Json(x) : Json(); }

Json error_json(const TrajectoryError& e) {
  return {{"rms_error_mm", number_or_null(e.rms_mm)},
          {"max_error_mm", number_or_null(e.max_mm)},
          {"rms_axis_error_rad", number_or_null(e.rms_axis_rad)},
          {"max_axis_error_rad", number_or_null(e.max_axis_rad)},
          {"rms_torque_diff_mNm", number_or_null(e.rms_torque_mNm)},
          {"status_mismatch_ticks", e.status_mismatch_ticks},
          {"iteration_mismatch_ticks", e.iteration_mismatch_ticks},
          {"finite", e.finite}};
}

Json row_json(const PrecisionRow& row) {
  Json j = {{"integrator", integrator_name(row.integrator)},
            {"h_s", row.step_s},
            {"substeps_per_tick", row.substeps}};
  j.update(error_json(row.error));
  j.update(Json{{"wall_time_s", row.wall_time_s},
                {"cpu_time_s", row.cpu_time_s},
                {"repeats", row.repeats},
                {"steps_per_s", row.steps_per_s},
                {"realtime_factor", row.realtime_factor},
                {"local_order", number_or_null(row.local_order)},
                {"used_in_fit", row.used_in_fit},
                {"on_front", row.on_front},
                {"on_front_cpu", row.on_front_cpu},
                {"is_default", row.is_default},
                {"mujoco_warnings", row.mujoco_warnings}});
  return j;
}

Json setting_json(const PrecisionRow& row) {
  return {{"integrator", integrator_name(row.integrator)}, {"h_s", row.step_s}};
}

Json orders_json(const PrecisionResult& r) {
  Json orders = Json::array();
  for (const OrderFit& f : r.fits) {
    orders.push_back({{"integrator", integrator_name(f.integrator)},
                      {"order", number_or_null(f.order)},
                      {"log10_coefficient", number_or_null(f.log10_coefficient)},
                      {"points", f.points},
                      {"h_used_s", f.steps_used_s}});
  }
  return orders;
}

// The scene's own setting: its error and time, whether it is on the fronts,
// and the settings that beat it on both error and time. When --integrators
// left its integrator out, only the setting, the fronts null.
Json default_json(const PrecisionResult& r) {
  Json def = Json::object();
  for (const PrecisionRow& row : r.rows) {
    if (!row.is_default) continue;
    def = {{"integrator", integrator_name(row.integrator)},
           {"h_s", row.step_s},
           {"rms_error_mm", number_or_null(row.error.rms_mm)},
           {"max_error_mm", number_or_null(row.error.max_mm)},
           {"wall_time_s", row.wall_time_s},
           {"cpu_time_s", row.cpu_time_s},
           {"on_front", row.on_front},
           {"on_front_cpu", row.on_front_cpu}};
    Json better = Json::array();
    for (const PrecisionRow& other : r.rows) {
      if (other.error.finite && row.error.finite &&
          other.error.rms_mm < row.error.rms_mm &&
          other.wall_time_s < row.wall_time_s) {
        better.push_back(setting_json(other));
      }
    }
    def["dominated_by"] = better;
  }
  if (def.empty()) {
    def = {{"integrator", integrator_name(r.default_integrator)},
           {"h_s", r.default_step_s},
           {"on_front", nullptr},
           {"on_front_cpu", nullptr}};
  }
  return def;
}


const char* const kColours[] = {"#1f77b4", "#d62728", "#2ca02c"};

const char* colour_of(Integrator i) {
  return kColours[static_cast<int>(i)];
}

// Euler and implicit are both first order and, on a smooth script, their
// points can fall on one another (docs/numerics.md section 1). So no curve
// hides another: euler (drawn first) has a wide line and large dots,
// implicit (drawn over it) a thin dotted line and rings through which
// euler's dots show.
output::SeriesLook look_of(Integrator i) {
  output::SeriesLook look;
  if (i == Integrator::kEuler) {
    look.line_width = 3.5;
    look.marker_radius = 5.0;
  } else if (i == Integrator::kImplicit) {
    look.dash = "2 2";
    look.hollow = true;
    look.marker_radius = 3.5;
  }
  return look;
}

// said under the charts' titles when both first-order integrators are drawn
std::string coincide_note(const PrecisionResult& r) {
  bool euler = false, implicit = false;
  for (const OrderFit& f : r.fits) {
    euler = euler || f.integrator == Integrator::kEuler;
    implicit = implicit || f.integrator == Integrator::kImplicit;
  }
  return euler && implicit
             ? "curves may coincide: euler wide and filled, implicit dotted rings"
             : "";
}

}  // namespace

nlohmann::ordered_json precision_json(const PrecisionResult& r) {
  Json rows = Json::array();
  Json front = Json::array();
  for (const PrecisionRow& row : r.rows) {
    rows.push_back(row_json(row));
    if (row.on_front) front.push_back(setting_json(row));
  }
  Json segments = Json::array();
  for (const sim::ScriptSegment& seg : r.segments) {
    segments.push_back({{"name", seg.name}, {"t0_s", seg.t0_s}, {"t1_s", seg.t1_s}});
  }
  Json j = {
      {"study", "precision"},
      {"case", r.name},
      {"scene", r.scene},
      {"duration_s", r.duration_s},
      {"servo_period_s", r.servo_period_s},
      {"ticks", r.ticks},
      {"quantize", 0},
      {"segments", segments},
      {"trajectory",
       "true wrist centre (omni_fk of MuJoCo's joint angles, device frame) "
       "and stylus axis at the end of every servo tick"},
      {"reference",
       {{"integrator", "rk4"},
        {"h_s", r.reference.step_s},
        {"wall_time_s", r.reference.wall_time_s},
        {"check_h_s", r.reference.check_step_s},
        {"check_wall_time_s", r.reference.check_wall_time_s},
        {"self_error", error_json(r.reference.self_error)}}},
      {"fit_floor_mm", r.floor_mm},
      {"orders", orders_json(r)},
      {"default", default_json(r)},
      {"front", front},
      {"rows", rows},
      {"study_wall_time_s", r.study_wall_time_s},
  };
  if (r.modelling_spread.present) {
    double default_error = std::nan("");
    for (const PrecisionRow& row : r.rows) {
      if (row.is_default) default_error = row.error.rms_mm;
    }
    j["modelling_spread"] = modelling_spread_json(r.modelling_spread, default_error);
  }
  if (!r.files.empty()) j["files"] = r.files;
  return j;
}

std::vector<std::string> write_precision_files(const PrecisionResult& r,
                                               const std::string& out_dir) {
  return {output::write_file_in(out_dir, "precision.csv", precision_csv(r)),
          output::write_file_in(out_dir, "precision.svg",
                                output::chart_svg(precision_chart(r))),
          output::write_file_in(out_dir, "precision_order.svg",
                                output::chart_svg(precision_order_chart(r)))};
}

std::string precision_csv(const PrecisionResult& r) {
  std::string s =
      "integrator,h_s,substeps_per_tick,rms_error_mm,max_error_mm,"
      "rms_axis_error_rad,max_axis_error_rad,rms_torque_diff_mNm,"
      "status_mismatch_ticks,iteration_mismatch_ticks,wall_time_s,cpu_time_s,"
      "repeats,steps_per_s,realtime_factor,local_order,used_in_fit,on_front,"
      "on_front_cpu,is_default,finite,mujoco_warnings\n";
  char buf[512];
  for (const PrecisionRow& row : r.rows) {
    const TrajectoryError& e = row.error;
    std::snprintf(buf, sizeof buf,
                  "%s,%.9g,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d,%.9g,%.9g,%d,%.9g,"
                  "%.9g,%.9g,%d,%d,%d,%d,%d,%d\n",
                  integrator_name(row.integrator), row.step_s, row.substeps,
                  e.rms_mm, e.max_mm, e.rms_axis_rad, e.max_axis_rad,
                  e.rms_torque_mNm, e.status_mismatch_ticks,
                  e.iteration_mismatch_ticks, row.wall_time_s, row.cpu_time_s,
                  row.repeats, row.steps_per_s, row.realtime_factor,
                  row.local_order, row.used_in_fit ? 1 : 0,
                  row.on_front ? 1 : 0, row.on_front_cpu ? 1 : 0,
                  row.is_default ? 1 : 0, e.finite ? 1 : 0,
                  row.mujoco_warnings);
    s += buf;
  }
  return s;
}

output::Chart precision_chart(const PrecisionResult& r) {
  output::Chart c;
  char title[160];
  // centred on the plot area, so kept short
  std::snprintf(title, sizeof title, "work-precision, %.3g s, T = %.3g ms",
                r.duration_s, r.servo_period_s * 1e3);
  c.title = title;
  c.subtitle = coincide_note(r);
  c.width_px = 820;
  c.height_px = 480;
  c.x = {"wall time of the run (s)", true};
  c.y = {"RMS wrist-centre error vs RK4 reference (mm)", true};
  for (const OrderFit& f : r.fits) {
    output::ChartSeries s;
    s.label = integrator_name(f.integrator);
    s.color = colour_of(f.integrator);
    for (const PrecisionRow& row : r.rows) {
      if (row.integrator != f.integrator || !row.error.finite) continue;
      s.x.push_back(row.wall_time_s);
      s.y.push_back(row.error.rms_mm);
    }
    c.series.push_back(s);
    c.looks.resize(c.series.size());
    c.looks.back() = look_of(f.integrator);
  }
  for (const PrecisionRow& row : r.rows) {
    if (!row.is_default || !row.error.finite) continue;
    output::ChartSeries s;
    char label[96];
    std::snprintf(label, sizeof label, "default (%s, h = %.3g ms)",
                  integrator_name(row.integrator), row.step_s * 1e3);
    s.label = label;
    s.color = "#000000";
    s.line = false;
    s.x = {row.wall_time_s};
    s.y = {row.error.rms_mm};
    c.series.push_back(s);
  }
  // the reference's own error, across the chart
  if (r.reference.self_error.rms_mm > 0.0 && !r.rows.empty()) {
    double lo = r.rows.front().wall_time_s, hi = lo;
    for (const PrecisionRow& row : r.rows) {
      lo = std::min(lo, row.wall_time_s);
      hi = std::max(hi, row.wall_time_s);
    }
    output::ChartSeries s;
    s.label = "reference self-error (RK4 " +
              exact(r.reference.check_step_s * 1e6) + " us vs " +
              exact(r.reference.step_s * 1e6) + " us)";
    s.color = "#7f7f7f";
    s.markers = false;
    s.dashed = true;
    s.x = {lo, hi};
    s.y = {r.reference.self_error.rms_mm, r.reference.self_error.rms_mm};
    c.series.push_back(s);
  }
  add_modelling_spread(&c, r.modelling_spread);
  return c;
}

output::Chart precision_order_chart(const PrecisionResult& r) {
  output::Chart c;
  c.title = "error against the physics step";
  c.subtitle = coincide_note(r);
  c.width_px = 820;
  c.height_px = 480;
  c.x = {"physics step h (s)", true};
  c.y = {"RMS wrist-centre error vs RK4 reference (mm)", true};
  for (const OrderFit& f : r.fits) {
    output::ChartSeries s;
    s.color = colour_of(f.integrator);
    s.label = integrator_name(f.integrator);
    for (const PrecisionRow& row : r.rows) {
      if (row.integrator != f.integrator || !row.error.finite) continue;
      s.x.push_back(row.step_s);
      s.y.push_back(row.error.rms_mm);
    }
    c.series.push_back(s);
    c.looks.resize(c.series.size());
    c.looks.back() = look_of(f.integrator);
    if (f.points >= 2) {
      output::ChartSeries line;
      char label[96];
      std::snprintf(label, sizeof label, "%s fit, order %.2f",
                    integrator_name(f.integrator), f.order);
      line.label = label;
      line.color = colour_of(f.integrator);
      line.markers = false;
      line.dashed = true;
      const auto [lo, hi] =
          std::minmax_element(f.steps_used_s.begin(), f.steps_used_s.end());
      for (double h : {*lo, *hi}) {
        line.x.push_back(h);
        line.y.push_back(std::pow(10.0, f.log10_coefficient) *
                         std::pow(h, f.order));
      }
      c.series.push_back(line);
    }
  }
  if (r.floor_mm > 0.0 && !r.rows.empty()) {
    output::ChartSeries s;
    s.label = "fit floor (10 x reference self-error)";
    s.color = "#7f7f7f";
    s.markers = false;
    s.dashed = true;
    double lo = r.rows.front().step_s, hi = lo;
    for (const PrecisionRow& row : r.rows) {
      lo = std::min(lo, row.step_s);
      hi = std::max(hi, row.step_s);
    }
    s.x = {lo, hi};
    s.y = {r.floor_mm, r.floor_mm};
    c.series.push_back(s);
  }
  return c;
}

}  // namespace vmh::studies
