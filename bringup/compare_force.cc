#include "bringup/compare_force.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "controller/device_frame.h"
#include "controller/omni_params.h"
#include "output/number_text.h"
#include "output/output_file.h"
#include "output/svg_chart.h"
#include "bringup/response_sim.h"
#include "sim/cases/case_catalogue.h"

namespace vmh::bringup {
namespace {

using constants::kPi;
const double kNan = std::nan("");

// three significant digits unless asked for more
std::string force_fmt(double v, int digits = 3) {
  return output::significant(v, digits);
}

// The recording's rows from the sample before the pulse to its settling:
// times, torques sent (NaN as zero), and the true device angles where the
// reading was good.
struct PulseWindow {
  int motor = 0;           // 1..3
  double t_start_s = 0.0;  // the pulse's first row
  double pulse_s = 0.0;
  double t_end_s = 0.0;       // the last row compared
  std::size_t sim_start = 0;  // index into the vectors below
  std::vector<double> t_s;
  std::vector<Vec3> tau_Nm;
  std::vector<Joints> q;  // true device angles (NaN when not good)
  std::vector<bool> good;
};

int pulsed_motor(const Recording& rec) {
  if (rec.meta.contains("motor") && rec.meta["motor"].is_number()) {
    const int m = rec.meta["motor"].get<int>();
    if (m < 1 || m > 3) {
      throw std::invalid_argument(rec.dir + "/meta.json: motor " +
                                  std::to_string(m) + " is not 1, 2 or 3");
    }
    return m;
  }
  // no meta: the motor sent a torque most often
  int best = 0;
  std::size_t most = 0;
  for (int m = 1; m <= 3; ++m) {
    const std::vector<double>& c =
        rec.col("tau_sent_" + std::to_string(m) + "_Nm");
    const auto n = static_cast<std::size_t>(
        std::count_if(c.begin(), c.end(),
                      [](double v) { return std::isfinite(v) && v != 0.0; }));
    if (n > most) most = n, best = m;
  }
  return best;
}

// Empty reason: found. Otherwise why there is nothing to compare.
std::string find_pulse(const Recording& rec, const ReadingMap& map,
                       const ForceOptions& o, PulseWindow* w) {
  if (!rec.has("tau_sent_1_Nm")) return "the trace has no tau_sent columns";
  w->motor = pulsed_motor(rec);
  if (w->motor == 0) return "no torque was sent on any motor (no pulse)";
  const std::vector<double>& ts = rec.col("t_s");
  const std::vector<double>& tau =
      rec.col("tau_sent_" + std::to_string(w->motor) + "_Nm");
  std::size_t start = rec.rows, last = rec.rows;
  for (std::size_t r = 0; r < rec.rows; ++r) {
    if (!std::isfinite(ts[r]) || !std::isfinite(tau[r]) || tau[r] == 0.0)
      continue;
    if (start == rec.rows) start = r;
    last = r;
  }
  if (start == rec.rows) {
    return "motor " + std::to_string(w->motor) +
           " never had a torque sent (no pulse)";
  }
  w->t_start_s = ts[start];
  const double period_s =
      start + 1 < rec.rows ? ts[start + 1] - ts[start] : 1e-3;
  w->pulse_s = ts[last] - ts[start] + std::max(period_s, 0.0);
  w->t_end_s = w->t_start_s + std::min(w->pulse_s + 1e-3 * o.settle_ms,
                                       1e-3 * o.max_window_ms);
  const double t_first = w->t_start_s - 1e-3 * o.pre_ms;
  std::vector<bool> good(rec.rows, false);
  for (std::size_t r : rec.good_rows()) good[r] = true;
  for (std::size_t r = 0; r < rec.rows; ++r) {
    if (!std::isfinite(ts[r]) || ts[r] < t_first || ts[r] > w->t_end_s)
      continue;
    if (!w->t_s.empty() && ts[r] <= w->t_s.back()) continue;  // not increasing
    w->t_s.push_back(ts[r]);
    Vec3 t = rec.tau_sent_Nm(r);
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite(t[i])) t[i] = 0.0;
    }
    w->tau_Nm.push_back(t);
    w->good.push_back(good[r]);
    w->q.push_back(
        good[r] ? map.true_from_reported(dh_to_device_joints(rec.q_dh_rad(r)))
                : Joints::Constant(kNan));
  }
  // the simulation starts half-way through the quiet samples before the pulse
  const double t_sim = w->t_start_s - 0.5e-3 * o.pre_ms;
  std::size_t best = w->t_s.size();
  for (std::size_t i = 0; i < w->t_s.size() && w->t_s[i] < w->t_start_s; ++i) {
    if (!w->good[i]) continue;
    if (best == w->t_s.size() ||
        std::abs(w->t_s[i] - t_sim) < std::abs(w->t_s[best] - t_sim)) {
      best = i;
    }
  }
  if (best == w->t_s.size()) {
    return "no good reading in the " + force_fmt(o.pre_ms) + " ms before the pulse";
  }
  w->sim_start = best;
  return {};
}

