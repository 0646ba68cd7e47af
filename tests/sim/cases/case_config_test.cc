// sim/cases/case_config: a case's parameters from the scene's <custom> fields,
// defaults where the scene is silent, `--set name=value` on top, and
// setup-time errors that name the file and the field.
//
// The scenes are tiny MJCF files written for each test (no bodies, only a
// <custom> block) and loaded by path with sim::load_model, as the simulator
// loads a case. Expected values are the documented ones (docs/cli.md, "Case
// parameters"; docs/testbed.md), written out here, not read from the field
// table the loader uses.
#include "sim/cases/case_config.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "controller/controller.h"
#include "sim/mujoco_util.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/temp_mjcf.h"
#include "tests/support/constants.h"
#include "tests/support/read_file.h"

namespace vmh::sim {
namespace {

using testing::numeric_field;
using testing::text_field;

using vmh::testing::kPi;

class CaseConfigTest : public ::testing::Test {
 protected:
  // Writes a scene with these <custom> entries and reads its configuration.
  CaseConfig load(const std::string& customs,
                  const std::vector<std::string>& overrides = {}) {
    path_ = dir_.write("scene" + std::to_string(count_++) + ".xml",
                       testing::custom_only_scene(customs));
    ModelPtr m = load_model(path_);
    return CaseConfig::from_model(m.get(), path_, overrides);
  }

