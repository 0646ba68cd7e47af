#include "studies/claims.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace vmh::studies {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace {

constexpr double kRadToDeg = 57.295779513082320876798;

// angle between two vectors in degrees; NaN if either is (near) zero
double angle_deg(const Vec3& a, const Vec3& b) {
  const double na = a.norm(), nb = b.norm();
  if (na < 1e-12 || nb < 1e-12) return std::nan("");
  const double c = std::clamp(a.dot(b) / (na * nb), -1.0, 1.0);
  return std::acos(c) * kRadToDeg;
}

// rows in the settled windows of the named segments
std::vector<const TraceRow*> settled(const std::vector<TraceRow>& rows,
                                     const HandScript& script,
                                     const std::set<std::string>& names) {
  std::vector<const TraceRow*> out;
  const auto& segs = script.segments();
  for (const TraceRow& r : rows) {
    const ScriptSegment& s = segs[static_cast<std::size_t>(r.segment)];
    if (names.count(s.name) && r.t_s >= s.settled_from_s()) out.push_back(&r);
  }
  return out;
}

std::string join(const std::set<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ",") + n;
  return s;
}

// the direction along the path from X_V toward X_R: their difference with
// the path's normal(s) at X_V removed
Vec3 along_path_toward_xr(const TraceRow& r, const ControllerParams& p) {
  Vec3 w = r.out.x_r_mm - r.out.x_v_mm;
  const Vec3 radial = (r.out.x_v_mm - p.vm.pivot_mm).normalized();
  w -= w.dot(radial) * radial;
  if (p.vm.kind == VmKind::kCircle) {
    const Vec3 n = p.vm.R_pivot.col(2);
    w -= w.dot(n) * n;
  }
  return w;
}

Claim make(const std::string& name, const std::string& statement,
           const std::set<std::string>& window, double value,
           const std::string& cmp, double threshold, const std::string& unit,
           int samples) {
  Claim c;
  c.name = name;
  c.statement = statement;
  c.window = join(window);
  c.value = value;
  c.comparison = cmp;
  c.threshold = threshold;
  c.unit = unit;
  c.samples = samples;
  c.pass = samples > 0 && std::isfinite(value) &&
           (cmp == "<=" ? value <= threshold : value >= threshold);
  return c;
}

double mean_of(const std::vector<double>& v) {
  if (v.empty()) return std::nan("");
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

}  // namespace

