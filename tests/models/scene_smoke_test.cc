// Smoke test of every scene under models/ (after mujoco_menagerie's
// test/model_test.py): each loads without a MuJoCo error or warning, is reset
// to its "home" keyframe when it has one, and runs one simulated second with
// random controls inside ctrlrange, after which d->warning is all zero and
// the state is finite.
//
// Scenes are found at run time: models/omni/scene*.xml (at least one must
// exist) and models/cases/*.xml (none yet is not a failure).
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
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

constexpr double kDurationS = 1.0;

// the .xml files in `dir` whose names start with `prefix`, sorted
std::vector<fs::path> xml_files(const fs::path& dir,
                                const std::string& prefix) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && e.path().extension() == ".xml" &&
        name.compare(0, prefix.size(), prefix) == 0) {
      files.push_back(e.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

bool state_finite(const mjModel* m, const mjData* d) {
  for (int i = 0; i < m->nq; ++i) {
    if (!std::isfinite(d->qpos[i])) return false;
  }
  for (int i = 0; i < m->nv; ++i) {
    if (!std::isfinite(d->qvel[i])) return false;
  }
  return true;
}

// loads `path`, resets to "home" if present, steps kDurationS with a fresh
// uniform ctrl inside ctrlrange at every step (seeded), and checks for
// warnings and a finite state
void smoke(const fs::path& path) {
  SCOPED_TRACE(path.string());
  MujocoGuard guard;
  std::string error;
  ModelPtr m = testing::load_model(path.string(), &error);
  ASSERT_NE(m, nullptr) << error;
  EXPECT_TRUE(error.empty()) << error;
  DataPtr d(mj_makeData(m.get()));
  ASSERT_NE(d, nullptr);

  const int home = mj_name2id(m.get(), mjOBJ_KEY, "home");
  if (home >= 0) {
    mj_resetDataKeyframe(m.get(), d.get(), home);
  }
  mj_forward(m.get(), d.get());

  std::mt19937 rng(12345u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int steps =
      static_cast<int>(std::lround(kDurationS / m->opt.timestep));
  double max_speed = 0.0;
  for (int n = 0; n < steps; ++n) {
    for (int a = 0; a < m->nu; ++a) {
      double lo = -1.0, hi = 1.0;
      if (m->actuator_ctrllimited[a]) {
        lo = m->actuator_ctrlrange[2 * a];
        hi = m->actuator_ctrlrange[2 * a + 1];
      }
      d->ctrl[a] = lo + unit(rng) * (hi - lo);
    }
    mj_step(m.get(), d.get());
    for (int i = 0; i < m->nv; ++i) {
      max_speed = std::max(max_speed, std::abs(d->qvel[i]));
    }
  }
  EXPECT_EQ(MujocoGuard::warnings(), "");
  EXPECT_EQ(MujocoGuard::data_warnings(d.get()), "");
  EXPECT_TRUE(state_finite(m.get(), d.get()));
  EXPECT_NEAR(d->time, kDurationS, 0.5 * m->opt.timestep);
  std::printf("  %s: %d steps of %.4g s, nq %d, nu %d, max |qvel| %.3g rad/s\n",
              path.filename().string().c_str(), steps, m->opt.timestep, m->nq,
              m->nu, max_speed);
}

// every models/omni/scene*.xml; there must be at least one
TEST(SceneSmokeTest, OmniScenesStepForASecond) {
  const std::vector<fs::path> scenes =
      xml_files(fs::path(testing::models_dir()) / "omni", "scene");
  ASSERT_FALSE(scenes.empty()) << "no models/omni/scene*.xml";
  for (const fs::path& p : scenes) smoke(p);
}

// every models/cases/*.xml (each includes omni.xml and hand.xml)
TEST(SceneSmokeTest, CaseScenesStepForASecond) {
  const std::vector<fs::path> cases =
      xml_files(fs::path(testing::models_dir()) / "cases", "");
  if (cases.empty()) {
    GTEST_SKIP() << "models/cases/ has no scenes yet";
  }
  for (const fs::path& p : cases) smoke(p);
}

}  // namespace
}  // namespace vmh
