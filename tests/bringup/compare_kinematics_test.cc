// bringup/compare_kinematics and compare_jacobian on synthetic
// recordings: the device's transform, velocity and Jacobian from MuJoCo's
// own wrist site (tests/bringup/synthetic_recording.h), the angles
// quantized as the sensors do, and each seeded fault named exactly.
#include "bringup/compare_kinematics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "sim/mujoco_util.h"
#include "sim/omni_model_edit.h"
#include "bringup/compare_jacobian.h"
#include "tests/bringup/synthetic_recording.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/openhaptics_reference.h"
#include "tests/support/read_file.h"

namespace vmh::bringup {
namespace {

using testing::SyntheticOptions;
using testing::synthetic_recording;
using testing::tour_motion;

constexpr double kNominalLinkMm = 133.35;

class CompareKinematics : public ::testing::Test {
 protected:
  // the tour: 8 s at 1 kHz, all six joints moving
  Recording record(const SyntheticOptions& o = {}, const sim::OmniModelEdit& edit = {},
                   double delay_s = 0.0) {
    sim::ModelPtr m = sim::load_model(std::string(VMH_MODELS_DIR) + "/omni/omni.xml");
    if (!edit.is_identity()) sim::apply_omni_edit(m.get(), edit);
    return synthetic_recording(m.get(), tour_motion(8.0, 1000.0, delay_s), o);
  }

  static std::set<std::string> fault_names(const CompareSection& s) {
    std::set<std::string> out;
    for (const SuspectedFault& f : s.faults) out.insert(f.name);
    return out;
  }
  static const CompareCheck& check(const CompareSection& s, const std::string& name) {
    for (const CompareCheck& c : s.checks) {
      if (c.name == name) return c;
    }
    throw std::runtime_error("no check " + name);
  }
  static bool all_pass(const CompareSection& s) {
    return !s.checks.empty() && std::all_of(s.checks.begin(), s.checks.end(),
                                            [](const CompareCheck& c) { return c.pass; });
  }
  static std::string describe(const CompareSection& s) {
    std::ostringstream o;
    for (const CompareCheck& c : s.checks) {
      o << c.name << " = " << c.value << " " << c.unit << (c.pass ? " pass" : " FAIL") << "\n";
    }
    for (const SuspectedFault& f : s.faults) o << "fault " << f.name << ": " << f.evidence << "\n";
    return o.str();
  }

