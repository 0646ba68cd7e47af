// The closed loop on the six thesis scenes: each steps with no MuJoCo
// warning, holds the torque over the servo period, keeps its physics honest
// (the hand's work matches the energy it moved). The thesis's claims on the
// same scenes are tests/thesis/claims_test.cc.
#include "sim/closed_loop.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/omni_ratings.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/thesis_cases.h"

namespace vmh::sim {
namespace {

std::string scene(int n) { return testing::thesis_case_scene(n); }

using CaseTest = testing::ThesisCaseTest;

// Every scene runs its whole script with no MuJoCo warning (d->warning all
// zero, no warning callback), finite state, and no controller fault.
TEST_P(CaseTest, RunsWithoutWarningOrFault) {
  ClosedLoop loop(scene(GetParam()), {});
  TickRecord row;
  int faults = 0;
  for (int k = 0; k < loop.ticks_per_run(); ++k) {
    loop.tick(&row);
    if (row.servo.zeroed) ++faults;
    ASSERT_TRUE(row.out.force_device_N.allFinite()) << "tick " << k;
  }
  EXPECT_EQ(testing::MujocoGuard::data_warnings(loop.data()), "");
  EXPECT_EQ(testing::MujocoGuard::warnings(), "");
  EXPECT_FALSE(loop.physics_fault().has_value());
  for (std::int64_t n : loop.mujoco_warning_counts()) EXPECT_EQ(n, 0);
  EXPECT_EQ(faults, 0);
  for (int i = 0; i < loop.model()->nq; ++i) {
    EXPECT_TRUE(std::isfinite(loop.data()->qpos[i]));
  }
  EXPECT_NEAR(loop.time_s(), 20.0, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(ThesisCases, CaseTest, ::testing::Range(1, 8));

// Zero-order hold: the motors hold the same torque over every physics step
// of a servo tick; the torque changes only at tick boundaries.
// A case scene compiled headless (load_model_headless: no drawn-only geoms,
// lights, cameras or skybox) runs the same trajectory to the last bit as
// the scene as written, for every case over its first 3 s: what is left
// out is never read by the physics.
TEST(ClosedLoopTest, HeadlessSceneRunsTheSameTrajectory) {
  for (int n = 1; n <= 6; ++n) {
    const std::string scene =
        std::string(VMH_MODELS_DIR) + "/cases/case" + std::to_string(n) + ".xml";
    const ModelPtr full = load_scene_model(scene);
    const ModelPtr lean = load_scene_model(scene, {}, /*headless=*/true);
    EXPECT_LT(lean->ngeom, full->ngeom / 2) << scene;
    EXPECT_EQ(lean->ncam, 0) << scene;
    EXPECT_EQ(lean->nlight, 0) << scene;
    EXPECT_GT(full->ncam, 0) << scene;
    EXPECT_EQ(lean->nbody, full->nbody) << scene;
    EXPECT_EQ(lean->nv, full->nv) << scene;
    ClosedLoop a(scene, *full, {"duration_s=3"});
    ClosedLoop b(scene, *lean, {"duration_s=3"});
    TickRecord ra, rb;
    int differing = 0;
    while (!a.finished()) {
      a.tick(&ra);
      b.tick(&rb);
      if (ra.q_true_dh != rb.q_true_dh ||
          ra.out.force_device_N != rb.out.force_device_N) {
        ++differing;
      }
    }
    EXPECT_EQ(differing, 0) << scene;
  }
}

TEST(ClosedLoopTest, TorqueIsHeldOverTheServoPeriod) {
  testing::MujocoGuard guard;
  ClosedLoop loop(scene(1), {"physics_step_s=0.0002"});
  ASSERT_EQ(loop.substeps(), 5);
  TickRecord row;
  // let the hand pull the RM off the path so that the torque is non-zero
  for (int k = 0; k < 1500; ++k) loop.tick(&row);
  ASSERT_GT(row.motor_torque_Nm.norm(), 1e-3);
  mjData* d = loop.data();
  const mjModel* m = loop.model();
  const int a = mj_name2id(m, mjOBJ_ACTUATOR, "m1");
  const double held = d->ctrl[a];
  for (int i = 0; i < loop.substeps(); ++i) {
    mj_step(m, d);
    EXPECT_EQ(d->ctrl[a], held) << "substep " << i;
  }
}

// torque_limits: the OpenHaptics samples' clamps by default (omni.xml's own
// ranges), and with "rated" both the controller's clamp and the simulated
// motors' range are the rated 0.44 N m, which a torque above the samples'
// clamps then actually reaches (the hand pulls the RM 60 mm off the path,
// where the law asks for more than either limit allows).
TEST(ClosedLoopTest, TorqueLimitsReachTheSimulatedMotors) {
  testing::MujocoGuard guard;
  for (const char* which : {"openhaptics_samples", "rated"}) {
    ClosedLoop loop(scene(1), {std::string("torque_limits=") + which});
    const auto lim = loop.controller_params().omni.motor_torque_limit_Nm;
    const auto expect = motor_torque_limits_Nm(OmniParams{}, parse_torque_limits(which));
    EXPECT_EQ(lim, expect) << which;
    const mjModel* m = loop.model();
    double largest = 0.0;
    TickRecord row;
    for (int k = 0; k < loop.ticks_per_run(); ++k) {
      loop.tick(&row);
      largest = std::max(largest, row.motor_torque_Nm.cwiseAbs().maxCoeff());
    }
    for (int i = 0; i < 3; ++i) {
      const int a = mj_name2id(m, mjOBJ_ACTUATOR, ("m" + std::to_string(i + 1)).c_str());
      EXPECT_DOUBLE_EQ(m->actuator_ctrlrange[2 * a + 1], expect[static_cast<std::size_t>(i)])
          << which << " m" << i + 1;
    }
    if (std::string(which) == "rated") {
      EXPECT_GT(largest, 0.35 + 1e-3) << "no torque above the samples' clamps";
    } else {
      EXPECT_LE(largest, 0.35 + 1e-12);
    }
  }
}

// The one-tick delay: with delay_ticks = 1, the torque the motors hold after
// tick k is the one the controller computed at tick k - 1.
TEST(ClosedLoopTest, DelayShiftsTheTorqueByWholeTicks) {
  testing::MujocoGuard guard;
  ClosedLoop loop(scene(2), {"delay_ticks=1"});
  TickRecord prev, row;
  loop.tick(&prev);
  for (int k = 0; k < 2000; ++k) {
    loop.tick(&row);
    ASSERT_LE((row.motor_torque_Nm - prev.out.tau_motor_Nm).norm(), 1e-15)
        << "tick " << k;
    prev = row;
  }
}

// The start pose is the script's: the wrist centre on the path and the
// stylus along script_dir, checked through omni_fk of the model's qpos
// (not the controller's reading).
TEST(ClosedLoopTest, StartsOnThePathWithTheScriptedStylus) {
  testing::MujocoGuard guard;
  for (int n : {1, 5}) {
    ClosedLoop loop(scene(n), {});
    const OmniParams omni;
    Joints q;
    for (int i = 0; i < 6; ++i) q[i] = loop.data()->qpos[i];
    const OmniPose pose = omni_fk(omni, q);
    const Vec3 p = base_to_device_mm(omni, pose.p_base_m);
    const Vec3 axis = base_to_device_vector(pose.R_base.col(2));
    EXPECT_NEAR(loop.distance_to_path_mm(p), 0.0, 1e-9) << "case" << n;
    EXPECT_NEAR((p - loop.script().start_mm()).norm(), 0.0, 1e-9);
    const Vec3 dir = Vec3(-0.35, 0.65, 0.65).normalized();
    EXPECT_NEAR(axis.dot(dir), 1.0, 1e-12) << "case" << n;
  }
}

// The reading path: with quantisation on, the controller's wrist centre is
// within the encoders' resolution of the truth (0.056 mm per count at the
// tip, docs/sources.md §6; three joints, so a few counts' worth), and exact with
// it off.
TEST(ClosedLoopTest, SensorModelSitsBetweenTruthAndController) {
  testing::MujocoGuard guard;
  for (const char* q : {"quantize=1", "quantize=0"}) {
    ClosedLoop loop(scene(1), {q});
    TickRecord row;
    double worst = 0.0;
    for (int k = 0; k < 3000; ++k) {
      loop.tick(&row);
      worst = std::max(worst, (row.out.p_rm_mm - row.p_true_mm).norm());
    }
    std::printf("  %s: max |p_controller - p_true| = %.4g mm\n", q, worst);
    if (std::string(q) == "quantize=1") {
      EXPECT_GT(worst, 1e-4);
      EXPECT_LT(worst, 0.2);
    } else {
      EXPECT_LT(worst, 1e-9);
    }
  }
}

// The closed-form path geometry used for ground truth: the nearest point is
// on the path and no farther than any sampled point of it.
TEST(ClosedLoopTest, NearestPointOnPathIsTheNearest) {
  testing::MujocoGuard guard;
  for (int n : {1, 5}) {
    ClosedLoop loop(scene(n), {});
    const Vec3 p(-31.0, 22.0, 17.0);
    const Vec3 q = loop.nearest_on_path_mm(p);
    EXPECT_NEAR(loop.distance_to_path_mm(q), 0.0, 1e-9);
    EXPECT_NEAR((p - q).norm(), loop.distance_to_path_mm(p), 1e-9);
    // sample the path: circle in the x-y plane / sphere of radius 50
    for (int i = 0; i < 360; ++i) {
      const double a = i * 3.14159265358979 / 180.0;
      for (int j = 0; j < (n == 5 ? 180 : 1); ++j) {
        const double b = n == 5 ? j * 3.14159265358979 / 180.0 : 0.5 * 3.14159265358979;
        const Vec3 s = 50.0 * Vec3(std::cos(a) * std::sin(b),
                                   std::sin(a) * std::sin(b), std::cos(b));
        ASSERT_GE((p - s).norm(), (p - q).norm() - 1e-9);
      }
    }
  }
}

}  // namespace
}  // namespace vmh::sim

namespace vmh::sim {
namespace {

// The hand's physics does not depend on who steps: case 2 driven by
// ClosedLoop::tick, and the same scene stepped by plain mj_step with the
// same hand targets and the same held motor commands, follow the same
// trajectory to the last bit. A third copy whose hand is gone (destroyed,
// so nothing is registered for its data) leaves that trajectory: the check
// can tell a hand from none.
TEST(ClosedLoopTest, PlainMjStepGivesTheSameTrajectory) {
  testing::MujocoGuard guard;
  ClosedLoop looped(scene(2), {"physics_step_s=0.0005"});
  ClosedLoop plain(scene(2), {"physics_step_s=0.0005"});
  ASSERT_EQ(looped.substeps(), 2);
  const mjModel* m = plain.model();
  mjData* d = plain.data();
  DataPtr bare(mj_makeData(m));
  mj_copyData(bare.get(), m, d);
  ASSERT_EQ(registered_hand(bare.get()), nullptr);
  ASSERT_EQ(registered_hand(d), &plain.hand());

  TickRecord row;
  double max_bare_gap = 0.0;
  for (int k = 0; k < 400; ++k) {
    const double t_s = looped.time_s();
    looped.tick(&row);
    // the command the loop held over this tick, and the hand's target
    mju_copy(d->ctrl, looped.data()->ctrl, m->nu);
    mju_copy(bare->ctrl, looped.data()->ctrl, m->nu);
    plain.set_hand_target(t_s);
    for (int i = 0; i < looped.substeps(); ++i) {
      mj_step(m, d);
      mj_step(m, bare.get());
    }
    for (int i = 0; i < m->nq; ++i) {
      ASSERT_EQ(d->qpos[i], looped.data()->qpos[i]) << "tick " << k << " q" << i;
      ASSERT_EQ(d->qvel[i], looped.data()->qvel[i]) << "tick " << k << " q" << i;
      max_bare_gap = std::max(
          max_bare_gap, std::abs(bare->qpos[i] - looped.data()->qpos[i]));
    }
  }
  // without the hand's pull the joints drift apart: 5.7e-5 rad after 0.4 s
  // of the thesis script's first hold (measured), far above rounding
  EXPECT_GT(max_bare_gap, 1e-5);
  EXPECT_EQ(testing::MujocoGuard::warnings(), "");
}

// A hand is registered for its own data only, and no longer once it is gone.
TEST(ClosedLoopTest, TheHandIsRegisteredForItsDataOnly) {
  testing::MujocoGuard guard;
  const mjData* d = nullptr;
  {
    ClosedLoop loop(scene(1), {});
    d = loop.data();
    EXPECT_EQ(registered_hand(d), &loop.hand());
    EXPECT_EQ(mjcb_control, &hand_control_callback);
  }
  EXPECT_EQ(registered_hand(d), nullptr);
}

// The manual hand holds the target it is given: with the controller's
// gains at zero nothing but the hand acts on the grip, so the grip ends
// near a target 20 mm away; the row reports that target's wrist pose, and
// the script's wrist pose comes back out of the script's own grip target
// (the inverse of set_hand_target's placement, computed separately).
TEST(ClosedLoopTest, ManualTargetPullsTheGrip) {
  testing::MujocoGuard guard;
  ClosedLoop loop(scene(1), {"k_pos_N_per_mm=0", "k_ornt_multiple=0"});
  TickRecord row;
  for (int k = 0; k < 50; ++k) loop.tick(&row);
  EXPECT_FALSE(loop.manual_hand());
  // off: the row's target is the script's, and the manual one starts from
  // where the hand holds now
  const ScriptPose scripted = loop.script().at(row.t_s);
  EXPECT_NEAR((row.hand_target.p_mm - scripted.p_mm).norm(), 0.0, 1e-12);
  loop.set_manual_hand(true);
  HandTargetState target = loop.manual_target();
  EXPECT_NEAR((target.p_m - loop.hand().target().p_m).norm(), 0.0, 1e-15);
  EXPECT_EQ(target.v_m_s, Vec3::Zero());

  const int g = loop.hand().grip_site();
  const Vec3 grip0(loop.data()->site_xpos + 3 * g);
  const Vec3 move_m(0.0, 0.012, 0.016);  // 20 mm, world frame
  target.p_m += move_m;
  loop.set_manual_target(target);
  for (int k = 0; k < 2000; ++k) loop.tick(&row);
  const Vec3 grip1(loop.data()->site_xpos + 3 * g);
  const Vec3 moved = grip1 - grip0;
  // along the move by most of its 20 mm, and little across it
  EXPECT_GT(moved.dot(move_m.normalized()), 0.8 * move_m.norm());
  EXPECT_LT((moved - moved.dot(move_m.normalized()) * move_m.normalized()).norm(),
            0.2 * move_m.norm());
  // the hand still holds the manual target, not the script's
  EXPECT_NEAR((loop.hand().target().p_m - target.p_m).norm(), 0.0, 1e-15);
  // the row's wrist pose is the target's: the wrist is where the grip site
  // sits on the stylus body (its offset from the model), device frame
  const mjModel* m = loop.model();
  const Vec3 grip_local(m->site_pos + 3 * g);
  mjtNum R_site[9];
  mju_quat2Mat(R_site, m->site_quat + 4 * g);
  Mat3 Rs;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Rs(r, c) = R_site[3 * r + c];
  const Mat3 R_wrist = target.R * Rs.transpose();
  const Vec3 wrist_m = target.p_m - R_wrist * grip_local;
  const Vec3 expect_mm =
      base_to_device_mm(loop.controller_params().omni, wrist_m);
  EXPECT_NEAR((row.hand_target.p_mm - expect_mm).norm(), 0.0, 1e-9);
  EXPECT_NEAR(row.hand_target.axis.norm(), 1.0, 1e-12);

  // back to the script: the next tick's target is the script's again
  loop.set_manual_hand(false);
  loop.tick(&row);
  EXPECT_NEAR((row.hand_target.p_mm - loop.script().at(row.t_s).p_mm).norm(),
              0.0, 1e-12);
  EXPECT_GT((loop.hand().target().p_m - target.p_m).norm(), 0.01);
}

// ---- the bounds on a run's counts, checked before any work (issue 17) ----

constexpr auto npos = std::string::npos;

// the message of the SimError that making case 1's loop throws; "" if none
std::string refusal(const std::vector<std::string>& sets,
                    const ModelHook& hook = {}) {
  try {
    ClosedLoop loop(scene(1), sets, hook);
  } catch (const SimError& e) {
    return e.what();
  }
  return "";
}

// T / h must fit kMaxSubstepsPerTick: 1e-3 s / 1e-300 s was an int cast of
// 1e297 (undefined behaviour) before
TEST(ClosedLoopBounds, RefusesTooManyPhysicsStepsPerTick) {
  const std::string msg = refusal({"physics_step_s=1e-300"});
  EXPECT_NE(msg.find("servo_period_s / physics_step_s (0.001 s / 1e-300 s)"),
            npos) << msg;
  EXPECT_NE(msg.find("[1, 1000000]"), npos) << msg;
  EXPECT_NE(msg.find("got 1e+297"), npos) << msg;
  EXPECT_EQ(refusal({"physics_step_s=1e-9"}), "");   // 1e6 steps: the bound
  EXPECT_NE(refusal({"physics_step_s=5e-10"}), "");  // 2e6
  // a step longer than the period
  EXPECT_NE(refusal({"physics_step_s=0.003"}).find("[1, 1000000]"), npos);
}

// the scene's own step (physics_step_s 0 keeps it) must be finite and > 0:
// timestep="0" made T / h infinite
TEST(ClosedLoopBounds, RefusesASceneStepThatIsNotFiniteAndPositive) {
  for (const double h : {0.0, -0.001, std::nan(""), HUGE_VAL}) {
    const std::string msg =
        refusal({}, [h](mjModel* m) { m->opt.timestep = h; });
    EXPECT_NE(msg.find("the scene's <option timestep> must be finite and > 0"),
              npos) << h << ": " << msg;
  }
}

// the jitter's longest period in physics steps: 0.9 s at a 1e-7 s step is
// 9e6 steps in one tick
TEST(ClosedLoopBounds, RefusesAJitterPeriodOfTooManySteps) {
  const std::string msg =
      refusal({"physics_step_s=1e-7", "servo_jitter_s=0.0004,0.9"});
  EXPECT_NE(msg.find("servo_jitter_s's longest period"), npos) << msg;
  EXPECT_NE(msg.find("at most 1000000 physics steps, got 9000000"), npos) << msg;
}

// a run must last at least one servo tick, and says so with the value as
// %g (1e-07, not 0.000000)
TEST(ClosedLoopBounds, RefusesARunShorterThanOneTick) {
  const std::string msg = refusal({"duration_s=1e-7"});
  EXPECT_NE(msg.find("duration_s (1e-07 s) must last from 1 to 1000000000 "
                     "servo periods (servo_period_s = 0.001 s), got 0.0001"),
            npos) << msg;
  EXPECT_EQ(refusal({"duration_s=0.0006"}), "");  // rounds to one tick
}

// the longest run the table allows at its shortest period: 3.6e8 ticks,
// counted in 64 bits
TEST(ClosedLoopBounds, CountsTheLongestRunInAWideType) {
  ClosedLoop loop(scene(1), {"duration_s=3600", "servo_period_s=1e-5",
                             "physics_step_s=1e-5"});
  EXPECT_EQ(loop.ticks_per_run(), std::int64_t{360000000});
  EXPECT_EQ(loop.substeps(), 1);
}

// ---- a physics state gone bad (issue 17) ----

// A hand 1e30 N/m stiff: the first physics step's qacc is beyond MuJoCo's
// 1e10; mj_step warns, resets the state and would carry on (here to blow
// up again at every step). The loop keeps the first bad step and counts
// every one, though each reset set MuJoCo's own counter back to 1.
TEST(ClosedLoopPhysics, TheFirstBadStateIsKeptAndEveryWarningCounted) {
  testing::MujocoGuard guard;  // MuJoCo's messages to the guard
  ClosedLoop loop(scene(1), {"hand_k_pos_N_per_m=1e30"});
  EXPECT_FALSE(loop.physics_fault().has_value());
  EXPECT_NO_THROW(loop.throw_if_physics_fault());
  TickRecord row;
  loop.tick(&row);
  ASSERT_TRUE(loop.physics_fault().has_value());
  const PhysicsFault first = *loop.physics_fault();
  EXPECT_DOUBLE_EQ(first.t_s, 0.001);
  EXPECT_EQ(first.part, "qacc");
  EXPECT_GE(first.index, 0);
  EXPECT_EQ(first.message(), "physics went non-finite at t=0.001 s (qacc, DOF " +
                                 std::to_string(first.index) + ")");
  EXPECT_FALSE(row.state_finite);
  try {
    loop.throw_if_physics_fault();
    ADD_FAILURE() << "no PhysicsError";
  } catch (const PhysicsError& e) {
    EXPECT_EQ(std::string(e.what()), scene(1) + ": " + first.message());
  }
  // tick() itself goes on (a study may look further), keeping the first
  // fault and counting each bad step across MuJoCo's resets
  const std::int64_t after_one = loop.mujoco_warning_counts()[mjWARN_BADQACC];
  EXPECT_GE(after_one, 1);
  for (int k = 0; k < 3; ++k) loop.tick(&row);
  EXPECT_GT(loop.mujoco_warning_counts()[mjWARN_BADQACC], after_one);
  EXPECT_DOUBLE_EQ(loop.physics_fault()->t_s, 0.001);
  // reset() starts clean
  loop.reset();
  EXPECT_FALSE(loop.physics_fault().has_value());
  for (std::int64_t n : loop.mujoco_warning_counts()) EXPECT_EQ(n, 0);
}

}  // namespace
}  // namespace vmh::sim
