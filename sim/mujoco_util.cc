#include "sim/mujoco_util.h"

#include <fstream>
#include <mutex>

namespace vmh::sim {

ModelPtr load_model(const std::string& path) {
  // mj_loadXML's own message for a missing file is terse; say it plainly
  if (!std::ifstream(path).good()) {
    throw SimError(path + ": cannot open the scene file");
  }
  // the XML parser keeps global state: one load at a time
  static std::mutex load_mutex;
  std::lock_guard<std::mutex> lock(load_mutex);
  char err[1024] = "";
  ModelPtr m(mj_loadXML(path.c_str(), nullptr, err, sizeof err));
  if (!m) {
    // MuJoCo's messages span lines; the error contract is one line
    std::string msg = err[0] ? err : "MuJoCo could not load it";
    for (char& ch : msg) {
      if (ch == '\n') ch = ' ';
    }
    throw SimError(path + ": " + msg);
  }
  return m;
}

int require_id(const mjModel* m, mjtObj type, const char* name,
               const std::string& source) {
  const int id = mj_name2id(m, type, name);
  if (id < 0) {
    const char* what = type == mjOBJ_JOINT      ? "joint"
                       : type == mjOBJ_SITE     ? "site"
                       : type == mjOBJ_BODY     ? "body"
                       : type == mjOBJ_ACTUATOR ? "actuator"
                                                : "object";
    throw SimError(source + ": " + what + " '" + name + "' not found");
  }
  return id;
}

std::vector<double> custom_numeric(const mjModel* m, const std::string& name) {
  const int id = mj_name2id(m, mjOBJ_NUMERIC, name.c_str());
  if (id < 0) return {};
  const int adr = m->numeric_adr[id];
  return std::vector<double>(m->numeric_data + adr,
                             m->numeric_data + adr + m->numeric_size[id]);
}

const char* custom_text(const mjModel* m, const std::string& name) {
  const int id = mj_name2id(m, mjOBJ_TEXT, name.c_str());
  return id < 0 ? nullptr : m->text_data + m->text_adr[id];
}

}  // namespace vmh::sim