RunMetrics run_metrics(const std::vector<TraceRow>& rows,
                       const ClosedLoop& loop) {
  RunMetrics m;
  const auto& segs = loop.script().segments();
  const double T = loop.controller_params().servo_period_s;
  double sum_d2 = 0.0, sum_xv2 = 0.0, sum_f = 0.0, sum_f2 = 0.0;
  int n = 0;
  for (const TraceRow& r : rows) {
    ++m.ticks;
    const ControlStatus s = r.out.status;
    if (s & kStatusForceSaturated) ++m.force_saturated_ticks;
    if (s & kStatusTorqueSaturated) ++m.torque_saturated_ticks;
    if (is_fault(s) || r.servo.zeroed) ++m.fault_ticks;
    if (s & kStatusPlacementNotConverged) ++m.placement_not_converged_ticks;
    m.max_placement_iterations =
        std::max(m.max_placement_iterations, r.out.placement_iterations);
    // the settle at the start is not part of the experiment
    if (segs.size() > 1 && r.segment == 0) continue;
    ++n;
    const double d = r.d_path_mm;
    const double f = r.out.force_device_N.norm();
    sum_d2 += d * d;
    sum_xv2 += (r.out.x_v_mm - r.out.p_rm_mm).squaredNorm();
    sum_f += f;
    sum_f2 += f * f;
    m.max_path_error_mm = std::max(m.max_path_error_mm, d);
    m.max_force_N = std::max(m.max_force_N, f);
    if (d <= kOnPathMm) m.time_on_path_s += T;
  }
  if (n > 0) {
    m.rms_path_error_mm = std::sqrt(sum_d2 / n);
    m.rms_xv_error_mm = std::sqrt(sum_xv2 / n);
    m.mean_force_N = sum_f / n;
    m.rms_force_N = std::sqrt(sum_f2 / n);
  }
  return m;
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

namespace {

std::vector<Claim> measure_claims(int thesis_case,
                                  const std::vector<TraceRow>& rows,
                                  const ClosedLoop& loop);

}  // namespace

std::vector<Claim> evaluate_claims(int thesis_case,
                                   const std::vector<TraceRow>& rows,
                                   const ClosedLoop& loop) {
  std::vector<Claim> claims = measure_claims(thesis_case, rows, loop);
  for (Claim& c : claims) {
    std::set<std::string> names;
    std::size_t start = 0;
    while (start <= c.window.size()) {
      const std::size_t comma = c.window.find(',', start);
      const std::size_t end = comma == std::string::npos ? c.window.size() : comma;
      names.insert(c.window.substr(start, end - start));
      start = end + 1;
    }
    // the sweep claim uses the whole segment, the others its settled half
    const bool whole = names.count("sweep") > 0;
    double sum = 0.0;
    int n = 0;
    for (const TraceRow& r : rows) {
      const ScriptSegment& s =
          loop.script().segments()[static_cast<std::size_t>(r.segment)];
      if (names.count(s.name) && (whole || r.t_s >= s.settled_from_s())) {
        sum += r.d_path_mm;
        ++n;
      }
    }
    c.mean_path_distance_mm = n > 0 ? sum / n : std::nan("");
  }
  return claims;
}

namespace {

// Cases 1 and 5, position error only: no force on the path, off it a force
// toward X(theta_V), and none from X(theta_R).
void position_claims(const std::vector<TraceRow>& rows, const HandScript& script,
                     const ControllerParams& p, std::vector<Claim>* claims_out) {
  std::vector<Claim>& claims = *claims_out;
  const std::set<std::string> off = {"off_out", "off_out_misaligned", "off_in"};
  const std::set<std::string> on = {"on_misaligned_a", "on_misaligned_b"};
  {
    const auto w = settled(rows, script, on);
    std::vector<double> f;
    for (const TraceRow* r : w) f.push_back(r->out.force_device_N.norm());
    claims.push_back(make(
        "on_path_no_force",
        "with the RM on the path there is no force (the stylus misaligned)",
        on, mean_of(f), "<=", 0.05, "N", static_cast<int>(w.size())));
  }
  {
    // measured against the ground truth: the true wrist centre and the
    // closed-form nearest point of the path, not the controller's own
    // (quantised, Gauss-Newton) X(theta_V)
    const auto w = settled(rows, script, off);
    double worst = 0.0;
    int n = 0;
    for (const TraceRow* r : w) {
      const double a =
          angle_deg(r->out.force_device_N, r->nearest_true_mm - r->p_true_mm);
      if (std::isfinite(a)) {
        worst = std::max(worst, a);
        ++n;
      }
    }
    claims.push_back(make(
        "off_path_force_toward_xv",
        "off the path the force is normal to it and pulls toward X(theta_V) "
        "(max angle from the true nearest point)",
        off, n > 0 ? worst : std::nan(""), "<=", 2.0, "deg", n));
  }
  {
    // the force compared with what the same gain would give on the error
    // to X(theta_R): "independent of X(theta_R)"
    const auto w = settled(rows, script, on);
    std::vector<double> f, xr;
    for (const TraceRow* r : w) {
      f.push_back(r->out.force_device_N.norm());
      xr.push_back((r->out.x_r_mm - r->out.p_rm_mm).norm());
    }
    const double ratio =
        mean_of(f) / (p.gains.k_pos_N_per_mm * std::max(mean_of(xr), 1e-9));
    claims.push_back(make(
        "force_independent_of_xr",
        "the force does not depend on X(theta_R): |F| / (K_pos |X(theta_R) "
        "- p|) on the path",
        on, ratio, "<=", 0.02, "-", static_cast<int>(w.size())));
  }
}

// Cases 2, 3, 4 and 6, position and orientation: off the path the force
// points between X(theta_V) and X(theta_R), on it toward X(theta_R), felt.
void orientation_claims(const std::vector<TraceRow>& rows,
                        const HandScript& script,
                        std::vector<Claim>* claims_out) {
  std::vector<Claim>& claims = *claims_out;
  const std::set<std::string> off_mis = {"off_out_misaligned"};
  const std::set<std::string> on = {"on_misaligned_a", "on_misaligned_b"};
  {
    const auto w = settled(rows, script, off_mis);
    int good = 0, n = 0;
    for (const TraceRow* r : w) {
      const Vec3 F = r->out.force_device_N;
      const Vec3 dv = r->out.x_v_mm - r->out.p_rm_mm;
      const Vec3 dr = r->out.x_r_mm - r->out.p_rm_mm;
      const double av = angle_deg(F, dv), ar = angle_deg(F, dr);
      if (!std::isfinite(av) || !std::isfinite(ar)) continue;
      ++n;
      const bool toward_path = F.dot(dv) > 0.0;
      const bool toward_xr_side = F.dot(r->out.x_r_mm - r->out.x_v_mm) > 0.0;
      if (toward_path && toward_xr_side && av < ar) ++good;
    }
    claims.push_back(make(
        "off_path_between_nearer_xv",
        "off the path the force points between X(theta_V) and X(theta_R), "
        "nearer X(theta_V): fraction of ticks",
        off_mis, n > 0 ? static_cast<double>(good) / n : std::nan(""), ">=",
        0.95, "-", n));
  }
  {
    // on the path the force moves the RM toward X(theta_R) (cases 2 and 6)
    const auto w = settled(rows, script, on);
    std::vector<double> f;
    int toward = 0;
    for (const TraceRow* r : w) {
      const Vec3 F = r->out.force_device_N;
      f.push_back(F.norm());
      if (F.dot(r->out.x_r_mm - r->out.p_rm_mm) > 0.0) ++toward;
    }
    const int n = static_cast<int>(w.size());
    claims.push_back(make(
        "on_path_force_toward_xr",
        "on the path the force moves the RM toward X(theta_R): fraction of "
        "ticks with F . (X(theta_R) - p) > 0",
        on, n > 0 ? static_cast<double>(toward) / n : std::nan(""), ">=",
        0.95, "-", n));
    claims.push_back(make("on_path_force_felt",
                          "on the path the orientation error is felt: mean |F|",
                          on, mean_of(f), ">=", 0.1, "N", n));
  }
}

// Case 2's "bending feel" on a circle: along the path, not across it.
void along_path_claim(const std::vector<TraceRow>& rows, const HandScript& script,
                      const ControllerParams& p, std::vector<Claim>* claims) {
  const std::set<std::string> on = {"on_misaligned_a", "on_misaligned_b"};
  const auto w = settled(rows, script, on);
  std::vector<double> a;
  for (const TraceRow* r : w) {
    const double x =
        angle_deg(r->out.force_device_N, along_path_toward_xr(*r, p));
    if (std::isfinite(x)) a.push_back(x);
  }
  claims->push_back(make(
      "on_path_force_along_path",
      "on the path the force runs along the path toward X(theta_R), a "
      "bending feel: mean angle from the path's tangent",
      on, mean_of(a), "<=", 25.0, "deg", static_cast<int>(a.size())));
}

// Cases 3 and 4: position (3) or orientation (4) weighs more than in case 2,
// the same readings through case 2's gains.
void weighting_claim(int thesis_case, const std::vector<TraceRow>& rows,
                     const HandScript& script, std::vector<Claim>* claims) {
  const std::set<std::string> off_mis = {"off_out_misaligned"};
  const auto w = settled(rows, script, off_mis);
  std::vector<double> mine, ref;
  for (const TraceRow* r : w) {
    const Vec3 dv = r->out.x_v_mm - r->out.p_rm_mm;
    const double a = angle_deg(r->out.force_device_N, dv);
    const double b = angle_deg(r->force_reference_N, dv);
    if (std::isfinite(a) && std::isfinite(b)) {
      mine.push_back(a);
      ref.push_back(b);
    }
  }
  const double ratio = mean_of(mine) / mean_of(ref);
  if (thesis_case == 3) {
    claims->push_back(make(
        "position_weighs_more_than_case2",
        "position error weighs more than in case 2: the force's angle from "
        "X(theta_V) over case 2's at the same readings",
        off_mis, ratio, "<=", 0.95, "-", static_cast<int>(mine.size())));
  } else {
    claims->push_back(make(
        "orientation_weighs_more_than_case2",
        "orientation error weighs more than in case 2: the force's angle "
        "from X(theta_V) over case 2's at the same readings",
        off_mis, ratio, ">=", 1.05, "-", static_cast<int>(mine.size())));
  }
}

// Case 4 (Fig. 4.12): farther from the path the force is much greater than
// on it.
void force_grows_claim(const std::vector<TraceRow>& rows,
                       const HandScript& script, std::vector<Claim>* claims) {
  const std::set<std::string> sweep = {"sweep"};
  std::vector<double> far, near;
  for (const TraceRow& r : rows) {
    if (script.segments()[static_cast<std::size_t>(r.segment)].name != "sweep")
      continue;
    const double f = r.out.force_device_N.norm();
    if (r.d_path_mm >= 5.0) far.push_back(f);
    if (r.d_path_mm <= kOnPathMm) near.push_back(f);
  }
  claims->push_back(make(
      "force_grows_off_path",
      "farther from the path the force is much greater than on it: mean "
      "|F| at >= 5 mm over mean |F| within 1 mm, during the sweep",
      sweep, mean_of(far) / std::max(mean_of(near), 1e-9), ">=", 3.0, "-",
      static_cast<int>(std::min(far.size(), near.size()))));
}

std::vector<Claim> measure_claims(int thesis_case,
                                  const std::vector<TraceRow>& rows,
                                  const ClosedLoop& loop) {
  std::vector<Claim> claims;
  if (thesis_case < 1 || thesis_case > 6) return claims;
  const HandScript& script = loop.script();
  const ControllerParams& p = loop.controller_params();
  if (!(p.gains.k_ornt_Nmm_per_rad > 0.0)) {  // cases 1 and 5
    position_claims(rows, script, p, &claims);
    return claims;
  }
  orientation_claims(rows, script, &claims);
  if (p.vm.kind == VmKind::kCircle) along_path_claim(rows, script, p, &claims);
  if (thesis_case == 3 || thesis_case == 4) {
    weighting_claim(thesis_case, rows, script, &claims);
  }
  if (thesis_case == 4) force_grows_claim(rows, script, &claims);
  return claims;
}

}  // namespace
}  // namespace vmh::studies
