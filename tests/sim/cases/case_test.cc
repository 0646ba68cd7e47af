// sim/cases/case: a case read from a scene as data, without a loop. The expected
// values are the scenes' own (models/cases/case1.xml and case3.xml: Euler
// at 1 ms, a 20 s thesis script, K_pos 0.5 and 0.6 N/mm) and the case
// table's documented defaults, written out here; the refusals are the
// ones a loop over the same scene gave before it read its case through
// make_case().
#include "sim/cases/case.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "sim/closed_loop.h"

namespace vmh::sim {
namespace {

const std::string kCase1 = std::string(VMH_MODELS_DIR) + "/cases/case1.xml";
const std::string kCase3 = std::string(VMH_MODELS_DIR) + "/cases/case3.xml";

// the SimError's message of load_case, "" if it loads
std::string refusal(const std::string& scene,
                    const std::vector<std::string>& sets) {
  try {
    load_case(scene, sets);
  } catch (const SimError& e) {
    return e.what();
  }
  return "";
}

TEST(Case, ReadsTheScenesParametersScriptAndTiming) {
  const Case c = load_case(kCase1, {});
  EXPECT_EQ(c.scene_path(), kCase1);
  EXPECT_EQ(c.config().thesis_case, 1);
  EXPECT_EQ(c.controller_params().vm.kind, VmKind::kCircle);
  EXPECT_DOUBLE_EQ(c.controller_params().vm.length_mm, 50.0);
  EXPECT_DOUBLE_EQ(c.controller_params().gains.k_pos_N_per_mm, 0.5);
  EXPECT_DOUBLE_EQ(c.controller_params().servo_period_s, 0.001);
  EXPECT_DOUBLE_EQ(c.physics_step_s(), 0.001);
  EXPECT_EQ(c.integrator(), IntegratorSetting::kEuler);
  EXPECT_EQ(c.substeps(), 1);
  EXPECT_FALSE(c.jitter());
  EXPECT_EQ(c.ticks_per_run(), 20000);  // 20 s at 1 kHz
  // the thesis script: settle, three off-path holds, two misaligned holds
  // on the path, the sweep
  ASSERT_EQ(c.script().segments().size(), 7u);
  EXPECT_EQ(c.script().segments().front().name, "settle");
  EXPECT_EQ(c.script().segments().back().name, "sweep");
  EXPECT_DOUBLE_EQ(c.script().segments().back().t1_s, 20.0);
  EXPECT_DOUBLE_EQ(load_case(kCase3, {}).controller_params().gains.k_pos_N_per_mm,
                   0.6);
}

TEST(Case, OverridesChangeTheTimingAndTheScript) {
  const Case c = load_case(
      kCase1, {"physics_step_s=0.00025", "integrator=rk4", "duration_s=2",
               "servo_jitter_s=0.0005,0.0015", "k_pos_N_per_mm=0.3"});
  EXPECT_DOUBLE_EQ(c.physics_step_s(), 0.00025);
  EXPECT_EQ(c.integrator(), IntegratorSetting::kRk4);
  EXPECT_EQ(c.substeps(), 4);
  EXPECT_TRUE(c.jitter());
  EXPECT_EQ(c.substeps_min(), 2);
  EXPECT_EQ(c.substeps_max(), 6);
  EXPECT_EQ(c.ticks_per_run(), 2000);
  EXPECT_DOUBLE_EQ(c.script().segments().back().t1_s, 2.0);
  EXPECT_DOUBLE_EQ(c.controller_params().gains.k_pos_N_per_mm, 0.3);
}

// A case outlives the model it was read from and is copied as plain data.
TEST(Case, IsPlainDataThatOutlivesItsModel) {
  std::vector<Case> kept;
  kept.push_back(load_case(kCase1, {"duration_s=4"}));
  const Case copy = kept.front();
  kept.clear();
  EXPECT_EQ(copy.ticks_per_run(), 4000);
  EXPECT_DOUBLE_EQ(copy.script().segments().back().t1_s, 4.0);
}

// The loop runs the case it reads: the same parameters, script and timing
// as a case read alone (what lets the studies read a case without a loop).
TEST(Case, ALoopRunsTheCaseReadAlone) {
  const std::vector<std::string> sets = {"physics_step_s=0.0005",
                                         "duration_s=3"};
  const Case alone = load_case(kCase1, sets);
  ClosedLoop loop(kCase1, sets);
  EXPECT_EQ(loop.ticks_per_run(), alone.ticks_per_run());
  EXPECT_EQ(loop.substeps(), alone.substeps());
  EXPECT_DOUBLE_EQ(loop.model()->opt.timestep, alone.physics_step_s());
  EXPECT_EQ(loop.script().segments().size(), alone.script().segments().size());
  EXPECT_DOUBLE_EQ(loop.controller_params().gains.k_ornt_Nmm_per_rad,
                   alone.controller_params().gains.k_ornt_Nmm_per_rad);
  // and its ticks cover the case's duration
  TickRecord row;
  std::int64_t n = 0;
  while (!loop.finished()) {
    loop.tick(&row);
    ++n;
  }
  EXPECT_EQ(n, alone.ticks_per_run());
}

// Scaled gains against the same case with its four gains set by `--set`
// at the scaled values (the scene's own parameters, an independent route
// through the case table), on case 3 with an orientation damping added so
// that every gain is non-zero; and a loop over the scaled case runs those
// gains with the case's script
TEST(Case, ScaledGainsAreTheGainsSetByHand) {
  const double s = 0.37;
  const Case base = load_case(kCase3, {"k_vel_ornt_Nmms_per_rad=2.5"});
  const ControllerSettings& k = base.config().controller;
  ASSERT_GT(k.k_ornt_multiple, 0.0);
  ASSERT_GT(k.k_vel_ornt_Nmms_per_rad, 0.0);
  auto num = [](double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return std::string(buf);
  };
  const Case by_hand = load_case(
      kCase3, {"k_pos_N_per_mm=" + num(s * k.k_pos_N_per_mm),
               "k_ornt_multiple=" + num(s * k.k_ornt_multiple),
               "k_vel_Ns_per_mm=" + num(s * k.k_vel_Ns_per_mm),
               "k_vel_ornt_Nmms_per_rad=" + num(s * k.k_vel_ornt_Nmms_per_rad)});
  const Case scaled = base.with_gains_scaled(s);
  const Gains& g = scaled.controller_params().gains;
  const Gains& h = by_hand.controller_params().gains;
  EXPECT_NEAR(g.k_pos_N_per_mm, h.k_pos_N_per_mm, 1e-12 * h.k_pos_N_per_mm);
  EXPECT_NEAR(g.k_ornt_Nmm_per_rad, h.k_ornt_Nmm_per_rad,
              1e-12 * h.k_ornt_Nmm_per_rad);
  EXPECT_NEAR(g.k_vel_Ns_per_mm, h.k_vel_Ns_per_mm, 1e-12 * h.k_vel_Ns_per_mm);
  EXPECT_NEAR(g.k_vel_ornt_Nmms_per_rad, h.k_vel_ornt_Nmms_per_rad,
              1e-12 * h.k_vel_ornt_Nmms_per_rad);
  EXPECT_NEAR(g.k_pos_N_per_mm, 0.37 * 0.6, 1e-12);  // case 3's K_pos
  EXPECT_NEAR(scaled.config().controller.k_pos_N_per_mm, 0.37 * 0.6, 1e-12);
  // the rest of the case is the case's own
  EXPECT_EQ(scaled.scene_path(), base.scene_path());
  EXPECT_EQ(scaled.ticks_per_run(), base.ticks_per_run());
  EXPECT_EQ(scaled.script().segments().size(), base.script().segments().size());
  EXPECT_DOUBLE_EQ(scaled.controller_params().vm.length_mm,
                   base.controller_params().vm.length_mm);
  ClosedLoop loop(scaled);
  EXPECT_DOUBLE_EQ(loop.controller_params().gains.k_pos_N_per_mm, g.k_pos_N_per_mm);
  EXPECT_DOUBLE_EQ(loop.controller().params().gains.k_ornt_Nmm_per_rad,
                   g.k_ornt_Nmm_per_rad);
  EXPECT_EQ(loop.ticks_per_run(), base.ticks_per_run());
}

TEST(Case, AGainScaleMustBeFiniteAndPositive) {
  const Case base = load_case(kCase1, {});
  for (double s : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
    try {
      (void)base.with_gains_scaled(s);
      ADD_FAILURE() << "scale " << s << " was taken";
    } catch (const SimError& e) {
      EXPECT_NE(std::string(e.what()).find(kCase1), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("gain scale"), std::string::npos) << e.what();
    }
  }
}

TEST(Case, RefusesWhatALoopRefusedNamingTheFileAndField) {
  using std::string;
  const auto npos = string::npos;
  string m = refusal(kCase1, {"physics_step_s=0.004"});  // 1/4 step a tick
  EXPECT_NE(m.find(kCase1), npos) << m;
  EXPECT_NE(m.find("whole number of physics steps"), npos) << m;
  m = refusal(kCase1, {"physics_step_s=0.0003"});  // 3.33 steps
  EXPECT_NE(m.find("whole multiple of the physics step"), npos) << m;
  m = refusal(kCase1, {"duration_s=0.0001"});
  EXPECT_NE(m.find("duration_s"), npos) << m;
  m = refusal(kCase1, {"servo_jitter_s=0.0005,0.00125"});
  EXPECT_NE(m.find("servo_jitter_s"), npos) << m;
  m = refusal(kCase1, {"no_such_field=1"});
  EXPECT_NE(m.find("no_such_field"), npos) << m;
  m = refusal(std::string(VMH_MODELS_DIR) + "/cases/missing.xml", {});
  EXPECT_NE(m.find("missing.xml"), npos) << m;
}

// Only a regular file is read as a scene: a folder fails by its type, and
// a FIFO is refused before it is opened (opening it would block).
TEST(Case, AFolderOrAFifoIsNotAScene) {
  const std::string dir = ::testing::TempDir() + "vmh_case_not_a_scene";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::string m = refusal(dir, {});
  EXPECT_NE(m.find(dir + ": not a scene file (a folder)"), std::string::npos) << m;
  const std::string fifo = dir + "/scene.xml";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  m = refusal(fifo, {});
  EXPECT_NE(m.find(fifo + ": not a scene file (a FIFO)"), std::string::npos) << m;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace vmh::sim
