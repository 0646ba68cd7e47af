// The work-precision study's outputs: the JSON the command line prints (keys
// in the order a reader meets them) and the files under the output folder.
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

}  // namespace vmh::studies
