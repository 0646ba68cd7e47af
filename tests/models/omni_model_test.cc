// models/omni/omni.xml against the controller library.
//
// The simulator reads qpos as the DH joint angles q1..q6 and compares site
// poses with vmh::omni_fk, so the model must reproduce the controller's
// kinematics exactly: the sites, their Jacobians, the joint ranges, the
// motor limits and the motor-to-joint map are checked here against
// OmniParams, omni_fk, omni_jacobian(_at) and dh_to_device_joints. The
// dynamic parameters (masses, damping, ...) are estimates; their values are
// pinned to the table of models/omni/README.md.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"
#include "controller/types.h"
#include "tests/models/model_files.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/mujoco_kinematics.h"
#include "tests/support/random_joints.h"
#include "tests/support/constants.h"

namespace vmh {
namespace {

using testing::DataPtr;
using testing::ModelPtr;
using testing::MujocoGuard;
using testing::max_abs_diff;
using testing::RowJac;
using RowMat6 = Eigen::Matrix<double, kOmniJoints, kOmniJoints, Eigen::RowMajor>;

using vmh::testing::kPi;
// kinematic identities hold to rounding: 1e-9 leaves ~1e6 ulps of room
constexpr double kKinTol = 1e-9;
// the tendon map is a sum of at most two terms with coefficients +-1
constexpr double kForceTol = 1e-12;

// the estimates of models/omni/README.md, body by body (kg)
struct BodyEstimate {
  const char* name;
  double mass_kg;
};
constexpr std::array<BodyEstimate, kOmniJoints> kBodies = {{
    {"turret", 0.25},
    {"upper_arm", 0.04},
    {"forearm", 0.035},
    {"gimbal_yaw", 0.015},
    {"gimbal_pitch", 0.01},
    {"stylus", 0.02},
}};
// README.md: "moving mass 0.370 kg"
constexpr double kMovingMassKg = 0.370;

class OmniModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    model_ = testing::load_model(testing::models_dir() + "/omni/omni.xml",
                                 &error);
    ASSERT_NE(model_, nullptr) << error;
    ASSERT_TRUE(error.empty()) << error;
    data_.reset(mj_makeData(model_.get()));
    ASSERT_NE(data_, nullptr);
    ASSERT_EQ(MujocoGuard::warnings(), "");
  }

  int id(mjtObj type, const char* name) const {
    return mj_name2id(model_.get(), type, name);
  }

  void set_q(const Joints& q) {
    testing::set_joints(model_.get(), data_.get(), q);
  }
  Vec3 site_pos(int s) const { return testing::site_pos(data_.get(), s); }
  Mat3 site_rot(int s) const { return testing::site_rot(data_.get(), s); }
  Mat6 site_jac(int s) const {
    return testing::site_jacobian(model_.get(), data_.get(), s);
  }

  MujocoGuard guard_;
  OmniParams params_;
  ModelPtr model_;
  DataPtr data_;
};

