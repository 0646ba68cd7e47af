// Loading the project's MJCF files in the model tests: RAII owners for
// mjModel/mjData, the path of models/, and a loader that turns a load failure
// into a message a gtest assertion can print.
#ifndef VMHAPTICS_TESTS_MODELS_MODEL_FILES_H_
#define VMHAPTICS_TESTS_MODELS_MODEL_FILES_H_

#include <mujoco/mujoco.h>

#include <memory>
#include <string>

namespace vmh::testing {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

// models/ of the source tree (set by tests/models/CMakeLists.txt)
inline std::string models_dir() { return VMH_MODELS_DIR; }

// Compiles an MJCF file. Returns null and fills *error when MuJoCo rejects
// it (a MujocoGuard must be alive: with it, a mju_error throws instead).
inline ModelPtr load_model(const std::string& path, std::string* error) {
  char err[1000] = "";
  ModelPtr m(mj_loadXML(path.c_str(), nullptr, err, sizeof err));
  if (!m) {
    *error = path + ": " + (err[0] ? err : "mj_loadXML returned null");
  } else if (err[0]) {
    // a non-fatal message from the parser (mj_loadXML's warning channel)
    *error = path + ": " + err;
  }
  return m;
}

}  // namespace vmh::testing

#endif  // VMHAPTICS_TESTS_MODELS_MODEL_FILES_H_
