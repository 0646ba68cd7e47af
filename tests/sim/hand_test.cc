// sim/hand: the simulated hand. Its mass and inertia join the body that
// carries the "grip" site, and at every step it pulls the grip toward the
// "hand_target" pose with a 6-DOF spring-damper, applied through
// d->qfrc_applied.
//
// The wrench is checked against numbers worked out by hand (K_p times a
// known displacement, K_r times a known angle about a known axis), and its
// generalised force against MuJoCo's own site Jacobian (mj_jacSite):
// qfrc = J_p^T F + J_r^T tau. All in the world (DH base) frame, SI.
#include "sim/hand.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "sim/cases/case_config.h"
#include "sim/mujoco_util.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/temp_mjcf.h"

namespace vmh::sim {
namespace {

using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

std::string case1_scene() { return std::string(VMH_MODELS_DIR) + "/cases/case1.xml"; }

// inertia tensor of body b about its own frame's origin, body axes:
// principal inertia rotated by body_iquat, moved from the centre of mass by
// the parallel-axis theorem
Mat3 inertia_about_body_origin(const mjModel* m, int b) {
  RowMat3 R;
  mju_quat2Mat(R.data(), m->body_iquat + 4 * b);
  const Vec3 I_principal(m->body_inertia + 3 * b);
  const Vec3 c(m->body_ipos + 3 * b);
  const double mass = m->body_mass[b];
  return Mat3(R) * I_principal.asDiagonal() * Mat3(R).transpose() +
         mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
}

class HandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    model_ = load_model(case1_scene());
    data_.reset(mj_makeData(model_.get()));
    grip_ = mj_name2id(model_.get(), mjOBJ_SITE, "grip");
    ASSERT_GE(grip_, 0);
  }

  // puts the arm at q (DH, rad) with joint velocities qdot and computes
  // positions and velocities
  void pose(const Joints& q, const Joints& qdot = Joints::Zero()) {
    const mjModel* m = model_.get();
    for (int i = 0; i < 6; ++i) {
      const std::string name = "q" + std::to_string(i + 1);
      const int j = mj_name2id(m, mjOBJ_JOINT, name.c_str());
      data_->qpos[m->jnt_qposadr[j]] = q[i];
      data_->qvel[m->jnt_dofadr[j]] = qdot[i];
    }
    mj_forward(m, data_.get());
  }

  Vec3 grip_p_m() const { return Vec3(data_->site_xpos + 3 * grip_); }
  Mat3 grip_R() const {
    return Eigen::Map<const RowMat3>(data_->site_xmat + 9 * grip_);
  }

  // J_p^T F + J_r^T tau from MuJoCo's site Jacobian
  std::vector<double> generalised(const Vec3& F_N, const Vec3& tau_Nm) const {
    const int nv = model_->nv;
    std::vector<double> jacp(3 * static_cast<std::size_t>(nv)),
        jacr(3 * static_cast<std::size_t>(nv));
    mj_jacSite(model_.get(), data_.get(), jacp.data(), jacr.data(), grip_);
    std::vector<double> q(static_cast<std::size_t>(nv), 0.0);
    for (int i = 0; i < nv; ++i) {
      for (int r = 0; r < 3; ++r) {
        q[i] += jacp[r * nv + i] * F_N[r] + jacr[r * nv + i] * tau_Nm[r];
      }
    }
    return q;
  }

  // J_p qdot and J_r qdot: the grip's linear and angular velocity
  void grip_velocity(Vec3* v_m_s, Vec3* w_rad_s) const {
    const int nv = model_->nv;
    std::vector<double> jacp(3 * static_cast<std::size_t>(nv)),
        jacr(3 * static_cast<std::size_t>(nv));
    mj_jacSite(model_.get(), data_.get(), jacp.data(), jacr.data(), grip_);
    v_m_s->setZero();
    w_rad_s->setZero();
    for (int r = 0; r < 3; ++r) {
      for (int i = 0; i < nv; ++i) {
        (*v_m_s)[r] += jacp[r * nv + i] * data_->qvel[i];
        (*w_rad_s)[r] += jacr[r * nv + i] * data_->qvel[i];
      }
    }
  }

