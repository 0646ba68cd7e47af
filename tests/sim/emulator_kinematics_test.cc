// sim/emulator_kinematics: the device's own transform, velocity and
// Jacobian, from MuJoCo's state, checked against the project's forward
// kinematics (omni_fk, an independent route) and its finite differences;
// then on a running emulator (in lockstep), against the ground truth.
#include "sim/emulator_kinematics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "controller/device_frame.h"
#include "controller/omni_kinematics.h"
#include "sim/closed_loop.h"
#include "sim/emulator.h"
#include "tests/support/random_joints.h"

namespace vmh::sim {
namespace {

const std::string kScene = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";

// the wrist centre (mm) and stylus rotation, device frame, by omni_fk of
// device joint angles; `fk` may have other link lengths than `frame`
Vec3 p_mm(const OmniParams& fk, const OmniParams& frame, const Joints& t) {
  return base_to_device_mm(frame, omni_fk(fk, device_to_dh_joints(t)).p_base_m);
}
Mat3 R_dev(const OmniParams& p, const Joints& t) {
  return base_to_device_rotation(omni_fk(p, device_to_dh_joints(t)).R_base);
}

// puts the Omni's joints at q_dh with velocities qdot_dh (DH, rad, rad/s)
void set_state(ClosedLoop* loop, const Joints& q_dh, const Joints& qdot_dh) {
  const mjModel* m = loop->model();
  mjData* d = loop->data();
  for (int i = 0; i < 6; ++i) {
    const int j = mj_name2id(m, mjOBJ_JOINT, kOmniJoints[i]);
    d->qpos[m->jnt_qposadr[j]] = q_dh[i];
    d->qvel[m->jnt_dofadr[j]] = qdot_dh[i];
  }
}

class EmulatorKinematicsTest : public ::testing::Test {
 protected:
  void check(ClosedLoop* loop, const OmniParams& fk, int n, unsigned seed) {
    const OmniParams nominal = loop->controller_params().omni;
    EmulatorKinematics kin(loop->model(), nominal);
    vmh::testing::JointSampler sampler(seed);
    double worst_p = 0, worst_R = 0, worst_Jv = 0, worst_Jw = 0, worst_v = 0;
    for (int k = 0; k < n; ++k) {
      const Joints q = sampler.next_within(nominal);
      const Joints qdot = 0.5 * vmh::testing::JointSampler(seed + k + 1, -1, 1).next();
      set_state(loop, q, qdot);
      DeviceState s;
      kin.fill(loop->model(), loop->data(), &s);
      ASSERT_TRUE(s.has(kStateTransform) && s.has(kStateVelocity) &&
                  s.has(kStateJacobian));
      const Joints t = dh_to_device_joints(q);
      worst_p = std::max(worst_p, (s.transform_mm.topRightCorner<3, 1>() -
                                   p_mm(fk, nominal, t)).cwiseAbs().maxCoeff());
      worst_R = std::max(worst_R, (s.transform_mm.topLeftCorner<3, 3>() -
                                   R_dev(fk, t)).cwiseAbs().maxCoeff());
      EXPECT_EQ(s.transform_mm.row(3), Eigen::RowVector4d(0, 0, 0, 1));
      // the Jacobian's columns: central differences in each device joint
      const double h = 1e-6;
      for (int c = 0; c < 6; ++c) {
        Joints tp = t, tm = t;
        tp[c] += h;
        tm[c] -= h;
        const Vec3 dp = (p_mm(fk, nominal, tp) - p_mm(fk, nominal, tm)) / (2 * h);
        // w from R(t + h) R(t - h)^T = I + [w]x 2h + O(h^2)
        const Mat3 dR = R_dev(fk, tp) * R_dev(fk, tm).transpose();
        const Vec3 w = Vec3(dR(2, 1) - dR(1, 2), dR(0, 2) - dR(2, 0),
                            dR(1, 0) - dR(0, 1)) / (4 * h);
        worst_Jv = std::max(worst_Jv, (s.jacobian.block<3, 1>(0, c) - dp).cwiseAbs().maxCoeff());
        worst_Jw = std::max(worst_Jw, (s.jacobian.block<3, 1>(3, c) - w).cwiseAbs().maxCoeff());
      }
      // the velocity: the position's change along the joint velocity
      const Vec3 v = (p_mm(fk, nominal, dh_to_device_joints(q + h * qdot)) -
                      p_mm(fk, nominal, dh_to_device_joints(q - h * qdot))) / (2 * h);
      worst_v = std::max(worst_v, (s.velocity_mm_s - v).cwiseAbs().maxCoeff());
      // and J t_dot, t_dot the device joints' rates (the map is linear)
      EXPECT_LE((s.jacobian.topRows<3>() * dh_to_device_joints(qdot) -
                 s.velocity_mm_s).cwiseAbs().maxCoeff(), 1e-9);
    }
    std::printf("  worst: p %.2g mm, R %.2g, J_v %.2g mm/rad, J_w %.2g, v %.2g mm/s\n",
                worst_p, worst_R, worst_Jv, worst_Jw, worst_v);
    EXPECT_LE(worst_p, 1e-9);
    EXPECT_LE(worst_R, 1e-12);
    EXPECT_LE(worst_Jv, 1e-5);  // central differences: O(h^2) and rounding
    EXPECT_LE(worst_Jw, 1e-7);
    EXPECT_LE(worst_v, 1e-5);
  }
};

TEST_F(EmulatorKinematicsTest, MatchesOmniFkAndItsDifferences) {
  ClosedLoop loop(kScene, {});
  check(&loop, loop.controller_params().omni, 200, 11u);
}

// a longer real l1 (a seeded fault): the transform follows the true link,
// omni_fk with l1 scaled, still placed in the nominal device frame
TEST_F(EmulatorKinematicsTest, FollowsALongerLink) {
  OmniModelEdit e;
  e.link1_scale = 1.02;
  ClosedLoop loop(kScene, {}, omni_model_hook("", e));
  OmniParams fk = loop.controller_params().omni;
  fk.l1_m *= 1.02;
  check(&loop, fk, 50, 12u);
}

TEST(EmulatorKinematics, ASceneWithoutTheWristSiteIsNamed) {
  const std::string xml = "<mujoco><worldbody><body><joint name='q1'/>"
                          "<geom size='0.1'/></body></worldbody></mujoco>";
  const std::string path = ::testing::TempDir() + "vmh_no_wrist.xml";
  FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs(xml.c_str(), f);
  std::fclose(f);
  ModelPtr model = load_model(path);
  try {
    EmulatorKinematics kin(model.get(), OmniParams{});
    FAIL() << "no throw";
  } catch (const SimError& e) {
    EXPECT_NE(std::string(e.what()).find("wrist"), std::string::npos) << e.what();
  }
}

// On the running emulator: every reading carries the kinematics, and its
// transform is the ground truth's wrist centre (omni_fk of MuJoCo's joint
// angles) and stylus axis. In lockstep the reading and the truth of each
// period are taken together, so every period's reading is checked (the
// old test, on the wall clock, matched five of them).
TEST(EmulatorKinematics, EveryReadingReportsTheTrueKinematics) {
  EmulatorOptions o;
  o.lockstep = true;
  o.scene = kScene;
  o.hand = HandProgram::kTour;
  Emulator emu(o);
  emu.start();
  for (int i = 0; i < 200; ++i) emu.advance();  // moving
  const OmniParams& p = emu.loop().controller_params().omni;
  double worst_p = 0.0, worst_axis = 0.0;
  for (int k = 0; k < 500; ++k) {
    emu.advance();
    DeviceState s;
    ASSERT_EQ(emu.read_state(&s), DeviceError::kOk) << k;
    const EmulatorTruth t = emu.truth();
    ASSERT_EQ(s.timestamp_s, t.wall_s) << k;  // the same period's
    ASSERT_TRUE(s.has(kStateTransform) && s.has(kStateVelocity) &&
                s.has(kStateJacobian)) << k;
    const OmniPose pose = omni_fk(p, t.q_end_dh);
    worst_p = std::max(worst_p, (s.transform_mm.topRightCorner<3, 1>() -
                                 base_to_device_mm(p, pose.p_base_m)).cwiseAbs().maxCoeff());
    worst_axis = std::max(worst_axis, (s.transform_mm.col(2).head<3>() - t.stylus_axis)
                                          .cwiseAbs().maxCoeff());
  }
  emu.stop();
  std::printf("  worst over 500 periods: p %.2g mm, axis %.2g\n", worst_p, worst_axis);
  EXPECT_LE(worst_p, 1e-9);
  EXPECT_LE(worst_axis, 1e-12);
}

}  // namespace
}  // namespace vmh::sim
