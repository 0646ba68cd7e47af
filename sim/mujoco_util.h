// MuJoCo plumbing shared by sim/: owners for mjModel/mjData, a loader that
// turns MuJoCo's error buffer into an exception naming the file, and readers
// for the model's <custom> fields.
#ifndef VMHAPTICS_SIM_MUJOCO_UTIL_H_
#define VMHAPTICS_SIM_MUJOCO_UTIL_H_

#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace vmh::sim {

// A setup-time error in the simulator (bad scene, bad parameter). The
// message names the file and the field.
class SimError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

// What a scene may be before it is compiled (besides
// sim/cases/scene_fields.h's kMaxSceneBytes for its XML and includes together):
// the bodies of the scene with its includes, and each asset file (mesh,
// texture, height field, skin) it names.
inline constexpr int kMaxSceneBodies = 200;
inline constexpr std::uint64_t kMaxAssetBytes = std::uint64_t{64} << 20;

// Compiles an MJCF file. Throws SimError "<path>: <MuJoCo's message>" when the
// file is missing or MuJoCo rejects it, and before MuJoCo reads it when the
// scene or a file it includes is not a regular file (a FIFO would block
// MuJoCo's reader), its XML is over kMaxSceneBytes, it has more than
// kMaxSceneBodies bodies, an include is a cycle, or an asset file it names
// is not a regular file or is over kMaxAssetBytes. Installs the project's MuJoCo error
// and warning handlers first (sim/mujoco_messages.h), as does
// save_edited_model_xml.
ModelPtr load_model(const std::string& path);

// The same scene for a run that draws nothing: the files it includes are
// compiled without what is only drawn (geoms of the "visual" classes and
// of group 2, lights, cameras, the skybox), which the physics does not
// read (every body has its own <inertial>; those geoms neither collide nor
// weigh) but MuJoCo would pose at every step: about a tenth of a case
// run's time. The trajectory is the same to the last bit
// (tests/sim/closed_loop_test.cc). Errors as load_model.
ModelPtr load_model_headless(const std::string& path);

// Loads in_path, calls edit on the model, and writes it as MJCF to out_path
// with mj_saveLastXML, which saves the last XML parsed with the model's
// current values: so the load and the save hold load_model's lock together.
// Throws SimError naming the file that could not be loaded or written.
void save_edited_model_xml(const std::string& in_path,
                           const std::function<void(mjModel*)>& edit,
                           const std::string& out_path);

// Id of a named object, or throws SimError "<what> '<name>' not found in
// <source>".
int require_id(const mjModel* m, mjtObj type, const char* name,
               const std::string& source);

// A <custom><numeric> field: its values, or empty if there is none.
std::vector<double> custom_numeric(const mjModel* m, const std::string& name);
// A <custom><text> field, or nullptr if there is none.
const char* custom_text(const mjModel* m, const std::string& name);

// Whether the n values at v are all finite (a state MuJoCo can go on
// from): no allocation, safe on the emulator's physics thread.
inline bool all_finite(const mjtNum* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

}  // namespace vmh::sim

#endif  // VMHAPTICS_SIM_MUJOCO_UTIL_H_
