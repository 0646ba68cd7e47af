// sim/omni_model_edit: each change checked by a route of its own — the
// scaled link lengths against omni_fk with scaled OmniParams, motor 3's
// coupling against MuJoCo's actuator moments, the scales against the
// model file's numbers, --model against a second load of the same file.
#include "sim/omni_model_edit.h"

#include <gtest/gtest.h>

#include <string>

#include "controller/omni_kinematics.h"
#include "sim/mujoco_util.h"

namespace vmh::sim {
namespace {

const std::string kOmni = std::string(VMH_MODELS_DIR) + "/omni/omni.xml";
const std::string kCase1 = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";

Vec3 wrist_at(const mjModel* m, const Joints& q) {
  mjData* d = mj_makeData(m);
  for (int i = 0; i < 6; ++i) {
    d->qpos[m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, kOmniJoints[i])]] = q[i];
  }
  mj_forward(m, d);
  const int s = mj_name2id(m, mjOBJ_SITE, "wrist");
  Vec3 p(d->site_xpos[3 * s], d->site_xpos[3 * s + 1], d->site_xpos[3 * s + 2]);
  mj_deleteData(d);
  return p;
}

TEST(OmniModelEdit, LinkScalesMoveTheWristAsOmniFkWithScaledLengths) {
  ModelPtr m = load_model(kOmni);
  OmniModelEdit e;
  e.link1_scale = 1.02;
  e.link2_scale = 0.97;
  apply_omni_edit(m.get(), e);
  OmniParams p;
  p.l1_m *= 1.02;
  p.l2_m *= 0.97;
  for (const Joints& q : {Joints((Joints() << 0.1, 0.3, -0.2, 0.4, 0.2, -0.3).finished()),
                          Joints((Joints() << -0.6, -0.5, 0.9, 0, 0, 0).finished())}) {
    const Vec3 expect = omni_fk(p, q).p_base_m;
    EXPECT_LT((wrist_at(m.get(), q) - expect).norm(), 1e-12);
    // and not where the nominal lengths put it
    EXPECT_GT((wrist_at(m.get(), q) - omni_fk(OmniParams(), q).p_base_m).norm(), 1e-3);
  }
}

// motor 3 on t3 = q2 + q3 pushes q2 and q3 alike; made relative, only q3
TEST(OmniModelEdit, Motor3RelativeDropsItsMomentOnQ2) {
  ModelPtr m = load_model(kOmni);
  auto moment = [](const mjModel* mm, const char* joint) {
    mjData* d = mj_makeData(mm);
    mj_forward(mm, d);
    const int a = mj_name2id(mm, mjOBJ_ACTUATOR, "m3");
    const int dof = mm->jnt_dofadr[mj_name2id(mm, mjOBJ_JOINT, joint)];
    const double v = d->actuator_moment[a * mm->nv + dof];
    mj_deleteData(d);
    return v;
  };
  EXPECT_DOUBLE_EQ(moment(m.get(), "q2"), 1.0);
  EXPECT_DOUBLE_EQ(moment(m.get(), "q3"), 1.0);
  OmniModelEdit e;
  e.motor3_relative = true;
  apply_omni_edit(m.get(), e);
  EXPECT_DOUBLE_EQ(moment(m.get(), "q2"), 0.0);
  EXPECT_DOUBLE_EQ(moment(m.get(), "q3"), 1.0);
}

TEST(OmniModelEdit, ScalesMassesFrictionDampingAndGains) {
  ModelPtr m = load_model(kCase1);  // a scene: the hand's bodies untouched
  ModelPtr ref = load_model(kCase1);
  OmniModelEdit e;
  e.mass_scale = 2.0;
  e.friction_scale = 3.0;
  e.damping_scale = 0.5;
  e.motor_gain = Vec3(1.0, -1.0, 1.1);
  apply_omni_edit(m.get(), e);
  const int upper = mj_name2id(m.get(), mjOBJ_BODY, "upper_arm");
  EXPECT_DOUBLE_EQ(m->body_mass[upper], 0.08);  // omni.xml: 0.04 kg
  EXPECT_DOUBLE_EQ(m->body_inertia[3 * upper + 1], 1.2e-4);
  const int q2 = m->jnt_dofadr[mj_name2id(m.get(), mjOBJ_JOINT, "q2")];
  EXPECT_DOUBLE_EQ(m->dof_frictionloss[q2], 0.03);  // 0.01 N m
  EXPECT_DOUBLE_EQ(m->dof_damping[q2], 2.5e-4);
  EXPECT_DOUBLE_EQ(m->actuator_gear[6 * mj_name2id(m.get(), mjOBJ_ACTUATOR, "m2")], -1.0);
  for (int b = 0; b < m->nbody; ++b) {
    bool omni = false;
    for (const char* n : kOmniBodies) omni |= mj_name2id(m.get(), mjOBJ_BODY, n) == b;
    if (!omni) {
      EXPECT_EQ(m->body_mass[b], ref->body_mass[b]) << "body " << b;
    }
  }
  EXPECT_EQ(omni_edit_text(e),
            "mass_scale=2,damping_scale=0.5,friction_scale=3,motor_gain2=-1,"
            "motor_gain3=1.1");
}

TEST(OmniModelEdit, CopyParametersCarriesACalibratedOmniIntoAScene) {
  ModelPtr calibrated = load_model(kOmni);
  OmniModelEdit e;
  e.mass_scale = 1.5;
  e.friction_scale = 2.0;
  e.link1_scale = 1.01;
  e.motor3_relative = true;
  apply_omni_edit(calibrated.get(), e);
  ModelPtr scene = load_model(kCase1);
  copy_omni_parameters(scene.get(), calibrated.get(), "calibrated");
  for (const char* n : kOmniBodies) {
    EXPECT_DOUBLE_EQ(scene->body_mass[mj_name2id(scene.get(), mjOBJ_BODY, n)],
                     calibrated->body_mass[mj_name2id(calibrated.get(), mjOBJ_BODY, n)]);
  }
  const Joints q = (Joints() << 0.2, 0.1, 0.3, 0, 0, 0).finished();
  EXPECT_LT((wrist_at(scene.get(), q) - wrist_at(calibrated.get(), q)).norm(), 1e-12);
}

TEST(OmniModelEdit, BadInputIsNamed) {
  ModelPtr m = load_model(kOmni);
  OmniModelEdit e;
  e.mass_scale = -1.0;
  try {
    apply_omni_edit(m.get(), e);
    FAIL() << "a negative mass scale was taken";
  } catch (const std::invalid_argument& ex) {
    EXPECT_NE(std::string(ex.what()).find("mass_scale"), std::string::npos);
  }
  ModelPtr slider = load_model(std::string(VMH_MODELS_DIR) + "/slider/slider.xml");
  try {
    apply_omni_edit(slider.get(), OmniModelEdit{2.0});
    FAIL() << "a model without the Omni was edited";
  } catch (const SimError& ex) {
    EXPECT_NE(std::string(ex.what()).find("turret"), std::string::npos) << ex.what();
  }
  EXPECT_THROW(load_omni_parameters(m.get(), "/nonexistent/omni.xml"), SimError);
}

}  // namespace
}  // namespace vmh::sim
