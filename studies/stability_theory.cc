#include "studies/stability_theory.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "controller/types.h"
#include "output/number_text.h"

namespace vmh::studies {
// the testbed's types (sim/) by their own names in this file
using namespace vmh::sim;  // NOLINT(build/namespaces)
namespace {

using constants::kPi;

// ten significant digits, for the messages
std::string str(double v) { return output::significant(v, 10); }

// "--option: what (got v)"
[[noreturn]] void bad(const std::string& option, const std::string& what,
                      double got) {
  throw SimError(option + ": " + what + " (got " + str(got) + ")");
}

// The plant over one servo period with the force F held:
//   [x, v]_{k+1} = A [x, v]_k + Bf F.
struct PlantStep {
  Eigen::Matrix2d A;
  Eigen::Vector2d Bf;
};

// m x'' + b x' = F solved exactly over T. With z = bT/m and e = exp(-z):
//   v(T) = e v + (1 - e)/b F
//   x(T) = x + (1 - e) m/b v + (T - (1 - e) m/b) F/b,
// written with phi1 = (1 - e) m/b = T (1 - e)/z and
// (T - phi1) m/b = T² g(z), g(z) = (z - 1 + e)/z², each evaluated without
// cancellation for small z (and so b = 0, where phi1 = T, g = 1/2).
PlantStep exact_zoh(const StabilityParams& p) {
  const double m = p.mass_kg, T = p.servo_period_s;
  const double z = p.damping_Ns_per_m * T / m;
  const double e = std::exp(-z);
  const double phi1_over_T = z < 1e-8 ? 1.0 - 0.5 * z : -std::expm1(-z) / z;
  const double g = z < 1e-3
                       ? 0.5 - z / 6.0 + z * z / 24.0 - z * z * z / 120.0
                       : (z + std::expm1(-z)) / (z * z);
  PlantStep s;
  s.A << 1.0, T * phi1_over_T, 0.0, e;
  s.Bf << T * T * g / m, T * phi1_over_T / m;
  return s;
}

// N steps of MuJoCo's Euler integrator with the joint damping implicit
// (mj_Euler: qacc solved with M + h D): v' = (m v + h F)/(m + h b), then
// x' = x + h v'.
PlantStep mujoco_euler(const StabilityParams& p) {
  const double m = p.mass_kg, h = p.physics_step_s;
  const double c = m / (m + h * p.damping_Ns_per_m);
  Eigen::Matrix2d As;
  As << 1.0, h * c, 0.0, c;
  const Eigen::Vector2d Bs(h * h / (m + h * p.damping_Ns_per_m),
                           h / (m + h * p.damping_Ns_per_m));
  PlantStep s;
  s.A.setIdentity();
  s.Bf.setZero();
  for (int i = 0, n = steps_per_tick(p); i < n; ++i) {
    s.A = As * s.A;
    s.Bf = As * s.Bf + Bs;
  }
  return s;
}

}  // namespace

void validate(const StabilityParams& p) {
  if (!std::isfinite(p.mass_kg) || !(p.mass_kg > 0.0)) {
    bad("--mass", "the slider's mass must be > 0 kg", p.mass_kg);
  }
  if (!std::isfinite(p.damping_Ns_per_m) || p.damping_Ns_per_m < 0.0) {
    bad("--damping", "the physical damping b must be >= 0 N s/m",
        p.damping_Ns_per_m);
  }
  if (!(p.servo_period_s >= kStudyMinServoPeriod_s &&
        p.servo_period_s <= kStudyMaxServoPeriod_s)) {
    bad("--servo-period", "the servo period T must be in [1e-05, 1] s",
        p.servo_period_s);
  }
  if (!std::isfinite(p.virtual_damping_Ns_per_m) ||
      p.virtual_damping_Ns_per_m < 0.0) {
    bad("--virtual-damping", "the virtual damping B must be >= 0 N s/m",
        p.virtual_damping_Ns_per_m);
  }
  if (!(p.damping_Ns_per_m + p.virtual_damping_Ns_per_m > 0.0)) {
    throw SimError(
        "--damping, --virtual-damping: b + B must be > 0 N s/m (with no "
        "damping at all no stiffness is stable, K_crit = 0)");
  }
  if (p.delay_ticks < 0 || p.delay_ticks > kStudyMaxDelayTicks) {
    bad("--delay-ticks",
        "the delay must be 0.." + std::to_string(kStudyMaxDelayTicks) + " ticks",
        p.delay_ticks);
  }
  const double h = p.physics_step_s, T = p.servo_period_s;
  if (!std::isfinite(h) || !(h > 0.0) || h > T * (1.0 + 1e-9)) {
    bad("--physics-step",
        "the physics step h must be > 0 s and at most the servo period " +
            str(T) + " s",
        h);
  }
  const double ratio = T / h;
  if (ratio > kMaxStepsPerTick + 0.5) {
    throw SimError("--physics-step: at most " +
                   std::to_string(kMaxStepsPerTick) +
                   " physics steps per servo period (T/h = " + str(ratio) +
                   ")");
  }
  if (std::abs(ratio - std::round(ratio)) > 1e-9 * ratio) {
    throw SimError("--physics-step: the servo period T = " + str(T) +
                   " s must be a whole multiple of the physics step h = " +
                   str(h) + " s (T/h = " + str(ratio) + ")");
  }
}

int steps_per_tick(const StabilityParams& p) {
  return static_cast<int>(std::lround(p.servo_period_s / p.physics_step_s));
}

// ---------------------------------------------------------------- theory

double k_bound_gil_N_per_m(const StabilityParams& p) {
  const double T = p.servo_period_s;
  return (p.damping_Ns_per_m + p.virtual_damping_Ns_per_m) /
         (0.5 * T + p.delay_ticks * T);
}

double k_passivity_N_per_m(const StabilityParams& p) {
  return 2.0 * (p.damping_Ns_per_m - std::abs(p.virtual_damping_Ns_per_m)) /
         p.servo_period_s;
}

Eigen::MatrixXd closed_loop_matrix(const StabilityParams& p, double k_N_per_m,
                                   PlantModel plant) {
  const PlantStep s =
      plant == PlantModel::kExactZoh ? exact_zoh(p) : mujoco_euler(p);
  const int n = p.delay_ticks;
  const int dim = 3 + n;
  const double BT = p.virtual_damping_Ns_per_m / p.servo_period_s;
  // the force computed this tick from the state: u_k = -K x_k - B/T (x_k -
  // x_{k-1})
  // (or -K x_k - B v_k with the sampled velocity)
  Eigen::RowVectorXd u_now = Eigen::RowVectorXd::Zero(dim);
  if (p.velocity == VelocityEstimate::kSampled) {
    u_now(0) = -k_N_per_m;
    u_now(1) = -p.virtual_damping_Ns_per_m;
  } else {
    u_now(0) = -k_N_per_m - BT;
    u_now(2) = BT;
  }
  // the force applied over this tick: u_k itself, or u_{k-n}
  Eigen::RowVectorXd f = Eigen::RowVectorXd::Zero(dim);
  if (n == 0) {
    f = u_now;
  } else {
    f(3 + n - 1) = 1.0;
  }
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(dim, dim);
  M.block(0, 0, 2, 2) = s.A;
  M.row(0) += s.Bf(0) * f;
  M.row(1) += s.Bf(1) * f;
  M(2, 0) = 1.0;  // x_{k-1} <- x_k
  if (n > 0) {
    M.row(3) = u_now;  // u_{k-1} <- u_k
    for (int j = 1; j < n; ++j) M(3 + j, 3 + j - 1) = 1.0;
  }
  return M;
}

double spectral_radius(const StabilityParams& p, double k_N_per_m,
                       PlantModel plant) {
  const Eigen::MatrixXd M = closed_loop_matrix(p, k_N_per_m, plant);
  Eigen::EigenSolver<Eigen::MatrixXd> es(M, false);
  return es.eigenvalues().cwiseAbs().maxCoeff();
}

DiscreteKcrit k_crit_discrete(const StabilityParams& p, PlantModel plant,
                              double rel_tol) {
  validate(p);
  DiscreteKcrit r;
  auto unstable = [&](double k) {
    ++r.iterations;
    return spectral_radius(p, k, plant) >= 1.0;
  };
  const double guess = k_bound_gil_N_per_m(p);
  // just above K = 0 the slider's free-position pole (z = 1) has moved
  // inside by about K T / (b + B): stable unless the damping loop itself
  // is not
  double lo = 1e-6 * guess;
  if (unstable(lo)) return r;
  double hi = 2.0 * guess;
  for (int i = 0; !unstable(hi); ++i) {
    if (i == 60) throw std::runtime_error("k_crit_discrete: no unstable K");
    lo = hi;
    hi *= 2.0;
  }
  while ((hi - lo) > rel_tol * lo) {
    const double mid = 0.5 * (lo + hi);
    (unstable(mid) ? hi : lo) = mid;
  }
  r.k_crit_N_per_m = 0.5 * (lo + hi);
  return r;
}

}  // namespace vmh::studies
