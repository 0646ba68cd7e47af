#include "studies/stability_study.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "controller/types.h"
#include "output/number_text.h"
#include "output/parallel.h"

namespace vmh::studies {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace {

using constants::kPi;

}  // namespace

// ---------------------------------------------------------------- simulation

std::string slider_model_path(const std::string& models_dir) {
  return (std::filesystem::path(models_dir) / "slider" / "slider.xml")
      .string();
}

SliderWall::SliderWall(const std::string& model_path,
                       const StabilityParams& p)
    : p_(p) {
  validate(p_);
  m_ = load_model(model_path);
  mjModel* m = m_.get();
  const int body = require_id(m, mjOBJ_BODY, "slider", model_path);
  const int joint = require_id(m, mjOBJ_JOINT, "x", model_path);
  const int motor = require_id(m, mjOBJ_ACTUATOR, "force", model_path);
  if (m->nq != 1 || m->nv != 1 || m->nu != 1 ||
      m->jnt_type[joint] != mjJNT_SLIDE || m->jnt_bodyid[joint] != body ||
      m->actuator_trntype[motor] != mjTRN_JOINT ||
      m->actuator_trnid[2 * motor] != joint ||
      m->actuator_gear[6 * motor] != 1.0 || m->actuator_ctrllimited[motor] ||
      m->actuator_forcelimited[motor] || m->dof_armature[0] != 0.0 ||
      m->dof_frictionloss[0] != 0.0 || m->jnt_limited[joint]) {
    throw SimError(model_path +
                   ": not the study's slider (one free slide joint 'x' of "
                   "body 'slider', no armature, friction or limit, and one "
                   "unlimited motor 'force' on it with gear 1)");
  }
  // m: the body's mass, its (irrelevant to a slide joint, but positive)
  // inertia scaled alike; b: the joint's damping; h: the step. Euler, as
  // the testbed's scenes, whose implicit joint damping is what
  // PlantModel::kMujocoEuler models.
  const double scale = p_.mass_kg / m->body_mass[body];
  m->body_mass[body] = p_.mass_kg;
  for (int i = 0; i < 3; ++i) m->body_inertia[3 * body + i] *= scale;
  m->dof_damping[0] = p_.damping_Ns_per_m;
  m->opt.timestep = p_.physics_step_s;
  m->opt.integrator = mjINT_EULER;
  d_.reset(mj_makeData(m));
  mj_setConst(m, d_.get());
  steps_per_tick_ = steps_per_tick(p_);
}

int SliderWall::horizon_ticks(double k_N_per_m) const {
  const double period_s =
      2.0 * kPi * std::sqrt(p_.mass_kg / std::max(k_N_per_m, 1e-300));
  const double ticks = kHorizonPeriods * period_s / p_.servo_period_s;
  return static_cast<int>(
      std::clamp(std::ceil(ticks), double{kMinHorizonTicks}, 1e7));
}

void SliderWall::run_ticks(double k_N_per_m, int ticks,
                           std::vector<double>* xs, WallRun* r) {
  mjModel* m = m_.get();
  mjData* d = d_.get();
  mj_resetData(m, d);
  const double x0 = kInitialDisplacement_m;
  d->qpos[0] = x0;
  mj_forward(m, d);

  const double T = p_.servo_period_s;
  const double B = p_.virtual_damping_Ns_per_m;
  const int n = p_.delay_ticks;
  std::vector<double> delay_line(static_cast<std::size_t>(n), 0.0);
  std::size_t oldest = 0;
  double x_prev = x0;

  xs->reserve(static_cast<std::size_t>(ticks) + 1);
  for (int k = 0; k < ticks; ++k) {
    const double x = d->qpos[0];
    xs->push_back(x);
    if (!std::isfinite(x) || std::abs(x) > kDivergedFactor * x0) {
      r->diverged = true;
      break;
    }
    // the controller's tick: sample, backward difference, wall force
    const double v = p_.velocity == VelocityEstimate::kSampled
                         ? d->qvel[0]
                         : (x - x_prev) / T;
    const double u = -k_N_per_m * x - B * v;
    x_prev = x;
    double f = u;
    if (n > 0) {
      f = delay_line[oldest];
      delay_line[oldest] = u;
      oldest = (oldest + 1) % delay_line.size();
    }
    // held over the period while the physics steps
    d->ctrl[0] = f;
    for (int j = 0; j < steps_per_tick_; ++j) mj_step(m, d);
    ++r->ticks;
  }
  if (!r->diverged) xs->push_back(d->qpos[0]);
}

void SliderWall::throw_if_warned(double k_N_per_m) const {
  for (int i = 0; i < mjNWARNING; ++i) {
    if (d_->warning[i].number > 0) {
      throw std::runtime_error(
          "stability study: MuJoCo warning " + std::to_string(i) +
          " during a run at K = " + output::significant(k_N_per_m, 10) + " N/m");
    }
  }
}

namespace {

// A run stopped when |x| passed kDivergedFactor x0: unstable, its growth
// rate from x0 to the last |x| over the ticks run.
void judge_diverged(const std::vector<double>& xs, double T, WallRun* r) {
  const double x0 = kInitialDisplacement_m;
  const std::size_t L = xs.size();
  r->stable = false;
  r->early_peak_m = x0;
  r->late_peak_m = std::abs(xs.back());
  r->growth_rate_per_s = std::log(r->late_peak_m / x0) /
                         (static_cast<double>(std::max<std::size_t>(L, 2) - 1) * T);
}

// The sums over the window [a, b) of Q_k = x_k² - x_{k-1} x_{k+1}, of x_k²
// and the largest |x_k| (judge_envelope says why Q).
double window_sum_q(const std::vector<double>& xs, std::size_t a,
                    std::size_t b) {
  double s = 0.0;
  for (std::size_t k = a; k < b; ++k) {
    s += xs[k] * xs[k] - xs[k - 1] * xs[k + 1];
  }
  return s;
}
double window_sum_x2(const std::vector<double>& xs, std::size_t a,
                     std::size_t b) {
  double s = 0.0;
  for (std::size_t k = a; k < b; ++k) s += xs[k] * xs[k];
  return s;
}
double window_peak(const std::vector<double>& xs, std::size_t a,
                   std::size_t b) {
  double s = 0.0;
  for (std::size_t k = a; k < b; ++k) s = std::max(s, std::abs(xs[k]));
  return s;
}

// The envelope of a run that did not diverge, x_k over its ticks at
// stiffness k_N_per_m on mass_kg, period T: its growth rate, whether it
// decays, and the early and late windows' peaks.
//
// For one oscillatory mode x_k = A rho^k cos(k theta + phi)
// the quantity Q_k = x_k² - x_{k-1} x_{k+1} equals A² sin²(theta) rho^{2k}
// exactly: a smooth exponential without the oscillation, so the sum of Q
// over a late window against an early one gives rho even when it is
// within 1e-6 of 1, where peaks of |x| sampled once a tick would be
// swamped by where the samples fall. (The sampled sequence of this linear
// loop is exactly that of a linear discrete system, whatever h is.)
// The loop's other modes, the backward difference's and the delay
// line's, are real or fast and die out within tens of ticks near K_crit;
// the early window starts a third of the way into the run (at least 100
// ticks), after them. Each window is one period of sqrt(K/m) long, at most
// a quarter of the run. If a window's sum is not positive (a mode at
// z = -1, where sin(theta) = 0), the sums of x² are used instead.
void judge_envelope(const std::vector<double>& xs, double k_N_per_m,
                    double mass_kg, double T, WallRun* r) {
  const std::size_t L = xs.size();
  const double period_ticks =
      2.0 * kPi * std::sqrt(mass_kg / std::max(k_N_per_m, 1e-300)) / T;
  const std::size_t W = static_cast<std::size_t>(std::clamp(
      std::round(period_ticks), 10.0, std::floor(static_cast<double>(L) / 4.0)));
  const std::size_t e0 = L / 3, e1 = e0 + W;  // early window [e0, e1)
  const std::size_t l0 = L - 1 - W, l1 = L - 1;  // late window [l0, l1)
  double early = window_sum_q(xs, e0, e1), late = window_sum_q(xs, l0, l1);
  if (!(early > 0.0 && late > 0.0)) {
    early = window_sum_x2(xs, e0, e1);
    late = window_sum_x2(xs, l0, l1);
  }
  const double dk = static_cast<double>(l0) - static_cast<double>(e0);
  // both sums go as rho^{2k}
  r->growth_rate_per_s = std::log(late / early) / (2.0 * dk * T);
  r->stable = late < early;
  r->early_peak_m = window_peak(xs, e0, e1);
  r->late_peak_m = window_peak(xs, l0, l1);
}

}  // namespace

WallRun SliderWall::run(double k_N_per_m, int ticks,
                        std::vector<double>* x_per_tick) {
  if (ticks <= 0) ticks = horizon_ticks(k_N_per_m);
  std::vector<double> xs;
  WallRun r;
  r.k_N_per_m = k_N_per_m;
  run_ticks(k_N_per_m, ticks, &xs, &r);
  throw_if_warned(k_N_per_m);
  if (x_per_tick != nullptr) *x_per_tick = xs;
  if (r.diverged) {
    judge_diverged(xs, p_.servo_period_s, &r);
  } else {
    judge_envelope(xs, k_N_per_m, p_.mass_kg, p_.servo_period_s, &r);
  }
  return r;
}

SimKcrit k_crit_simulated(SliderWall& wall, double k_guess_N_per_m,
                          double rel_tol, const runtime::StopFn& stop) {
  SimKcrit r;
  WallRun at_lo, at_hi;  // the bracket's runs
  auto grows = [&](double k) {
    runtime::throw_if_stop_asked(stop);
    const WallRun run = wall.run(k);
    r.history.push_back(run);
    ++r.runs;
    r.physics_steps +=
        static_cast<long long>(run.ticks) * steps_per_tick(wall.params());
    (run.stable ? at_lo : at_hi) = run;
    return !run.stable;
  };
  // a bracket around the guess, widened until it holds
  double step = 1.03;
  double lo = k_guess_N_per_m / step, hi = k_guess_N_per_m * step;
  bool hi_known = false;
  while (grows(lo)) {
    hi = lo;
    hi_known = true;
    lo /= step;
    step *= step;
    if (lo < 1e-9 * k_guess_N_per_m) return r;  // no stable K found
  }
  if (!hi_known) {
    while (!grows(hi)) {
      lo = hi;
      hi *= step;
      step *= step;
      if (hi > 1e9 * k_guess_N_per_m) {
        throw std::runtime_error("k_crit_simulated: no unstable K found");
      }
    }
  }
  while (hi - lo > rel_tol * lo) {
    const double mid = 0.5 * (lo + hi);
    (grows(mid) ? hi : lo) = mid;
  }
  r.k_stable_N_per_m = lo;
  r.k_unstable_N_per_m = hi;
  // The growth rate is a smooth function of K (the log of the dominant
  // eigenvalue's modulus, over T) measured to many digits, so its zero
  // between the bracket's two runs is a far closer K_crit than the
  // bracket's middle; the middle if a run diverged.
  const double r_lo = at_lo.growth_rate_per_s, r_hi = at_hi.growth_rate_per_s;
  if (!at_hi.diverged && r_lo < 0.0 && r_hi >= 0.0 && r_hi > r_lo) {
    r.k_crit_N_per_m = lo + (hi - lo) * (-r_lo) / (r_hi - r_lo);
    r.interpolated = true;
  } else {
    r.k_crit_N_per_m = 0.5 * (lo + hi);
  }
  return r;
}

StabilityReport study_stability(const std::string& model_path,
                                const StabilityParams& p, double rel_tol,
                                const runtime::StopFn& stop) {
  const auto t0 = std::chrono::steady_clock::now();
  StabilityReport r;
  r.params = p;
  SliderWall wall(model_path, p);  // validates
  r.k_bound_gil_N_per_m = k_bound_gil_N_per_m(p);
  r.k_passivity_N_per_m = k_passivity_N_per_m(p);
  r.exact = k_crit_discrete(p, PlantModel::kExactZoh);
  r.euler = k_crit_discrete(p, PlantModel::kMujocoEuler);
  // the exact discrete value only says where to start looking
  const double guess = r.exact.k_crit_N_per_m > 0.0 ? r.exact.k_crit_N_per_m
                                                    : r.k_bound_gil_N_per_m;
  r.sim = k_crit_simulated(wall, guess, rel_tol, stop);
  r.wall_time_s = std::chrono::duration<double>(
                      std::chrono::steady_clock::now() - t0)
                      .count();
  return r;
}

// ---------------------------------------------------------------- map

std::vector<MapPoint> stability_map(const std::string& model_path,
                                    const MapSpec& spec) {
  std::vector<MapPoint> points;
  std::vector<StabilityParams> params;
  for (int n : spec.delay_ticks) {
    for (double B : spec.virtual_damping_Ns_per_m) {
      StabilityParams p = spec.base;
      p.virtual_damping_Ns_per_m = B;
      p.delay_ticks = n;
      validate(p);  // every point before any runs
      params.push_back(p);
      MapPoint pt;
      pt.virtual_damping_Ns_per_m = B;
      pt.delay_ticks = n;
      points.push_back(pt);
    }
  }
  std::vector<std::exception_ptr> errors(points.size());
  std::atomic<std::size_t> finished{0};
  std::atomic<bool> stopped{false};
  output::parallel_for(points.size(), spec.jobs, [&](std::size_t i) {
    // once stopped, the points not begun are skipped
    if (stopped || runtime::stop_asked(spec.should_stop)) {
      stopped = true;
      return;
    }
    try {
      const StabilityParams& p = params[i];
      MapPoint& pt = points[i];
      pt.k_bound_gil_N_per_m = k_bound_gil_N_per_m(p);
      pt.k_passivity_N_per_m = k_passivity_N_per_m(p);
      pt.k_crit_exact_N_per_m =
          k_crit_discrete(p, PlantModel::kExactZoh).k_crit_N_per_m;
      pt.k_crit_mujoco_euler_N_per_m =
          k_crit_discrete(p, PlantModel::kMujocoEuler).k_crit_N_per_m;
      SliderWall wall(model_path, p);
      const double guess = pt.k_crit_exact_N_per_m > 0.0
                               ? pt.k_crit_exact_N_per_m
                               : pt.k_bound_gil_N_per_m;
      pt.sim = k_crit_simulated(wall, guess, spec.rel_tol, spec.should_stop);
    } catch (const runtime::Interrupted&) {
      stopped = true;
      return;
    } catch (...) {
      errors[i] = std::current_exception();
    }
    if (spec.progress) spec.progress(++finished, points.size());
  });
  if (stopped) throw runtime::Interrupted();
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  return points;
}

StabilityResult run_stability_study(const StabilityOptions& o) {
  StabilityResult r;
  r.options = o;
  if (!r.is_map()) {
    r.bisection = study_stability(o.model_path, o.params, o.rel_tol, o.should_stop);
    SliderWall probe(o.model_path, o.params);
    r.horizon_ticks_at_k_crit = probe.horizon_ticks(r.bisection.sim.k_crit_N_per_m);
    r.wall_time_s = r.bisection.wall_time_s;
  } else {
    MapSpec spec;
    spec.base = o.params;
    spec.virtual_damping_Ns_per_m = o.map_virtual_damping_Ns_per_m;
    spec.delay_ticks = o.map_delay_ticks;
    spec.rel_tol = o.rel_tol;
    spec.jobs = o.jobs;
    spec.progress = o.progress;
    spec.should_stop = o.should_stop;
    const auto t0 = std::chrono::steady_clock::now();
    r.map = stability_map(o.model_path, spec);
    r.wall_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
            .count();
  }
  // the last poll: from here the files go in
  runtime::throw_if_stop_asked(o.should_stop);
  if (!o.out_dir.empty()) r.files = write_stability_files(r, o.out_dir);
  return r;
}

}  // namespace vmh::studies
