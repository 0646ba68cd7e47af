// The motor test's pulse for compare's force-direction check
// (bringup/compare_force_pulse.h): which motor pushed, the window of rows
// around its pulse read through the reading map, and the state the
// prediction starts from.
#include "bringup/compare_force_pulse.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "controller/device_frame.h"

namespace vmh::bringup::detail {
namespace {

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

}  // namespace

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

}  // namespace vmh::bringup::detail
