// sim/case_config: a case's parameters from the scene's <custom> fields,
// defaults where the scene is silent, `--set name=value` on top, and
// setup-time errors that name the file and the field.
//
// The scenes are tiny MJCF files written for each test (no bodies, only a
// <custom> block) and loaded by path with sim::load_model, as the simulator
// loads a case. Expected values are the documented ones (docs/cli.md, "Case
// parameters"; docs/testbed.md), written out here, not read from the field
// table the loader uses.
#include "sim/case_config.h"

#include <gtest/gtest.h>

#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "controller/controller.h"
#include "sim/mujoco_util.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/temp_mjcf.h"

namespace vmh::sim {
namespace {

using testing::numeric_field;
using testing::text_field;

constexpr double kPi = 3.14159265358979323846;

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

// ---- defaults, scene values, overrides --------------------------------

// A scene that gives only the required vm_kind gets every documented
// default, each marked as such.
TEST_F(CaseConfigTest, DefaultsFillEveryFieldTheSceneLeavesOut) {
  const CaseConfig c = load(kCircle);
  EXPECT_EQ(c.text("vm_kind"), "circle");
  EXPECT_EQ(c.source_of("vm_kind"), ValueSource::kScene);

  // scalars: name, documented default (docs/cli.md, "Case parameters")
  const std::vector<std::pair<const char*, double>> scalars = {
      {"thesis_case", 0.0},
      {"vm_length_mm", 50.0},
      {"k_pos_N_per_mm", 0.5},
      {"k_ornt_multiple", 0.0},
      {"k_vel_Ns_per_mm", 0.0},
      {"length_unit_mm", 1.0},
      {"servo_period_s", 0.001},
      {"physics_step_s", 0.0},
      {"delay_ticks", 0.0},
      {"quantize", 1.0},
      {"force_limit_N", 3.3},
      {"duration_s", 20.0},
      {"script_off_mm", 60.0},
      {"script_misalign_rad", 0.5},
      {"script_sweep_mm", 40.0},
      {"script_sweep_rad", 0.5},
      {"hand_mass_kg", 0.554},
      {"hand_k_pos_N_per_m", 135.0},
      {"hand_b_pos_Ns_per_m", 6.45},
      {"hand_k_rot_Nm_per_rad", 0.5},
      {"hand_b_rot_Nms_per_rad", 0.02},
  };
  for (const auto& [name, value] : scalars) {
    EXPECT_EQ(c.number(name), value) << name;
    EXPECT_EQ(c.numbers(name).size(), 1u) << name;
    EXPECT_EQ(c.source_of(name), ValueSource::kDefault) << name;
  }
  EXPECT_EQ(c.numbers("vm_pivot_mm"), (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(c.numbers("placement_weights"),
            (std::vector<double>{1, 1, 1, 0, 0, 0}));
  EXPECT_EQ(c.numbers("projection_weights"),
            (std::vector<double>{1, 1, 1, 1, 1, 1}));
  EXPECT_EQ(c.numbers("script_dir"), (std::vector<double>{-0.35, 0.65, 0.65}));
  EXPECT_EQ(c.numbers("hand_inertia_kgm2"),
            (std::vector<double>{2e-4, 2e-4, 2e-4}));
  for (const char* name : {"vm_pivot_mm", "placement_weights", "script_dir"}) {
    EXPECT_EQ(c.source_of(name), ValueSource::kDefault) << name;
  }
  EXPECT_EQ(c.text("error"), "thesis");
  EXPECT_EQ(c.text("placement"), "gauss-newton");
  EXPECT_EQ(c.text("integrator"), "scene");
  EXPECT_EQ(c.text("script"), "thesis");
  EXPECT_EQ(c.source_of("script"), ValueSource::kDefault);
  EXPECT_EQ(c.scene_path(), path());
}

TEST_F(CaseConfigTest, SceneValuesReplaceTheDefaults) {
  const CaseConfig c = load(
      text_field("vm_kind", "sphere") + numeric_field("vm_length_mm", "42.5") +
      numeric_field("vm_pivot_mm", "1.5 -2 3") +
      numeric_field("placement_weights", "1 1 1 0.25 0.25 0.25") +
      text_field("error", "geometric") + numeric_field("delay_ticks", "3"));
  EXPECT_EQ(c.text("vm_kind"), "sphere");
  EXPECT_EQ(c.number("vm_length_mm"), 42.5);
  EXPECT_EQ(c.vec3("vm_pivot_mm"), Vec3(1.5, -2.0, 3.0));
  EXPECT_EQ(c.numbers("placement_weights"),
            (std::vector<double>{1, 1, 1, 0.25, 0.25, 0.25}));
  EXPECT_EQ(c.text("error"), "geometric");
  EXPECT_EQ(c.number("delay_ticks"), 3.0);
  for (const char* name : {"vm_kind", "vm_length_mm", "vm_pivot_mm",
                           "placement_weights", "error", "delay_ticks"}) {
    EXPECT_EQ(c.source_of(name), ValueSource::kScene) << name;
  }
  // the rest keep their defaults
  EXPECT_EQ(c.number("k_pos_N_per_mm"), 0.5);
  EXPECT_EQ(c.source_of("k_pos_N_per_mm"), ValueSource::kDefault);
}

// A scene value that is not exactly representable in a short decimal still
// comes through bit for bit.
TEST_F(CaseConfigTest, SceneNumbersKeepFullPrecision) {
  const CaseConfig c =
      load(kCircle + numeric_field("k_pos_N_per_mm", "0.1234567890123456789"));
  EXPECT_EQ(c.number("k_pos_N_per_mm"), 0.1234567890123456789);
}

TEST_F(CaseConfigTest, SetOverridesScalarsVectorsAndTexts) {
  const CaseConfig c = load(kCircle + numeric_field("k_pos_N_per_mm", "0.6"),
                            {"k_pos_N_per_mm=0.75", "vm_pivot_mm=1,-2.5,3e1",
                             "script_dir=0 1 0", "vm_kind=sphere"});
  EXPECT_EQ(c.number("k_pos_N_per_mm"), 0.75);  // over the scene's 0.6
  EXPECT_EQ(c.vec3("vm_pivot_mm"), Vec3(1.0, -2.5, 30.0));
  EXPECT_EQ(c.vec3("script_dir"), Vec3(0.0, 1.0, 0.0));
  EXPECT_EQ(c.text("vm_kind"), "sphere");
  for (const char* name :
       {"k_pos_N_per_mm", "vm_pivot_mm", "script_dir", "vm_kind"}) {
    EXPECT_EQ(c.source_of(name), ValueSource::kOverride) << name;
  }
  EXPECT_EQ(c.source_of("vm_length_mm"), ValueSource::kDefault);
}

// The last --set of a name wins.
TEST_F(CaseConfigTest, LaterSetWins) {
  const CaseConfig c = load(kCircle, {"duration_s=5", "duration_s=7.5"});
  EXPECT_EQ(c.number("duration_s"), 7.5);
}

// --set can supply the one required field the scene lacks
TEST_F(CaseConfigTest, SetCanSupplyTheRequiredField) {
  const CaseConfig c =
      load(numeric_field("vm_length_mm", "40"), {"vm_kind=circle"});
  EXPECT_EQ(c.text("vm_kind"), "circle");
  EXPECT_EQ(c.source_of("vm_kind"), ValueSource::kOverride);
}

TEST(ValueSourceName, NamesEachSource) {
  EXPECT_STREQ(value_source_name(ValueSource::kDefault), "default");
  EXPECT_STREQ(value_source_name(ValueSource::kScene), "scene");
  EXPECT_STREQ(value_source_name(ValueSource::kOverride), "set");
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
        num("thesis_case", "7"),
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
        txt("integrator", "implicitfast")));

// The edges of the ranges are accepted.
TEST_F(CaseConfigTest, RangeEdgesAreAccepted) {
  for (const std::string& customs :
       {numeric_field("delay_ticks", "0"), numeric_field("delay_ticks", "64"),
        numeric_field("quantize", "0"), numeric_field("thesis_case", "6"),
        numeric_field("k_pos_N_per_mm", "0"),
        numeric_field("placement_weights", "0 0 0 0 0 0")}) {
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

}  // namespace
}  // namespace vmh::sim