// Structure: nq = nv = 6, six hinges named q1..q6 at qpos addresses 0..5,
// ranges equal to OmniParams (exactly: the same decimal literals), motors
// m1..m3 with ctrlrange = forcerange = +-motor_torque_limit_Nm, and a "home"
// keyframe inside the ranges. Exact equality throughout.
TEST_F(OmniModelTest, StructureMatchesOmniParams) {
  const mjModel* m = model_.get();
  EXPECT_EQ(m->nq, kOmniJoints);
  EXPECT_EQ(m->nv, kOmniJoints);
  EXPECT_EQ(m->njnt, kOmniJoints);
  EXPECT_EQ(m->nu, kOmniActuated);
  EXPECT_EQ(m->ntendon, kOmniActuated);
  EXPECT_EQ(m->nbody, kOmniJoints + 1);
  for (int i = 0; i < kOmniJoints; ++i) {
    SCOPED_TRACE(joint_name(i));
    const int j = id(mjOBJ_JOINT, joint_name(i));
    ASSERT_GE(j, 0);
    EXPECT_EQ(m->jnt_type[j], mjJNT_HINGE);
    EXPECT_EQ(m->jnt_qposadr[j], i);
    EXPECT_EQ(m->jnt_dofadr[j], i);
    // one body per DH row, in order: joint i moves body i + 1
    EXPECT_EQ(m->jnt_bodyid[j], i + 1);
    EXPECT_STREQ(mj_id2name(m, mjOBJ_BODY, i + 1), kBodies[i].name);
    EXPECT_TRUE(m->jnt_limited[j]);
    EXPECT_EQ(m->jnt_range[2 * j], params_.joint_lower_rad[i]);
    EXPECT_EQ(m->jnt_range[2 * j + 1], params_.joint_upper_rad[i]);
  }

  const char* const motors[kOmniActuated] = {"m1", "m2", "m3"};
  const char* const tendons[kOmniActuated] = {"t1", "t2", "t3"};
  for (int k = 0; k < kOmniActuated; ++k) {
    SCOPED_TRACE(motors[k]);
    const int a = id(mjOBJ_ACTUATOR, motors[k]);
    ASSERT_GE(a, 0);
    EXPECT_EQ(m->actuator_trntype[a], mjTRN_TENDON);
    EXPECT_EQ(m->actuator_trnid[2 * a], id(mjOBJ_TENDON, tendons[k]));
    EXPECT_EQ(m->actuator_gear[6 * a], 1.0);
    const double lim = params_.motor_torque_limit_Nm[k];
    EXPECT_TRUE(m->actuator_ctrllimited[a]);
    EXPECT_EQ(m->actuator_ctrlrange[2 * a], -lim);
    EXPECT_EQ(m->actuator_ctrlrange[2 * a + 1], lim);
    EXPECT_TRUE(m->actuator_forcelimited[a]);
    EXPECT_EQ(m->actuator_forcerange[2 * a], -lim);
    EXPECT_EQ(m->actuator_forcerange[2 * a + 1], lim);
  }

  const int home = id(mjOBJ_KEY, "home");
  ASSERT_GE(home, 0);
  Joints q_home;
  for (int i = 0; i < kOmniJoints; ++i) {
    q_home[i] = m->key_qpos[home * m->nq + i];
    EXPECT_GE(q_home[i], params_.joint_lower_rad[i]) << joint_name(i);
    EXPECT_LE(q_home[i], params_.joint_upper_rad[i]) << joint_name(i);
  }
  EXPECT_TRUE(omni_within_limits(params_, q_home));
  EXPECT_EQ(q_home, Joints::Zero());
  // visual geoms (group 2) never collide; collision geoms (group 3) may
  // touch only what a scene gives a conaffinity, so never one another: no
  // geom of the model has a conaffinity (README.md), and every body's mass
  // is its <inertial>, not its geoms'
  int visual = 0, collision = 0;
  for (int g = 0; g < m->ngeom; ++g) {
    EXPECT_EQ(m->geom_conaffinity[g], 0) << "geom " << g;
    if (m->geom_group[g] == 2) {
      ++visual;
      EXPECT_EQ(m->geom_contype[g], 0) << "geom " << g;
    } else {
      EXPECT_EQ(m->geom_group[g], 3) << "geom " << g;
      EXPECT_EQ(m->geom_contype[g], 1) << "geom " << g;
      ++collision;
    }
  }
  // one collision shape per moving body, and the base's
  EXPECT_EQ(collision, m->nbody);
  EXPECT_GT(visual, 2 * collision);
}

