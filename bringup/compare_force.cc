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
#include "bringup/compare_force_pulse.h"
#include "bringup/response_sim.h"
#include "sim/cases/case_catalogue.h"

namespace vmh::bringup {
namespace {

using constants::kPi;
using detail::find_pulse;
using detail::force_fmt;
using detail::kNan;
using detail::PulseWindow;
using detail::response_input;

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

// The pulse's three checks (prefix + _angle, _gain, _lag) skipped, for why
void skip_pulse_checks(const std::string& prefix, const std::string& why,
                       const std::string& dir, CompareSection* s) {
  for (const char* c : {"_angle", "_gain", "_lag"}) {
    s->skipped.push_back({prefix + c, why, dir});
  }
}

// the scene to predict with: the emulator's own when it says which (never
// its seeded faults), else the options', else the emulator's default
std::string prediction_scene(const Recording& rec, const ForceOptions& o) {
  std::string scene = rec.emulator_scene();
  if (scene.empty()) {
    scene = o.scene.empty() ? sim::models_dir() + "/cases/case1.xml" : o.scene;
  }
  return scene;
}

// The lag: the extra delay (whole ms, 0..lag_max_ms) whose response best
// fits the measured effect in shape, amplitude free. Every delay's
// response, the residual at each for the report, and the best delay (-1
// when none gave a finite fit).
struct LagSearch {
  std::vector<SimulatedResponse> by_lag;
  nlohmann::ordered_json curve = nlohmann::ordered_json::array();
  int best = -1;
};

LagSearch search_lag(const PulseWindow& w, const ResponseInput& in,
                     const SimulatedResponse& free, const ForceOptions& o,
                     ResponseSimulator* sim) {
  LagSearch out;
  std::vector<double> m, p;
  double best_res = std::numeric_limits<double>::infinity();
  const int lag_steps = static_cast<int>(std::floor(o.lag_max_ms));
  for (int d = 0; d <= lag_steps; ++d) {
    out.by_lag.push_back(sim->simulate(in, {}, 1e-3 * d));
    effects(w, out.by_lag.back(), free, w.t_start_s, w.t_end_s, &m, &p);
    const double pp = dot(p, p);
    double res = kNan;
    if (out.by_lag.back().finite && pp > 0.0) {
      const double mp = dot(m, p);
      res = dot(m, m) - mp * mp / pp;
    }
    out.curve.push_back(
        {{"lag_ms", d},
         {"residual_rad2", std::isfinite(res) ? nlohmann::ordered_json(res)
                                              : nlohmann::ordered_json()}});
    if (std::isfinite(res) && res < best_res) best_res = res, out.best = d;
  }
  return out;
}

// What the prediction says of a pulse: its checks are made and its fault
// named from these
struct PulseVerdict {
  double lag_ms = kNan;   // the extra delay that fits best
  std::size_t at = 0;     // its response in LagSearch::by_lag
  double t0_fit_s = 0.0;  // the response's start, where the fit is made
  double t1_fit_s = 0.0;
  Fit fit;                   // angle and gain there
  std::size_t base = 0;      // a clean device's lag (lag_baseline_ms), ms
  std::size_t nominal = 0;   // its response (the nominal) in by_lag
  double rms_rad = kNan;     // measured - nominal, t1..t3
  bool observable = false;   // the nominal moves t1..t3 three counts
  bool moved = false;        // the measured effect is ten counts
  bool gain_failed = false;  // set by add_pulse_checks
};

// The pulse judged from the lag search: the fit at the fitted lag over the
// response's first initial_ms, and the nominal prediction at a clean
// device's lag
PulseVerdict judge_pulse(const PulseWindow& w, const LagSearch& lag,
                         const SimulatedResponse& free, const ForceOptions& o) {
  PulseVerdict v;
  v.lag_ms = lag.best >= 0 ? static_cast<double>(lag.best) : kNan;
  v.at = lag.best >= 0 ? static_cast<std::size_t>(lag.best) : 0;
  // the response's first initial_ms (from the fitted lag), longer until the
  // prediction has moved kWindowEffect_rad: a few counts' quantization
  // would otherwise decide the angle
  v.t0_fit_s = w.t_start_s + 1e-3 * static_cast<double>(v.at);
  v.t1_fit_s = response_window_end(w, lag.by_lag[v.at], free, v.t0_fit_s,
                                   v.t0_fit_s + 1e-3 * o.initial_ms);
  std::vector<double> m, p;
  effects(w, lag.by_lag[v.at], free, v.t0_fit_s, v.t1_fit_s, &m, &p);
  v.fit = fit(m, p);

  // the nominal prediction: a clean device's lag
  v.base = static_cast<std::size_t>(std::lround(o.lag_baseline_ms));
  v.nominal = std::min(v.base, lag.by_lag.size() - 1);
  const SimulatedResponse& nominal = lag.by_lag[v.nominal];
  v.rms_rad = rms_error(w, nominal);
  effects(w, nominal, free, w.t_start_s, w.t_end_s, &m, &p);
  // a pulse the model says cannot move the arm (into a joint limit, below
  // the friction) judges nothing; the arm moving anyway still asks why
  v.observable = peak(p) >= kMinEffect_rad;
  v.moved = peak(m) >= kWindowEffect_rad;
  return v;
}

// why the checks of a pulse the nominal does not move are skipped
std::string unobservable_why() {
  return "the prediction moves t1..t3 less than " +
         force_fmt(kMinEffect_rad * 1e3) +
         " mrad (three encoder counts): a pulse into a joint limit or "
         "below the friction; ask a larger torque or another pose";
}

// The pulse's checks: the angle and the gain over the response's start
// at the fitted lag, and the lag. True when the gain
// is outside [gain_min, gain_max].
bool add_pulse_checks(const std::string& prefix, const PulseVerdict& v,
                      const ForceOptions& o, CompareSection* s) {
  const std::string at_lag =
      " at the fitted lag " + force_fmt(v.lag_ms) + " ms";
  s->checks.push_back(make_check(
      prefix + "_angle", v.fit.angle_deg, o.angle_max_deg, "deg",
      CompareCheck::kAtMost,
      "angle between measured and predicted t1..t3 "
      "motion over the response's first " +
          force_fmt(1e3 * (v.t1_fit_s - v.t0_fit_s)) + " ms" + at_lag));
  const CompareCheck gain_lo =
      make_check(prefix + "_gain", v.fit.gain, o.gain_min, "ratio",
                 CompareCheck::kAtLeast);
  CompareCheck gain = make_check(
      prefix + "_gain", v.fit.gain, o.gain_max, "ratio", CompareCheck::kAtMost,
      "least-squares measured/predicted amplitude" + at_lag +
          ", pass within [" + force_fmt(o.gain_min) + ", " +
          force_fmt(o.gain_max) + "]");
  gain.pass = gain.pass && gain_lo.pass;
  s->checks.push_back(gain);
  s->checks.push_back(
      make_check(prefix + "_lag", v.lag_ms, o.lag_baseline_ms + o.lag_excess_ms,
                 "ms", CompareCheck::kAtMost,
                 "extra delay (0.." + force_fmt(o.lag_max_ms) +
                     " ms) that best fits; a clean recording shows " +
                     force_fmt(o.lag_baseline_ms) + " ms"));
  return !gain.pass;
}

// The alternatives a failed pulse is tried against, at a clean device's
// lag base_s: the motor's sign, motor 3 on the relative elbow angle, the
// torque's units either way, and the delay when the lag was judged and is
// too long
std::vector<Hypothesis> pulse_hypotheses(int motor, double base_s,
                                         const PulseVerdict& v,
                                         const ForceOptions& o) {
  std::vector<Hypothesis> hyps;
  Hypothesis sign =
      hypothesis("motor" + std::to_string(motor) + "_sign", base_s);
  sign.edit.motor_gain[motor - 1] = -1.0;
  hyps.push_back(sign);
  if (motor == 3) {
    Hypothesis rel = hypothesis("motor3_relative", base_s);
    rel.edit.motor3_relative = true;
    hyps.push_back(rel);
  }
  hyps.push_back(hypothesis("torque_units_Nm", base_s, 1000.0));
  hyps.push_back(hypothesis("torque_units_mNm", base_s, 0.001));
  const double excess_ms = v.lag_ms - o.lag_baseline_ms;
  if (v.observable && excess_ms >= o.lag_excess_ms) {
    hyps.push_back(
        hypothesis("delay_" + std::to_string(std::lround(excess_ms)) + "ms",
                   1e-3 * v.lag_ms));
  }
  return hyps;
}

// Each hypothesis simulated (the fitted lag's response when it changes
// nothing), its rms into *json; the one that fits best when its rms is
// below hypothesis_ratio times the nominal's, else nullptr
const Hypothesis* best_hypothesis(const PulseWindow& w, const ResponseInput& in,
                                  const SimulatedResponse& at_lag,
                                  const PulseVerdict& v, const ForceOptions& o,
                                  ResponseSimulator* sim,
                                  std::vector<Hypothesis>* hyps,
                                  nlohmann::ordered_json* json) {
  const Hypothesis* named = nullptr;
  for (Hypothesis& h : *hyps) {
    h.response = h.scale == 1.0 && h.edit.is_identity()
                     ? at_lag
                     : sim->simulate(in, h.edit, h.delay_s, h.scale);
    h.rms_rad = rms_error(w, h.response);
    if (std::isfinite(h.rms_rad) &&
        (named == nullptr || h.rms_rad < named->rms_rad)) {
      named = &h;
    }
    json->push_back({{"name", h.name}, {"rms_rad", h.rms_rad}});
  }
  if (named != nullptr && !(named->rms_rad < o.hypothesis_ratio * v.rms_rad))
    named = nullptr;
  return named;
}

// The fault a failed pulse points to, with its evidence: the hypothesis
// that fits (named), else what the nominal fit says (a gain 10x off: the
// torque's units; a failed gain; a failed angle: the direction; else the
// delay). Nothing when the prediction does not move the arm and no
// hypothesis fits.
void name_pulse_fault(int motor, const PulseVerdict& v, const Hypothesis* named,
                      const ForceOptions& o, const std::string& dir,
                      CompareSection* s) {
  std::string fault, evidence;
  if (!v.observable && named == nullptr) {
    // moved without a prediction to judge it by: nothing to name
  } else if (named != nullptr) {
    fault = named->name;
    evidence = named->name + " fits with rms " + force_fmt(named->rms_rad) +
               " rad against the nominal's " + force_fmt(v.rms_rad) + " rad";
  } else if (v.fit.gain > 10.0) {
    fault = "torque_units_Nm";
  } else if (v.fit.gain < 0.1) {
    fault = "torque_units_mNm";
  } else if (v.gain_failed) {
    fault = "motor" + std::to_string(motor) + "_gain";
  } else if (!s->checks.empty() && !s->checks[0].pass) {
    fault = "motor" + std::to_string(motor) + "_direction";
  } else {
    fault = "delay_" +
            std::to_string(std::lround(v.lag_ms - o.lag_baseline_ms)) + "ms";
  }
  if (evidence.empty()) {
    evidence = "angle " + force_fmt(v.fit.angle_deg) + " deg, gain " +
               force_fmt(v.fit.gain) + ", lag " + force_fmt(v.lag_ms) +
               " ms; no alternative fits clearly better";
  }
  if (!fault.empty()) s->faults.push_back({fault, evidence, dir});
}

// every other sample's measured (null when not good) and predicted t1..t3
nlohmann::ordered_json pulse_history(const PulseWindow& w,
                                     const SimulatedResponse& nominal) {
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
  return hist;
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
    skip_pulse_checks("force_direction.motor" + m, why, rec.dir, &s);
    return s;
  }
  const std::string prefix = "force_direction.motor" + std::to_string(w.motor);
  const std::string scene = prediction_scene(rec, o);
  ResponseSimulator sim(scene, o.model_file);
  const ResponseInput in = response_input(w, o);
  ResponseInput quiet = in;
  for (Vec3& t : quiet.tau_motor_Nm) t.setZero();
  const SimulatedResponse free = sim.simulate(quiet);