  // The SimError message of load(); a test failure (and "") if it loads.
  std::string load_error(const std::string& customs,
                         const std::vector<std::string>& overrides = {}) {
    try {
      load(customs, overrides);
    } catch (const SimError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no SimError for customs [" << customs << "]";
    return "";
  }

  const std::string& path() const { return path_; }

  testing::MujocoGuard guard_;
  testing::TempMjcfDir dir_;
  std::string path_;
  int count_ = 0;
};

const std::string kCircle = text_field("vm_kind", "circle");

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

// where a parameter's value came from (the record summary.json reports)
ValueSource source_of(const CaseParams& c, const char* name) {
  const ParamSpec* f = find_param(name);
  EXPECT_NE(f, nullptr) << name;
  return f == nullptr ? ValueSource::kDefault : c.value(*f).source;
}

Vec6 vec6(double a, double b, double c, double d, double e, double f) {
  Vec6 v;
  v << a, b, c, d, e, f;
  return v;
}

// ---- defaults, scene values, overrides --------------------------------

// A scene that gives only the required vm_kind gets every documented
// default, each marked as such.
TEST_F(CaseConfigTest, DefaultsFillEveryFieldTheSceneLeavesOut) {
  const CaseConfig c = load(kCircle);
  EXPECT_EQ(c.controller.vm_kind, VmKind::kCircle);
  EXPECT_EQ(source_of(c, "vm_kind"), ValueSource::kScene);

  // documented defaults (docs/parameters.md), as typed members
  EXPECT_EQ(c.thesis_case, 0);
  const ControllerSettings& k = c.controller;
  EXPECT_EQ(k.vm_pivot_mm, Vec3::Zero());
  EXPECT_EQ(k.vm_length_mm, 50.0);
  EXPECT_EQ(k.friction_mu, 0.0);
  EXPECT_FALSE(k.unilateral);
  EXPECT_EQ(k.k_pos_N_per_mm, 0.5);
  EXPECT_EQ(k.k_ornt_multiple, 0.0);
  EXPECT_EQ(k.k_vel_Ns_per_mm, 0.0);
  EXPECT_EQ(k.k_vel_ornt_Nmms_per_rad, 0.0);
  EXPECT_EQ(k.placement_weights, vec6(1, 1, 1, 0, 0, 0));
  EXPECT_EQ(k.projection_weights, Vec6::Ones());
  EXPECT_EQ(k.length_unit_mm, 1.0);
  EXPECT_EQ(k.error, ErrorFormulation::kThesis);
  EXPECT_EQ(k.placement, PlacementMethod::kGaussNewton);
  EXPECT_EQ(k.servo_period_s, 0.001);
  EXPECT_EQ(k.force_limit_N, 3.3);
  const SimSettings& sim = c.sim;
  EXPECT_EQ(sim.physics_step_s, 0.0);
  EXPECT_EQ(sim.integrator, IntegratorSetting::kScene);
  EXPECT_EQ(sim.delay_ticks, 0);
  EXPECT_TRUE(sim.quantize);
  EXPECT_EQ(sim.jitter_min_s, 0.0);
  EXPECT_EQ(sim.jitter_max_s, 0.0);
  EXPECT_EQ(sim.jitter_seed, 1u);
  EXPECT_EQ(sim.fault, SensorFaultKind::kNone);
  EXPECT_EQ(sim.fault_joint, 1);
  EXPECT_EQ(sim.fault_at_s, 1.0);
  EXPECT_TRUE(sim.sensor_guard);
  EXPECT_EQ(sim.guard_max_speed_rad_s, 50.0);
  EXPECT_TRUE(sim.gimbal_limits);
  EXPECT_EQ(sim.duration_s, 20.0);
  EXPECT_EQ(c.script.kind, ScriptKind::kThesis);
  EXPECT_EQ(c.script.name, "thesis");
  EXPECT_EQ(c.script.dir, Vec3(-0.35, 0.65, 0.65));
  EXPECT_EQ(c.script.axis, Vec3::Zero());
  EXPECT_EQ(c.script.off_mm, 60.0);
  EXPECT_EQ(c.script.misalign_rad, 0.5);
  EXPECT_EQ(c.script.sweep_mm, 40.0);
  EXPECT_EQ(c.script.sweep_rad, 0.5);
  EXPECT_EQ(c.hand.mass_kg, 0.554);
  EXPECT_EQ(c.hand.inertia_kgm2, Vec3(2e-4, 2e-4, 2e-4));
  EXPECT_EQ(c.hand.k_pos_N_per_m, 135.0);
  EXPECT_EQ(c.hand.b_pos_Ns_per_m, 6.45);
  EXPECT_EQ(c.hand.k_rot_Nm_per_rad, 0.5);
  EXPECT_EQ(c.hand.b_rot_Nms_per_rad, 0.02);

  // every other parameter is marked as a default, with its value as given
  for (const ParamSpec& f : case_fields()) {
    if (std::string(f.name) == "vm_kind") continue;
    EXPECT_EQ(c.value(f).source, ValueSource::kDefault) << f.name;
    if (!f.is_text) {
      EXPECT_EQ(static_cast<int>(c.value(f).numbers.size()), f.size) << f.name;
    }
  }
  EXPECT_EQ(c.value(*find_param("placement_weights")).numbers,
            (std::vector<double>{1, 1, 1, 0, 0, 0}));
  EXPECT_EQ(c.value(*find_param("error")).text, "thesis");
  EXPECT_EQ(c.scene_path(), path());
}

// The surface is placed by its orientation rows too: its placement weights
// default to all ones (the circle and the sphere keep W_p), in scenes as in
// ctl; a scene's own weights still win.
TEST_F(CaseConfigTest, SurfacePlacementWeightsDefaultToOnes) {
  const CaseConfig s = load(text_field("vm_kind", "surface"));
  EXPECT_EQ(s.controller.placement_weights, Vec6::Ones());
  EXPECT_EQ(source_of(s, "placement_weights"), ValueSource::kDefault);
  const CaseConfig sphere = load(text_field("vm_kind", "sphere"));
  EXPECT_EQ(sphere.controller.placement_weights, vec6(1, 1, 1, 0, 0, 0));
  const CaseConfig given =
      load(text_field("vm_kind", "surface") +
           numeric_field("placement_weights", "1 1 1 0 0 0"));
  EXPECT_EQ(given.controller.placement_weights, vec6(1, 1, 1, 0, 0, 0));
  // --set vm_kind=surface over a circle scene gets the surface's default
  const CaseConfig set = load(kCircle, {"vm_kind=surface"});
  EXPECT_EQ(set.controller.placement_weights, Vec6::Ones());
}

TEST_F(CaseConfigTest, SceneValuesReplaceTheDefaults) {
  const CaseConfig c = load(
      text_field("vm_kind", "sphere") + numeric_field("vm_length_mm", "42.5") +
      numeric_field("vm_pivot_mm", "1.5 -2 3") +
      numeric_field("placement_weights", "1 1 1 0.5 0.5 0.5") +
      text_field("error", "geometric") + numeric_field("delay_ticks", "3"));
  EXPECT_EQ(c.controller.vm_kind, VmKind::kSphere);
  EXPECT_EQ(c.controller.vm_length_mm, 42.5);
  EXPECT_EQ(c.controller.vm_pivot_mm, Vec3(1.5, -2.0, 3.0));
  EXPECT_EQ(c.controller.placement_weights, vec6(1, 1, 1, 0.5, 0.5, 0.5));
  EXPECT_EQ(c.controller.error, ErrorFormulation::kGeometric);
  EXPECT_EQ(c.sim.delay_ticks, 3);
  for (const char* name : {"vm_kind", "vm_length_mm", "vm_pivot_mm",
                           "placement_weights", "error", "delay_ticks"}) {
    EXPECT_EQ(source_of(c, name), ValueSource::kScene) << name;
  }
  // what the scene leaves out keeps its default
  EXPECT_EQ(c.controller.k_pos_N_per_mm, 0.5);
  EXPECT_EQ(source_of(c, "k_pos_N_per_mm"), ValueSource::kDefault);
}

// A scene's numbers pass through text to the loader; no digit is lost.
TEST_F(CaseConfigTest, SceneNumbersKeepFullPrecision) {
  const CaseConfig c =
      load(kCircle + numeric_field("k_pos_N_per_mm", "0.1234567890123456789"));
  EXPECT_EQ(c.controller.k_pos_N_per_mm, 0.1234567890123456789);
}

TEST_F(CaseConfigTest, SetOverridesScalarsVectorsAndTexts) {
  const CaseConfig c = load(kCircle + numeric_field("k_pos_N_per_mm", "0.6"),
                            {"k_pos_N_per_mm=0.75", "vm_pivot_mm=1,-2.5,30",
                             "script_dir=0 1 0", "vm_kind=sphere"});
  EXPECT_EQ(c.controller.k_pos_N_per_mm, 0.75);  // over the scene's 0.6
  EXPECT_EQ(c.controller.vm_pivot_mm, Vec3(1.0, -2.5, 30.0));
  EXPECT_EQ(c.script.dir, Vec3(0.0, 1.0, 0.0));
  EXPECT_EQ(c.controller.vm_kind, VmKind::kSphere);
  for (const char* name :
       {"k_pos_N_per_mm", "vm_pivot_mm", "script_dir", "vm_kind"}) {
    EXPECT_EQ(source_of(c, name), ValueSource::kOverride) << name;
  }
  EXPECT_EQ(source_of(c, "vm_length_mm"), ValueSource::kDefault);
}

// Of two --set of the same name the later wins.
TEST_F(CaseConfigTest, LaterSetWins) {
  const CaseConfig c = load(kCircle, {"duration_s=5", "duration_s=7.5"});
  EXPECT_EQ(c.sim.duration_s, 7.5);
}

// The required vm_kind may come from --set instead of the scene.
TEST_F(CaseConfigTest, SetCanSupplyTheRequiredField) {
  const CaseConfig c =
      load(numeric_field("vm_length_mm", "50"), {"vm_kind=circle"});
  EXPECT_EQ(c.controller.vm_kind, VmKind::kCircle);
  EXPECT_EQ(source_of(c, "vm_kind"), ValueSource::kOverride);
}

TEST(ValueSourceName, NamesEachSource) {
  EXPECT_STREQ(value_source_name(ValueSource::kDefault), "default");
  EXPECT_STREQ(value_source_name(ValueSource::kScene), "scene");
  EXPECT_STREQ(value_source_name(ValueSource::kOverride), "set");
}

// The settings only ctl had before the one table: a scene now sets the
// surface's friction and unilateral contact and the orientation rows'
// damping, and they reach the controller.
TEST_F(CaseConfigTest, SceneSetsFrictionUnilateralAndOrientationDamping) {
  const CaseConfig c =
      load(text_field("vm_kind", "surface") +
           numeric_field("friction_mu", "0.3") +
           numeric_field("unilateral", "1") +
           numeric_field("k_vel_Ns_per_mm", "0.002") +
           numeric_field("k_vel_ornt_Nmms_per_rad", "2.5"));
  const ControllerParams p = controller_params(c);
  EXPECT_EQ(p.vm.friction_mu, 0.3);
  EXPECT_TRUE(p.vm.unilateral);
  EXPECT_EQ(p.gains.k_vel_Ns_per_mm, 0.002);
  // K_v of the orientation rows is its own parameter, not derived from the
  // position rows'
  EXPECT_EQ(p.gains.k_vel_ornt_Nmms_per_rad, 2.5);
  for (const char* name : {"friction_mu", "unilateral", "k_vel_ornt_Nmms_per_rad"}) {
    EXPECT_EQ(source_of(c, name), ValueSource::kScene) << name;
  }
  // and by --set; mu = inf (never slides) is the one non-finite value
  const CaseConfig s = load(text_field("vm_kind", "surface"),
                            {"friction_mu=inf", "unilateral=1"});
  EXPECT_TRUE(std::isinf(controller_params(s).vm.friction_mu));
  EXPECT_TRUE(controller_params(s).vm.unilateral);
  EXPECT_NO_THROW(Controller{controller_params(s)});
  // the position rows' K_v alone leaves the orientation rows undamped, in a
  // scene as in ctl
  const CaseConfig kv = load(kCircle, {"k_vel_Ns_per_mm=0.002"});
  EXPECT_EQ(controller_params(kv).gains.k_vel_ornt_Nmms_per_rad, 0.0);
}

// the device's rated peak caps the force limit (1e6 was accepted and the
// commanded force reached 3.55 N, bounded by the motors' clamps alone)
TEST_F(CaseConfigTest, ForceLimitIsCappedAtTheRatedPeak) {
  EXPECT_NO_THROW(load(kCircle, {"force_limit_N=3.3"}));
  for (const char* bad : {"force_limit_N=1e6", "force_limit_N=3.31"}) {
    const std::string msg = load_error(kCircle, {bad});
    EXPECT_TRUE(contains(msg, "'force_limit_N'")) << bad << ": " << msg;
    EXPECT_TRUE(contains(msg, "3.3")) << bad << ": " << msg;
  }
}

TEST_F(CaseConfigTest, OnlyFrictionMayBeInfinite) {
  EXPECT_NO_THROW(load(kCircle, {"friction_mu=inf"}));
  for (const char* bad : {"friction_mu=-inf", "friction_mu=nan",
                          "k_vel_ornt_Nmms_per_rad=inf", "force_limit_N=inf"}) {
    const std::string msg = load_error(kCircle, {bad});
    const std::string name =
        std::string(bad).substr(0, std::string(bad).find('='));
    EXPECT_TRUE(contains(msg, "'" + name + "'")) << bad << ": " << msg;
    EXPECT_TRUE(contains(msg, "finite")) << bad << ": " << msg;
  }
}

// ---- errors that name the file and the field --------------------------

TEST_F(CaseConfigTest, UnknownSceneFieldNamesFileAndField) {
  const std::string msg =
      load_error(kCircle + numeric_field("k_pos_N_per_m", "0.5"));
  EXPECT_TRUE(contains(msg, path())) << msg;
  EXPECT_TRUE(contains(msg, "'k_pos_N_per_m'")) << msg;
  EXPECT_TRUE(contains(msg, "unknown")) << msg;
}

TEST_F(CaseConfigTest, UnknownSceneTextFieldIsAnErrorToo) {
  const std::string msg = load_error(kCircle + text_field("colour", "red"));
  EXPECT_TRUE(contains(msg, path())) << msg;
  EXPECT_TRUE(contains(msg, "'colour'")) << msg;
}

// A known field under the other kind's tag is an error, not a silent
// default: a number written as <text>, and a word written as <numeric>.
TEST_F(CaseConfigTest, NumberFieldWrittenAsTextIsAnError) {
  const std::string msg =
      load_error(kCircle + text_field("k_pos_N_per_mm", "0.6"));
  EXPECT_TRUE(contains(msg, path())) << msg;
  EXPECT_TRUE(contains(msg, "'k_pos_N_per_mm'")) << msg;
  EXPECT_TRUE(contains(msg, "<numeric>")) << msg;
}

TEST_F(CaseConfigTest, TextFieldWrittenAsNumericIsAnError) {
  const std::string msg = load_error(numeric_field("vm_kind", "1"));
  EXPECT_TRUE(contains(msg, path())) << msg;
  EXPECT_TRUE(contains(msg, "'vm_kind'")) << msg;
  EXPECT_TRUE(contains(msg, "<text>")) << msg;
  EXPECT_FALSE(contains(msg, "missing")) << msg;
}

TEST_F(CaseConfigTest, UnknownSetNameIsNamed) {
  const std::string msg = load_error(kCircle, {"k_pos=1"});
  EXPECT_TRUE(contains(msg, "--set")) << msg;
  EXPECT_TRUE(contains(msg, "'k_pos'")) << msg;
}

TEST_F(CaseConfigTest, SetWithoutAnEqualsSignIsAnError) {
  for (const char* bad : {"k_pos_N_per_mm", "=0.5"}) {
    const std::string msg = load_error(kCircle, {bad});
    EXPECT_TRUE(contains(msg, "--set")) << msg;
    EXPECT_TRUE(contains(msg, "name=value")) << msg;
  }
}

TEST_F(CaseConfigTest, WrongVectorSizeInTheSceneNamesFileAndField) {
  std::string msg = load_error(kCircle + numeric_field("vm_pivot_mm", "1 2"));
  EXPECT_TRUE(contains(msg, path())) << msg;
  EXPECT_TRUE(contains(msg, "'vm_pivot_mm'")) << msg;
  EXPECT_TRUE(contains(msg, "expects 3")) << msg;

  msg = load_error(kCircle + numeric_field("vm_length_mm", "50 60"));
  EXPECT_TRUE(contains(msg, path())) << msg;
  EXPECT_TRUE(contains(msg, "'vm_length_mm'")) << msg;
  EXPECT_TRUE(contains(msg, "expects 1")) << msg;
}

TEST_F(CaseConfigTest, WrongVectorSizeInSetIsNamed) {
  for (const char* bad : {"vm_pivot_mm=1,2", "vm_pivot_mm=1,2,3,4",
                          "vm_pivot_mm=", "placement_weights=1,1,1"}) {
    const std::string msg = load_error(kCircle, {bad});
    const std::string name =
        std::string(bad).substr(0, std::string(bad).find('='));
    EXPECT_TRUE(contains(msg, "--set")) << bad << ": " << msg;
    EXPECT_TRUE(contains(msg, "'" + name + "'")) << bad << ": " << msg;
    EXPECT_TRUE(contains(msg, "value(s)")) << bad << ": " << msg;
  }
}

TEST_F(CaseConfigTest, NonNumbersAreRejected) {
  for (const char* bad : {"k_pos_N_per_mm=abc", "k_pos_N_per_mm=0.5N",
                          "vm_pivot_mm=1,x,3", "delay_ticks=two"}) {
    const std::string msg = load_error(kCircle, {bad});
    const std::string name =
        std::string(bad).substr(0, std::string(bad).find('='));
    EXPECT_TRUE(contains(msg, "'" + name + "'")) << bad << ": " << msg;
    EXPECT_TRUE(contains(msg, "expects numbers")) << bad << ": " << msg;
  }
}

TEST_F(CaseConfigTest, NonFiniteNumbersAreRejected) {
  for (const char* bad :
       {"k_pos_N_per_mm=nan", "vm_length_mm=inf", "vm_pivot_mm=0,-inf,0"}) {
    const std::string msg = load_error(kCircle, {bad});
    const std::string name =
        std::string(bad).substr(0, std::string(bad).find('='));
    EXPECT_TRUE(contains(msg, "'" + name + "'")) << bad << ": " << msg;
    EXPECT_TRUE(contains(msg, "finite")) << bad << ": " << msg;
  }
}

TEST_F(CaseConfigTest, MissingVmKindNamesFileAndField) {
  const std::string msg = load_error(numeric_field("vm_length_mm", "50"));
  EXPECT_TRUE(contains(msg, path())) << msg;
  EXPECT_TRUE(contains(msg, "missing")) << msg;
  EXPECT_TRUE(contains(msg, "'vm_kind'")) << msg;
}

// One validation rule per row: the scene's <custom> entry that breaks it
// and the field the message must name.
struct BadValue {
  std::string custom;
  std::string field;
};

class CaseConfigRuleTest : public CaseConfigTest,
                           public ::testing::WithParamInterface<BadValue> {};

TEST_P(CaseConfigRuleTest, SceneValueBreakingARuleNamesFileAndField) {
  const BadValue& b = GetParam();
  // vm_kind comes first unless the row replaces it
  const std::string customs =
      b.field == "vm_kind" ? b.custom : kCircle + b.custom;
  const std::string msg = load_error(customs);
  EXPECT_TRUE(contains(msg, path())) << msg;
  EXPECT_TRUE(contains(msg, "'" + b.field + "'")) << msg;
}

void PrintTo(const BadValue& b, std::ostream* os) { *os << b.custom; }

BadValue num(const char* field, const char* data) {
  return {numeric_field(field, data), field};
}
BadValue txt(const char* field, const char* data) {
  return {text_field(field, data), field};
}

INSTANTIATE_TEST_SUITE_P(
    Rules, CaseConfigRuleTest,
    ::testing::Values(
        // gains and hand impedances must not be negative
        num("k_pos_N_per_mm", "-0.5"), num("k_ornt_multiple", "-1"),
        num("k_vel_Ns_per_mm", "-0.001"), num("hand_k_pos_N_per_m", "-135"),
        num("hand_b_pos_Ns_per_m", "-1"), num("hand_k_rot_Nm_per_rad", "-0.5"),
        num("hand_b_rot_Nms_per_rad", "-0.02"),
        // lengths, periods and masses must be positive
        num("vm_length_mm", "0"), num("servo_period_s", "0"),
        num("force_limit_N", "-3.3"), num("length_unit_mm", "0"),
        num("duration_s", "0"), num("hand_mass_kg", "0"),
        num("physics_step_s", "-0.0002"), num("script_off_mm", "-60"),
        num("script_sweep_mm", "-1"),
        // whole numbers within a range
        num("delay_ticks", "-1"), num("delay_ticks", "65"),
        num("delay_ticks", "1.5"), num("quantize", "2"), num("quantize", "0.5"),
        num("thesis_case", "8"),
        // weights and inertias
        num("placement_weights", "1 1 1 -1 0 0"),
        num("projection_weights", "1 1 1 1 1 -0.1"),
        num("hand_inertia_kgm2", "2e-4 0 2e-4"),
        // a zero script direction
        num("script_dir", "0 0 0"),
        // enumerations
        txt("vm_kind", "circel"), txt("vm_kind", "Circle"),
        txt("error", "geometrical"), txt("placement", "newton"),
        txt("script", "sweep"), txt("integrator", "RK4"),
        txt("integrator", "implicitfast"),
        // the controller settings scenes could not set before
        num("friction_mu", "-0.1"), num("unilateral", "2"),
        num("unilateral", "0.5"), num("k_vel_ornt_Nmms_per_rad", "-1"),
        num("projection_weights", "1 1 1 1 1 0"),
        // rules between parameters
        BadValue{text_field("fault", "jump") + numeric_field("fault_joint", "4"),
                 "fault_joint"},
        num("fault_joint", "7"), num("servo_jitter_s", "0.002 0.001"),
        num("servo_jitter_s", "0 0.001"), txt("fault", "drift"),
        // the bounds that keep a run's counts in range (issue 17)
        num("servo_period_s", "3e6"), num("servo_period_s", "1e-6"),
        num("duration_s", "1e308"), num("duration_s", "3601"),
        num("physics_step_s", "1.5"), num("servo_jitter_s", "0.0004 1e12"),
        num("servo_jitter_s", "-0.001 0.001")));

// The edges of the ranges are accepted.
TEST_F(CaseConfigTest, RangeEdgesAreAccepted) {
  for (const std::string& customs :
       {numeric_field("delay_ticks", "0"), numeric_field("delay_ticks", "64"),
        numeric_field("quantize", "0"), numeric_field("thesis_case", "6"),
        numeric_field("k_pos_N_per_mm", "0"),
        numeric_field("placement_weights", "0 0 0 0 0 0"),
        numeric_field("servo_period_s", "1e-5"),
        numeric_field("servo_period_s", "1"),
        numeric_field("duration_s", "3600"),
        numeric_field("physics_step_s", "1"),
        numeric_field("servo_jitter_s", "1 1")}) {
    EXPECT_NO_THROW(load(kCircle + customs)) << customs;
  }
  for (const char* kind : {"circle", "sphere", "surface"}) {
    EXPECT_NO_THROW(load(text_field("vm_kind", kind))) << kind;
  }
  for (const char* integrator : {"scene", "euler", "implicit", "rk4"}) {
    EXPECT_NO_THROW(load(kCircle + text_field("integrator", integrator)))
        << integrator;
  }
  for (const char* v : {"error=geometric", "placement=closed", "script=hold"}) {
    EXPECT_NO_THROW(load(kCircle, {v})) << v;
  }
}

// A rule broken by --set names --set and the field, not the scene.
TEST_F(CaseConfigTest, SetValueBreakingARuleNamesSetAndField) {
  const std::string msg = load_error(kCircle, {"delay_ticks=100"});
  EXPECT_TRUE(contains(msg, "--set")) << msg;
  EXPECT_TRUE(contains(msg, "'delay_ticks'")) << msg;
  EXPECT_FALSE(contains(msg, path())) << msg;
}

// ---- the controller's parameters ----------------------------------------

TEST_F(CaseConfigTest, ControllerParamsMapEveryField) {
  const CaseConfig c = load(
      text_field("vm_kind", "sphere") + numeric_field("vm_pivot_mm", "1 -2 3") +
      numeric_field("vm_length_mm", "40") +
      numeric_field("k_pos_N_per_mm", "0.6") +
      numeric_field("k_ornt_multiple", "0.5") +
      numeric_field("k_vel_Ns_per_mm", "0.002") +
      numeric_field("k_vel_ornt_Nmms_per_rad", "7.5") +
      numeric_field("friction_mu", "0.25") + numeric_field("unilateral", "1") +
      numeric_field("placement_weights", "1 2 3 4 5 6") +
      numeric_field("projection_weights", "6 5 4 3 2 1") +
      numeric_field("length_unit_mm", "1000") +
      text_field("error", "geometric") + text_field("placement", "closed") +
      numeric_field("servo_period_s", "0.002") +
      numeric_field("force_limit_N", "2.5"));
  const ControllerParams p = controller_params(c);
  EXPECT_EQ(p.vm.kind, VmKind::kSphere);
  EXPECT_EQ(p.vm.pivot_mm, Vec3(1.0, -2.0, 3.0));
  EXPECT_EQ(p.vm.length_mm, 40.0);
  EXPECT_EQ(p.gains.k_pos_N_per_mm, 0.6);
  // eq. 3.28: 0.5 N/mm times the circumference 2 pi 40 mm = 80 pi mm,
  // so K_ornt = 40 pi N mm/rad = 125.66... N mm/rad
  EXPECT_NEAR(p.gains.k_ornt_Nmm_per_rad, 40.0 * kPi, 1e-12);
  EXPECT_NEAR(p.gains.k_ornt_Nmm_per_rad, 125.6637061435917, 1e-9);
  EXPECT_EQ(p.gains.k_vel_Ns_per_mm, 0.002);
  EXPECT_EQ(p.gains.k_vel_ornt_Nmms_per_rad, 7.5);
  EXPECT_EQ(p.vm.friction_mu, 0.25);
  EXPECT_TRUE(p.vm.unilateral);
  Vec6 w, wa;
  w << 1, 2, 3, 4, 5, 6;
  wa << 6, 5, 4, 3, 2, 1;
  EXPECT_EQ(p.placement_options.weights, w);
  EXPECT_EQ(p.projection_weights, wa);
  EXPECT_EQ(p.length_unit_mm, 1000.0);
  EXPECT_EQ(p.error, ErrorFormulation::kGeometric);
  EXPECT_EQ(p.placement, PlacementMethod::kClosedForm);
  EXPECT_EQ(p.servo_period_s, 0.002);
  EXPECT_EQ(p.force_limit_N, 2.5);
  // what the case does not set: the device and the pivot frame
  EXPECT_EQ(p.vm.R_pivot, Mat3::Identity());
  EXPECT_EQ(p.omni.l1_m, OmniParams().l1_m);
  EXPECT_NO_THROW(p.validate());
}

// The thesis's own numbers (docs/sources.md §2): L = 50 mm, multiple 1 gives
// 2 pi 50 = 314.159... N mm/rad; the defaults give case 1's parameters.
TEST_F(CaseConfigTest, ControllerParamsOfTheThesisDefaults) {
  ControllerParams p = controller_params(load(kCircle));
  EXPECT_EQ(p.vm.kind, VmKind::kCircle);
  EXPECT_EQ(p.vm.pivot_mm, Vec3::Zero());
  EXPECT_EQ(p.vm.length_mm, 50.0);
  EXPECT_EQ(p.gains.k_pos_N_per_mm, 0.5);
  EXPECT_EQ(p.gains.k_ornt_Nmm_per_rad, 0.0);
  EXPECT_EQ(p.error, ErrorFormulation::kThesis);
  EXPECT_EQ(p.placement, PlacementMethod::kGaussNewton);
  Vec6 w_p;
  w_p << 1, 1, 1, 0, 0, 0;
  EXPECT_EQ(p.placement_options.weights, w_p);
  EXPECT_EQ(p.projection_weights, Vec6::Ones());
  EXPECT_EQ(p.force_limit_N, 3.3);

  p = controller_params(load(kCircle, {"k_ornt_multiple=1"}));
  EXPECT_NEAR(p.gains.k_ornt_Nmm_per_rad, 314.1592653589793, 1e-9);
}

// ---- one route: scenes and ctl ------------------------------------------

// Every field of ControllerParams either route can reach, compared exactly.
void expect_same_params(const ControllerParams& a, const ControllerParams& b,
                        const std::string& what) {
  EXPECT_EQ(a.vm.kind, b.vm.kind) << what;
  EXPECT_EQ(a.vm.pivot_mm, b.vm.pivot_mm) << what;
  EXPECT_EQ(a.vm.R_pivot, b.vm.R_pivot) << what;
  EXPECT_EQ(a.vm.length_mm, b.vm.length_mm) << what;
  EXPECT_EQ(a.vm.friction_mu, b.vm.friction_mu) << what;
  EXPECT_EQ(a.vm.unilateral, b.vm.unilateral) << what;
  EXPECT_EQ(a.gains.k_pos_N_per_mm, b.gains.k_pos_N_per_mm) << what;
  EXPECT_EQ(a.gains.k_ornt_Nmm_per_rad, b.gains.k_ornt_Nmm_per_rad) << what;
  EXPECT_EQ(a.gains.k_vel_Ns_per_mm, b.gains.k_vel_Ns_per_mm) << what;
  EXPECT_EQ(a.gains.k_vel_ornt_Nmms_per_rad, b.gains.k_vel_ornt_Nmms_per_rad)
      << what;
  EXPECT_EQ(a.error, b.error) << what;
  EXPECT_EQ(a.placement, b.placement) << what;
  EXPECT_EQ(a.placement_options.weights, b.placement_options.weights) << what;
  EXPECT_EQ(a.placement_options.tolerance, b.placement_options.tolerance)
      << what;
  EXPECT_EQ(a.placement_options.max_iterations,
            b.placement_options.max_iterations)
      << what;
  EXPECT_EQ(a.projection_weights, b.projection_weights) << what;
  EXPECT_EQ(a.length_unit_mm, b.length_unit_mm) << what;
  EXPECT_EQ(a.servo_period_s, b.servo_period_s) << what;
  EXPECT_EQ(a.velocity_cutoff_Hz, b.velocity_cutoff_Hz) << what;
  EXPECT_EQ(a.singular_rcond, b.singular_rcond) << what;
  EXPECT_EQ(a.singular_damping, b.singular_damping) << what;
  EXPECT_EQ(a.force_limit_N, b.force_limit_N) << what;
  EXPECT_EQ(a.omni.joint_lower_rad, b.omni.joint_lower_rad) << what;
  EXPECT_EQ(a.omni.joint_upper_rad, b.omni.joint_upper_rad) << what;
}

// One setting: the ctl option, the scene field and the value in each
// spelling (ctl and --set take commas, a scene's <numeric> spaces).
struct Setting {
  const char* option;
  const char* field;
  const char* ctl_value;
  const char* scene_value;
  bool text;
};

// The same settings given to ctl (as its command line would) and written in
// a scene give the same ControllerParams, field by field, and so do the
// defaults of both.
TEST_F(CaseConfigTest, CtlAndSceneGiveTheSameControllerParams) {
  const std::vector<std::vector<Setting>> sets = {
      {},  // the defaults (ctl's vm circle, the scene's vm_kind circle)
      {{"--vm", "vm_kind", "sphere", "sphere", true},
       {"--pivot-mm", "vm_pivot_mm", "1,-2,3", "1 -2 3", false},
       {"--length-mm", "vm_length_mm", "40", "40", false},
       {"--kpos", "k_pos_N_per_mm", "0.6", "0.6", false},
       {"--kornt", "k_ornt_multiple", "0.5", "0.5", false},
       {"--kv", "k_vel_Ns_per_mm", "0.002", "0.002", false},
       {"--kv-ornt", "k_vel_ornt_Nmms_per_rad", "3.5", "3.5", false},
       {"--weights", "placement_weights", "1,2,3,4,5,6", "1 2 3 4 5 6", false},
       {"--projection-weights", "projection_weights", "6,5,4,3,2,1",
        "6 5 4 3 2 1", false},
       {"--length-unit-mm", "length_unit_mm", "1000", "1000", false},
       {"--error", "error", "geometric", "geometric", true},
       {"--placement", "placement", "closed", "closed", true},
       {"--servo-period-s", "servo_period_s", "0.002", "0.002", false},
       {"--force-limit-N", "force_limit_N", "2.5", "2.5", false}},
      // the surface: its own placement-weight default, mu and unilateral
      {{"--vm", "vm_kind", "surface", "surface", true},
       {"--mu", "friction_mu", "0.4", "0.4", false},
       {"--unilateral", "unilateral", "", "1", false}},
      // --kv alone damps the position rows only, in both
      {{"--kv", "k_vel_Ns_per_mm", "0.003", "0.003", false}},
  };
  for (std::size_t k = 0; k < sets.size(); ++k) {
    std::vector<std::pair<std::string, std::string>> given;
    std::string customs;
    bool has_kind = false;
    for (const Setting& s : sets[k]) {
      given.emplace_back(s.option, s.ctl_value);
      customs += s.text ? text_field(s.field, s.scene_value)
                        : numeric_field(s.field, s.scene_value);
      has_kind |= std::string(s.field) == "vm_kind";
    }
    if (!has_kind) customs = kCircle + customs;
    const ControllerParams from_ctl =
        controller_params(load_case_params("ctl", ctl_inputs(given)));
    const ControllerParams from_scene = controller_params(load(customs));
    expect_same_params(from_ctl, from_scene, "setting set " + std::to_string(k));
  }
}

// Every controller setting is a ctl option and every ctl option is a
// parameter of the table, once; the sim's, the hand's and the script's are
// not ctl's.
TEST(CaseParamTable, CtlOptionsAreTheControllerParameters) {
  std::vector<std::string> options;
  for (const ParamSpec& f : case_fields()) {
    const bool controller = std::string(f.group) == "controller";
    EXPECT_EQ(f.ctl_option != nullptr, controller) << f.name;
    if (f.ctl_option == nullptr) continue;
    EXPECT_EQ(std::string(f.ctl_option).rfind("--", 0), 0u) << f.name;
    EXPECT_EQ(std::count(options.begin(), options.end(), f.ctl_option), 0)
        << f.ctl_option;
    options.push_back(f.ctl_option);
    EXPECT_NE(f.bind, nullptr) << f.name;
  }
  // the option names ctl had before the table still exist
  for (const char* old : {"--vm", "--pivot-mm", "--length-mm", "--kpos",
                          "--kornt", "--kv", "--error", "--placement",
                          "--weights", "--length-unit-mm", "--mu",
                          "--unilateral"}) {
    EXPECT_EQ(std::count(options.begin(), options.end(), old), 1) << old;
  }
  EXPECT_THROW(ctl_inputs({{"--no-such", "1"}}), ParamError);
}

// Names are unique, every row binds a member, and the loader fills the
// record of every row.
TEST(CaseParamTable, RowsAreUniqueAndBound) {
  std::vector<std::string> names;
  for (const ParamSpec& f : case_fields()) {
    EXPECT_EQ(std::count(names.begin(), names.end(), f.name), 0) << f.name;
    names.push_back(f.name);
    EXPECT_NE(f.bind, nullptr) << f.name;
    EXPECT_GT(std::string(f.doc).size(), 0u) << f.name;
    EXPECT_EQ(find_param(f.name), &f) << f.name;
  }
  const CaseParams c = load_case_params(
      "t", {{"vm_kind", "circle", ValueSource::kOverride, "test"}});
  EXPECT_EQ(c.values.size(), case_fields().size());
}

// docs/parameters.md is the program's table, verbatim (regenerate it with
// `build/vmhaptics params > docs/parameters.md`).
TEST(CaseParamTable, DocsAreTheGeneratedTable) {
  const std::string doc = std::string(VMH_MODELS_DIR) + "/../docs/parameters.md";
  ASSERT_TRUE(std::filesystem::is_regular_file(doc)) << doc;
  const std::string text = vmh::testing::read_file(doc);
  EXPECT_EQ(text, parameters_markdown())
      << "docs/parameters.md is stale: run build/vmhaptics params > "
         "docs/parameters.md";
  // and it has a row for every parameter
  for (const ParamSpec& f : case_fields()) {
    EXPECT_NE(text.find(std::string("| `") + f.name + "` |"),
              std::string::npos)
        << f.name;
  }
}

// The bounds are the table's (so `vmhaptics params` shows them), and a
// refusal names where the value came from, the field, the range and the
// value as %g: 1e-7 is "1e-07", not std::to_string's "0.000000".
TEST(CaseParamTable, BoundsAreInTheTableAndItsMessages) {
  const ParamSpec& duration = *find_param("duration_s");
  EXPECT_EQ(duration.range_text(), "> 0 and <= 3600");
  EXPECT_EQ(find_param("servo_period_s")->range_text(), "in [1e-05, 1]");
  const std::string steps = std::to_string(kMaxSubstepsPerTick);
  EXPECT_EQ(find_param("physics_step_s")->range_text(),
            ">= 0 and <= 1; servo_period_s / h a whole number in [1, " +
                steps + "]");
  EXPECT_EQ(find_param("servo_jitter_s")->range_text(),
            "each >= 0 and <= 1; 0 0, or 0 < min <= max; max / the physics "
            "step <= " + steps);
  EXPECT_EQ(find_param("delay_ticks")->range_text(),
            "a whole number in [0, 64]");

  const auto message = [](const char* name, double x) {
    try {
      check_param_number(*find_param(name), x, "--where");
    } catch (const ParamError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message("duration_s", 1e308),
            "--where: field 'duration_s' must be > 0 and <= 3600, got 1e+308");
  EXPECT_EQ(message("duration_s", -1e-7),
            "--where: field 'duration_s' must be > 0 and <= 3600, got -1e-07");
  EXPECT_EQ(message("duration_s", std::nan("")),
            "--where: field 'duration_s' must be > 0 and <= 3600, got nan");
  EXPECT_EQ(message("servo_period_s", 3e6),
            "--where: field 'servo_period_s' must be in [1e-05, 1], got 3000000");
  EXPECT_EQ(message("duration_s", 1e-7), "");  // one tick: ClosedLoop's check
  EXPECT_EQ(message("vm_pivot_mm", -1e300), "");  // kAny
}

}  // namespace
}  // namespace vmh::sim
