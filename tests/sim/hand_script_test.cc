// sim/hand_script: where the scripted hand puts the wrist centre and the
// stylus axis (device frame, mm) over a run.
//
// The script's layout is docs/testbed.md's table, in twentieths of the run:
// settle 0-1, off_out 1-3, off_out_misaligned 3-5, off_in 5-7,
// on_misaligned_a 7-10, on_misaligned_b 10-13, sweep 13-20. Distances from
// the path and misalignment angles are measured here from the pivot and L
// in closed form, not through the script's own geometry.
//
// The scripts run on a non-default duration, pivot and amplitudes so that
// a default sneaking in would show.
#include "sim/hand_script.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sim/cases/case_config.h"
#include "sim/mujoco_util.h"
#include "tests/support/mujoco_guard.h"
#include "tests/support/temp_mjcf.h"

namespace vmh::sim {
namespace {

using testing::numeric_field;
using testing::text_field;

constexpr double kDuration_s = 8.0;
constexpr double kLength_mm = 45.0;
constexpr double kOff_mm = 25.0;
constexpr double kMisalign_rad = 0.4;
constexpr double kSweep_mm = 15.0;
constexpr double kSweep_rad = 0.35;
const Vec3 kPivot_mm(10.0, -5.0, 3.0);
// the plane normal / pole axis: the pivot frame's z, identity in the cases
const Vec3 kNormal = Vec3::UnitZ();

struct Loaded {
  CaseConfig config;
  VmParams vm;
};

class HandScriptTest : public ::testing::TestWithParam<const char*> {
 protected:
  Loaded load(const std::string& kind,
              const std::vector<std::string>& overrides = {}) {
    const std::string customs = text_field("vm_kind", kind) +
                                numeric_field("vm_length_mm", "45") +
                                numeric_field("vm_pivot_mm", "10 -5 3") +
                                numeric_field("duration_s", "8") +
                                numeric_field("script_off_mm", "25") +
                                numeric_field("script_misalign_rad", "0.4") +
                                numeric_field("script_sweep_mm", "15") +
                                numeric_field("script_sweep_rad", "0.35");
    path_ = dir_.write("script.xml", testing::custom_only_scene(customs));
    ModelPtr m = load_model(path_);
    CaseConfig c = CaseConfig::from_model(m.get(), path_, overrides);
    const VmParams vm = controller_params(c).vm;
    return {c, vm};
  }

  bool circle() const { return std::string(GetParam()) == "circle"; }

  // the unit direction from the pivot at which the script starts: the
  // default script_dir, for the circle projected on its plane
  Vec3 start_dir() const {
    Vec3 d = Vec3(-0.35, 0.65, 0.65);
    if (circle()) d.z() = 0.0;
    return d.normalized();
  }

  // signed distance from the path: the circle (radius L in the plane
  // z = pivot z) or the sphere (radius L about the pivot); positive outside
  double path_offset_mm(const Vec3& p_mm) const {
    const Vec3 r = p_mm - kPivot_mm;
    if (circle()) {
      return std::hypot(std::hypot(r.x(), r.y()) - kLength_mm, r.z()) *
             (std::hypot(r.x(), r.y()) >= kLength_mm ? 1.0 : -1.0);
    }
    return r.norm() - kLength_mm;
  }

  // the angle between the stylus axis and the VM's link through p: for the
  // circle both projected on its plane (only that part is constrained), for
  // the sphere in space
  double misalignment_rad(const Vec3& p_mm, const Vec3& axis) const {
    Vec3 link = p_mm - kPivot_mm;
    Vec3 a = axis;
    if (circle()) {
      link -= link.dot(kNormal) * kNormal;
      a -= a.dot(kNormal) * kNormal;
    }
    return std::atan2(link.cross(a).norm(), link.dot(a));
  }

