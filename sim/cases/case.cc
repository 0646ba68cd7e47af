#include "sim/cases/case.h"

#include <cmath>
#include <stdexcept>

#include "sim/cases/case_params_detail.h"

namespace vmh::sim {
namespace {

// a number in a message: %g-style, 9 significant digits (1e-07, 0.001)
std::string case_num(double v) { return detail::format_number(v); }

IntegratorSetting integrator_of(const mjModel& m, IntegratorSetting set) {
  if (set != IntegratorSetting::kScene) return set;
  switch (m.opt.integrator) {
    case mjINT_RK4: return IntegratorSetting::kRk4;
    case mjINT_IMPLICIT: return IntegratorSetting::kImplicit;
    default: return IntegratorSetting::kEuler;
  }
}

// The run's physics step and counts, refused as the file comment says.
// Every count is computed in double, checked against its bound and only
// then made an integer; the table's ranges (sim/cases/case_fields.cc) have
// already refused non-finite values, T outside [1e-5, 1] s and a duration
// outside (0, 3600] s.
CaseTiming read_timing(const std::string& path, const mjModel& m,
                       const CaseConfig& config) {
  CaseTiming t;
  const SimSettings& sim = config.sim;
  t.integrator = integrator_of(m, sim.integrator);
  const double h = sim.physics_step_s > 0.0 ? sim.physics_step_s : m.opt.timestep;
  t.step_s = h;
  const double T = config.controller.servo_period_s;
  const std::string step_name = sim.physics_step_s > 0.0
                                    ? "physics_step_s"
                                    : "the scene's <option timestep>";
  if (!std::isfinite(h) || !(h > 0.0)) {
    throw SimError(path + ": " + step_name + " must be finite and > 0, got " +
                   case_num(h) + " s");
  }
  const double n = std::round(T / h);
  if (!(n >= 1.0 && n <= static_cast<double>(kMaxSubstepsPerTick))) {
    throw SimError(path + ": servo_period_s / " + step_name + " (" +
                   case_num(T) + " s / " + case_num(h) +
                   " s) must be a whole number of physics steps in [1, " +
                   std::to_string(kMaxSubstepsPerTick) + "], got " +
                   case_num(T / h));
  }
  if (std::abs(n * h - T) > 1e-9 * T) {
    throw SimError(path + ": servo_period_s (" + case_num(T) +
                   " s) must be a whole multiple of the physics step (" +
                   case_num(h) + " s)");
  }
  t.substeps = static_cast<int>(n);
  const double duration_s = sim.duration_s;
  const double ticks = std::round(duration_s / T);
  if (!(ticks >= 1.0 && ticks <= static_cast<double>(kMaxTicksPerRun))) {
    throw SimError(path + ": duration_s (" + case_num(duration_s) +
                   " s) must last from 1 to " +
                   std::to_string(kMaxTicksPerRun) +
                   " servo periods (servo_period_s = " + case_num(T) +
                   " s), got " + case_num(duration_s / T));
  }
  t.ticks_per_run = static_cast<std::int64_t>(ticks);

  // servo jitter: each tick's period drawn from [min, max] in whole steps
  t.jitter_lo = t.jitter_hi = t.substeps;
  const double jitter_s[2] = {sim.jitter_min_s, sim.jitter_max_s};
  if (!(jitter_s[1] > 0.0)) return t;
  t.jitter = true;
  const double steps[2] = {std::round(jitter_s[0] / h),
                           std::round(jitter_s[1] / h)};
  if (steps[0] < 1.0) {
    throw SimError(path + ": servo_jitter_s's shortest period (" +
                   case_num(jitter_s[0]) +
                   " s) is less than one physics step (" + case_num(h) +
                   " s)");
  }
  if (!(steps[1] <= static_cast<double>(kMaxSubstepsPerTick))) {
    throw SimError(path + ": servo_jitter_s's longest period / the physics "
                   "step (" + case_num(jitter_s[1]) + " s / " + case_num(h) +
                   " s) must be at most " +
                   std::to_string(kMaxSubstepsPerTick) +
                   " physics steps, got " + case_num(jitter_s[1] / h));
  }
  // the periods are drawn in whole physics steps: ends that are not whole
  // steps would be moved without a word
  for (double end_s : jitter_s) {
    if (std::abs(std::round(end_s / h) * h - end_s) > 1e-9 * end_s) {
      throw SimError(path + ": servo_jitter_s (" + case_num(end_s) +
                     " s) must be a whole multiple of the physics step (" +
                     case_num(h) + " s); set physics_step_s");
    }
  }
  t.jitter_lo = static_cast<int>(steps[0]);
  t.jitter_hi = static_cast<int>(steps[1]);
  return t;
}

}  // namespace

Case make_case(const std::string& path, const mjModel& m,
               const std::vector<std::string>& overrides) {
  CaseConfig config = CaseConfig::from_model(&m, path, overrides);
  // the timing first, then the controller: the order in which a loop
  // refused them before it read its case here
  const CaseTiming timing = read_timing(path, m, config);
  ControllerParams controller = case_controller_params(config);
  try {
    controller.validate();
  } catch (const std::invalid_argument& e) {
    throw SimError(path + ": " + e.what());
  }
  HandScript script(config, controller.vm);
  return Case(path, std::move(config), std::move(controller),
              std::move(script), timing);
}

Case Case::with_gains_scaled(double scale) const {
  if (!std::isfinite(scale) || !(scale > 0.0)) {
    throw SimError(path_ + ": a gain scale must be finite and > 0, got " +
                   case_num(scale));
  }
  CaseConfig config = config_;
  ControllerSettings& k = config.controller;
  k.k_pos_N_per_mm *= scale;
  k.k_ornt_multiple *= scale;  // K_ornt = multiple x 2 pi L (eq. 3.28)
  k.k_vel_Ns_per_mm *= scale;
  k.k_vel_ornt_Nmms_per_rad *= scale;
  ControllerParams controller = case_controller_params(config);
  try {
    controller.validate();
  } catch (const std::invalid_argument& e) {
    throw SimError(path_ + ": " + e.what());
  }
  // the script follows the mechanism, not the gains
  return Case(path_, std::move(config), std::move(controller), script_, t_);
}

Case load_case(const std::string& path,
               const std::vector<std::string>& overrides,
               const ModelHook& model_hook) {
  ModelPtr m = load_model_headless(path);
  if (model_hook) model_hook(m.get());
  return make_case(path, *m, overrides);
}

}  // namespace vmh::sim