  const LagSearch lag = search_lag(w, in, free, o, &sim);
  PulseVerdict v = judge_pulse(w, lag, free, o);
  const SimulatedResponse& nominal = lag.by_lag[v.nominal];
  if (!v.observable) {
    skip_pulse_checks(prefix, unobservable_why(), rec.dir, &s);
  } else {
    v.gain_failed = add_pulse_checks(prefix, v, o, &s);
  }
  for (CompareCheck& c : s.checks) c.recording = rec.dir;

  const bool failed =
      v.observable ? std::any_of(s.checks.begin(), s.checks.end(),
                                 [](const CompareCheck& c) { return !c.pass; })
                   : v.moved;
  nlohmann::ordered_json hyp_json = nlohmann::ordered_json::array();
  const Hypothesis* named = nullptr;
  std::vector<Hypothesis> hyps;
  if (failed) {
    hyps = pulse_hypotheses(w.motor, 1e-3 * static_cast<double>(v.base), v, o);
    named =
        best_hypothesis(w, in, lag.by_lag[v.at], v, o, &sim, &hyps, &hyp_json);
    name_pulse_fault(w.motor, v, named, o, rec.dir, &s);
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
              {"nominal_rms_rad", v.rms_rad},
              {"lag_search", lag.curve},
              {"hypotheses", hyp_json},
              {"history", pulse_history(w, nominal)}};
  if (!figure_dir.empty()) write_figure(w, nominal, named, figure_dir, &s);
  return s;
}

}  // namespace vmh::bringup
