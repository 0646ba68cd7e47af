// MuJoCo as an independent check of controller/omni_kinematics.
//
// The MJCF chain is generated from the rows of omni_dh_table() alone (never
// from omni_frames or omni_fk), so MuJoCo's own frame composition, site poses
// and mj_jacSite are compared with the controller's forward kinematics and
// geometric Jacobian. A modified-DH row
//   T_{i-1,i} = RotX(alpha) TransX(a) RotZ(theta_offset + q) TransZ(d)
// is rewritten as RotX(alpha) TransX(a) TransZ(d) RotZ(theta_offset) RotZ(q)
// (RotZ and TransZ commute): everything but RotZ(q) is the fixed body pose,
// and RotZ(q) is a hinge about the body's local z axis.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "controller/omni_kinematics.h"
#include "controller/omni_params.h"
#include "controller/types.h"
#include "tests/models/model_files.h"
#include "tests/support/mujoco_kinematics.h"
#include "tests/support/constants.h"

namespace vmh {
namespace {

using vmh::testing::kPi;
// every identity below holds to rounding; 1e-9 leaves room for ~1e6 ulps
constexpr double kTol = 1e-9;
constexpr int kConfigs = 2000;

using testing::max_abs_diff;

// -- mujoco error capture --

// the default mujoco handlers print and exit the process; these record the
// message instead so that a gtest assertion can report it
std::vector<std::string>& mujoco_messages() {
  static std::vector<std::string> messages;
  return messages;
}

void record_error(const char* msg) {
  mujoco_messages().push_back(std::string("mujoco error: ") + msg);
}

void record_warning(const char* msg) {
  mujoco_messages().push_back(std::string("mujoco warning: ") + msg);
}

// installs the recording handlers for its lifetime and restores the old ones
class MujocoMessageGuard {
 public:
  MujocoMessageGuard()
      : old_error_(mju_user_error), old_warning_(mju_user_warning) {
    mujoco_messages().clear();
    mju_user_error = record_error;
    mju_user_warning = record_warning;
  }
  ~MujocoMessageGuard() {
    mju_user_error = old_error_;
    mju_user_warning = old_warning_;
  }
  MujocoMessageGuard(const MujocoMessageGuard&) = delete;
  MujocoMessageGuard& operator=(const MujocoMessageGuard&) = delete;

  static std::string joined() {
    std::string all;
    for (const std::string& m : mujoco_messages()) all += m + "\n";
    return all;
  }