// the samples from the simulation's start, as ResponseSimulator takes them
ResponseInput response_input(const PulseWindow& w, const ForceOptions& o) {
  ResponseInput in;
  const std::size_t k = w.sim_start;
  in.t_s.assign(w.t_s.begin() + static_cast<long>(k), w.t_s.end());
  in.tau_motor_Nm.assign(w.tau_Nm.begin() + static_cast<long>(k),
                         w.tau_Nm.end());
  in.q0_device_rad = w.q[k];
  // the velocity from the quiet samples only: the pulse must not bend it
  std::vector<double> t;
  std::vector<Joints> q;
  std::size_t at = 0;
  for (std::size_t i = 0; i < w.t_s.size() && w.t_s[i] < w.t_start_s; ++i) {
    if (!w.good[i]) continue;
    if (i == k) at = t.size();
    t.push_back(w.t_s[i]);
    q.push_back(w.q[i]);
  }
  in.qdot0_device_rad_s = velocity_estimate(t, q, at, 0.5e-3 * o.pre_ms);
  return in;
}

// t1..t3 of the samples (from sim_start) that are good and within [t0, t1]
struct Stack {
  std::vector<double> v;
  void add(const Joints& q, int n = 3) {
    for (int i = 0; i < n; ++i) v.push_back(q[i]);
  }
};

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

// measured and predicted effect (each minus the free motion), stacked
void effects(const PulseWindow& w, const SimulatedResponse& pred,
             const SimulatedResponse& free, double t0_s, double t1_s,
             std::vector<double>* m, std::vector<double>* p) {
  m->clear();
  p->clear();
  for (std::size_t j = 0; j < pred.t_s.size(); ++j) {
    const std::size_t i = w.sim_start + j;
    if (!w.good[i] || w.t_s[i] < t0_s || w.t_s[i] > t1_s) continue;
    for (int c = 0; c < 3; ++c) {
      m->push_back(w.q[i][c] - free.q_device_rad[j][c]);
      p->push_back(pred.q_device_rad[j][c] - free.q_device_rad[j][c]);
    }
  }
}

// rms of measured - predicted, t1..t3 over the compared window (rad)
double rms_error(const PulseWindow& w, const SimulatedResponse& pred) {
  if (!pred.finite) return std::numeric_limits<double>::infinity();
  double s = 0.0;
  int n = 0;
  for (std::size_t j = 0; j < pred.t_s.size(); ++j) {
    const std::size_t i = w.sim_start + j;
    if (!w.good[i] || w.t_s[i] < w.t_start_s) continue;
    for (int c = 0; c < 3; ++c) {
      const double e = w.q[i][c] - pred.q_device_rad[j][c];
      s += e * e;
      ++n;
    }
  }
  return n > 0 ? std::sqrt(s / n) : kNan;
}

// ten encoder counts (2 pi / 15000 rad each on t1..t3)
const double kWindowEffect_rad = 10.0 * 2.0 * kPi / OmniParams().encoder_counts_per_rev;

