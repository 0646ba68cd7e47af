#include "studies/precision_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <memory>
#include <thread>

#include <time.h>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "sim/cases/case.h"
#include "sim/closed_loop.h"
#include "sim/mujoco_util.h"
#include "studies/study_numbers.h"

namespace vmh::studies {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace {

using detail::exact;
using detail::thread_cpu_s;

using Clock = std::chrono::steady_clock;

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// What a run leaves behind, one entry per servo tick, sampled at the end of
// the tick (t = (k + 1) T): the start state is the same for every run.
struct Trajectory {
  std::vector<Vec3> p_mm;       // true wrist centre, device frame
  std::vector<Vec3> axis;       // true stylus axis, device frame, unit
  std::vector<Vec3> tau_Nm;     // motor torques the controller commanded
  std::vector<int> status;
  std::vector<int> iterations;  // placement iterations
  int substeps = 0;
  int mujoco_warnings = 0;
  bool finite = true;
  double wall_time_s = 0.0;     // the fastest repeat
  double cpu_time_s = 0.0;      // the thread's CPU time, least of the repeats
  int repeats = 0;
};

int warning_count(const mjData* d) {
  int n = 0;
  for (int i = 0; i < mjNWARNING; ++i) n += d->warning[i].number;
  return n;
}

std::vector<std::string> run_overrides(const PrecisionOptions& o,
                                       Integrator integrator, double step_s) {
  std::vector<std::string> sets = o.overrides;
  sets.push_back("quantize=0");
  sets.push_back(std::string("integrator=") + integrator_name(integrator));
  sets.push_back("physics_step_s=" + exact(step_s));
  return sets;
}

// One loop, run for `ticks` servo ticks; repeated (from reset()) while the
// repeats took less than min_timing_s, up to max_repeats, and the fastest
// repeat's time kept. Every repeat samples the trajectory the same way (a
// forward kinematics per tick, well under 1% of a tick) and must reproduce
// the first one exactly (MuJoCo and the controller are deterministic), else
// SimError.
Trajectory run_loop(ClosedLoop* loop, int ticks, double min_timing_s,
                    int max_repeats, const runtime::StopFn& stop) {
  const OmniParams& omni = loop->controller_params().omni;
  const std::size_t n = static_cast<std::size_t>(ticks);
  Trajectory tr, again;
  for (Trajectory* t : {&tr, &again}) {
    t->p_mm.resize(n);
    t->axis.resize(n);
    t->tau_Nm.resize(n);
    t->status.resize(n);
    t->iterations.resize(n);
  }
  tr.substeps = loop->substeps();

  TickRecord row;
  double spent_s = 0.0;
  double best_s = std::numeric_limits<double>::infinity();
  double best_cpu_s = std::numeric_limits<double>::infinity();
  for (int rep = 0; rep < std::max(1, max_repeats); ++rep) {
    if (rep > 0 && spent_s >= min_timing_s) break;
    Trajectory& t = rep == 0 ? tr : again;
    loop->reset();
    const auto t0 = Clock::now();
    const double cpu0 = thread_cpu_s();
    for (std::size_t k = 0; k < n; ++k) {
      // every 64 ticks: a poll per tick would be timed with the rung
      if ((k & 63u) == 0) runtime::throw_if_stop_asked(stop);
      loop->tick(&row);
      const OmniPose pose = omni_fk(omni, loop->device().true_q_dh());
      t.p_mm[k] = base_to_device_mm(omni, pose.p_base_m);
      t.axis[k] = base_to_device_vector(pose.R_base.col(2));
      t.tau_Nm[k] = row.out.tau_motor_Nm;
      t.status[k] = row.out.status;
      t.iterations[k] = row.out.placement_iterations;
    }
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    spent_s += dt;
    best_s = std::min(best_s, dt);
    best_cpu_s = std::min(best_cpu_s, thread_cpu_s() - cpu0);
    ++tr.repeats;
    if (rep == 0) {
      tr.mujoco_warnings = warning_count(loop->data());
      for (const Vec3& p : tr.p_mm) tr.finite &= p.allFinite();
      tr.finite &= tr.mujoco_warnings == 0;
      // a run that blew up is not timed again
      if (!tr.finite) break;
    } else if (again.p_mm != tr.p_mm || again.tau_Nm != tr.tau_Nm) {
      throw SimError(loop->config().scene_path() +
                     ": a repeated run did not reproduce the first");
    }
  }
  tr.wall_time_s = best_s;
  tr.cpu_time_s = best_cpu_s;
  return tr;
}

// Every run of the study solves the constraints with Newton, whatever the
// scene asks for: the study measures the integrator's error, and Newton
// solves the scenes' few friction and limit rows exactly (to rounding),
// while PGS, which the case scenes use for speed, stops on a tolerance.
// Its residual, summed over the hundreds of thousands of steps of a fine
// rung, would put a floor near 1e-6 mm under every error below 0.5 ms and
// hide RK4's convergence (docs/numerics.md, "The constraint solver").
void exact_constraint_solve(mjModel* m) { m->opt.solver = mjSOL_NEWTON; }

Trajectory run_setting(const PrecisionOptions& o, Integrator integrator,
                       double step_s, int ticks, double min_timing_s,
                       int max_repeats) {
  ClosedLoop loop(o.scene, run_overrides(o, integrator, step_s),
                  exact_constraint_solve);
  return run_loop(&loop, ticks, min_timing_s, max_repeats, o.should_stop);
}

TrajectoryError compare(const Trajectory& run, const Trajectory& ref) {
  TrajectoryError e;
  const std::size_t n = std::min(run.p_mm.size(), ref.p_mm.size());
  double sum_p = 0.0, sum_a = 0.0, sum_t = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double dp = (run.p_mm[k] - ref.p_mm[k]).norm();
    const double cos_a = std::clamp(run.axis[k].dot(ref.axis[k]), -1.0, 1.0);
    // atan2 of |a x b| and a.b: accurate at small angles, unlike acos
    const double da = std::atan2(run.axis[k].cross(ref.axis[k]).norm(), cos_a);
    const double dt = (run.tau_Nm[k] - ref.tau_Nm[k]).norm() * 1e3;
    sum_p += dp * dp;
    sum_a += da * da;
    sum_t += dt * dt;
    e.max_mm = std::max(e.max_mm, dp);
    e.max_axis_rad = std::max(e.max_axis_rad, da);
    if (run.status[k] != ref.status[k]) ++e.status_mismatch_ticks;
    if (run.iterations[k] != ref.iterations[k]) ++e.iteration_mismatch_ticks;
  }
  const double nn = std::max<double>(1.0, static_cast<double>(n));
  e.rms_mm = std::sqrt(sum_p / nn);
  e.rms_axis_rad = std::sqrt(sum_a / nn);
  e.rms_torque_mNm = std::sqrt(sum_t / nn);
  e.finite = run.finite && std::isfinite(e.rms_mm);
  if (!e.finite) {
    e.rms_mm = e.max_mm = e.rms_axis_rad = e.max_axis_rad = kNaN;
  }
  return e;
}

// the test ClosedLoop's loader applies (sim/closed_loop.cc)
bool divides_servo_period(double step_s, double period_s) {
  const double n = std::round(period_s / step_s);
  return n >= 1.0 && std::abs(n * step_s - period_s) <= 1e-9 * period_s;
}

bool same_step(double a, double b) {
  return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b));
}

}  // namespace