 private:
  void (*old_error_)(const char*);
  void (*old_warning_)(const char*);
};

// -- raii owners --

struct VfsDeleter {
  void operator()(mjVFS* vfs) const {
    mj_deleteVFS(vfs);
    delete vfs;
  }
};
// the model tests' owners (tests/models/model_files.h): this test is part
// of their program (tests/CMakeLists.txt)
using testing::DataPtr;
using testing::ModelPtr;

// -- mjcf from the dh table --

std::string num(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// One body per row of omni_dh_table(params). Body i sits at
// TransX(a) then TransZ(d) after RotX(alpha), i.e. at (a, -sin(alpha) d,
// cos(alpha) d) in its parent, turned by RotX(alpha) RotZ(theta_offset)
// (intrinsic x-y-z euler angles alpha, 0, theta_offset). Site "wrist" is the
// origin of frame 6; site "tool" sits tool_offset_m along its z axis.
std::string omni_mjcf(const OmniParams& params, double tool_offset_m) {
  const std::array<DhRow, kOmniJoints> table = omni_dh_table(params);
  std::ostringstream xml;
  xml << "<mujoco model=\"omni_dh_check\">\n"
      << "  <compiler angle=\"radian\" autolimits=\"true\" eulerseq=\"xyz\"/>\n"
      // kinematics only: no contacts, no gravity
      << "  <option gravity=\"0 0 0\">\n"
      << "    <flag contact=\"disable\" gravity=\"disable\"/>\n"
      << "  </option>\n"
      << "  <worldbody>\n";
  std::string indent = "    ";
  for (int i = 0; i < kOmniJoints; ++i) {
    const DhRow& r = table[i];
    const double px = r.a_m;
    const double py = -std::sin(r.alpha_rad) * r.d_m;
    const double pz = std::cos(r.alpha_rad) * r.d_m;
    xml << indent << "<body name=\"link" << i + 1 << "\" pos=\"" << num(px)
        << ' ' << num(py) << ' ' << num(pz) << "\" euler=\"" << num(r.alpha_rad)
        << " 0 " << num(r.theta_offset_rad) << "\">\n"
        << indent << "  <joint name=\"q" << i + 1
        << "\" type=\"hinge\" axis=\"0 0 1\" pos=\"0 0 0\"/>\n"
        // small inertia: only kinematics is used, but moving bodies need mass
        << indent
        << "  <inertial pos=\"0 0 0\" mass=\"0.01\" "
           "diaginertia=\"1e-5 1e-5 1e-5\"/>\n";
    indent += "  ";
  }
  xml << indent << "<site name=\"wrist\" pos=\"0 0 0\"/>\n"
      << indent << "<site name=\"tool\" pos=\"0 0 " << num(tool_offset_m)
      << "\"/>\n";
  for (int i = kOmniJoints - 1; i >= 0; --i) {
    indent.resize(indent.size() - 2);
    xml << indent << "</body>\n";
  }
  xml << "  </worldbody>\n</mujoco>\n";
  return xml.str();
}

// Compiles `xml` through an in-memory vfs. Returns null and fills *error when
// mujoco rejects it.
ModelPtr load_mjcf(const std::string& xml, std::string* error) {
  // mjVFS holds fixed arrays of ~2 MB: keep it off the stack
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  const char* name = "omni_dh_check.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size())) != 0) {
    *error = "mj_makeEmptyFileVFS failed";
    return nullptr;
  }
  const int idx = mj_findFileVFS(vfs.get(), name);
  if (idx < 0) {
    *error = "mj_findFileVFS did not find the file just made";
    return nullptr;
  }
  std::memcpy(vfs->filedata[idx], xml.data(), xml.size());
  char err[1000] = "";
  ModelPtr m(mj_loadXML(name, vfs.get(), err, sizeof err));
  if (!m) *error = err[0] ? err : "mj_loadXML returned null, no message";
  return m;
}

// -- comparison helpers --

Joints random_joints(std::mt19937_64* rng) {
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  Joints q;
  for (int i = 0; i < kOmniJoints; ++i) q[i] = angle(*rng);
  return q;
}

// largest error seen over all configurations, one per identity
struct MaxErrors {
  double frames = 0.0;
  double wrist_pos = 0.0;
  double wrist_rot = 0.0;
  double jac_lin = 0.0;
  double jac_ang = 0.0;
  double tool_pos = 0.0;
  double tool_jac_lin = 0.0;
  double tool_jac_ang = 0.0;
};

class OmniMujocoTest : public ::testing::Test {
 protected:
  void build(const OmniParams& params, double tool_offset_m) {
    params_ = params;
    params_.tool_offset_m = tool_offset_m;
    std::string error;
    model_ = load_mjcf(omni_mjcf(params_, tool_offset_m), &error);
    ASSERT_NE(model_, nullptr) << error;
    ASSERT_TRUE(mujoco_messages().empty()) << MujocoMessageGuard::joined();
    data_.reset(mj_makeData(model_.get()));
    ASSERT_NE(data_, nullptr);
    ASSERT_EQ(model_->nq, kOmniJoints);
    ASSERT_EQ(model_->nv, kOmniJoints);
    // world + six links
    ASSERT_EQ(model_->nbody, kOmniJoints + 1);
    wrist_ = mj_name2id(model_.get(), mjOBJ_SITE, "wrist");
    tool_ = mj_name2id(model_.get(), mjOBJ_SITE, "tool");
    ASSERT_GE(wrist_, 0);
    ASSERT_GE(tool_, 0);
  }

  void TearDown() override {
    EXPECT_TRUE(mujoco_messages().empty()) << MujocoMessageGuard::joined();
  }

  void set_q(const Joints& q) {
    testing::set_joints(model_.get(), data_.get(), q);
  }
  Vec3 site_pos(int site) const { return testing::site_pos(data_.get(), site); }
  Mat3 site_rot(int site) const { return testing::site_rot(data_.get(), site); }
  // mj_jacSite: linear rows over angular rows
  Mat6 site_jac(int site) const {
    return testing::site_jacobian(model_.get(), data_.get(), site);
  }