// the end of the angle and gain's window: t1_s, or later (up to the
// window's end) until the predicted effect reaches kWindowEffect_rad
double response_window_end(const PulseWindow& w, const SimulatedResponse& pred,
                           const SimulatedResponse& free, double t0_s,
                           double t1_s) {
  for (std::size_t j = 0; j < pred.t_s.size(); ++j) {
    const double t = pred.t_s[j];
    if (t < t0_s) continue;
    const double e = (pred.q_device_rad[j] - free.q_device_rad[j])
                         .head<3>()
                         .cwiseAbs()
                         .maxCoeff();
    if (t >= t1_s && e >= kWindowEffect_rad) return t;
  }
  return w.t_end_s;
}

double peak(const std::vector<double>& v) {
  double out = 0.0;
  for (double x : v) out = std::max(out, std::abs(x));
  return out;
}

struct Fit {
  double angle_deg = kNan;
  double gain = kNan;
};

// below this the predicted effect is lost in the encoders' quantization
// (2 pi / 15000 rad a count on t1..t3): a few counts' worth
const double kMinEffect_rad = 3.0 * 2.0 * kPi / OmniParams().encoder_counts_per_rev;

Fit fit(const std::vector<double>& m, const std::vector<double>& p) {
  Fit f;
  const double pp = dot(p, p), mm = dot(m, m), mp = dot(m, p);
  double peak = 0.0;
  for (double v : p) peak = std::max(peak, std::abs(v));
  if (p.empty() || peak < kMinEffect_rad) return f;
  f.gain = mp / pp;
  if (mm > 0.0) {
    f.angle_deg =
        std::acos(std::clamp(mp / std::sqrt(mm * pp), -1.0, 1.0)) * 180.0 / kPi;
  }
  return f;
}

struct Hypothesis {
  std::string name;
  sim::OmniModelEdit edit;
  double delay_s = 0.0;
  double scale = 1.0;
  double rms_rad = kNan;
  SimulatedResponse response;
};

Hypothesis hypothesis(std::string name, double delay_s, double scale = 1.0) {
  Hypothesis h;
  h.name = std::move(name);
  h.delay_s = delay_s;
  h.scale = scale;
  return h;
}

void write_figure(const PulseWindow& w, const SimulatedResponse& nominal,
                  const Hypothesis* named, const std::string& dir,
                  CompareSection* s) {
  output::ChartGrid g;
  g.title = "force direction: motor " + std::to_string(w.motor) + " pulse, " +
            force_fmt(1e3 * w.pulse_s) + " ms";
  g.notes.push_back(
      "device joints t1..t3 (rad), measured through the reading map; "
      "time from the pulse's start (ms)");
  g.columns = 3;
  for (int c = 0; c < 3; ++c) {
    output::Chart ch;
    ch.title = "t" + std::to_string(c + 1);
    ch.x.label = "time from pulse start (ms)";
    ch.y.label = "t" + std::to_string(c + 1) + " (rad)";
    ch.bands.push_back({0.0, 1e3 * w.pulse_s, "#e8e8e8"});
    output::ChartSeries meas{"measured", {}, {}, "#1f77b4", false, true, false};
    output::ChartSeries pred{"predicted", {},    {},   "#d62728",
                             true,        false, false};
    output::ChartSeries hyp{
        named ? named->name : "", {}, {}, "#2ca02c", true, false, true};
    for (std::size_t j = 0; j < nominal.t_s.size(); ++j) {
      const std::size_t i = w.sim_start + j;
      const double t_ms = 1e3 * (w.t_s[i] - w.t_start_s);
      if (w.good[i]) {
        meas.x.push_back(t_ms);
        meas.y.push_back(w.q[i][c]);
      }
      pred.x.push_back(t_ms);
      pred.y.push_back(nominal.q_device_rad[j][c]);
      if (named) {
        hyp.x.push_back(t_ms);
        hyp.y.push_back(named->response.q_device_rad[j][c]);
      }
    }
    ch.series = {meas, pred};
    if (named) ch.series.push_back(hyp);
    g.panels.push_back(ch);
  }
  s->figures.push_back(output::write_file_in(
      dir, "force_direction_motor" + std::to_string(w.motor) + ".svg",
      output::chart_grid_svg(g)));
}

}  // namespace