  testing::MujocoGuard guard_;
  testing::TempMjcfDir dir_;
  std::string path_;
};

TEST_P(HandScriptTest, SegmentsAreTheTwentiethsOfTheRun) {
  const Loaded l = load(GetParam());
  const HandScript s(l.config, l.vm);
  const std::vector<ScriptSegment>& seg = s.segments();
  const char* names[] = {"settle", "off_out",         "off_out_misaligned",
                         "off_in", "on_misaligned_a", "on_misaligned_b",
                         "sweep"};
  const double ends[] = {0, 1, 3, 5, 7, 10, 13, 20};  // twentieths
  ASSERT_EQ(seg.size(), 7u);
  for (std::size_t i = 0; i < seg.size(); ++i) {
    EXPECT_EQ(seg[i].name, names[i]);
    EXPECT_NEAR(seg[i].t0_s, ends[i] * kDuration_s / 20.0, 1e-12) << names[i];
    EXPECT_NEAR(seg[i].t1_s, ends[i + 1] * kDuration_s / 20.0, 1e-12)
        << names[i];
    EXPECT_EQ(seg[i].hold, seg[i].name != "sweep") << names[i];
    EXPECT_NEAR(seg[i].settled_from_s(), 0.5 * (seg[i].t0_s + seg[i].t1_s),
                1e-12);
    // contiguous: each starts exactly where the last ended
    if (i > 0) {
      EXPECT_EQ(seg[i].t0_s, seg[i - 1].t1_s) << names[i];
    }
  }
  // they cover [0, duration]
  EXPECT_EQ(seg.front().t0_s, 0.0);
  EXPECT_NEAR(seg.back().t1_s, kDuration_s, 1e-12);
  // segment_at: each start belongs to its segment; past the end, the last
  for (std::size_t i = 0; i < seg.size(); ++i) {
    EXPECT_EQ(s.segment_at(seg[i].t0_s), static_cast<int>(i));
    EXPECT_EQ(s.segment_at(seg[i].t1_s - 1e-9), static_cast<int>(i));
  }
  EXPECT_EQ(s.segment_at(kDuration_s + 1.0), 6);
}

TEST_P(HandScriptTest, StartsOnThePathAlongScriptDir) {
  const Loaded l = load(GetParam());
  const HandScript s(l.config, l.vm);
  const Vec3 p0_mm = kPivot_mm + kLength_mm * start_dir();
  EXPECT_TRUE(s.start_mm().isApprox(p0_mm, 1e-12)) << s.start_mm().transpose();
  const ScriptPose pose = s.at(0.0);
  EXPECT_TRUE(pose.p_mm.isApprox(p0_mm, 1e-12));
  // the stylus along script_dir itself (for the circle, out of the plane too)
  EXPECT_TRUE(pose.axis.isApprox(Vec3(-0.35, 0.65, 0.65).normalized(), 1e-12));
  EXPECT_NEAR(misalignment_rad(pose.p_mm, pose.axis), 0.0, 1e-12);
  // the sweep's tangent: about the normal, outward x tangent along it
  const Vec3 t = kNormal.cross(start_dir()).normalized();
  EXPECT_TRUE(s.tangent().isApprox(t, 1e-12));
}

// In the settled half of each hold the target does not move at all.
TEST_P(HandScriptTest, HeldSegmentsStandStillInTheirSettledHalf) {
  const Loaded l = load(GetParam());
  const HandScript s(l.config, l.vm);
  int checked = 0;
  for (const ScriptSegment& seg : s.segments()) {
    if (!seg.hold) continue;
    const ScriptPose settled = s.at(seg.settled_from_s());
    for (int k = 0; k < 50; ++k) {
      const double t =
          seg.settled_from_s() + (seg.t1_s - seg.settled_from_s()) * k / 50.0;
      const ScriptPose p = s.at(t);
      EXPECT_EQ(p.p_mm, settled.p_mm) << seg.name << " t " << t;
      EXPECT_EQ(p.axis, settled.axis) << seg.name << " t " << t;
    }
    ++checked;
  }
  EXPECT_EQ(checked, 6);
}

// Each change of target is blended in, not a jump: the target moves by
// little between two close instants, even across a segment boundary.
TEST_P(HandScriptTest, TargetHasNoJumps) {
  const Loaded l = load(GetParam());
  const HandScript s(l.config, l.vm);
  const double dt_s = 1e-4;
  double largest_mm = 0.0, largest_rad = 0.0;
  for (double t = 0.0; t < kDuration_s; t += dt_s) {
    const ScriptPose a = s.at(t), b = s.at(t + dt_s);
    largest_mm = std::max(largest_mm, (b.p_mm - a.p_mm).norm());
    largest_rad = std::max(largest_rad, std::atan2(a.axis.cross(b.axis).norm(),
                                                   a.axis.dot(b.axis)));
  }
  // the largest change, 50 mm from off_out_misaligned to off_in, blended
  // by a smoothstep over 0.1 s peaks at 1.5 x 50 mm / 0.1 s: 0.075 mm per
  // 0.1 ms; the largest turn, 0.8 rad (circle, a to b), 1.2e-3 rad
  EXPECT_LT(largest_mm, 0.1);
  EXPECT_LT(largest_rad, 0.01);
}

TEST_P(HandScriptTest, OffSegmentsSitOffThePath) {
  const Loaded l = load(GetParam());
  const HandScript s(l.config, l.vm);
  const struct {
    int index;
    double offset_mm;
    double misalign_rad;
  } rows[] = {
      {1, kOff_mm, 0.0}, {2, kOff_mm, kMisalign_rad}, {3, -kOff_mm, 0.0}};
  for (const auto& row : rows) {
    const ScriptSegment& seg =
        s.segments()[static_cast<std::size_t>(row.index)];
    for (const double f : {0.0, 0.5, 0.99}) {
      const double t =
          seg.settled_from_s() + f * (seg.t1_s - seg.settled_from_s());
      const ScriptPose p = s.at(t);
      EXPECT_NEAR(path_offset_mm(p.p_mm), row.offset_mm, 1e-9) << seg.name;
      // straight out from (or in toward) the start point, in the plane
      const Vec3 expected_mm =
          kPivot_mm + (kLength_mm + row.offset_mm) * start_dir();
      EXPECT_TRUE(p.p_mm.isApprox(expected_mm, 1e-12)) << seg.name;
      EXPECT_NEAR(misalignment_rad(p.p_mm, p.axis), row.misalign_rad, 1e-9)
          << seg.name;
    }
  }
}

TEST_P(HandScriptTest, OnPathSegmentsAreOnThePathAndMisaligned) {
  const Loaded l = load(GetParam());
  const HandScript s(l.config, l.vm);
  const Vec3 r0 = start_dir();
  const Vec3 t0 = kNormal.cross(r0).normalized();
  for (const int index : {4, 5}) {
    const ScriptSegment& seg = s.segments()[static_cast<std::size_t>(index)];
    const ScriptPose p = s.at(seg.settled_from_s());
    EXPECT_NEAR(path_offset_mm(p.p_mm), 0.0, 1e-9) << seg.name;
    EXPECT_TRUE(p.p_mm.isApprox(kPivot_mm + kLength_mm * r0, 1e-12));
    EXPECT_NEAR(misalignment_rad(p.p_mm, p.axis), kMisalign_rad, 1e-9)
        << seg.name;
    EXPECT_NEAR(p.axis.norm(), 1.0, 1e-12);
    if (circle()) {
      // turned about the normal, + in a, - in b: the signed in-plane angle
      // from the link to the axis, and the out-of-plane part untouched
      Vec3 a = p.axis - p.axis.dot(kNormal) * kNormal;
      const double signed_rad = std::atan2(kNormal.dot(r0.cross(a)), r0.dot(a));
      EXPECT_NEAR(signed_rad, index == 4 ? kMisalign_rad : -kMisalign_rad,
                  1e-9);
      EXPECT_NEAR(p.axis.z(), Vec3(-0.35, 0.65, 0.65).normalized().z(), 1e-12);
    } else {
      // a: toward the tangent along the path; b: about that tangent (the
      // polar angle), cos a r0 + sin a (t0 x r0)
      const Vec3 expected =
          index == 4
              ? std::cos(kMisalign_rad) * r0 + std::sin(kMisalign_rad) * t0
              : std::cos(kMisalign_rad) * r0 +
                    std::sin(kMisalign_rad) * t0.cross(r0);
      EXPECT_TRUE(p.axis.isApprox(expected, 1e-12))
          << seg.name << ": " << p.axis.transpose() << " vs "
          << expected.transpose();
    }
  }
}

// After its blend-in the sweep stays within +-script_sweep_rad about the
// normal and +-script_sweep_mm across the path, reaches both, and keeps the
// stylus turning with the link.
TEST_P(HandScriptTest, SweepStaysWithinItsAmplitudes) {
  const Loaded l = load(GetParam());
  const HandScript s(l.config, l.vm);
  const ScriptSegment& sweep = s.segments().back();
  const Vec3 r0 = start_dir();
  const double polar0_rad = std::acos(r0.dot(kNormal));
  double across_min = 0, across_max = 0, phi_min = 0, phi_max = 0;
  for (double t = sweep.t0_s + 0.3; t <= sweep.t1_s; t += 1e-3) {
    const ScriptPose p = s.at(t);
    const Vec3 r = p.p_mm - kPivot_mm;
    const double across_mm = r.norm() - kLength_mm;
    // the angle about the normal from the start direction
    const Vec3 r_flat = r - r.dot(kNormal) * kNormal;
    const Vec3 r0_flat = r0 - r0.dot(kNormal) * kNormal;
    const double phi_rad =
        std::atan2(kNormal.dot(r0_flat.cross(r_flat)), r0_flat.dot(r_flat));
    across_min = std::min(across_min, across_mm);
    across_max = std::max(across_max, across_mm);
    phi_min = std::min(phi_min, phi_rad);
    phi_max = std::max(phi_max, phi_rad);
    EXPECT_LE(std::abs(across_mm), kSweep_mm + 1e-9) << t;
    EXPECT_LE(std::abs(phi_rad), kSweep_rad + 1e-9) << t;
    // it moves on the surface of revolution of the path: same polar angle
    EXPECT_NEAR(std::acos(r.normalized().dot(kNormal)), polar0_rad, 1e-9) << t;
    EXPECT_NEAR(misalignment_rad(p.p_mm, p.axis), 0.0, 1e-9) << t;
  }
  EXPECT_GT(across_max, 0.95 * kSweep_mm);
  EXPECT_LT(across_min, -0.95 * kSweep_mm);
  EXPECT_GT(phi_max, 0.95 * kSweep_rad);
  EXPECT_LT(phi_min, -0.95 * kSweep_rad);
}

// `script = hold`: one segment, the start pose throughout.
TEST_P(HandScriptTest, HoldKeepsTheStartPose) {
  const Loaded l = load(GetParam(), {"script=hold"});
  const HandScript s(l.config, l.vm);
  ASSERT_EQ(s.segments().size(), 1u);
  EXPECT_EQ(s.segments()[0].t0_s, 0.0);
  EXPECT_EQ(s.segments()[0].t1_s, kDuration_s);
  const Vec3 p0_mm = kPivot_mm + kLength_mm * start_dir();
  for (const double t : {0.0, 1.0, 4.0, 7.99, 9.0}) {
    const ScriptPose p = s.at(t);
    EXPECT_TRUE(p.p_mm.isApprox(p0_mm, 1e-12)) << t;
    EXPECT_EQ(s.segment_at(t), 0);
  }
}

INSTANTIATE_TEST_SUITE_P(CircleAndSphere, HandScriptTest,
                         ::testing::Values("circle", "sphere"));

// The line slider (vm_kind line) runs along the pivot frame's y axis (the
// device y here) through the pivot. Its script, in closed form: the start
// is the foot of the perpendicular from pivot + L dir; the off-path holds
// stand off the line along x, toward dir's side (out) and away (in); the
// sweep slides L phi along the line, the stylus turning with nothing.
class LineScriptTest : public ::testing::Test {
 protected:
  HandScript script(const std::vector<std::string>& overrides) {
    const std::string customs = text_field("vm_kind", "line") +
                                numeric_field("vm_length_mm", "45") +
                                numeric_field("vm_pivot_mm", "10 -5 3") +
                                numeric_field("duration_s", "8") +
                                numeric_field("script_off_mm", "25") +
                                numeric_field("script_sweep_mm", "15") +
                                numeric_field("script_sweep_rad", "0.35");
    const std::string path =
        dir_.write("line.xml", testing::custom_only_scene(customs));
    ModelPtr m = load_model(path);
    const CaseConfig c = CaseConfig::from_model(m.get(), path, overrides);
    return HandScript(c, controller_params(c).vm);
  }
  // the target in the middle of a segment's settled half, or at a time
  ScriptPose settled(const HandScript& s, const std::string& name) {
    for (const ScriptSegment& g : s.segments()) {
      if (g.name == name) return s.at(0.5 * (g.settled_from_s() + g.t1_s));
    }
    ADD_FAILURE() << "no segment " << name;
    return {};
  }