// Sites: "wrist" at the stylus body's origin, "grip" and "tip" 0.05 m and
// 0.10 m along -z6 (eq. B.7 puts a tool at -L_t), all three in the stylus
// body with its axes (identity site_quat). Exact equality.
TEST_F(OmniModelTest, SitesSitOnTheStylusAxis) {
  const mjModel* m = model_.get();
  const int stylus = id(mjOBJ_BODY, "stylus");
  ASSERT_GE(stylus, 0);
  const std::array<std::pair<const char*, double>, 3> sites = {{
      {"wrist", 0.0}, {"grip", -0.05}, {"tip", -0.10}}};
  for (const auto& [name, z] : sites) {
    SCOPED_TRACE(name);
    const int s = id(mjOBJ_SITE, name);
    ASSERT_GE(s, 0);
    EXPECT_EQ(m->site_bodyid[s], stylus);
    EXPECT_EQ(m->site_pos[3 * s], 0.0);
    EXPECT_EQ(m->site_pos[3 * s + 1], 0.0);
    EXPECT_EQ(m->site_pos[3 * s + 2], z);
    EXPECT_EQ(m->site_quat[4 * s], 1.0);
    for (int i = 1; i < 4; ++i) EXPECT_EQ(m->site_quat[4 * s + i], 0.0);
  }
}

// Identities at 2000 configurations uniform inside the joint ranges and 1000
// uniform in [-pi, pi]^6:
//   xpos, xmat of body i            == T_{0,i} of omni_frames   (i = 1..6)
//   site_xpos(wrist), site_xmat     == omni_fk: p_base_m, R_base
//   mj_jacSite(wrist)               == omni_jacobian
//   site_xpos(s), mj_jacSite(s)     == omni_tool_point, omni_jacobian_at
//                                      with offset = site_pos z of s,
//                                      for s = tip (-0.10) and grip (-0.05)
// each to 1e-9 (max abs entry; m, m/rad, or 1).
TEST_F(OmniModelTest, SitesMatchControllerKinematics) {
  const int wrist = id(mjOBJ_SITE, "wrist");
  const int tip = id(mjOBJ_SITE, "tip");
  const int grip = id(mjOBJ_SITE, "grip");
  ASSERT_GE(wrist, 0);
  ASSERT_GE(tip, 0);
  ASSERT_GE(grip, 0);
  // the tool offsets come from the model, and must be the README's
  const double tip_offset = model_->site_pos[3 * tip + 2];
  const double grip_offset = model_->site_pos[3 * grip + 2];
  ASSERT_EQ(tip_offset, -0.10);
  ASSERT_EQ(grip_offset, -0.05);
  OmniParams tip_params = params_;
  tip_params.tool_offset_m = tip_offset;
  OmniParams grip_params = params_;
  grip_params.tool_offset_m = grip_offset;

  struct {
    double frames = 0, wrist_pos = 0, wrist_rot = 0, wrist_jac = 0;
    double tip_pos = 0, tip_jac = 0, grip_pos = 0, grip_jac = 0;
  } e;
  constexpr int kInside = 2000;
  constexpr int kAnywhere = 1000;
  testing::JointSampler sampler(20250704u, -kPi, kPi);
  OmniFrames frames;
  for (int n = 0; n < kInside + kAnywhere; ++n) {
    const Joints q = n < kInside ? sampler.next_within(params_)
                                 : sampler.next();
    set_q(q);

    omni_frames(params_, q, &frames);
    e.frames = std::max(e.frames, testing::max_body_frame_error(data_.get(), frames));

    const OmniPose pose = omni_fk(params_, q);
    e.wrist_pos =
        std::max(e.wrist_pos, max_abs_diff(site_pos(wrist), pose.p_base_m));
    e.wrist_rot =
        std::max(e.wrist_rot, max_abs_diff(site_rot(wrist), pose.R_base));
    e.wrist_jac = std::max(
        e.wrist_jac, max_abs_diff(site_jac(wrist), omni_jacobian(params_, q)));

    e.tip_pos = std::max(e.tip_pos, max_abs_diff(site_pos(tip),
                                                 omni_tool_point(tip_params,
                                                                 pose)));
    e.tip_jac = std::max(
        e.tip_jac,
        max_abs_diff(site_jac(tip), omni_jacobian_at(params_, q, tip_offset)));
    e.grip_pos = std::max(
        e.grip_pos,
        max_abs_diff(site_pos(grip), omni_tool_point(grip_params, pose)));
    e.grip_jac = std::max(
        e.grip_jac, max_abs_diff(site_jac(grip),
                                 omni_jacobian_at(params_, q, grip_offset)));
  }
  EXPECT_LE(e.frames, kKinTol) << "body frames vs omni_frames";
  EXPECT_LE(e.wrist_pos, kKinTol) << "wrist site_xpos vs omni_fk";
  EXPECT_LE(e.wrist_rot, kKinTol) << "wrist site_xmat vs omni_fk";
  EXPECT_LE(e.wrist_jac, kKinTol) << "wrist mj_jacSite vs omni_jacobian";
  EXPECT_LE(e.tip_pos, kKinTol) << "tip site_xpos vs omni_tool_point";
  EXPECT_LE(e.tip_jac, kKinTol) << "tip mj_jacSite vs omni_jacobian_at";
  EXPECT_LE(e.grip_pos, kKinTol) << "grip site_xpos vs omni_tool_point";
  EXPECT_LE(e.grip_jac, kKinTol) << "grip mj_jacSite vs omni_jacobian_at";
  std::printf(
      "  %d configs (%d inside the ranges), max |error|: frames %.3g; wrist "
      "pos %.3g, rot %.3g, jac %.3g; tip pos %.3g, jac %.3g; grip pos %.3g, "
      "jac %.3g\n",
      kInside + kAnywhere, kInside, e.frames, e.wrist_pos, e.wrist_rot,
      e.wrist_jac, e.tip_pos, e.tip_jac, e.grip_pos, e.grip_jac);
  RecordProperty("max_wrist_pos_err", std::to_string(e.wrist_pos));
  RecordProperty("max_tip_jac_err", std::to_string(e.tip_jac));
}