  testing::MujocoGuard guard_;
  ModelPtr model_;
  DataPtr data_;
  int grip_ = -1;
  const Joints q_ = (Joints() << 0.2, 0.3, 0.1, 0.4, -0.3, 0.5).finished();
};

TEST_F(HandTest, AddsTheHandToTheGripBody) {
  mjModel* m = model_.get();
  const int b = m->site_bodyid[grip_];
  EXPECT_STREQ(m->names + m->name_bodyadr[b], "stylus");
  const double mass_before_kg = m->body_mass[b];
  const double total_before_kg = m->body_subtreemass[0];
  const Mat3 I_before = inertia_about_body_origin(m, b);

  HandParams h;
  h.mass_kg = 0.5;
  h.inertia_kgm2 = Vec3(1e-4, 2e-4, 3e-4);
  SimHand hand(m, data_.get(), h, case1_scene());

  EXPECT_NEAR(m->body_mass[b], mass_before_kg + 0.5, 1e-15);
  // mj_setConst ran: the world's subtree carries the extra mass too
  EXPECT_NEAR(m->body_subtreemass[0], total_before_kg + 0.5, 1e-12);
  // the hand as a rigid body at the grip site, grip-site axes, moved to the
  // body origin by the parallel-axis theorem, adds to the body's tensor
  RowMat3 R_site;
  mju_quat2Mat(R_site.data(), m->site_quat + 4 * grip_);
  const Vec3 c_site(m->site_pos + 3 * grip_);
  const Mat3 I_hand =
      Mat3(R_site) * h.inertia_kgm2.asDiagonal() * Mat3(R_site).transpose() +
      0.5 * (c_site.squaredNorm() * Mat3::Identity() -
             c_site * c_site.transpose());
  const Mat3 I_after = inertia_about_body_origin(m, b);
  EXPECT_TRUE(I_after.isApprox(I_before + I_hand, 1e-10))
      << "after:\n"
      << I_after << "\nexpected:\n"
      << I_before + I_hand;
  // grip 50 mm down the stylus axis (omni.xml): the centre of mass moves
  // toward it, (0.02 kg at -45 mm + 0.5 kg at -50 mm) / 0.52 kg
  ASSERT_NEAR(mass_before_kg, 0.02, 1e-15);
  EXPECT_NEAR(m->body_ipos[3 * b + 2], (0.02 * -0.045 + 0.5 * -0.05) / 0.52,
              1e-12);
}

// Target 10, -20, 5 mm from the grip, same orientation, everything at rest:
// F = 135 N/m x dx, no torque.
TEST_F(HandTest, SpringForceIsStiffnessTimesDisplacement) {
  SimHand hand(model_.get(), data_.get(), HandParams(), case1_scene());
  pose(q_);
  HandTargetState target;
  target.p_m = grip_p_m() + Vec3(0.010, -0.020, 0.005);
  target.R = grip_R();
  hand.set_target(model_.get(), data_.get(), target);
  hand.apply(model_.get(), data_.get());
  EXPECT_NEAR(hand.force_N().x(), 1.35, 1e-9);
  EXPECT_NEAR(hand.force_N().y(), -2.70, 1e-9);
  EXPECT_NEAR(hand.force_N().z(), 0.675, 1e-9);
  EXPECT_LT(hand.torque_Nm().norm(), 1e-9);
}