  testing::MujocoGuard guard_;
};

// The helper's device transform is the published OpenHaptics position
// formula at the true angles: the recordings below stand on an independent
// route, not on controller/
TEST_F(CompareKinematics, SyntheticTransformIsThePublishedFormula) {
  SyntheticOptions o;
  o.quantize = false;
  const Recording r = record(o);
  ASSERT_GT(r.rows, 1000u);
  for (std::size_t row : {0ul, 1234ul, 5678ul}) {
    const Joints q = r.q_dh_rad(row);
    Joints t;
    t << -q[0], q[1], q[1] + q[2], -q[3], q[4], -q[5];
    EXPECT_LT((r.dev_p_mm(row) - testing::openhaptics_wrist_mm(t, kNominalLinkMm,
                                                                kNominalLinkMm)).norm(),
              1e-6);
    EXPECT_LT((r.dev_R(row) - testing::openhaptics_stylus_rotation(t)).norm(), 1e-6);
  }
}

TEST_F(CompareKinematics, CleanPassesWithMarginAndNamesNothing) {
  const Recording r = record();
  const CompareSection k = compare_kinematics(r, "");
  EXPECT_TRUE(all_pass(k)) << describe(k);
  EXPECT_EQ(k.checks.size(), 4u);
  EXPECT_TRUE(k.faults.empty()) << describe(k);
  // margin: quantization stays well under the thresholds
  EXPECT_LT(check(k, "kinematics.position_error_p95").value, 0.25 * kPositionErrorP95ThresholdMm);
  EXPECT_LT(check(k, "kinematics.stylus_axis_error_p95").value,
            0.25 * kStylusAxisErrorP95ThresholdDeg);
  EXPECT_EQ(k.detail["rotation_column"]["text"], "+column 3");
  EXPECT_EQ(k.detail["readings"]["map"], "identity");
  EXPECT_EQ(k.detail["worst_samples"].size(), 5u);
  std::printf("clean: %s", describe(k).c_str());

  const CompareSection j = compare_jacobian(r, ReadingMap{}, "");
  EXPECT_TRUE(all_pass(j)) << describe(j);
  EXPECT_EQ(j.checks.size(), 3u);
  EXPECT_EQ(j.detail["layout"], "as_stored_device_joints");
  EXPECT_FALSE(j.detail.contains("explained_by"));
  std::printf("clean jacobian: %s", describe(j).c_str());
}

// A device whose rotation has the stylus axis in its first column, negated
// (and the others moved round to keep it a rotation): found, and clean
TEST_F(CompareKinematics, TheDevicesRotationConventionIsFound) {
  SyntheticOptions o;
  o.rotation_convention << 0, -1, 0,
                           0, 0, 1,
                           -1, 0, 0;
  ASSERT_NEAR(o.rotation_convention.determinant(), 1.0, 1e-12);
  const CompareSection k = compare_kinematics(record(o), "");
  EXPECT_EQ(k.detail["rotation_column"]["text"], "-column 1");
  EXPECT_TRUE(all_pass(k)) << describe(k);
  EXPECT_TRUE(k.faults.empty()) << describe(k);
}

TEST_F(CompareKinematics, JointSignsAreNamed) {
  for (int n = 1; n <= 6; ++n) {
    SyntheticOptions o;
    o.map.sign[n - 1] = -1.0;
    const CompareSection k = compare_kinematics(record(o), "");
    EXPECT_EQ(fault_names(k), std::set<std::string>{"joint" + std::to_string(n) + "_sign"})
        << describe(k);
    EXPECT_FALSE(all_pass(k));
  }
}

TEST_F(CompareKinematics, EachGimbalSwapIsNamed) {
  for (auto [a, b] : {std::pair{3, 4}, std::pair{3, 5}, std::pair{4, 5}}) {
    SyntheticOptions o;
    std::swap(o.map.perm[a], o.map.perm[b]);
    const CompareSection k = compare_kinematics(record(o), "");
    EXPECT_EQ(fault_names(k), std::set<std::string>{"gimbal_swap"})
        << "t" << a + 1 << "-t" << b + 1 << "\n" << describe(k);
  }
}

TEST_F(CompareKinematics, LongerUpperArmIsNamedWithItsLength) {
  sim::OmniModelEdit edit;
  edit.link1_scale = 1.02;
  const CompareSection k = compare_kinematics(record({}, edit), "");
  EXPECT_FALSE(check(k, "kinematics.position_error_p95").pass);
  ASSERT_EQ(fault_names(k), std::set<std::string>{"link_length_2pct"}) << describe(k);
  EXPECT_NE(k.faults[0].evidence.find("l1"), std::string::npos) << k.faults[0].evidence;
  const auto& params = k.detail["geometry_fit"]["parameters"];
  EXPECT_EQ(params[0]["name"], "l1");
  const double l1 = params[0]["fitted"].get<double>();
  EXPECT_NEAR(l1, 1.02 * kNominalLinkMm, 0.002 * 1.02 * kNominalLinkMm);
  EXPECT_TRUE(k.detail["geometry_fit"]["explains"].get<bool>());
  std::printf("l1 +2 %%: %sfitted l1 %.3f mm\n", describe(k).c_str(), l1);
  const CompareSection j = compare_jacobian(record({}, edit), ReadingMap{}, "");
  std::printf("l1 +2 %% jacobian: %s", describe(j).c_str());
}

TEST_F(CompareKinematics, ShorterForearmIsNamedNegative) {
  sim::OmniModelEdit edit;
  edit.link2_scale = 0.97;
  const CompareSection k = compare_kinematics(record({}, edit), "");
  ASSERT_EQ(fault_names(k), std::set<std::string>{"link_length_-3pct"}) << describe(k);
  EXPECT_NE(k.faults[0].evidence.find("l2"), std::string::npos) << k.faults[0].evidence;
}

TEST_F(CompareKinematics, JointOffsetIsNamed) {
  SyntheticOptions o;
  o.reported_offset_device_rad[1] = 0.02;
  const CompareSection k = compare_kinematics(record(o), "");
  EXPECT_EQ(fault_names(k), std::set<std::string>{"joint2_offset"}) << describe(k);
  const double fitted = k.detail["geometry_fit"]["parameters"][kOffsetT1 + 1]["fitted"];
  EXPECT_NEAR(fitted, -0.02, 0.001) << "the fit takes the offset back out";
}

TEST_F(CompareKinematics, BaseOffsetIsNamed) {
  SyntheticOptions o;
  o.origin_offset_mm = Vec3(1.5, -0.5, 0.8);
  const CompareSection k = compare_kinematics(record(o), "");
  EXPECT_EQ(fault_names(k), std::set<std::string>{"base_offset"}) << describe(k);
  const auto& params = k.detail["geometry_fit"]["parameters"];
  EXPECT_NEAR(params[kBaseX]["fitted"].get<double>(), 1.5, 0.05);
}

// a pot read 5 % high: the fit's gain takes it back out (1 / 1.05)
TEST_F(CompareKinematics, PotGainIsNamed) {
  SyntheticOptions o;
  o.gimbal_gain[1] = 1.05;
  const CompareSection k = compare_kinematics(record(o), "");
  EXPECT_EQ(fault_names(k), std::set<std::string>{"joint5_scale"}) << describe(k);
  const auto& params = k.detail["geometry_fit"]["parameters"];
  EXPECT_NEAR(params[kScaleT4 + 1]["fitted"].get<double>(), 1.0 / 1.05, 0.003);
}

// a wrist position error no geometry or map makes: a 3 mm wobble in x
TEST_F(CompareKinematics, AnUnexplainedErrorIsSaidToBe) {
  Recording r = record();
  std::vector<double>& x = r.num["dev_p_x_mm"];
  for (std::size_t i = 0; i < r.rows; ++i) x[i] += 3.0 * std::sin(7.0 * r.t_s(i));
  const CompareSection k = compare_kinematics(r, "");
  EXPECT_EQ(fault_names(k), std::set<std::string>{"kinematics_unexplained"}) << describe(k);
  EXPECT_FALSE(k.detail["geometry_fit"]["explains"].get<bool>());
}

TEST_F(CompareKinematics, AConsistentDelayTripsNothing) {
  const Recording r = record({}, {}, 0.005);
  const CompareSection k = compare_kinematics(r, "");
  EXPECT_TRUE(all_pass(k)) << describe(k);
  EXPECT_TRUE(k.faults.empty()) << describe(k);
  const CompareSection j = compare_jacobian(r, ReadingMap{}, "");
  EXPECT_TRUE(all_pass(j)) << describe(j);
}

TEST_F(CompareKinematics, JacobianLayoutIsFound) {
  SyntheticOptions t;
  t.jacobian_transposed = true;
  const CompareSection jt = compare_jacobian(record(t), ReadingMap{}, "");
  EXPECT_EQ(jt.detail["layout"], "transposed_device_joints");
  EXPECT_TRUE(check(jt, "jacobian.matrix_rel_error").pass) << describe(jt);
  // the layouts that do not fit are far off, not marginally
  EXPECT_GT(jt.detail["layout_median_rel_error"]["as_stored_device_joints"].get<double>(),
            10 * kJacobianRelErrorThreshold);

  SyntheticOptions q;
  q.jacobian_dh_columns = true;
  const CompareSection jq = compare_jacobian(record(q), ReadingMap{}, "");
  EXPECT_EQ(jq.detail["layout"], "as_stored_dh_joints");
  EXPECT_TRUE(check(jq, "jacobian.matrix_rel_error").pass) << describe(jq);
}

TEST_F(CompareKinematics, JacobianReadsThroughTheMap) {
  SyntheticOptions o;
  o.map.sign[0] = -1.0;
  const Recording r = record(o);
  const CompareSection raw = compare_jacobian(r, ReadingMap{}, "");
  EXPECT_FALSE(check(raw, "jacobian.matrix_rel_error").pass) << describe(raw);
  EXPECT_FALSE(check(raw, "jacobian.velocity_rel_error").pass) << describe(raw);
  const ReadingDiagnosis d = diagnose_readings(r);
  ASSERT_EQ(d.map.name, "joint1_sign") << d.evidence;
  const CompareSection through = compare_jacobian(r, d.map, "");
  EXPECT_TRUE(all_pass(through)) << describe(through);
  EXPECT_EQ(through.detail["explained_by"], "joint1_sign");
}

TEST_F(CompareKinematics, WithoutTheDevicesOwnColumnsChecksAreSkipped) {
  SyntheticOptions o;
  o.transform = o.velocity = o.jacobian = false;
  const Recording r = record(o);
  const CompareSection k = compare_kinematics(r, "");
  EXPECT_TRUE(k.checks.empty());
  EXPECT_TRUE(k.faults.empty());
  ASSERT_EQ(k.skipped.size(), 4u);
  EXPECT_NE(k.skipped[0].reason.find("dev_p"), std::string::npos);
  const CompareSection j = compare_jacobian(r, ReadingMap{}, "");
  EXPECT_TRUE(j.checks.empty());
  EXPECT_EQ(j.skipped.size(), 3u);
  EXPECT_EQ(diagnose_readings(r).map.name, "");
}

TEST_F(CompareKinematics, FiguresAreWritten) {
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "cmpkin_figures";
  std::filesystem::remove_all(dir);
  const Recording r = record();
  const CompareSection k = compare_kinematics(r, dir.string());
  const CompareSection j = compare_jacobian(r, ReadingMap{}, dir.string());
  ASSERT_EQ(k.figures.size(), 1u);
  ASSERT_EQ(j.figures.size(), 1u);
  for (const std::string& f : {k.figures[0], j.figures[0]}) {
    const std::string text = vmh::testing::read_file(f);
    EXPECT_NE(text.find("<svg"), std::string::npos) << f;
    EXPECT_NE(text.find("series-1"), std::string::npos) << f;
  }
}

}  // namespace
}  // namespace vmh::bringup