const char* integrator_name(Integrator i) {
  switch (i) {
    case Integrator::kEuler: return "euler";
    case Integrator::kImplicit: return "implicit";
    case Integrator::kRk4: return "rk4";
  }
  return "unknown";
}

bool parse_integrator(const std::string& name, Integrator* out) {
  for (Integrator i :
       {Integrator::kEuler, Integrator::kImplicit, Integrator::kRk4}) {
    if (name == integrator_name(i)) {
      *out = i;
      return true;
    }
  }
  return false;
}

OrderFit fit_order(const std::vector<double>& steps_s,
                   const std::vector<double>& errors) {
  OrderFit f;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (std::size_t i = 0; i < steps_s.size() && i < errors.size(); ++i) {
    if (!(steps_s[i] > 0.0) || !(errors[i] > 0.0) ||
        !std::isfinite(errors[i])) {
      continue;
    }
    const double x = std::log10(steps_s[i]);
    const double y = std::log10(errors[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    ++n;
    f.steps_used_s.push_back(steps_s[i]);
  }
  f.points = n;
  const double den = n * sxx - sx * sx;
  if (n < 2 || den <= 0.0) {
    f.order = f.log10_coefficient = kNaN;
    return f;
  }
  f.order = (n * sxy - sx * sy) / den;
  f.log10_coefficient = (sy - f.order * sx) / n;
  return f;
}

std::vector<bool> pareto_front(const std::vector<double>& x,
                               const std::vector<double>& y) {
  const std::size_t n = std::min(x.size(), y.size());
  std::vector<bool> front(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    bool dominated = false;
    for (std::size_t j = 0; j < n && !dominated; ++j) {
      if (j == i || !std::isfinite(x[j]) || !std::isfinite(y[j])) continue;
      dominated = x[j] <= x[i] && y[j] <= y[i] && (x[j] < x[i] || y[j] < y[i]);
    }
    front[i] = !dominated;
  }
  return front;
}

namespace {

// One setting of the ladder.
struct Setting {
  Integrator integrator;
  double step_s;
};

// The scene's own setting (integrator, step, servo period) and script
// segments, read from a loop built once, and the duration checked against
// the case's script.
void probe_scene(const PrecisionOptions& o, PrecisionResult* r) {
  const sim::Case probe = sim::load_case(o.scene, o.overrides);
  r->servo_period_s = probe.controller_params().servo_period_s;
  r->default_step_s = probe.physics_step_s();
  switch (probe.integrator()) {
    case sim::IntegratorSetting::kRk4: r->default_integrator = Integrator::kRk4; break;
    case sim::IntegratorSetting::kImplicit:
      r->default_integrator = Integrator::kImplicit;
      break;
    default: r->default_integrator = Integrator::kEuler; break;
  }
  for (const ScriptSegment& seg : probe.script().segments()) {
    if (seg.t0_s < o.duration_s) r->segments.push_back(seg);
  }
  const double script_s = probe.config().sim.duration_s;
  if (!(o.duration_s > 0.0) || o.duration_s > script_s + 1e-12) {
    throw SimError(o.scene + ": the study's duration (" +
                   exact(o.duration_s) + " s) must be > 0 and at most the "
                   "case's duration_s (" + exact(script_s) + " s)");
  }
}

// The ladder per integrator, largest step first, the scene's own step added
// for its own integrator; every step checked against the reference step
// and the servo period (the loader would refuse one that does not divide
// it), and the references' steps likewise.
std::vector<Setting> ladder(const PrecisionOptions& o, const PrecisionResult& r) {
  std::vector<Setting> settings;
  for (Integrator i : o.integrators) {
    std::vector<double> steps = o.steps_s;
    if (i == r.default_integrator &&
        std::none_of(steps.begin(), steps.end(), [&](double h) {
          return same_step(h, r.default_step_s);
        })) {
      steps.push_back(r.default_step_s);
    }
    std::sort(steps.begin(), steps.end(), std::greater<double>());
    steps.erase(std::unique(steps.begin(), steps.end(), same_step), steps.end());
    for (double h : steps) {
      if (!(h > o.reference_step_s)) {
        throw SimError("the ladder's step " + exact(h) +
                       " s is not above the reference step " +
                       exact(o.reference_step_s) + " s");
      }
      settings.push_back({i, h});
    }
  }
  for (const Setting& s : settings) {
    if (!divides_servo_period(s.step_s, r.servo_period_s)) {
      throw SimError("the physics step " + exact(s.step_s) +
                     " s does not divide the servo period " +
                     exact(r.servo_period_s) + " s");
    }
  }
  for (double h : {o.reference_step_s, o.reference_check_step_s}) {
    if (!divides_servo_period(h, r.servo_period_s)) {
      throw SimError("the reference step " + exact(h) +
                     " s does not divide the servo period " +
                     exact(r.servo_period_s) + " s");
    }
  }
  return settings;
}

// The two references, side by side (each loop has its own thread, and its
// hand is registered for its own mjData); the check bounds the
// reference's own error, which sets the fit's floor.
Trajectory run_references(const PrecisionOptions& o, PrecisionResult* r) {
  Trajectory ref, ref_check;
  std::exception_ptr failure;
  std::thread check_thread([&] {
    try {
      ref_check = run_setting(o, Integrator::kRk4, o.reference_check_step_s,
                              r->ticks, 0.0, 1);
    } catch (...) {
      failure = std::current_exception();
    }
  });
  try {
    ref = run_setting(o, Integrator::kRk4, o.reference_step_s, r->ticks, 0.0, 1);
  } catch (...) {
    check_thread.join();
    throw;
  }
  check_thread.join();
  if (failure) std::rethrow_exception(failure);
  if (!ref.finite) {
    throw SimError(o.scene + ": the reference run blew up (MuJoCo warnings: " +
                   std::to_string(ref.mujoco_warnings) + ")");
  }
  r->reference.step_s = o.reference_step_s;
  r->reference.check_step_s = o.reference_check_step_s;
  r->reference.wall_time_s = ref.wall_time_s;
  r->reference.check_wall_time_s = ref_check.wall_time_s;
  r->reference.self_error = compare(ref_check, ref);
  r->floor_mm = kFloorFactor * r->reference.self_error.rms_mm;
  return ref;
}

// One rung of the ladder against the reference.
PrecisionRow run_rung(const PrecisionOptions& o, const Setting& s,
                      const Trajectory& ref, const PrecisionResult& r) {
  const double simulated_s = r.ticks * r.servo_period_s;
  const Trajectory tr = run_setting(o, s.integrator, s.step_s, r.ticks,
                                    o.min_timing_s, o.max_repeats);
  PrecisionRow row;
  row.integrator = s.integrator;
  row.step_s = s.step_s;
  row.substeps = tr.substeps;
  row.error = compare(tr, ref);
  row.wall_time_s = tr.wall_time_s;
  row.cpu_time_s = tr.cpu_time_s;
  row.repeats = tr.repeats;
  row.steps_per_s =
      static_cast<double>(r.ticks) * tr.substeps / std::max(tr.wall_time_s, 1e-12);
  row.realtime_factor = simulated_s / std::max(tr.wall_time_s, 1e-12);
  row.is_default = s.integrator == r.default_integrator &&
                   same_step(s.step_s, r.default_step_s);
  row.mujoco_warnings = tr.mujoco_warnings;
  row.local_order = kNaN;
  return row;
}

// Local orders, and the fitted order per integrator over the rungs above
// the floor.
void fit_orders(const std::vector<Integrator>& integrators, PrecisionResult* r) {
  for (Integrator i : integrators) {
    std::vector<double> hs, es;
    const PrecisionRow* prev = nullptr;
    for (PrecisionRow& row : r->rows) {
      if (row.integrator != i) continue;
      if (prev != nullptr && row.error.finite && prev->error.finite &&
          row.error.rms_mm > 0.0 && prev->error.rms_mm > 0.0) {
        row.local_order = std::log(prev->error.rms_mm / row.error.rms_mm) /
                          std::log(prev->step_s / row.step_s);
      }
      prev = &row;
      row.used_in_fit = row.error.finite && row.error.rms_mm > r->floor_mm;
      if (row.used_in_fit) {
        hs.push_back(row.step_s);
        es.push_back(row.error.rms_mm);
      }
    }
    OrderFit fit = fit_order(hs, es);
    fit.integrator = i;
    r->fits.push_back(fit);
  }
}

// The Pareto fronts of (wall time, error) and (CPU time, error).
void mark_fronts(PrecisionResult* r) {
  std::vector<double> wall, cpu, err;
  for (const PrecisionRow& row : r->rows) {
    wall.push_back(row.wall_time_s);
    cpu.push_back(row.cpu_time_s);
    err.push_back(row.error.finite ? row.error.rms_mm : kNaN);
  }
  const std::vector<bool> front = pareto_front(wall, err);
  const std::vector<bool> front_cpu = pareto_front(cpu, err);
  for (std::size_t k = 0; k < r->rows.size(); ++k) {
    r->rows[k].on_front = front[k];
    r->rows[k].on_front_cpu = front_cpu[k];
  }
}

}  // namespace

PrecisionResult run_precision_study(const PrecisionOptions& o) {
  const auto study_start = Clock::now();
  PrecisionResult r;
  r.name = o.name;
  r.scene = o.scene;
  r.duration_s = o.duration_s;
  r.modelling_spread = o.modelling_spread;

  // every check before the first run
  probe_scene(o, &r);
  r.ticks = static_cast<int>(std::llround(o.duration_s / r.servo_period_s));
  if (r.ticks < 1) throw SimError("the study's duration is under one servo tick");
  if (o.integrators.empty()) throw SimError("no integrator to study");
  if (!(o.reference_step_s > 0.0) ||
      !(o.reference_check_step_s > o.reference_step_s)) {
    throw SimError("the reference step must be > 0 and below the check step");
  }
  const std::vector<Setting> settings = ladder(o, r);

  const std::size_t runs = settings.size() + 1;
  if (o.progress) o.progress(0, runs);
  const Trajectory ref = run_references(o, &r);
  if (o.progress) o.progress(1, runs);
  // the ladder, one run at a time, so that the timings do not compete
  for (const Setting& s : settings) {
    runtime::throw_if_stop_asked(o.should_stop);
    r.rows.push_back(run_rung(o, s, ref, r));
    if (o.progress) o.progress(r.rows.size() + 1, runs);
  }
  fit_orders(o.integrators, &r);
  mark_fronts(&r);

  r.study_wall_time_s =
      std::chrono::duration<double>(Clock::now() - study_start).count();
  // the last poll: from here the files go in
  runtime::throw_if_stop_asked(o.should_stop);
  if (!o.out_dir.empty()) r.files = write_precision_files(r, o.out_dir);
  return r;
}

}  // namespace vmh::studies