// A pen grip's hand is stiffer fore-aft than sideways: per-axis stiffness
// along the device frame. The world is the DH base frame, whose x, y, z are
// the device's z (toward the user), x (right) and y (up) (docs/kinematics.md), so
// a target 10 mm off along base x is 10 mm along device z: F = k_z dx
// there, and likewise for the other two, each alone on its axis.
TEST_F(HandTest, PerAxisStiffnessActsAlongTheDeviceAxes) {
  HandParams p;
  p.k_pos_axes_N_per_m = Vec3(65.0, 88.0, 201.0);  // device x, y, z
  SimHand hand(model_.get(), data_.get(), p, case1_scene());
  pose(q_);
  struct Push {
    Vec3 d_base_m;
    Vec3 expected_base_N;
  };
  for (const Push& push : {Push{Vec3(0.010, 0, 0), Vec3(2.01, 0, 0)},    // device z
                           Push{Vec3(0, 0.010, 0), Vec3(0, 0.65, 0)},    // device x
                           Push{Vec3(0, 0, -0.010), Vec3(0, 0, -0.88)},  // device y
                           Push{Vec3(0.010, 0.010, 0.010),
                                Vec3(2.01, 0.65, 0.88)}}) {
    HandTargetState target;
    target.p_m = grip_p_m() + push.d_base_m;
    target.R = grip_R();
    hand.set_target(model_.get(), data_.get(), target);
    hand.apply(model_.get(), data_.get());
    EXPECT_TRUE(hand.force_N().isApprox(push.expected_base_N, 1e-9))
        << hand.force_N().transpose() << " vs "
        << push.expected_base_N.transpose();
  }
}

// The same for damping; and a hand without per-axis values (0 0 0) keeps
// its scalar on every axis.
TEST_F(HandTest, PerAxisDampingActsAlongTheDeviceAxesAndZeroMeansTheScalar) {
  HandParams p;
  p.b_pos_axes_Ns_per_m = Vec3(3.2, 4.6, 9.9);  // device x, y, z
  SimHand hand(model_.get(), data_.get(), p, case1_scene());
  pose(q_);  // at rest
  HandTargetState target;
  target.p_m = grip_p_m() + Vec3(0.010, 0.0, 0.0);
  target.R = grip_R();
  target.v_m_s = Vec3(0.1, -0.2, 0.3);  // base x, y, z: device z, x, y
  hand.set_target(model_.get(), data_.get(), target);
  hand.apply(model_.get(), data_.get());
  // stiffness still the scalar 135 N/m (its axes are 0 0 0)
  const Vec3 expected(1.35 + 9.9 * 0.1, 3.2 * -0.2, 4.6 * 0.3);
  EXPECT_TRUE(hand.force_N().isApprox(expected, 1e-9))
      << hand.force_N().transpose() << " vs " << expected.transpose();
}

// Target turned 0.3 rad about world x from the grip, same place: tau =
// 0.5 N m/rad x 0.3 rad about x; and 0.2 rad about (0, 0.6, 0.8).
TEST_F(HandTest, SpringTorqueIsStiffnessTimesAngle) {
  SimHand hand(model_.get(), data_.get(), HandParams(), case1_scene());
  pose(q_);
  struct Turn {
    Vec3 axis;
    double angle_rad;
    Vec3 expected_Nm;
  };
  for (const Turn& turn :
       {Turn{Vec3::UnitX(), 0.3, Vec3(0.15, 0.0, 0.0)},
        Turn{Vec3(0.0, 0.6, 0.8), 0.2, Vec3(0.0, 0.06, 0.08)},
        Turn{-Vec3::UnitZ(), 1.0, Vec3(0.0, 0.0, -0.5)}}) {
    HandTargetState target;
    target.p_m = grip_p_m();
    target.R = Eigen::AngleAxisd(turn.angle_rad, turn.axis) * grip_R();
    hand.set_target(model_.get(), data_.get(), target);
    hand.apply(model_.get(), data_.get());
    EXPECT_TRUE(hand.torque_Nm().isApprox(turn.expected_Nm, 1e-9))
        << hand.torque_Nm().transpose() << " vs "
        << turn.expected_Nm.transpose();
    EXPECT_LT(hand.force_N().norm(), 1e-9);
  }
}

