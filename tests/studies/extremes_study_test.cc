// The stiff and extreme cases (studies/extremes_study.h), one test per scenario,
// and the machinery they rest on: the passivity observer against an
// independent sum, the servo jitter's draws and clock, the faults' zero
// torque, and the two instabilities the study names.
//
// Every scenario test re-checks the raw figures (not the study's own
// verdict): no NaN, |F| and |tau| within their limits, no MuJoCo warning,
// the status the scenario must produce, no fault named where none was
// injected, energy bounded where it is required to be, and that the run
// reached the extreme it is named after.
#include "studies/extremes_study.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "controller/device_frame.h"
#include "thesis/run_case.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/constants.h"

namespace vmh::studies {
using namespace vmh::sim;  // NOLINT(build/namespaces): the testbed's types
namespace {

using vmh::testing::kPi;

std::string scene(const char* name) {
  return std::string(VMH_MODELS_DIR) + "/cases/" + name + ".xml";
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
  for (const std::string& x : v) {
    if (x == s) return true;
  }
  return false;
}

const ExtremeScenario& scenario_named(const std::string& name) {
  static const std::vector<ExtremeScenario> table = extreme_scenarios();
  for (const ExtremeScenario& s : table) {
    if (s.name == name) return s;
  }
  throw std::runtime_error("no scenario " + name);
}

std::vector<std::string> scenario_names() {
  std::vector<std::string> names;
  for (const ExtremeScenario& s : extreme_scenarios()) names.push_back(s.name);
  return names;
}

// What each scenario must have reached for its name to be true, measured on
// MuJoCo's true state (ExtremeResult's "reached" figures).
const std::map<std::string, std::function<void(const ExtremeResult&)>>&
reached_checks() {
  static const std::map<std::string, std::function<void(const ExtremeResult&)>> m = {
      {"rm_at_pivot_sphere",
       [](const ExtremeResult& r) { EXPECT_LT(r.min_pivot_distance_mm, 0.1); }},
      {"rm_at_pivot_circle",
       [](const ExtremeResult& r) { EXPECT_LT(r.min_pivot_distance_mm, 0.1); }},
      // within 0.5 mm of the pole at L = 50 mm
      {"sphere_pole_plus_z",
       [](const ExtremeResult& r) { EXPECT_LT(r.min_pole_angle_rad, 0.01); }},
      {"sphere_pole_minus_z",
       [](const ExtremeResult& r) { EXPECT_LT(r.min_pole_angle_rad, 0.01); }},
      {"gimbal_singular",
       [](const ExtremeResult& r) { EXPECT_LT(r.min_q5_to_singular_rad, 0.01); }},
      // full reach is l1 + l2 = 266.7 mm; the range stops q3 at 263.3 mm
      // (0.987); the hand pulls the elbow past it
      {"stretched_arm",
       [](const ExtremeResult& r) { EXPECT_GT(r.max_reach_fraction, 0.987); }},
      {"orientation_error_pi",
       [](const ExtremeResult& r) { EXPECT_GE(r.orientation_wraps, 2); }},
  };
  return m;
}

class ExtremeScenarioTest : public ::testing::TestWithParam<std::string> {
 protected:
  testing::MujocoGuard guard_;
};

TEST_P(ExtremeScenarioTest, EndsFiniteBoundedAndNamed) {
  const ExtremeScenario& s = scenario_named(GetParam());
  const ExtremeResult r = run_extreme(s);
  std::printf("  %-24s %-28s maxF %.3f N  E max %.4g J  rest rise %.3g J  "
              "KE rest %.3g J  %.2f s\n",
              s.name.c_str(), r.outcome.c_str(), r.max_force_N,
              r.energy_motor_max_J, r.rest_energy_rise_J, r.rest_kinetic_max_J,
              r.wall_time_s);
  RecordProperty("outcome", r.outcome);

  // finite, and no MuJoCo warning
  EXPECT_TRUE(r.finite) << r.first_nonfinite;
  EXPECT_EQ(r.mujoco_warnings, 0);
  EXPECT_EQ(testing::MujocoGuard::warnings(), "");
  // the command within its limits
  EXPECT_LE(r.max_force_N, r.force_limit_N * (1.0 + 1e-12));
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(r.max_motor_torque_Nm[i], r.motor_limit_Nm[i] * (1.0 + 1e-12))
        << "motor " << i + 1;
  }
  // the status the scenario must name
  std::vector<std::string> named = r.statuses;
  named.insert(named.end(), r.device_errors.begin(), r.device_errors.end());
  named.insert(named.end(), r.guard_faults.begin(), r.guard_faults.end());
  if (!s.expected.empty()) {
    EXPECT_TRUE(contains(named, s.expected)) << "expected status " << s.expected;
  }
  if (s.injected == "none") {
    EXPECT_TRUE(r.device_errors.empty());
    EXPECT_TRUE(r.guard_faults.empty());
    EXPECT_FALSE(contains(r.statuses, "invalid_input"));
    EXPECT_FALSE(contains(r.statuses, "numerical_fault"));
    EXPECT_EQ(r.zeroed_ticks, 0);
  }
  // energy where it is required to stay bounded
  if (r.energy_expected == "bounded") {
    EXPECT_TRUE(r.energy_bounded)
        << "the observer rose " << r.rest_energy_rise_J << " J at rest";
  }
  // the study agrees with the figures
  EXPECT_TRUE(r.pass()) << r.outcome;
  auto check = reached_checks().find(s.name);
  if (check != reached_checks().end()) check->second(r);
}

INSTANTIATE_TEST_SUITE_P(
    Extremes, ExtremeScenarioTest, ::testing::ValuesIn(scenario_names()),
    [](const ::testing::TestParamInfo<std::string>& param) {
      std::string n = param.param;
      for (char& c : n) {
        if (c == '.') c = '_';
      }
      return n;
    });

// -- faults: what the servo loop sends after each --

TEST(ExtremeFaults, NanZeroesTheTorqueFromTheFaultOn) {
  testing::MujocoGuard guard;
  for (const char* name : {"fault_nan", "fault_nan_unguarded"}) {
    std::vector<TickRecord> rows;
    const ExtremeResult r = run_extreme(scenario_named(name), &rows);
    ASSERT_GE(r.fault_tick, 0) << name;
    EXPECT_EQ(r.detection_tick, r.fault_tick) << name;
    for (std::size_t k = static_cast<std::size_t>(r.fault_tick); k < rows.size(); ++k) {
      const TickRecord& row = rows[k];
      ASSERT_TRUE(row.servo.zeroed) << name << " tick " << k;
      ASSERT_EQ(row.motor_torque_Nm, Vec3::Zero()) << name << " tick " << k;
      if (std::string(name) == "fault_nan") {
        ASSERT_EQ(row.servo.read, DeviceError::kSensorFault);
        ASSERT_EQ(row.guard, GuardFault::kNonFinite);
      } else {
        // the guard off: the reading reaches the controller, which refuses it
        ASSERT_EQ(row.servo.read, DeviceError::kOk);
        ASSERT_TRUE(row.out.status & kStatusInvalidInput);
      }
    }
    // before the fault the loop was pushing
    EXPECT_GT(rows[static_cast<std::size_t>(r.fault_tick) - 1].motor_torque_Nm.norm(), 0.05);
  }
}

TEST(ExtremeFaults, JumpIsDetectedWithinOneTickAndLatches) {
  testing::MujocoGuard guard;
  std::vector<TickRecord> rows;
  const ExtremeResult r = run_extreme(scenario_named("fault_jump"), &rows);
  ASSERT_GE(r.fault_tick, 0);
  ASSERT_GE(r.detection_tick, 0);
  EXPECT_LE(r.detection_tick - r.fault_tick, 1);
  for (std::size_t k = static_cast<std::size_t>(r.detection_tick); k < rows.size(); ++k) {
    ASSERT_EQ(rows[k].guard, GuardFault::kJump) << "tick " << k;
    ASSERT_EQ(rows[k].motor_torque_Nm, Vec3::Zero()) << "tick " << k;
  }
  // the reading the device produced really was 1000 counts off
  const std::size_t f = static_cast<std::size_t>(r.fault_tick);
  const double off = dh_to_device_joints(rows[f].q_dh)[0] -
                     dh_to_device_joints(rows[f].q_true_dh)[0];
  EXPECT_NEAR(off, 1000.0 * 2.0 * kPi / 15000.0, 5.0 * 2.0 * kPi / 15000.0);
}

// A stuck encoder: the reading freezes while the joint moves, nothing names
// it, and the loop stays bounded (the VM pushes at a fixed error, saturated).
TEST(ExtremeFaults, StuckEncoderGoesUnseenButStaysBounded) {
  testing::MujocoGuard guard;
  std::vector<TickRecord> rows;
  const ExtremeResult r = run_extreme(scenario_named("fault_stuck"), &rows);
  ASSERT_GE(r.fault_tick, 0);
  const std::size_t f = static_cast<std::size_t>(r.fault_tick);
  const double frozen = dh_to_device_joints(rows[f].q_dh)[1];
  double true_travel = 0.0;
  for (std::size_t k = f; k < rows.size(); ++k) {
    ASSERT_EQ(dh_to_device_joints(rows[k].q_dh)[1], frozen) << "tick " << k;
    true_travel = std::max(true_travel,
                           std::abs(dh_to_device_joints(rows[k].q_true_dh)[1] - frozen));
  }
  EXPECT_GT(true_travel, 0.05) << "the joint should have moved under the stuck encoder";
  EXPECT_EQ(r.detection_tick, -1);
  EXPECT_EQ(r.zeroed_ticks, 0);
  EXPECT_EQ(r.outcome, "fault_undetected:stuck");
  EXPECT_TRUE(r.energy_bounded);
}

// -- servo jitter --

TEST(ServoJitter, PeriodsLieInTheRangeAndTheClockAddsUp) {
  testing::MujocoGuard guard;
  ClosedLoop loop(scene("case2"), {"servo_jitter_s=0.0004,0.0028",
                                   "physics_step_s=0.0002", "duration_s=2"});
  const double h = loop.model()->opt.timestep;
  ASSERT_EQ(loop.substeps_min(), 2);   // 0.4 ms / 0.2 ms
  ASSERT_EQ(loop.substeps_max(), 14);  // 2.8 ms / 0.2 ms
  TickRecord row;
  double t_sum = 0.0;
  long steps = 0;
  std::set<int> seen;
  int ticks = 0;
  while (!loop.finished()) {
    loop.tick(&row);
    ++ticks;
    EXPECT_NEAR(row.t_s, t_sum, 1e-12) << "tick " << ticks;
    ASSERT_GE(row.period_s, 0.4e-3 - 1e-12);
    ASSERT_LE(row.period_s, 2.8e-3 + 1e-12);
    EXPECT_NEAR(row.period_s, row.substeps * h, 1e-15);
    seen.insert(row.substeps);
    t_sum += row.period_s;
    steps += row.substeps;
  }
  // the run's time is the sum of its periods, and MuJoCo's own clock agrees
  EXPECT_NEAR(loop.time_s(), t_sum, 1e-12);
  EXPECT_NEAR(loop.data()->time, t_sum, 1e-9);
  EXPECT_NEAR(loop.time_s(), static_cast<double>(steps) * h, 1e-12);
  EXPECT_GE(loop.time_s(), 2.0 - 0.5 * h);
  EXPECT_LT(loop.time_s(), 2.0 + 2.8e-3);
  // about 2 s / 1.6 ms ticks, every whole number of steps from 2 to 14 drawn
  EXPECT_EQ(seen.size(), 13u);
  EXPECT_GT(ticks, 1000);
  EXPECT_LT(ticks, 1600);
}

TEST(ServoJitter, TheSeedFixesTheDraws) {
  testing::MujocoGuard guard;
  auto draws = [](const char* seed) {
    ClosedLoop loop(scene("case5"), {"servo_jitter_s=0.0004,0.0028",
                                     "physics_step_s=0.0002", "duration_s=0.2",
                                     std::string("jitter_seed=") + seed});
    std::vector<int> n;
    TickRecord row;
    while (!loop.finished()) {
      loop.tick(&row);
      n.push_back(row.substeps);
    }
    // and reset() starts the same sequence again
    loop.reset();
    loop.tick(&row);
    EXPECT_EQ(row.substeps, n.front());
    return n;
  };
  EXPECT_EQ(draws("3"), draws("3"));
  EXPECT_NE(draws("3"), draws("4"));
}

TEST(ServoJitter, OffKeepsTheFixedPeriod) {
  testing::MujocoGuard guard;
  ClosedLoop loop(scene("case1"), {"duration_s=0.1"});
  EXPECT_FALSE(loop.jitter());
  TickRecord row;
  int k = 0;
  while (!loop.finished()) {
    loop.tick(&row);
    ASSERT_EQ(row.substeps, loop.substeps());
    ASSERT_EQ(row.t_s, k * 1e-3);
    ++k;
  }
  EXPECT_EQ(k, loop.ticks_per_run());
}

TEST(ServoJitter, RejectsARangeBelowOneStep) {
  testing::MujocoGuard guard;
  EXPECT_THROW(ClosedLoop(scene("case1"), {"servo_jitter_s=0.00005,0.001"}), SimError);
  // at the scenes' 1 ms step, 0.4 ms is no whole number of steps
  EXPECT_THROW(ClosedLoop(scene("case1"), {"servo_jitter_s=0.0004,0.0028"}), SimError);
  EXPECT_NO_THROW(ClosedLoop(scene("case1"), {"servo_jitter_s=0.0004,0.0028",
                                              "physics_step_s=0.0002"}));
  EXPECT_THROW(ClosedLoop(scene("case1"), {"servo_jitter_s=0.002,0.001"}), SimError);
  EXPECT_THROW(ClosedLoop(scene("case1"), {"fault=jump", "fault_joint=4"}), SimError);
  EXPECT_THROW(ClosedLoop(scene("case1"), {"fault=glitch"}), SimError);
}

// -- the passivity observer --

// E equals the work of the held motor torques along the true motion,
// summed here from the trace alone through the tendon map of
// controller/device_frame.h (t1 = -q1, t2 = q2, t3 = q2 + q3), and the
// energy balance holds: what the motors and the hand put in, less the
// kinetic energy, is what the joints' damping and friction took out (>= 0).
TEST(PassivityObserver, IsTheWorkOfTheHeldTorquesAlongTheTrueMotion) {
  testing::MujocoGuard guard;
  for (const char* integrator : {"euler", "rk4"}) {
    ClosedLoop loop(scene("case2"), {"duration_s=3", std::string("integrator=") + integrator});
    std::vector<TickRecord> rows;
    while (!loop.finished()) {
      rows.emplace_back();
      loop.tick(&rows.back());
    }
    double sum = 0.0;
    double worst = 0.0, least_dissipated = 1e300, swing = 0.0;
    for (std::size_t k = 0; k + 1 < rows.size(); ++k) {
      const Joints a = dh_to_device_joints(rows[k].q_true_dh);
      const Joints b = dh_to_device_joints(rows[k + 1].q_true_dh);
      sum += rows[k].motor_torque_Nm.dot((b - a).head<3>());
      worst = std::max(worst, std::abs(sum - rows[k].energy_motor_J));
      swing = std::max(swing, std::abs(rows[k].energy_motor_J));
      least_dissipated = std::min(least_dissipated, rows[k].energy_motor_J +
                                                        rows[k].energy_hand_J -
                                                        rows[k].kinetic_J);
    }
    std::printf("  %s: max |E - sum| = %.3g J over |E| up to %.3g J; least "
                "dissipated %.3g J\n",
                integrator, worst, swing, least_dissipated);
    EXPECT_GT(swing, 0.01) << "the run should move energy";
    EXPECT_LT(worst, 1e-12);
    EXPECT_GT(least_dissipated, -1e-6);
  }
}

TEST(PassivityObserver, ReadsZeroWithTheControllerOff) {
  testing::MujocoGuard guard;
  ClosedLoop loop(scene("case2"),
                  {"duration_s=1", "k_pos_N_per_mm=0", "k_ornt_multiple=0"});
  TickRecord row;
  double hand = 0.0;
  while (!loop.finished()) {
    loop.tick(&row);
    ASSERT_EQ(row.energy_motor_J, 0.0);
    hand = std::max(hand, std::abs(row.energy_hand_J));
  }
  EXPECT_GT(hand, 1e-3);  // the hand still moved the device
}

// -- the instabilities the study names --

// K_pos x100 on the sphere breaks Colgate & Schenkel's passivity bound
// (K T/2 = 25 N s/m against the hand's 6.45): the observer sees energy
// pumped in at rest. Give the hand more damping than K T/2 (30 N s/m) and
// the limit cycle goes; K_pos x10 (2.5 N s/m) never had one.
TEST(ExtremeInstabilities, PositionLimitCycleFollowsColgate) {
  testing::MujocoGuard guard;
  auto run = [](std::vector<std::string> sets) {
    ExtremeScenario s;
    s.name = "probe";
    s.base = "case5";
    s.overrides = std::move(sets);
    return run_extreme(s);
  };
  const ExtremeResult x100 = run({"k_pos_N_per_mm=50"});
  const ExtremeResult damped = run({"k_pos_N_per_mm=50", "hand_b_pos_Ns_per_m=30"});
  const ExtremeResult x10 = run({"k_pos_N_per_mm=5"});
  std::printf("  rest rise: x100 %.3g J, x100 b = 30 %.3g J, x10 %.3g J\n",
              x100.rest_energy_rise_J, damped.rest_energy_rise_J,
              x10.rest_energy_rise_J);
  EXPECT_FALSE(x100.colgate_passive);
  EXPECT_FALSE(x100.energy_bounded);
  EXPECT_EQ(x100.outcome, "limit_cycle");
  EXPECT_TRUE(damped.colgate_passive);
  EXPECT_TRUE(damped.energy_bounded);
  EXPECT_TRUE(x10.colgate_passive);
  EXPECT_TRUE(x10.energy_bounded);
}

// K_ornt x10 on the circle flutters: the orientation term turns the
// stylus's angle, which the hand holds through a soft wrist, into force on
// the arm, a non-conservative coupling. It is not the sampling: it stays at
// a 5 kHz servo rate and without quantisation; it goes with a stiffer wrist
// (5 N m/rad) or a more damped one (0.1 N m s/rad). The wrist's values are
// estimates (docs/sources.md §10 found none published).
TEST(ExtremeInstabilities, OrientationGainFlutters) {
  testing::MujocoGuard guard;
  auto run = [](std::vector<std::string> extra) {
    ExtremeScenario s = scenario_named("gains_x10");
    s.overrides.insert(s.overrides.end(), extra.begin(), extra.end());
    return run_extreme(s);
  };
  const ExtremeResult nominal = run({});
  const ExtremeResult fast =
      run({"servo_period_s=0.0002", "physics_step_s=0.0002", "quantize=0"});
  const ExtremeResult stiff_wrist = run({"hand_k_rot_Nm_per_rad=5"});
  const ExtremeResult damped_wrist = run({"hand_b_rot_Nms_per_rad=0.1"});
  std::printf("  rest rise: nominal %.3g J, 5 kHz exact %.3g J, stiff wrist "
              "%.3g J, damped wrist %.3g J\n",
              nominal.rest_energy_rise_J, fast.rest_energy_rise_J,
              stiff_wrist.rest_energy_rise_J, damped_wrist.rest_energy_rise_J);
  EXPECT_TRUE(nominal.colgate_passive);  // not the translational sampling
  EXPECT_FALSE(nominal.energy_bounded);
  EXPECT_GT(nominal.rest_kinetic_max_J, 1e-3);  // a visible oscillation
  EXPECT_FALSE(fast.energy_bounded);
  EXPECT_TRUE(stiff_wrist.energy_bounded);
  EXPECT_TRUE(damped_wrist.energy_bounded);
}

// The thesis's six cases at their own pace (20 s) stay far from both: the
// observer never climbs at rest.
TEST(ExtremeInstabilities, ThesisCasesComeToRest) {
  testing::MujocoGuard guard;
  for (const char* c : {"case4", "case6"}) {
    ExtremeScenario s;
    s.name = c;
    s.base = c;
    s.overrides = {"duration_s=20"};
    const ExtremeResult r = run_extreme(s);
    EXPECT_TRUE(r.energy_bounded) << c << ": " << r.rest_energy_rise_J << " J";
    EXPECT_EQ(r.outcome, "ok") << c;
  }
}

}  // namespace
}  // namespace vmh::studies
