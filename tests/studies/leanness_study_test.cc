// studies/leanness_study.cc: the scenes as composed against the same scenes with
// contacts, gravity and a viewer's scene update switched on.
//
// Performance figures are reported by `vmhaptics study leanness`, never
// asserted here (a shared machine makes any timing threshold flaky). What is
// asserted is that each variant really is what its name says, read back
// from the model and data its run used, and what follows from that without
// a clock: the contacts variant finds contacts and carries more constraint
// rows, viewing does not change the motion, gravity does.
#include "studies/leanness_study.h"

#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <string>

#include "sim/closed_loop.h"
#include "tests/support/mujoco_guard.h"

namespace {

using vmh::studies::CaseLeanness;
using vmh::studies::LeannessOptions;
using vmh::studies::LeannessResult;
using vmh::studies::VariantResult;

class LeannessStudy : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    vmh::testing::MujocoGuard guard;
    LeannessOptions o;
    o.scenes = {{"case1", std::string(VMH_MODELS_DIR) + "/cases/case1.xml"}};
    o.duration_s = 0.2;  // 200 ticks of the script compressed into 0.2 s
    o.repeats = 1;
    result_ = new LeannessResult(vmh::studies::run_leanness_study(o));
    warnings_ = new std::string(guard.warnings());
  }
  static void TearDownTestSuite() {
    delete result_;
    delete warnings_;
  }

  static const VariantResult& variant(const std::string& name) {
    for (const VariantResult& v : result_->cases.at(0).variants) {
      if (v.variant.name == name) return v;
    }
    throw std::runtime_error("no variant " + name);
  }

  static LeannessResult* result_;
  static std::string* warnings_;
};

LeannessResult* LeannessStudy::result_ = nullptr;
std::string* LeannessStudy::warnings_ = nullptr;

TEST_F(LeannessStudy, EveryVariantRanEveryTick) {
  ASSERT_EQ(result_->cases.size(), 1u);
  const CaseLeanness& c = result_->cases[0];
  EXPECT_EQ(c.nv, 6);
  EXPECT_EQ(c.ticks, 200);
  EXPECT_EQ(c.substeps, 1);  // Euler, h = T = 1 ms (models/cases/)
  ASSERT_EQ(c.variants.size(), vmh::studies::leanness_variants().size());
  for (const VariantResult& v : c.variants) {
    EXPECT_GT(v.wall_time_s, 0.0) << v.variant.name;
    EXPECT_GT(v.cpu_time_s, 0.0) << v.variant.name;
    EXPECT_GT(v.steps_per_s, 0.0) << v.variant.name;
    EXPECT_EQ(v.mujoco_warnings, 0) << v.variant.name;
  }
  EXPECT_GT(c.controller_cpu_time_s, 0.0);
  EXPECT_EQ(*warnings_, "");
}

TEST_F(LeannessStudy, ComposedSceneLeavesContactsAndGravityOut) {
  const VariantResult& v = variant("composed");
  EXPECT_FALSE(v.contact_enabled);
  EXPECT_FALSE(v.gravity_enabled);
  EXPECT_TRUE(v.frictionloss_enabled);
  EXPECT_EQ(v.colliding_geoms, 0);
  EXPECT_EQ(v.max_ncon, 0);
  EXPECT_EQ(v.scene_geoms, 0);
  EXPECT_DOUBLE_EQ(v.slowdown, 1.0);
  EXPECT_DOUBLE_EQ(v.max_deviation_mm, 0.0);
}

TEST_F(LeannessStudy, ContactsVariantCollidesAndCarriesMoreRows) {
  const VariantResult& composed = variant("composed");
  for (const char* name : {"contacts", "all"}) {
    const VariantResult& v = variant(name);
    EXPECT_TRUE(v.contact_enabled) << name;
    EXPECT_EQ(v.colliding_geoms, result_->cases[0].ngeom) << name;
    // with every geom made to collide, the turret's collision cylinder
    // overlaps the fixed drum under it (the world is not its parent for
    // MuJoCo's filter), so contacts are found and carry constraint rows;
    // that contact is along the turret's axis and moves nothing, so the
    // motion itself is not compared
    EXPECT_GT(v.max_ncon, 0) << name;
    EXPECT_GT(v.mean_nefc, composed.mean_nefc) << name;
  }
}

TEST_F(LeannessStudy, GravityVariantHasGravityAndItMovesTheArm) {
  const VariantResult& v = variant("gravity");
  EXPECT_TRUE(v.gravity_enabled);
  EXPECT_FALSE(v.contact_enabled);
  EXPECT_GT(v.max_deviation_mm, 1.0);
}

TEST_F(LeannessStudy, RenderingFillsASceneAndChangesNothing) {
  const VariantResult& v = variant("rendering");
  // the Omni's drawn geoms: groups 0-2 are visible by default, the
  // collision class (group 3) is not
  int visible = 0;
  {
    vmh::sim::ClosedLoop loop(result_->cases[0].scene, {});
    for (int g = 0; g < loop.model()->ngeom; ++g) {
      visible += loop.model()->geom_group[g] <= 2 ? 1 : 0;
    }
  }
  EXPECT_GT(visible, 20);
  EXPECT_LT(visible, result_->cases[0].ngeom);
  EXPECT_EQ(v.scene_geoms, visible);
  EXPECT_FALSE(v.contact_enabled);
  EXPECT_FALSE(v.gravity_enabled);
  EXPECT_GT(v.render_us_per_tick, 0.0);
  EXPECT_EQ(variant("composed").render_us_per_tick, 0.0);
  // updating a scene reads mjData and writes only the scene
  EXPECT_EQ(v.max_deviation_mm, 0.0);
  EXPECT_GT(variant("all").scene_geoms, 0);
  EXPECT_TRUE(variant("all").gravity_enabled);
}

TEST_F(LeannessStudy, NoFrictionlossDropsTheFrictionRows) {
  const VariantResult& composed = variant("composed");
  const VariantResult& v = variant("no_frictionloss");
  EXPECT_FALSE(v.frictionloss_enabled);
  // one frictionloss row per joint in the composed scene
  EXPECT_GE(composed.mean_nefc, 6.0);
  EXPECT_LT(v.mean_nefc, composed.mean_nefc - 5.0);
}

TEST_F(LeannessStudy, TableHasOneRowPerVariant) {
  const std::string csv = vmh::studies::leanness_csv(*result_);
  std::istringstream in(csv);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("case,variant,contacts,gravity,rendering,", 0), 0u);
  for (const char* col : {"wall_time_s", "cpu_time_s", "steps_per_s",
                          "slowdown", "mean_ncon", "max_deviation_mm"}) {
    EXPECT_NE(header.find(col), std::string::npos) << col;
  }
  int lines = 0;
  std::string line;
  while (std::getline(in, line)) {
    ++lines;
    EXPECT_EQ(line.rfind("case1,", 0), 0u) << line;
  }
  EXPECT_EQ(lines, static_cast<int>(vmh::studies::leanness_variants().size()));
}

}  // namespace
