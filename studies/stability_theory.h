// The theory of the stability study (studies/stability_study.h): the
// sampled-data virtual wall on the 1-DOF slider (mass m, damping b, servo
// period T, virtual damper B, delay n T, MuJoCo step h) as bounds in closed
// form and as the exact discrete-time loop whose spectral radius gives
// K_crit. No MuJoCo here: the simulation that is checked against it is in
// stability_study.
//
// The theory the simulation is compared with:
//   - Gil, Avello, Rubio and Flórez 2004, "Stability analysis of a 1 DOF
//     haptic interface using the Routh-Hurwitz criterion" (IEEE Trans.
//     Control Systems Technology 12(4)): K < (b + B)/(T/2 + t_d), their
//     approximation of the Routh-Hurwitz condition for a short period. The
//     exact discrete loop (below) puts its error, with no delay, at about
//     +bT/(6m) from b and -BT/m from B (the backward difference's lag on
//     the damper); a delay makes the b term a little larger. So it holds to
//     5% while bT/m and BT/m are small (BT/m < ~0.05); the test says where.
//     The T/2 is the hold's: with the true velocity sampled instead of the
//     backward difference, the exact K_crit is 2(b + B)/T too, to first
//     order (VelocityEstimate::kSampled).
//   - Colgate and Schenkel 1997, "Passivity of a class of sampled-data
//     systems: application to haptic interfaces" (J. Robotic Systems 14(1)):
//     the wall is passive iff b > K T/2 + |B|, i.e. K < 2(b - |B|)/T, which
//     guarantees stability coupled to any passive human and is more
//     conservative than stability of the device alone (Diolaiti et al.
//     2006). Abbott and Okamura 2005 ("Effects of position quantization and
//     sampling rate on virtual-wall passivity", IEEE Trans. Robotics 21(5))
//     add K < 2 f_c/Δ for Coulomb friction f_c and position quantum Δ,
//     neither of which the slider has.
//   - The exact discrete-time loop: the plant m x'' + b x' = F discretised
//     exactly under the zero-order hold, with the backward-difference and
//     delay states; K_crit is where its spectral radius reaches 1.
//
// The simulation converges to the exact loop as h/T -> 0, from above:
// MuJoCo's semi-implicit Euler moves x with the step's new velocity, so the
// held force acts h/2 early and K_crit is higher by about h/((1 + 2n) T)
// (0.1% at the command line's default h = T/1000). The same loop with
// MuJoCo's step as the plant (PlantModel::kMujocoEuler) is what the
// simulation computes, exactly: the two K_crit agree to ~1e-6.
#ifndef VMHAPTICS_STUDIES_STABILITY_THEORY_H_
#define VMHAPTICS_STUDIES_STABILITY_THEORY_H_

#include <Eigen/Core>

#include "sim/mujoco_util.h"

namespace vmh::studies {

// How the controller estimates the velocity for the damper B.
enum class VelocityEstimate {
  kBackwardDifference,  // (x_k - x_{k-1}) / T, as Gil et al. model it
  kSampled,             // the true velocity at t = kT (a tachometer)
};

// One setting of the loop, SI units. K is not here: it is what is searched.
struct StabilityParams {
  double mass_kg = 0.0;                   // m   (--mass)
  double damping_Ns_per_m = 0.0;          // b   (--damping), >= 0
  double servo_period_s = 0.0;            // T   (--servo-period)
  double virtual_damping_Ns_per_m = 0.0;  // B   (--virtual-damping), >= 0
  int delay_ticks = 0;                    // n   (--delay-ticks), t_d = n T
  double physics_step_s = 0.0;            // h   (--physics-step); T = N h
  VelocityEstimate velocity = VelocityEstimate::kBackwardDifference;
};

// Throws SimError naming the command-line option when a value is out of
// range: m > 0, b >= 0, T in [1e-5, 1] s, B >= 0, b + B > 0 (else no K is stable),
// 0 <= n <= kStudyMaxDelayTicks, 0 < h <= T with T a whole multiple of h (to
// 1e-9 relative), and at most kMaxStepsPerTick steps per tick.
void validate(const StabilityParams& p);
inline constexpr int kStudyMaxDelayTicks = 20;
// The servo periods the study takes, those of the case parameter
// servo_period_s: a period of 1e-12 s ran for ever, one of 1e308 s
// "found" K_crit = 0 (issue 17)
inline constexpr double kStudyMinServoPeriod_s = 1e-5;
inline constexpr double kStudyMaxServoPeriod_s = 1.0;
inline constexpr int kMaxStepsPerTick = 100000;

// T / h, the MuJoCo steps per servo tick (p validated).
int steps_per_tick(const StabilityParams& p);

// ---------------------------------------------------------------- theory

// Gil et al. 2004: (b + B) / (T/2 + n T).
double k_bound_gil_N_per_m(const StabilityParams& p);

// Colgate and Schenkel 1997: 2 (b - B) / T (B >= 0); <= 0 when B >= b, i.e.
// no stiffness is passive.
double k_passivity_N_per_m(const StabilityParams& p);

// How the plant is discretised over one servo period with the force held.
enum class PlantModel {
  kExactZoh,     // m x'' + b x' = F solved exactly over T (closed form)
  kMujocoEuler,  // N = T/h steps of MuJoCo's Euler with implicit damping:
                 // v' = (m v + h F) / (m + h b), x' = x + h v'
};

// The closed loop's one-tick transition matrix for the state
// [x_k, v_k, x_{k-1}, u_{k-1}, ..., u_{k-n}] (u_j: the force computed at
// tick j), for stiffness K.
Eigen::MatrixXd closed_loop_matrix(const StabilityParams& p, double k_N_per_m,
                                   PlantModel plant = PlantModel::kExactZoh);

// Largest |eigenvalue| of closed_loop_matrix (Eigen::EigenSolver).
double spectral_radius(const StabilityParams& p, double k_N_per_m,
                       PlantModel plant = PlantModel::kExactZoh);

struct DiscreteKcrit {
  double k_crit_N_per_m = 0.0;  // 0 if no K > 0 is stable
  int iterations = 0;           // eigenvalue evaluations
};

// The K at which the spectral radius reaches 1, by bisection to a relative
// `rel_tol`: the smallest K above which the loop is unstable, searched from
// K -> 0+ (where the free slider's integrator pole at z = 1 moves inside
// the unit circle) upward. Assumes one crossing, as for this loop.
DiscreteKcrit k_crit_discrete(const StabilityParams& p,
                              PlantModel plant = PlantModel::kExactZoh,
                              double rel_tol = 1e-9);


}  // namespace vmh::studies

#endif  // VMHAPTICS_STUDIES_STABILITY_THEORY_H_