  // checks every identity at kConfigs random configurations and returns the
  // largest errors
  MaxErrors check_random_configs(std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    MaxErrors e;
    OmniFrames frames;
    for (int k = 0; k < kConfigs; ++k) {
      const Joints q = random_joints(&rng);
      set_q(q);

      // frame of body i (xpos, xmat) == T_{0,i} of omni_frames, i = 1..6
      omni_frames(params_, q, &frames);
      e.frames =
          std::max(e.frames, testing::max_body_frame_error(data_.get(), frames));

      // wrist site: site_xpos == omni_fk.p_base_m, site_xmat == R_base
      const OmniPose pose = omni_fk(params_, q);
      e.wrist_pos =
          std::max(e.wrist_pos, max_abs_diff(site_pos(wrist_), pose.p_base_m));
      e.wrist_rot =
          std::max(e.wrist_rot, max_abs_diff(site_rot(wrist_), pose.R_base));

      // wrist jacobian: jacp == J.rows(0..2), jacr == J.rows(3..5)
      const Mat6 J = omni_jacobian(params_, q);
      const Mat6 Jm = site_jac(wrist_);
      e.jac_lin = std::max(e.jac_lin,
                           max_abs_diff(Jm.topRows<3>(), J.topRows<3>()));
      e.jac_ang = std::max(e.jac_ang,
                           max_abs_diff(Jm.bottomRows<3>(), J.bottomRows<3>()));

      // tool site: site_xpos == omni_tool_point(omni_fk), and mj_jacSite ==
      // omni_jacobian_at(q, tool_offset_m)
      e.tool_pos = std::max(
          e.tool_pos,
          max_abs_diff(site_pos(tool_), omni_tool_point(params_, pose)));
      const Mat6 Jt = omni_jacobian_at(params_, q, params_.tool_offset_m);
      const Mat6 Jtm = site_jac(tool_);
      e.tool_jac_lin = std::max(
          e.tool_jac_lin, max_abs_diff(Jtm.topRows<3>(), Jt.topRows<3>()));
      e.tool_jac_ang = std::max(
          e.tool_jac_ang, max_abs_diff(Jtm.bottomRows<3>(), Jt.bottomRows<3>()));
    }
    return e;
  }

  void expect_within_tolerance(const MaxErrors& e) {
    EXPECT_LE(e.frames, kTol) << "body frames vs omni_frames";
    EXPECT_LE(e.wrist_pos, kTol) << "wrist site_xpos vs omni_fk.p_base_m";
    EXPECT_LE(e.wrist_rot, kTol) << "wrist site_xmat vs omni_fk.R_base";
    EXPECT_LE(e.jac_lin, kTol) << "wrist jacp vs omni_jacobian rows 0-2";
    EXPECT_LE(e.jac_ang, kTol) << "wrist jacr vs omni_jacobian rows 3-5";
    EXPECT_LE(e.tool_pos, kTol) << "tool site_xpos vs omni_tool_point";
    EXPECT_LE(e.tool_jac_lin, kTol) << "tool jacp vs omni_jacobian_at 0-2";
    EXPECT_LE(e.tool_jac_ang, kTol) << "tool jacr vs omni_jacobian_at 3-5";
    // the figures go in the test log and the xml report
    std::printf(
        "  %d configs, max |error|: frames %.3g, wrist pos %.3g, rot %.3g, "
        "jacp %.3g, jacr %.3g; tool pos %.3g, jacp %.3g, jacr %.3g\n",
        kConfigs, e.frames, e.wrist_pos, e.wrist_rot, e.jac_lin, e.jac_ang,
        e.tool_pos, e.tool_jac_lin, e.tool_jac_ang);
    RecordProperty("configs", kConfigs);
    RecordProperty("max_wrist_pos_err", num(e.wrist_pos));
    RecordProperty("max_wrist_rot_err", num(e.wrist_rot));
    RecordProperty("max_jacp_err", num(e.jac_lin));
    RecordProperty("max_jacr_err", num(e.jac_ang));
    RecordProperty("max_tool_pos_err", num(e.tool_pos));
    RecordProperty("max_tool_jacp_err", num(e.tool_jac_lin));
    RecordProperty("max_tool_jacr_err", num(e.tool_jac_ang));
  }