// With the grip moving and the target moving: F = B_p (v_target - v_grip),
// tau = B_r (w_target - w_grip), the grip's twist from J qdot.
TEST_F(HandTest, DampingActsOnTheRelativeTwist) {
  SimHand hand(model_.get(), data_.get(), HandParams(), case1_scene());
  Joints qdot;
  qdot << 0.5, -0.4, 0.3, 1.0, -2.0, 1.5;
  pose(q_, qdot);
  Vec3 v_grip, w_grip;
  grip_velocity(&v_grip, &w_grip);
  ASSERT_GT(v_grip.norm(), 0.01);
  HandTargetState target;
  target.p_m = grip_p_m();
  target.R = grip_R();
  target.v_m_s = Vec3(0.1, 0.0, -0.05);
  target.w_rad_s = Vec3(0.0, 2.0, 0.0);
  hand.set_target(model_.get(), data_.get(), target);
  hand.apply(model_.get(), data_.get());
  const Vec3 F_expected = 6.45 * (target.v_m_s - v_grip);
  const Vec3 tau_expected = 0.02 * (target.w_rad_s - w_grip);
  EXPECT_TRUE(hand.force_N().isApprox(F_expected, 1e-9))
      << hand.force_N().transpose() << " vs " << F_expected.transpose();
  EXPECT_TRUE(hand.torque_Nm().isApprox(tau_expected, 1e-9))
      << hand.torque_Nm().transpose() << " vs " << tau_expected.transpose();
}

// The wrench reaches the joints as J_p^T F + J_r^T tau, replacing whatever
// qfrc_applied held.
TEST_F(HandTest, WrenchEntersQfrcAppliedThroughTheGripJacobian) {
  SimHand hand(model_.get(), data_.get(), HandParams(), case1_scene());
  pose(q_);
  HandTargetState target;
  target.p_m = grip_p_m() + Vec3(-0.004, 0.012, 0.02);
  target.R = Eigen::AngleAxisd(0.25, Vec3(1, -1, 0.5).normalized()) * grip_R();
  hand.set_target(model_.get(), data_.get(), target);
  for (int i = 0; i < model_->nv; ++i) data_->qfrc_applied[i] = 1.0;
  hand.apply(model_.get(), data_.get());
  // K_p dx and K_r angle axis, by hand
  const Vec3 F_N = 135.0 * Vec3(-0.004, 0.012, 0.02);
  const Vec3 tau_Nm = 0.5 * 0.25 * Vec3(1, -1, 0.5).normalized();
  ASSERT_TRUE(hand.force_N().isApprox(F_N, 1e-9));
  ASSERT_TRUE(hand.torque_Nm().isApprox(tau_Nm, 1e-9));
  const std::vector<double> expected = generalised(F_N, tau_Nm);
  double largest = 0.0;
  for (int i = 0; i < model_->nv; ++i) {
    EXPECT_NEAR(data_->qfrc_applied[i], expected[static_cast<std::size_t>(i)],
                1e-9)
        << "dof " << i;
    largest =
        std::max(largest, std::abs(expected[static_cast<std::size_t>(i)]));
  }
  EXPECT_GT(largest, 1e-3);  // the check is not of zeros
  // and only there: nothing is left in the Cartesian xfrc_applied
  for (int i = 0; i < 6 * model_->nbody; ++i) {
    EXPECT_EQ(data_->xfrc_applied[i], 0.0) << i;
  }
}

TEST_F(HandTest, SetTargetMovesTheMocapBody) {
  SimHand hand(model_.get(), data_.get(), HandParams(), case1_scene());
  const int body = mj_name2id(model_.get(), mjOBJ_BODY, "hand_target");
  const int mocap = model_->body_mocapid[body];
  ASSERT_GE(mocap, 0);
  HandTargetState target;
  target.p_m = Vec3(0.1, -0.02, 0.03);
  target.R = Eigen::AngleAxisd(0.7, Vec3(0, 0, 1)).toRotationMatrix();
  hand.set_target(model_.get(), data_.get(), target);
  EXPECT_EQ(Vec3(data_->mocap_pos + 3 * mocap), target.p_m);
  RowMat3 R;
  mju_quat2Mat(R.data(), data_->mocap_quat + 4 * mocap);
  EXPECT_TRUE(Mat3(R).isApprox(target.R, 1e-12));
}