  testing::MujocoGuard guard_;
  testing::TempMjcfDir dir_;
};

TEST_F(LineScriptTest, StartsAtTheFootAndHoldsOffAcrossTheLine) {
  for (const double side : {1.0, -1.0}) {  // script_dir's x as given, mirrored
    const Vec3 dir = Vec3(side * -0.35, 0.65, 0.65).normalized();
    const HandScript s = script(
        {"script_dir=" + std::to_string(side * -0.35) + ",0.65,0.65"});
    const Vec3 foot = kPivot_mm + Vec3(0.0, kLength_mm * dir.y(), 0.0);
    const Vec3 out(side * -1.0, 0.0, 0.0);  // toward dir's side, in the plane
    EXPECT_LT((s.start_mm() - foot).norm(), 1e-12);
    EXPECT_LT((s.outward() - out).norm(), 1e-12);
    EXPECT_LT((settled(s, "off_out").p_mm - (foot + kOff_mm * out)).norm(),
              1e-12);
    EXPECT_LT((settled(s, "off_in").p_mm - (foot - kOff_mm * out)).norm(),
              1e-12);
    EXPECT_LT((settled(s, "on_misaligned_a").p_mm - foot).norm(), 1e-12);
    // a quarter into the sweep: phi = sweep_rad, across = 0, along the
    // tangent z x out
    const ScriptSegment& sweep = s.segments().back();
    ASSERT_EQ(sweep.name, "sweep");
    const ScriptPose q = s.at(sweep.t0_s + 0.25 * (sweep.t1_s - sweep.t0_s));
    const Vec3 tangent = Vec3::UnitZ().cross(out);
    EXPECT_LT((q.p_mm - (foot + kLength_mm * kSweep_rad * tangent)).norm(),
              1e-9);
    EXPECT_LT((q.axis - dir).norm(), 1e-12);  // the stylus did not turn
  }
}

// A circle whose plane the start direction is normal to has no start point
// on its path: refused, naming the scene and script_dir.
TEST(HandScriptErrorTest, DirectionAlongTheCircleNormalIsRefused) {
  testing::MujocoGuard guard;
  testing::TempMjcfDir dir;
  const std::string path =
      dir.write("normal.xml",
                testing::custom_only_scene(text_field("vm_kind", "circle")));
  ModelPtr m = load_model(path);
  for (const char* dir_set : {"script_dir=0,0,1", "script_dir=0,0,-2"}) {
    const CaseConfig c = CaseConfig::from_model(m.get(), path, {dir_set});
    try {
      HandScript s(c, controller_params(c).vm);
      ADD_FAILURE() << dir_set << " accepted";
    } catch (const SimError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(path), std::string::npos) << msg;
      EXPECT_NE(msg.find("script_dir"), std::string::npos) << msg;
    }
  }
  // the sphere has a start point in that direction
  const CaseConfig c = CaseConfig::from_model(
      m.get(), path, {"vm_kind=sphere", "script_dir=0,0,1"});
  EXPECT_NO_THROW(HandScript(c, controller_params(c).vm));
}

}  // namespace
}  // namespace vmh::sim
