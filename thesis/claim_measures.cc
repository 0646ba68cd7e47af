#include "thesis/claim_measures.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

namespace vmh::thesis::detail {
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
std::vector<const TickRecord*> settled(const std::vector<TickRecord>& rows,
                                     const HandScript& script,
                                     const std::set<std::string>& names) {
  std::vector<const TickRecord*> out;
  const auto& segs = script.segments();
  std::vector<char> named(segs.size(), 0);
  for (std::size_t k = 0; k < segs.size(); ++k) {
    named[k] = names.count(segs[k].name) > 0 ? 1 : 0;
  }
  for (const TickRecord& r : rows) {
    const auto k = static_cast<std::size_t>(r.segment);
    if (named[k] && r.t_s >= segs[k].settled_from_s()) out.push_back(&r);
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
Vec3 along_path_toward_xr(const Vec3& x_v_mm, const Vec3& x_r_mm,
                          const ControllerParams& p) {
  Vec3 w = x_r_mm - x_v_mm;
  const Vec3 radial = (x_v_mm - p.vm.pivot_mm).normalized();
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

// the prediction of claim c: `value` computed the same way on the law's
// predicted forces; none (with the note) where no row had a prediction
void set_prediction(Claim* c, double value, int n, double tolerance,
                    const std::string& note) {
  if (n > 0 && std::isfinite(value)) {
    c->prediction = value;
    c->tolerance = tolerance;
    c->prediction_note = note;
  } else {
    c->prediction_note =
        "none: the law has no closed-form prediction at these poses (" +
        note + ")";
  }
}

constexpr const char* kStaticNote =
    "the static law (e_dot = 0) at the ground-truth poses, closed-form "
    "placement, limits included (thesis/law_prediction.h)";

// Cases 1 and 5, position error only, and case 7 (the line, whose law
// reads no orientation): no force on the path, and off it a force toward
// X(theta_V). (The thesis's third statement, "independent of
// X(theta_R)", is the first one again: with K_ornt = 0 nothing in the law
// reads X(theta_R), so on the path the force is K_pos times the distance.)
void position_claims(const std::vector<TickRecord>& rows, const HandScript& script,
                     const Predictions& pred, std::vector<Claim>* claims_out) {
  std::vector<Claim>& claims = *claims_out;
  const std::set<std::string> off = {"off_out", "off_out_misaligned", "off_in"};
  const std::set<std::string> on = {"on_misaligned_a", "on_misaligned_b"};
  {
    const auto w = settled(rows, script, on);
    std::vector<double> f, fp;
    for (const TickRecord* r : w) {
      f.push_back(r->out.force_device_N.norm());
      const LawPrediction& lp = pred.at(r);
      if (lp.available) fp.push_back(lp.force_limited_N.norm());
    }
    Claim c = make(
        "on_path_no_force",
        "with the RM on the path there is no force (the stylus misaligned)",
        on, mean_of(f), "<=", 0.05, "N", static_cast<int>(w.size()));
    const double pr = mean_of(fp);
    set_prediction(&c, pr, static_cast<int>(fp.size()),
                   std::max(0.01, 0.1 * pr),
                   std::string("mean |F| of ") + kStaticNote +
                       ": K_pos times the distance from the path");
    claims.push_back(c);
  }
  {
    // measured against the ground truth: the true wrist centre and the
    // closed-form nearest point of the path, not the controller's own
    // (quantised, Gauss-Newton) X(theta_V)
    const auto w = settled(rows, script, off);
    double worst = 0.0, worst_p = 0.0;
    int n = 0, np = 0;
    for (const TickRecord* r : w) {
      const double a =
          angle_deg(r->out.force_device_N, r->nearest_true_mm - r->p_true_mm);
      if (std::isfinite(a)) {
        worst = std::max(worst, a);
        ++n;
      }
      const LawPrediction& lp = pred.at(r);
      const double ap =
          lp.available
              ? angle_deg(lp.force_limited_N,
                          lp.x_v_mm - r->p_true_mm)
              : std::nan("");
      if (std::isfinite(ap)) {
        worst_p = std::max(worst_p, ap);
        ++np;
      }
    }
    Claim c = make(
        "off_path_force_toward_xv",
        "off the path the force is normal to it and pulls toward X(theta_V) "
        "(max angle from the true nearest point)",
        off, n > 0 ? worst : std::nan(""), "<=", 2.0, "deg", n);
    set_prediction(&c, np > 0 ? worst_p : std::nan(""), np, 2.0,
                   std::string("max angle of ") + kStaticNote);
    claims.push_back(c);
  }
}

// Cases 2, 3, 4 and 6, position and orientation: off the path the force
// points between X(theta_V) and X(theta_R), on it toward X(theta_R), felt.
void orientation_claims(const std::vector<TickRecord>& rows,
                        const HandScript& script, const Predictions& pred,
                        std::vector<Claim>* claims_out) {
  std::vector<Claim>& claims = *claims_out;
  const std::set<std::string> off_mis = {"off_out_misaligned"};
  const std::set<std::string> on = {"on_misaligned_a", "on_misaligned_b"};
  // between X_V and X_R (from p), nearer X_V
  const auto between = [](const Vec3& F, const Vec3& x_v, const Vec3& x_r,
                          const Vec3& pos, bool* ok) {
    const Vec3 dv = x_v - pos, dr = x_r - pos;
    const double av = angle_deg(F, dv), ar = angle_deg(F, dr);
    *ok = std::isfinite(av) && std::isfinite(ar);
    return F.dot(dv) > 0.0 && F.dot(x_r - x_v) > 0.0 && av < ar;
  };
  {
    const auto w = settled(rows, script, off_mis);
    int good = 0, n = 0, good_p = 0, np = 0;
    for (const TickRecord* r : w) {
      bool ok = false;
      const bool g = between(r->out.force_device_N, r->out.x_v_mm,
                             r->out.x_r_mm, r->out.p_rm_mm, &ok);
      if (ok) {
        ++n;
        good += g ? 1 : 0;
      }
      const LawPrediction& lp = pred.at(r);
      if (!lp.available) continue;
      const bool gp = between(lp.force_limited_N, lp.x_v_mm, lp.x_r_mm,
                              r->p_true_mm, &ok);
      if (ok) {
        ++np;
        good_p += gp ? 1 : 0;
      }
    }
    Claim c = make(
        "off_path_between_nearer_xv",
        "off the path the force points between X(theta_V) and X(theta_R), "
        "nearer X(theta_V): fraction of ticks",
        off_mis, n > 0 ? static_cast<double>(good) / n : std::nan(""), ">=",
        0.95, "-", n);
    set_prediction(&c, np > 0 ? static_cast<double>(good_p) / np : std::nan(""),
                   np, 0.05, std::string("fraction of ticks by ") + kStaticNote);
    claims.push_back(c);
  }
  {
    // on the path the force moves the RM toward X(theta_R) (cases 2 and 6)
    const auto w = settled(rows, script, on);
    std::vector<double> f, fp;
    int toward = 0, toward_p = 0;
    for (const TickRecord* r : w) {
      const Vec3 F = r->out.force_device_N;
      f.push_back(F.norm());
      if (F.dot(r->out.x_r_mm - r->out.p_rm_mm) > 0.0) ++toward;
      const LawPrediction& lp = pred.at(r);
      if (!lp.available) continue;
      fp.push_back(lp.force_limited_N.norm());
      if (lp.force_limited_N.dot(lp.x_r_mm - r->p_true_mm) >
          0.0) {
        ++toward_p;
      }
    }
    const int n = static_cast<int>(w.size());
    const int np = static_cast<int>(fp.size());
    Claim c = make(
        "on_path_force_toward_xr",
        "on the path the force moves the RM toward X(theta_R): fraction of "
        "ticks with F . (X(theta_R) - p) > 0",
        on, n > 0 ? static_cast<double>(toward) / n : std::nan(""), ">=",
        0.95, "-", n);
    set_prediction(&c, np > 0 ? static_cast<double>(toward_p) / np : std::nan(""),
                   np, 0.05, std::string("fraction of ticks by ") + kStaticNote);
    claims.push_back(c);
    // felt: at least a tenth of a newton, and the size the law gives
    Claim felt = make("on_path_force_felt",
                      "on the path the orientation error is felt: mean |F|",
                      on, mean_of(f), ">=", 0.1, "N", n);
    const double pr = mean_of(fp);
    set_prediction(&felt, pr, np, std::max(0.05, 0.1 * pr),
                   std::string("mean |F| of ") + kStaticNote);
    claims.push_back(felt);
  }
}

// Case 2's "bending feel" on a circle: along the path, not across it.
void along_path_claim(const std::vector<TickRecord>& rows, const HandScript& script,
                      const Predictions& pred, std::vector<Claim>* claims) {
  const ControllerParams& p = pred.params();
  const std::set<std::string> on = {"on_misaligned_a", "on_misaligned_b"};
  const auto w = settled(rows, script, on);
  std::vector<double> a, ap;
  for (const TickRecord* r : w) {
    const double x =
        angle_deg(r->out.force_device_N,
                  along_path_toward_xr(r->out.x_v_mm, r->out.x_r_mm, p));
    if (std::isfinite(x)) a.push_back(x);
    const LawPrediction& lp = pred.at(r);
    if (!lp.available) continue;
    const double y =
        angle_deg(lp.force_limited_N,
                  along_path_toward_xr(lp.x_v_mm, lp.x_r_mm, p));
    if (std::isfinite(y)) ap.push_back(y);
  }
  Claim c = make(
      "on_path_force_along_path",
      "on the path the force runs along the path toward X(theta_R), a "
      "bending feel: mean angle from the path's tangent",
      on, mean_of(a), "<=", 25.0, "deg", static_cast<int>(a.size()));
  set_prediction(&c, mean_of(ap), static_cast<int>(ap.size()), 5.0,
                 std::string("mean angle of ") + kStaticNote);
  claims->push_back(c);
}

// Cases 3 and 4: position (3) or orientation (4) weighs more than in case 2,
// the same readings through case 2's gains.
void weighting_claim(int thesis_case, const std::vector<TickRecord>& rows,
                     const HandScript& script, const Predictions& pred,
                     std::vector<Claim>* claims) {
  const ControllerParams& p = pred.params();
  const std::optional<ControllerParams> ref = reference_params(thesis_case, p);
  const std::set<std::string> off_mis = {"off_out_misaligned"};
  const auto w = settled(rows, script, off_mis);
  std::vector<double> mine, theirs, mine_p, theirs_p;
  for (const TickRecord* r : w) {
    const Vec3 dv = r->out.x_v_mm - r->out.p_rm_mm;
    const double a = angle_deg(r->out.force_device_N, dv);
    const double b = angle_deg(r->force_reference_N, dv);
    if (std::isfinite(a) && std::isfinite(b)) {
      mine.push_back(a);
      theirs.push_back(b);
    }
    const LawPrediction& lp = pred.at(r);
    if (!lp.available || !ref) continue;
    const LawPrediction lr = Predictions::predict(*r, *ref);
    if (!lr.available) continue;
    const Vec3 dv_p = lp.x_v_mm - r->p_true_mm;
    const double ap = angle_deg(lp.force_limited_N, dv_p);
    const double bp = angle_deg(lr.force_limited_N, dv_p);
    if (std::isfinite(ap) && std::isfinite(bp)) {
      mine_p.push_back(ap);
      theirs_p.push_back(bp);
    }
  }
  const double ratio = mean_of(mine) / mean_of(theirs);
  const double ratio_p = mean_of(mine_p) / mean_of(theirs_p);
  const std::string note = std::string("the same ratio by ") + kStaticNote +
                           ", with this case's gains and case 2's";
  if (thesis_case == 3) {
    Claim c = make(
        "position_weighs_more_than_case2",
        "position error weighs more than in case 2: the force's angle from "
        "X(theta_V) over case 2's at the same readings",
        off_mis, ratio, "<=", 0.95, "-", static_cast<int>(mine.size()));
    set_prediction(&c, ratio_p, static_cast<int>(mine_p.size()),
                   std::max(0.02, 0.1 * std::abs(ratio_p)), note);
    claims->push_back(c);
  } else {
    Claim c = make(
        "orientation_weighs_more_than_case2",
        "orientation error weighs more than in case 2: the force's angle "
        "from X(theta_V) over case 2's at the same readings",
        off_mis, ratio, ">=", 1.05, "-", static_cast<int>(mine.size()));
    set_prediction(&c, ratio_p, static_cast<int>(mine_p.size()),
                   std::max(0.02, 0.1 * std::abs(ratio_p)), note);
    claims->push_back(c);
  }
}

// Case 4 (Fig. 4.12): farther from the path the force is much greater than
// on it.
void force_grows_claim(const std::vector<TickRecord>& rows,
                       const HandScript& script, const Predictions& pred,
                       std::vector<Claim>* claims) {
  const std::set<std::string> sweep = {"sweep"};
  std::vector<double> far, near, far_p, near_p;
  for (const TickRecord& r : rows) {
    if (script.segments()[static_cast<std::size_t>(r.segment)].name != "sweep")
      continue;
    const double f = r.out.force_device_N.norm();
    const LawPrediction& lp = pred.at(&r);
    if (r.d_path_mm >= 5.0) {
      far.push_back(f);
      if (lp.available) far_p.push_back(lp.force_limited_N.norm());
    }
    if (r.d_path_mm <= kOnPathMm) {
      near.push_back(f);
      if (lp.available) near_p.push_back(lp.force_limited_N.norm());
    }
  }
  Claim c = make(
      "force_grows_off_path",
      "farther from the path the force is much greater than on it: mean "
      "|F| at >= 5 mm over mean |F| within 1 mm, during the sweep",
      sweep, mean_of(far) / std::max(mean_of(near), 1e-9), ">=", 3.0, "-",
      static_cast<int>(std::min(far.size(), near.size())));
  const double ratio_p = mean_of(far_p) / std::max(mean_of(near_p), 1e-9);
  set_prediction(&c, ratio_p,
                 static_cast<int>(std::min(far_p.size(), near_p.size())),
                 0.15 * std::abs(ratio_p),
                 std::string("the same ratio by ") + kStaticNote);
  claims->push_back(c);
}

// Case 7, the line slider (controller/vm_line.h): whatever the hand does
// along the line, the force has no part along it; the circle's bending
// force has gone with its curvature.
void line_sweep_claim(const std::vector<TickRecord>& rows,
                      const HandScript& script, const Predictions& pred,
                      std::vector<Claim>* claims) {
  const std::set<std::string> sweep = {"sweep"};
  const Vec3 t = pred.params().vm.R_pivot.col(1);  // the line's direction
  // the force's angle from the plane normal to the line (deg), where there
  // is a force to measure it on
  const auto off_normal_deg = [&t](const Vec3& F) {
    const double f = F.norm();
    if (!(f > 0.05)) return std::nan("");
    return std::asin(std::min(1.0, std::abs(F.dot(t)) / f)) * kRadToDeg;
  };
  double worst = 0.0, worst_p = 0.0;
  int n = 0, np = 0;
  for (const TickRecord& r : rows) {
    if (script.segments()[static_cast<std::size_t>(r.segment)].name != "sweep")
      continue;
    const double a = off_normal_deg(r.out.force_device_N);
    if (std::isfinite(a)) {
      worst = std::max(worst, a);
      ++n;
    }
    const LawPrediction& lp = pred.at(&r);
    const double ap =
        lp.available ? off_normal_deg(lp.force_limited_N) : std::nan("");
    if (std::isfinite(ap)) {
      worst_p = std::max(worst_p, ap);
      ++np;
    }
  }
  Claim c = make(
      "sweep_force_normal_to_line",
      "along the line the slider resists nothing: over the sweep, the "
      "force's largest angle from the plane normal to the line (|F| > "
      "0.05 N)",
      sweep, n > 0 ? worst : std::nan(""), "<=", 1.0, "deg", n);
  set_prediction(&c, np > 0 ? worst_p : std::nan(""), np, 1.0,
                 std::string("the largest angle of ") + kStaticNote);
  claims->push_back(c);
}

}  // namespace

std::vector<Claim> measure_claims(int thesis_case,
                                  const std::vector<TickRecord>& rows,
                                  const sim::Case& the_case,
                                  const Predictions& pred) {
  std::vector<Claim> claims;
  if (thesis_case < 1 || thesis_case > 7) return claims;
  const HandScript& script = the_case.script();
  const ControllerParams& p = the_case.controller_params();
  if (thesis_case == 7) {
    // the position claims hold with K_ornt > 0: the misaligned stylus on
    // the line is not felt
    position_claims(rows, script, pred, &claims);
    line_sweep_claim(rows, script, pred, &claims);
    return claims;
  }
  if (!(p.gains.k_ornt_Nmm_per_rad > 0.0)) {  // cases 1 and 5
    position_claims(rows, script, pred, &claims);
    return claims;
  }
  orientation_claims(rows, script, pred, &claims);
  if (p.vm.kind == VmKind::kCircle) along_path_claim(rows, script, pred, &claims);
  if (thesis_case == 3 || thesis_case == 4) {
    weighting_claim(thesis_case, rows, script, pred, &claims);
  }
  if (thesis_case == 4) force_grows_claim(rows, script, pred, &claims);
  return claims;
}

}  // namespace vmh::thesis::detail