// At q = 0 the wrist centre is the origin of the OpenHaptics device frame,
// which is what makes "home" the DH zero pose: base_to_device_mm(wrist) = 0
// to 1e-9 mm, and the tip lies 100 mm along -z_device (away from the user).
TEST_F(OmniModelTest, HomeWristIsTheDeviceOrigin) {
  const int home = id(mjOBJ_KEY, "home");
  ASSERT_GE(home, 0);
  mj_resetDataKeyframe(model_.get(), data_.get(), home);
  mj_forward(model_.get(), data_.get());
  const Vec3 wrist_mm =
      base_to_device_mm(params_, site_pos(id(mjOBJ_SITE, "wrist")));
  const Vec3 tip_mm =
      base_to_device_mm(params_, site_pos(id(mjOBJ_SITE, "tip")));
  EXPECT_LE(wrist_mm.cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LE(max_abs_diff(tip_mm, Vec3(0.0, 0.0, -100.0)), 1e-9);
  std::printf("  home: wrist %.3g mm from the device origin, tip at "
              "(%.3g, %.3g, %.3g) mm\n",
              wrist_mm.norm(), tip_mm[0], tip_mm[1], tip_mm[2]);
}

// The three motors act on the device joints: t1 = -q1, t2 = q2, t3 = q2 + q3
// (dh_to_device_joints). Identities, at 2000 random (q, u) with u inside
// ctrlrange, after mj_forward:
//   actuator_length_k == dh_to_device_joints(q)[k]                 (k = 0..2)
//   qfrc_actuator     == (-u1, u2 + u3, u3, 0, 0, 0)
// and the controller's motor map (controller.cc) inverts it:
//   u = (-tau1, tau2 - tau3, tau3)  =>  qfrc_actuator = (tau1, tau2, tau3, 0..)
// each to 1e-12. A ctrl beyond the range is clamped to +-the limit.
TEST_F(OmniModelTest, MotorsDriveTheDeviceJoints) {
  const mjModel* m = model_.get();
  mjData* d = data_.get();
  std::mt19937 rng(4711u);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  testing::JointSampler sampler(99u);
  double e_len = 0, e_frc = 0, e_inv = 0;
  constexpr int kTrials = 2000;
  for (int n = 0; n < kTrials; ++n) {
    const Joints q = sampler.next_within(params_);
    for (int i = 0; i < kOmniJoints; ++i) d->qpos[i] = q[i];
    for (int i = 0; i < kOmniJoints; ++i) d->qvel[i] = unit(rng);
    Vec3 u;
    for (int k = 0; k < kOmniActuated; ++k) {
      u[k] = unit(rng) * params_.motor_torque_limit_Nm[k];
      d->ctrl[k] = u[k];
    }
    mj_forward(m, d);

    const Joints q_dev = dh_to_device_joints(q);
    for (int k = 0; k < kOmniActuated; ++k) {
      e_len = std::max(e_len, std::abs(d->actuator_length[k] - q_dev[k]));
    }
    Vec6 expected;
    expected << -u[0], u[1] + u[2], u[2], 0.0, 0.0, 0.0;
    e_frc = std::max(e_frc, max_abs_diff(Eigen::Map<const Vec6>(
                                             d->qfrc_actuator),
                                         expected));

    // the controller's map: joint torques tau on q1..q3 as motor torques,
    // scaled into the ranges so that no clamp acts
    Vec3 tau(unit(rng), unit(rng), unit(rng));
    tau *= 0.09;
    d->ctrl[0] = -tau[0];
    d->ctrl[1] = tau[1] - tau[2];
    d->ctrl[2] = tau[2];
    mj_forward(m, d);
    expected << tau[0], tau[1], tau[2], 0.0, 0.0, 0.0;
    e_inv = std::max(e_inv, max_abs_diff(Eigen::Map<const Vec6>(
                                             d->qfrc_actuator),
                                         expected));
  }
  EXPECT_LE(e_len, kForceTol) << "actuator_length vs dh_to_device_joints";
  EXPECT_LE(e_frc, kForceTol) << "qfrc_actuator vs (-u1, u2+u3, u3)";
  EXPECT_LE(e_inv, kForceTol) << "qfrc_actuator of the controller's map";

  // beyond the range: ctrl is clamped (ctrllimited), so qfrc follows the
  // limits, 0.2 N m on q1 and 0.35 + 0.2 N m on q2
  for (int k = 0; k < kOmniActuated; ++k) {
    d->ctrl[k] = 3.0 * params_.motor_torque_limit_Nm[k];
  }
  mj_forward(m, d);
  EXPECT_NEAR(d->qfrc_actuator[0], -params_.motor_torque_limit_Nm[0],
              kForceTol);
  EXPECT_NEAR(d->qfrc_actuator[1],
              params_.motor_torque_limit_Nm[1] + params_.motor_torque_limit_Nm[2],
              kForceTol);
  EXPECT_NEAR(d->qfrc_actuator[2], params_.motor_torque_limit_Nm[2],
              kForceTol);
  std::printf("  %d trials, max |error|: actuator_length %.3g rad, "
              "qfrc_actuator %.3g N m, controller map %.3g N m\n",
              kTrials, e_len, e_frc, e_inv);
  EXPECT_EQ(MujocoGuard::data_warnings(d), "");
}

// Masses: each body's mass is the README's estimate (exactly), the moving
// chain weighs 0.370 kg (to 1e-12 kg), and each body's principal inertia is
// positive and satisfies the triangle inequality I_a + I_b >= I_c (MuJoCo
// would warn otherwise). Prints the apparent mass at the wrist at home.
TEST_F(OmniModelTest, MassesAreTheReadmeEstimates) {
  const mjModel* m = model_.get();
  double total = 0.0;
  for (int i = 0; i < kOmniJoints; ++i) {
    SCOPED_TRACE(kBodies[i].name);
    const int b = id(mjOBJ_BODY, kBodies[i].name);
    ASSERT_EQ(b, i + 1);
    EXPECT_EQ(m->body_mass[b], kBodies[i].mass_kg);
    EXPECT_GT(m->body_mass[b], 0.0);
    const double* I = m->body_inertia + 3 * b;
    for (int k = 0; k < 3; ++k) {
      EXPECT_GT(I[k], 0.0);
      EXPECT_GE(I[(k + 1) % 3] + I[(k + 2) % 3], I[k]);
    }
    total += m->body_mass[b];
  }
  EXPECT_NEAR(total, kMovingMassKg, 1e-12);
  EXPECT_NEAR(mj_getTotalmass(m), kMovingMassKg, 1e-12);

  // the apparent mass of the wrist centre at home, gimbal free:
  // Lambda = (J_p M^-1 J_p^T)^-1 with the 6x6 joint-space inertia M
  mjData* d = data_.get();
  mj_resetDataKeyframe(m, d, id(mjOBJ_KEY, "home"));
  mj_forward(m, d);
  RowMat6 M;
  mj_fullM(m, M.data(), d->qM);
  RowJac jacp;
  mj_jacSite(m, d, jacp.data(), nullptr, id(mjOBJ_SITE, "wrist"));
  const Eigen::Matrix<double, 3, kOmniJoints> Jp = jacp;
  const Mat3 Lambda_inv = Jp * M.llt().solve(Jp.transpose());
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(Lambda_inv.inverse());
  std::printf("  moving mass %.4f kg; apparent mass at the wrist, home: "
              "%.1f..%.1f g\n",
              total, 1e3 * eig.eigenvalues().minCoeff(),
              1e3 * eig.eigenvalues().maxCoeff());
  // sanity band, not a measurement: tens of grams (README.md)
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.01);
  EXPECT_LT(eig.eigenvalues().maxCoeff(), 0.3);

  // the motors can hold the arm against gravity at home: gravity torques on
  // q1..q3 as motor torques, (-g1, g2 - g3, g3), inside the clamps
  const Vec3 g(d->qfrc_bias[0], d->qfrc_bias[1], d->qfrc_bias[2]);
  const Vec3 g_motor(-g[0], g[1] - g[2], g[2]);
  for (int k = 0; k < kOmniActuated; ++k) {
    EXPECT_LT(std::abs(g_motor[k]), params_.motor_torque_limit_Nm[k])
        << "motor " << k + 1;
  }
  std::printf("  gravity at home as motor torques: %.4f %.4f %.4f N m\n",
              g_motor[0], g_motor[1], g_motor[2]);
}

// The joint dynamics of models/omni/README.md: actuated joints damping
// 5e-4 N m s/rad, friction 0.01 N m, armature 1.9e-4 (q1) and 1.35e-4 kg m^2
// (q2, q3); gimbal joints 1e-5, 1e-3 and 0. Exact equality.
TEST_F(OmniModelTest, JointDynamicsAreTheReadmeEstimates) {
  const mjModel* m = model_.get();
  const std::array<double, kOmniJoints> damping = {5e-4, 5e-4, 5e-4,
                                                   1e-5, 1e-5, 1e-5};
  const std::array<double, kOmniJoints> friction = {0.01, 0.01, 0.01,
                                                    1e-3, 1e-3, 1e-3};
  const std::array<double, kOmniJoints> armature = {1.9e-4, 1.35e-4, 1.35e-4,
                                                    0.0,    0.0,     0.0};
  for (int i = 0; i < kOmniJoints; ++i) {
    SCOPED_TRACE(joint_name(i));
    EXPECT_EQ(m->dof_damping[i], damping[i]);
    EXPECT_EQ(m->dof_frictionloss[i], friction[i]);
    EXPECT_EQ(m->dof_armature[i], armature[i]);
  }
}

}  // namespace
}  // namespace vmh