  MujocoMessageGuard guard_;
  OmniParams params_;
  ModelPtr model_;
  DataPtr data_;
  int wrist_ = -1;
  int tool_ = -1;
};

// l0 = 0.03 with l1 != l2: a swapped or dropped length moves the wrist centre
// by centimetres
OmniParams skewed_params() {
  OmniParams p;
  p.l0_m = 0.03;
  p.l1_m = 0.11;
  p.l2_m = 0.17;
  return p;
}

// The mujoco chain is built from omni_dh_table, so a wrong table would agree
// with itself below. Identity: omni_dh_table(p) == Table B.1 written out by
// hand (a_{i-1}, alpha_{i-1}, d_i, theta_i - q_i), exactly.
TEST(OmniMujocoTableTest, DhTableIsTableB1) {
  const OmniParams p = skewed_params();
  const double h = 0.5 * kPi;
  const std::array<DhRow, kOmniJoints> expected = {{
      {0.0, 0.0, p.l0_m, 0.0},
      {0.0, h, 0.0, 0.0},
      {p.l1_m, 0.0, 0.0, 0.0},
      {0.0, h, p.l2_m, 0.0},
      {0.0, -h, 0.0, -h},
      {0.0, -h, 0.0, h},
  }};
  const std::array<DhRow, kOmniJoints> table = omni_dh_table(p);
  for (int i = 0; i < kOmniJoints; ++i) {
    SCOPED_TRACE("row " + std::to_string(i + 1));
    EXPECT_EQ(table[i].a_m, expected[i].a_m);
    EXPECT_DOUBLE_EQ(table[i].alpha_rad, expected[i].alpha_rad);
    EXPECT_EQ(table[i].d_m, expected[i].d_m);
    EXPECT_DOUBLE_EQ(table[i].theta_offset_rad, expected[i].theta_offset_rad);
  }
}

// Identity: at q = 0 the mujoco chain and omni_fk agree on the wrist centre
// and stylus frame, and with skewed lengths that point is not the one the
// default lengths give (so the random tests below can tell the lengths apart).
TEST_F(OmniMujocoTest, HomePoseMatchesAndLengthsMatter) {
  build(skewed_params(), -0.05);
  set_q(Joints::Zero());
  const OmniPose pose = omni_fk(params_, Joints::Zero());
  EXPECT_LE(max_abs_diff(site_pos(wrist_), pose.p_base_m), kTol);
  EXPECT_LE(max_abs_diff(site_rot(wrist_), pose.R_base), kTol);

  OmniParams swapped = params_;
  std::swap(swapped.l1_m, swapped.l2_m);
  EXPECT_GT(
      max_abs_diff(site_pos(wrist_), omni_fk(swapped, Joints::Zero()).p_base_m),
      1e-3);
  OmniParams no_l0 = params_;
  no_l0.l0_m = 0.0;
  EXPECT_GT(
      max_abs_diff(site_pos(wrist_), omni_fk(no_l0, Joints::Zero()).p_base_m),
      1e-3);
}

// Identities, at kConfigs configurations uniform in [-pi, pi]^6, default
// Omni lengths (l0 = 0, l1 = l2), tool 0.05 m behind the wrist (eq. B.7):
//   xpos_i, xmat_i == T_{0,i} of omni_frames      (i = 1..6)
//   site_xpos(wrist) == omni_fk.p_base_m,  site_xmat(wrist) == omni_fk.R_base
//   mj_jacSite(wrist) == [omni_jacobian rows 0-2; rows 3-5]
//   site_xpos(tool) == omni_tool_point,
//   mj_jacSite(tool) == [omni_jacobian_at(offset) rows 0-2; rows 3-5]
// each to kTol (max abs entry).
TEST_F(OmniMujocoTest, DefaultLengthsMatchAtRandomConfigs) {
  build(OmniParams(), -0.05);
  expect_within_tolerance(check_random_configs(20240601));
}

// The same identities with l0 = 0.03, l1 = 0.11, l2 = 0.17, which catches a
// swapped l1/l2 or a dropped l0 that equal default lengths would hide.
TEST_F(OmniMujocoTest, SkewedLengthsMatchAtRandomConfigs) {
  build(skewed_params(), -0.05);
  expect_within_tolerance(check_random_configs(77));
}

// The same identities with the tool point ahead of the wrist (+0.08 m), so a
// sign flip of the offset in omni_jacobian_at or omni_tool_point is caught.
TEST_F(OmniMujocoTest, PositiveToolOffsetMatchesAtRandomConfigs) {
  build(skewed_params(), 0.08);
  expect_within_tolerance(check_random_configs(4242));
}

// The harness itself: a malformed model comes back as null with a message,
// and a mujoco warning is recorded instead of ending the process.
TEST(OmniMujocoHarnessTest, LoadErrorsAndWarningsAreCaught) {
  MujocoMessageGuard guard;
  std::string error;
  ModelPtr bad = load_mjcf("<mujoco><worldbody><body></mujoco>", &error);
  EXPECT_EQ(bad, nullptr);
  EXPECT_FALSE(error.empty());

  mju_warning("probe");
  ASSERT_EQ(mujoco_messages().size(), 1u);
  EXPECT_NE(mujoco_messages()[0].find("probe"), std::string::npos);
  mujoco_messages().clear();
}

}  // namespace
}  // namespace vmh
