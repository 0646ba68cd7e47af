#include "bringup/compare_replay.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "controller/controller.h"
#include "output/output_file.h"
#include "output/svg_chart.h"
#include "sim/cases/case.h"
#include "output/number_text.h"
#include "sim/closed_loop.h"

namespace vmh::bringup {
namespace {

// four significant digits unless asked otherwise
std::string replay_fmt(double v, int digits = 4) {
  return output::significant(v, digits);
}

bool text_is(const Recording& r, const char* column, std::size_t row,
             const char* want) {
  return !r.has(column) || r.text_col(column)[row] == want;
}

// the gain scale hw run applied, as the header says where it is found
double gain_scale_of(const Recording& r, const ReplayOptions& o,
                     std::string* source) {
  if (std::isfinite(o.gain_scale)) {
    *source = "option";
    return o.gain_scale;
  }
  if (r.meta.contains("gain_scale") && r.meta["gain_scale"].is_number()) {
    *source = "meta.json";
    return r.meta["gain_scale"].get<double>();
  }
  // summary.json as any file of a recording: regular, bounded, read
  // without blocking (a FIFO there is refused, not waited on)
  bool missing = false;
  const std::string text = runtime::read_regular_file(
      r.dir + "/summary.json", runtime::RecordingLimits{}.max_meta_bytes, &missing);
  if (!missing) {
    nlohmann::json s;
    try {
      s = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
      throw RecordingError(r.dir + "/summary.json: not valid JSON (" +
                           e.what() + ")");
    }
    if (s.is_object() && s.contains("gain_scale")) {
      const nlohmann::json& g = s["gain_scale"];
      if (!g.is_number() || !std::isfinite(g.get<double>()) || g.get<double>() < 0) {
        throw RecordingError(r.dir + "/summary.json: key 'gain_scale': " +
                             g.dump().substr(0, 40) +
                             " is not a finite number >= 0");
      }
      *source = "summary.json";
      return g.get<double>();
    }
  }
  *source = "default";
  return 1.0;
}

std::vector<std::string> overrides_of(const Recording& r,
                                      const ReplayOptions& o) {
  std::vector<std::string> out;
  if (r.meta.contains("sets") && r.meta["sets"].is_array()) {
    for (const auto& s : r.meta["sets"]) {
      if (s.is_string()) out.push_back(s.get<std::string>());
    }
  }
  out.insert(out.end(), o.overrides.begin(), o.overrides.end());
  return out;
}

struct Series {
  std::vector<double> t_s, e_mm, F_N;
  double rms(const std::vector<double>& v) const {
    double s = 0.0;
    for (double x : v) s += x * x;
    return v.empty() ? std::nan("")
                     : std::sqrt(s / static_cast<double>(v.size()));
  }
};

CompareCheck ratio_check(const std::string& name, double value,
                         const ReplayOptions& o, const std::string& detail) {
  CompareCheck c =
      make_check(name, value, o.ratio_max, "ratio", CompareCheck::kAtMost,
                 detail + "; pass within [" + replay_fmt(o.ratio_min) + ", " +
                     replay_fmt(o.ratio_max) + "]");
  c.pass = c.pass && value >= o.ratio_min;
  return c;
}

void write_figure(const Series& rec, const Series& sim, const std::string& dir,
                  CompareSection* s) {
  output::ChartGrid g;
  g.title = "closed loop: recorded against the simulated scene";
  g.notes.push_back(
      "a real hand is not the scene's scripted hand: compare levels, not "
      "traces");
  g.columns = 2;
  const char* what[2] = {"|e| position error (mm)", "|F| commanded force (N)"};
  for (int k = 0; k < 2; ++k) {
    output::Chart ch;
    ch.title = what[k];
    ch.x.label = "t (s)";
    ch.y.label = what[k];
    ch.series.push_back({"recorded", rec.t_s, k == 0 ? rec.e_mm : rec.F_N,
                         "#1f77b4", true, false, false});
    ch.series.push_back({"simulated", sim.t_s, k == 0 ? sim.e_mm : sim.F_N,
                         "#d62728", true, false, true});
    g.panels.push_back(ch);
  }
  s->figures.push_back(
      output::write_file_in(dir, "closed_loop.svg", output::chart_grid_svg(g)));
}

// (a) the replay; fills its check and detail
void replay(const Recording& r, const ControllerParams& params,
            const ReplayOptions& o, CompareSection* s) {
  Controller c(params);
  ControlOutput out;
  double worst_Nm = 0.0;
  long first = -1, compared = 0, failed_reads = 0;
  Vec3 first_rec = Vec3::Zero(), first_rep = Vec3::Zero();
  for (std::size_t i = 0; i < r.rows; ++i) {
    const Joints q = r.q_dh_rad(i);
    Vec3 expect = Vec3::Zero();
    if (!text_is(r, "read_error", i, "ok") || !q.allFinite()) {
      c.reset();  // as servo_tick: no derivative kick on the next reading
      ++failed_reads;
    } else {
      const ControlStatus st = c.tick(q, &out);
      if (!is_fault(st) && text_is(r, "write_error", i, "ok"))
        expect = out.tau_motor_Nm;
    }
    const Vec3 rec = r.tau_cmd_Nm(i);
    if (!rec.allFinite()) continue;
    ++compared;
    const double err = (rec - expect).cwiseAbs().maxCoeff();
    worst_Nm = std::max(worst_Nm, err);
    if (first < 0 && 1e3 * err > o.torque_error_max_mNm) {
      first = static_cast<long>(i);
      first_rec = rec;
      first_rep = expect;
    }
  }
  std::string detail = "fresh controller over " + std::to_string(compared) +
                       " rows (" + std::to_string(failed_reads) +
                       " failed reads)";
  nlohmann::ordered_json d{{"rows_compared", compared},
                           {"failed_reads", failed_reads}};
  if (first >= 0) {
    const auto row = static_cast<std::size_t>(first);
    detail += "; first differing row " + std::to_string(first) + " (t_s " +
              replay_fmt(r.t_s(row), 6) + "): recorded " + replay_fmt(1e3 * first_rec[0]) +
              ", " + replay_fmt(1e3 * first_rec[1]) + ", " + replay_fmt(1e3 * first_rec[2]) +
              " mN m, replayed " + replay_fmt(1e3 * first_rep[0]) + ", " +
              replay_fmt(1e3 * first_rep[1]) + ", " + replay_fmt(1e3 * first_rep[2]) +
              " mN m";
    d["first_differing_row"] = {
        {"row", first},
        {"t_s", r.t_s(row)},
        {"recorded_mNm",
         {1e3 * first_rec[0], 1e3 * first_rec[1], 1e3 * first_rec[2]}},
        {"replayed_mNm",
         {1e3 * first_rep[0], 1e3 * first_rep[1], 1e3 * first_rep[2]}}};
  }
  CompareCheck ck =
      make_check("closed_loop.replay_torque_error_max", 1e3 * worst_Nm,
                 o.torque_error_max_mNm, "mNm", CompareCheck::kAtMost, detail);
  ck.recording = r.dir;
  s->checks.push_back(ck);
  s->detail["replay"] = d;
}

// (b) the scene simulated for the recording's length; fills its checks
void simulate(const Recording& r, const std::string& scene,
              std::vector<std::string> overrides, double gain_scale,
              const ReplayOptions& o, const std::string& figure_dir,
              CompareSection* s) {
  Series rec;
  for (std::size_t i : r.good_rows()) {
    const Vec3 e = r.vec3("e_", "_mm", i);
    const Vec3 F = r.vec3("F_", "_N", i, true);
    if (!e.allFinite() || !F.allFinite()) continue;
    rec.t_s.push_back(r.t_s(i));
    rec.e_mm.push_back(e.norm());
    rec.F_N.push_back(F.norm());
  }
  if (rec.t_s.size() < 2) {
    for (const char* n :
         {"closed_loop.error_rms_ratio", "closed_loop.force_rms_ratio"}) {
      s->skipped.push_back({n, "fewer than two good rows with e and F", r.dir});
    }
    return;
  }
  // the span compared: the recording's rows (its window, when it was cut
  // to one); the script as the session ran it, over the session's whole
  // length (a hand script is laid out over its duration_s)
  const double duration_s = rec.t_s.back();
  double script_s = duration_s;
  if (r.cut_to_window() && r.meta.contains("session") && r.meta["session"].is_object() &&
      r.meta["session"].contains("duration_s") &&
      r.meta["session"]["duration_s"].is_number()) {
    script_s = std::max(duration_s, r.meta["session"]["duration_s"].get<double>());
  }
  overrides.push_back("duration_s=" + replay_fmt(std::max(script_s, 1e-3), 9));
  // the case as the session ran it: its gains scaled as hw run scaled them
  const sim::Case session =
      sim::load_case(scene, overrides).with_gains_scaled(gain_scale);
  sim::ClosedLoop loop(session);
  Series sim;
  TickRecord row;
  while (!loop.finished()) {
    loop.tick(&row);
    if (row.t_s > duration_s + 1e-9) break;  // past the span compared
    sim.t_s.push_back(row.t_s);
    sim.e_mm.push_back(row.out.e.head<3>().norm());
    sim.F_N.push_back(row.out.force_device_N.norm());
  }
  const double e_ratio = rec.rms(rec.e_mm) / sim.rms(sim.e_mm);
  const double f_ratio = rec.rms(rec.F_N) / sim.rms(sim.F_N);
  const std::string over = " over " + replay_fmt(duration_s) + " s";
  s->checks.push_back(ratio_check(
      "closed_loop.error_rms_ratio", e_ratio, o,
      "RMS |e_1..3_mm| recorded " + replay_fmt(rec.rms(rec.e_mm)) + " mm, simulated " +
          replay_fmt(sim.rms(sim.e_mm)) + " mm" + over));
  s->checks.push_back(ratio_check("closed_loop.force_rms_ratio", f_ratio, o,
                                  "RMS |F| recorded " + replay_fmt(rec.rms(rec.F_N)) +
                                      " N, simulated " + replay_fmt(sim.rms(sim.F_N)) +
                                      " N" + over));
  for (std::size_t k = s->checks.size() - 2; k < s->checks.size(); ++k) {
    s->checks[k].recording = r.dir;
  }
  s->detail["simulation"] = {
      {"duration_s", duration_s},
      {"error_rms_mm",
       {{"recorded", rec.rms(rec.e_mm)}, {"simulated", sim.rms(sim.e_mm)}}},
      {"force_rms_N",
       {{"recorded", rec.rms(rec.F_N)}, {"simulated", sim.rms(sim.F_N)}}},
      {"hand", "the scene's scripted hand; a person differs"}};
  if (!figure_dir.empty()) write_figure(rec, sim, figure_dir, s);
}

}  // namespace

void ReplayOptions::validate() const {
  if (!(torque_error_max_mNm > 0.0) || !std::isfinite(torque_error_max_mNm)) {
    throw std::invalid_argument(
        "ReplayOptions.torque_error_max_mNm must be a finite number > 0");
  }
  if (!(ratio_min > 0.0) || !(ratio_max > ratio_min) ||
      !std::isfinite(ratio_max)) {
    throw std::invalid_argument(
        "ReplayOptions.ratio_min and ratio_max must satisfy 0 < ratio_min < "
        "ratio_max");
  }
  if (!std::isnan(gain_scale) &&
      !(gain_scale >= 0.0 && std::isfinite(gain_scale))) {
    throw std::invalid_argument(
        "ReplayOptions.gain_scale must be a number >= 0 (or NaN)");
  }
}

CompareSection compare_closed_loop(const Recording& r, const ReplayOptions& o,
                                   const std::string& figure_dir) {
  o.validate();
  CompareSection s;
  s.name = "closed_loop";
  const char* kAll[3] = {"closed_loop.replay_torque_error_max",
                         "closed_loop.error_rms_ratio",
                         "closed_loop.force_rms_ratio"};
  auto skip_all = [&](const std::string& why) {
    for (const char* n : kAll) s.skipped.push_back({n, why, r.dir});
    return s;
  };
  if (r.verb != "hw run")
    return skip_all("not a hw run recording (verb '" + r.verb + "')");
  if (!r.has("tau_1_Nm"))
    return skip_all("the trace has no tau_1..3_Nm columns");
  std::string scene = o.scene;
  if (scene.empty() && r.meta.contains("scene") &&
      r.meta["scene"].is_string()) {
    scene = r.meta["scene"].get<std::string>();
  }
  if (scene.empty())
    return skip_all("meta.json names no scene (give one as an option)");
  std::string gain_source;
  const double gain_scale = gain_scale_of(r, o, &gain_source);
  const std::vector<std::string> overrides = overrides_of(r, o);
  const ControllerParams params = sim::load_case(scene, overrides)
                                     .with_gains_scaled(gain_scale)
                                     .controller_params();
  s.detail["scene"] = scene;
  s.detail["overrides"] = overrides;
  s.detail["gain_scale"] = gain_scale;
  s.detail["gain_scale_from"] = gain_source;
  replay(r, params, o, &s);

  if (!o.simulate) {
    for (int k = 1; k < 3; ++k)
      s.skipped.push_back({kAll[k], "simulation not asked for", r.dir});
  } else if (!r.has("e_1_mm") || !r.has("F_x_N")) {
    for (int k = 1; k < 3; ++k)
      s.skipped.push_back({kAll[k], "the trace has no e_*_mm / F_*_N", r.dir});
  } else {
    simulate(r, scene, overrides, gain_scale, o, figure_dir, &s);
  }
  for (const CompareCheck& c : s.checks) {
    if (c.pass) continue;
    const std::string name = c.name == kAll[0]   ? "controller_mismatch"
                             : c.name == kAll[1] ? "closed_loop_error_level"
                                                 : "closed_loop_force_level";
    s.faults.push_back(
        {name, c.name + " = " + replay_fmt(c.value) + " " + c.unit + ": " + c.detail,
         r.dir});
  }
  return s;
}

}  // namespace vmh::bringup
