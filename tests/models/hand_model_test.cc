// models/hand/hand.xml, included after models/omni/omni.xml the way the
// case scenes include it. It must leave the Omni as it is (no degree of
// freedom, geometry or mass added, so omni.xml's keyframes stay valid) and
// carry the six hand_* numerics the simulator reads (sim/hand.h).
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "tests/models/model_files.h"
#include "tests/support/mujoco_guard.h"

namespace vmh {
namespace {

namespace fs = std::filesystem;
using testing::DataPtr;
using testing::ModelPtr;
using testing::MujocoGuard;

// A scene in a fresh temporary directory that includes omni.xml and then
// hand.xml, as the case scenes do; removed with the object. MuJoCo 2.2.2
// resolves an include relative to the including file's directory even when
// it is absolute, so the paths are written relative to that directory.
class TempScene {
 public:
  TempScene() {
    std::random_device rd;
    dir_ = fs::temp_directory_path() /
           ("vmh_hand_model_test_" + std::to_string(rd()));
    fs::create_directories(dir_);
    path_ = dir_ / "scene.xml";
    std::ofstream(path_) << "<mujoco model=\"hand_check\">\n"
                         << "  <include file=\"" << include_path(omni_xml())
                         << "\"/>\n"
                         << "  <include file=\"" << include_path(hand_xml())
                         << "\"/>\n"
                         << "</mujoco>\n";
  }
  ~TempScene() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  TempScene(const TempScene&) = delete;
  TempScene& operator=(const TempScene&) = delete;
  std::string path() const { return path_.string(); }

  static std::string omni_xml() {
    return testing::models_dir() + "/omni/omni.xml";
  }
  static std::string hand_xml() {
    return testing::models_dir() + "/hand/hand.xml";
  }

 private:
  fs::path dir_;
  fs::path path_;

  std::string include_path(const std::string& file) const {
    return fs::relative(fs::absolute(file), dir_).generic_string();
  }
};

ModelPtr load_or_fail(const std::string& path) {
  std::string error;
  ModelPtr m = testing::load_model(path, &error);
  EXPECT_NE(m, nullptr) << error;
  EXPECT_TRUE(error.empty()) << error;
  return m;
}

std::vector<double> numeric(const mjModel* m, const char* name) {
  const int id = mj_name2id(m, mjOBJ_NUMERIC, name);
  if (id < 0) return {};
  const mjtNum* p = m->numeric_data + m->numeric_adr[id];
  return std::vector<double>(p, p + m->numeric_size[id]);
}

// The hand after the Omni: nq = nv = 6, nu = 3, the same bodies' masses,
// geoms and joints as omni.xml alone; one mocap body "hand_target" with a
// site of the same name and no geom; keyframe "home" still loads. Exact.
TEST(HandModelTest, AddsNoDegreeOfFreedom) {
  MujocoGuard guard;
  const TempScene scene;
  ModelPtr m = load_or_fail(scene.path());
  ModelPtr omni = load_or_fail(TempScene::omni_xml());
  ASSERT_NE(m, nullptr);
  ASSERT_NE(omni, nullptr);

  EXPECT_EQ(m->nq, 6);
  EXPECT_EQ(m->nv, 6);
  EXPECT_EQ(m->nu, omni->nu);
  EXPECT_EQ(m->njnt, omni->njnt);
  EXPECT_EQ(m->ngeom, omni->ngeom);
  EXPECT_EQ(m->nbody, omni->nbody + 1);
  EXPECT_EQ(m->nmocap, 1);
  EXPECT_EQ(mj_getTotalmass(m.get()), mj_getTotalmass(omni.get()));

  const int target = mj_name2id(m.get(), mjOBJ_BODY, "hand_target");
  ASSERT_GE(target, 0);
  EXPECT_EQ(m->body_mocapid[target], 0);
  EXPECT_EQ(m->body_parentid[target], 0);
  EXPECT_EQ(m->body_geomnum[target], 0);
  EXPECT_EQ(m->body_mass[target], 0.0);
  const int site = mj_name2id(m.get(), mjOBJ_SITE, "hand_target");
  ASSERT_GE(site, 0);
  EXPECT_EQ(m->site_bodyid[site], target);
  // the simulator needs the grip site of omni.xml next to the target
  EXPECT_GE(mj_name2id(m.get(), mjOBJ_SITE, "grip"), 0);

  const int home = mj_name2id(m.get(), mjOBJ_KEY, "home");
  ASSERT_GE(home, 0);
  DataPtr d(mj_makeData(m.get()));
  mj_resetDataKeyframe(m.get(), d.get(), home);
  mj_forward(m.get(), d.get());
  for (int i = 0; i < m->nq; ++i) EXPECT_EQ(d->qpos[i], 0.0);
  EXPECT_EQ(MujocoGuard::warnings(), "");
  EXPECT_EQ(MujocoGuard::data_warnings(d.get()), "");
}

// The six hand_* numerics exist with their sizes (1, 3, 1, 1, 1, 1) and the
// values of models/hand/README.md; every value is finite and > 0. Exact.
TEST(HandModelTest, DefinesTheHandNumerics) {
  MujocoGuard guard;
  const TempScene scene;
  ModelPtr m = load_or_fail(scene.path());
  ASSERT_NE(m, nullptr);
  struct Field {
    const char* name;
    std::vector<double> value;
  };
  const std::array<Field, 6> fields = {{
      {"hand_mass_kg", {0.554}},
      {"hand_inertia_kgm2", {2e-4, 2e-4, 2e-4}},
      {"hand_k_pos_N_per_m", {135.0}},
      {"hand_b_pos_Ns_per_m", {6.45}},
      {"hand_k_rot_Nm_per_rad", {0.5}},
      {"hand_b_rot_Nms_per_rad", {0.02}},
  }};
  for (const Field& f : fields) {
    SCOPED_TRACE(f.name);
    const std::vector<double> v = numeric(m.get(), f.name);
    ASSERT_EQ(v.size(), f.value.size());
    EXPECT_EQ(v, f.value);
  }
  EXPECT_EQ(m->nnumeric, static_cast<int>(fields.size()));

  // the rotational damping is critical for the stylus roll held by the hand
  // alone (README.md): b = 2 sqrt(k I), to 1e-12
  const double k = numeric(m.get(), "hand_k_rot_Nm_per_rad")[0];
  const double inertia = numeric(m.get(), "hand_inertia_kgm2")[2];
  const double b = numeric(m.get(), "hand_b_rot_Nms_per_rad")[0];
  EXPECT_NEAR(b, 2.0 * std::sqrt(k * inertia), 1e-12);
  std::printf("  hand: %d numerics; roll damping ratio %.3f\n", m->nnumeric,
              b / (2.0 * std::sqrt(k * inertia)));
}

}  // namespace
}  // namespace vmh