TEST_F(HandTest, HandParamsComeFromTheCase) {
  const CaseConfig c = CaseConfig::from_model(
      model_.get(), case1_scene(),
      {"hand_mass_kg=0.3", "hand_inertia_kgm2=1e-4,2e-4,3e-4",
       "hand_k_pos_N_per_m=200", "hand_b_pos_Ns_per_m=4",
       "hand_k_rot_Nm_per_rad=0.7", "hand_b_rot_Nms_per_rad=0.01",
       "hand_k_pos_axes_N_per_m=65,88,201",
       "hand_b_pos_axes_Ns_per_m=3.2,4.6,9.9"});
  const HandParams h = hand_params(c);
  EXPECT_EQ(h.k_pos_axes_N_per_m, Vec3(65.0, 88.0, 201.0));
  EXPECT_EQ(h.b_pos_axes_Ns_per_m, Vec3(3.2, 4.6, 9.9));
  EXPECT_EQ(h.mass_kg, 0.3);
  EXPECT_EQ(h.inertia_kgm2, Vec3(1e-4, 2e-4, 3e-4));
  EXPECT_EQ(h.k_pos_N_per_m, 200.0);
  EXPECT_EQ(h.b_pos_Ns_per_m, 4.0);
  EXPECT_EQ(h.k_rot_Nm_per_rad, 0.7);
  EXPECT_EQ(h.b_rot_Nms_per_rad, 0.01);
}

// ---- scenes without the pieces the hand needs ---------------------------

class HandSceneTest : public ::testing::Test {
 protected:
  std::string hand_error(bool with_grip, bool with_target, bool mocap) {
    std::string xml =
        "<mujoco model=\"hand_parts\">\n<worldbody>\n"
        "<body name=\"stylus\"><inertial pos=\"0 0 0\" mass=\"0.02\" "
        "diaginertia=\"1e-5 1e-5 1e-5\"/>"
        "<joint name=\"q1\" type=\"hinge\" axis=\"0 0 1\"/>";
    if (with_grip) xml += "<site name=\"grip\" pos=\"0 0 -0.05\"/>";
    xml += "</body>\n";
    if (with_target) {
      xml += std::string("<body name=\"hand_target\"") +
             (mocap ? " mocap=\"true\"" : "") + ">";
      if (!mocap) {
        xml +=
            "<inertial pos=\"0 0 0\" mass=\"0.01\" "
            "diaginertia=\"1e-6 1e-6 1e-6\"/>";
      }
      xml += "</body>\n";
    }
    xml += "</worldbody>\n</mujoco>\n";
    path_ = dir_.write("hand_parts.xml", xml);
    ModelPtr m = load_model(path_);
    DataPtr d(mj_makeData(m.get()));
    try {
      SimHand hand(m.get(), d.get(), HandParams(), path_);
    } catch (const SimError& e) {
      return e.what();
    }
    return "";
  }

  testing::MujocoGuard guard_;
  testing::TempMjcfDir dir_;
  std::string path_;
};

TEST_F(HandSceneTest, CompleteSceneIsAccepted) {
  EXPECT_EQ(hand_error(true, true, true), "");
}

TEST_F(HandSceneTest, MissingGripSiteIsNamed) {
  const std::string msg = hand_error(false, true, true);
  EXPECT_NE(msg.find("site 'grip'"), std::string::npos) << msg;
  EXPECT_NE(msg.find(path_), std::string::npos) << msg;
}

TEST_F(HandSceneTest, MissingTargetBodyIsNamed) {
  const std::string msg = hand_error(true, false, true);
  EXPECT_NE(msg.find("body 'hand_target'"), std::string::npos) << msg;
  EXPECT_NE(msg.find(path_), std::string::npos) << msg;
}

TEST_F(HandSceneTest, TargetThatIsNotMocapIsRefused) {
  const std::string msg = hand_error(true, true, false);
  EXPECT_NE(msg.find("'hand_target'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("mocap"), std::string::npos) << msg;
}

}  // namespace
}  // namespace vmh::sim