void ForceOptions::validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      throw std::invalid_argument(std::string("ForceOptions.") + name +
                                  " must be a finite number > 0");
    }
  };
  positive(pre_ms, "pre_ms");
  positive(initial_ms, "initial_ms");
  positive(max_window_ms, "max_window_ms");
  positive(angle_max_deg, "angle_max_deg");
  positive(gain_min, "gain_min");
  positive(lag_excess_ms, "lag_excess_ms");
  positive(hypothesis_ratio, "hypothesis_ratio");
  if (!(settle_ms >= 0.0) || !std::isfinite(settle_ms)) {
    throw std::invalid_argument(
        "ForceOptions.settle_ms must be a finite number >= 0");
  }
  if (!(gain_max > gain_min) || !std::isfinite(gain_max)) {
    throw std::invalid_argument(
        "ForceOptions.gain_max must be finite and > gain_min");
  }
  if (!(lag_max_ms >= 1.0) || lag_max_ms > 200.0) {
    throw std::invalid_argument("ForceOptions.lag_max_ms must be in [1, 200]");
  }
  if (!(lag_baseline_ms >= 0.0) || lag_baseline_ms > lag_max_ms) {
    throw std::invalid_argument(
        "ForceOptions.lag_baseline_ms must be in [0, lag_max_ms]");
  }
}

