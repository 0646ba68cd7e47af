// libFuzzer harness: a scene's <custom> fields as the case loader reads them
// (sim/cases/case_config.h: CaseConfig::from_model).
//
// The input is the body of a scene's <custom> element (<numeric> and <text>
// fields); the harness puts it into a minimal MJCF scene, has MuJoCo
// (uninstrumented, from an in-memory file) compile it, and reads the case
// from the model. A scene MuJoCo refuses is not this harness's business.
// From a compiled model the loader must either refuse with a SimError that
// has a message (an unknown field, a field under the other kind's tag, a
// bad value) or accept with every value within its table row's documented
// range (case_params_check.h).
#include <mujoco/mujoco.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>

#include "sim/cases/case_config.h"
#include "sim/mujoco_messages.h"
#include "sim/mujoco_util.h"
#include "tests/fuzz/case_params_check.h"

namespace {

const char kHead[] = "<mujoco model=\"fuzz\">\n<custom>\n";
const char kTail[] =
    "\n</custom>\n<worldbody><body><freejoint/><geom size=\"0.01\"/></body>"
    "</worldbody>\n</mujoco>\n";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data,
                                      std::size_t size) {
  using namespace vmh;
  static const bool installed = (sim::install_mujoco_handlers(), true);
  (void)installed;
  static mjVFS* vfs = [] {
    auto* v = new mjVFS;
    mj_defaultVFS(v);
    return v;
  }();

  std::string xml = kHead;
  xml.append(reinterpret_cast<const char*>(data), size);
  xml += kTail;
  const char* name = "fuzz.xml";
  if (mj_makeEmptyFileVFS(vfs, name, static_cast<int>(xml.size())) != 0) {
    fuzz::fail(__FILE__, __LINE__, "VFS", "cannot make the in-memory file");
  }
  const int i = mj_findFileVFS(vfs, name);
  std::memcpy(vfs->filedata[i], xml.data(), xml.size());
  char err[1024] = "";
  mjModel* m = nullptr;
  try {
    m = mj_loadXML(name, vfs, err, sizeof err);
  } catch (const sim::MujocoError&) {
    m = nullptr;
  }
  mj_deleteFileVFS(vfs, name);
  if (m == nullptr) return 0;
  std::unique_ptr<mjModel, void (*)(mjModel*)> model(m, mj_deleteModel);

  try {
    const sim::CaseConfig c = sim::CaseConfig::from_model(m, name, {});
    fuzz::check_loaded(c);
  } catch (const sim::SimError& e) {
    fuzz::check_refusal(e);
  }
  return 0;
}
