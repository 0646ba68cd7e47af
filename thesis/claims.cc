#include "thesis/claims.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "thesis/claim_measures.h"

namespace vmh::thesis {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
using detail::Predictions;

MetricsAccumulator::MetricsAccumulator(const sim::Case& the_case)
    : T_s_(the_case.controller_params().servo_period_s),
      has_settle_(the_case.script().segments().size() > 1) {}

void MetricsAccumulator::add(const TickRecord& r) {
  RunMetrics& m = m_;
  ++m.ticks;
  const ControlStatus s = r.out.status;
  if (s & kStatusForceSaturated) ++m.force_saturated_ticks;
  if (s & kStatusTorqueSaturated) ++m.torque_saturated_ticks;
  if (is_fault(s) || r.servo.zeroed) ++m.fault_ticks;
  if (s & kStatusPlacementNotConverged) ++m.placement_not_converged_ticks;
  m.max_placement_iterations =
      std::max(m.max_placement_iterations, r.out.placement_iterations);
  // the settle at the start is not part of the experiment
  if (has_settle_ && r.segment == 0) return;
  ++n_;
  const double d = r.d_path_mm;
  const double f = r.out.force_device_N.norm();
  sum_d2_ += d * d;
  sum_xv2_ += (r.out.x_v_mm - r.out.p_rm_mm).squaredNorm();
  sum_f_ += f;
  sum_f2_ += f * f;
  m.max_path_error_mm = std::max(m.max_path_error_mm, d);
  m.max_force_N = std::max(m.max_force_N, f);
  if (d <= kOnPathMm) m.time_on_path_s += T_s_;
}

RunMetrics MetricsAccumulator::result() const {
  RunMetrics m = m_;
  if (n_ > 0) {
    const double n = static_cast<double>(n_);
    m.rms_path_error_mm = std::sqrt(sum_d2_ / n);
    m.rms_xv_error_mm = std::sqrt(sum_xv2_ / n);
    m.mean_force_N = sum_f_ / n;
    m.rms_force_N = std::sqrt(sum_f2_ / n);
  }
  return m;
}

RunMetrics run_metrics(const std::vector<TickRecord>& rows,
                       const sim::Case& the_case) {
  MetricsAccumulator acc(the_case);
  for (const TickRecord& r : rows) acc.add(r);
  return acc.result();
}

std::set<std::string> window_segments(const Claim& c) {
  std::set<std::string> names;
  std::size_t start = 0;
  while (start <= c.window.size()) {
    const std::size_t comma = c.window.find(',', start);
    const std::size_t end = comma == std::string::npos ? c.window.size() : comma;
    names.insert(c.window.substr(start, end - start));
    start = end + 1;
  }
  return names;
}

bool measured_off_path(const Claim& c) {
  return c.window.find("off_") != std::string::npos;
}

void merge_sides(std::vector<Claim>* first, const SideLabel& where_first,
                 const std::vector<SideRun>& others) {
  const auto side = [](const Claim& c, const std::string& where) {
    Claim::Side s;
    s.where = where;
    s.value = c.value;
    s.pass = c.pass;
    s.prediction = c.prediction;
    s.matches_prediction = c.matches_prediction;
    s.regime = c.regime;
    s.mean_path_distance_mm = c.mean_path_distance_mm;
    return s;
  };
  for (Claim& c : *first) {
    const bool off_path = measured_off_path(c);
    const auto label = [&](const SideLabel& l) {
      return off_path ? l.where_off_path : l.where;
    };
    c.sides = {side(c, label(where_first))};
    for (const SideRun& run : others) {
      if (run.off_path_only && !off_path) continue;
      const auto other =
          std::find_if(run.claims.begin(), run.claims.end(),
                       [&](const Claim& o) { return o.name == c.name; });
      if (other != run.claims.end()) {
        c.sides.push_back(side(*other, label(run.label)));
      }
    }
    int held = 0;
    std::string where;
    for (const Claim::Side& s : c.sides) {
      if (!s.pass) continue;
      ++held;
      where += (where.empty() ? "" : "; ") + s.where;
    }
    const int n = static_cast<int>(c.sides.size());
    c.pass = held == n;
    c.partial = held > 0 && held < n;
    c.holds_where = c.partial ? where : "";
  }
}

std::optional<ControllerParams> reference_params(int thesis_case,
                                                 const ControllerParams& p) {
  if (thesis_case != 3 && thesis_case != 4) return std::nullopt;
  // case 2: K_pos 0.5 N/mm, K_ornt 0.5 x 2 pi L (docs/sources.md §2)
  ControllerParams ref = p;
  ref.gains.k_pos_N_per_mm = 0.5;
  ref.gains.k_ornt_Nmm_per_rad = thesis_orientation_gain(0.5, p.vm.length_mm);
  return ref;
}

std::vector<Claim> evaluate_claims(int thesis_case,
                                   const std::vector<TickRecord>& rows,
                                   const sim::Case& the_case) {
  const Predictions pred(rows, the_case.controller_params());
  std::vector<Claim> claims = detail::measure_claims(thesis_case, rows, the_case, pred);
  for (Claim& c : claims) {
    const std::set<std::string> names = window_segments(c);
    // the sweep claim uses the whole segment, the others its settled half
    const bool whole = names.count("sweep") > 0;
    const std::vector<ScriptSegment>& segs = the_case.script().segments();
    std::vector<char> in_window(segs.size(), 0);
    for (std::size_t k = 0; k < segs.size(); ++k) {
      in_window[k] = names.count(segs[k].name) > 0 ? 1 : 0;
    }
    double sum = 0.0;
    int n = 0, limited = 0;
    for (const TickRecord& r : rows) {
      const auto k = static_cast<std::size_t>(r.segment);
      if (in_window[k] && (whole || r.t_s >= segs[k].settled_from_s())) {
        sum += r.d_path_mm;
        ++n;
        if (r.out.status & (kStatusForceSaturated | kStatusTorqueSaturated)) {
          ++limited;
        }
      }
    }
    c.mean_path_distance_mm = n > 0 ? sum / n : std::nan("");
    c.saturated_fraction = n > 0 ? static_cast<double>(limited) / n : 0.0;
    c.regime = c.saturated_fraction >= 0.5 ? "saturated" : "linear";
    if (c.prediction) {
      c.matches_prediction = std::isfinite(c.value) && std::isfinite(*c.prediction) &&
                             std::abs(c.value - *c.prediction) <= c.tolerance;
    }
  }
  return claims;
}

}  // namespace vmh::thesis