CompareSection compare_force_direction(const Recording& rec,
                                       const ReadingMap& map,
                                       const ForceOptions& o,
                                       const std::string& figure_dir) {
  o.validate();
  CompareSection s;
  s.name = "force_direction";
  PulseWindow w;
  const std::string why = find_pulse(rec, map, o, &w);
  if (!why.empty()) {
    const std::string m = w.motor > 0 ? std::to_string(w.motor) : "N";
    for (const char* c : {"_angle", "_gain", "_lag"}) {
      s.skipped.push_back({"force_direction.motor" + m + c, why, rec.dir});
    }
    return s;
  }
  const std::string prefix = "force_direction.motor" + std::to_string(w.motor);
  // the emulator's own scene when it says which (never its seeded faults)
  std::string scene = rec.emulator_scene();
  if (scene.empty()) {
    scene = o.scene.empty() ? sim::models_dir() + "/cases/case1.xml" : o.scene;
  }
  ResponseSimulator sim(scene, o.model_file);
  const ResponseInput in = response_input(w, o);
  ResponseInput quiet = in;
  for (Vec3& t : quiet.tau_motor_Nm) t.setZero();
  const SimulatedResponse free = sim.simulate(quiet);

  // the lag: the delay whose response best fits in shape, amplitude free
  std::vector<double> m, p;
  nlohmann::ordered_json lag_curve = nlohmann::ordered_json::array();
  int best_lag = -1;
  double best_res = std::numeric_limits<double>::infinity();
  std::vector<SimulatedResponse> by_lag;
  const int lag_steps = static_cast<int>(std::floor(o.lag_max_ms));
  for (int d = 0; d <= lag_steps; ++d) {
    by_lag.push_back(sim.simulate(in, {}, 1e-3 * d));
    effects(w, by_lag.back(), free, w.t_start_s, w.t_end_s, &m, &p);
    const double pp = dot(p, p);
    double res = kNan;
    if (by_lag.back().finite && pp > 0.0) {
      const double mp = dot(m, p);
      res = dot(m, m) - mp * mp / pp;
    }
    lag_curve.push_back(
        {{"lag_ms", d},
         {"residual_rad2", std::isfinite(res) ? nlohmann::ordered_json(res)
                                              : nlohmann::ordered_json()}});
    if (std::isfinite(res) && res < best_res) best_res = res, best_lag = d;
  }
  const double lag_ms = best_lag >= 0 ? static_cast<double>(best_lag) : kNan;
  const std::size_t at = best_lag >= 0 ? static_cast<std::size_t>(best_lag) : 0;
  // the response's first initial_ms (from the fitted lag), longer until the
  // prediction has moved kWindowEffect_rad: a few counts' quantization
  // would otherwise decide the angle
  const double t0_fit_s = w.t_start_s + 1e-3 * static_cast<double>(at);
  const double t1_fit_s = response_window_end(w, by_lag[at], free, t0_fit_s,
                                              t0_fit_s + 1e-3 * o.initial_ms);
  effects(w, by_lag[at], free, t0_fit_s, t1_fit_s, &m, &p);
  const Fit nominal_fit = fit(m, p);

  // the nominal prediction: a clean device's lag
  const std::size_t base =
      static_cast<std::size_t>(std::lround(o.lag_baseline_ms));
  const SimulatedResponse& nominal = by_lag[std::min(base, by_lag.size() - 1)];
  const double rms0 = rms_error(w, nominal);
  effects(w, nominal, free, w.t_start_s, w.t_end_s, &m, &p);
  // a pulse the model says cannot move the arm (into a joint limit, below
  // the friction) judges nothing; the arm moving anyway still asks why
  const bool observable = peak(p) >= kMinEffect_rad;
  const bool moved = peak(m) >= kWindowEffect_rad;
  if (!observable) {
    for (const char* c : {"_angle", "_gain", "_lag"}) {
      s.skipped.push_back(
          {prefix + c,
           "the prediction moves t1..t3 less than " +
               force_fmt(kMinEffect_rad * 1e3) +
               " mrad (three encoder counts): a pulse into a joint limit or "
               "below the friction; ask a larger torque or another pose",
           rec.dir});
    }
  }

  const std::string at_lag = " at the fitted lag " + force_fmt(lag_ms) + " ms";
  bool gain_failed = false;
  if (observable) {
    s.checks.push_back(make_check(prefix + "_angle", nominal_fit.angle_deg,
                                  o.angle_max_deg, "deg", CompareCheck::kAtMost,
                                  "angle between measured and predicted t1..t3 "
                                  "motion over the response's first " +
                                      force_fmt(1e3 * (t1_fit_s - t0_fit_s)) + " ms" +
                                      at_lag));
    const CompareCheck gain_lo =
        make_check(prefix + "_gain", nominal_fit.gain, o.gain_min, "ratio",
                   CompareCheck::kAtLeast);
    CompareCheck gain = make_check(
        prefix + "_gain", nominal_fit.gain, o.gain_max, "ratio",
        CompareCheck::kAtMost,
        "least-squares measured/predicted amplitude" + at_lag +
            ", pass within [" + force_fmt(o.gain_min) + ", " + force_fmt(o.gain_max) + "]");
    gain.pass = gain.pass && gain_lo.pass;
    gain_failed = !gain.pass;
    s.checks.push_back(gain);
    s.checks.push_back(
        make_check(prefix + "_lag", lag_ms, o.lag_baseline_ms + o.lag_excess_ms,
                   "ms", CompareCheck::kAtMost,
                   "extra delay (0.." + force_fmt(o.lag_max_ms) +
                       " ms) that best fits; a clean recording shows " +
                       force_fmt(o.lag_baseline_ms) + " ms"));
  }
  for (CompareCheck& c : s.checks) c.recording = rec.dir;

  const bool failed =
      observable ? std::any_of(s.checks.begin(), s.checks.end(),
                               [](const CompareCheck& c) { return !c.pass; })
                 : moved;
  nlohmann::ordered_json hyp_json = nlohmann::ordered_json::array();
  const Hypothesis* named = nullptr;
  std::vector<Hypothesis> hyps;
  if (failed) {
    const double base_s = 1e-3 * static_cast<double>(base);
    Hypothesis sign =
        hypothesis("motor" + std::to_string(w.motor) + "_sign", base_s);
    sign.edit.motor_gain[w.motor - 1] = -1.0;
    hyps.push_back(sign);
    if (w.motor == 3) {
      Hypothesis rel = hypothesis("motor3_relative", base_s);
      rel.edit.motor3_relative = true;
      hyps.push_back(rel);
    }
    hyps.push_back(hypothesis("torque_units_Nm", base_s, 1000.0));
    hyps.push_back(hypothesis("torque_units_mNm", base_s, 0.001));
    const double excess_ms = lag_ms - o.lag_baseline_ms;
    if (observable && excess_ms >= o.lag_excess_ms) {
      hyps.push_back(
          hypothesis("delay_" + std::to_string(std::lround(excess_ms)) + "ms",
                     1e-3 * lag_ms));
    }
    for (Hypothesis& h : hyps) {
      h.response = h.scale == 1.0 && h.edit.is_identity()
                       ? by_lag[at]
                       : sim.simulate(in, h.edit, h.delay_s, h.scale);
      h.rms_rad = rms_error(w, h.response);
      if (std::isfinite(h.rms_rad) &&
          (named == nullptr || h.rms_rad < named->rms_rad)) {
        named = &h;
      }
      hyp_json.push_back({{"name", h.name}, {"rms_rad", h.rms_rad}});
    }
    if (named != nullptr && !(named->rms_rad < o.hypothesis_ratio * rms0))
      named = nullptr;
    std::string fault, evidence;
    if (!observable && named == nullptr) {
      // moved without a prediction to judge it by: nothing to name
    } else if (named != nullptr) {
      fault = named->name;
      evidence = named->name + " fits with rms " + force_fmt(named->rms_rad) +
                 " rad against the nominal's " + force_fmt(rms0) + " rad";
    } else if (nominal_fit.gain > 10.0) {
      fault = "torque_units_Nm";
    } else if (nominal_fit.gain < 0.1) {
      fault = "torque_units_mNm";
    } else if (gain_failed) {
      fault = "motor" + std::to_string(w.motor) + "_gain";
    } else if (!s.checks.empty() && !s.checks[0].pass) {
      fault = "motor" + std::to_string(w.motor) + "_direction";
    } else {
      fault = "delay_" +
              std::to_string(std::lround(lag_ms - o.lag_baseline_ms)) + "ms";
    }
    if (evidence.empty()) {
      evidence = "angle " + force_fmt(nominal_fit.angle_deg) + " deg, gain " +
                 force_fmt(nominal_fit.gain) + ", lag " + force_fmt(lag_ms) +
                 " ms; no alternative fits clearly better";
    }
    if (!fault.empty()) s.faults.push_back({fault, evidence, rec.dir});
  }

  nlohmann::ordered_json hist = nlohmann::ordered_json::array();
  for (std::size_t j = 0; j < nominal.t_s.size(); j += 2) {
    const std::size_t i = w.sim_start + j;
    nlohmann::ordered_json row{{"t_ms", 1e3 * (w.t_s[i] - w.t_start_s)}};
    nlohmann::ordered_json qm = nullptr;
    if (w.good[i]) qm = {w.q[i][0], w.q[i][1], w.q[i][2]};
    row["measured_rad"] = qm;
    row["predicted_rad"] = {nominal.q_device_rad[j][0],
                            nominal.q_device_rad[j][1],
                            nominal.q_device_rad[j][2]};
    hist.push_back(row);
  }
  s.detail = {{"motor", w.motor},
              {"scene", scene},
              {"reading_map", map.is_identity() ? "identity" : map.name},
              {"pulse_start_s", w.t_start_s},
              {"pulse_ms", 1e3 * w.pulse_s},
              {"window_end_s", w.t_end_s},
              {"initial_velocity_rad_s",
               {in.qdot0_device_rad_s[0], in.qdot0_device_rad_s[1],
                in.qdot0_device_rad_s[2]}},
              {"joint_space", "device t1..t3 (rad)"},
              {"nominal_rms_rad", rms0},
              {"lag_search", lag_curve},
              {"hypotheses", hyp_json},
              {"history", hist}};
  if (!figure_dir.empty()) write_figure(w, nominal, named, figure_dir, &s);
  return s;
}

}  // namespace vmh::bringup
